//! Time-domain simulation of the closed loop: exact discretisation with a first-order hold on
//! the set points, and the R-Test-like output series of docs/commands.md.
//!
//! Over one output step h, with the set points linear between samples
//! (u(t) = u_k + (t − t_k)/h·(u_{k+1} − u_k)), the exact solution of ẋ = A x + B u is
//! x_{k+1} = Φ x_k + Γ₀ u_k + Γ₁ u_{k+1}, read off one matrix exponential:
//!
//! ```text
//! exp([[A h, B h, 0], [0, 0, I], [0, 0, 0]]) = [[Φ, Γa, Γb], [0, I, I], [0, 0, I]],
//! Γ₀ = Γa − Γb,  Γ₁ = Γb.
//! ```

pub mod harmonic;
pub mod output;
pub mod propagate;
pub mod setpoint;

use crate::control::{ClosedLoop, INPUTS_PER_AXIS};
use nalgebra::{DMatrix, DVector};
use setpoint::SetPoint;

/// The discretised closed loop at one step size.
#[derive(Debug, Clone)]
pub struct Discrete {
    /// Output step, s.
    pub step_s: f64,
    /// Φ = exp(A h).
    pub phi: DMatrix<f64>,
    /// Γ₀ (weight of u_k).
    pub gamma0: DMatrix<f64>,
    /// Γ₁ (weight of u_{k+1}).
    pub gamma1: DMatrix<f64>,
}

impl Discrete {
    /// Exact first-order-hold discretisation of `cl` at step `step_s`.
    pub fn new(cl: &ClosedLoop, step_s: f64) -> Discrete {
        let nx = cl.a.nrows();
        let nu = cl.b.ncols();
        let n = nx + 2 * nu;
        let mut m = DMatrix::zeros(n, n);
        m.view_mut((0, 0), (nx, nx)).copy_from(&(&cl.a * step_s));
        m.view_mut((0, nx), (nx, nu)).copy_from(&(&cl.b * step_s));
        m.view_mut((nx, nx + nu), (nu, nu)).fill_with_identity();
        let e = m.exp();
        let phi = e.view((0, 0), (nx, nx)).into_owned();
        let ga = e.view((0, nx), (nx, nu)).into_owned();
        let gb = e.view((0, nx + nu), (nx, nu)).into_owned();
        Discrete {
            step_s,
            phi,
            gamma0: ga - &gb,
            gamma1: gb,
        }
    }
}

/// A simulated run: set inputs and outputs sampled at the output rate, stored sample-major
/// (`inputs[k·nu + i]`, `outputs[k·ny + i]`).
#[derive(Debug, Clone)]
pub struct Run {
    /// Sample times, s.
    pub t_s: Vec<f64>,
    /// Number of inputs per sample.
    pub nu: usize,
    /// Number of outputs per sample.
    pub ny: usize,
    /// Inputs, in the closed loop's input order.
    pub inputs: Vec<f64>,
    /// Outputs, in the closed loop's output order.
    pub outputs: Vec<f64>,
}

impl Run {
    /// An empty run with room for `samples` samples of `nu` inputs and `ny` outputs.
    pub fn with_capacity(nu: usize, ny: usize, samples: usize) -> Run {
        Run {
            t_s: Vec::with_capacity(samples),
            nu,
            ny,
            inputs: Vec::with_capacity(samples * nu),
            outputs: Vec::with_capacity(samples * ny),
        }
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t_s.len()
    }

    /// Whether the run has no samples.
    pub fn is_empty(&self) -> bool {
        self.t_s.is_empty()
    }

    /// The series of output `i`.
    pub fn output(&self, i: usize) -> impl Iterator<Item = f64> + '_ {
        self.outputs.iter().skip(i).step_by(self.ny).copied()
    }

    /// The series of input `i`.
    pub fn input(&self, i: usize) -> impl Iterator<Item = f64> + '_ {
        self.inputs.iter().skip(i).step_by(self.nu).copied()
    }

    /// The series of one named output, if the closed loop has it.
    pub fn output_series(&self, cl: &ClosedLoop, name: &str) -> Option<Vec<f64>> {
        Some(self.output(cl.output(name)?).collect())
    }

    /// Appends the samples of `other` (same inputs and outputs).
    pub fn extend(&mut self, other: &Run) {
        self.t_s.extend_from_slice(&other.t_s);
        self.inputs.extend_from_slice(&other.inputs);
        self.outputs.extend_from_slice(&other.outputs);
    }

    /// The series of one named input, if the closed loop has it.
    pub fn input_series(&self, cl: &ClosedLoop, name: &str) -> Option<Vec<f64>> {
        Some(self.input(cl.input(name)?).collect())
    }
}

/// Errors of the simulation.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimError {
    /// A non-physical request.
    #[error("{0}")]
    Invalid(String),
    /// No equilibrium at the first set point (singular A).
    #[error("the closed loop has no equilibrium at the first set point")]
    NoEquilibrium,
}

/// Simulates `setpoint` from rest in equilibrium at its first value, sampled at `rate_hz`.
pub fn simulate(cl: &ClosedLoop, setpoint: &dyn SetPoint, rate_hz: f64) -> Result<Run, SimError> {
    if !(rate_hz.is_finite() && rate_hz > 0.0) {
        return Err(SimError::Invalid(format!(
            "sample rate {rate_hz} Hz must be > 0"
        )));
    }
    let h = 1.0 / rate_hz;
    let disc = Discrete::new(cl, h);
    simulate_discrete(cl, &disc, setpoint)
}

/// As [`simulate`] with a discretisation computed beforehand (reuse it across set points).
pub fn simulate_discrete(
    cl: &ClosedLoop,
    disc: &Discrete,
    setpoint: &dyn SetPoint,
) -> Result<Run, SimError> {
    run_piecewise(&[(0.0, cl, disc, None)], setpoint)
}

/// The time loop over pieces `(from_s, closed loop, discretisation)` sorted by start time: from
/// rest in equilibrium at the first set point, the state carried across piece boundaries
/// ([`propagate`]: blocks of samples, matrix products over each block), collected into one run.
fn run_piecewise(pieces: &[Piece], setpoint: &dyn SetPoint) -> Result<Run, SimError> {
    let mut run: Option<Run> = None;
    propagate::run_blocks(pieces, setpoint, |block: &Run| -> Result<(), SimError> {
        match &mut run {
            None => {
                let samples = (setpoint.duration_s() / pieces[0].2.step_s).ceil() as usize + 1;
                let mut all = Run::with_capacity(block.nu, block.ny, samples);
                all.extend(block);
                run = Some(all);
            }
            Some(all) => all.extend(block),
        }
        Ok(())
    })?;
    run.ok_or_else(|| SimError::Invalid("no samples simulated".into()))
}

/// As [`simulate`], handing the run to `sink` in blocks of at most
/// [`propagate::BLOCK_SAMPLES`] samples as they are simulated (for output written while the
/// simulation runs: memory independent of the run's length).
pub fn simulate_blocks<E: From<SimError>>(
    cl: &ClosedLoop,
    setpoint: &dyn SetPoint,
    rate_hz: f64,
    sink: impl FnMut(&Run) -> Result<(), E>,
) -> Result<(), E> {
    if !(rate_hz.is_finite() && rate_hz > 0.0) {
        return Err(SimError::Invalid(format!("sample rate {rate_hz} Hz must be > 0")).into());
    }
    let disc = Discrete::new(cl, 1.0 / rate_hz);
    propagate::run_blocks(&[(0.0, cl, &disc, None)], setpoint, sink)
}

/// Most samples one simulation computes (bounds its memory: each sample holds every input
/// and output of the closed loop).
pub const MAX_SAMPLES: usize = 2_000_000;

/// One stretch of a run: start time, closed loop, discretisation and, for a long move, the set
/// position (axis order, m) at which the closed loop was assembled.
pub(crate) type Piece<'a> = (f64, &'a ClosedLoop, &'a Discrete, Option<&'a [f64]>);

/// The deviation at the point of the workpiece now under the tool: the closed loop's TCP
/// outputs refer to the point under the TCP where it was assembled; since then the TCP has moved
/// by Δr = set position − `origin` relative to the workpiece (ISO 841 axis coordinates), and
/// the workpiece body's rotation θ moves that point by θ × Δr more, so the deviation there is
/// tcp·q + Δr × θ. Continuous across segment switches, where the piecewise-constant point would
/// step by θ × (segment length).
fn follow_the_tool(
    cl: &ClosedLoop,
    origin: &[f64],
    x: &DVector<f64>,
    u: &DVector<f64>,
    y: &mut DVector<f64>,
) {
    let n = cl.model.n_dof();
    let theta = &cl.model.nest_rotation * x.rows(0, n);
    let mut dr = nalgebra::Vector3::zeros();
    for (i, axis) in cl.axes.iter().enumerate() {
        dr[axis.index()] += u[INPUTS_PER_AXIS * i] - origin[i];
    }
    let shift = dr.cross(&nalgebra::Vector3::new(theta[0], theta[1], theta[2]));
    let na = cl.axes.len();
    for k in 0..3 {
        y[na + k] += shift[k];
    }
}

/// A closed loop assembled at one stretch of a long move, with its discretisation; it is used
/// from `from_s` on (until the next segment starts).
#[derive(Debug, Clone)]
pub struct Segment {
    /// Start time, s.
    pub from_s: f64,
    /// The closed loop assembled at the middle of the stretch.
    pub closed_loop: ClosedLoop,
    /// Its discretisation at the run's step.
    pub discrete: Discrete,
    /// Set position at which it was assembled, relative to the set point's origin (machine axis
    /// order, m): the TCP outputs then follow the point of the workpiece under the tool.
    pub set_position_m: Vec<f64>,
}

/// Simulates a set point over several segments, each with the model assembled where the axis
/// then is (position dependence along long moves). The state carries over unchanged at a
/// switch: displacements along the drive are rigid-body motions that neither model strains
/// (K·v = D·v = 0 for the drive mode v), so both models read the same state alike and only the
/// stiffness met by the deformation changes. Segments must share one machine and step size.
pub fn simulate_segments(segments: &[Segment], setpoint: &dyn SetPoint) -> Result<Run, SimError> {
    let pieces: Vec<Piece> = segments
        .iter()
        .map(|s| {
            (
                s.from_s,
                &s.closed_loop,
                &s.discrete,
                Some(s.set_position_m.as_slice()),
            )
        })
        .collect();
    run_piecewise(&pieces, setpoint)
}

/// Longest stretch of a move simulated on one assembly of the model, m (see [`move_segments`]).
pub(crate) const MOVE_SEGMENT_M: f64 = 0.01;

/// The segments of a jerk-limited move of axis `axis_index` from `start_m` (machine axis order):
/// the travel is cut into ⌈|D| / 10 mm⌉ equal stretches, each simulated on the model assembled at
/// its middle and entered when the set position reaches it; the TCP outputs follow the point of
/// the workpiece under the tool (continuous across switches). On the demo, a 250 mm X move's
/// z deviation changes by its whole amplitude as the table travels over the saddle: one
/// assembly misses 99 % of it, 50 mm stretches 20 %, 10 mm stretches 6.8 % (0.05 µm) against
/// 2 mm stretches (tests/sim.rs). The paper's 20 mm move runs on two assemblies.
pub fn move_segments(
    machine: &crate::machine::Machine,
    start_m: &[f64],
    axis_index: usize,
    mv: &setpoint::JerkLimitedMove,
    rate_hz: f64,
) -> Result<Vec<Segment>, crate::control::ControlError> {
    let n = (mv.distance_m.abs() / MOVE_SEGMENT_M).ceil().max(1.0) as usize;
    (0..n)
        .map(|j| {
            let mut pose = start_m.to_vec();
            let mut set_position_m = vec![0.0; start_m.len()];
            set_position_m[axis_index] = mv.distance_m * (j as f64 + 0.5) / n as f64;
            pose[axis_index] += set_position_m[axis_index];
            let pose = crate::machine::Pose::new(machine, &pose)?;
            let closed_loop = ClosedLoop::new(machine, &pose)?;
            let discrete = Discrete::new(&closed_loop, 1.0 / rate_hz);
            let from_s = if j == 0 {
                0.0
            } else {
                mv.time_at_fraction(j as f64 / n as f64)
            };
            Ok(Segment {
                from_s,
                closed_loop,
                discrete,
                set_position_m,
            })
        })
        .collect()
}
