//! Seeded mutations of the fuzz targets' seeds and past crashes (byte flips, insertions,
//! deletions, duplicated spans, spliced-in tokens), so that the loaders' entry points stay
//! covered under `cargo test`; `fuzz/README.md` runs the same entry points under libFuzzer for
//! longer. Every input must give a value or an error of one line naming the source; nothing may
//! panic.

/// xorshift64*: small, seeded, the same sequence everywhere.
pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Tokens that reach the loaders' edge cases.
pub const TOKENS: &[&[u8]] = &[
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

pub fn mutate(rng: &mut Rng, seed: &[u8]) -> Vec<u8> {
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

pub fn inputs(target: &str) -> Vec<Vec<u8>> {
    let fuzz = super::root().join("fuzz");
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
pub fn run(target: &str, seed: u64, n: usize, check: impl Fn(&[u8])) {
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

pub fn one_line(e: &dyn std::fmt::Display, source: &str) {
    let text = e.to_string();
    assert!(text.starts_with(source), "{text}");
    assert_eq!(text.lines().count(), 1, "{text}");
}
