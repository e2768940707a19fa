//! The one harness of the integration tests: paths to the bundled files, scratch folders,
//! running the `eij` binary and checking the one-line error contract, and synthetic R-Test
//! series with known EIJ ([`synth`]). Every test file uses it with `mod common;`.
#![allow(dead_code)]

pub mod bad_input;
pub mod circle_terms;
pub mod diagnosis_checks;
pub mod diagnosis_demo;
pub mod imperfect;
pub mod mutation;
pub mod random_machine;
pub mod shop;
pub mod synth;
pub mod traces;

use eij::machine::Machine;
use eij::mbs::Model;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The bundled demo machine (relative to the repository root).
pub const DEMO: &str = "machines/demo-vmc.toml";
/// One R-Test file of the bundled demo measurements.
pub const ZX_CSV: &str = "measurements/demo-vmc/pos-a/zx_ccw_5.csv";
/// The contract columns of an R-Test series, in the documented order.
pub const HEADER: &str = "t_s,x_int_mm,y_int_mm,z_int_mm,x_ext_mm,y_ext_mm,z_ext_mm";

/// The repository root.
pub fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// A machine file below `machines/` (e.g. `demo-vmc.toml`, `reference/single-axis.toml`).
pub fn machine(name: &str) -> Machine {
    Machine::from_file(&root().join("machines").join(name)).unwrap()
}

/// The demo machine.
pub fn demo() -> Machine {
    machine("demo-vmc.toml")
}

/// The demo machine's default parameters (guideway factors) identified from `tests`, without
/// the ranking of candidate tests: the problem and its result.
pub fn fit_demo(
    tests: Vec<eij::ident::TestCase>,
) -> (eij::ident::Problem, eij::ident::IdentResult) {
    let base = demo();
    let settings = eij::ident::Settings {
        design: false,
        ..Default::default()
    };
    let params = eij::ident::Parameter::default_set(&base);
    let problem = eij::ident::Problem::new(base, params, tests, settings).unwrap();
    let result = eij::ident::identify(&problem, None).unwrap();
    (problem, result)
}

/// The demo machine file's text (for variations of it).
pub fn demo_text() -> String {
    std::fs::read_to_string(root().join(DEMO)).unwrap()
}

/// The rigid motion of every free body together, as a small rotation `rot` about the point `o`
/// plus a translation `tr` (rotors held relative to their carriers; elastic coordinates zero).
pub fn whole_machine_motion(
    machine: &Machine,
    model: &Model,
    pose: &[f64],
    tr: nalgebra::Vector3<f64>,
    rot: nalgebra::Vector3<f64>,
    o: nalgebra::Vector3<f64>,
) -> nalgebra::DVector<f64> {
    let mut v = nalgebra::DVector::zeros(model.n_dof());
    for (b, body) in machine.bodies().iter().enumerate() {
        let Some(i) = model.body_dofs[b] else {
            continue;
        };
        // The body's COG at this pose: shifted by every axis that carries it.
        let mut c = body.cog_m;
        for (ai, a) in machine.axes().iter().enumerate() {
            if machine.is_carried_by(b, ai) {
                c += a.direction() * (a.side.sign() * (pose[ai] - a.reference_m));
            }
        }
        // Rigid coordinates at the COG (elastic ones, if any, stay zero).
        let u = tr + rot.cross(&(c - o));
        for d in 0..3 {
            v[i + d] = u[d];
            v[i + 3 + d] = rot[d];
        }
    }
    v
}

/// Asserts that the motion `v` (m, rad) is free: no spring force (relative 1e-12), no
/// deviation at the R-Test and no scale reading (below `tol_m`).
pub fn assert_motion_free(model: &Model, v: &nalgebra::DVector<f64>, tol_m: f64) {
    let force = (&model.stiffness * v).norm();
    assert!(
        force < 1e-12 * model.stiffness.norm() * v.norm(),
        "{force} N"
    );
    assert!((&model.tcp * v).norm() < tol_m, "a deviation");
    for p in &model.axes {
        assert!(p.scale.dot(v).abs() < tol_m, "a scale reading");
    }
}

/// The simulated EIJ of one test on one machine (harmonic, default settings).
pub fn one_eij(machine: &Machine, test: eij::predict::CircleTest) -> eij::predict::EijMap {
    let settings = eij::predict::SimSettings::default();
    eij::predict::simulated_eij(std::slice::from_ref(machine), &[test], &settings)
        .unwrap()
        .remove(0)
        .remove(0)
}

/// A scratch folder, emptied on creation and removed on drop.
pub struct Scratch(pub PathBuf);

impl Scratch {
    /// `eij-<tag>-<process id>` in the temporary folder.
    pub fn new(tag: &str) -> Self {
        let d = std::env::temp_dir().join(format!("eij-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        Scratch(d)
    }

    /// A path inside the folder.
    pub fn path(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }

    /// A path inside the folder, as text (for command lines).
    pub fn s(&self, name: &str) -> String {
        self.path(name).display().to_string()
    }

    /// Writes a file (parents created) and returns its path as text.
    pub fn write(&self, name: &str, text: impl AsRef<[u8]>) -> String {
        let p = self.path(name);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(&p, text).unwrap();
        p.display().to_string()
    }

    /// Every entry below the folder (hidden temporary files included), with its contents (a
    /// symbolic link: its target; a FIFO, device or socket: its kind, never read).
    pub fn snapshot(&self) -> BTreeSet<(PathBuf, Vec<u8>)> {
        fn walk(dir: &Path, out: &mut BTreeSet<(PathBuf, Vec<u8>)>) {
            for e in std::fs::read_dir(dir).unwrap() {
                let p = e.unwrap().path();
                let t = std::fs::symlink_metadata(&p).unwrap().file_type();
                if t.is_symlink() {
                    let target = std::fs::read_link(&p).unwrap();
                    out.insert((p, format!("link {}", target.display()).into_bytes()));
                } else if t.is_dir() {
                    out.insert((p.clone(), Vec::new()));
                    walk(&p, out);
                } else if t.is_file() {
                    out.insert((p.clone(), std::fs::read(&p).unwrap()));
                } else {
                    out.insert((p, format!("special {t:?}").into_bytes()));
                }
            }
        }
        let mut out = BTreeSet::new();
        walk(&self.0, &mut out);
        out
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Runs `eij args…` in the repository root.
pub fn eij(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_eij"))
        .current_dir(root())
        .args(args)
        .output()
        .expect("run eij")
}

/// Checks a refused command: non-zero exit, exactly one line `eij: error: …` on standard error
/// holding every needle, no panic. Returns the line.
pub fn one_line_error(out: &Output, needles: &[&str]) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success(), "succeeded: {stderr}");
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 1, "stderr not one line:\n{stderr}");
    let line = lines[0];
    assert!(line.starts_with("eij: error: "), "{line}");
    assert!(!line.contains("panicked"), "{line}");
    for n in needles {
        assert!(line.contains(n), "'{n}' not in: {line}");
    }
    line.to_string()
}

/// An error's message followed by its causes, `a: b: c` (as the command line prints it).
pub fn chain(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut source = e.source();
    while let Some(s) = source {
        text.push_str(": ");
        text.push_str(&s.to_string());
        source = s.source();
    }
    text
}

/// `(name, identified, std_err)` of every parameter of an identify report (JSON).
pub fn identified(report: &serde_json::Value) -> Vec<(String, f64, f64)> {
    report["parameters"]
        .as_array()
        .expect("parameters")
        .iter()
        .map(|p| {
            (
                p["name"].as_str().unwrap_or_default().to_string(),
                p["identified"].as_f64().unwrap_or(f64::NAN),
                p["std_err"].as_f64().unwrap_or(f64::NAN),
            )
        })
        .collect()
}

/// What a run of the binary gave, as text.
pub struct Run {
    /// Exit status 0.
    pub ok: bool,
    /// Standard output.
    pub stdout: String,
    /// Standard error.
    pub stderr: String,
}

/// Runs `eij args…` in the repository root and returns its outputs as text.
pub fn run(args: &[&str]) -> Run {
    let out = eij(args);
    Run {
        ok: out.status.success(),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}

/// `eij simulate circle` of the zx circle r = 2 mm, 5 m/s², ccw on `machine`, written to `out`:
/// the arguments, for tests that add their own options.
pub fn circle_args(machine: &str, out: &str) -> Vec<String> {
    [
        "simulate",
        "circle",
        "--machine",
        machine,
        "--plane",
        "zx",
        "--radius-mm",
        "2",
        "--accel-m-s2",
        "5",
        "--direction",
        "ccw",
        "--out",
        out,
    ]
    .map(String::from)
    .to_vec()
}

/// `eij map` of plane zx at 5 m/s² on three points along x (0, 1, 2 mm) of `machine`, written
/// to `out`: the arguments, for tests that add their own options.
pub fn map_args(machine: &str, out: &str) -> Vec<String> {
    [
        "map",
        "--machine",
        machine,
        "--plane",
        "zx",
        "--accel-m-s2",
        "5",
        "--grid",
        "x=0:1:2",
        "--out",
        out,
    ]
    .map(String::from)
    .to_vec()
}

/// `eij identify` of the one bundled zx test for `z.guideway_normal` alone (fast, no ranking of
/// candidate tests), writing `out` and `report`: the arguments, for tests that add their own.
pub fn identify_args(out: &str, report: &str) -> Vec<String> {
    [
        "identify",
        "--machine",
        DEMO,
        "--measured",
        ZX_CSV,
        "--param",
        "z.guideway_normal",
        "--no-design",
        "--out",
        out,
        "--report",
        report,
    ]
    .map(String::from)
    .to_vec()
}
