//! EIJ recovery from synthetic circle tests with known truth (generator in `tests/common/synth.rs`).

mod common;

use common::synth::Synth;
use eij::axes::{Direction, Plane};
use eij::rtest::{evaluate, EvalOptions};

const ACCELS: [f64; 3] = [1.0, 4.0, 10.0];

/// Noise-free, circular internal path (lag and centre offset present): the joint fit
/// recovers every EIJ to 1e-9 µm·s²/m, with plane, direction, radius and acceleration
/// inferred from the data.
#[test]
fn noise_free_recovery_is_exact() {
    for plane in Plane::ALL {
        for ccw in [false, true] {
            for accel in ACCELS {
                let syn = Synth::new(plane, ccw, accel).exact();
                let r = evaluate(&syn.series(), &EvalOptions::default()).unwrap();
                assert_eq!(r.plane, plane);
                assert_eq!(
                    r.direction,
                    if ccw { Direction::Ccw } else { Direction::Cw }
                );
                assert!((r.radius_mm - 2.0).abs() < 1e-12, "{}", r.radius_mm);
                assert!((r.accel_m_s2 - accel).abs() < 1e-9 * accel);
                assert_eq!(r.revolutions, 5);
                for (p, truth) in syn.truth() {
                    let got = r.eij[&p].value;
                    assert!(
                        (got - truth).abs() < 1e-9,
                        "{plane} ccw={ccw} a={accel}: {p} = {got}, truth {truth}"
                    );
                }
                assert!(r.rms_residual_um < 1e-9, "{}", r.rms_residual_um);
                let offsets = r.offsets_um;
                for ax in eij::axes::Axis::ALL {
                    let truth = syn.ext_offset_um[ax.index()];
                    assert!((offsets[&ax] - truth).abs() < 1e-9);
                }
            }
        }
    }
}

/// With noise σ = 1.4 µm, lag, axis radius errors and centre offsets: every EIJ lies within
/// 3 standard errors of the truth, the standard errors are within 20 % of σ·√(2/n)/a, and the
/// normalised errors z = (Ê − E)/se have a mean square near 1 (the standard errors are honest).
#[test]
fn noisy_recovery_within_three_standard_errors() {
    let mut z2 = Vec::new();
    let mut z2_ellipse = Vec::new();
    for plane in Plane::ALL {
        for ccw in [false, true] {
            for (k, accel) in ACCELS.into_iter().enumerate() {
                let mut syn = Synth::new(plane, ccw, accel);
                syn.seed = 1000 + 10 * plane as u64 + 3 * k as u64 + ccw as u64;
                let opts = EvalOptions {
                    radius_mm: Some(2.0),
                    ..Default::default()
                };
                let r = evaluate(&syn.series(), &opts).unwrap();
                let n = r.samples_used as f64;
                let expected_se = syn.noise_um * (2.0 / n).sqrt() / accel;
                for (p, truth) in syn.truth() {
                    let (got, se) = (r.eij[&p].value, r.eij[&p].std_err);
                    let z = (got - truth) / se;
                    assert!(
                        z.abs() < 3.0,
                        "{plane} ccw={ccw} a={accel}: {p} = {got} ± {se}, truth {truth}"
                    );
                    let ratio = se / expected_se;
                    assert!(
                        (0.8..1.2).contains(&ratio),
                        "{plane} a={accel}: {p} se {se} vs σ√(2/n)/a {expected_se}"
                    );
                    z2.push(z * z);
                }
                assert!(
                    (r.rms_residual_um / syn.noise_um - 1.0).abs() < 0.1,
                    "rms {}",
                    r.rms_residual_um
                );
                assert!(r.warnings.is_empty(), "{:?}", r.warnings);
                let route = r.ellipse_fit.as_ref().unwrap();
                for (p, v) in &route.eij {
                    let z = (v - route.predicted_from_joint[p]) / r.eij[p].std_err;
                    z2_ellipse.push(z * z);
                }
            }
        }
    }
    let m_e = z2_ellipse.len() as f64;
    let mean_e = z2_ellipse.iter().sum::<f64>() / m_e;
    println!("ellipse route vs prediction: mean z² = {mean_e} over {m_e}");
    // The route shares the data with the joint fit: its difference from the prediction is no
    // noisier than one joint standard error, so the 3·√2·se warning threshold is conservative.
    assert!(mean_e < 1.0, "ellipse route mean z² = {mean_e}");
    let m = z2.len() as f64;
    let mean_z2 = z2.iter().sum::<f64>() / m;
    // E[z²] = 1 with standard deviation √(2/m) for honest standard errors.
    assert!(
        (mean_z2 - 1.0).abs() < 3.0 * (2.0 / m).sqrt(),
        "mean z² = {mean_z2} over {m}"
    );
}

/// The plane fit is the joint fit's normal row in a rescaled regressor (ä = −ω² x_set sample by
/// sample): theory says equal to rounding. The ellipse route is first order in
/// ε = 10⁻⁶ ω² E: for a circular internal path its exact value is
/// (1 − √((1 − ε_aa)² + ε_ab²)) / (10⁻⁶ ω²), i.e. E_aa − E_ab ε_ab / 2 + O(ε²·E).
#[test]
fn routes_agree_with_theory_noise_free() {
    for plane in Plane::ALL {
        for accel in ACCELS {
            let syn = Synth::new(plane, true, accel).exact();
            let r = evaluate(&syn.series(), &EvalOptions::default()).unwrap();
            let truth = syn.truth();
            for (p, v) in &r.plane_fit.value_map() {
                assert!(
                    (v - r.eij[p].value).abs() <= 1e-9 * r.eij[p].value.abs().max(1.0),
                    "{p}: plane fit {v} vs joint {}",
                    r.eij[p].value
                );
            }
            let k = 1e-6 * syn.omega0().powi(2);
            let (a, b) = plane.axes();
            for (i, j) in [(a, b), (b, a)] {
                let e_ii = truth[&eij::axes::Eij::new(i, i)];
                let e_ij = truth[&eij::axes::Eij::new(i, j)];
                let exact = (1.0 - ((1.0 - k * e_ii).powi(2) + (k * e_ij).powi(2)).sqrt()) / k;
                let got = r.ellipse_fit.as_ref().unwrap().eij[&eij::axes::Eij::new(i, i)];
                assert!(
                    (got - exact).abs() < 1e-9,
                    "{plane} a={accel}: ellipse E{i}{i} = {got}, theory {exact}"
                );
                // The first-order difference from the joint fit is −E_ij ε_ij / 2.
                let second_order = -e_ij * k * e_ij / 2.0;
                let diff = got - r.eij[&eij::axes::Eij::new(i, i)].value;
                assert!(
                    (diff - second_order).abs()
                        <= 2.0 * (k * e_ij.abs().max(e_ii.abs())).powi(2) / k,
                    "{plane} a={accel}: diff {diff} vs {second_order}"
                );
            }
            assert!(r.warnings.is_empty(), "{:?}", r.warnings);
        }
    }
}

/// A 2° servo lag handled by taking the phase from time instead of the internal readings
/// would leak in-talk into cross-talk by about E_aa·sin 2°; the evaluation takes the phase from
/// the internal readings, so a lag of 2° and of 0° give the same EIJ.
#[test]
fn servo_lag_does_not_leak_into_cross_talk() {
    let with_lag = Synth::new(Plane::Zx, true, 10.0).exact();
    let mut no_lag = with_lag.clone();
    no_lag.lag_deg = 0.0;
    let r1 = evaluate(&with_lag.series(), &EvalOptions::default()).unwrap();
    let r0 = evaluate(&no_lag.series(), &EvalOptions::default()).unwrap();
    for p in Plane::Zx.parameters() {
        assert!((r1.eij[&p].value - r0.eij[&p].value).abs() < 1e-9, "{p}");
    }
}

/// A set radius that is no positive number is refused, not used.
#[test]
fn bad_set_radius_is_refused() {
    let s = Synth::new(Plane::Xy, true, 5.0).series();
    for r in [0.0, -2.0, f64::NAN] {
        let opts = EvalOptions {
            radius_mm: Some(r),
            ..Default::default()
        };
        let err = evaluate(&s, &opts).unwrap_err().to_string();
        assert!(err.contains("must be a positive number of mm"), "{err}");
    }
}

/// Long dwells at rest (the plateau is only 7 % of the file) do not hide the plateau: still 5
/// whole revolutions, still exact.
#[test]
fn long_dwells_still_give_the_plateau() {
    let mut syn = Synth::new(Plane::Yz, false, 10.0).exact();
    syn.dwell_s = 3.0;
    let r = evaluate(&syn.series(), &EvalOptions::default()).unwrap();
    assert_eq!(r.revolutions, 5);
    for (p, truth) in syn.truth() {
        assert!(
            (r.eij[&p].value - truth).abs() < 1e-9,
            "{p}: {} vs {truth}",
            r.eij[&p].value
        );
    }
}

/// Noisy internal readings (1 µm, far noisier than linear scales) still give the steady
/// revolutions, and the EIJ within 3 standard errors.
#[test]
fn noisy_internal_readings_are_tolerated() {
    for plane in Plane::ALL {
        let mut syn = Synth::new(plane, false, 4.0);
        syn.int_noise_um = 1.0;
        syn.seed = 5 + plane as u64;
        let r = evaluate(&syn.series(), &EvalOptions::default()).unwrap();
        assert_eq!(r.revolutions, 5);
        for (p, truth) in syn.truth() {
            let z = (r.eij[&p].value - truth) / r.eij[&p].std_err;
            assert!(
                z.abs() < 3.0,
                "{plane} {p}: {} ± {}",
                r.eij[&p].value,
                r.eij[&p].std_err
            );
        }
    }
}

/// Noise-free but with an elliptic internal path (axis radius errors +3/−2 µm): the ellipse
/// route equals the same route applied to the joint fit's model; the first-order truncation
/// (here up to ~E·ε ≈ 0.03 µm·s²/m) cancels.
#[test]
fn ellipse_route_matches_its_joint_prediction() {
    for plane in Plane::ALL {
        let mut syn = Synth::new(plane, true, 10.0);
        syn.noise_um = 0.0;
        let r = evaluate(&syn.series(), &EvalOptions::default()).unwrap();
        let route = r.ellipse_fit.as_ref().unwrap();
        for (p, v) in &route.eij {
            let pred = route.predicted_from_joint[p];
            assert!((v - pred).abs() < 1e-6, "{p}: {v} vs {pred}");
        }
        assert!(r.warnings.is_empty(), "{:?}", r.warnings);
    }
}
