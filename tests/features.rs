//! The bare library builds without the command line: `cargo build --lib --no-default-features`
//! must keep working. Building it here would double the suite's build time, so this guard
//! checks what that build relies on: the command-line and figure crates are optional, and no
//! library module outside `cli` and `report` names them.

use std::path::Path;

mod common;

use common::root;

const FRONT_END_CRATES: [&str; 3] = ["clap", "indicatif", "plotters"];

#[test]
fn command_line_and_figure_crates_are_optional_features() {
    let text = std::fs::read_to_string(root().join("Cargo.toml")).unwrap();
    let cargo: toml::Table = toml::from_str(&text).unwrap();
    let deps = cargo["dependencies"].as_table().unwrap();
    for name in FRONT_END_CRATES {
        let optional = deps[name].get("optional").and_then(|v| v.as_bool());
        assert_eq!(
            optional,
            Some(true),
            "{name} must be an optional dependency"
        );
    }
    let features = cargo["features"].as_table().unwrap();
    let list = |f: &str| -> Vec<String> {
        features[f]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_str().unwrap().to_string())
            .collect()
    };
    assert_eq!(list("default"), ["cli"]);
    assert!(list("cli").contains(&"dep:clap".to_string()));
    assert!(list("cli").contains(&"report".to_string()));
    assert_eq!(list("report"), ["dep:plotters"]);
}

fn rust_files(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

#[test]
fn the_library_outside_cli_and_report_does_not_name_them() {
    let src = root().join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let gated = ["cli", "report", "main.rs"];
    let mut checked = 0;
    for f in files {
        let rel = f.strip_prefix(&src).unwrap();
        let first = rel
            .components()
            .next()
            .unwrap()
            .as_os_str()
            .to_str()
            .unwrap();
        if gated.contains(&first.trim_end_matches(".rs")) || gated.contains(&first) {
            continue;
        }
        let text = std::fs::read_to_string(&f).unwrap();
        for (n, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap();
            for c in FRONT_END_CRATES {
                assert!(
                    !code.contains(&format!("{c}::")),
                    "{}:{}: names {c} outside the cli/report features: {line}",
                    rel.display(),
                    n + 1
                );
            }
        }
        checked += 1;
    }
    assert!(checked > 40, "only {checked} library files found");
    let lib = std::fs::read_to_string(src.join("lib.rs")).unwrap();
    for m in ["report", "cli"] {
        if let Some(i) = lib.find(&format!("pub mod {m};")) {
            let before = &lib[..i];
            assert!(
                before
                    .trim_end()
                    .ends_with(&format!("#[cfg(feature = \"{m}\")]")),
                "lib.rs: `pub mod {m}` is not behind its feature"
            );
        }
    }
}
