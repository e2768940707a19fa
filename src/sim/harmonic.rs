//! Harmonic steady state: a circle's set points are sinusoids at one frequency, so in steady
//! state every output is y(t) = Re(Y e^{jωt}) with Y = H(jω) U, H(jω) = C (jωI − A)⁻¹ B + D —
//! one complex solve instead of a time integration, on the closed loop's Hessenberg form
//! ([`FrequencyForm`], shared by all tests of one closed loop).
//!
//! For the circle a = r·cos ωt, b = r·sin ωt (paper eq. 3–4, ω < 0 for cw) the input phasors
//! are U_a = (r, jωr, −ω²r) and U_b = (−jr, ωr, jω²r) for (position, velocity, acceleration).
//! [`steady_harmonic`] hands the phasors to the closed-form evaluation
//! ([`crate::rtest::harmonic`]); [`steady_circle`] samples the steady state over whole
//! revolutions as a [`Run`] for the sampled evaluation, which the closed form reproduces.

use super::Run;
use crate::axes::{Axis, Direction, Plane};
use crate::control::{ClosedLoop, FrequencyForm, INPUTS_PER_AXIS};
use crate::rtest::harmonic::{SteadyHarmonic, Window};
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
    let form = cl.frequency_form();
    circle_phasors_in(&form, &cl.axes, plane, radius_m, accel_m_s2, direction)
}

/// As [`circle_phasors`] on a closed loop reduced beforehand (`axes`: its axes in input order).
pub fn circle_phasors_in(
    form: &FrequencyForm,
    axes: &[Axis],
    plane: Plane,
    radius_m: f64,
    accel_m_s2: f64,
    direction: Direction,
) -> Option<CirclePhasors> {
    let omega = direction.sign() * (accel_m_s2 / radius_m).sqrt();
    let (a, b) = plane.axes();
    let mut u = vec![c64::new(0.0, 0.0); INPUTS_PER_AXIS * axes.len()];
    let r = radius_m;
    for (i, ax) in axes.iter().enumerate() {
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
        u[INPUTS_PER_AXIS * i..INPUTS_PER_AXIS * (i + 1)].copy_from_slice(&v);
    }
    let outputs = form.response(omega, &u)?;
    Some(CirclePhasors {
        omega,
        inputs: u,
        outputs,
    })
}

/// The R-Test view of the phasors: internal readings along the plane's axes (mm) and the
/// structural deviation external − internal along a, b and the normal (µm), as the CSV
/// columns and [`super::output::to_series`] give them (0 for an axis the machine lacks).
pub fn steady_harmonic(cl: &ClosedLoop, plane: Plane, phasors: &CirclePhasors) -> SteadyHarmonic {
    let output = |name: String| -> c64 {
        cl.output(&name)
            .map_or(c64::new(0.0, 0.0), |i| phasors.outputs[i])
    };
    let (a, b) = plane.axes();
    let int_m = |ax: Axis| output(format!("{ax}_int_m"));
    let dev_um = |ax: Axis| (output(format!("{ax}_tcp_m")) - int_m(ax)) * 1e6;
    SteadyHarmonic {
        plane,
        omega_rad_s: phasors.omega,
        int_mm: [int_m(a) * 1e3, int_m(b) * 1e3],
        dev_um: [dev_um(a), dev_um(b), dev_um(plane.normal())],
    }
}

/// Revolutions sampled beyond the ones evaluated: a quarter at each end where the evaluation's
/// half-revolution speed is undefined, and a quarter of slack for its sampling stride.
pub const STEADY_MARGIN: f64 = 0.75;

/// Samples of [`steady_circle`]: whole revolutions, the margin, and the closing sample.
fn steady_samples(samples_per_revolution: usize, revolutions: usize) -> usize {
    revolutions * samples_per_revolution
        + (STEADY_MARGIN * samples_per_revolution as f64).round() as usize
        + 1
}

/// The window the evaluation keeps of [`steady_circle`]'s samples: `revolutions` whole
/// revolutions centred in the record (the sampled evaluation's window starts within a few
/// samples of it, by its speed search's stride).
pub fn steady_window(omega: f64, samples_per_revolution: usize, revolutions: usize) -> Window {
    let spare = steady_samples(samples_per_revolution, revolutions)
        - 1
        - revolutions * samples_per_revolution;
    Window {
        start_rad: omega.signum() * std::f64::consts::TAU * 0.5 * spare as f64
            / samples_per_revolution as f64,
        samples_per_revolution,
        revolutions,
    }
}

/// e^{jθ}: the phasors rotated to set-point angle θ give the outputs there, y = Re(Y e^{jθ}).
pub fn phase_factor(theta: f64) -> c64 {
    c64::cis(theta)
}

/// Samples the steady state of `phasors` over `revolutions` whole revolutions plus
/// [`STEADY_MARGIN`] of a revolution (the evaluation cannot tell the speed within a quarter
/// revolution of either end and keeps whole revolutions, centred, of the rest),
/// `samples_per_revolution` samples per revolution: the evaluation keeps `revolutions`.
pub fn steady_circle(
    phasors: &CirclePhasors,
    samples_per_revolution: usize,
    revolutions: usize,
) -> Run {
    let period = std::f64::consts::TAU / phasors.omega.abs();
    let h = period / samples_per_revolution as f64;
    let n = steady_samples(samples_per_revolution, revolutions);
    let (nu, ny) = (phasors.inputs.len(), phasors.outputs.len());
    let mut run = Run::with_capacity(nu, ny, n);
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
