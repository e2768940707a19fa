//! Identification against synthetic data with known reduction factors.

use eij::axes::{Direction, EijEstimates, Plane};
use eij::ident::{identify, IdentError, Parameter, Problem, Settings, TestCase};
use eij::machine::Machine;
use eij::predict::{simulated_eij, CircleTest};

mod common;

use common::{demo_text, root};

fn conditions(planes: &[Plane], accels: &[f64]) -> Vec<TestCase> {
    let mut v = Vec::new();
    for &plane in planes {
        for &accel_m_s2 in accels {
            v.push(TestCase {
                source: format!("synthetic {plane} {accel_m_s2}"),
                circle: CircleTest::new(plane, Direction::Ccw, 2.0, accel_m_s2)
                    .at(vec![0.15, -0.1, 0.0]),
                measured: Default::default(),
                clock: None,
            });
        }
    }
    v
}

/// "Measured" EIJ: the model with the true factors, evaluated exactly as identification does.
fn synthetic(truth: &Machine, tests: &mut [TestCase], settings: &Settings) {
    let circles: Vec<CircleTest> = tests.iter().map(|t| t.circle.clone()).collect();
    let sims = simulated_eij(std::slice::from_ref(truth), &circles, &settings.simulation)
        .unwrap()
        .remove(0);
    for (t, sim) in tests.iter_mut().zip(sims) {
        t.measured = EijEstimates::with_std_err(sim, 0.02);
    }
}

#[test]
fn noise_free_factors_are_recovered_from_catalogue_start() {
    let machine = Machine::from_toml_str(&demo_text(), "demo").unwrap();
    let names = ["x.guideway", "y.guideway", "z.guideway"];
    let truth_values = [0.35, 0.5, 0.7];
    let params: Vec<Parameter> = names
        .iter()
        .map(|n| Parameter::parse(n, &machine).unwrap())
        .collect();
    let mut truth = machine.clone();
    for (p, v) in params.iter().zip(truth_values) {
        p.set(&mut truth, v).unwrap();
    }
    let settings = Settings::default();
    let mut tests = conditions(&Plane::ALL, &[3.0, 7.0]);
    synthetic(&truth, &mut tests, &settings);
    let problem = Problem::new(machine, params, tests, settings).unwrap();
    let result = identify(&problem, None).unwrap();
    for (q, want) in result.parameters.iter().zip(truth_values) {
        assert_eq!(q.initial, 1.0);
        assert!(
            ((q.value - want) / want).abs() < 1e-4,
            "{} = {} (truth {want})",
            q.name,
            q.value
        );
        assert!(q.identifiable);
    }
    assert!(result.cost_final < 1e-6 * result.cost_initial);
}

/// The demo machine with its bed fixed to the ground: the spindle head (Z) is then decoupled
/// from table and saddle, so XY circles cannot see the Z guideway at all.
fn fixed_bed_machine() -> Machine {
    let text = demo_text()
        .replace("name = \"bed\"            # bed and column, one casting on four levelling feet\nmass_kg = 6000.0", "name = \"bed\"\nfixed = true\nmass_kg = 6000.0")
        .split("[[joint]]")
        .next()
        .unwrap()
        .to_string()
        + &demo_text()[demo_text().find("# ---------------------------------------------------------------- X").unwrap()..];
    let machine = Machine::from_toml_str(&text, "fixed-bed").unwrap();
    assert!(
        machine
            .bodies()
            .iter()
            .any(|b| b.name == "bed" && b.is_fixed())
            && machine.joints().is_empty()
    );
    machine
}

#[test]
fn a_parameter_without_influence_is_reported_not_identifiable() {
    let machine = fixed_bed_machine();
    let params: Vec<Parameter> = ["x.guideway", "y.guideway", "z.guideway_normal"]
        .iter()
        .map(|n| Parameter::parse(n, &machine).unwrap())
        .collect();
    let mut truth = machine.clone();
    params[0].set(&mut truth, 0.6).unwrap();
    params[1].set(&mut truth, 0.8).unwrap();
    let settings = Settings::default();
    let mut tests = conditions(&[Plane::Xy], &[2.0, 5.0, 8.0]);
    synthetic(&truth, &mut tests, &settings);
    let problem = Problem::new(machine, params, tests, settings).unwrap();
    let result = identify(&problem, None).unwrap();
    let z = &result.parameters[2];
    assert!(
        !z.identifiable && z.std_err.is_none() && z.value == 1.0,
        "{z:?}"
    );
    assert!(result.warnings.iter().any(|w| w
        .to_string()
        .starts_with("z.guideway_normal is not identifiable")));
    assert!((result.parameters[0].value / 0.6 - 1.0).abs() < 1e-4);
    assert!((result.parameters[1].value / 0.8 - 1.0).abs() < 1e-4);
}

#[test]
fn no_overlap_between_parameters_and_tests_is_an_error() {
    let machine = fixed_bed_machine();
    let params = vec![Parameter::parse("z.guideway", &machine).unwrap()];
    let settings = Settings::default();
    let mut tests = conditions(&[Plane::Xy], &[3.0, 6.0]);
    synthetic(&machine, &mut tests, &settings);
    let problem = Problem::new(machine, params, tests, settings).unwrap();
    match identify(&problem, None) {
        Err(IdentError::NoData(m)) => {
            assert!(m.contains("no overlap between parameters and tests"), "{m}")
        }
        other => panic!("expected NoData, got {:?}", other.map(|r| r.parameters)),
    }
}

#[test]
fn tests_without_values_or_in_a_plane_the_model_lacks_are_refused() {
    let machine = Machine::from_toml_str(&demo_text(), "demo").unwrap();
    let params = Parameter::default_set(&machine);
    let err = Problem::new(
        machine,
        params,
        conditions(&[Plane::Zx], &[4.0]),
        Settings::default(),
    )
    .unwrap_err();
    assert_eq!(err.to_string(), "synthetic zx 4: no EIJ values");
    let single = Machine::from_file(&root().join("machines/reference/single-axis.toml")).unwrap();
    let mut tests = conditions(&[Plane::Xy], &[4.0]);
    tests[0].circle.position_m = None;
    tests[0].measured.insert(
        eij::axes::Eij::new(eij::axes::Axis::X, eij::axes::Axis::X),
        -1.0,
        0.02,
    );
    let err = Problem::new(
        single.clone(),
        Parameter::default_set(&single),
        tests,
        Settings::default(),
    )
    .unwrap_err();
    assert!(
        err.to_string()
            .contains("plane xy needs axis y, which the model single-axis does not have"),
        "{err}"
    );
}

#[test]
fn noisy_demo_set_recovers_the_generator_truth_within_three_standard_errors() {
    // measurements/demo-vmc was generated from demo-vmc-true.toml with R-Test noise σ = 1.4 µm.
    let machine = Machine::from_file(&root().join("machines/demo-vmc.toml")).unwrap();
    let tests =
        eij::ident::measured::load(&[root().join("measurements/demo-vmc")], &Default::default())
            .unwrap();
    assert_eq!(tests.len(), 36);
    let problem = Problem::new(
        machine.clone(),
        Parameter::default_set(&machine),
        tests,
        Settings::default(),
    )
    .unwrap();
    let result = identify(&problem, None).unwrap();
    let truth = [0.45, 0.60, 0.35, 0.50, 0.40, 0.70];
    for (q, t) in result.parameters.iter().zip(truth) {
        let se = q.std_err.unwrap();
        assert!(
            (q.value - t).abs() < 3.0 * se,
            "{} = {} ± {se}, truth {t}",
            q.name,
            q.value
        );
    }
    // The fit is at the noise level: s ≈ 1 (σ from the evaluation's standard errors).
    assert!(
        result.residual_std > 0.8 && result.residual_std < 1.25,
        "s = {}",
        result.residual_std
    );
    // Catalogue model under-predicts the in-talk by a factor 2–3 before, not after.
    let t = &problem.tests()[0];
    let (e, m) = t.measured.iter().find(|(e, _)| e.is_in_talk()).unwrap();
    let before = result.simulated_initial[0][e] / m.value;
    let after = result.simulated_final[0][e] / m.value;
    assert!(before > 0.3 && before < 0.5, "catalogue/measured {before}");
    assert!((after - 1.0).abs() < 0.05, "identified/measured {after}");
}
