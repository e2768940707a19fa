//! Identification on data with the imperfections of real measurements (static geometry, centre
//! offsets, reversal terms, noise), generated from machines with known factors that are not
//! the demo's (tests/common/imperfect.rs says how).

use eij::axes::Plane;
use eij::ident::{identify, IdentResult, Parameter, Problem, Settings, StaticTerms, TestCase};
use eij::machine::Machine;

mod common;

use common::imperfect::{self, Imperfections};
use common::machine;

const COLUMN_MILL: &str = "reference/column-mill.toml";
const POSITIONS_MM: [[f64; 3]; 2] = [[150.0, -100.0, 0.0], [-150.0, 100.0, 100.0]];
/// On this machine the X table's lateral and normal guideway compliance tilt it alike (the
/// analysis names them tied, correlation −1): one factor for both.
const TRUTH: [(&str, f64); 5] = [
    ("x.guideway", 0.5),
    ("y.guideway_normal", 0.4),
    ("y.guideway_lateral", 0.6),
    ("z.guideway_normal", 0.55),
    ("z.guideway_lateral", 0.8),
];

fn with_factors(base: &Machine, truth: &[(&str, f64)]) -> (Vec<Parameter>, Machine) {
    let params: Vec<Parameter> = truth
        .iter()
        .map(|(n, _)| Parameter::parse(n, base).unwrap())
        .collect();
    let mut m = base.clone();
    for (p, (_, v)) in params.iter().zip(truth) {
        p.set(&mut m, *v);
    }
    (params, m)
}

/// 1–2 µm of ellipticity and squareness, a tilted plane and a few µm of centre offset, other
/// for every plane and position; R-Test noise σ = 1.4 µm.
fn geometry(plane: Plane, pos: [f64; 3]) -> Imperfections {
    let k = plane as usize as f64 + if pos[0] > 0.0 { 0.0 } else { 3.0 };
    let s = if pos[0] > 0.0 { 1.0 } else { -1.0 };
    Imperfections {
        // On r = 2 mm: ±0.75 µm/mm is ±1.5 µm on the radius.
        g_um_per_mm: [
            [0.75 * s, 0.5 - 0.1 * k],
            [0.4 - 0.05 * k, -0.6 * s],
            [0.3, -0.2 * s],
        ],
        offset_um: [3.0 - k, -2.0 + 0.5 * k, 4.0],
        noise_um: 1.4,
        ..Default::default()
    }
}

fn assert_recovered(result: &IdentResult, truth: &[(&str, f64)]) {
    assert!(result.refusal.is_none(), "{:?}", result.refusal);
    for (q, (name, t)) in result.parameters.iter().zip(truth) {
        assert_eq!(&q.name, name);
        let se = q.std_err.unwrap_or_else(|| panic!("{name} not identified"));
        assert!(
            (q.value - t).abs() < 3.0 * se,
            "{name} = {} ± {se}, truth {t}",
            q.value
        );
    }
}

fn run(
    machine: &Machine,
    params: &[Parameter],
    tests: &[TestCase],
    mode: StaticTerms,
) -> IdentResult {
    let settings = Settings {
        static_terms: mode,
        design: false,
        ..Default::default()
    };
    let problem = Problem::new(machine.clone(), params.to_vec(), tests.to_vec(), settings).unwrap();
    identify(&problem, None).unwrap()
}

#[test]
fn static_geometry_on_another_machine_is_fitted_and_the_factors_recovered() {
    let base = machine(COLUMN_MILL);
    let (params, truth) = with_factors(&base, &TRUTH);
    let planned = imperfect::grid(&POSITIONS_MM, &Plane::ALL, &[2.0, 5.0, 8.0]);
    let tests = imperfect::tests(&truth, &planned, geometry, 100);
    let result = run(&base, &params, &tests, StaticTerms::Auto);
    assert_recovered(&result, &TRUTH);
    assert!(result.residual_std < 1.3, "s = {}", result.residual_std);
    // The geometry itself is recovered: every shared term within 3.5 standard errors (36
    // terms) of what was put in.
    let mut worst: f64 = 0.0;
    for e in &result.static_estimates {
        let g = &result.statics.groups[e.group];
        let put = geometry(g.plane, [g.position_m[0] * 1e3, 0.0, 0.0]).g_um_per_mm;
        let (a, b) = g.plane.axes();
        let row = [a, b, g.plane.normal()]
            .iter()
            .position(|&x| x == e.eij.deviation)
            .unwrap();
        let col = if e.eij.accelerated == a { 0 } else { 1 };
        let z = (e.value_um_per_mm - put[row][col]) / e.std_err_um_per_mm;
        worst = worst.max(z.abs());
    }
    assert!(
        worst < 3.5,
        "a static term is {worst:.1} standard errors off"
    );
    assert_eq!(result.static_estimates.len(), 36);
    // No reversal terms: the geometry is the same for cw and ccw.
    assert!(result.statics.groups.iter().all(|g| !g.reversal));

    // The same data with every test taken alone: the geometry biases the factors far beyond
    // their standard errors (what the issue saw: factors off by 30–220 %).
    let alone = run(&base, &params, &tests, StaticTerms::None);
    let off = alone
        .parameters
        .iter()
        .zip(&TRUTH)
        .filter_map(|(q, (_, t))| q.std_err.map(|se| (q.value - t).abs() / se))
        .fold(0.0, f64::max);
    assert!(
        off > 5.0,
        "without static terms the worst factor is only {off:.1} σ off"
    );
}

#[test]
fn a_reversal_term_is_added_where_the_data_need_it() {
    // Group zx at the first position carries 0.5 µm/mm of a direction-dependent term; the
    // others only shared geometry.
    let base = machine(COLUMN_MILL);
    let (params, truth) = with_factors(&base, &TRUTH);
    let planned = imperfect::grid(&POSITIONS_MM, &Plane::ALL, &[2.0, 5.0, 8.0]);
    let imp = |plane: Plane, pos: [f64; 3]| {
        let mut i = geometry(plane, pos);
        if plane == Plane::Zx && pos[0] > 0.0 {
            i.reversal_um_per_mm = [[0.5, 0.0], [0.0, 0.5], [0.0, 0.0]];
        }
        i
    };
    let tests = imperfect::tests(&truth, &planned, imp, 300);
    let result = run(&base, &params, &tests, StaticTerms::Auto);
    let with: Vec<String> = result
        .statics
        .groups
        .iter()
        .filter(|g| g.reversal)
        .map(|g| g.label())
        .collect();
    assert_eq!(
        with,
        vec!["zx @ 150,-100,0 mm".to_string()],
        "{:?}",
        result.notes
    );
    assert!(result.notes.iter().any(|n| n.contains("reversal terms")));
    assert_recovered(&result, &TRUTH);
}

#[test]
fn a_trial_step_that_cannot_be_simulated_is_rejected_not_fatal() {
    // The demo data with the catalogue guideways and only the Z screw free: the data want the
    // screw so soft that the Z drive's closed loop goes unstable (below about 0.09 with its
    // gains). σ is taken ten times smaller than measured, so that the screw is identifiable
    // from the start. Trial steps beyond the limit are rejected (not an abort); the fit ends at
    // the limit and is refused with that diagnosis.
    let base = common::demo();
    let mut tests = eij::ident::measured::load(
        &[common::root().join("measurements/demo-vmc")],
        &Default::default(),
    )
    .unwrap();
    for t in &mut tests {
        for v in t.measured.values_mut() {
            v.1 *= 0.1;
        }
    }
    let params = vec![Parameter::parse("z.screw", &base).unwrap()];
    let result = run(&base, &params, &tests, StaticTerms::Auto);
    assert!(result.rejected_steps > 0, "no trial step was unstable");
    match &result.refusal {
        Some(eij::ident::IdentError::AtSimulationLimit { names, .. }) => {
            assert!(names.starts_with("z.screw"), "{names}")
        }
        other => panic!("expected a refusal at the simulation limit, got {other:?}"),
    }
    assert!(result.parameters[0].value < 0.2 && result.parameters[0].value > 0.05);
    assert!(result
        .notes
        .iter()
        .any(|n| n.contains("could not be simulated")));
}
