//! The identification problem: measured tests, the parameters fitted to them, weighted
//! residuals r = P·(E_sim − E_meas)/σ (P eliminates the static terms, see [`super::statics`])
//! and their central-difference Jacobian, and the problem as argmin sees it (`Reduced`:
//! residual operator, Jacobian and cost over the free parameters; a trial point whose closed
//! loop cannot be simulated has infinite cost, so that the optimiser rejects the step).

use super::parameters::{to_factor, to_theta, Parameter};
use super::settings::SIMULATION_RESOLUTION;
use super::statics::{Row, Statics};
use super::{IdentError, Settings};
use crate::axes::EijEstimates;
use crate::machine::Machine;
use crate::predict::{CircleTest, EijMap, PredictError, Prediction, SolverKind};
use argmin::core::{CostFunction, Jacobian, Operator};
use nalgebra::{DMatrix, DVector};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

/// One measured circle test: its conditions and measured EIJ with their uncertainty.
#[derive(Debug, Clone, PartialEq)]
pub struct TestCase {
    /// Where it came from (file, or file and table rows).
    pub source: String,
    /// The conditions it was measured under, simulated alike.
    pub circle: CircleTest,
    /// Measured value and standard uncertainty σ per parameter, µm·s²/m.
    pub measured: EijEstimates,
    /// The clock it was recorded on (tests sharing one time offset between scales and R-Test,
    /// e.g. the files of one folder); `None`: its own (a table row group).
    pub clock: Option<String>,
}

impl TestCase {
    /// A short label of the conditions (see [`CircleTest::label`]).
    pub fn label(&self) -> String {
        self.circle.label()
    }
}

/// The identification problem: base machine, parameters, tests.
#[derive(Debug)]
pub struct Problem {
    machine: Machine,
    params: Vec<Parameter>,
    tests: Vec<TestCase>,
    settings: Settings,
    /// The tests' conditions prepared for simulation.
    prediction: Prediction,
    /// The residual rows.
    rows: Vec<Row>,
    /// The static terms eliminated from the residuals.
    statics: Statics,
    /// Parameter sets simulated so far.
    evaluations: AtomicU64,
    /// The latest simulations by parameter set, shared with clones (they simulate the same
    /// tests; only the static terms may differ, which the simulations do not depend on).
    cache: Arc<Mutex<SimCache>>,
    /// Trial points that could not be simulated (rejected steps).
    unsimulable: AtomicU64,
}

impl Clone for Problem {
    fn clone(&self) -> Self {
        Problem {
            machine: self.machine.clone(),
            params: self.params.clone(),
            tests: self.tests.clone(),
            settings: self.settings.clone(),
            prediction: self.prediction.clone(),
            rows: self.rows.clone(),
            statics: self.statics.clone(),
            evaluations: AtomicU64::new(self.evaluations()),
            cache: Arc::clone(&self.cache),
            unsimulable: AtomicU64::new(self.unsimulable()),
        }
    }
}

/// The weighted error Jacobian, the weighted errors, and the parameters whose difference was
/// one-sided ([`Problem::error_jacobian_edges`]).
pub(crate) type JacobianEdges = (DMatrix<f64>, DVector<f64>, Vec<usize>);

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
            let (a, b) = t.circle.plane.axes();
            for ax in [a, b] {
                if machine.axis(ax).is_none() {
                    return Err(IdentError::Test {
                        input: t.source.clone(),
                        message: format!(
                            "plane {} needs axis {ax}, which the model {} does not have",
                            t.circle.plane,
                            machine.name()
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
        let circles = tests.iter().map(|t| t.circle.clone()).collect();
        let prediction =
            Prediction::new(&machine, circles, settings.simulation.clone()).map_err(|e| match e
                .test_index()
            {
                Some(i) => IdentError::Conditions {
                    input: tests[i].source.clone(),
                    source: Box::new(e),
                },
                None => e.into(),
            })?;
        let rows = tests
            .iter()
            .enumerate()
            .flat_map(|(i, t)| {
                t.measured.iter().map(move |(eij, m)| Row {
                    test: i,
                    eij: *eij,
                    sigma: m.std_err.max(settings.sigma_floor),
                    r_over_a: t.circle.radius_mm / t.circle.accel_m_s2,
                    direction: t.circle.direction,
                })
            })
            .collect::<Vec<_>>();
        let mut problem = Problem {
            machine,
            params,
            tests,
            settings,
            prediction,
            rows,
            statics: Statics::new(&[], &[], super::StaticTerms::None, &[]),
            evaluations: AtomicU64::new(0),
            cache: Arc::default(),
            unsimulable: AtomicU64::new(0),
        };
        problem.statics = problem.statics_with(&[]);
        Ok(problem)
    }

    /// The static terms of the settings' mode, with reversal terms forced for the groups
    /// `reversal` (indices into [`Statics::groups`]).
    pub(crate) fn statics_with(&self, reversal: &[usize]) -> Statics {
        let tests: Vec<_> = self
            .tests
            .iter()
            .enumerate()
            .map(|(i, t)| {
                (
                    t.circle.plane,
                    self.position_m(i).to_vec(),
                    t.circle.accel_m_s2,
                    t.circle.direction,
                )
            })
            .collect();
        let statics = Statics::new(&tests, &self.rows, self.settings.static_terms, reversal);
        if self.settings.static_terms == super::StaticTerms::None {
            return statics;
        }
        let planes: Vec<_> = self.tests.iter().map(|t| t.circle.plane).collect();
        statics.with_clocks(&self.clock_of(), &self.rows, &planes)
    }

    /// The clock of every test: the folder of its file (one R-Test session), `""` for tests
    /// from memory; EIJ tables have none of their own (each table row group its own).
    pub fn clock_of(&self) -> Vec<String> {
        self.tests
            .iter()
            .enumerate()
            .map(|(i, t)| match &t.clock {
                Some(c) => c.clone(),
                None => format!("#{i}"),
            })
            .collect()
    }

    /// The same problem with other static terms.
    pub(crate) fn with_statics(&self, statics: Statics) -> Problem {
        let mut p = self.clone();
        p.statics = statics;
        p
    }

    /// The static terms eliminated from the residuals.
    pub fn statics(&self) -> &Statics {
        &self.statics
    }

    /// The residual rows: (test, EIJ, σ) in residual order.
    pub fn rows(&self) -> &[Row] {
        &self.rows
    }

    /// Degrees of freedom of the fit with `free` parameters: m − n − rank(A).
    pub fn dof(&self, free: usize) -> usize {
        self.rows.len().saturating_sub(free + self.statics.rank())
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

    /// The settings.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// The circle centre test `index` is simulated at, m (machine axis order).
    pub fn position_m(&self, index: usize) -> &[f64] {
        self.prediction.position_m(index)
    }

    /// Parameter sets simulated so far (every set counts once, whatever the number of tests).
    pub fn evaluations(&self) -> u64 {
        self.evaluations.load(Ordering::Relaxed)
    }

    /// Trial points so far that could not be simulated (unstable closed loop, resonance) and
    /// were rejected as steps.
    pub(crate) fn unsimulable(&self) -> u64 {
        self.unsimulable.load(Ordering::Relaxed)
    }

    /// θ = 1/p of the starting machine.
    pub fn initial_theta(&self) -> DVector<f64> {
        DVector::from_iterator(
            self.params.len(),
            self.params.iter().map(|p| to_theta(p.get(&self.machine))),
        )
    }

    /// The machine with factors p = 1/θ (an error for a factor that is not finite and > 0).
    pub fn machine_at(&self, theta: &DVector<f64>) -> Result<Machine, IdentError> {
        let mut m = self.machine.clone();
        for (p, t) in self.params.iter().zip(theta.iter()) {
            p.set(&mut m, to_factor(*t))?;
        }
        Ok(m)
    }

    /// `name=value, …` of the factors at θ (for messages).
    fn describe(&self, theta: &DVector<f64>) -> String {
        self.params
            .iter()
            .zip(theta.iter())
            .map(|(p, t)| format!("{}={:.4}", p.name, to_factor(*t)))
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// Simulated EIJ of every test for every parameter vector, in parallel over all
    /// (parameter vector, test) pairs; the order of the result does not depend on threads.
    pub fn simulate_many(&self, thetas: &[DVector<f64>]) -> Result<Vec<Vec<EijMap>>, IdentError> {
        self.simulate_many_with(thetas, self.settings.simulation.solver)
    }

    /// As [`Problem::simulate_many`], with a result per parameter vector: one that cannot be
    /// simulated does not spoil the others.
    pub(crate) fn simulate_each(
        &self,
        thetas: &[DVector<f64>],
    ) -> Vec<Result<Vec<EijMap>, IdentError>> {
        match self.simulate_many(thetas) {
            Ok(all) => all.into_iter().map(Ok).collect(),
            Err(_) => thetas
                .iter()
                .map(|t| {
                    self.simulate_many(std::slice::from_ref(t))
                        .map(|mut v| v.remove(0))
                })
                .collect(),
        }
    }

    /// As [`Problem::simulate_many`] with an explicit solver. Parameter sets simulated
    /// recently (the centre and neighbours of a Jacobian, an accepted step) are taken from a
    /// cache and not simulated again; [`Problem::evaluations`] counts the ones simulated.
    pub(crate) fn simulate_many_with(
        &self,
        thetas: &[DVector<f64>],
        solver: SolverKind,
    ) -> Result<Vec<Vec<EijMap>>, IdentError> {
        let cached: Vec<Option<Arc<Vec<EijMap>>>> = {
            let cache = self.cache.lock().map_err(|_| poisoned())?;
            thetas.iter().map(|t| cache.get(t, solver)).collect()
        };
        let missing: Vec<usize> = (0..thetas.len()).filter(|&k| cached[k].is_none()).collect();
        let fresh = if missing.is_empty() {
            Vec::new()
        } else {
            let todo: Vec<DVector<f64>> = missing.iter().map(|&k| thetas[k].clone()).collect();
            self.simulate_uncached(&todo, solver)?
        };
        let mut cache = self.cache.lock().map_err(|_| poisoned())?;
        let mut out: Vec<Option<Vec<EijMap>>> = cached
            .into_iter()
            .map(|hit| hit.map(|sims| sims.as_ref().clone()))
            .collect();
        for (&k, sims) in missing.iter().zip(fresh) {
            cache.put(&thetas[k], solver, Arc::new(sims.clone()));
            out[k] = Some(sims);
        }
        out.into_iter()
            .collect::<Option<Vec<_>>>()
            .ok_or_else(poisoned)
    }

    fn simulate_uncached(
        &self,
        thetas: &[DVector<f64>],
        solver: SolverKind,
    ) -> Result<Vec<Vec<EijMap>>, IdentError> {
        self.evaluations
            .fetch_add(thetas.len() as u64, Ordering::Relaxed);
        let machines: Vec<Machine> = thetas
            .iter()
            .map(|t| self.machine_at(t))
            .collect::<Result<_, _>>()?;
        self.prediction
            .simulate_with(&machines, solver)
            .map_err(|e| match e {
                PredictError::Simulation {
                    test,
                    machine,
                    source,
                } => IdentError::Simulation {
                    test,
                    params: self.describe(&thetas[machine]),
                    source,
                },
                other => other.into(),
            })
    }

    /// Weighted errors (E_sim − E_meas)/σ in the order of [`Problem::rows`] (tests, then
    /// parameters by name), before the static terms are eliminated.
    pub(crate) fn errors_of(&self, sims: &[EijMap]) -> DVector<f64> {
        DVector::from_iterator(
            self.rows.len(),
            self.rows.iter().map(|row| {
                let value = self.tests[row.test].measured[&row.eij].value;
                let sim = sims[row.test].get(&row.eij).copied().unwrap_or(f64::NAN);
                (sim - value) / row.sigma
            }),
        )
    }

    /// (E_a − E_b)/σ in the order of [`Problem::rows`], a difference within the simulation's
    /// rounding ([`SIMULATION_RESOLUTION`] of the test's largest EIJ) taken as none: a
    /// parameter that no test sees then has an exactly zero Jacobian column.
    fn weighted_difference(&self, a: &[EijMap], b: &[EijMap]) -> DVector<f64> {
        let largest = |s: &[EijMap], t: usize| s[t].values().fold(0.0_f64, |m, v| m.max(v.abs()));
        DVector::from_iterator(
            self.rows.len(),
            self.rows.iter().map(|row| {
                let get = |s: &[EijMap]| s[row.test].get(&row.eij).copied().unwrap_or(f64::NAN);
                let (x, y) = (get(a), get(b));
                let scale = largest(a, row.test).max(largest(b, row.test));
                if (x - y).abs() <= SIMULATION_RESOLUTION * scale {
                    0.0
                } else {
                    (x - y) / row.sigma
                }
            }),
        )
    }

    /// Residuals r = P·(E_sim − E_meas)/σ: the weighted errors without the static terms.
    pub(crate) fn residuals_of(&self, sims: &[EijMap]) -> DVector<f64> {
        self.statics.project(&self.errors_of(sims))
    }

    /// Residuals at θ.
    pub(crate) fn residuals_at(&self, theta: &DVector<f64>) -> Result<DVector<f64>, IdentError> {
        let sims = self.simulate_many(std::slice::from_ref(theta))?;
        Ok(self.residuals_of(&sims[0]))
    }

    /// Jacobian of the residuals and the residuals at θ (see [`Problem::error_jacobian_at`]):
    /// the projection is linear and does not depend on θ, so P·J is exact.
    pub(crate) fn jacobian_at(
        &self,
        theta: &DVector<f64>,
    ) -> Result<(DMatrix<f64>, DVector<f64>), IdentError> {
        let (j, e) = self.error_jacobian_at(theta)?;
        Ok((self.statics.project_matrix(&j), self.statics.project(&e)))
    }

    /// Central-difference Jacobian of the weighted errors ∂e/∂θ at θ (all 2n + 1 parameter
    /// sets in parallel) and the errors there. Central differences matter: the tests
    /// determine some combinations thousands of times more weakly than others, and a forward
    /// difference's O(h) error would swamp those directions.
    pub fn error_jacobian_at(
        &self,
        theta: &DVector<f64>,
    ) -> Result<(DMatrix<f64>, DVector<f64>), IdentError> {
        self.error_jacobian_edges(theta).map(|(j, e, _)| (j, e))
    }

    /// As [`Problem::error_jacobian_at`], with the parameters whose difference had to be
    /// one-sided because a neighbour of θ cannot be simulated: θ lies at the edge of what the
    /// model can run (e.g. the closed loop's stability limit).
    pub fn error_jacobian_edges(&self, theta: &DVector<f64>) -> Result<JacobianEdges, IdentError> {
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
        let sims = self.simulate_each(&thetas);
        let centre = sims[0].clone()?;
        let r0 = self.errors_of(&centre);
        let mut j = DMatrix::zeros(r0.len(), theta.len());
        let mut edges = Vec::new();
        for i in 0..theta.len() {
            if sims[1 + 2 * i].is_err() || sims[2 + 2 * i].is_err() {
                edges.push(i);
            }
            // Central difference; one-sided where the other side cannot be simulated (a
            // neighbour beyond the closed loop's stability limit).
            let column = match (&sims[1 + 2 * i], &sims[2 + 2 * i]) {
                (Ok(plus), Ok(minus)) => self.weighted_difference(plus, minus) / (2.0 * h[i]),
                (Ok(plus), Err(_)) => self.weighted_difference(plus, &centre) / h[i],
                (Err(_), Ok(minus)) => self.weighted_difference(&centre, minus) / h[i],
                (Err(e), Err(_)) => return Err(e.clone()),
            };
            j.set_column(i, &column);
        }
        Ok((j, r0, edges))
    }
}

/// The problem restricted to the identifiable parameters, as argmin sees it.
pub(crate) struct Reduced<'a> {
    pub(crate) problem: &'a Problem,
    /// Indices of the free parameters in the full vector.
    pub(crate) free: Vec<usize>,
    /// The full vector (fixed parameters at their start values).
    pub(crate) base: DVector<f64>,
}

impl Reduced<'_> {
    /// The full θ with the free entries taken from `theta`.
    pub(crate) fn full(&self, theta: &DVector<f64>) -> DVector<f64> {
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
        Ok(self
            .problem
            .trial(self.problem.residuals_at(&self.full(theta)))?)
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
            .trial(self.problem.residuals_at(&self.full(&clamped)))?
            .norm_squared();
        Ok(cost * (1.0 + 1e3 * excess) + 1e3 * excess)
    }
}

impl Problem {
    /// Residuals at a trial point; a point whose simulation fails (an unstable closed loop, a
    /// pole at a circle frequency) gets infinite residuals: a step there is rejected, not an
    /// abort. Other errors pass.
    fn trial(&self, r: Result<DVector<f64>, IdentError>) -> Result<DVector<f64>, IdentError> {
        match r {
            Err(IdentError::Simulation { .. }) => {
                self.unsimulable.fetch_add(1, Ordering::Relaxed);
                Ok(DVector::from_element(1, f64::INFINITY))
            }
            other => other,
        }
    }
}

/// Simulations kept: a central-difference Jacobian's 2n + 1 parameter sets and a few more.
const CACHE_SETS: usize = 64;

/// The latest simulated parameter sets (exact θ, solver) and their EIJ, oldest first.
#[derive(Debug, Default)]
struct SimCache {
    entries: std::collections::VecDeque<(Vec<u64>, SolverKind, Arc<Vec<EijMap>>)>,
}

impl SimCache {
    fn key(theta: &DVector<f64>) -> Vec<u64> {
        theta.iter().map(|t| t.to_bits()).collect()
    }

    fn get(&self, theta: &DVector<f64>, solver: SolverKind) -> Option<Arc<Vec<EijMap>>> {
        let key = Self::key(theta);
        self.entries
            .iter()
            .find(|(k, s, _)| *k == key && *s == solver)
            .map(|(_, _, sims)| Arc::clone(sims))
    }

    fn put(&mut self, theta: &DVector<f64>, solver: SolverKind, sims: Arc<Vec<EijMap>>) {
        if self.entries.len() == CACHE_SETS {
            self.entries.pop_front();
        }
        self.entries.push_back((Self::key(theta), solver, sims));
    }
}

/// The cache unusable (a thread panicked holding its lock) or a simulation result missing.
fn poisoned() -> IdentError {
    IdentError::Optimiser("simulation results lost (a simulation thread panicked)".into())
}
