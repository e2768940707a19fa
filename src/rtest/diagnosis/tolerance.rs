//! Tolerances and the verdict: `rtest.toml` `[tolerances]` (read with the folder's conditions)
//! gives limits on the circular deviation G and on the terms' magnitudes, per source; every
//! test is judged against them, term by term.
//!
//! ```toml
//! [tolerances]                 # the TCP, what a ballbar measures
//! circular_deviation_um = 10   # ISO 230-4 G of the path
//! backlash_um = 3              # every axis: backlash_x, backlash_y, ...
//! squareness_um_per_m = 50
//! servo_mismatch_ms = 0.5
//! [tolerances.internal]        # the axes' own path (also: [tolerances.structure])
//! circular_deviation_um = 6
//! ```
//!
//! A key is a term name or a family (the name without its axis, e.g. `backlash`, `cyclic`,
//! `centre_offset`) followed by the term's unit (`_um`, `_um_per_m`, `_ms`), so that the file
//! says what it means; a term's own key beats its family's. The limit applies to |value|.

use std::collections::BTreeMap;

use serde::Serialize;

use super::{CircleDiagnosis, Source};

/// The key of the limit on G.
pub const CIRCULAR_DEVIATION: &str = "circular_deviation_um";

/// Every family and its unit: a term `<family>` or `<family>_<axis>[_h<n>]`.
const FAMILIES: [(&str, &str); 17] = [
    ("centre_offset", "um"),
    ("radius_deviation", "um"),
    ("scale_mismatch", "um"),
    ("squareness", "um_per_m"),
    ("servo_mismatch", "ms"),
    ("straightness", "um"),
    ("backlash", "um"),
    ("reversal_spike", "um"),
    ("lateral_play", "um"),
    ("cyclic", "um"),
    ("rotation", "um_per_m"),
    ("feed_deviation", "um_per_m"),
    ("out_of_plane_offset", "um"),
    ("out_of_plane_tilt", "um_per_m"),
    ("out_of_plane_saddle", "um"),
    ("out_of_plane_play", "um"),
    ("circular_deviation", "um"),
];

/// The limits of one source: on G and per term (or family), in the term's unit.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Limits {
    /// Largest ISO 230-4 circular deviation G, µm.
    pub circular_deviation_um: Option<f64>,
    /// Largest |value| per term name or family (without the unit suffix).
    pub terms: BTreeMap<String, f64>,
}

/// The tolerances of a folder's tests, per source.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Tolerances {
    /// Per source (the TCP from the table's own keys).
    pub sources: BTreeMap<Source, Limits>,
}

/// A key of `[tolerances]` that is not one.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ToleranceError {
    /// The key path, e.g. `tolerances.internal.backlash_mm`.
    pub key: String,
    /// What is wrong.
    pub message: String,
}

impl std::fmt::Display for ToleranceError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.key, self.message)
    }
}

impl Tolerances {
    /// Validates a `[tolerances]` table: numbers > 0 under known keys, sub-tables `internal`,
    /// `structure`, `tcp` (the top level is the TCP; a key given in both is an error).
    pub fn from_toml(table: &toml::Table) -> Result<Tolerances, ToleranceError> {
        let mut out = Tolerances::default();
        for (key, value) in table {
            let path = format!("tolerances.{key}");
            if let toml::Value::Table(sub) = value {
                let source = Source::ALL
                    .into_iter()
                    .find(|s| s.name() == key)
                    .ok_or_else(|| ToleranceError {
                        key: path.clone(),
                        message: "unknown table (expected internal, structure or tcp)".into(),
                    })?;
                for (k, v) in sub {
                    let limits = out.sources.entry(source).or_default();
                    insert(limits, &format!("{path}.{k}"), k, v)?;
                }
            } else {
                insert(
                    out.sources.entry(Source::Tcp).or_default(),
                    &path,
                    key,
                    value,
                )?;
            }
        }
        Ok(out)
    }

    /// True when nothing is limited.
    pub fn is_empty(&self) -> bool {
        self.sources
            .values()
            .all(|l| l.circular_deviation_um.is_none() && l.terms.is_empty())
    }
}

fn insert(
    limits: &mut Limits,
    path: &str,
    key: &str,
    value: &toml::Value,
) -> Result<(), ToleranceError> {
    let err = |message: String| ToleranceError {
        key: path.to_string(),
        message,
    };
    let limit = match value {
        toml::Value::Float(f) => *f,
        toml::Value::Integer(i) => *i as f64,
        other => {
            return Err(err(format!(
                "expected a number, found {}",
                other.type_str()
            )))
        }
    };
    if !(limit.is_finite() && limit > 0.0) {
        return Err(err(format!("limit {limit}: expected a number > 0")));
    }
    let term = term_of_key(key).map_err(err)?;
    let twice = if term == "circular_deviation" {
        limits.circular_deviation_um.replace(limit).is_some()
    } else {
        limits.terms.insert(term, limit).is_some()
    };
    if twice {
        // Only possible across the top level and `[tolerances.tcp]`.
        return Err(err(
            "given twice (at the top level and in [tolerances.tcp])".into(),
        ));
    }
    Ok(())
}

/// The term or family of a key `<name>_<unit>`, checked against the family's unit.
fn term_of_key(key: &str) -> Result<String, String> {
    let family = FAMILIES
        .iter()
        .filter(|(f, _)| key.starts_with(f))
        .max_by_key(|(f, _)| f.len());
    let Some(&(family, unit)) = family else {
        let names: Vec<&str> = FAMILIES.iter().map(|(f, _)| *f).collect();
        return Err(format!(
            "unknown term (expected one of {}, with an axis or not, and its unit)",
            names.join(", ")
        ));
    };
    let name = key.strip_suffix(&format!("_{unit}")).ok_or_else(|| {
        format!("{family} is in {unit}: write the key as <term>_{unit}, e.g. {family}_{unit}")
    })?;
    let rest = &name[family.len()..];
    let axis_part = rest.strip_prefix('_').unwrap_or(rest);
    let valid = rest.is_empty()
        || (rest.starts_with('_')
            && (matches!(axis_part, "a" | "b")
                || axis_part
                    .split_once("_h")
                    .map_or(is_axis(axis_part), |(ax, h)| {
                        is_axis(ax) && h.parse::<usize>().is_ok_and(|h| h >= 2)
                    })));
    if !valid {
        return Err(format!("{name}: no such term of {family}"));
    }
    Ok(name.to_string())
}

fn is_axis(s: &str) -> bool {
    matches!(s, "x" | "y" | "z")
}

/// The family of a term name: the longest family it starts with.
fn family_of(name: &str) -> &str {
    FAMILIES
        .iter()
        .map(|(f, _)| *f)
        .filter(|f| name.starts_with(f))
        .max_by_key(|f| f.len())
        .unwrap_or(name)
}

/// One limit checked.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Check {
    /// The source.
    pub source: Source,
    /// `circular_deviation` or the term's name.
    pub name: String,
    /// |value| (G itself for the circular deviation).
    pub value: f64,
    /// Standard error of the value, where it has one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub std_err: Option<f64>,
    /// The limit.
    pub limit: f64,
    /// The unit of value and limit.
    pub unit: &'static str,
    /// `pass` or `fail`.
    pub verdict: &'static str,
}

/// The verdict of one test.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Verdict {
    /// `pass` when every check passes, else `fail`.
    pub verdict: &'static str,
    /// Every limit checked.
    pub checks: Vec<Check>,
    /// Limits that found no term in this test (e.g. servo mismatch without a test in the
    /// opposite direction, cyclic error without a pitch).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub unchecked: Vec<String>,
}

impl Verdict {
    /// True when every check passed.
    pub fn passed(&self) -> bool {
        self.verdict == "pass"
    }
}

/// Judges a diagnosed test against `tol`, and writes each term's limit and verdict into it.
pub fn judge(test: &mut CircleDiagnosis, tol: &Tolerances) -> Verdict {
    let mut checks = Vec::new();
    let mut unchecked = Vec::new();
    for (&source, limits) in &tol.sources {
        let sd = &mut test.sources[source as usize];
        let verdict = |ok: bool| if ok { "pass" } else { "fail" };
        if let Some(limit) = limits.circular_deviation_um {
            let g = sd.circular_deviation_um;
            checks.push(Check {
                source,
                name: "circular_deviation".into(),
                value: g,
                std_err: None,
                limit,
                unit: "um",
                verdict: verdict(g <= limit),
            });
        }
        for (key, &limit) in &limits.terms {
            let mut found = false;
            for t in sd.terms.iter_mut() {
                let own = limits.terms.contains_key(&t.name);
                if !(t.name == *key || (!own && family_of(&t.name) == key)) {
                    continue;
                }
                found = true;
                let v = verdict(t.value.abs() <= limit);
                t.limit = Some(limit);
                t.verdict = Some(v);
                checks.push(Check {
                    source,
                    name: t.name.clone(),
                    value: t.value.abs(),
                    std_err: Some(t.std_err),
                    limit,
                    unit: t.unit,
                    verdict: v,
                });
            }
            if !found {
                unchecked.push(format!("{} {key}", source.name()));
            }
        }
    }
    let pass = checks.iter().all(|c| c.verdict == "pass");
    Verdict {
        verdict: if pass { "pass" } else { "fail" },
        checks,
        unchecked,
    }
}
