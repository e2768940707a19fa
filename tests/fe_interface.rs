//! `interface_modes` in a machine file (docs/machine-file.md): the FE reference machine
//! (`machines/reference/column-mill-fe.toml`, a solid column with 19 attachment stations, 114
//! interface DOFs) with its interface reduced keeps far fewer elastic coordinates, and its
//! free-free frequencies below half `cutoff_hz` stay within 0.1 % of the full FE model's
//! (issue 27's tolerance), the full model's taken from a dense eigensolution of the exported
//! M and K written here. Bad values are one line naming the key.

mod fe_common;

use eij::fe::mtx;
use eij::machine::Machine;
use fe_common::{dense, generalized_eigenvalues, hz};

const FE: &str = "machines/reference/column-mill-fe.toml";
const CUTOFF_HZ: f64 = 2000.0;
const INTERFACE_MODES: usize = 12;

fn root() -> &'static std::path::Path {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The FE reference machine with `modes = 24` replaced by `with`.
fn machine(with: &str) -> Result<Machine, String> {
    let path = root().join(FE);
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains("modes = 24\n"));
    Machine::from_toml_str(
        &text.replacen("modes = 24\n", &format!("{with}\n"), 1),
        &path.display().to_string(),
    )
    .map_err(|e| e.to_string())
}

fn column(m: &Machine) -> usize {
    m.bodies().iter().position(|b| b.name == "column").unwrap()
}

/// The full FE model's elastic free-free frequencies, Hz (dense, the 6 rigid-body modes left
/// out).
fn full_frequencies_hz() -> Vec<f64> {
    let dir = root().join("machines/reference/fe");
    let read = |f: &str| {
        let p = dir.join(f);
        dense(&mtx::read_symmetric(&p, &p.display().to_string()).unwrap())
    };
    let (m, k) = (read("column-solid-M.mtx"), read("column-solid-K.mtx"));
    generalized_eigenvalues(&k, &m)[6..]
        .iter()
        .map(|l| hz(*l))
        .collect()
}

#[test]
fn a_reduced_interface_keeps_few_coordinates_and_the_low_modes() {
    let m = machine(&format!(
        "cutoff_hz = {CUTOFF_HZ}\ninterface_modes = {INTERFACE_MODES}"
    ))
    .unwrap();
    let s = m.fe_summary(column(&m)).unwrap().unwrap();
    assert_eq!(s.interface_dofs, 114);
    assert_eq!(s.interface_coordinates, 6 + INTERFACE_MODES);
    // Elastic coordinates: the interface coordinates and the fixed-interface modes, less the
    // six rigid-body motions.
    assert_eq!(
        s.free_frequencies_hz.len(),
        INTERFACE_MODES + s.modes,
        "{s:?}"
    );
    let full = full_frequencies_hz();
    let mut compared = 0;
    for (i, (r, f)) in s.free_frequencies_hz.iter().zip(&full).enumerate() {
        // A Rayleigh–Ritz projection never lies below the full model.
        assert!(*r >= f * (1.0 - 1e-9), "mode {}: {r} below {f}", i + 1);
        if *f < 0.5 * CUTOFF_HZ {
            assert!(
                (r - f) / f <= 1e-3,
                "mode {}: {r:.3} Hz vs the full model's {f:.3} Hz",
                i + 1
            );
            compared += 1;
        }
    }
    let below = full.iter().filter(|f| **f < 0.5 * CUTOFF_HZ).count();
    assert_eq!(compared, below);
    assert!(
        compared >= 3,
        "{compared} modes below {} Hz",
        0.5 * CUTOFF_HZ
    );
}

#[test]
fn bad_interface_modes_are_one_line_naming_the_key() {
    for (with, needles) in [
        (
            "modes = 24\ninterface_modes = 0",
            &["body[column].fe.interface_modes", "0 must be in 1 … 1000"][..],
        ),
        (
            "modes = 24\ninterface_modes = 5000",
            &[
                "body[column].fe.interface_modes",
                "5000 must be in 1 … 1000",
            ][..],
        ),
        (
            "modes = 24\ninterface_modes = -3",
            &["column-mill-fe.toml: line ", "invalid value: integer `-3`"][..],
        ),
        (
            "modes = 24\ninterface_modes = 2.5",
            &["column-mill-fe.toml", "invalid type"][..],
        ),
    ] {
        let e = machine(with).unwrap_err();
        assert!(!e.contains('\n'), "{e}");
        for n in needles {
            assert!(e.contains(n), "{n} not in: {e}");
        }
    }
}
