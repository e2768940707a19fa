//! Issue 29, items 1 and 13 (outputs and environment): a reader that stops early or a full
//! standard output costs no output file and panics nothing; a leftover commit journal can
//! neither touch a user's file nor block; two runs into one folder take turns; every output is
//! checked before the work; SOURCE_DATE_EPOCH and RAYON_NUM_THREADS are checked; control
//! characters never reach the terminal raw; a full disk names the file and leaves no folder.

mod common;

use common::{eij, one_line_error, root, Scratch, DEMO, ZX_CSV};
use std::io::Read;
use std::path::Path;
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

/// A process id that runs nowhere (above any pid_max).
const DEAD: u32 = i32::MAX as u32;

fn command<S: AsRef<std::ffi::OsStr>>(args: &[S]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_eij"));
    c.current_dir(root()).args(args);
    c
}

/// Waits for `child` at most `limit`; kills it and fails if it runs longer.
fn wait_at_most(mut child: Child, limit: Duration, what: &str) -> std::process::ExitStatus {
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return status;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{what}: still running after {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// The identification of one test and one parameter (fast), writing `out` and `report`.
fn identify_args(out: &str, report: &str) -> Vec<String> {
    common::identify_args(out, report)
}

fn owned(args: &[&str]) -> Vec<String> {
    args.iter().map(|a| a.to_string()).collect()
}

/// The whole standard error of a spawned `child`.
fn stderr_of(child: &mut Child) -> String {
    let mut stderr = String::new();
    if let Some(mut e) = child.stderr.take() {
        e.read_to_string(&mut stderr).unwrap();
    }
    stderr
}

#[test]
fn a_reader_that_stops_early_costs_no_output() {
    let s = Scratch::new("i29-pipe");
    let (out, report, comp, csv) = (s.s("m.toml"), s.s("r.json"), s.s("c.csv"), s.s("e.csv"));
    let runs: Vec<(Vec<String>, Vec<&str>)> = vec![
        (identify_args(&out, &report), vec![&out, &report]),
        (
            owned(&[
                "compensation",
                "--machine",
                DEMO,
                "--points",
                "2",
                "--out",
                &comp,
            ]),
            vec![&comp],
        ),
        (owned(&["evaluate", ZX_CSV, "--csv-out", &csv]), vec![&csv]),
        (owned(&["modal", "--machine", DEMO]), vec![]),
        (owned(&["stiffness", "--machine", DEMO]), vec![]),
    ];
    for (args, files) in runs {
        // `eij … | head -1`: the reader takes one line and goes away.
        let mut child = command(&args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let mut stdout = child.stdout.take().unwrap();
        let mut first = [0u8; 1];
        stdout.read_exact(&mut first).unwrap();
        drop(stdout);
        let stderr = stderr_of(&mut child);
        let status = child.wait().unwrap();
        assert!(status.success(), "{args:?}: {status:?} {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        for f in files {
            assert!(Path::new(f).is_file(), "{args:?}: {f} not written");
            std::fs::remove_file(f).unwrap();
        }
    }
}

#[test]
fn a_full_standard_output_is_an_error_after_the_files_are_written() {
    let s = Scratch::new("i29-full");
    let (out, report) = (s.s("m.toml"), s.s("r.json"));
    for (args, files) in [
        (identify_args(&out, &report), vec![&out, &report]),
        (owned(&["evaluate", ZX_CSV]), vec![]),
        (owned(&["stiffness", "--machine", DEMO]), vec![]),
    ] {
        let full = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap();
        let o = command(&args).stdout(full).output().unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        let last = stderr.lines().last().unwrap_or("");
        assert!(
            last.starts_with("eij: error: standard output: cannot write: No space left"),
            "{args:?}: {stderr}"
        );
        for f in files {
            assert!(Path::new(f).is_file(), "{args:?}: {f} not written");
        }
    }
}

/// A journal named like eij's, of a process that no longer runs, in `dir`.
fn leftover_journal(dir: &Path, n: u32, renames: &[(&Path, &Path)]) -> std::path::PathBuf {
    let journal = dir.join(format!(".eij-{DEAD}-{n}.commit"));
    let text = serde_json::json!({
        "renames": renames,
        "copies": [&journal],
    });
    std::fs::write(&journal, text.to_string()).unwrap();
    journal
}

#[test]
fn a_leftover_journal_touches_nothing_but_its_own_temporary_files() {
    let s = Scratch::new("i29-journal");
    let dir = s.0.canonicalize().unwrap();
    let machine = s.write("m.toml", common::demo_text());
    let notes = s.write("notes.txt", "a user's file\n");
    let out = dir.join("e.json");
    // A foreign temporary name for the output, and a temporary name for an input.
    let fake_tmp = s.write(
        &format!(".eij-{DEAD}-2-0123456789abcdef.tmp"),
        "not eij's\n",
    );
    leftover_journal(
        &dir,
        1,
        &[
            (Path::new(&notes), Path::new(&machine)),
            (Path::new(&notes), &out),
            (Path::new(&fake_tmp), Path::new(&machine)),
        ],
    );
    let before_machine = std::fs::read(&machine).unwrap();
    let o = eij(&[
        "export",
        "--machine",
        &machine,
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(std::fs::read_to_string(&notes).unwrap(), "a user's file\n");
    assert_eq!(std::fs::read(&machine).unwrap(), before_machine);
    assert_eq!(std::fs::read_to_string(&fake_tmp).unwrap(), "not eij's\n");
    let export: serde_json::Value = serde_json::from_slice(&std::fs::read(&out).unwrap()).unwrap();
    assert!(export["state_space"]["A"].is_array());
}

#[test]
fn a_fifo_named_like_a_journal_never_blocks() {
    let s = Scratch::new("i29-fifo");
    let fifo = s.path(&format!(".eij-{DEAD}-1.commit"));
    let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    // SAFETY: mkfifo with a valid C string.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o644) }, 0);
    let out = s.s("e.json");
    let child = command(&["export", "--machine", DEMO, "--out", &out])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let status = wait_at_most(
        child,
        Duration::from_secs(30),
        "export beside a FIFO journal",
    );
    assert!(status.success());
    assert!(Path::new(&out).is_file());
}

#[test]
fn a_run_waits_while_another_commits_into_the_folder() {
    use std::os::fd::AsRawFd;
    let s = Scratch::new("i29-lock");
    let out = s.s("e.json");
    // Another run's commit holds the folder (the lock eij takes while committing).
    let folder = std::fs::File::open(&s.0).unwrap();
    // SAFETY: flock on a descriptor this test owns.
    assert_eq!(unsafe { libc::flock(folder.as_raw_fd(), libc::LOCK_EX) }, 0);
    let mut child = command(&["export", "--machine", DEMO, "--out", &out])
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(1500));
    assert!(
        !Path::new(&out).exists(),
        "written while the folder was held"
    );
    assert!(child.try_wait().unwrap().is_none(), "did not wait");
    drop(folder);
    let status = wait_at_most(child, Duration::from_secs(30), "export after the lock");
    assert!(status.success());
    assert!(Path::new(&out).is_file());
}

#[test]
fn concurrent_runs_leave_one_runs_set() {
    let s = Scratch::new("i29-pairs");
    let (csv, svg) = (s.s("o.csv"), s.s("o.svg"));
    let files = [
        "measurements/demo-vmc/pos-a/xy_cw_2.csv",
        "measurements/demo-vmc/pos-b/zx_ccw_5.csv",
    ];
    for _ in 0..8 {
        let children: Vec<Child> = files
            .iter()
            .map(|f| {
                command(&["evaluate", f, "--csv-out", &csv, "--plot", &svg])
                    .stdout(Stdio::null())
                    .stderr(Stdio::null())
                    .spawn()
                    .unwrap()
            })
            .collect();
        for c in children {
            assert!(wait_at_most(c, Duration::from_secs(60), "evaluate").success());
        }
        let table = std::fs::read_to_string(&csv).unwrap();
        let figure = std::fs::read_to_string(&svg).unwrap();
        let from_xy = table.contains("\nxy,");
        assert_eq!(
            figure.contains("xy_cw_2.csv"),
            from_xy,
            "the table and the figure come from different runs"
        );
    }
}

#[test]
fn every_output_is_checked_before_the_work() {
    let s = Scratch::new("i29-check");
    let out = s.s("m.toml");
    let long = s.s(&format!("{}.json", "r".repeat(300)));
    let start = Instant::now();
    let o = command(&identify_args(&out, &long)).output().unwrap();
    one_line_error(&o, &["File name too long"]);
    assert!(!Path::new(&out).exists());
    // Found before the fit: far faster than the identification itself.
    let refused_in = start.elapsed();
    let report = s.write("r.json", "old report\n");
    // An immutable report (root only: chattr +i needs CAP_LINUX_IMMUTABLE).
    let immutable = Command::new("chattr")
        .args(["+i", &report])
        .output()
        .is_ok_and(|o| o.status.success());
    if immutable {
        let o = command(&identify_args(&out, &report)).output().unwrap();
        let _ = Command::new("chattr").args(["-i", &report]).output();
        one_line_error(&o, &["r.json", "cannot be replaced", "immutable"]);
        assert!(!Path::new(&out).exists());
        assert_eq!(std::fs::read_to_string(&report).unwrap(), "old report\n");
    } else {
        eprintln!("chattr +i not permitted here: the immutable case is not run");
    }
    assert!(refused_in < Duration::from_secs(30));
}

#[test]
fn source_date_epoch_must_be_seconds() {
    let s = Scratch::new("i29-epoch");
    let (out, report) = (s.s("m.toml"), s.s("r.json"));
    for (value, why) in [
        ("1700000000000", "after the year 9999"),
        ("2023-11-14", "not a whole number"),
        ("-5", "not a whole number"),
    ] {
        let o = command(&identify_args(&out, &report))
            .env("SOURCE_DATE_EPOCH", value)
            .output()
            .unwrap();
        one_line_error(&o, &["SOURCE_DATE_EPOCH", why]);
        let o = command(&["report", "--measured", ZX_CSV, "--out", &s.s("rep")])
            .env("SOURCE_DATE_EPOCH", value)
            .output()
            .unwrap();
        one_line_error(&o, &["SOURCE_DATE_EPOCH", why]);
        assert_eq!(std::fs::read_dir(&s.0).unwrap().count(), 0);
    }
    let o = command(&identify_args(&out, &report))
        .env("SOURCE_DATE_EPOCH", "1700000000")
        .output()
        .unwrap();
    assert!(o.status.success());
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.contains("2023-11-14T22:13:20Z"), "{text}");
}

/// The largest number of threads of process `pid` seen while it runs.
fn peak_threads(child: &mut Child) -> usize {
    let status = format!("/proc/{}/status", child.id());
    let mut peak = 0;
    while child.try_wait().unwrap().is_none() {
        if let Ok(text) = std::fs::read_to_string(&status) {
            if let Some(n) = text
                .lines()
                .find_map(|l| l.strip_prefix("Threads:"))
                .and_then(|n| n.trim().parse().ok())
            {
                peak = peak.max(n);
            }
        }
        std::thread::sleep(Duration::from_millis(2));
    }
    peak
}

#[test]
fn worker_threads_are_capped_at_the_cores() {
    let s = Scratch::new("i29-threads");
    let (out, report) = (s.s("m.toml"), s.s("r.json"));
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let asked = (4 * cores + 32).to_string();
    let mut child = command(&identify_args(&out, &report))
        .env("RAYON_NUM_THREADS", &asked)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let peak = peak_threads(&mut child);
    let stderr = stderr_of(&mut child);
    assert!(child.wait().unwrap().success(), "{stderr}");
    // The main thread and the workers.
    assert!(peak <= cores + 2, "{peak} threads on {cores} cores");
    assert!(
        stderr.contains(&format!("RAYON_NUM_THREADS={asked} is more than")),
        "{stderr}"
    );
}

#[test]
fn control_characters_never_reach_the_terminal_raw() {
    let s = Scratch::new("i29-ctl");
    let name = s.s("bad\u{1b}[31mred\u{7}.csv");
    let o = eij(&["evaluate", &name]);
    let line = one_line_error(&o, &["file not found", "\\u{1b}[31mred\\u{7}"]);
    assert!(!line.chars().any(char::is_control), "{line:?}");
    let o: Output = eij(&["evaluate", &s.write("x\u{1b}.csv", "t_s\n0\n")]);
    let line = one_line_error(&o, &["x\\u{1b}.csv"]);
    assert!(!line.chars().any(char::is_control), "{line:?}");
}

/// A 1 MiB tmpfs at `dir` (root only), unmounted on drop.
struct SmallDisk(std::path::PathBuf);

impl SmallDisk {
    fn mount(dir: std::path::PathBuf) -> Option<SmallDisk> {
        std::fs::create_dir_all(&dir).unwrap();
        let ok = Command::new("mount")
            .args(["-t", "tmpfs", "-o", "size=1m", "tmpfs"])
            .arg(&dir)
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|s| s.success());
        ok.then_some(SmallDisk(dir))
    }
}

impl Drop for SmallDisk {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(&self.0).status();
    }
}

#[test]
fn a_full_disk_names_the_file_and_leaves_no_report_folder() {
    let s = Scratch::new("i29-disk");
    let Some(disk) = SmallDisk::mount(s.path("disk")) else {
        eprintln!("no tmpfs could be mounted here (root only): the full-disk case is not run");
        return;
    };
    let d = &disk.0;
    std::fs::write(d.join("fill"), vec![0u8; 1000 * 1024]).unwrap();
    let csv = d.join("c.csv").display().to_string();
    let args = common::circle_args(DEMO, &csv);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    one_line_error(&eij(&args), &["c.csv", "No space left on device"]);
    let rep = d.join("rep");
    let o = eij(&[
        "report",
        "--measured",
        "measurements/demo-vmc/pos-a",
        "--out",
        rep.to_str().unwrap(),
    ]);
    one_line_error(&o, &["report.html", "No space left on device"]);
    assert!(!rep.exists(), "the empty report folder is left behind");
    let left: Vec<_> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left, ["fill"]);
}
