//! The library's front door (issue 29 item 12): what `src/lib.rs` re-exports is enough to
//! identify, read the verdict and write the identified machine file, and the file is the one
//! `eij identify` writes.

mod common;

use common::{root, Scratch, DEMO};
use eij::ident::Parameter;
use eij::{Chi2, ExportError, IdentError, Identification, Machine, Provenance, Standing};
use std::process::Command;

/// Measured paths given as `&str` (the builder takes anything that is a path): the machine
/// file written by the library is byte for byte the one `eij identify` writes for the same
/// inputs and date, and it holds the identified factors exactly.
#[test]
fn library_writes_the_machine_file_eij_identify_writes() {
    let scratch = Scratch::new("front-door");
    let cli_file = scratch.s("cli.toml");
    let out = Command::new(env!("CARGO_BIN_EXE_eij"))
        .current_dir(root())
        .env("SOURCE_DATE_EPOCH", "0")
        .args(["identify", "--quiet", "--no-design", "--out", &cli_file])
        .args(["--report", &scratch.s("cli.json")])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );

    // The working folder of integration tests is the repository root: relative paths as a
    // user at the command line would give them.
    let result = Identification::new(Machine::from_file(root().join(DEMO).as_path()).unwrap())
        .measured(["measurements/demo-vmc"])
        .run()
        .unwrap();
    // The provenance the command line records: the machine file and every data file read.
    let mut files: Vec<String> = ["pos-a", "pos-b"]
        .iter()
        .flat_map(|d| std::fs::read_dir(root().join("measurements/demo-vmc").join(d)).unwrap())
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "csv"))
        .map(|p| p.strip_prefix(root()).unwrap().display().to_string())
        .collect();
    files.sort();
    assert_eq!(files.len(), 36);
    let mut prov = Provenance::now(DEMO, &files).unwrap();
    prov.date = "1970-01-01T00:00:00Z".into();
    let lib_file = scratch.path("lib.toml");
    result.write_machine_file(&lib_file, &prov).unwrap();
    let lib_text = std::fs::read_to_string(&lib_file).unwrap();
    assert_eq!(lib_text, std::fs::read_to_string(&cli_file).unwrap());
    assert_eq!(
        lib_text,
        eij::machine_toml(&problem(), &result, &prov).unwrap()
    );

    let identified = Machine::from_file(&lib_file).unwrap();
    assert_eq!(identified.name(), "demo-vmc-identified");
    for p in &result.parameters {
        let param = Parameter::parse(&p.name, &identified).unwrap();
        assert_eq!(param.get(&identified), p.value, "{}", p.name);
    }
}

/// The problem the front door's identification ran on (for the free function's signature).
fn problem() -> eij::ident::Problem {
    Identification::new(Machine::from_file(root().join(DEMO).as_path()).unwrap())
        .measured([root().join("measurements/demo-vmc")])
        .problem()
        .unwrap()
}

/// The verdict the front door gives is the χ² test of the result's own s and degrees of
/// freedom, and each factor's standing follows its relative standard error.
#[test]
fn verdict_follows_the_fit() {
    let result = Identification::new(common::demo())
        .parameters(["z.guideway_normal", "z.guideway_lateral"])
        .measured([root().join("measurements/demo-vmc/pos-a")])
        .run()
        .unwrap();
    let chi2 = result.chi2();
    assert_eq!(
        chi2,
        Chi2::new(result.residual_std, result.degrees_of_freedom)
    );
    assert_eq!(chi2.passed, result.residual_std <= chi2.s_limit);
    assert!(chi2.dof > 0 && chi2.dof < result.residuals);
    // The bands of the standing (docs/identification.md): ≤ 10 % determined, ≤ 50 % loose,
    // ≤ 100 % weak, above: not determined.
    for p in &result.parameters {
        let rel = p.std_err.unwrap() / p.value;
        let (r, band) = match p.standing() {
            Standing::Determined { rel } => (rel, 0.0..=0.10),
            Standing::Loose { rel } => (rel, 0.10..=0.50),
            Standing::Weak { rel } => (rel, 0.50..=1.0),
            other => panic!("{}: {other:?} with σ/value {rel}", p.name),
        };
        assert_eq!(r, rel, "{}", p.name);
        assert!(band.contains(&rel), "{}: {rel} not in {band:?}", p.name);
    }
}

/// A fit the identification refuses (here: stopped after one iteration, not converged) is not
/// written: the error says why and no file appears.
#[test]
fn a_refused_fit_is_not_written() {
    let result = Identification::new(common::demo())
        .measured([root().join("measurements/demo-vmc/pos-a")])
        .max_iters(1)
        .run()
        .unwrap();
    assert!(
        matches!(
            result.refusal,
            Some(IdentError::NotConverged { iterations: 1 })
        ),
        "{:?}",
        result.refusal
    );
    let scratch = Scratch::new("front-door-refused");
    let path = scratch.path("refused.toml");
    let prov = Provenance::now(DEMO, ["measurements/demo-vmc/pos-a"]).unwrap();
    match result.write_machine_file(&path, &prov) {
        Err(ExportError::Refused(e)) => {
            assert!(matches!(*e, IdentError::NotConverged { .. }), "{e}")
        }
        other => panic!("{other:?}"),
    }
    assert!(!path.exists());
}
