//! The shop folder spoiled (docs/bad-inputs.md rows 204–219): three of its tests (xy cw 2,
//! xy ccw 2, yz cw 2 m/s²; TNCscope traces, R-Test files with a metadata line and a units row,
//! one `[[pairing]]`, written by `tests/common/shop.rs`), one thing wrong per variant; each
//! is refused with one line naming the file and the line or key, before any result is
//! written. Files a shop writes differently but correctly (Latin-1 `µm`, UTF-16 with a
//! byte-order mark, English channel names, blocks closed by `%`) are read alike.

mod common;

use common::shop;
use common::{one_line_error, root, Scratch};
use eij::measured::inputs::expand_tests;
use eij::measured::suite::{evaluate_tests, Suite, SuiteOptions};

/// The tests of the shop folder used here (0-based, recording order).
const PICK: [usize; 3] = [0, 3, 6];

/// The files of the picked tests and the shop folder's `rtest.toml`.
fn shop_files() -> Vec<(String, Vec<u8>)> {
    let all = shop::files(&root().join("measurements/demo-vmc/pos-a"));
    let keep: Vec<String> = PICK
        .iter()
        .flat_map(|&k| [format!("cnc/TRACE_{:02}.sco", k + 1), shop::rtest_name(k)])
        .collect();
    all.into_iter()
        .filter(|(n, _)| n == "rtest.toml" || keep.contains(n))
        .collect()
}

fn evaluate(dir: &std::path::Path) -> Result<Suite, String> {
    let tests = expand_tests(&[dir.to_path_buf()]).map_err(|e| e.to_string())?;
    evaluate_tests(&tests, &SuiteOptions::default()).map_err(|e| e.to_string())
}

/// The text of a file of `files`.
fn text(files: &[(String, Vec<u8>)], name: &str) -> String {
    let (_, b) = files.iter().find(|(n, _)| n == name).expect(name);
    String::from_utf8(b.clone()).unwrap()
}

/// The 1-based line number of the first line of `text` starting with `prefix`.
fn line_of(text: &str, prefix: &str) -> usize {
    text.lines()
        .position(|l| l.starts_with(prefix))
        .expect(prefix)
        + 1
}

#[test]
fn every_spoiled_shop_folder_is_refused_in_one_line() {
    let d = Scratch::new("shop-bad");
    let files = shop_files();
    let toml = text(&files, "rtest.toml");
    let (t1, t2) = ("cnc/TRACE_01.sco", "cnc/TRACE_04.sco");
    let (r1, r2, r3) = (
        shop::rtest_name(0),
        shop::rtest_name(3),
        shop::rtest_name(6),
    );
    // Each variant: folder, files replaced (None: removed), needles of the one line.
    type Edit = Vec<(String, Option<Vec<u8>>)>;
    let set = |name: &str, body: String| (name.to_string(), Some(body.into_bytes()));
    let gone = |name: &str| (name.to_string(), None);
    let trace = text(&files, t2);
    let data = line_of(&trace, "%[DATA]");
    // Cut in the middle of row 500 of the data.
    let cut_at: usize = trace
        .lines()
        .take(data + 499)
        .map(|l| l.len() + 1)
        .sum::<usize>()
        + 30;
    // The last 100 rows gone (cut at a row's end): %COUNT says more.
    let short: String = {
        let lines: Vec<&str> = trace.lines().collect();
        lines[..lines.len() - 100].join("\n") + "\n"
    };
    let probe = text(&files, &r1);
    let variants: Vec<(&str, Edit, Vec<String>)> = vec![
        (
            "counts",
            vec![gone(&r3)],
            vec![
                "counts/rtest.toml: [[pairing]] #1 external: 3 internal files match 'cnc/*.sco' but 2 external files 'rtest/*.csv': every test needs both".into(),
            ],
        ),
        (
            "claim",
            vec![
                gone(t1),
                set(
                    &format!("cnc/{}", r1.trim_start_matches("rtest/").replace(".csv", ".sco")),
                    text(&files, t1),
                ),
                set(
                    &format!("cnc/{}", r1.trim_start_matches("rtest/").replace(".csv", ".txt")),
                    text(&files, t1),
                ),
                set("rtest.toml", toml.replace("cnc/*.sco", "cnc/*")),
            ],
            vec![
                "[[pairing]] #1 internal:".into(),
                " both claim ".into(),
                format!("{r1} as their partner"),
            ],
        ),
        (
            "nokey",
            vec![set(
                "rtest.toml",
                toml.replace("internal_coordinates = \"absolute\"\n", ""),
            )],
            vec![
                format!("nokey/{t1}: internal_coordinates: the internal readings lie about [150"),
                "write internal_coordinates = \"absolute\"".into(),
            ],
        ),
        (
            "cut",
            vec![set(t2, trace[..cut_at].to_string())],
            vec![format!("cut/{t2}:{}: row cut off", data + 500)],
        ),
        (
            "units",
            vec![set(
                "rtest.toml",
                toml.replace("t_s = \"Zeit\"", "t_s = { name = \"Zeit\", unit = \"s\" }"),
            )],
            vec![format!(
                "units/{r1}:3: column Zeit: the units row says ms, rtest.toml [columns] says s"
            )],
        ),
        (
            "order",
            vec![
                set(&r1, text(&files, &r2)),
                set(&r2, text(&files, &r1)),
            ],
            vec![
                format!("order/{t1} + "),
                "not one test: the internal recording is a xy cw circle".into(),
                "the external one a xy ccw circle".into(),
                "paired in recording order".into(),
            ],
        ),
        (
            "nomatch",
            vec![set("rtest.toml", toml.replace("cnc/*.sco", "cnc/*.csv"))],
            vec!["rtest.toml: [[pairing]] #1 internal: 'cnc/*.csv' matches no file".into()],
        ),
        (
            "swapped",
            vec![set(
                "rtest.toml",
                toml.replace("internal = \"cnc/*.sco\"", "internal = \"@\"")
                    .replace("external = \"rtest/*.csv\"", "external = \"cnc/*.sco\"")
                    .replace("internal = \"@\"", "internal = \"rtest/*.csv\""),
            )],
            vec![
                "swapped/rtest.toml: [[pairing]] #1 external: 'cnc/*.sco' matches ".into(),
                format!("swapped/{t1}, a controller trace (the axes' own readings): traces belong to the internal pattern, the R-Test files to the external one (the patterns swapped?)"),
            ],
        ),
        (
            "centre",
            vec![set(
                "rtest.toml",
                toml.replace("position_mm = [150.0, -100.0, 0.0]", "position_mm = [0.0, 0.0, -200.0]"),
            )],
            vec![
                format!("centre/{t1}: internal_coordinates: \"absolute\": the internal readings lie about [150"),
                "away from the circle centre".into(),
            ],
        ),
        (
            "count",
            vec![set(t2, short)],
            vec![format!(
                "count/{t2}:{}: %COUNT=",
                line_of(&trace, "%COUNT=")
            ), "of channel 's ist/X', but its column holds".into()],
        ),
        (
            "header",
            vec![set(&r1, probe.replacen("Zeit;X;Y;Z", "Time;X;Y;Z", 1))],
            vec![format!("header/{r1}"), "missing column(s) Zeit (for t_s)".into()],
        ),
        (
            "rcut",
            vec![set(&r2, {
                let p = text(&files, &r2);
                let at: usize = p.lines().take(599).map(|l| l.len() + 1).sum::<usize>() + 7;
                p[..at].to_string()
            })],
            vec![format!("rcut/{r2}:600:")],
        ),
        (
            "empty",
            vec![set(t1, String::new())],
            vec![format!("empty/{t1}: empty file")],
        ),
        (
            "both",
            vec![
                set("cnc/notes.csv", text(&files, &r1)),
                set(
                    "rtest.toml",
                    toml.replace("internal = \"cnc/*.sco\"", "internal = \"cnc/*\"")
                        .replace("external = \"rtest/*.csv\"", "external = \"*/*.csv\""),
                ),
            ],
            vec!["[[pairing]] #1".into(), "cnc/notes.csv".into(), "both".into()],
        ),
        (
            "key",
            vec![set(
                "rtest.toml",
                toml.replace("internal = \"cnc/*.sco\"", "internal = \"cnc/*.sco\"\nexternals = \"rtest/*.csv\""),
            )],
            vec!["rtest.toml".into(), "externals".into()],
        ),
    ];
    let mut wrong = Vec::new();
    for (folder, edits, needles) in &variants {
        for (name, bytes) in &files {
            d.write(&format!("{folder}/{name}"), bytes);
        }
        for (name, body) in edits {
            match body {
                Some(b) => {
                    d.write(&format!("{folder}/{name}"), b);
                }
                None => std::fs::remove_file(d.path(&format!("{folder}/{name}"))).unwrap(),
            }
        }
        let e = match evaluate(&d.path(folder)) {
            Ok(_) => "accepted".to_string(),
            Err(e) => e,
        };
        println!("{folder}: {e}");
        if needles.iter().any(|n| !e.contains(n.as_str())) {
            wrong.push(format!("{folder}: {e}\n  wanted: {needles:?}"));
            continue;
        }
        let before = d.snapshot();
        let out = common::eij(&["evaluate", &d.s(folder), "--csv-out", &d.s("out.csv")]);
        let refs: Vec<&str> = needles.iter().map(String::as_str).collect();
        one_line_error(&out, &refs);
        assert!(d.snapshot() == before, "{folder}: something was written");
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}
