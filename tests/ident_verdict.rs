//! How an identification is read (`eij::ident::verdict`): each parameter's standing from its
//! relative standard error, the χ² test, and the report's own keys overruling a bare
//! `identifiable: true`.

use eij::ident::report::IdentReport;
use eij::ident::verdict::{implausible, Chi2, Implausible, Standing};

#[test]
fn standing_follows_the_relative_standard_error() {
    // The example: 9.998 ± 86 is 860 % — nothing is known about it.
    let s = Standing::of(9.998, Some(86.0), true, false);
    assert_eq!(s, Standing::NotDetermined { rel: 86.0 / 9.998 });
    assert!(!s.usable());
    assert_eq!(s.label(), "NOT determined");
    assert_eq!(Standing::of(0.4, Some(0.3), true, false).label(), "weak");
    assert_eq!(Standing::of(0.4, Some(0.1), true, false).label(), "loose");
    assert_eq!(
        Standing::of(0.4, Some(0.04), true, false).label(),
        "determined"
    );
    assert_eq!(Standing::of(0.4, Some(0.041), true, false).label(), "loose");
    assert_eq!(
        Standing::of(0.4, None, true, false),
        Standing::NotIdentifiable
    );
    assert_eq!(
        Standing::of(0.4, Some(0.01), false, false),
        Standing::NotIdentifiable
    );
    assert_eq!(
        Standing::of(10.0, Some(0.01), true, true),
        Standing::OnBound
    );
    assert_eq!(
        Standing::of(0.4, Some(f64::NAN), true, false).label(),
        "NOT determined"
    );
    assert!(implausible("x.guideway", 1.2, None) && implausible("x.screw", 0.05, None));
    assert!(!implausible("z.guideway_normal", 0.45, Some(0.01)));
    // An elastic body's factor is judged against its FE model, not a catalogue: 1.2 and 0.7
    // are plausible, a factor of 2 either way is not.
    assert!(
        !implausible("column.stiffness", 1.2, Some(0.01))
            && !implausible("column.stiffness", 0.7, Some(0.01))
    );
    assert!(
        implausible("column.stiffness", 0.45, Some(0.01))
            && implausible("column.stiffness", 2.1, Some(0.01))
    );
}

/// The 3σ interval in the compliance θ = 1/p, by hand: [1/(θ + 3σ/p²), 1/(θ − 3σ/p²)].
fn interval_by_hand(p: f64, sigma: f64) -> (f64, f64) {
    let (theta, s) = (1.0 / p, sigma / (p * p));
    (1.0 / (theta + 3.0 * s), 1.0 / (theta - 3.0 * s))
}

#[test]
fn a_factor_is_implausible_only_beyond_its_uncertainty() {
    // Issue 28 leftover: 1.0003 within its standard error of 1 raised "stiffer than the
    // catalogue". Now a factor is implausible only when its whole 3σ interval (in 1/p, the
    // one identify prints) lies outside the plausible range.
    let (low, _) = interval_by_hand(1.0003, 0.0010);
    assert!(low < 1.0, "{low}"); // 0.99731: it may well be 1
    assert!(!implausible("x.guideway_normal", 1.0003, Some(0.0010)));
    assert_eq!(
        Implausible::of("x.guideway_normal", 1.0003, Some(0.0010)),
        None
    );
    let (low, _) = interval_by_hand(1.03, 0.0010);
    assert!(low > 1.0, "{low}"); // 1.0270: stiffer beyond doubt
    assert_eq!(
        Implausible::of("x.guideway_normal", 1.03, Some(0.0010)),
        Some(Implausible::StifferThanCatalogue)
    );
    // Just either side of the edge: low = 1 exactly at p with 1/p + 3σ/p² = 1, i.e.
    // σ = p²·(1 − 1/p)/3 = p(p − 1)/3.
    let p = 1.05;
    let edge = p * (p - 1.0) / 3.0;
    assert!(implausible("y.screw", p, Some(edge * 0.99)));
    assert!(!implausible("y.screw", p, Some(edge * 1.01)));
    // Far softer: 0.05 ± 0.002 ([0.0446, 0.0568]) is below 0.1 beyond doubt; 0.09 ± 0.01
    // reaches 0.1 ([0.0675, 0.1350]).
    let (_, high) = interval_by_hand(0.05, 0.002);
    assert!(high < 0.1, "{high}");
    assert_eq!(
        Implausible::of("z.guideway", 0.05, Some(0.002)),
        Some(Implausible::FarSofterThanCatalogue)
    );
    let (_, high) = interval_by_hand(0.09, 0.01);
    assert!(high > 0.1, "{high}");
    assert!(!implausible("z.guideway", 0.09, Some(0.01)));
    // An elastic body: 2.1 ± 0.1 reaches 2 ([1.8375, 2.4500]), 2.1 ± 0.01 does not
    // ([2.0704, 2.1304]); 0.45 ± 0.05 reaches 0.5 ([0.3375, 0.6750]), 0.45 ± 0.005 does not
    // ([0.4355, 0.4655]).
    assert!(!implausible("column.stiffness", 2.1, Some(0.1)));
    assert_eq!(
        Implausible::of("column.stiffness", 2.1, Some(0.01)),
        Some(Implausible::StifferThanFeModel)
    );
    assert!(!implausible("column.stiffness", 0.45, Some(0.05)));
    assert_eq!(
        Implausible::of("column.stiffness", 0.45, Some(0.005)),
        Some(Implausible::SofterThanFeModel)
    );
    // The warning says value, standard error and the interval that lies outside.
    let w = Implausible::StifferThanCatalogue.warning("x.guideway_normal", 1.03, Some(0.001));
    assert!(
        w.starts_with("x.guideway_normal = 1.0300 ± 0.0010 (3σ interval [1.0270, 1.0330]) lies above 1 beyond its uncertainty"),
        "{w}"
    );
}

#[test]
fn chi2_limit_is_one_plus_four_standard_deviations_of_s_squared() {
    // dof = 172: s² ≤ 1 + 4·√(2/172) = 1.431331…, s ≤ 1.196383…
    let c = Chi2::new(0.949, 172);
    assert!((c.s_limit - 1.196_383).abs() < 1e-6, "{}", c.s_limit);
    assert!(c.passed);
    assert!(c
        .describe()
        .starts_with("passed: s = 0.949 ≤ 1.196 over 172"));
    assert!(!Chi2::new(1.2, 172).passed);
    assert!(Chi2::new(1.5, 2).passed, "s² = 2.25 ≤ 1 + 4·1 = 5");
}

#[test]
fn a_parameter_listed_not_identifiable_is_not_identifiable_whatever_its_flag_says() {
    let v = serde_json::json!({
        "parameters": [
            {"name": "x.guideway_normal", "initial": 1.0, "identified": 9.998, "std_err": 86.0, "identifiable": true},
            {"name": "x.screw", "initial": 1.0, "identified": 1.0, "std_err": 0.02, "identifiable": true}
        ],
        "correlation": [[1.0, 0.0], [0.0, 1.0]],
        "cost_initial": 10.0, "cost_final": 5.0, "residual_std": 1.1, "degrees_of_freedom": 40,
        "not_identifiable": [{"name": "x.screw", "reason": "no influence"}],
        "tests": [{"plane": "zx", "direction": "ccw", "accel_m_s2": 5.0,
                   "measured": {"EZZ": -1.0}, "simulated_initial": {"EZZ": -0.5},
                   "simulated_final": {"EZZ": -1.0}}]
    });
    let r = IdentReport::from_value(&v).unwrap();
    assert_eq!(r.standing(&r.parameters[0]).label(), "NOT determined");
    assert_eq!(r.standing(&r.parameters[1]), Standing::NotIdentifiable);
    let c = r.chi2().unwrap();
    assert_eq!((c.dof, c.passed), (40, true));
}
