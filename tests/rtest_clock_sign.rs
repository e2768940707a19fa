//! The sign of a clock lag (issue 29 item 11): an external series late by τ (its sample stamped t
//! is the position at t − τ) reads x(t − τ) ≈ x(t) − τ·v, so on a steady circle of plane (a, b)
//! the evaluation returns Ê_ab = E_ab − 10³·τ·(ρ_a/r)/ω and Ê_ba = E_ba + 10³·τ·(ρ_b/r)/ω (τ in
//! ms, ω signed, rad/s; ρ_a the external path's half-width along a, r the set radius), and the
//! identification reports that lag as a positive clock offset `external_late_ms`.
//! docs/identification.md and the doc comments of `ident::statics` and `rtest::clock_fit` state
//! it so; these tests measure it on series lagged exactly (by whole samples), not by the formula.

mod common;

use common::{eij, root, Scratch, DEMO};
use eij::axes::{Axis, Direction, Eij, Plane};
use eij::rtest::{evaluate, CircleSeries, EvalOptions};
use eij::{Identification, Machine};

/// Sample rate of the simulated series, Hz; the lag is two samples.
const RATE_HZ: f64 = 10_000.0;
const LAG_SAMPLES: usize = 2;

/// A noise-free circle of the demo at 10 kHz, simulated by `eij simulate circle`.
fn simulated(s: &Scratch, plane: Plane, direction: Direction, accel: f64) -> String {
    let name = format!("{plane}_{direction}_{accel}.csv");
    let out = s.s(&name);
    let args = [
        "simulate",
        "circle",
        "--machine",
        DEMO,
        "--plane",
        plane.name(),
        "--radius-mm",
        "2",
        "--accel-m-s2",
        &accel.to_string(),
        "--direction",
        direction.name(),
        "--out",
        &out,
        "--rate-hz",
        &RATE_HZ.to_string(),
    ];
    let run = eij(&args);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    out
}

/// The series with its external readings `LAG_SAMPLES` late: row k pairs the time and
/// internal readings of sample k + LAG with the external readings of sample k.
fn lagged(s: &CircleSeries) -> CircleSeries {
    let (n, l) = (s.len(), LAG_SAMPLES);
    let axes = Axis::ALL;
    CircleSeries::new(
        format!("{} (external {l} samples late)", s.source()),
        s.t_s()[l..].to_vec(),
        axes.map(|a| s.int_mm(a)[l..].to_vec()),
        axes.map(|a| s.ext_mm(a)[..n - l].to_vec()),
    )
    .unwrap()
}

#[test]
fn a_late_external_series_lowers_e_ab_by_the_lag_over_omega() {
    let s = Scratch::new("clock-sign");
    let tau_ms = LAG_SAMPLES as f64 / RATE_HZ * 1e3;
    let opts = EvalOptions {
        plane: None,
        radius_mm: Some(2.0),
    };
    for plane in [Plane::Xy, Plane::Zx] {
        for direction in Direction::ALL {
            let series = CircleSeries::read_csv(simulated(&s, plane, direction, 5.0)).unwrap();
            let on_time = evaluate(&series, &opts).unwrap();
            let late = evaluate(&lagged(&series), &opts).unwrap();
            assert_eq!(late.direction, direction);
            let omega = direction.sign() * std::f64::consts::TAU * on_time.freq_hz;
            // The lagged readings are the external ones, and v_a = −ρ_a·ω·sin θ with ρ_a the
            // external path's half-width along a (√2 × its rms over the steady revolutions).
            let (a, b) = plane.axes();
            let half_width = |axis: Axis| {
                let x = &series.ext_mm(axis)[on_time.steady.clone()];
                let mean = x.iter().sum::<f64>() / x.len() as f64;
                (2.0 * x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / x.len() as f64).sqrt()
            };
            let lag_over_omega = 1e3 * tau_ms / (on_time.radius_mm * omega);
            let (shift_ab, shift_ba) = (
                lag_over_omega * half_width(a),
                lag_over_omega * half_width(b),
            );
            let change = |e: Eij| late.eij[&e].value - on_time.eij[&e].value;
            let (ab, ba) = (Eij::new(a, b), Eij::new(b, a));
            // First order in τω (0.009 here): the next term is (τω)²/6 of the shift.
            assert!(
                (change(ab) + shift_ab).abs() < 1e-3 * shift_ab.abs(),
                "{plane} {direction}: {ab} changed by {:.4}, −10³·τ·(ρ_a/r)/ω = {:.4}",
                change(ab),
                -shift_ab
            );
            assert!(
                (change(ba) - shift_ba).abs() < 1e-3 * shift_ba.abs(),
                "{plane} {direction}: {ba} changed by {:.4}, +10³·τ·(ρ_b/r)/ω = {:.4}",
                change(ba),
                shift_ba
            );
            // The sign the docs state: a late external series lowers E_ab of a ccw circle.
            if direction == Direction::Ccw {
                assert!(change(ab) < 0.0 && change(ba) > 0.0);
            }
            // The in-talk moves only by the second-order term τ²/2·ä: 10⁶·τ²/2 µm·s²/m.
            let second_order = 1e6 * (tau_ms * 1e-3).powi(2) / 2.0;
            for e in [Eij::new(a, a), Eij::new(b, b)] {
                assert!(change(e).abs() < 2.0 * second_order, "{e}: {}", change(e));
            }
        }
    }
}

/// The identification fits the lag of a folder whose tests hold both directions as a clock
/// offset with the EIJ, reported positive for late external readings: τ within three
/// standard errors (the static terms and the lag's second-order term take their share).
#[test]
fn identify_reports_a_late_external_clock_as_positive() {
    let s = Scratch::new("clock-sign-identify");
    let folder = s.path("late");
    std::fs::create_dir_all(&folder).unwrap();
    std::fs::write(
        folder.join("rtest.toml"),
        "radius_mm = 2.0\nposition_mm = [0.0, 0.0, 0.0]\n",
    )
    .unwrap();
    for direction in Direction::ALL {
        for accel in [3.0, 6.0] {
            let series = CircleSeries::read_csv(simulated(&s, Plane::Xy, direction, accel));
            let late = lagged(&series.unwrap());
            let mut csv = String::from(common::HEADER);
            csv.push('\n');
            for k in 0..late.len() {
                let int = Axis::ALL.map(|a| late.int_mm(a)[k]);
                let ext = Axis::ALL.map(|a| late.ext_mm(a)[k]);
                csv.push_str(&format!(
                    "{},{},{},{},{},{},{}\n",
                    late.t_s()[k],
                    int[0],
                    int[1],
                    int[2],
                    ext[0],
                    ext[1],
                    ext[2]
                ));
            }
            std::fs::write(folder.join(format!("xy_{direction}_{accel}.csv")), csv).unwrap();
        }
    }
    let machine = Machine::from_file(&root().join(DEMO)).unwrap();
    let result = Identification::new(machine)
        .parameters(["x.guideway_normal", "y.guideway_normal"])
        .measured([&folder])
        .run()
        .unwrap();
    let clocks: Vec<_> = result
        .static_estimates
        .iter()
        .filter(|e| e.clock.is_some())
        .collect();
    assert_eq!(clocks.len(), 1, "{:?}", result.static_estimates);
    let tau_ms = LAG_SAMPLES as f64 / RATE_HZ * 1e3;
    let (late_ms, se) = (clocks[0].value_um_per_mm, clocks[0].std_err_um_per_mm);
    assert!(
        (late_ms - tau_ms).abs() < 3.0 * se + 0.01 * tau_ms,
        "external_late_ms = {late_ms} ± {se}, lag {tau_ms} ms"
    );
}
