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
        p.set(&mut m, *v).unwrap();
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
    for e in result.static_estimates.iter().filter(|e| e.clock.is_none()) {
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
    assert_eq!(
        result.static_estimates.len(),
        36 + 1,
        "36 geometric terms and one clock"
    );
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
    assert!(result.notes.iter().any(|n| matches!(
        n,
        eij::ident::Note::ReversalTermsFitted { group } if group == "zx @ 150,-100,0 mm"
    )));
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
        for (_, v) in t.measured.iter_mut() {
            v.std_err *= 0.1;
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
        .any(|n| matches!(n, eij::ident::Note::RejectedSteps { count } if *count == result.rejected_steps)));
}

#[test]
fn nine_factors_with_known_screw_factors_are_recovered() {
    // The demo machine with the demo's guideway truth and screw factors of its own (the
    // bundled demo's truth has none), measured as the demo is: two circle centres, three
    // planes, both directions, 2/5/8 m/s². Noise σ = 0.7 µm (the R-Test's 1.4 µm halved, e.g.
    // two runs averaged): with 1.4 µm these tests do not determine the Z screw (predicted
    // standard error 138 % of its value), and identify names it not identifiable instead.
    let base = common::demo();
    let truth_values = [
        ("x.guideway_normal", 0.45),
        ("x.guideway_lateral", 0.60),
        ("x.screw", 0.7),
        ("y.guideway_normal", 0.35),
        ("y.guideway_lateral", 0.50),
        ("y.screw", 0.8),
        ("z.guideway_normal", 0.40),
        ("z.guideway_lateral", 0.70),
        ("z.screw", 0.6),
    ];
    let (params, truth) = with_factors(&base, &truth_values);
    let demo_positions = [[150.0, -100.0, 0.0], [-150.0, 100.0, 0.0]];
    let planned = imperfect::grid(&demo_positions, &Plane::ALL, &[2.0, 5.0, 8.0]);
    let noisy = |_: Plane, _: [f64; 3]| Imperfections {
        noise_um: 0.7,
        ..Default::default()
    };
    let tests = imperfect::tests(&truth, &planned, noisy, 700);
    let result = run(&base, &params, &tests, StaticTerms::Auto);
    assert_recovered(&result, &truth_values);
    assert!(result.residual_std < 1.3, "s = {}", result.residual_std);
}

#[test]
fn one_plane_names_the_factors_it_cannot_determine_and_ranks_tests_that_would() {
    // Only the XY circles at one circle centre of the demo data, the six guideway factors:
    // the Z guideways (tilting the spindle head) are hardly seen in XY. They are named, kept
    // at their start value and not mistaken for a bound error; the best candidate test is in
    // another plane.
    let base = common::demo();
    let dir = common::root().join("measurements/demo-vmc/pos-a");
    let files: Vec<std::path::PathBuf> = [
        "xy_ccw_2", "xy_ccw_5", "xy_ccw_8", "xy_cw_2", "xy_cw_5", "xy_cw_8",
    ]
    .iter()
    .map(|f| dir.join(format!("{f}.csv")))
    .collect();
    let tests = eij::ident::measured::load(&files, &Default::default()).unwrap();
    let problem = Problem::new(
        base.clone(),
        Parameter::default_set(&base),
        tests,
        Settings::default(),
    )
    .unwrap();
    let result = identify(&problem, None).unwrap();
    assert!(result.refusal.is_none(), "{:?}", result.refusal);
    let held: Vec<&str> = result
        .parameters
        .iter()
        .filter(|q| !q.identifiable)
        .map(|q| q.name.as_str())
        .collect();
    assert!(held.iter().any(|n| n.starts_with("z.")), "{held:?}");
    for q in result.parameters.iter().filter(|q| !q.identifiable) {
        assert_eq!(q.value, q.initial);
        assert!(!q.at_bound);
        assert!(
            result.warnings.iter().any(|w| w
                .to_string()
                .starts_with(&format!("{} is not identifiable", q.name))),
            "{:?}",
            result.warnings
        );
    }
    assert!(result
        .warnings
        .iter()
        .all(|w| !w.to_string().contains("bound")));
    // The partners' values are conditional on the held one, and the warning says so.
    for w in result
        .warnings
        .iter()
        .map(ToString::to_string)
        .filter(|w| w.contains("cannot separate it from"))
    {
        assert!(w.contains("hold only for"), "{w}");
    }
    let design = result.design.as_ref().unwrap();
    let (now, _) = design.worst_now();
    let best = &design.candidates[0];
    assert_ne!(best.circle.plane, Plane::Xy);
    assert!(
        best.worst_rel_std_err < 0.5 * now,
        "{} vs {now}",
        best.worst_rel_std_err
    );
}

#[test]
fn held_out_tests_are_predicted_within_their_uncertainty() {
    // Fit the demo at 2 and 8 m/s², predict the 5 m/s² circles.
    let base = common::demo();
    let root = common::root().join("measurements/demo-vmc");
    let (mut fit, mut hold) = (Vec::new(), Vec::new());
    for pos in ["pos-a", "pos-b"] {
        for plane in ["xy", "yz", "zx"] {
            for d in ["cw", "ccw"] {
                for a in ["2", "8"] {
                    fit.push(root.join(format!("{pos}/{plane}_{d}_{a}.csv")));
                }
                hold.push(root.join(format!("{pos}/{plane}_{d}_5.csv")));
            }
        }
    }
    let load =
        |f: &[std::path::PathBuf]| eij::ident::measured::load(f, &Default::default()).unwrap();
    let settings = Settings {
        design: false,
        ..Default::default()
    };
    let problem = Problem::new(
        base.clone(),
        Parameter::default_set(&base),
        load(&fit),
        settings.clone(),
    )
    .unwrap();
    let result = identify(&problem, None).unwrap();
    let cov = eij::ident::validation::ParameterCovariance::of(problem.parameters(), &result);
    let v = eij::ident::validation::validate(&result.machine, Some(&cov), load(&hold), &settings)
        .unwrap();
    assert!(v.passed, "χ²/dof = {}", v.chi2_per_dof);
    assert_eq!(v.tests.len(), 12);
    assert!(v.tests.iter().all(|t| t.rms_z < 3.0));
    // The catalogue model does not predict them: the validation can fail.
    let v0 = eij::ident::validation::validate(&base, None, load(&hold), &settings).unwrap();
    assert!(
        !v0.passed && v0.chi2_per_dof > 100.0,
        "χ²/dof = {}",
        v0.chi2_per_dof
    );
}

#[test]
fn a_probe_logger_lag_is_fitted_not_taken_for_cross_talk() {
    // The R-Test logger lags the scales by 0.1 ms on top of the geometry: δ·v is 10 µm on a
    // 2 mm circle at 8 Hz and would pass as antisymmetric in-plane cross-talk of about
    // 2 µm·s²/m. With cw and ccw in every folder the offset is fitted with the EIJ. (The lag's
    // second-order term δ²/2·ä biases the in-talk by 10⁶·δ²/2 µm·s²/m — 0.005 here, 0.02 at
    // 0.2 ms — and is not yet corrected: docs/identification.md.)
    let base = machine(COLUMN_MILL);
    let (params, truth) = with_factors(&base, &TRUTH);
    let planned = imperfect::grid(&POSITIONS_MM, &Plane::ALL, &[2.0, 5.0, 8.0]);
    let lagging = |plane: Plane, pos: [f64; 3]| Imperfections {
        lag_s: 0.1e-3,
        ..geometry(plane, pos)
    };
    let tests = imperfect::tests(&truth, &planned, lagging, 900);
    let result = run(&base, &params, &tests, StaticTerms::Auto);
    assert_recovered(&result, &TRUTH);
    let clocks = eij::ident::diagnosis::fitted_clocks(&result);
    assert_eq!(clocks.len(), 1);
    let c = &clocks[0];
    assert!(
        // Within 3 % (the path's speed is taken as the set speed; this machine's servo radius
        // errors are about 1 %) plus 3 standard errors.
        (c.external_late_ms - 0.1).abs() < 0.003 + 3.0 * c.std_err_ms && c.std_err_ms < 0.01,
        "fitted lag {} ± {} ms, put in 0.1 ms",
        c.external_late_ms,
        c.std_err_ms
    );
}
