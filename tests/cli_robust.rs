//! Issue 15, by class (catalogue in `docs/bad-inputs.md`, cases 105–): limits on every size a
//! file or an option sets, every file read is an input and never an output, non-regular outputs
//! refused and left as they are, the outputs of a run written as one set, no silent nonsense
//! (NaN, doubled data, ignored files, duplicate rows), short and well-aimed messages.
//! Every refusal: non-zero exit, one line, no panic, the scratch folder unchanged.

mod common;

use common::{demo_text, eij, one_line_error, Scratch, DEMO, ZX_CSV};
use std::os::unix::fs::PermissionsExt;

/// Runs `eij args…`, checks a refusal (one line holding `needle`, nothing on stdout, the
/// scratch folder unchanged) and returns the line.
fn refused(s: &Scratch, args: &[&str], needle: &str) -> String {
    let before = s.snapshot();
    let out = eij(args);
    assert!(out.stdout.is_empty(), "{args:?}: stdout not empty");
    let line = one_line_error(&out, &[needle]);
    assert!(
        s.snapshot() == before,
        "{args:?}: the scratch folder changed"
    );
    line
}

fn ok(args: &[&str]) {
    let out = eij(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn circle(out: &str, machine: &str) -> Vec<String> {
    common::circle_args(machine, out)
}

fn identify(s: &Scratch, machine: &str, measured: &str, extra: &[&str]) -> Vec<String> {
    let mut v: Vec<String> = [
        "identify",
        "--machine",
        machine,
        "--measured",
        measured,
        "--param",
        "z.guideway_normal",
        "--quiet",
        "--no-design",
        "--out",
        &s.s("id.toml"),
        "--report",
        &s.s("id.json"),
    ]
    .map(String::from)
    .to_vec();
    v.extend(extra.iter().map(|e| e.to_string()));
    v
}

fn strs(v: &[String]) -> Vec<&str> {
    v.iter().map(String::as_str).collect()
}

/// `eij map` of the demo into `map.csv` (three points along x): its text and last row.
fn demo_map(s: &Scratch) -> (String, String) {
    let mp = s.s("map.csv");
    ok(&strs(&common::map_args(DEMO, &mp)));
    let text = std::fs::read_to_string(&mp).unwrap();
    let last = text.lines().last().unwrap().to_string();
    (text, last)
}

// ---- sizes ---------------------------------------------------------------------------------

#[test]
fn every_size_is_bounded_before_allocating() {
    let s = Scratch::new("rb-sizes");
    for (text, needle) in [
        (
            "revolutions = 1000000000\n",
            "revolutions = 1e9 is not allowed: must lie in (0, 1000]",
        ),
        (
            "revolutions = 1e9\n",
            "revolutions = 1e9 is not allowed: must lie in (0, 1000]",
        ),
        (
            "revolutions = 2.5\n",
            "revolutions = 2.5 is not allowed: must be a whole number",
        ),
        (
            "rate_hz = 1e12\n",
            "rate_hz = 1e12 is not allowed: must lie in (0, 1000000] Hz",
        ),
        (
            "max_iters = 1e30\n",
            "max_iters = 1e30 is not allowed: must lie in (0, 1000000]",
        ),
    ] {
        let cfg = s.write("cfg.toml", text);
        let args = identify(&s, DEMO, ZX_CSV, &["--config", &cfg]);
        refused(&s, &strs(&args), &format!("{cfg}: {needle}"));
    }
    // Within each limit, but together too long: the simulation says so before allocating.
    let cfg = s.write(
        "cfg.toml",
        "rate_hz = 1e6\nrevolutions = 1000\nsolver = \"time\"\n",
    );
    let args = identify(&s, DEMO, ZX_CSV, &["--config", &cfg]);
    refused(&s, &strs(&args), "samples, at most 2000000 are simulated");
    let mut args = circle(&s.s("c.csv"), DEMO);
    args.extend(["--revolutions".into(), "4000000000".into()]);
    refused(
        &s,
        &strs(&args),
        "--revolutions: 4000000000 must lie in 1…1000 steady revolutions",
    );
    let mut many = demo_text();
    let at = many.find("[[body]]").unwrap();
    let extra: String = (0..150)
        .map(|k| format!("[[body]]\nname = \"extra{k}\"\nfixed = true\n\n"))
        .collect();
    many.insert_str(at, &extra);
    let m = s.write("many.toml", many);
    refused(
        &s,
        &["modal", "--machine", &m],
        &format!("{m}: body: 155 given, at most 100"),
    );
}

#[test]
fn an_endless_pipe_stops_at_the_size_limit() {
    let s = Scratch::new("rb-fifo-in");
    let fifo = s.path("endless.csv");
    assert!(std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let writer = {
        let fifo = fifo.clone();
        std::thread::spawn(move || {
            use std::io::Write;
            let mut f = std::fs::OpenOptions::new().write(true).open(fifo).unwrap();
            let block = vec![b'0'; 1 << 20];
            // Until eij closes its end (EPIPE): far more than it reads.
            while f.write_all(&block).is_ok() {}
        })
    };
    let f = fifo.display().to_string();
    refused(
        &s,
        &["evaluate", &f],
        &format!("{f}: cannot read: holds more than 512 MiB (the most eij reads from one input; an endless device or pipe?)"),
    );
    writer.join().unwrap();
}

// ---- inputs are never outputs ----------------------------------------------------------------

/// A machine with an extra catalogue beside it.
fn with_catalogue(s: &Scratch) -> (String, String) {
    let cat = s.write(
        "extra.toml",
        "[[carriage]]\nid = \"MY ONE\"\nradial_n_per_um = 500\nreverse_radial_n_per_um = 400\n\
         lateral_n_per_um = 450\nestimated = []\nsource = \"test\"\n",
    );
    let m = s.write(
        "m.toml",
        demo_text().replacen("\n[", "\ncatalogue = [\"extra.toml\"]\n\n[", 1),
    );
    (m, cat)
}

#[test]
fn no_output_replaces_a_file_read_directly_or_indirectly() {
    let s = Scratch::new("rb-inputs");
    let (m, cat) = with_catalogue(&s);
    let clobber = format!("{cat}: refusing to overwrite an input file");
    refused(&s, &strs(&circle(&cat, &m)), &clobber);
    refused(&s, &["export", "--machine", &m, "--out", &cat], &clobber);
    refused(&s, &["stiffness", "--machine", &m, "--out", &cat], &clobber);
    refused(
        &s,
        &["compensation", "--machine", &m, "--out", &cat],
        &clobber,
    );
    let mp = s.s("map.csv");
    let mut map = common::map_args(&m, &mp);
    map.extend(["--plot".to_string(), cat.clone()]);
    refused(&s, &strs(&map), &clobber);
    let args = identify(&s, &m, ZX_CSV, &["--stiffness-out", &cat]);
    refused(&s, &strs(&args), &clobber);
    // A hard link to an input is the input.
    let input = s.write(
        "zx.csv",
        std::fs::read(common::root().join(ZX_CSV)).unwrap(),
    );
    let hard = s.s("hard.csv");
    std::fs::hard_link(&input, &hard).unwrap();
    refused(
        &s,
        &["evaluate", &input, "--csv-out", &hard],
        &format!("{hard}: refusing to overwrite an input file (read as {input})"),
    );
    // The folder's rtest.toml and a two-system test's external file are inputs too.
    let cond = s.write("meas/rtest.toml", "radius_mm = 2.0\n");
    s.write("meas/zx.csv", std::fs::read(&input).unwrap());
    let meas = s.s("meas");
    refused(
        &s,
        &["evaluate", &meas, "--csv-out", &cond],
        &format!("{cond}: refusing to overwrite an input file"),
    );
    // A map given to the report, named like the report's page.
    let rep = s.s("rep");
    std::fs::create_dir(&rep).unwrap();
    let (text, _) = demo_map(&s);
    let own = s.write("rep/report.html", text);
    refused(
        &s,
        &["report", "--measured", &input, "--map", &own, "--out", &rep],
        &format!("{own}: refusing to overwrite an input file"),
    );
}

// ---- non-regular outputs -----------------------------------------------------------------------

#[test]
fn devices_fifos_sockets_and_links_are_never_replaced() {
    let s = Scratch::new("rb-special");
    let run = |cmd: &str, p: &std::path::Path| {
        assert!(std::process::Command::new("sh")
            .arg("-c")
            .arg(format!("{cmd} '{}'", p.display()))
            .status()
            .unwrap()
            .success());
    };
    let fifo = s.path("out.fifo");
    run("mkfifo", &fifo);
    // A character device made here (1,3 is what the system's null device is), never the
    // system's own node.
    let dev = s.path("null.dev");
    assert!(std::process::Command::new("mknod")
        .args([dev.to_str().unwrap(), "c", "1", "3"])
        .status()
        .unwrap()
        .success());
    let target = s.write("target.csv", "old\n");
    let link = s.path("link.csv");
    std::os::unix::fs::symlink(&target, &link).unwrap();
    let dangling = s.path("dangling.csv");
    std::os::unix::fs::symlink(s.path("nowhere.csv"), &dangling).unwrap();
    let sock = s.path("sock");
    let _listener = std::os::unix::net::UnixListener::bind(&sock).unwrap();
    for (p, kind) in [
        (&fifo, "FIFO"),
        (&dev, "character device"),
        (&link, "symbolic link"),
        (&dangling, "symbolic link"),
        (&sock, "socket"),
    ] {
        let p = p.display().to_string();
        let needle =
            format!("{p}: is a {kind}, not a regular file; eij replaces only regular files");
        refused(&s, &strs(&circle(&p, DEMO)), &needle);
        refused(&s, &["export", "--machine", DEMO, "--out", &p], &needle);
        let args = identify(&s, DEMO, ZX_CSV, &["--plot", &p]);
        refused(&s, &strs(&args), &needle);
    }
    // The report's page itself.
    let rep = s.s("rep");
    std::fs::create_dir(&rep).unwrap();
    run("mkfifo", &s.path("rep/report.html"));
    refused(
        &s,
        &["report", "--measured", ZX_CSV, "--out", &rep],
        &format!("{rep}/report.html: is a FIFO"),
    );
}

// ---- outputs as a set --------------------------------------------------------------------------

#[test]
fn outputs_are_written_together_keeping_permissions_and_long_names() {
    let s = Scratch::new("rb-set");
    // One output refused: none of the run's outputs is written, and no work is done.
    let file = s.write("file", "x");
    let args = identify(&s, DEMO, ZX_CSV, &["--plot", &format!("{file}/p.svg")]);
    refused(&s, &strs(&args), "cannot write: folder");
    // A replaced output keeps its permissions (never widened to 0644).
    let out = s.write("c.csv", "old\n");
    let plot = s.write("c.svg", "old\n");
    std::fs::set_permissions(&out, std::fs::Permissions::from_mode(0o600)).unwrap();
    std::fs::set_permissions(&plot, std::fs::Permissions::from_mode(0o640)).unwrap();
    let mut args = circle(&out, DEMO);
    args.extend(["--plot".into(), plot.clone()]);
    ok(&strs(&args));
    for (p, mode) in [(&out, 0o600), (&plot, 0o640)] {
        let m = std::fs::metadata(p).unwrap();
        assert_eq!(m.permissions().mode() & 0o777, mode, "{p}");
        assert!(m.len() > 100, "{p} not replaced");
    }
    // A name of 251 characters (the longest with .csv that fits 255) is written: the
    // temporary name does not grow with it.
    let long = s.s(&format!("{}.csv", "a".repeat(247)));
    ok(&strs(&circle(&long, DEMO)));
    let names: Vec<String> = std::fs::read_dir(&s.0)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(names.iter().all(|n| !n.starts_with(".eij-")), "{names:?}");
}

// ---- silent nonsense -----------------------------------------------------------------------------

#[test]
fn doubled_or_ignored_data_is_refused() {
    let s = Scratch::new("rb-silent");
    let data = std::fs::read(common::root().join(ZX_CSV)).unwrap();
    s.write("loop/zx.csv", &data);
    std::os::unix::fs::symlink(".", s.path("loop/self")).unwrap();
    let dir = s.s("loop");
    refused(
        &s,
        &["evaluate", &dir],
        &format!("{dir}/self: cannot read: the folder lies inside itself (a symbolic-link loop)"),
    );
    std::fs::remove_file(s.path("loop/self")).unwrap();
    std::os::unix::fs::symlink("zx.csv", s.path("loop/again.csv")).unwrap();
    refused(
        &s,
        &["evaluate", &dir],
        &format!("{dir}/zx.csv: cannot read: the same file as {dir}/again.csv (each measured file counts once)"),
    );
    let f = s.write("one.csv", &data);
    refused(
        &s,
        &["evaluate", &f, &f],
        &format!("{f}: cannot read: the same file as {f} (each measured file counts once)"),
    );
    s.write("rt/zx.csv", &data);
    std::fs::create_dir(s.path("rt/rtest.toml")).unwrap();
    let rt = s.s("rt");
    refused(
        &s,
        &["evaluate", &rt],
        &format!(
            "{rt}/rtest.toml: cannot read: is a folder; the conditions file must be a TOML file"
        ),
    );
    s.write("dup/a.csv", &data);
    let cond = s.write(
        "dup/rtest.toml",
        "[[test]]\nfile = \"a.csv\"\n[[test]]\nfile = \"./a.csv\"\n",
    );
    refused(
        &s,
        &["evaluate", &s.s("dup")],
        &format!("{cond}: [[test]] #2 file: {}/./a.csv: already named by [[test]] #1 file (each file is one test)", s.s("dup")),
    );
    // A map row twice.
    let (text, last) = demo_map(&s);
    let twice = s.write("twice.csv", format!("{text}{last}\n"));
    refused(
        &s,
        &[
            "report",
            "--measured",
            ZX_CSV,
            "--map",
            &twice,
            "--out",
            &s.s("rep"),
        ],
        &format!("{twice}:4: position [1, 0, 0] mm given twice (first on line 3)"),
    );
    // A catalogue entry that would silently replace a bundled one.
    let (m, _) = with_catalogue(&s);
    s.write(
        "extra.toml",
        "[[carriage]]\nid = \"HIWIN HGH25CA ZA\"\nradial_n_per_um = 5\nreverse_radial_n_per_um = 4\n\
         lateral_n_per_um = 4\nestimated = []\nsource = \"test\"\n",
    );
    refused(
        &s,
        &["modal", "--machine", &m],
        "extra.toml: carriage[0] (HIWIN HGH25CA ZA).id: already defined in machines/catalogue/carriages.toml",
    );
}

#[test]
fn modal_validates_like_export() {
    let s = Scratch::new("rb-modal");
    for (from, to, needle) in [
        (
            "mass_kg = 450.0",
            "mass_kg = 1e300",
            "mass_kg: 1e300 is beyond 1000000 kg",
        ),
        (
            "mass_kg = 450.0",
            "mass_kg = 1e-300",
            "mass_kg: 1e-300 is below 0.001 kg",
        ),
        (
            "kp_nm_s_per_rad = 5.0",
            "kp_nm_s_per_rad = 5000.0",
            "closed loop unstable at axis y",
        ),
    ] {
        let m = s.write("m.toml", demo_text().replacen(from, to, 1));
        let modal = refused(&s, &["modal", "--machine", &m], needle);
        let export = refused(
            &s,
            &["export", "--machine", &m, "--out", &s.s("o.json")],
            needle,
        );
        assert_eq!(modal, export);
    }
}

// ---- messages ------------------------------------------------------------------------------------

#[test]
fn messages_are_short_and_blame_the_right_thing() {
    let s = Scratch::new("rb-msg");
    let m = s.write(
        "lag.toml",
        demo_text().replacen("current_lag_s = 0.0005", "current_lag_s = 0.01", 1),
    );
    refused(
        &s,
        &["export", "--machine", &m, "--out", &s.s("o.json")],
        "the current-loop lag current_lag_s = 0.01 s is long for this loop",
    );
    let m = s.write(
        "lag.toml",
        demo_text().replacen("current_lag_s = 0.0005", "current_lag_s = 1e300", 1),
    );
    let line = refused(
        &s,
        &["modal", "--machine", &m],
        &format!("{m}: axis[x].control.current_lag_s: 1e300 is beyond 0.1 s"),
    );
    assert!(line.len() < 200, "{line}");
    // A huge value in a mm column is not blamed on µm.
    let mut rows: Vec<String> = std::fs::read_to_string(common::root().join(ZX_CSV))
        .unwrap()
        .lines()
        .map(String::from)
        .collect();
    let mut cells: Vec<String> = rows[4].split(',').map(String::from).collect();
    cells[1] = "1e308".into();
    rows[4] = cells.join(",");
    let f = s.write("big.csv", rows.join("\n") + "\n");
    let line = refused(&s, &["evaluate", &f], "is implausible for an R-Test circle");
    assert!(
        !line.contains("µm") || line.contains("too large for µm"),
        "{line}"
    );
    assert!(line.len() < 200, "{line}");
    // Table values name the table.
    let t = s.write(
        "t.csv",
        "plane,direction,accel_m_s2,parameter,value_um_s2_per_m\nzx,ccw,4.5,EXZ,1e300\n",
    );
    let args = identify(&s, DEMO, &t, &[]);
    refused(
        &s,
        &strs(&args),
        &format!("{t}:2: column value_um_s2_per_m: 1e300 µm·s²/m is implausible for an EIJ"),
    );
    // A CSV reader's error names file and line once.
    let (text, last) = demo_map(&s);
    let extra = s.write("extra.csv", format!("{text}{last},7\n"));
    let line = refused(
        &s,
        &[
            "report",
            "--measured",
            ZX_CSV,
            "--map",
            &extra,
            "--out",
            &s.s("rep"),
        ],
        &format!("{extra}:4: 15 field(s), the header has 14"),
    );
    assert!(!line.contains("CSV error"), "{line}");
}

#[test]
fn verify_checks_its_own_file() {
    let s = Scratch::new("rb-verify");
    let root = common::root().display().to_string();
    let head = format!(
        "description = \"x\"\nmachine = \"{root}/{DEMO}\"\nmeasured = [\"{root}/{ZX_CSV}\"]\n"
    );
    let k = s.write(
        "k.toml",
        format!("{head}[settings]\nradius_mm = 7\n[expected.\"z.guideway_normal\"]\nvalue = 0.4\nrel_tol = 0.1\n"),
    );
    refused(
        &s,
        &["verify", &k],
        &format!("{k}: radius_mm = 7 is not allowed: must lie in (0, 3] mm"),
    );
    for tol in ["nan", "-0.1", "inf"] {
        let k = s.write(
            "k.toml",
            format!("{head}[expected.\"z.guideway_normal\"]\nvalue = 0.4\nrel_tol = {tol}\n"),
        );
        let shown = if tol == "nan" { "NaN" } else { tol };
        refused(
            &s,
            &["verify", &k],
            &format!("{k}: expected.\"z.guideway_normal\".rel_tol = {shown} is not allowed: a relative tolerance must lie in (0, 1)"),
        );
    }
}
