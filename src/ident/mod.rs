//! Identification: stiffness reduction factors (and the like) fitted so that the simulated
//! circle tests reproduce the measured EIJ.
//!
//! Parameters p are optimised as compliance factors θ = 1/p, within bounds
//! 1/p_max ≤ θ ≤ 1/p_min (positive by construction). Deviations at the TCP are sums of elastic
//! deflections, each proportional to a compliance, so EIJ are nearly linear in θ: Gauss–Newton
//! steps then travel straight along the weakly determined combinations (e.g. X against Y
//! guideway compliance, both tilted by the same accelerations) instead of crawling along the
//! curved valley that ln p makes of them. The residuals
//! are r = (E_sim(p) − E_meas)/σ over every (test, EIJ) pair, where E_sim comes from simulating
//! the very same circle test (plane, direction, radius, acceleration) on the model and
//! evaluating it with the very same evaluation ([`crate::rtest`]). The finite-difference
//! Jacobian runs its columns and tests in parallel (rayon); results do not depend on the number
//! of threads. The uncertainty follows from cov(θ) ≈ s²·(JᵀJ)⁻¹, s² = rᵀr/(m − n).

pub mod config;
pub mod lm;
pub mod measured;
pub mod report;

use crate::axes::{Axis, Direction, Eij, Plane};
use crate::control::ClosedLoop;
use crate::machine::Machine;
use crate::rtest::{self, EvalOptions};
use crate::sim::setpoint::Circle;
use crate::sim::{harmonic, output, simulate_discrete, Discrete};
use argmin::core::observers::{Observe, ObserverMode};
use argmin::core::{CostFunction, Executor, Jacobian, Operator, State, TerminationReason, KV};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};

/// Errors of the identification.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IdentError {
    /// A parameter name that does not fit the machine.
    #[error("parameter '{name}': {message}")]
    Parameter {
        /// The name given.
        name: String,
        /// What is wrong.
        message: String,
    },
    /// A test the model cannot simulate.
    #[error("{input}: {message}")]
    Test {
        /// Where the test came from.
        input: String,
        /// What is wrong.
        message: String,
    },
    /// Reading or evaluating measured data (the message names file and line).
    #[error(transparent)]
    Rtest(#[from] crate::rtest::RtestError),
    /// An input file that cannot be used (the message names file and place).
    #[error("{0}")]
    Input(String),
    /// Nothing to fit.
    #[error("{0}")]
    NoData(String),
    /// The simulation of a test failed for some parameter set.
    #[error("simulating {test} at {params}: {message}")]
    Simulation {
        /// The test.
        test: String,
        /// The parameter values.
        params: String,
        /// What failed.
        message: String,
    },
    /// The optimiser did not converge or ended at a bound.
    #[error("{0}")]
    NotConverged(String),
    /// An error of the optimiser itself.
    #[error("optimiser: {0}")]
    Optimiser(String),
}

/// What a parameter scales.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ParameterKind {
    /// Normal and lateral guideway stiffness together (`<axis>.guideway`).
    Guideway,
    /// Normal guideway stiffness (`<axis>.guideway_normal`).
    GuidewayNormal,
    /// Lateral guideway stiffness (`<axis>.guideway_lateral`).
    GuidewayLateral,
    /// Axial stiffness of the ball-screw drive (`<axis>.screw`).
    Screw,
}

/// One identified quantity: a reduction factor on the catalogue data of one axis.
#[derive(Debug, Clone, PartialEq)]
pub struct Parameter {
    /// Name, e.g. `z.guideway_normal`.
    pub name: String,
    /// Index of the axis in [`Machine::axes`].
    pub axis_index: usize,
    /// What it scales.
    pub kind: ParameterKind,
}

impl Parameter {
    /// Parses `<axis>.<kind>` for `machine`.
    pub fn parse(name: &str, machine: &Machine) -> Result<Parameter, IdentError> {
        let bad = |m: String| IdentError::Parameter {
            name: name.to_string(),
            message: m,
        };
        let (axis, kind) = name
            .split_once('.')
            .ok_or_else(|| bad("expected <axis>.<kind>, e.g. z.guideway_normal".into()))?;
        let axis: Axis = axis.parse().map_err(bad)?;
        let axis_index = machine
            .axes
            .iter()
            .position(|a| a.axis == axis)
            .ok_or_else(|| bad(format!("the machine {} has no axis {axis}", machine.name)))?;
        let kind = match kind {
            "guideway" => ParameterKind::Guideway,
            "guideway_normal" => ParameterKind::GuidewayNormal,
            "guideway_lateral" => ParameterKind::GuidewayLateral,
            "screw" => ParameterKind::Screw,
            _ => {
                return Err(bad(format!(
                    "unknown kind '{kind}' (guideway, guideway_normal, guideway_lateral, screw)"
                )))
            }
        };
        let g = &machine.axes[axis_index].guideway;
        if kind == ParameterKind::Guideway && g.reduction_normal != g.reduction_lateral {
            return Err(bad(format!(
                "the machine's normal ({}) and lateral ({}) factors differ: identify {axis}.guideway_normal and {axis}.guideway_lateral instead",
                g.reduction_normal, g.reduction_lateral
            )));
        }
        Ok(Parameter {
            name: name.to_string(),
            axis_index,
            kind,
        })
    }

    /// The default set: normal and lateral guideway factors of every axis.
    pub fn default_set(machine: &Machine) -> Vec<Parameter> {
        let mut v = Vec::new();
        for (i, a) in machine.axes.iter().enumerate() {
            for (suffix, kind) in [
                ("guideway_normal", ParameterKind::GuidewayNormal),
                ("guideway_lateral", ParameterKind::GuidewayLateral),
            ] {
                v.push(Parameter {
                    name: format!("{}.{suffix}", a.axis),
                    axis_index: i,
                    kind,
                });
            }
        }
        v
    }

    /// The factor's value in `machine`.
    pub fn get(&self, machine: &Machine) -> f64 {
        let a = &machine.axes[self.axis_index];
        match self.kind {
            ParameterKind::Guideway | ParameterKind::GuidewayNormal => a.guideway.reduction_normal,
            ParameterKind::GuidewayLateral => a.guideway.reduction_lateral,
            ParameterKind::Screw => a.drive.reduction,
        }
    }

    /// Sets the factor in `machine`.
    pub fn set(&self, machine: &mut Machine, value: f64) {
        let a = &mut machine.axes[self.axis_index];
        match self.kind {
            ParameterKind::Guideway => {
                a.guideway.reduction_normal = value;
                a.guideway.reduction_lateral = value;
            }
            ParameterKind::GuidewayNormal => a.guideway.reduction_normal = value,
            ParameterKind::GuidewayLateral => a.guideway.reduction_lateral = value,
            ParameterKind::Screw => a.drive.reduction = value,
        }
    }
}

/// One measured circle test: its conditions and measured EIJ with their uncertainty.
#[derive(Debug, Clone, PartialEq)]
pub struct TestCase {
    /// Where it came from (file, or file and table rows).
    pub source: String,
    /// Plane.
    pub plane: Plane,
    /// Direction.
    pub direction: Direction,
    /// Radius, mm.
    pub radius_mm: f64,
    /// Set acceleration, m/s².
    pub accel_m_s2: f64,
    /// Axis positions of the circle centre, m (`None`: [`Settings::position_m`], else the
    /// machine's reference position).
    pub position_m: Option<Vec<f64>>,
    /// Measured value and standard uncertainty σ per parameter, µm·s²/m.
    pub measured: BTreeMap<Eij, (f64, f64)>,
}

impl TestCase {
    /// A short label: `zx ccw 5.00 m/s²`, with the circle centre where one is given
    /// (`zx ccw 5.00 m/s² @ 150,-100,0 mm`).
    pub fn label(&self) -> String {
        let base = format!(
            "{} {} {:.2} m/s²",
            self.plane, self.direction, self.accel_m_s2
        );
        match &self.position_m {
            Some(p) => format!(
                "{base} @ {} mm",
                p.iter()
                    .map(|v| format!("{:.0}", v * 1e3))
                    .collect::<Vec<_>>()
                    .join(",")
            ),
            None => base,
        }
    }
}

/// How a test is simulated.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize, clap::ValueEnum,
)]
#[serde(rename_all = "kebab-case")]
pub enum SolverKind {
    /// Harmonic steady state (one complex solve per test; default).
    Harmonic,
    /// Time-domain simulation with ramps, exactly like `eij simulate circle`.
    Time,
}

/// Which optimiser.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize, clap::ValueEnum,
)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Levenberg–Marquardt on the weighted residuals (default).
    Lm,
    /// Nelder–Mead on the weighted sum of squares (robust fallback, slower).
    NelderMead,
}

/// Settings of an identification run (documented defaults).
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    /// Output rate of time-domain simulated tests, Hz (1000: 100 samples per revolution at
    /// 10 Hz; the first-order hold then scales a sine by 1 − (ωh)²/12 ≥ 1 − 3.3e-4).
    pub rate_hz: f64,
    /// Steady revolutions per simulated test (4).
    pub revolutions: u32,
    /// Lower bound of every factor (0.01).
    pub min_factor: f64,
    /// Upper bound of every factor (10).
    pub max_factor: f64,
    /// Iteration limit (50; 2000 for Nelder–Mead through [`config::IdentConfig`]).
    pub max_iters: u64,
    /// Relative cost decrease that counts as converged (1e-10).
    pub tol_cost: f64,
    /// Step in θ = 1/p that counts as converged (1e-8).
    pub tol_step: f64,
    /// Central-difference step, relative to θ (1e-3).
    pub fd_step: f64,
    /// Optimiser.
    pub method: Method,
    /// Smallest σ used to weight a measured value, µm·s²/m (1e-3): keeps noise-free data finite.
    pub sigma_floor: f64,
    /// Axis positions of the circle centre, m (machine axis order; `None`: reference position).
    pub position_m: Option<Vec<f64>>,
    /// How the tests are simulated inside the optimisation (harmonic).
    pub solver: SolverKind,
    /// Samples per revolution of the harmonic steady state (128).
    pub harmonic_samples_per_revolution: usize,
}

impl Settings {
    /// Bounds of θ = 1/p.
    pub fn theta_bounds(&self) -> (f64, f64) {
        (1.0 / self.max_factor, 1.0 / self.min_factor)
    }
}

/// Compliance factor θ = 1/p of a stiffness factor p.
fn to_theta(p: f64) -> f64 {
    1.0 / p
}

/// Stiffness factor p = 1/θ.
fn to_factor(theta: f64) -> f64 {
    1.0 / theta
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            rate_hz: 1000.0,
            revolutions: 4,
            min_factor: 0.01,
            max_factor: 10.0,
            max_iters: 50,
            tol_cost: 1e-10,
            tol_step: 1e-8,
            fd_step: 1e-3,
            method: Method::Lm,
            sigma_floor: 1e-3,
            position_m: None,
            solver: SolverKind::Harmonic,
            harmonic_samples_per_revolution: 128,
        }
    }
}

/// The identification problem: base machine, parameters, tests.
#[derive(Debug, Clone)]
pub struct Problem {
    machine: Machine,
    params: Vec<Parameter>,
    tests: Vec<TestCase>,
    settings: Settings,
    /// Distinct circle-centre positions of the tests.
    poses: Vec<Vec<f64>>,
    /// Index into `poses` per test.
    test_pose: Vec<usize>,
}

type EijMap = BTreeMap<Eij, f64>;

impl Problem {
    /// Checks that the model can run every test and builds the problem.
    pub fn new(
        machine: Machine,
        params: Vec<Parameter>,
        tests: Vec<TestCase>,
        settings: Settings,
    ) -> Result<Problem, IdentError> {
        if tests.is_empty() {
            return Err(IdentError::NoData("no measured tests given".into()));
        }
        if params.is_empty() {
            return Err(IdentError::NoData("no parameters to identify".into()));
        }
        for t in &tests {
            let (a, b) = t.plane.axes();
            for ax in [a, b] {
                if machine.axis(ax).is_none() {
                    return Err(IdentError::Test {
                        input: t.source.clone(),
                        message: format!(
                            "plane {} needs axis {ax}, which the model {} does not have",
                            t.plane, machine.name
                        ),
                    });
                }
            }
            if t.measured.is_empty() {
                return Err(IdentError::Test {
                    input: t.source.clone(),
                    message: "no EIJ values".into(),
                });
            }
        }
        for (i, p) in params.iter().enumerate() {
            if params[..i].iter().any(|q| q.name == p.name) {
                return Err(IdentError::Parameter {
                    name: p.name.clone(),
                    message: "given twice".into(),
                });
            }
            let v = p.get(&machine);
            if !(settings.min_factor..=settings.max_factor).contains(&v) {
                return Err(IdentError::Parameter {
                    name: p.name.clone(),
                    message: format!(
                        "initial value {v} outside the bounds [{}, {}]",
                        settings.min_factor, settings.max_factor
                    ),
                });
            }
        }
        let (poses, test_pose) = distinct_poses(&machine, &tests, &settings)?;
        Ok(Problem {
            machine,
            params,
            tests,
            settings,
            poses,
            test_pose,
        })
    }

    /// The parameters.
    pub fn parameters(&self) -> &[Parameter] {
        &self.params
    }

    /// The tests.
    pub fn tests(&self) -> &[TestCase] {
        &self.tests
    }

    /// The machine the problem starts from.
    pub fn machine(&self) -> &Machine {
        &self.machine
    }

    /// θ = 1/p of the starting machine.
    pub fn initial_theta(&self) -> DVector<f64> {
        DVector::from_iterator(
            self.params.len(),
            self.params.iter().map(|p| to_theta(p.get(&self.machine))),
        )
    }

    /// The machine with factors p = 1/θ.
    pub fn machine_at(&self, theta: &DVector<f64>) -> Machine {
        let mut m = self.machine.clone();
        for (p, t) in self.params.iter().zip(theta.iter()) {
            p.set(&mut m, to_factor(*t));
        }
        m
    }

    fn describe(&self, theta: &DVector<f64>) -> String {
        self.params
            .iter()
            .zip(theta.iter())
            .map(|(p, t)| format!("{}={:.4}", p.name, to_factor(*t)))
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// Simulates and evaluates one test on a prepared closed loop (`disc` for the time domain).
    fn run_test(
        &self,
        cl: &ClosedLoop,
        disc: Option<&Discrete>,
        test: &TestCase,
    ) -> Result<EijMap, String> {
        let run = match disc {
            Some(disc) => {
                let mut circle = Circle::new(
                    test.plane,
                    test.radius_mm * 1e-3,
                    test.accel_m_s2,
                    test.direction,
                );
                circle.steady_revolutions = self.settings.revolutions;
                simulate_discrete(cl, disc, &circle).map_err(|e| e.to_string())?
            }
            None => {
                let ph = harmonic::circle_phasors(
                    cl,
                    test.plane,
                    test.radius_mm * 1e-3,
                    test.accel_m_s2,
                    test.direction,
                )
                .ok_or("the closed loop has a pole at the circle frequency")?;
                harmonic::steady_circle(
                    &ph,
                    self.settings.harmonic_samples_per_revolution,
                    self.settings.revolutions as usize,
                )
            }
        };
        let series = output::to_series(cl, &run, test.label()).map_err(|e| e.to_string())?;
        let opts = EvalOptions {
            plane: Some(test.plane),
            radius_mm: Some(test.radius_mm),
        };
        let (_, joint) = rtest::evaluate_joint(&series, &opts).map_err(|e| e.to_string())?;
        Ok(joint.eij)
    }

    /// Simulated EIJ of every test for every parameter vector, in parallel over all
    /// (parameter vector, test) pairs; the order of the result does not depend on threads.
    pub fn simulate_many(&self, thetas: &[DVector<f64>]) -> Result<Vec<Vec<EijMap>>, IdentError> {
        self.simulate_many_with(thetas, self.settings.solver)
    }

    /// As [`Problem::simulate_many`] with an explicit solver.
    pub fn simulate_many_with(
        &self,
        thetas: &[DVector<f64>],
        solver: SolverKind,
    ) -> Result<Vec<Vec<EijMap>>, IdentError> {
        let np = self.poses.len();
        let loops: Vec<Result<(ClosedLoop, Option<Discrete>), IdentError>> = (0..thetas.len() * np)
            .into_par_iter()
            .map(|k| {
                let theta = &thetas[k / np];
                let m = self.machine_at(theta);
                let cl = ClosedLoop::new(&m, &self.poses[k % np]).map_err(|e| {
                    IdentError::Simulation {
                        test: "closed loop".into(),
                        params: self.describe(theta),
                        message: e.to_string(),
                    }
                })?;
                let disc = (solver == SolverKind::Time)
                    .then(|| Discrete::new(&cl, 1.0 / self.settings.rate_hz));
                Ok((cl, disc))
            })
            .collect();
        let loops: Vec<(ClosedLoop, Option<Discrete>)> =
            loops.into_iter().collect::<Result<_, _>>()?;
        let nt = self.tests.len();
        let flat: Vec<Result<EijMap, IdentError>> = (0..thetas.len() * nt)
            .into_par_iter()
            .map(|k| {
                let (s, t) = (k / nt, k % nt);
                let (cl, disc) = &loops[s * np + self.test_pose[t]];
                self.run_test(cl, disc.as_ref(), &self.tests[t])
                    .map_err(|message| IdentError::Simulation {
                        test: self.tests[t].label(),
                        params: self.describe(&thetas[s]),
                        message,
                    })
            })
            .collect();
        let mut out = Vec::with_capacity(thetas.len());
        let mut it = flat.into_iter();
        for _ in 0..thetas.len() {
            out.push((&mut it).take(nt).collect::<Result<Vec<_>, _>>()?);
        }
        Ok(out)
    }

    /// Weighted residuals (E_sim − E_meas)/σ in a fixed order: tests, then parameters by name.
    pub fn residuals_of(&self, sims: &[EijMap]) -> DVector<f64> {
        let mut r = Vec::new();
        for (test, sim) in self.tests.iter().zip(sims) {
            for (p, (value, sigma)) in &test.measured {
                let s = sigma.max(self.settings.sigma_floor);
                r.push((sim.get(p).copied().unwrap_or(f64::NAN) - value) / s);
            }
        }
        DVector::from_vec(r)
    }

    /// Residuals at θ.
    pub fn residuals_at(&self, theta: &DVector<f64>) -> Result<DVector<f64>, IdentError> {
        let sims = self.simulate_many(std::slice::from_ref(theta))?;
        Ok(self.residuals_of(&sims[0]))
    }

    /// Central-difference Jacobian ∂r/∂θ at θ (all 2n + 1 parameter sets in parallel) and the
    /// residuals there. Central differences matter: the tests determine some combinations
    /// thousands of times more weakly than others, and a forward difference's O(h) error would
    /// swamp those directions.
    pub fn jacobian_at(
        &self,
        theta: &DVector<f64>,
    ) -> Result<(DMatrix<f64>, DVector<f64>), IdentError> {
        let h: Vec<f64> = theta
            .iter()
            .map(|t| self.settings.fd_step * t.abs())
            .collect();
        let mut thetas = vec![theta.clone()];
        for i in 0..theta.len() {
            for sign in [1.0, -1.0] {
                let mut t = theta.clone();
                t[i] += sign * h[i];
                thetas.push(t);
            }
        }
        let sims = self.simulate_many(&thetas)?;
        let r0 = self.residuals_of(&sims[0]);
        let mut j = DMatrix::zeros(r0.len(), theta.len());
        for i in 0..theta.len() {
            let plus = self.residuals_of(&sims[1 + 2 * i]);
            let minus = self.residuals_of(&sims[2 + 2 * i]);
            j.set_column(i, &((plus - minus) / (2.0 * h[i])));
        }
        Ok((j, r0))
    }
}

/// The distinct circle-centre positions of the tests (checked against the strokes) and the
/// index of each test's position.
fn distinct_poses(
    machine: &Machine,
    tests: &[TestCase],
    settings: &Settings,
) -> Result<(Vec<Vec<f64>>, Vec<usize>), IdentError> {
    let default = settings
        .position_m
        .clone()
        .unwrap_or_else(|| machine.reference_pose());
    let mut poses: Vec<Vec<f64>> = Vec::new();
    let mut index = Vec::with_capacity(tests.len());
    for t in tests {
        let pose = t.position_m.clone().unwrap_or_else(|| default.clone());
        if pose.len() != machine.axes.len() {
            return Err(IdentError::Test {
                input: t.source.clone(),
                message: format!(
                    "position_mm (from the folder's rtest.toml, --position-mm or the config) has {} values, the machine {} has {} axes ({})",
                    pose.len(),
                    machine.name,
                    machine.axes.len(),
                    machine.axes.iter().map(|a| a.axis.name()).collect::<Vec<_>>().join(", ")
                ),
            });
        }
        crate::mbs::Model::assemble(machine, &pose).map_err(|e| IdentError::Test {
            input: t.source.clone(),
            message: format!("test position: {e}"),
        })?;
        let i = match poses.iter().position(|p| *p == pose) {
            Some(i) => i,
            None => {
                poses.push(pose);
                poses.len() - 1
            }
        };
        index.push(i);
    }
    Ok((poses, index))
}

/// Simulated EIJ of `tests` (their conditions; measured values are ignored) on `machine`,
/// exactly as the identification computes them.
pub fn simulated_eij(
    machine: &Machine,
    tests: &[TestCase],
    settings: &Settings,
) -> Result<Vec<EijMap>, IdentError> {
    let (poses, test_pose) = distinct_poses(machine, tests, settings)?;
    let problem = Problem {
        machine: machine.clone(),
        params: Vec::new(),
        tests: tests.to_vec(),
        settings: settings.clone(),
        poses,
        test_pose,
    };
    Ok(problem.simulate_many(&[DVector::zeros(0)])?.remove(0))
}

/// The problem restricted to the identifiable parameters, as argmin sees it.
struct Reduced<'a> {
    problem: &'a Problem,
    /// Indices of the free parameters in the full vector.
    free: Vec<usize>,
    /// The full vector (fixed parameters at their start values).
    base: DVector<f64>,
}

impl Reduced<'_> {
    fn full(&self, theta: &DVector<f64>) -> DVector<f64> {
        let mut t = self.base.clone();
        for (k, &i) in self.free.iter().enumerate() {
            t[i] = theta[k];
        }
        t
    }
}

impl Operator for Reduced<'_> {
    type Param = DVector<f64>;
    type Output = DVector<f64>;
    fn apply(&self, theta: &DVector<f64>) -> Result<DVector<f64>, argmin::core::Error> {
        Ok(self.problem.residuals_at(&self.full(theta))?)
    }
}

impl Jacobian for Reduced<'_> {
    type Param = DVector<f64>;
    type Jacobian = DMatrix<f64>;
    fn jacobian(&self, theta: &DVector<f64>) -> Result<DMatrix<f64>, argmin::core::Error> {
        let (j, _) = self.problem.jacobian_at(&self.full(theta))?;
        Ok(DMatrix::from_fn(j.nrows(), self.free.len(), |r, c| {
            j[(r, self.free[c])]
        }))
    }
}

impl CostFunction for Reduced<'_> {
    type Param = DVector<f64>;
    type Output = f64;
    fn cost(&self, theta: &DVector<f64>) -> Result<f64, argmin::core::Error> {
        // Outside the bounds the model is evaluated on the bound and the excess is penalised,
        // so that the simplex is pushed back instead of drifting over a flat cost.
        let (lo, hi) = self.problem.settings.theta_bounds();
        let clamped = theta.map(|t| t.clamp(lo, hi));
        let excess = (theta - &clamped).norm_squared() / (hi - lo).powi(2);
        let cost = self
            .problem
            .residuals_at(&self.full(&clamped))?
            .norm_squared();
        Ok(cost * (1.0 + 1e3 * excess) + 1e3 * excess)
    }
}

/// Called after every iteration with (iteration, cost = Σr²).
pub type ProgressFn = dyn Fn(u64, f64) + Send + Sync;

struct Progress {
    costs: Arc<Mutex<Vec<f64>>>,
    callback: Option<Arc<ProgressFn>>,
    half: bool,
}

impl<I: State<Float = f64>> Observe<I> for Progress {
    fn observe_iter(&mut self, state: &I, _kv: &KV) -> Result<(), argmin::core::Error> {
        let cost = if self.half {
            2.0 * state.get_cost()
        } else {
            state.get_cost()
        };
        if let Ok(mut c) = self.costs.lock() {
            c.push(cost);
        }
        if let Some(cb) = &self.callback {
            cb(state.get_iter(), cost);
        }
        Ok(())
    }
}

/// One identified parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct Identified {
    /// Name.
    pub name: String,
    /// Start value.
    pub initial: f64,
    /// Identified value (the start value when not identifiable).
    pub value: f64,
    /// Standard error (delta method: p·σ_θ), `None` when not identifiable.
    pub std_err: Option<f64>,
    /// Whether the tests determine it.
    pub identifiable: bool,
}

/// The result of an identification.
#[derive(Debug, Clone)]
pub struct IdentResult {
    /// Parameters in the order given.
    pub parameters: Vec<Identified>,
    /// Correlation matrix of the identifiable parameters (order of `parameters`, others 0).
    pub correlation: DMatrix<f64>,
    /// Singular values of the weighted Jacobian ∂r/∂θ (θ = 1/p) at the solution, descending.
    pub singular_values: Vec<f64>,
    /// Σr² at the start.
    pub cost_initial: f64,
    /// Σr² at the solution.
    pub cost_final: f64,
    /// Σr² at the start and after every iteration.
    pub cost_history: Vec<f64>,
    /// Residual standard deviation s = √(Σr²/(m − n)).
    pub residual_std: f64,
    /// Number of residuals m.
    pub residuals: usize,
    /// Iterations.
    pub iterations: u64,
    /// Simulated EIJ per test at the start.
    pub simulated_initial: Vec<EijMap>,
    /// Simulated EIJ per test at the solution.
    pub simulated_final: Vec<EijMap>,
    /// The same by the time-domain simulation (confirmation of a harmonic optimisation).
    pub simulated_final_time: Option<Vec<EijMap>>,
    /// Warnings (non-identifiable parameters, near-singular combinations).
    pub warnings: Vec<String>,
    /// The identified machine.
    pub machine: Machine,
}

/// Best parameters, iterations and whether the solver converged (rather than ran out of
/// iterations), from a finished argmin state.
fn outcome<S: State<Param = DVector<f64>>>(
    st: &S,
) -> Result<(DVector<f64>, u64, bool), IdentError> {
    let converged = matches!(
        st.get_termination_reason(),
        Some(TerminationReason::SolverConverged)
    );
    let p = st
        .get_best_param()
        .cloned()
        .ok_or_else(|| IdentError::Optimiser("no result".into()))?;
    Ok((p, st.get_iter(), converged))
}

/// Column norms below this fraction of the largest mark a parameter the tests do not see.
const UNIDENTIFIABLE: f64 = 1e-6;

/// Runs the identification.
pub fn identify(
    problem: &Problem,
    progress: Option<Arc<ProgressFn>>,
) -> Result<IdentResult, IdentError> {
    let s = &problem.settings;
    let theta0 = problem.initial_theta();
    let n = theta0.len();
    let (j0, r0) = problem.jacobian_at(&theta0)?;
    let m = r0.len();
    let norms: Vec<f64> = (0..n).map(|i| j0.column(i).norm()).collect();
    let max_norm = norms.iter().cloned().fold(0.0, f64::max);
    let free: Vec<usize> = (0..n)
        .filter(|&i| norms[i] > UNIDENTIFIABLE * max_norm && norms[i] > 1e-12)
        .collect();
    let mut warnings = Vec::new();
    for i in (0..n).filter(|i| !free.contains(i)) {
        warnings.push(format!(
            "{} is not identifiable from the tests given (no influence on any measured EIJ); kept at {}",
            problem.params[i].name,
            to_factor(theta0[i])
        ));
    }
    if free.is_empty() {
        return Err(IdentError::NoData(
            "none of the parameters influences the measured EIJ: no overlap between parameters and tests".into(),
        ));
    }
    if m <= free.len() {
        return Err(IdentError::NoData(format!(
            "{m} measured values cannot determine {} parameters",
            free.len()
        )));
    }
    let reduced = Reduced {
        problem,
        free: free.clone(),
        base: theta0.clone(),
    };
    let start = DVector::from_iterator(free.len(), free.iter().map(|&i| theta0[i]));
    let (lo, hi) = s.theta_bounds();
    // Cost history: the start, then after every iteration.
    let costs = Arc::new(Mutex::new(vec![r0.norm_squared()]));
    let (theta_free, iterations, converged) = match s.method {
        Method::Lm => {
            let solver = lm::LevenbergMarquardt::new(
                DVector::from_element(free.len(), lo),
                DVector::from_element(free.len(), hi),
                s.tol_cost,
                s.tol_step,
            );
            let observer = Progress {
                costs: costs.clone(),
                callback: progress,
                half: true,
            };
            let res = Executor::new(reduced, solver)
                .configure(|st| st.param(start).max_iters(s.max_iters))
                .add_observer(observer, ObserverMode::Always)
                .run()
                .map_err(|e| IdentError::Optimiser(format!("{e:#}")))?;
            outcome(res.state())?
        }
        Method::NelderMead => {
            let mut simplex = vec![start.clone()];
            for i in 0..start.len() {
                let mut v = start.clone();
                v[i] *= 1.3;
                simplex.push(v);
            }
            let solver = argmin::solver::neldermead::NelderMead::new(simplex)
                // Converged when the simplex costs spread by less than 1e-7 of the
                // starting cost (NM has no gradient to test).
                .with_sd_tolerance((1e-7 * r0.norm_squared()).max(1e-12))
                .map_err(|e| IdentError::Optimiser(e.to_string()))?;
            let observer = Progress {
                costs: costs.clone(),
                callback: progress,
                half: false,
            };
            let res = Executor::new(reduced, solver)
                .configure(|st| st.max_iters(s.max_iters))
                .add_observer(observer, ObserverMode::Always)
                .run()
                .map_err(|e| IdentError::Optimiser(format!("{e:#}")))?;
            let (p, iterations, converged) = outcome(res.state())?;
            (p.map(|t| t.clamp(lo, hi)), iterations, converged)
        }
    };
    let mut theta = theta0.clone();
    for (k, &i) in free.iter().enumerate() {
        theta[i] = theta_free[k];
    }
    if !converged {
        return Err(IdentError::NotConverged(format!(
            "the optimiser did not converge in {iterations} iterations (raise --max-iters, or check the data); nothing exported"
        )));
    }
    for &i in &free {
        let at = |b: f64| (theta[i] - b).abs() < 1e-9;
        if at(lo) || at(hi) {
            return Err(IdentError::NotConverged(format!(
                "{} ended at its bound {} (allowed [{}, {}]): the data want a value outside; widen the bounds or check the data; nothing exported",
                problem.params[i].name,
                to_factor(theta[i]),
                s.min_factor,
                s.max_factor
            )));
        }
    }

    // Uncertainty at the solution.
    let (j_full, r) = problem.jacobian_at(&theta)?;
    let j = DMatrix::from_fn(m, free.len(), |row, c| j_full[(row, free[c])]);
    let dof = (m - free.len()) as f64;
    let cost_final = r.norm_squared();
    let s2 = cost_final / dof;
    let svd = j.clone().svd(false, false);
    let mut singular_values: Vec<f64> = svd.singular_values.iter().copied().collect();
    singular_values.sort_by(|a, b| b.total_cmp(a));
    if let (Some(first), Some(last)) = (singular_values.first(), singular_values.last()) {
        if *last < 1e-8 * first {
            warnings.push(format!(
                "the tests hardly separate some parameter combination (singular values {first:.3e} … {last:.3e}): correlated estimates"
            ));
        }
    }
    // χ² test of the fit: with honest σ, s² = χ²/(m − n) scatters about 1 by √(2/(m − n)).
    if s2 > 1.0 + 4.0 * (2.0 / dof).sqrt() {
        warnings.push(format!(
            "residual std s = {:.2} ≫ 1: the model cannot reproduce the measured EIJ within their uncertainty (a missing parameter, a model error, or σ too small); standard errors are scaled by s",
            s2.sqrt()
        ));
    }
    let jtj = j.transpose() * &j;
    let cov = jtj
        .clone()
        .try_inverse()
        .or_else(|| jtj.pseudo_inverse(1e-14).ok())
        .unwrap_or_else(|| DMatrix::zeros(free.len(), free.len()))
        * s2;
    let mut correlation = DMatrix::zeros(n, n);
    for (a, &i) in free.iter().enumerate() {
        for (b, &k) in free.iter().enumerate() {
            let d = (cov[(a, a)] * cov[(b, b)]).sqrt();
            correlation[(i, k)] = if d > 0.0 { cov[(a, b)] / d } else { 0.0 };
        }
    }
    let parameters: Vec<Identified> = problem
        .params
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let fi = free.iter().position(|&f| f == i);
            Identified {
                name: p.name.clone(),
                initial: to_factor(theta0[i]),
                value: to_factor(theta[i]),
                // p = 1/θ: σ_p = σ_θ/θ².
                std_err: fi.map(|k| cov[(k, k)].max(0.0).sqrt() / (theta[i] * theta[i])),
                identifiable: fi.is_some(),
            }
        })
        .collect();
    for q in &parameters {
        if let Some(se) = q.std_err.filter(|se| *se > 0.5 * q.value) {
            warnings.push(format!(
                "{} = {:.3} ± {:.3} is only weakly determined by these tests (correlated with others, see the correlation matrix)",
                q.name, q.value, se
            ));
        }
    }
    let sims = problem.simulate_many(&[theta0.clone(), theta.clone()])?;
    // The final result is confirmed once in the time domain (when optimised harmonically).
    let simulated_final_time = if s.solver == SolverKind::Harmonic {
        let time = problem
            .simulate_many_with(std::slice::from_ref(&theta), SolverKind::Time)?
            .remove(0);
        let mut worst = (0.0, String::new());
        for (i, (h, t)) in sims[1].iter().zip(&time).enumerate() {
            for (e, v) in h {
                let d = (v - t[e]).abs();
                let allowed = (0.01 * t[e].abs()).max(0.01);
                if d / allowed > worst.0 {
                    worst = (
                        d / allowed,
                        format!(
                            "{} {e}: harmonic {v:.4}, time domain {:.4}",
                            problem.tests[i].label(),
                            t[e]
                        ),
                    );
                }
            }
        }
        if worst.0 > 1.0 {
            warnings.push(format!(
                "harmonic and time-domain EIJ disagree beyond 1 % / 0.01 µm·s²/m: {}",
                worst.1
            ));
        }
        Some(time)
    } else {
        None
    };
    let cost_history = costs.lock().map(|c| c.clone()).unwrap_or_default();
    Ok(IdentResult {
        parameters,
        correlation,
        singular_values,
        cost_initial: r0.norm_squared(),
        cost_final,
        cost_history,
        residual_std: s2.sqrt(),
        residuals: m,
        iterations,
        simulated_initial: sims[0].clone(),
        simulated_final: sims[1].clone(),
        simulated_final_time,
        warnings,
        machine: problem.machine_at(&theta),
    })
}
