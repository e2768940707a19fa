//! The terms `tests/rtest_diagnosis.rs`' "each term alone" leaves to the combined tests, each
//! alone: squareness in the axes and in the structure (where a shear of the TCP against the
//! scales is squareness α and rotation −α/2), and servo mismatch alone, told from squareness by
//! a cw/ccw pair; a rotation of the structure alone, and the R-Test clock at another rate
//! (`feed_deviation`) alone; every other term of every source near 0.

mod common;

use common::circle_terms::TermCircle;
use common::diagnosis_checks::{check, diagnose, expect, Expected};
use eij::axes::Plane;
use eij::rtest::diagnosis::{separate, Source};

#[test]
fn squareness_alone_in_each_source() {
    for (plane, ccw) in [(Plane::Xy, true), (Plane::Zx, false)] {
        for in_structure in [false, true] {
            let mut c = TermCircle::new(plane, ccw, 3.0);
            c.seed = 300 + u64::from(in_structure) + 2 * u64::from(ccw);
            let alpha = 800.0;
            if in_structure {
                c.structure.squareness_um_per_m = alpha;
            } else {
                c.internal.squareness_um_per_m = alpha;
            }
            let d = diagnose(&c);
            let sq = expect(&[("squareness".into(), alpha)]);
            let st = expect(&[
                ("squareness".into(), alpha),
                ("rotation".into(), -alpha / 2.0),
            ]);
            let none = Expected::new();
            let tag = |s: &str| format!("{plane} squareness in structure {in_structure} → {s}");
            let (int, stru) = if in_structure {
                (&none, &st)
            } else {
                (&sq, &none)
            };
            check(&tag("internal"), d.source(Source::Internal), int);
            check(&tag("structure"), d.source(Source::Structure), stru);
            check(&tag("tcp"), d.source(Source::Tcp), &sq);
        }
    }
}

/// 0.2 ms of servo mismatch and nothing else: one test sees a 45° ellipse of ±10³ω·Δτ µm/m
/// (apparent squareness); the pair finds Δτ = 0.2 ms and squareness 0, in the axes and in the
/// TCP, none in the structure, every other term 0.
#[test]
fn servo_mismatch_alone() {
    let mut pair: Vec<_> = [true, false]
        .into_iter()
        .map(|ccw| {
            let mut c = TermCircle::new(Plane::Yz, ccw, 4.0);
            c.internal.lag_ms = [1.2, 1.0];
            c.seed = 400 + u64::from(ccw);
            diagnose(&c)
        })
        .collect();
    for d in &pair {
        let apparent = d.omega_rad_s * 0.2e-3 * 1e6;
        let exp = expect(&[("squareness".into(), apparent)]);
        check("one test, internal", d.source(Source::Internal), &exp);
        check("one test, tcp", d.source(Source::Tcp), &exp);
    }
    separate(&mut pair);
    let exp = expect(&[("servo_mismatch".into(), 0.2)]);
    for d in &pair {
        check("pair, internal", d.source(Source::Internal), &exp);
        check(
            "pair, structure",
            d.source(Source::Structure),
            &Expected::new(),
        );
        check("pair, tcp", d.source(Source::Tcp), &exp);
        let s = d.source(Source::Internal).term("servo_mismatch").unwrap();
        assert!(s.std_err < 0.01, "{s:?}");
    }
}

/// A rotation of the TCP against the scales alone (the structure turned by ρ about the normal):
/// `rotation` = ρ in the structure, every other term of every source 0 (the TCP source fits the
/// rotation with the nominal angle and does not report it).
#[test]
fn rotation_alone() {
    for (plane, ccw) in [(Plane::Xy, true), (Plane::Yz, false)] {
        let mut c = TermCircle::new(plane, ccw, 3.0);
        c.seed = 500 + u64::from(ccw);
        // 2000 µrad: 4 µm at r = 2 mm, 70 standard errors (0.5 µm noise on the R-Test).
        let rho = 2000.0;
        c.structure.rotation_um_per_m = rho;
        let d = diagnose(&c);
        let tag = |s: &str| format!("{plane} rotation → {s}");
        let none = Expected::new();
        check(&tag("internal"), d.source(Source::Internal), &none);
        check(
            &tag("structure"),
            d.source(Source::Structure),
            &expect(&[("rotation".into(), rho)]),
        );
        check(&tag("tcp"), d.source(Source::Tcp), &none);
    }
}

/// The R-Test's clock running ε = 150 ppm fast against the scales alone (external readings of
/// the path at t + ε·(t − t_mid), t_mid the recording's middle): `feed_deviation` = ε in the
/// structure, every other term of every source 0 — but `rotation`: the diagnosis measures the
/// ramp from the middle of the revolutions it keeps, not from the recording's, so the two
/// differ by a constant tangential offset ε·ω·Δt, |ω·Δt| at most half a revolution (π).
#[test]
fn feed_deviation_alone() {
    for (plane, ccw) in [(Plane::Zx, true), (Plane::Xy, false)] {
        let mut c = TermCircle::new(plane, ccw, 4.0);
        c.seed = 600 + u64::from(ccw);
        let eps = 150.0;
        c.structure.clock_rate_um_per_m = eps;
        let d = diagnose(&c);
        let tag = |s: &str| format!("{plane} clock rate → {s}");
        let none = Expected::new();
        check(&tag("internal"), d.source(Source::Internal), &none);
        check(&tag("tcp"), d.source(Source::Tcp), &none);
        let mut structure = d.source(Source::Structure).clone();
        let rotation = structure.term("rotation").unwrap().clone();
        assert!(
            rotation.value.abs() <= eps * std::f64::consts::PI + 4.0 * rotation.std_err,
            "{}: rotation {:.2} ± {:.2}",
            tag("structure"),
            rotation.value,
            rotation.std_err
        );
        structure.terms.retain(|t| t.name != "rotation");
        check(
            &tag("structure"),
            &structure,
            &expect(&[("feed_deviation".into(), eps)]),
        );
    }
}
