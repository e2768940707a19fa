//! The closed loop against hand-derived transfer functions and an independent integrator.

use eij::axes::{Axis, Direction, Plane};
use eij::control::{ClosedLoop, ControlError};
use eij::machine::{Machine, Pose};
use eij::sim::setpoint::{Circle, SetPoint};
use eij::sim::simulate;
use nalgebra::{Complex, DMatrix, DVector};
use std::f64::consts::{PI, TAU};

mod common;

use common::machine as load;

/// The following error X_set − X per unit set position of `machines/reference/single-axis.toml`
/// at s = jω, derived by hand in the Laplace domain. The slide's x and the rotor angle Φ
/// decouple from the other DOF (nut and scale on the COG line, no carriage stiffness along x)
/// but for the thread torque on the slide's roll, which softens k̃ (see below):
///
/// ```text
/// m s² X = −k̃ δ,  δ = X − h'Φ,  k̃ = k_ax + c_s s                (slide on the screw)
/// J s² Φ + c_f s Φ = T + h' k̃ δ                                   (rotor)
/// T (1 + Tc s) = Kp (1 + 1/(Tn s)) (ρ (Kv (X_s − X) + k_vff s X_s) − s Φ) + k_aff J_eq ρ s² X_s
/// ```
/// with h' = h/2π, ρ = 1/h', J_eq = J + m h'². Eliminating X = G Φ, G = k̃ h'/(m s² + k̃):
/// Φ = (P ρ (Kv + k_vff s) + F) / (J s² + c_f s − h' k̃ (G − h') + P ρ Kv G + P s).
fn hand_following_error(omega: f64) -> Complex<f64> {
    let s = Complex::new(0.0, omega);
    let (m, j, h) = (500.0, 0.004, 0.02);
    let hp = h / TAU;
    let rho = 1.0 / hp;
    let k_shaft = 2.1e11 * PI * 0.03 * 0.03 / 4.0 / 0.5;
    let k_ax = 1.0 / (1.0 / k_shaft + 1.0 / 1e9 + 1.0 / 1e9);
    let (c_s, c_f) = (4.0e3, 0.01);
    let (kv, kp, tn, tc, kvff, kaff) = (40.0, 2.0, 0.01, 0.0004, 0.9, 0.8);
    let j_eq = j + m * hp * hp;
    // The right-hand thread turns the nut's axial force into a torque on the slide's roll a
    // (δ = X − h'(Φ + a)); the roll, coupled with y by the carriages below the COG, answers
    // with a = H_aa·h'·k̃·δ, so the screw acts as k̃ in series with the roll: k̃/(1 + h'²k̃H_aa).
    let (kc, cc) = (
        Complex::new(5e8, 0.0) + 2e3 * s,
        Complex::new(5e8, 0.0) + 2e3 * s,
    );
    let z_yy = 4.0 * kc + 500.0 * s * s;
    let z_ya = 4.0 * kc * 0.2;
    let z_aa = 4.0 * kc * 0.04 + 4.0 * cc * 0.0625 + 20.0 * s * s;
    let h_aa = z_yy / (z_yy * z_aa - z_ya * z_ya);
    let kt = k_ax + c_s * s;
    let kt = kt / (1.0 + hp * hp * kt * h_aa);
    let g = kt * hp / (m * s * s + kt);
    let one = Complex::new(1.0, 0.0);
    let p = kp * (one + one / (tn * s)) / (one + tc * s);
    let f = kaff * j_eq * rho * s * s / (one + tc * s);
    let lhs = j * s * s + c_f * s - hp * kt * (g - hp) + p * rho * kv * g + p * s;
    let rhs = p * rho * (kv + kvff * s) + f;
    let phi = rhs / lhs;
    one - g * phi
}

/// A sinusoidal set point x = r·sin(ωt) on one axis, with its exact derivatives.
struct Sine {
    r: f64,
    omega: f64,
    duration: f64,
}

impl SetPoint for Sine {
    fn duration_s(&self) -> f64 {
        self.duration
    }
    fn eval(&self, t: f64, _axes: &[Axis], out: &mut [f64]) {
        let (s, c) = (self.omega * t).sin_cos();
        out[0] = self.r * s;
        out[1] = self.r * self.omega * c;
        out[2] = -self.r * self.omega * self.omega * s;
    }
}

#[test]
fn following_error_at_8_hz_matches_the_hand_derived_transfer_function() {
    let machine = load("reference/single-axis.toml");
    let cl = ClosedLoop::new(&machine, &Pose::new(&machine, &[0.0]).unwrap()).unwrap();
    let omega = TAU * 8.0;
    let want = hand_following_error(omega);

    // Frequency response of the state space: set position, velocity jω, acceleration −ω².
    let h = cl.frequency_response(omega).unwrap();
    let fe = cl.output("x_following_error_m").unwrap();
    let jw = Complex::new(0.0, omega);
    let got = h[(fe, 0)] + jw * h[(fe, 1)] - omega * omega * h[(fe, 2)];
    assert!(
        (got - want).norm() < 1e-9 * want.norm(),
        "H(jω) {got} vs hand {want}"
    );

    // Time domain: the steady following error's sine and cosine parts after the transient
    // (slowest drive pole −14 1/s: after 1.5 s it has decayed by e⁻²¹). The first-order hold
    // interpolates the sine linearly between samples, attenuating it by ≈ (ωh)²/12; the
    // following error (≈ 6 % of the set amplitude) feels that as (ωh)²/12/0.065 relative, so
    // 100 kHz keeps it at 3e-7.
    let r = 1e-3;
    let duration = 2.5;
    let run = simulate(&cl, &Sine { r, omega, duration }, 100_000.0).unwrap();
    let e = run.output_series(&cl, "x_following_error_m").unwrap();
    // Least squares over the last 8 whole periods (1 s) on [sin ωt, cos ωt, 1].
    let start = run.t_s.iter().position(|&t| t >= duration - 1.0).unwrap();
    let rows: Vec<usize> = (start..run.len() - 1).collect();
    let x = DMatrix::from_fn(rows.len(), 3, |i, c| {
        let t = run.t_s[rows[i]];
        [(omega * t).sin(), (omega * t).cos(), 1.0][c]
    });
    let y = DVector::from_iterator(rows.len(), rows.iter().map(|&k| e[k]));
    let coef = x.svd(true, true).solve(&y, 1e-14).unwrap();
    // r·sin(ωt) → r·(Re H·sin ωt + Im H·cos ωt)
    let got = Complex::new(coef[0], coef[1]) / r;
    let rel = (got - want).norm() / want.norm();
    assert!(
        rel < 1e-6,
        "simulated {got} vs hand {want}: relative {rel:e}"
    );
    assert!(
        (got.norm() - want.norm()).abs() < 1e-6 * want.norm()
            && (got.arg() - want.arg()).abs() < 1e-6
    );
}

#[test]
fn exported_state_space_integrated_by_rk4_reproduces_the_simulator() {
    let dir = std::env::temp_dir().join(format!("eij-rk4-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let json_path = dir.join("demo.json");
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_eij"))
        .args(["export", "--machine"])
        .arg(common::root().join(common::DEMO))
        .arg("--out")
        .arg(&json_path)
        .status()
        .unwrap();
    assert!(status.success());
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&json_path).unwrap()).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    let matrix = |v: &serde_json::Value| {
        let rows: Vec<Vec<f64>> = serde_json::from_value(v.clone()).unwrap();
        DMatrix::from_fn(rows.len(), rows[0].len(), |i, j| rows[i][j])
    };
    let ss = &json["state_space"];
    let (a, b, c, d) = (
        matrix(&ss["A"]),
        matrix(&ss["B"]),
        matrix(&ss["C"]),
        matrix(&ss["D"]),
    );
    let names = |k: &str| -> Vec<String> { serde_json::from_value(ss[k].clone()).unwrap() };
    let (inputs, outputs) = (names("inputs"), names("outputs"));
    // Every state named once: the 27 DOF twice, and per axis the PI integral, the lagged
    // torque and the set-point filter of the demo's three drives (2·27 + 3·3 = 63).
    let states = names("states");
    assert_eq!((states.len(), a.nrows()), (63, 63), "{states:?}");
    let distinct: std::collections::BTreeSet<&String> = states.iter().collect();
    assert_eq!(distinct.len(), states.len(), "{states:?}");
    for want in ["x.pi_integral", "z.torque", "y.setpoint_filter"] {
        assert!(states.iter().any(|s| s == want), "missing state {want}");
    }
    for want in [
        "x_pos_set_m",
        "x_vel_set_m_s",
        "x_acc_set_m_s2",
        "z_acc_set_m_s2",
    ] {
        assert!(inputs.iter().any(|i| i == want), "missing input {want}");
    }
    for want in [
        "x_int_m", "y_int_m", "z_int_m", "x_tcp_m", "y_tcp_m", "z_tcp_m",
    ] {
        assert!(outputs.iter().any(|o| o == want), "missing output {want}");
    }

    // The simulator on the same machine: a ZX circle, first 0.15 s (ramp-in).
    let machine = load("demo-vmc.toml");
    let cl = ClosedLoop::new(&machine, &machine.reference_pose()).unwrap();
    let mut circle = Circle::new(Plane::Zx, 0.002, 5.0, Direction::Ccw);
    circle.steady_revolutions = 1;
    let rate = 10_000.0;
    let run = simulate(&cl, &circle, rate).unwrap();

    // Classic RK4 with 20 sub-steps per sample, the set points linear between samples.
    let nu = b.ncols();
    let u_at = |k: usize| DVector::from_column_slice(&run.inputs[k * nu..(k + 1) * nu]);
    let u0 = u_at(0);
    let mut x = a.clone().lu().solve(&(-(&b * &u0))).unwrap();
    let sub = 20;
    let hs = 1.0 / rate / sub as f64;
    let f = |x: &DVector<f64>, u: &DVector<f64>| &a * x + &b * u;
    let tcp_x = outputs.iter().position(|o| o == "x_tcp_m").unwrap();
    let tcp_y = outputs.iter().position(|o| o == "y_tcp_m").unwrap();
    let int_z = outputs.iter().position(|o| o == "z_int_m").unwrap();
    let mut max_err: f64 = 0.0;
    for k in 0..1500 {
        let (uk, uk1) = (u_at(k), u_at(k + 1));
        for i in 0..sub {
            let w = |frac: f64| &uk + (&uk1 - &uk) * ((i as f64 + frac) / sub as f64);
            let (ua, um, ub) = (w(0.0), w(0.5), w(1.0));
            let k1 = f(&x, &ua);
            let k2 = f(&(&x + &k1 * (hs / 2.0)), &um);
            let k3 = f(&(&x + &k2 * (hs / 2.0)), &um);
            let k4 = f(&(&x + &k3 * hs), &ub);
            x += (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (hs / 6.0);
        }
        let y = &c * &x + &d * &uk1;
        for (o, name) in [(tcp_x, "x_tcp_m"), (tcp_y, "y_tcp_m"), (int_z, "z_int_m")] {
            let sim = run.outputs[(k + 1) * run.ny + cl.output(name).unwrap()];
            max_err = max_err.max((y[o] - sim).abs());
        }
    }
    // Outputs are ~2 mm; structural deviations ~1 µm: agreement to 1 nm·1e-3.
    assert!(
        max_err < 1e-12,
        "RK4 and exact discretisation differ by {max_err:e} m"
    );
}

#[test]
fn unstable_gains_are_refused_naming_the_axis() {
    let text = std::fs::read_to_string(common::root().join("machines/reference/single-axis.toml"))
        .unwrap()
        .replace("kp_nm_s_per_rad = 2.0", "kp_nm_s_per_rad = 2000.0");
    let machine = Machine::from_toml_str(&text, "hot-gains.toml").unwrap();
    match ClosedLoop::new(&machine, &Pose::new(&machine, &[0.0]).unwrap()) {
        Err(e @ ControlError::Unstable { axis: Axis::X, .. }) => {
            let msg = e.to_string();
            assert!(
                msg.starts_with("hot-gains.toml: closed loop unstable at axis x")
                    && msg.ends_with("lower kv_per_s or kp_nm_s_per_rad, or raise tn_s"),
                "{msg}"
            );
        }
        other => panic!("expected an unstable loop, got {:?}", other.map(|_| ())),
    }
}

/// H(jω) on the balanced Hessenberg form against a dense complex LU of jωI − A with iterative
/// refinement (nalgebra, independent of faer) on the demo's 63-state closed loop, from the slowest circle (0.5 Hz) to far above the
/// structural modes, both senses of rotation.
#[test]
fn hessenberg_frequency_response_equals_a_dense_solve() {
    let machine = load("demo-vmc.toml");
    let cl = ClosedLoop::new(&machine, &machine.reference_pose()).unwrap();
    let n = cl.a.nrows();
    let complex = |m: &DMatrix<f64>| m.map(|v| Complex::new(v, 0.0));
    let (b, c, d) = (complex(&cl.b), complex(&cl.c), complex(&cl.d));
    for omega in [3.0, 30.0, -62.8, 700.0, 4000.0] {
        let shifted = DMatrix::from_fn(n, n, |i, k| {
            let diag = if i == k { omega } else { 0.0 };
            Complex::new(-cl.a[(i, k)], diag)
        });
        // Dense LU with two steps of iterative refinement as the reference.
        let lu = shifted.clone().lu();
        let mut x = lu.solve(&b).unwrap();
        for _ in 0..2 {
            x += lu.solve(&(&b - &shifted * &x)).unwrap();
        }
        let want = &c * &x + &d;
        let got = cl.frequency_response(omega).unwrap();
        let scale = want.iter().fold(0.0_f64, |m, z| m.max(z.norm()));
        let diff = (&got - &want).iter().fold(0.0_f64, |m, z| m.max(z.norm()));
        assert!(diff < 1e-10 * scale, "ω = {omega}: {diff:e} of {scale:e}");
    }
}

/// The largest real part of `a`'s eigenvalues, by nalgebra's real Schur form (with an
/// iteration cap: independent of faer's eigen-solver that the stability check uses).
fn spectral_abscissa(a: &DMatrix<f64>) -> f64 {
    let schur = a.clone().try_schur(1e-14, 100_000).expect("Schur form");
    let t = schur.unpack().1;
    let n = t.nrows();
    let mut worst = f64::NEG_INFINITY;
    let mut i = 0;
    while i < n {
        if i + 1 < n && t[(i + 1, i)] != 0.0 {
            // A 2×2 block: the real part of its complex pair is half its trace.
            worst = worst.max(0.5 * (t[(i, i)] + t[(i + 1, i + 1)]));
            i += 2;
        } else {
            worst = worst.max(t[(i, i)]);
            i += 1;
        }
    }
    worst
}

/// The Lyapunov certificate of a stable loop proves the loops of a finite-difference step
/// around it stable, proves nothing for a loop far away (that one is checked in full, and
/// stays stable), and never proves an unstable loop stable — even one just across the
/// stability limit from the loop it was made from. `ClosedLoop::new_near` always gives the
/// verdict of `ClosedLoop::new`.
#[test]
fn stability_certificate_proves_nearby_loops_and_never_an_unstable_one() {
    use eij::control::stability::Certificate;
    use eij::control::PoseChecks;
    use eij::machine::Reduction;
    use eij::mbs::Model;
    let demo = load("demo-vmc.toml");
    let pose = demo.reference_pose();
    let state_matrix =
        |m: &Machine| ClosedLoop::from_model(m, Model::assemble(m, &pose).unwrap()).a;
    let with_factor = |f: f64| {
        let mut m = demo.clone();
        m.set_reduction(0, Reduction::GuidewayNormal, f).unwrap();
        m
    };
    let cert = Certificate::new(&state_matrix(&demo)).expect("the demo's loop is strictly stable");
    for f in [0.999, 1.001] {
        let a = state_matrix(&with_factor(f));
        assert!(spectral_abscissa(&a) < -1.0);
        assert!(cert.certifies(&a), "a 1e-3 step of x.guideway_normal");
    }
    let far = state_matrix(&with_factor(0.3));
    assert!(
        spectral_abscissa(&far) < -1.0,
        "stable, but far from the certificate's loop"
    );
    assert!(!cert.certifies(&far));
    let near = PoseChecks::default();
    assert!(ClosedLoop::new_near(&with_factor(0.3), &pose, &near).is_ok());

    // The single-axis drive's proportional gain up to its stability limit (bisection on the
    // full check), and the certificates of loops just inside it against loops just outside.
    let text = std::fs::read_to_string(common::root().join("machines/reference/single-axis.toml"))
        .unwrap();
    let with_kp = |kp: f64| {
        let t = text.replace("kp_nm_s_per_rad = 2.0", &format!("kp_nm_s_per_rad = {kp}"));
        Machine::from_toml_str(&t, "kp.toml").unwrap()
    };
    let at_0 = |m: &Machine| Pose::new(m, &[0.0]).unwrap();
    let stable = |kp: f64| ClosedLoop::new(&with_kp(kp), &at_0(&with_kp(kp))).is_ok();
    let (mut lo, mut hi) = (2.0, 2000.0);
    assert!(stable(lo) && !stable(hi));
    for _ in 0..60 {
        let mid = (lo * hi).sqrt();
        if stable(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let a_of = |kp: f64| {
        ClosedLoop::from_model(
            &with_kp(kp),
            Model::assemble(&with_kp(kp), &at_0(&with_kp(kp))).unwrap(),
        )
        .a
    };
    for inside in [lo, lo * (1.0 - 1e-6), lo * (1.0 - 1e-3)] {
        let Some(cert) = Certificate::new(&a_of(inside)) else {
            continue;
        };
        for outside in [hi, hi * (1.0 + 1e-6), hi * (1.0 + 1e-3), 2000.0] {
            assert!(spectral_abscissa(&a_of(outside)) > 0.0 || !stable(outside));
            assert!(
                !cert.certifies(&a_of(outside)),
                "kp {inside} certified kp {outside}"
            );
        }
    }
    for kp in [lo, hi, 2000.0, 2.0] {
        let near = PoseChecks::default();
        assert!(
            !near.stability.renew(&a_of(lo * 0.9)),
            "the first visit makes no certificate"
        );
        assert!(near.stability.renew(&a_of(lo * (1.0 - 1e-3))));
        assert_eq!(
            ClosedLoop::new_near(&with_kp(kp), &at_0(&with_kp(kp)), &near).is_ok(),
            stable(kp),
            "kp {kp}"
        );
    }
}

/// `ClosedLoop::new_near` checks the support once per pose, with the first loop there: the
/// rigid-body modes are null(Σ fᵢKᵢ) = ∩ null(Kᵢ) for factors fᵢ > 0, so other factors keep a
/// supported structure supported; an unsupported one is refused by every loop, not only the
/// first, and the loops after the first are the loops `ClosedLoop::new` builds.
#[test]
fn support_is_checked_once_per_pose_and_never_waved_through() {
    use eij::control::PoseChecks;
    use eij::machine::catalogue::Catalogue;
    use eij::machine::Reduction;
    use eij::mbs::MbsError;
    let demo = load("demo-vmc.toml");
    let mut raw = demo.to_raw();
    raw.axes[0].guideway.rails.truncate(1);
    let one_rail = Machine::from_raw(raw, &Catalogue::bundled().unwrap(), "one-rail.toml").unwrap();
    let pose = demo.reference_pose();
    let checks = PoseChecks::default();
    for visit in 0..2 {
        match ClosedLoop::new_near(&one_rail, &pose, &checks) {
            Err(ControlError::Mbs(MbsError::Unsupported { count: 1, .. })) => {}
            other => panic!("visit {visit}: expected Unsupported, got {other:?}"),
        }
    }
    let checks = PoseChecks::default();
    for f in [1.0, 0.999, 0.4] {
        let mut m = demo.clone();
        m.set_reduction(1, Reduction::GuidewayLateral, f).unwrap();
        let near = ClosedLoop::new_near(&m, &pose, &checks).unwrap();
        let full = ClosedLoop::new(&m, &pose).unwrap();
        assert_eq!(near.a, full.a, "factor {f}");
    }
}

/// A centre stops making Lyapunov certificates once one proved no loop but its own (the
/// elastic column's lightly damped modes: every finite-difference step needs a new one, which
/// costs several eigenvalue checks), and keeps making them where they pay (the rigid demo's
/// steps); the verdict of `new_near` is the eigenvalues' either way.
#[test]
fn certificates_that_prove_nothing_are_no_longer_made_and_the_verdict_stays() {
    use eij::control::stability::MAX_WASTED_RENEWALS;
    use eij::control::PoseChecks;
    use eij::machine::Reduction;
    use eij::mbs::Model;
    let demo = load("demo-vmc.toml");
    let pose = demo.reference_pose();
    let with_factor = |f: f64| {
        let mut m = demo.clone();
        m.set_reduction(0, Reduction::GuidewayNormal, f).unwrap();
        m
    };
    let a_of = |f: f64| {
        let m = with_factor(f);
        ClosedLoop::from_model(&m, Model::assemble(&m, &pose).unwrap()).a
    };
    // Where certificates pay: each proves the next 1e-3 step, and renewing goes on.
    let paying = PoseChecks::default();
    assert!(!paying.stability.renew(&a_of(1.0)), "the first visit");
    for k in 0..4 {
        let f = 1.0 + 0.2 * k as f64;
        assert!(paying.stability.renew(&a_of(f)), "certificate at {f}");
        assert!(paying.stability.certifies(&a_of(f * 1.001)));
    }
    assert!(!paying.stability.given_up());
    // Where they do not: loops far apart, each certificate proves only its own.
    let wasted = PoseChecks::default();
    assert!(!wasted.stability.renew(&a_of(1.0)));
    let mut made = 0;
    for f in [0.3, 3.0, 0.05, 8.0] {
        assert!(!wasted.stability.certifies(&a_of(f)), "far from the last");
        if wasted.stability.renew(&a_of(f)) {
            made += 1;
        }
    }
    assert_eq!(made, MAX_WASTED_RENEWALS as usize);
    assert!(wasted.stability.given_up());
    // The verdict is the eigenvalues': stable loops pass, an unstable one is refused.
    for f in [0.3, 1.0, 5.0] {
        assert!(ClosedLoop::new_near(&with_factor(f), &pose, &wasted).is_ok());
    }
    let text = std::fs::read_to_string(common::root().join("machines/reference/single-axis.toml"))
        .unwrap();
    let unstable = Machine::from_toml_str(
        &text.replace("kp_nm_s_per_rad = 2.0", "kp_nm_s_per_rad = 2000.0"),
        "kp.toml",
    )
    .unwrap();
    let at_0 = Pose::new(&unstable, &[0.0]).unwrap();
    let near = PoseChecks::default();
    let stable_text = Machine::from_toml_str(&text, "kp.toml").unwrap();
    let a = |m: &Machine| ClosedLoop::from_model(m, Model::assemble(m, &at_0).unwrap()).a;
    assert!(!near.stability.renew(&a(&stable_text)));
    assert!(near.stability.renew(&a(&stable_text)));
    assert!(ClosedLoop::new_near(&unstable, &at_0, &near).is_err());
    assert!(
        near.stability.given_up(),
        "a certificate that proved nothing"
    );
    assert!(ClosedLoop::new_near(&unstable, &at_0, &near).is_err());
}
