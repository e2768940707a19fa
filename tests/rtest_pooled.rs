//! Pooled evaluation: static geometric terms G separated from EIJ across accelerations.

mod common;

use common::synth::Synth;
use eij::axes::Plane;
use eij::rtest::{evaluate, evaluate_pooled, CircleSeries, EvalOptions, RtestError, Warning};

/// Static geometry: a radial/elliptic deviation (G_aa, G_bb), a skew (G_ab, G_ba) and a tilt
/// of the circle plane (G_ka, G_kb), µm per mm of set position.
const G: [[f64; 2]; 3] = [[1.2, 0.4], [-0.3, -0.9], [0.5, -0.25]];

fn with_geometry(plane: Plane, ccw: bool, accel: f64) -> Synth {
    let mut s = Synth::new(plane, ccw, accel);
    s.g_um_per_mm = G;
    s
}

fn tests(plane: Plane, exact: bool) -> Vec<Synth> {
    let mut out = Vec::new();
    for (i, accel) in [2.0, 5.0, 10.0].into_iter().enumerate() {
        for ccw in [false, true] {
            let mut s = with_geometry(plane, ccw, accel);
            s.seed = 77 + 2 * i as u64 + ccw as u64;
            if exact {
                s = s.exact();
            }
            out.push(s);
        }
    }
    out
}

/// Noise-free: the pooled fit returns E and G to 1e-9.
#[test]
fn pooled_fit_separates_geometry_exactly() {
    for plane in Plane::ALL {
        let syn = tests(plane, true);
        let series: Vec<CircleSeries> = syn.iter().map(Synth::series).collect();
        let refs: Vec<&CircleSeries> = series.iter().collect();
        let p = evaluate_pooled(&refs, &EvalOptions::default()).unwrap();
        assert_eq!(p.plane, plane);
        for (k, truth) in syn[0].truth() {
            assert!(
                (p.eij[&k].value - truth).abs() < 1e-9,
                "{k}: {} vs {truth}",
                p.eij[&k].value
            );
        }
        for (k, truth) in syn[0].truth_geometric() {
            let got = p.geometric_um_per_mm[&k].value;
            assert!((got - truth).abs() < 1e-9, "G{k}: {got} vs {truth}");
        }
        assert!(p.rms_residual_um < 1e-9);
    }
}

/// With noise: E and G within 3 standard errors, while a single-acceleration joint fit,
/// which cannot tell G·x_set from E·ä (= −ω² E·x_set), is off by far more than its
/// standard errors — by exactly the aliased −1000 G/ω² in the noise-free limit.
#[test]
fn pooled_fit_recovers_what_a_single_test_cannot() {
    let plane = Plane::Zx;
    let syn = tests(plane, false);
    let series: Vec<CircleSeries> = syn.iter().map(Synth::series).collect();
    let refs: Vec<&CircleSeries> = series.iter().collect();
    let opts = EvalOptions {
        radius_mm: Some(2.0),
        ..Default::default()
    };
    let p = evaluate_pooled(&refs, &opts).unwrap();
    for (k, truth) in syn[0].truth() {
        let z = (p.eij[&k].value - truth) / p.eij[&k].std_err;
        assert!(
            z.abs() < 3.0,
            "{k}: {} ± {} vs {truth}",
            p.eij[&k].value,
            p.eij[&k].std_err
        );
    }
    for (k, truth) in syn[0].truth_geometric() {
        let (got, se) = (
            p.geometric_um_per_mm[&k].value,
            p.geometric_um_per_mm[&k].std_err,
        );
        assert!(
            ((got - truth) / se).abs() < 3.0,
            "G{k}: {got} ± {se} vs {truth}"
        );
    }
    assert_eq!(p.cw_ccw_difference_sigma.len(), 6);
    assert!(p.warnings.is_empty(), "{:?}", p.warnings);

    let single = evaluate(&series[2], &opts).unwrap();
    let w2 = syn[2].omega0().powi(2);
    for (k, truth) in syn[2].truth() {
        let aliased = truth - 1000.0 * syn[2].truth_geometric()[&k] / w2;
        let z_truth = (single.eij[&k].value - truth) / single.eij[&k].std_err;
        let z_alias = (single.eij[&k].value - aliased) / single.eij[&k].std_err;
        assert!(
            z_truth.abs() > 5.0,
            "{k}: single fit should be biased, z = {z_truth}"
        );
        assert!(
            z_alias.abs() < 3.0,
            "{k}: {} vs aliased {aliased}",
            single.eij[&k].value
        );
    }
}

/// Tests that all share one acceleration cannot separate G from E: an error, not a guess.
#[test]
fn same_acceleration_is_not_separable() {
    let a = with_geometry(Plane::Xy, true, 5.0).series();
    let b = with_geometry(Plane::Xy, false, 5.0).series();
    let err = evaluate_pooled(&[&a, &b], &EvalOptions::default()).unwrap_err();
    assert!(matches!(err, RtestError::Pooling { .. }), "{err}");
    assert!(err.to_string().contains("same acceleration"), "{err}");
    let c = with_geometry(Plane::Yz, true, 10.0).series();
    let err = evaluate_pooled(&[&a, &c], &EvalOptions::default()).unwrap_err();
    assert!(err.to_string().contains("plane yz differs"), "{err}");
}

/// A velocity-dependent deviation in one direction only (a ccw-only bias of E) shows in the
/// cw/ccw comparison.
#[test]
fn cw_ccw_inconsistency_is_flagged() {
    let mut syn = tests(Plane::Xy, false);
    for s in syn.iter_mut().filter(|s| s.ccw) {
        s.e[2][0] += 0.5;
    }
    let series: Vec<CircleSeries> = syn.iter().map(Synth::series).collect();
    let refs: Vec<&CircleSeries> = series.iter().collect();
    let p = evaluate_pooled(&refs, &EvalOptions::default()).unwrap();
    let z = p.cw_ccw_difference_sigma[&eij::axes::Eij::new(eij::axes::Axis::Z, eij::axes::Axis::X)];
    assert!(z < -3.0, "z = {z}");
    assert!(
        p.warnings.iter().any(
            |w| matches!(w, Warning::CwCcwDiffer { eij, z, .. } if eij.name() == "EZX" && *z < -3.0)
        ),
        "{:?}",
        p.warnings
    );
}
