//! The fuzz targets' entry points under `cargo test`: the seeds and past crashes of `fuzz/`
//! replayed, then thousands of seeded mutations of them (byte flips, insertions, deletions,
//! duplicated spans, spliced-in tokens). Every input must give a value or an error of one line
//! naming the source; nothing may panic. `fuzz/README.md` runs the same entry points under
//! libFuzzer for longer.

use eij::ident::config::IdentConfig;
use eij::ident::measured::MeasuredOptions;
use eij::ident::Settings;
use eij::machine::Machine;
use eij::rtest::conditions::TestConditions;
use eij::rtest::{evaluate, table, CircleSeries, EvalOptions};
use std::path::Path;

/// xorshift64*: small, seeded, the same sequence everywhere.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Tokens that reach the loaders' edge cases.
const TOKENS: &[&[u8]] = &[
    b",",
    b"\n",
    b"\r\n",
    b"\"",
    b"nan",
    b"inf",
    b"-",
    b"1e308",
    b"0",
    b"=",
    b"[",
    b"]",
    b"{",
    b"}",
    b"\xEF\xBB\xBF",
    b"\xff",
    b"\0",
    b"#",
    b"'",
    b"\"\"\"",
    b"[[axis]]",
    b"[body]",
    b"t_s",
    b"x_int_mm",
    b"zx",
    b"EXZ",
    b"radius_mm",
    b"position_mm",
    b"mass_kg",
    b"true",
];

fn mutate(rng: &mut Rng, seed: &[u8]) -> Vec<u8> {
    let mut v = seed.to_vec();
    for _ in 0..1 + rng.below(4) {
        let at = rng.below(v.len() + 1);
        match rng.below(5) {
            0 if !v.is_empty() => {
                let i = at.min(v.len() - 1);
                v[i] ^= 1 << rng.below(8);
            }
            1 => {
                let end = (at + rng.below(16)).min(v.len());
                v.drain(at..end);
            }
            2 => {
                let t = TOKENS[rng.below(TOKENS.len())];
                v.splice(at..at, t.iter().copied());
            }
            3 if !v.is_empty() => {
                let start = rng.below(v.len());
                let end = (start + rng.below(64)).min(v.len());
                let span = v[start..end].to_vec();
                v.splice(at..at, span);
            }
            _ => v.truncate(at),
        }
    }
    v
}

fn inputs(target: &str) -> Vec<Vec<u8>> {
    let fuzz = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz");
    let mut out = Vec::new();
    for dir in ["seeds", "regressions"] {
        if let Ok(entries) = std::fs::read_dir(fuzz.join(dir).join(target)) {
            let mut paths: Vec<_> = entries.map(|e| e.unwrap().path()).collect();
            paths.sort();
            out.extend(paths.iter().map(|p| std::fs::read(p).unwrap()));
        }
    }
    assert!(!out.is_empty(), "no seeds for {target}");
    out
}

/// Feeds the seeds and `n` mutations of them to `check`.
fn run(target: &str, seed: u64, n: usize, check: impl Fn(&[u8])) {
    let seeds = inputs(target);
    let mut rng = Rng(seed);
    for s in &seeds {
        check(s);
    }
    for _ in 0..n {
        let s = &seeds[rng.below(seeds.len())];
        check(&mutate(&mut rng, s));
    }
}

fn one_line(e: &dyn std::fmt::Display, source: &str) {
    let text = e.to_string();
    assert!(text.starts_with(source), "{text}");
    assert_eq!(text.lines().count(), 1, "{text}");
}

#[test]
fn rtest_series_mutations() {
    run(
        "rtest_series",
        1,
        3000,
        |data| match CircleSeries::from_csv_bytes("fuzz.csv", data) {
            Ok(series) => {
                if let Err(e) = evaluate(&series, &EvalOptions::default()) {
                    one_line(&e, "fuzz.csv");
                }
            }
            Err(e) => one_line(&e, "fuzz.csv"),
        },
    );
}

#[test]
fn rtest_table_mutations() {
    run("rtest_table", 2, 50_000, |data| {
        if let Err(e) = table::from_bytes("fuzz.csv", data) {
            one_line(&e, "fuzz.csv");
        }
    });
}

#[test]
fn machine_toml_mutations() {
    run("machine_toml", 3, 20_000, |data| {
        let Ok(text) = std::str::from_utf8(data) else {
            return;
        };
        if let Err(e) = Machine::from_toml_str(text, "fuzz.toml") {
            one_line(&e, "fuzz.toml: ");
        }
    });
}

#[test]
fn ident_config_mutations() {
    run("ident_config", 4, 50_000, |data| {
        let Ok(text) = std::str::from_utf8(data) else {
            return;
        };
        if let Ok(config) = toml::from_str::<IdentConfig>(text) {
            let _ = config.apply(&mut Settings::default(), &mut MeasuredOptions::default());
        }
    });
}

#[test]
fn rtest_conditions_mutations() {
    run("rtest_conditions", 5, 50_000, |data| {
        let Ok(text) = std::str::from_utf8(data) else {
            return;
        };
        if let Err(e) = TestConditions::from_toml_str(text, "rtest.toml") {
            one_line(&e, "rtest.toml: ");
        }
    });
}
