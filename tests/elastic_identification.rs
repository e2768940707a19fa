//! An elastic body's stiffness factor (`<body>.stiffness`) in the identification, beside the
//! guideway factors: the factor scales the reduced body exactly as a scaled Young's and shear
//! modulus does, without a new reduction (checked against a second reduction made from the
//! scaled moduli); it is in the default parameter set, recovered from the EIJ it produced with
//! the others, judged by the identifiability analysis, the plausibility rule for FE models, the
//! bounds, and the experiment design. Machines: `machines/reference/column-mill-beam.toml` (a
//! beam with interior nodes, so that it has fixed-interface modes) and the flexible demo
//! `machines/demo-vmc-flex.toml` with its generator truth.

use eij::axes::{Direction, Plane};
use eij::ident::{identify, IdentError, Parameter, Problem, Settings, TestCase};
use eij::machine::catalogue::Catalogue;
use eij::machine::elastic::{FeBody, Reduction};
use eij::machine::{Machine, Pose};
use eij::mbs::{modal, Model};
use eij::predict::{simulated_eij, CircleTest, SimSettings};
use std::sync::Arc;

mod common;

use common::{machine as load, root};

const FLEX: &str = "demo-vmc-flex.toml";
const FLEX_TRUTH: &str = "measurements/demo-vmc-flex/generator/demo-vmc-flex-true.toml";

fn truth() -> Machine {
    Machine::from_file(&root().join(FLEX_TRUTH)).unwrap()
}

fn reduction(m: &Machine) -> Arc<Reduction> {
    m.bodies()
        .iter()
        .find_map(|b| b.elastic())
        .and_then(|e| e.model().as_any().downcast_ref::<FeBody>())
        .map(|f| f.reduction().clone())
        .expect("an elastic body")
}

fn with_factor(m: &Machine, name: &str, value: f64) -> Machine {
    let mut out = m.clone();
    Parameter::parse(name, m)
        .unwrap()
        .set(&mut out, value)
        .unwrap();
    out
}

/// The same machine with E and G of its beam multiplied by `c`: a new FE model, reduced anew.
fn with_moduli_scaled(m: &Machine, c: f64) -> Machine {
    let mut raw = m.to_raw();
    let beam = raw.bodies.iter_mut().find_map(|b| b.beam.as_mut()).unwrap();
    beam.youngs_modulus_pa *= c;
    beam.shear_modulus_pa *= c;
    Machine::from_raw(raw, &Catalogue::bundled().unwrap(), "moduli scaled").unwrap()
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// Circle tests in `planes` at the circle centres `poses_m`, ccw, 5 m/s².
fn circles(planes: &[Plane], poses_m: &[[f64; 3]]) -> Vec<CircleTest> {
    poses_m
        .iter()
        .flat_map(|p| {
            planes
                .iter()
                .map(|&plane| CircleTest::new(plane, Direction::Ccw, 2.0, 5.0).at(p.to_vec()))
        })
        .collect()
}

/// Noise-free "measurements" of `circles` on `truth`, each value with σ = 0.01 µm·s²/m.
fn measured(truth: &Machine, circles: Vec<CircleTest>) -> Vec<TestCase> {
    let sims = simulated_eij(
        std::slice::from_ref(truth),
        &circles,
        &SimSettings::default(),
    )
    .unwrap()
    .remove(0);
    circles
        .into_iter()
        .zip(sims)
        .map(|(circle, sim)| TestCase {
            source: format!("synthetic {}", circle.label()),
            circle,
            measured: eij::EijEstimates::with_std_err(sim, 0.01),
            clock: None,
        })
        .collect()
}

fn params(machine: &Machine, names: &[&str]) -> Vec<Parameter> {
    names
        .iter()
        .map(|n| Parameter::parse(n, machine).unwrap())
        .collect()
}

#[test]
fn a_stiffness_factor_scales_the_reduced_body_as_scaled_moduli_do_without_a_new_reduction() {
    let base = load("reference/column-mill-beam.toml");
    let r1 = reduction(&base);
    assert!(
        !r1.reduced.fixed_interface_eigenvalues.is_empty(),
        "the test needs a body with interior nodes"
    );
    let pose = Pose::new(&base, &[0.1, -0.1, 0.2]).unwrap();
    let frequencies = |m: &Machine| -> Vec<f64> {
        modal::modes(&Model::assemble(m, &pose).unwrap())
            .unwrap()
            .iter()
            .map(|f| f.frequency_hz)
            .collect()
    };
    let tests = circles(&Plane::ALL, &[[0.1, -0.1, 0.2]]);
    for c in [0.5, 2.0] {
        let by_factor = with_factor(&base, "column.stiffness", c);
        // The factor reuses the reduction: the same object, nothing reduced again.
        assert!(Arc::ptr_eq(&r1, &reduction(&by_factor)));
        let by_moduli = with_moduli_scaled(&base, c);
        let rc = reduction(&by_moduli);
        assert!(!Arc::ptr_eq(&r1, &rc), "scaled moduli are a new FE model");
        // Independent check: the new reduction's fixed-interface and free-free ω² are c times
        // the old ones (frequencies ∝ √c), as the factor assumes. Both come from shift-invert
        // Lanczos runs on different matrices, which agree to ~1e-12 relative.
        let pairs = [
            (
                &r1.reduced.fixed_interface_eigenvalues,
                &rc.reduced.fixed_interface_eigenvalues,
            ),
            (&r1.reduced.eigenvalues, &rc.reduced.eigenvalues),
        ];
        for (old, new) in pairs {
            assert_eq!(old.len(), new.len());
            for (o, n) in old.iter().zip(new.iter()) {
                assert!(rel(*n, c * o) < 1e-9, "ω² {n} against {c} × {o}");
            }
        }
        for (a, b) in r1
            .reduced
            .frequencies_hz(c)
            .iter()
            .zip(rc.reduced.frequencies_hz(1.0))
        {
            assert!(rel(*a, b) < 1e-9, "{a} Hz against {b} Hz");
        }
        // The body's reduced stiffness is exactly c times its unit stiffness.
        let column = base
            .bodies()
            .iter()
            .position(|b| b.name == "column")
            .unwrap();
        let k1 = base.bodies()[column].elastic_matrices().unwrap().0;
        let kc = by_factor.bodies()[column].elastic_matrices().unwrap().0;
        assert_eq!(kc, &k1 * c);
        // The coupled machine: the same modes and the same EIJ either way.
        for (a, b) in frequencies(&by_factor).iter().zip(frequencies(&by_moduli)) {
            assert!((a - b).abs() <= 1e-9 * b.max(1.0), "{a} Hz against {b} Hz");
        }
        let machines = [by_factor, by_moduli];
        let eij = simulated_eij(&machines, &tests, &SimSettings::default()).unwrap();
        for (f, m) in eij[0].iter().zip(&eij[1]) {
            let scale = m.values().fold(0.0f64, |s, v| s.max(v.abs()));
            for (k, v) in m {
                assert!(
                    (f[k] - v).abs() <= 1e-9 * scale,
                    "{k}: {} against {v}",
                    f[k]
                );
            }
        }
    }
}

#[test]
fn every_parameter_set_of_an_identification_shares_the_column_reduction() {
    let machine = load(FLEX);
    let names: Vec<String> = Parameter::default_set(&machine)
        .iter()
        .map(|p| p.name.clone())
        .collect();
    assert_eq!(
        names,
        [
            "x.guideway_normal",
            "x.guideway_lateral",
            "y.guideway_normal",
            "y.guideway_lateral",
            "z.guideway_normal",
            "z.guideway_lateral",
            "column.stiffness"
        ]
    );
    let problem = Problem::new(
        machine.clone(),
        Parameter::default_set(&machine),
        measured(&machine, circles(&[Plane::Yz], &[[0.0, 0.0, 0.0]])),
        Settings::default(),
    )
    .unwrap();
    let r = reduction(&machine);
    for scale in [0.3, 1.7, 4.0] {
        let theta = problem.initial_theta() * scale;
        let m = problem.machine_at(&theta).unwrap();
        assert!(Arc::ptr_eq(&r, &reduction(&m)));
        let column = m.bodies().iter().find_map(|b| b.elastic()).unwrap();
        assert!(rel(column.stiffness_factor(), 1.0 / scale) < 1e-15);
    }
}

#[test]
fn the_default_set_recovers_the_column_and_the_guideways_of_the_flexible_demo() {
    let machine = load(FLEX);
    let truth = truth();
    let tests = measured(
        &truth,
        circles(&Plane::ALL, &[[0.15, -0.1, 0.0], [-0.15, 0.1, 0.25]]),
    );
    let problem = Problem::new(
        machine.clone(),
        Parameter::default_set(&machine),
        tests,
        Settings::default(),
    )
    .unwrap();
    let result = identify(&problem, None).unwrap();
    for q in &result.parameters {
        let want = Parameter::parse(&q.name, &truth).unwrap().get(&truth);
        assert!(q.identifiable && q.std_err.is_some(), "{}", q.name);
        assert!(
            rel(q.value, want) < 1e-3,
            "{} = {} (truth {want})",
            q.name,
            q.value
        );
    }
    // 0.7 on an FE model is plausible: no warning names the column.
    assert!(
        result
            .warnings
            .iter()
            .all(|w| !w.to_string().contains("column")),
        "{:?}",
        result.warnings
    );
    let design = result.design.as_ref().unwrap();
    let k = design
        .parameters
        .iter()
        .position(|n| n == "column.stiffness")
        .unwrap();
    assert!(design.rel_std_err_now[k] > 0.0 && design.rel_std_err_now[k] < 0.1);
    assert!(design.candidates.iter().all(|c| c.rel_std_err.len() == 7));
}

#[test]
fn tests_that_never_move_z_cannot_tell_the_column_from_the_z_guideway_and_the_design_says_where_to_look(
) {
    // xy circles at one centre load neither the Z guideway nor the column in a way that tells
    // them apart: the analysis keeps the column at its start and names the tie; the design
    // proposes a test that moves Z.
    let machine = load(FLEX);
    let truth = truth();
    let tests = measured(&truth, circles(&[Plane::Xy], &[[0.15, -0.1, 0.0]]));
    let names = ["z.guideway_normal", "column.stiffness", "x.guideway_normal"];
    let problem = Problem::new(
        machine.clone(),
        params(&machine, &names),
        tests,
        Settings::default(),
    )
    .unwrap();
    let result = identify(&problem, None).unwrap();
    let column = result
        .not_identifiable
        .iter()
        .find(|n| names[n.index] == "column.stiffness")
        .expect("the column is not identifiable from xy tests");
    assert!(!column.no_influence, "the column does move the xy EIJ");
    assert!(column
        .tied_to
        .iter()
        .any(|(i, _)| names[*i] == "z.guideway_normal"));
    assert_eq!(result.parameters[1].value, 1.0, "kept at its start value");
    let design = result.design.as_ref().unwrap();
    let best = &design.candidates[0];
    assert_ne!(best.circle.plane, Plane::Xy, "{best:?}");
    assert!(
        best.rel_std_err[1] < 0.1 * design.rel_std_err_now[1],
        "{best:?} against {:?}",
        design.rel_std_err_now
    );
}

/// `column.stiffness` alone of the flexible demo, fitted to the noise-free EIJ of the demo
/// with its column's factor `truth` (yz and zx circles at Z = 250 mm).
fn fit_column_alone(truth: f64) -> eij::IdentResult {
    let machine = load(FLEX);
    let truth = with_factor(&machine, "column.stiffness", truth);
    let tests = measured(
        &truth,
        circles(&[Plane::Yz, Plane::Zx], &[[0.0, 0.0, 0.25]]),
    );
    let problem = Problem::new(
        machine.clone(),
        params(&machine, &["column.stiffness"]),
        tests,
        Settings::default(),
    )
    .unwrap();
    identify(&problem, None).unwrap()
}

#[test]
fn a_column_far_softer_than_its_fe_model_is_identified_with_a_warning() {
    let result = fit_column_alone(0.3);
    assert!(rel(result.parameters[0].value, 0.3) < 1e-4);
    let warning = result
        .warnings
        .iter()
        .map(ToString::to_string)
        .find(|w| {
            w.starts_with("column.stiffness = 0.3000 ± ")
                && w.contains("lies below 0.5 beyond its uncertainty")
        })
        .unwrap_or_else(|| panic!("{:?}", result.warnings));
    assert!(warning.contains("FE model") && warning.contains("joints"));
    assert!(result.accepted().is_ok(), "a warning, not a refusal");
}

#[test]
fn a_column_the_data_want_stiffer_than_the_bounds_is_refused_on_its_bound() {
    let result = fit_column_alone(1e3);
    match result.accepted() {
        Err(IdentError::AtBound { name, bound, .. }) => {
            assert_eq!((name.as_str(), bound), ("column.stiffness", 10.0))
        }
        other => panic!("{other:?}"),
    }
}
