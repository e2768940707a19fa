//! Hold-out validation counts every uncertainty (issue 28 item 4): the prediction of held-out
//! tests carries the identified parameters' covariance, C = I + J Σ Jᵀ in units of σ, and the
//! held-out groups' static terms are fitted on them (generalised least squares).

use eij::ident::validation::{validate, HeldOut, ParameterCovariance};
use eij::ident::{Problem, TestCase};
use nalgebra::{DMatrix, DVector};
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};

mod common;

/// C⁻¹ = I − u uᵀ·c/(1 + c·uᵀu) for C = I + c·u uᵀ (Sherman–Morrison), written out.
fn inverse_rank_one(u: &[f64], c: f64) -> DMatrix<f64> {
    let m = u.len();
    let uu: f64 = u.iter().map(|x| x * x).sum();
    DMatrix::from_fn(m, m, |i, k| {
        let delta = if i == k { 1.0 } else { 0.0 };
        delta - c * u[i] * u[k] / (1.0 + c * uu)
    })
}

#[test]
fn the_held_out_chi2_of_a_linear_toy_model_is_the_hand_calculation() {
    // Four held-out values, one parameter: sensitivity j, variance Σ = 0.25.
    let j = [1.0, 2.0, 0.0, -1.0];
    let e = [0.5, 1.5, -0.3, 0.2];
    let sigma2 = 0.25;
    let jm = DMatrix::from_column_slice(4, 1, &j);
    let ev = DVector::from_column_slice(&e);
    let cov = DMatrix::from_element(1, 1, sigma2);
    let held = HeldOut::new(&ev, &jm, &cov, &DMatrix::zeros(4, 0)).unwrap();
    // χ² = eᵀe − Σ(jᵀe)²/(1 + Σ jᵀj): eᵀe = 2.63, jᵀe = 3.3, jᵀj = 6.
    let hand = 2.63 - 0.25 * 3.3 * 3.3 / (1.0 + 0.25 * 6.0);
    assert!((held.chi2 - hand).abs() < 1e-12, "{} vs {hand}", held.chi2);
    assert_eq!(held.dof, 4);
    // Per value z = e/√(1 + Σ jᵢ²).
    let z = held.z();
    for i in 0..4 {
        let want = e[i] / (1.0 + sigma2 * j[i] * j[i]).sqrt();
        assert!((z[i] - want).abs() < 1e-12);
    }
    // Without the parameter's uncertainty: χ² = eᵀe.
    let exact = HeldOut::new(&ev, &jm, &DMatrix::zeros(1, 1), &DMatrix::zeros(4, 0)).unwrap();
    assert!((exact.chi2 - 2.63).abs() < 1e-12);

    // One static term a (a geometric offset of the held-out set-up), fitted by generalised
    // least squares: χ² = eᵀC⁻¹e − (aᵀC⁻¹e)²/(aᵀC⁻¹a), one degree of freedom fewer.
    let a = [0.5, 0.25, 1.0, 0.2];
    let am = DMatrix::from_column_slice(4, 1, &a);
    let held = HeldOut::new(&ev, &jm, &cov, &am).unwrap();
    let ci = inverse_rank_one(&j, sigma2);
    let av = DVector::from_column_slice(&a);
    let q = |x: &DVector<f64>, y: &DVector<f64>| (x.transpose() * &ci * y)[(0, 0)];
    let hand = q(&ev, &ev) - q(&av, &ev).powi(2) / q(&av, &av);
    assert!((held.chi2 - hand).abs() < 1e-12, "{} vs {hand}", held.chi2);
    assert_eq!(held.dof, 3);
    // The residual is e + a·ĝ with ĝ = −aᵀC⁻¹e/aᵀC⁻¹a.
    let g = -q(&av, &ev) / q(&av, &av);
    for i in 0..4 {
        assert!((held.residual[i] - (e[i] + a[i] * g)).abs() < 1e-12);
    }
}

#[test]
fn a_linear_toy_identification_predicts_held_out_values_with_chi2_one_on_average() {
    // E = X θ (a quadratic in t): fit θ on 12 noisy values at t in [0, 1] (σ = 1), predict 40
    // values at t in [0, 1.3] with one static term. Over many repetitions χ²/dof must average 1 when the parameters'
    // covariance is counted, and lie above 1 when it is not.
    let mut rng = rand::rngs::StdRng::seed_from_u64(28);
    let unit = Normal::new(0.0, 1.0).unwrap();
    let theta = DVector::from_column_slice(&[1.0, -2.0, 0.5]);
    let x_fit = DMatrix::from_fn(12, 3, |i, k| (i as f64 / 11.0).powi(k as i32));
    let x_hold = DMatrix::from_fn(40, 3, |i, k| (i as f64 / 30.0).powi(k as i32));
    let a = DMatrix::from_fn(40, 1, |i, _| 1.0 / (1.0 + (i % 4) as f64));
    let cov = (x_fit.transpose() * &x_fit).try_inverse().unwrap();
    let runs = 2000;
    let (mut with, mut without) = (0.0, 0.0);
    for _ in 0..runs {
        let y_fit = &x_fit * &theta + DVector::from_fn(12, |_, _| unit.sample(&mut rng));
        let theta_hat = &cov * x_fit.transpose() * y_fit;
        let offset = 0.7;
        let y_hold =
            &x_hold * &theta - &a * offset + DVector::from_fn(40, |_, _| unit.sample(&mut rng));
        let e = &x_hold * &theta_hat - y_hold;
        with += HeldOut::new(&e, &x_hold, &cov, &a).unwrap().chi2 / 39.0;
        without += HeldOut::new(&e, &x_hold, &DMatrix::zeros(3, 3), &a)
            .unwrap()
            .chi2
            / 39.0;
    }
    let (with, without) = (with / runs as f64, without / runs as f64);
    // Mean of χ²/dof over 2000 runs: standard error √(2/39)/√2000 = 0.005.
    assert!((with - 1.0).abs() < 4.0 * 0.005, "χ²/dof = {with}");
    assert!(without > 1.3, "without the covariance χ²/dof = {without}");
}

fn demo_tests(folder: &str) -> Vec<TestCase> {
    let path = common::root().join("measurements/demo-vmc").join(folder);
    eij::ident::measured::load(&[path], &Default::default()).unwrap()
}

#[test]
fn the_exact_demo_model_passes_hold_out_validation_both_ways() {
    // Before the parameters' covariance was counted, pos-a → pos-b failed (χ²/dof = 1.74
    // over 89 degrees of freedom) while the reverse passed, on the very model that generated
    // the data. The pass limit is 1 + 4·√(2/dof).
    for (fitted, held) in [("pos-a", "pos-b"), ("pos-b", "pos-a")] {
        let (problem, result) = common::fit_demo(demo_tests(fitted));
        let cov = ParameterCovariance::of(problem.parameters(), &result);
        let v = validate(
            &result.machine,
            Some(&cov),
            demo_tests(held),
            problem.settings(),
        )
        .unwrap();
        let limit = 1.0 + 4.0 * (2.0 / v.dof as f64).sqrt();
        assert_eq!(
            (v.values, v.dof),
            (108, 108 - 18 - 1),
            "18 static terms, one clock"
        );
        assert!(
            v.passed && v.chi2_per_dof <= limit,
            "{fitted} → {held}: χ²/dof = {} > {limit}",
            v.chi2_per_dof
        );
        assert!(v.chi2_per_dof <= v.chi2_per_dof_measurement_only + 1e-9);
        if fitted == "pos-a" {
            assert!(
                v.chi2_per_dof_measurement_only > limit,
                "the failure counted without the covariance: {}",
                v.chi2_per_dof_measurement_only
            );
        }
    }
}

#[test]
fn the_prediction_variance_matches_simulations_of_parameters_drawn_from_their_covariance() {
    // Independent of the Jacobian: draw θ ~ N(θ̂, Σ), simulate the held-out tests, and compare
    // the summed variance of the simulated EIJ with Σ over tests of count·rms σ_pred².
    let (problem, result) = common::fit_demo(demo_tests("pos-a"));
    let cov = ParameterCovariance::of(problem.parameters(), &result);
    let held = demo_tests("pos-b");
    let v = validate(
        &result.machine,
        Some(&cov),
        held.clone(),
        problem.settings(),
    )
    .unwrap();
    let predicted: f64 = v
        .tests
        .iter()
        .zip(&held)
        .map(|(t, c)| c.measured.len() as f64 * t.rms_prediction_sigma_um_s2_per_m.powi(2))
        .sum();
    let sim = Problem::new(
        result.machine.clone(),
        problem.parameters().to_vec(),
        held,
        problem.settings().clone(),
    )
    .unwrap();
    let centre = sim.initial_theta();
    let l = cov.theta.clone().cholesky().unwrap().l();
    let mut rng = rand::rngs::StdRng::seed_from_u64(7);
    let unit = Normal::new(0.0, 1.0).unwrap();
    let n = centre.len();
    let draws: Vec<DVector<f64>> = (0..400)
        .map(|_| &centre + &l * DVector::from_fn(n, |_, _| unit.sample(&mut rng)))
        .collect();
    let sims = sim.simulate_many(&draws).unwrap();
    let rows = sim.rows();
    // Per draw: ‖E(θ_k) − mean‖² over every held-out value, µm·s²/m.
    let values: Vec<Vec<f64>> = sims
        .iter()
        .map(|s| rows.iter().map(|r| s[r.test][&r.eij]).collect())
        .collect();
    let mean: Vec<f64> = (0..rows.len())
        .map(|i| values.iter().map(|v| v[i]).sum::<f64>() / values.len() as f64)
        .collect();
    let spread: Vec<f64> = values
        .iter()
        .map(|v| v.iter().zip(&mean).map(|(x, m)| (x - m).powi(2)).sum())
        .collect();
    let k = spread.len() as f64;
    let mc = spread.iter().sum::<f64>() / (k - 1.0);
    let sd = (spread.iter().map(|s| (s - mc).powi(2)).sum::<f64>() / (k - 1.0)).sqrt() / k.sqrt();
    assert!(
        (mc - predicted).abs() < 4.0 * sd,
        "Monte Carlo {mc:.3e} ± {sd:.1e} vs J Σ Jᵀ {predicted:.3e}"
    );
}
