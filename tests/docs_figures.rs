//! The figures in README.md and docs/ come from commands that print them (issue 29 item 10):
//! every fenced `text` block whose first line is `$ eij …` is run, and what it shows must be
//! what the command prints, line by line (a last line `…` stands for more output, left out).
//! The commands of one file run in order in one scratch folder that holds the repository's
//! `machines/`, `measurements/` and `tests/`, so a later command reads what an earlier wrote.
//! `2>&1` after a command compares standard output followed by standard error. Masked alike
//! on both sides: the run time of `eij identify` (`3 iterations, 0.1 s`) and of `eij compare`.

mod common;

use common::{root, Scratch};
use std::process::Command;

/// One checked block: where it is, the command's arguments and the lines it shows.
struct Example {
    at: String,
    args: Vec<String>,
    with_stderr: bool,
    shown: Vec<String>,
    more: bool,
}

/// The checked blocks of a Markdown file.
fn examples(file: &str) -> Vec<Example> {
    let text = std::fs::read_to_string(root().join(file)).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        if lines[i].trim_end() != "```text" || i + 1 >= lines.len() {
            i += 1;
            continue;
        }
        let Some(command) = lines[i + 1].strip_prefix("$ eij ") else {
            i += 1;
            continue;
        };
        let end = (i + 2..lines.len())
            .find(|&k| lines[k].trim_end() == "```")
            .unwrap_or_else(|| panic!("{file}:{}: block not closed", i + 1));
        let (command, with_stderr) = match command.strip_suffix(" 2>&1") {
            Some(c) => (c, true),
            None => (command, false),
        };
        let mut shown: Vec<String> = lines[i + 2..end].iter().map(|l| l.to_string()).collect();
        let more = shown.last().is_some_and(|l| l.trim() == "…");
        if more {
            shown.pop();
        }
        out.push(Example {
            at: format!("{file}:{}", i + 2),
            args: command.split_whitespace().map(String::from).collect(),
            with_stderr,
            shown,
            more,
        });
        i = end + 1;
    }
    out
}

/// `Identified demo-vmc from 36 tests (216 values), 3 iterations, 0.1 s` → `…, 3 iterations, T s`;
/// `Compared 2 candidate models on … , 13.7 s` (`eij compare`) → `…, T s`.
fn masked(line: &str) -> String {
    if line.starts_with("Compared ") {
        if let Some((head, time)) = line.rsplit_once(", ") {
            if time
                .strip_suffix(" s")
                .is_some_and(|t| t.parse::<f64>().is_ok())
            {
                return format!("{head}, T s");
            }
        }
    }
    match line.find(" iterations, ") {
        Some(k) => {
            let rest = &line[k + " iterations, ".len()..];
            match rest.find(" s") {
                Some(e) if rest[..e].parse::<f64>().is_ok() => {
                    format!("{}T{}", &line[..k + " iterations, ".len()], &rest[e..])
                }
                _ => line.to_string(),
            }
        }
        None => line.to_string(),
    }
}

/// Runs every checked block of `file` and compares.
fn check(file: &str) -> usize {
    let scratch = Scratch::new(&format!("docs-{}", file.replace('/', "-")));
    for dir in ["machines", "measurements", "tests"] {
        std::os::unix::fs::symlink(root().join(dir), scratch.path(dir)).unwrap();
    }
    let all = examples(file);
    for ex in &all {
        let out = Command::new(env!("CARGO_BIN_EXE_eij"))
            .current_dir(&scratch.0)
            .env("SOURCE_DATE_EPOCH", "0")
            .args(&ex.args)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            out.status.success(),
            "{}: eij {}: {stderr}",
            ex.at,
            ex.args.join(" ")
        );
        let mut printed = String::from_utf8_lossy(&out.stdout).into_owned();
        if ex.with_stderr {
            printed.push_str(&stderr);
        }
        let printed: Vec<String> = printed.lines().map(masked).collect();
        let shown: Vec<String> = ex.shown.iter().map(|l| masked(l)).collect();
        let compared = if ex.more {
            printed.len().min(shown.len())
        } else {
            printed.len()
        };
        assert_eq!(
            shown,
            printed[..compared],
            "{}: `eij {}` prints otherwise (left: the document, right: the command)",
            ex.at,
            ex.args.join(" ")
        );
    }
    all.len()
}

#[test]
fn readme_shows_what_the_commands_print() {
    assert!(check("README.md") >= 2);
}

#[test]
fn docs_show_what_the_commands_print() {
    let mut n = 0;
    for e in std::fs::read_dir(root().join("docs")).unwrap() {
        let path = e.unwrap().path();
        if path.extension().is_some_and(|x| x == "md") {
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            n += check(&format!("docs/{name}"));
        }
    }
    assert!(n >= 3, "{n} checked blocks in docs/");
}

/// One feed per test on the report page (issue 29 item 10: the header said 3790 mm/min, the
/// table 3795): the header's feeds and every feed cell are the path speed 2π·r·f of
/// `eij evaluate --json`, to 10 mm/min, and no cell shows an unrounded one.
#[test]
fn the_report_shows_one_feed_per_test() {
    let s = Scratch::new("docs-feed");
    let folder = "measurements/demo-vmc/pos-a";
    let json = common::eij(&["evaluate", folder, "--json"]);
    assert!(json.status.success());
    let json: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    let out = s.s("report");
    let run = common::eij(&["report", "--measured", folder, "--out", &out]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let page = std::fs::read_to_string(s.path("report/report.html")).unwrap();
    let header = page
        .split("feed ")
        .find_map(|rest| rest.split_once(" mm/min; circle centres").map(|(f, _)| f))
        .expect("the conditions line names the feeds");
    let header: Vec<f64> = header.split(", ").map(|f| f.parse().unwrap()).collect();
    let tests = json["tests"].as_array().unwrap();
    for t in tests {
        let exact = std::f64::consts::TAU
            * t["radius_mm"].as_f64().unwrap()
            * t["freq_hz"].as_f64().unwrap()
            * 60.0;
        let shown = (exact / 10.0).round() * 10.0;
        assert!(
            header.contains(&shown),
            "{exact} mm/min: {shown} not in {header:?}"
        );
        assert!(
            page.contains(&format!("<td>{shown:.0}</td>")),
            "{shown} not in a table"
        );
        if exact.round() != shown {
            let unrounded = format!("<td>{:.0}</td>", exact);
            assert!(!page.contains(&unrounded), "{unrounded} on the page");
        }
    }
    // The demo's accelerations give feeds off the 10 mm/min grid (2 m/s²: 3795.4 mm/min).
    assert!(tests.iter().any(|t| {
        let f = std::f64::consts::TAU
            * t["radius_mm"].as_f64().unwrap()
            * t["freq_hz"].as_f64().unwrap()
            * 60.0;
        f.round() % 10.0 != 0.0
    }));
}
