//! Headers as shops write them (docs/measurement-files.md, section 2): metadata lines before the
//! header row (the header found by the column map), and a units row under it (`[ms]`, `[mm]`,
//! `(µm)`) read as the units where `[columns]` states none and checked against `[columns]` where
//! it does. Each shop file is made here from the demo's contract file (time in ms, R-Test
//! columns in µm, decimal comma) and must evaluate to the contract file's EIJ; a units row that
//! contradicts `[columns]`, names no unit eij reads, or a unit of the wrong kind is refused in
//! one line naming file, line and column.

mod common;

use std::collections::BTreeMap;

use common::traces::demo_test;
use common::{one_line_error, Scratch};
use eij::axes::Eij;
use eij::measured::inputs::expand_tests;
use eij::measured::suite::{evaluate_tests, SuiteOptions};

const DEMO: &str = "pos-a/zx_ccw_5.csv";

/// The demo test as a shop export: two metadata lines, a German header, the units row `units`
/// (time ms, internal mm, external µm, and a temperature column eij does not read).
fn shop_file(units: &str) -> String {
    let d = demo_test(DEMO);
    let mut s =
        String::from("Messung;R-Test Kreisform;Maschine DMU 50\nDatum;28.11.2026;Bediener;KS\n");
    s.push_str("Zeit;X;Y;Z;XR;YR;ZR;Temp\n");
    s.push_str(units);
    s.push('\n');
    for i in 0..d.t_s.len() {
        let cells = [
            d.t_s[i] * 1e3,
            d.int[0][i],
            d.int[1][i],
            d.int[2][i],
            d.ext[0][i] * 1e3,
            d.ext[1][i] * 1e3,
            d.ext[2][i] * 1e3,
            20.5,
        ];
        let row: Vec<String> = cells
            .iter()
            .map(|v| format!("{v}").replace('.', ","))
            .collect();
        s.push_str(&row.join(";"));
        s.push('\n');
    }
    s
}

const NAMES: &str = "t_s = \"Zeit\"\nx_int_mm = \"X\"\ny_int_mm = \"Y\"\nz_int_mm = \"Z\"\nx_ext_mm = \"XR\"\ny_ext_mm = \"YR\"\nz_ext_mm = \"ZR\"\n";

const UNITS: &str = "[ms];[mm];[mm];[mm];(µm);(µm);(µm);[°C]";

fn eij_of(folder: &std::path::Path) -> BTreeMap<Eij, f64> {
    let tests = expand_tests(&[folder.to_path_buf()]).unwrap();
    let suite = evaluate_tests(&tests, &SuiteOptions::default()).unwrap();
    suite.tests[0].result.eij.value_map()
}

fn write(d: &Scratch, folder: &str, csv: &str, columns: &str) {
    d.write(&format!("{folder}/shop.csv"), csv);
    d.write(
        &format!("{folder}/rtest.toml"),
        format!("radius_mm = 2.0\n[columns]\n{columns}"),
    );
}

/// With names only in `[columns]`, the units row gives the units; with units stated alike, it
/// agrees; either way the EIJ are those of the contract file (the same numbers, written in other
/// units: to 1e-9 µm·s²/m).
#[test]
fn a_units_row_gives_the_units() {
    let d = Scratch::new("headers-units");
    d.write(
        "contract/demo.csv",
        std::fs::read(common::root().join("measurements/demo-vmc").join(DEMO)).unwrap(),
    );
    d.write("contract/rtest.toml", "radius_mm = 2.0\n");
    let truth = eij_of(&d.path("contract"));
    write(&d, "names", &shop_file(UNITS), NAMES);
    let stated = "t_s = { name = \"Zeit\", unit = \"ms\" }\nx_int_mm = { name = \"X\", unit = \"mm\" }\ny_int_mm = \"Y\"\nz_int_mm = \"Z\"\nx_ext_mm = { name = \"XR\", unit = \"um\" }\ny_ext_mm = { name = \"YR\", unit = \"µm\" }\nz_ext_mm = { name = \"ZR\", unit = \"um\" }\n";
    write(&d, "stated", &shop_file(UNITS), stated);
    // Units written bare and with empty cells where the column's unit is the contract's.
    write(&d, "bare", &shop_file("ms;;;;um;um;um;°C"), NAMES);
    for folder in ["names", "stated", "bare"] {
        let e = eij_of(&d.path(folder));
        assert_eq!(e.len(), truth.len());
        for (p, v) in &truth {
            assert!(
                (e[p] - v).abs() < 1e-9,
                "{folder} {p}: {} vs contract {v}",
                e[p]
            );
        }
    }
}

/// The contract names with a units row in seconds and millimetres, and no `rtest.toml`: read.
#[test]
fn contract_names_with_a_units_row_are_read() {
    let d = Scratch::new("headers-contract");
    let text =
        std::fs::read_to_string(common::root().join("measurements/demo-vmc").join(DEMO)).unwrap();
    let (header, body) = text.split_once('\n').unwrap();
    d.write("c/demo.csv", format!("# exported by the R-Test software\n{header}\n[s],[mm],[mm],[mm],[mm],[mm],[mm]\n{body}"));
    d.write("c/rtest.toml", "radius_mm = 2.0\n");
    d.write("plain/demo.csv", &text);
    d.write("plain/rtest.toml", "radius_mm = 2.0\n");
    assert_eq!(eij_of(&d.path("c")), eij_of(&d.path("plain")));
}

/// A units row that contradicts `[columns]`, a unit eij does not read, a unit of length for time:
/// one line naming file, line 4 (the units row) and the column.
#[test]
fn a_units_row_that_disagrees_is_refused_in_one_line() {
    let d = Scratch::new("headers-bad");
    let conflict = NAMES.replace("t_s = \"Zeit\"", "t_s = { name = \"Zeit\", unit = \"s\" }");
    let cases = [
        (
            "conflict",
            UNITS.to_string(),
            conflict,
            "column Zeit: the units row says ms, rtest.toml [columns] says s",
        ),
        (
            "unknown",
            UNITS.replace("(µm);(µm);(µm)", "(µm);(inch);(µm)"),
            NAMES.to_string(),
            "column YR: the units row gives 'inch', not a unit eij reads",
        ),
        (
            "kind",
            UNITS.replace("[ms]", "[mm]"),
            NAMES.to_string(),
            "column Zeit: the units row gives 'mm', no unit of time",
        ),
    ];
    for (folder, units, columns, message) in cases {
        write(&d, folder, &shop_file(&units), &columns);
        let out = common::eij(&["evaluate", &d.s(folder)]);
        let file = d.s(&format!("{folder}/shop.csv"));
        one_line_error(&out, &[&format!("{file}:4: {message}")]);
    }
}
