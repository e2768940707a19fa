//! The figures in README.md and docs/ come from commands that print them (issue 29 item 10):
//! every fenced `text` block whose first line is `$ eij …` is run, and what it shows must be
//! what the command prints, line by line (a line `…` stands for output left out there: at the
//! end, more output; inside, lines skipped).
//! The commands of one file run in order in one scratch folder that holds the repository's
//! `machines/`, `measurements/` and `tests/`, so a later command reads what an earlier wrote.
//! `2>&1` after a command compares standard output followed by standard error. A command that
//! ends in `; echo "exit $?"` is expected to exit with the status its block's last line states
//! (`exit 3`: a verdict, the outputs written; a `…` may stand before it); every other command
//! must succeed. Masked alike
//! on both sides: the run time of `eij identify` (`3 iterations, 0.1 s`) and of `eij compare`.

mod common;

use common::{root, Scratch};
use std::process::Command;

/// One checked block: where it is, the command's arguments and the lines it shows.
struct Example {
    at: String,
    args: Vec<String>,
    with_stderr: bool,
    /// The exit status the block states (`; echo "exit $?"`), else success.
    status: Option<i32>,
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
        let (command, with_status) = match command.strip_suffix("; echo \"exit $?\"") {
            Some(c) => (c, true),
            None => (command, false),
        };
        let (command, with_stderr) = match command.strip_suffix(" 2>&1") {
            Some(c) => (c, true),
            None => (command, false),
        };
        let mut shown: Vec<String> = lines[i + 2..end].iter().map(|l| l.to_string()).collect();
        let status = with_status.then(|| {
            shown
                .pop()
                .and_then(|l| l.strip_prefix("exit ")?.parse::<i32>().ok())
                .unwrap_or_else(|| panic!("{file}:{}: last line `exit N` missing", i + 2))
        });
        let more = shown.last().is_some_and(|l| l.trim() == "…");
        if more {
            shown.pop();
        }
        out.push(Example {
            at: format!("{file}:{}", i + 2),
            args: command.split_whitespace().map(String::from).collect(),
            with_stderr,
            status,
            shown,
            more,
        });
        i = end + 1;
    }
    out
}

/// `Identified demo-vmc from 36 tests (216 values), 3 iterations, 0.1 s` → `…, 3 iterations, T s`;
/// `Compared 2 candidate models on … , 13.7 s` (`eij compare`) → `…, T s`; `eij fe`'s
/// `Reduction (Craig–Bampton) in 0.345 s:` → `in T s:` and its FE file `…/fe/column-K.mtx`.
fn masked(line: &str) -> String {
    // `eij fe`: the reduction's time, and the FE file's path up to its folder (absolute).
    if let Some(rest) = line.strip_prefix("Reduction (Craig–Bampton) in ") {
        if let Some((t, tail)) = rest.split_once(" s: ") {
            if t.parse::<f64>().is_ok() {
                return format!("Reduction (Craig–Bampton) in T s: {tail}");
            }
        }
    }
    if line.starts_with("Elastic body ") {
        if let Some((head, path)) = line.split_once(", stiffness ") {
            let path = path.trim_end_matches(')');
            let parts: Vec<&str> = path.rsplitn(3, '/').collect();
            if parts.len() == 3 {
                return format!("{head}, stiffness …/{}/{})", parts[1], parts[0]);
            }
        }
    }
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

/// Every place in `text` where a U+2212 minus stands right before a digit or an axis letter
/// (`−60`, `−x`): eij prints numbers and directions with the ASCII hyphen-minus, as Rust
/// formats them, on the console and the page alike; `−` stays an operator between spaces.
fn typographic_minus_numbers(text: &str) -> Vec<String> {
    text.match_indices('−')
        .filter(|(k, m)| {
            text[k + m.len()..]
                .chars()
                .next()
                .is_some_and(|c| c.is_ascii_digit() || "xyzXYZ".contains(c))
        })
        .map(|(k, _)| {
            let from = text[..k].char_indices().rev().nth(30).map_or(0, |(i, _)| i);
            let to = text[k..]
                .char_indices()
                .nth(20)
                .map_or(text.len(), |(i, _)| k + i);
            text[from..to].to_string()
        })
        .collect()
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
        match ex.status {
            Some(code) => assert_eq!(
                out.status.code(),
                Some(code),
                "{}: eij {}: {stderr}",
                ex.at,
                ex.args.join(" ")
            ),
            None => assert!(
                out.status.success(),
                "{}: eij {}: {stderr}",
                ex.at,
                ex.args.join(" ")
            ),
        }
        let mut printed = String::from_utf8_lossy(&out.stdout).into_owned();
        if ex.with_stderr {
            printed.push_str(&stderr);
        }
        assert_eq!(
            typographic_minus_numbers(&printed),
            Vec::<String>::new(),
            "{}: numbers print with the ASCII minus",
            ex.at
        );
        let printed: Vec<String> = printed.lines().map(masked).collect();
        let shown: Vec<String> = ex.shown.iter().map(|l| masked(l)).collect();
        // A `…` line inside a block leaves out lines there: the parts around it must follow
        // one another in the output, the first from its start.
        let parts: Vec<&[String]> = shown.split(|l| l.trim() == "…").collect();
        let mut at = 0;
        for (k, part) in parts.iter().enumerate() {
            let from = if k == 0 {
                0
            } else {
                (at..=printed.len().saturating_sub(part.len()))
                    .find(|&j| printed[j..j + part.len()] == **part)
                    .unwrap_or_else(|| {
                        panic!(
                            "{}: `eij {}` prints no lines {part:#?} after line {at}",
                            ex.at,
                            ex.args.join(" ")
                        )
                    })
            };
            let last = k + 1 == parts.len();
            let end = if last && !ex.more {
                printed.len()
            } else {
                (from + part.len()).min(printed.len())
            };
            assert_eq!(
                **part,
                printed[from..end],
                "{}: `eij {}` prints otherwise (left: the document, right: the command)",
                ex.at,
                ex.args.join(" ")
            );
            at = end;
        }
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
    // Numbers with one minus (issue 28 leftover): the page writes every number as the console
    // does, with the ASCII hyphen-minus (F min -3.869, positions 150,-100,0); the ring key
    // said "from −60 µm" and the axis labels "−x" in U+2212.
    assert_eq!(typographic_minus_numbers(&page), Vec::<String>::new());
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

/// README.md, docs/*.md and the rustdoc of src/ hold everything they rely on (issue 29
/// item 6: they cited `../shared/CONTRACT.md` nine times, a file a clone does not have): every
/// relative Markdown link resolves to a file of the repository, and nothing names a path that
/// climbs out of it.
#[test]
fn docs_point_only_inside_the_repository() {
    let root = root();
    let mut files = vec![root.join("README.md")];
    for dir in ["docs", "src"] {
        let mut stack = vec![root.join(dir)];
        while let Some(d) = stack.pop() {
            for e in std::fs::read_dir(&d).unwrap() {
                let p = e.unwrap().path();
                if p.is_dir() {
                    stack.push(p);
                } else if p.extension().is_some_and(|x| x == "md" || x == "rs") {
                    files.push(p);
                }
            }
        }
    }
    let mut bad = Vec::new();
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        let name = f.strip_prefix(root).unwrap().display().to_string();
        for (n, line) in text.lines().enumerate() {
            if line.contains("../shared") || line.contains("CONTRACT.md") {
                bad.push(format!("{name}:{}: {line}", n + 1));
            }
            if f.extension().is_some_and(|x| x != "md") {
                continue;
            }
            for (k, _) in line.match_indices("](") {
                let rest = &line[k + 2..];
                let Some(end) = rest.find(')') else { continue };
                let target = rest[..end].split('#').next().unwrap();
                if target.is_empty() || target.contains("://") || target.starts_with("mailto:") {
                    continue;
                }
                let resolved = f.parent().unwrap().join(target);
                let inside = resolved
                    .canonicalize()
                    .is_ok_and(|p| p.starts_with(root.canonicalize().unwrap()));
                if !inside {
                    bad.push(format!("{name}:{}: link {target}", n + 1));
                }
            }
        }
    }
    assert!(files.len() > 50, "{} files", files.len());
    assert!(
        bad.is_empty(),
        "outside the repository:\n{}",
        bad.join("\n")
    );
}
