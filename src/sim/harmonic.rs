//! Harmonic steady state: a circle's set points are sinusoids at one frequency, so in steady
//! state every output is y(t) = Re(Y e^{jωt}) with Y = H(jω) U, H(jω) = C (jωI − A)⁻¹ B + D —
//! one complex solve instead of a time integration ([`ClosedLoop::response`], faer's
//! partial-pivoting LU).
//!
//! For the circle a = r·cos ωt, b = r·sin ωt (paper eq. 3–4, ω < 0 for cw) the input phasors
//! are U_a = (r, jωr, −ω²r) and U_b = (−jr, ωr, jω²r) for (position, velocity, acceleration).
//! [`steady_circle`] samples the steady state over whole revolutions as a [`Run`], so the same
//! output and evaluation code serves harmonic and time-domain results alike.

use super::Run;
use crate::axes::{Direction, Plane};
use crate::control::ClosedLoop;
use faer::c64;

/// The steady-state complex amplitudes of the closed loop's inputs and outputs for a circle.
#[derive(Debug, Clone, PartialEq)]
pub struct CirclePhasors {
    /// Signed angular speed ω, rad/s.
    pub omega: f64,
    /// Input phasors U (closed-loop input order).
    pub inputs: Vec<c64>,
    /// Output phasors Y = H(jω) U (closed-loop output order).
    pub outputs: Vec<c64>,
}

/// Steady-state phasors of a circle of radius `radius_m` at set acceleration `accel_m_s2`;
/// `None` if jωI − A is singular (a closed-loop pole on the imaginary axis at ω).
pub fn circle_phasors(
    cl: &ClosedLoop,
    plane: Plane,
    radius_m: f64,
    accel_m_s2: f64,
    direction: Direction,
) -> Option<CirclePhasors> {
    let omega = direction.sign() * (accel_m_s2 / radius_m).sqrt();
    let (a, b) = plane.axes();
    let nu = cl.b.ncols();
    let mut u = vec![c64::new(0.0, 0.0); nu];
    let r = radius_m;
    for (i, ax) in cl.axes.iter().enumerate() {
        let v = if *ax == a {
            [
                c64::new(r, 0.0),
                c64::new(0.0, omega * r),
                c64::new(-omega * omega * r, 0.0),
            ]
        } else if *ax == b {
            [
                c64::new(0.0, -r),
                c64::new(omega * r, 0.0),
                c64::new(0.0, omega * omega * r),
            ]
        } else {
            continue;
        };
        u[3 * i..3 * i + 3].copy_from_slice(&v);
    }
    let outputs = cl.response(omega, &u)?;
    Some(CirclePhasors {
        omega,
        inputs: u,
        outputs,
    })
}

/// e^{jθ}: the phasors rotated to set-point angle θ give the outputs there, y = Re(Y e^{jθ}).
pub fn phase_factor(theta: f64) -> c64 {
    c64::cis(theta)
}

/// Samples the steady state of `phasors` over `revolutions` whole revolutions plus half a
/// revolution (the evaluation trims a quarter revolution at each end while it looks for the
/// steady part), `samples_per_revolution` samples per revolution.
pub fn steady_circle(
    phasors: &CirclePhasors,
    samples_per_revolution: usize,
    revolutions: usize,
) -> Run {
    let period = std::f64::consts::TAU / phasors.omega.abs();
    let h = period / samples_per_revolution as f64;
    let n = (revolutions * samples_per_revolution) + samples_per_revolution / 2 + 1;
    let (nu, ny) = (phasors.inputs.len(), phasors.outputs.len());
    let mut run = Run {
        t_s: Vec::with_capacity(n),
        nu,
        ny,
        inputs: Vec::with_capacity(n * nu),
        outputs: Vec::with_capacity(n * ny),
    };
    for k in 0..n {
        let t = k as f64 * h;
        let e = c64::cis(phasors.omega * t);
        run.t_s.push(t);
        run.inputs.extend(phasors.inputs.iter().map(|u| (u * e).re));
        run.outputs
            .extend(phasors.outputs.iter().map(|y| (y * e).re));
    }
    run
}
