//! Issue 27 item 6 through the binary: every bad FE input of a `[body.fe]` machine
//! (`machines/reference/column-mill-fe.toml`, its files copied and spoiled one at a time) gives
//! one line naming the machine file and key, the FE file and line where there is one, and what
//! is wrong; a non-zero exit, and no output written.

mod common;

use common::{one_line_error, root, Scratch};

const FILES: [&str; 4] = [
    "column-solid-M.mtx",
    "column-solid-K.mtx",
    "column-solid-dofs.csv",
    "column-solid-nodes.csv",
];

fn original(name: &str) -> String {
    std::fs::read_to_string(root().join("machines/reference/fe").join(name)).unwrap()
}

/// The FE machine in a scratch folder with `file` replaced by `text` (the others as committed),
/// the machine file changed by `edit`; runs `eij simulate circle` on it and checks the refusal.
fn refused(tag: &str, file: &str, text: String, edit: (&str, &str), needles: &[&str]) {
    let s = Scratch::new(tag);
    for f in FILES {
        s.write(
            &format!("fe/{f}"),
            if f == file { text.clone() } else { original(f) },
        );
    }
    let machine =
        std::fs::read_to_string(root().join("machines/reference/column-mill-fe.toml")).unwrap();
    assert!(machine.contains(edit.0), "{}", edit.0);
    let m = s.write("m.toml", machine.replacen(edit.0, edit.1, 1));
    let out = s.s("circle.csv");
    let args = common::circle_args(&m, &out);
    let run = common::eij(&args.iter().map(String::as_str).collect::<Vec<_>>());
    let line = one_line_error(&run, needles);
    assert!(line.contains("m.toml: body[column]"), "{line}");
    assert!(!s.path("circle.csv").exists(), "{line}");
    let left: Vec<_> = std::fs::read_dir(&s.0)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    assert_eq!(left.len(), 2, "nothing but the inputs: {left:?}");
}

/// `text`'s lines with line `n` (1-based) replaced.
fn line_replaced(text: &str, n: usize, with: &str) -> String {
    let mut lines: Vec<&str> = text.lines().collect();
    lines[n - 1] = with;
    lines.join("\n") + "\n"
}

const K: &str = "column-solid-K.mtx";
const M: &str = "column-solid-M.mtx";
const NONE: (&str, &str) = ("modes = 24", "modes = 24");

#[test]
fn matrix_market_faults_name_the_file_and_line() {
    let k = original(K);
    // Line 5 is the size line, line 6 the first entry `1 1 v`.
    let first = k.lines().nth(5).unwrap().to_string();
    let value = first.split_whitespace().nth(2).unwrap().to_string();
    for (tag, text, needles) in [
        (
            "square",
            line_replaced(&k, 5, "432 431 11466"),
            vec!["column-solid-K.mtx: line 5", "432×431, not square"],
        ),
        (
            "zero",
            line_replaced(&k, 6, &format!("0 1 {value}")),
            vec!["column-solid-K.mtx: line 6", "row index 0", "start at 1"],
        ),
        (
            "nan",
            line_replaced(&k, 6, "1 1 NaN"),
            vec!["column-solid-K.mtx: line 6", "NaN is not finite"],
        ),
        (
            "inf",
            line_replaced(&k, 6, "1 1 inf"),
            vec!["column-solid-K.mtx: line 6", "not finite"],
        ),
        (
            "not-mtx",
            original("column-solid-dofs.csv"),
            vec!["column-solid-K.mtx: line 1", "not a Matrix Market file"],
        ),
    ] {
        refused(&format!("fe-bad-{tag}"), K, text, NONE, &needles);
    }
    // A `general` file whose (i, j) and (j, i) differ: not symmetric.
    let mut general = k.replacen("coordinate real symmetric", "coordinate real general", 1);
    general = line_replaced(&general, 5, "432 432 11468");
    general.push_str("432 1 1.0\n1 432 2.0\n");
    refused(
        "fe-bad-asym",
        K,
        general,
        NONE,
        &["column-solid-K.mtx", "not symmetric"],
    );
}

#[test]
fn model_faults_name_the_file_and_what() {
    // A spring to ground on the first DOF: fewer than 6 rigid-body modes.
    let k = original(K);
    let first = k.lines().nth(5).unwrap().to_string();
    let value: f64 = first.split_whitespace().nth(2).unwrap().parse().unwrap();
    refused(
        "fe-bad-ground",
        K,
        line_replaced(&k, 6, &format!("1 1 {:e}", 2.0 * value)),
        NONE,
        &[
            "column-solid-K.mtx",
            "a rigid-body translation x produces elastic forces",
            "fewer than 6 rigid-body modes",
        ],
    );
    // A negative mass on the diagonal: not positive semi-definite.
    let m = original(M);
    let mass = m
        .lines()
        .nth(5)
        .unwrap()
        .split_whitespace()
        .nth(2)
        .unwrap()
        .to_string();
    refused(
        "fe-bad-mass",
        M,
        line_replaced(&m, 6, &format!("1 1 -{mass}")),
        NONE,
        &[
            "column-solid-M.mtx",
            "(1, 1)",
            "is negative",
            "positive semi-definite",
        ],
    );
    // The DOF map one row short, and naming a node the node file does not have.
    let dofs = original("column-solid-dofs.csv");
    let short: String = dofs.lines().take(432).map(|l| format!("{l}\n")).collect();
    refused(
        "fe-bad-short",
        "column-solid-dofs.csv",
        short,
        NONE,
        &["column-solid-dofs.csv", "431 DOF rows", "432×432"],
    );
    refused(
        "fe-bad-node",
        "column-solid-dofs.csv",
        line_replaced(&dofs, 2, "9999,ux"),
        NONE,
        &[
            "column-solid-dofs.csv: line 2",
            "node 9999 is not in the node file",
        ],
    );
}

#[test]
fn attachments_the_model_cannot_take_name_the_point() {
    let k = original(K);
    // An RBE3 radius that catches fewer than three nodes around a point.
    refused(
        "fe-bad-radius",
        K,
        k.clone(),
        ("attach_radius_m = 0.2", "attach_radius_m = 0.01"),
        &[
            "body[column].fe",
            "fewer than 3 non-collinear nodes within attach_radius_m = 0.01 m",
            "nearest node",
        ],
    );
    // The Z scale's reading head 3.4 m in front of the column: no node near its travel line.
    refused(
        "fe-bad-far-line",
        K,
        k.clone(),
        ("scale_m = [0.2, 0.4, 0.45]", "scale_m = [0.2, -3.0, 0.45]"),
        &[
            "body[column].fe",
            "attachment z.scale",
            "no node within 0.2",
        ],
    );
    // The Y nut on the column 4.2 m behind it: beyond the body's extent (1.7 m).
    refused(
        "fe-bad-far",
        K,
        k,
        ("nut_m = [0.0, 0.55, -0.15]", "nut_m = [0.0, 5.0, -0.15]"),
        &[
            "body[column].fe",
            "attachment y.nut",
            "beyond the body's extent",
        ],
    );
}
