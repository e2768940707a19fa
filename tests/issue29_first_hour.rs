//! Issue 29, what got in a new user's way: a report of an identification alone (item 4), one
//! verdict in one colour (item 5), progress on a terminal only and one line saying what was
//! written (item 7), an output path ending in a separator (item 8).

mod common;

use common::{eij, one_line_error, root, run, Scratch, DEMO, ZX_CSV};
use std::io::Read;
use std::os::fd::{FromRawFd, OwnedFd};
use std::process::{Command, Stdio};

/// A doubtful identification (one test for one parameter: the χ² test fails) into `s`.
fn doubtful_report(s: &Scratch) -> String {
    let (out, report) = (s.s("m.toml"), s.s("r.json"));
    let args = common::identify_args(&out, &report);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let r = run(&args);
    assert!(r.ok, "{}", r.stderr);
    assert!(r.stderr.contains("χ² test failed"), "{}", r.stderr);
    report
}

#[test]
fn a_report_of_an_identification_alone() {
    let s = Scratch::new("i29-report-alone");
    let report = doubtful_report(&s);
    let dir = s.s("page");
    let r = run(&["report", "--identify-report", &report, "--out", &dir]);
    assert!(r.ok, "{}", r.stderr);
    let page = std::fs::read_to_string(s.path("page/report.html")).unwrap();
    assert!(page.contains("Verdict"));
    assert!(page.contains("none given: no circle test on this page"));
    // No circle test, so no word about circle tests' warnings.
    assert!(!page.contains("Circle-test evaluation"));
    // Still at least one input.
    let o = eij(&["report", "--out", &dir]);
    one_line_error(&o, &["required arguments were not provided"]);
}

/// The verdict block of the first identification: from its frame to its parameter table.
fn verdict_block(page: &str) -> &str {
    let start = page.find("<div class=\"verdict").expect("a verdict block");
    let end = start + page[start..].find("<table").expect("a parameter table");
    &page[start..end]
}

#[test]
fn one_verdict_in_one_colour() {
    let s = Scratch::new("i29-colour");
    let report = doubtful_report(&s);
    let dir = s.s("page");
    let r = run(&[
        "report",
        "--measured",
        ZX_CSV,
        "--identify-report",
        &report,
        "--out",
        &dir,
    ]);
    assert!(r.ok, "{}", r.stderr);
    let page = std::fs::read_to_string(s.path("page/report.html")).unwrap();
    let block = verdict_block(&page);
    assert!(block.contains("DOUBTFUL"), "{block}");
    assert!(block.contains("class=\"bad\""), "{block}");
    for other in ["class=\"ok\"", "class=\"weak\""] {
        assert!(
            !block.contains(other),
            "a second colour in the verdict: {block}"
        );
    }
    assert!(
        block.contains("whether to use it: see the verdict"),
        "{block}"
    );
}

#[test]
fn an_output_ending_in_a_separator_is_refused_by_every_command() {
    let s = Scratch::new("i29-slash");
    let dir = format!("{}/", s.s("newdir"));
    let circle = common::circle_args(DEMO, &dir);
    let map = common::map_args(DEMO, &dir);
    let identify = common::identify_args(&dir, &s.s("r.json"));
    let commands: Vec<Vec<String>> = vec![
        ["export", "--machine", DEMO, "--out", &dir]
            .map(String::from)
            .to_vec(),
        ["stiffness", "--machine", DEMO, "--out", &dir]
            .map(String::from)
            .to_vec(),
        ["compensation", "--machine", DEMO, "--out", &dir]
            .map(String::from)
            .to_vec(),
        ["evaluate", ZX_CSV, "--csv-out", &dir]
            .map(String::from)
            .to_vec(),
        circle,
        map,
        identify,
    ];
    for args in commands {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = eij(&args);
        one_line_error(
            &o,
            &["newdir/: ends in a path separator, so it names a folder"],
        );
        assert_eq!(std::fs::read_dir(&s.0).unwrap().count(), 0, "{args:?}");
    }
}

#[test]
fn piped_or_quiet_there_is_no_progress_and_one_line_says_what_was_written() {
    let s = Scratch::new("i29-quiet");
    let out = s.s("map.csv");
    let args = common::map_args(DEMO, &out);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let r = run(&args);
    assert!(r.ok, "{}", r.stderr);
    assert_eq!(r.stdout, "");
    assert_eq!(r.stderr, format!("eij: wrote {out}\n"));
    let mut quiet = args.clone();
    quiet.push("--quiet");
    let r = run(&quiet);
    assert!(r.ok, "{}", r.stderr);
    assert_eq!((r.stdout.as_str(), r.stderr.as_str()), ("", ""));
    // Every command that writes a file says so, in one line.
    let e = s.s("e.json");
    let r = run(&["export", "--machine", DEMO, "--out", &e]);
    assert_eq!(r.stderr, format!("eij: wrote {e}\n"));
    let c = s.s("c.csv");
    let circle = common::circle_args(DEMO, &c);
    let circle: Vec<&str> = circle.iter().map(String::as_str).collect();
    let r = run(&circle);
    assert_eq!(r.stderr, format!("eij: wrote {c}\n"));
}

/// Runs `eij args…` with standard error on a new pseudo-terminal; what the terminal received.
fn on_a_terminal(args: &[&str]) -> String {
    let (mut master, mut slave) = (0, 0);
    // SAFETY: openpty fills two descriptors; no name, settings or size are passed.
    let r = unsafe {
        libc::openpty(
            &mut master,
            &mut slave,
            std::ptr::null_mut(),
            std::ptr::null(),
            std::ptr::null(),
        )
    };
    assert_eq!(r, 0, "openpty");
    // SAFETY: both descriptors were just opened and are owned here alone.
    let (master, slave) = unsafe { (OwnedFd::from_raw_fd(master), OwnedFd::from_raw_fd(slave)) };
    let mut child = Command::new(env!("CARGO_BIN_EXE_eij"))
        .current_dir(root())
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::from(slave))
        .spawn()
        .unwrap();
    let mut terminal = std::fs::File::from(master);
    let mut seen = Vec::new();
    let mut buf = [0u8; 4096];
    // Read until the child has ended and closed its side (then the read fails with EIO).
    while let Ok(n) = terminal.read(&mut buf) {
        if n == 0 {
            break;
        }
        seen.extend_from_slice(&buf[..n]);
    }
    assert!(child.wait().unwrap().success());
    String::from_utf8_lossy(&seen).into_owned()
}

#[test]
fn a_terminal_shows_progress() {
    let s = Scratch::new("i29-tty");
    let out = s.s("map.csv");
    let seen = on_a_terminal(&[
        "map",
        "--machine",
        DEMO,
        "--plane",
        "zx",
        "--accel-m-s2",
        "5",
        "--grid",
        "x=-300:300:40",
        "--out",
        &out,
    ]);
    assert!(seen.contains("/40 grid points"), "{seen:?}");
    assert!(seen.contains(&format!("eij: wrote {out}")), "{seen:?}");
}
