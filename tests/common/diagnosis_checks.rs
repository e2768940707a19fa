//! Checks of the circle diagnosis on synthetic circles ([`super::circle_terms`]): diagnose with
//! cyclic error at [`PITCH_MM`], compare every term of a source with its expected value (3
//! standard errors) or with 0 (4 standard errors).

use std::collections::BTreeMap;

use super::circle_terms::TermCircle;
use eij::rtest::diagnosis::{
    diagnose_series, CircleDiagnosis, DiagnosisOptions, Source, SourceDiagnosis,
};
use eij::rtest::EvalOptions;

/// Pitch of the cyclic error the synthetic circles use, mm.
pub const PITCH_MM: f64 = 0.5;

/// The diagnosis options: cyclic error at [`PITCH_MM`].
pub fn opts() -> DiagnosisOptions {
    DiagnosisOptions {
        cyclic_pitch_mm: Some(PITCH_MM),
        ..Default::default()
    }
}

/// The diagnosis of one synthetic circle.
pub fn diagnose(c: &TermCircle) -> CircleDiagnosis {
    let eval = EvalOptions {
        radius_mm: Some(c.radius_mm),
        ..Default::default()
    };
    diagnose_series(&c.series(), &eval, &opts()).unwrap()
}

/// Expected values per term name (others 0).
pub type Expected = BTreeMap<String, f64>;

/// Amplitudes are ≥ 0 (Rayleigh-distributed about 0): not in the z-score statistics.
pub fn is_amplitude(name: &str) -> bool {
    name.starts_with("cyclic") || name == "out_of_plane_tilt" || name == "out_of_plane_saddle"
}

/// Checks one source: expected terms within 3 se, the others within 4 se of 0 (hundreds of
/// checks: 4 se keeps chance failures below 1 in 10⁴ each). Returns the z-scores of the
/// terms expected to be 0 (not amplitudes).
pub fn check(what: &str, d: &SourceDiagnosis, expected: &Expected) -> Vec<f64> {
    let mut zeros = Vec::new();
    for t in &d.terms {
        let truth = expected.get(&t.name).copied().unwrap_or(0.0);
        let z = (t.value - truth) / t.std_err;
        let bound = if expected.contains_key(&t.name) {
            3.0
        } else {
            4.0
        };
        assert!(
            z.abs() < bound,
            "{what}: {} = {:.4} ± {:.4} {}, expected {truth} (z = {z:.2})",
            t.name,
            t.value,
            t.std_err,
            t.unit
        );
        if !expected.contains_key(&t.name) && !is_amplitude(&t.name) {
            zeros.push(z);
        }
    }
    zeros
}

/// Expected values from (name, value) pairs.
pub fn expect(pairs: &[(String, f64)]) -> Expected {
    pairs.iter().cloned().collect()
}

/// (value, std_err) of a term of a source.
pub fn term(d: &CircleDiagnosis, source: Source, name: &str) -> (f64, f64) {
    let t = d
        .source(source)
        .term(name)
        .unwrap_or_else(|| panic!("{name} in {source:?}"));
    (t.value, t.std_err)
}

/// |v − truth| < k·se.
pub fn within(what: &str, (v, se): (f64, f64), truth: f64, k: f64) {
    assert!(
        (v - truth).abs() < k * se,
        "{what}: {v:.4} ± {se:.4}, expected {truth}"
    );
}
