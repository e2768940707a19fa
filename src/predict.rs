//! Prediction: the EIJ a machine model gives for given circle-test conditions.
//!
//! A circle test is simulated on the closed loop assembled at its circle centre ([`crate::sim`],
//! harmonic steady state or time domain) and the simulated series is evaluated by the very
//! evaluation that serves measured series ([`crate::rtest::evaluate_joint`]), so that model and
//! measurement are compared like with like; a harmonic steady state is evaluated by that
//! evaluation's closed form ([`crate::rtest::harmonic`], equal to the sampled route to 1e-9). This stage sits between `sim`/`rtest` and its users:
//! the identification ([`crate::ident`]), EIJ maps over the workspace ([`crate::map`]) and
//! compensation tables.
//!
//! [`simulated_eij`] runs every (machine, test) pair in parallel (rayon); one closed loop is built
//! per (machine, distinct circle centre) and shared by the tests there. The order of the results
//! does not depend on the number of threads.
//!
//! ```
//! use eij::axes::{Axis, Direction, Eij, Plane};
//! use eij::machine::Machine;
//! use eij::predict::{simulated_eij, CircleTest, SimSettings};
//!
//! let path = concat!(env!("CARGO_MANIFEST_DIR"), "/machines/demo-vmc.toml");
//! let machine = Machine::from_file(std::path::Path::new(path))?;
//! let test = CircleTest::new(Plane::Zx, Direction::Ccw, 2.0, 5.0);
//! let eij = simulated_eij(&[machine], &[test], &SimSettings::default())?;
//! // In-talk of Z: the TCP lags behind the scale reading when Z accelerates.
//! assert!(eij[0][0][&Eij::new(Axis::Z, Axis::Z)].abs() > 0.1);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::axes::{Direction, Plane};
use crate::control::{ClosedLoop, ControlError, FrequencyForm, PoseChecks};
use crate::machine::{Machine, Pose, PoseError};
use crate::rtest::{self, EvalOptions, RtestError};
use crate::sim::setpoint::Circle;
use crate::sim::{harmonic, output, simulate_discrete, Discrete, SimError};
use rayon::prelude::*;
use std::sync::Arc;

pub use crate::axes::EijMap;

/// The conditions of one circle test (docs/commands.md: plane, direction, set radius, set
/// acceleration a = r·ω², circle centre).
#[derive(Debug, Clone, PartialEq)]
pub struct CircleTest {
    /// Plane.
    pub plane: Plane,
    /// Direction.
    pub direction: Direction,
    /// Set radius, mm.
    pub radius_mm: f64,
    /// Set acceleration, m/s².
    pub accel_m_s2: f64,
    /// Axis positions of the circle centre, m, in machine axis order (`None`:
    /// [`SimSettings::position_m`], else the machine's reference position).
    pub position_m: Option<Vec<f64>>,
}

impl CircleTest {
    /// A test at the default circle centre.
    pub fn new(plane: Plane, direction: Direction, radius_mm: f64, accel_m_s2: f64) -> Self {
        CircleTest {
            plane,
            direction,
            radius_mm,
            accel_m_s2,
            position_m: None,
        }
    }

    /// The same test with its circle centre at `position_m` (machine axis order, m).
    pub fn at(mut self, position_m: Vec<f64>) -> Self {
        self.position_m = Some(position_m);
        self
    }

    /// Circle frequency f = √(a/r)/(2π), Hz.
    pub fn freq_hz(&self) -> f64 {
        (self.accel_m_s2 / (self.radius_mm * 1e-3)).sqrt() / std::f64::consts::TAU
    }

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
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SolverKind {
    /// Harmonic steady state (one complex solve per test; default).
    Harmonic,
    /// Time-domain simulation with ramps, exactly like `eij simulate circle`.
    Time,
}

/// How circle tests are simulated (documented defaults in [`SimSettings::default`]).
#[derive(Debug, Clone, PartialEq)]
pub struct SimSettings {
    /// Harmonic steady state or time domain (harmonic).
    pub solver: SolverKind,
    /// Output rate of time-domain simulated tests, Hz (1000: 100 samples per revolution at
    /// 10 Hz; the first-order hold then scales a sine by 1 − (ωh)²/12 ≥ 1 − 3.3e-4).
    pub rate_hz: f64,
    /// Steady revolutions per simulated test (4).
    pub revolutions: u32,
    /// Samples per revolution of the harmonic steady state (128): nothing is sampled, but the
    /// closed-form evaluation reproduces the evaluation of this many samples per revolution
    /// (the phase slope's share of the internal path's ripple depends on it).
    pub harmonic_samples_per_revolution: usize,
    /// Axis positions of the circle centre for tests that give none, m (machine axis order;
    /// `None`: the machine's reference position).
    pub position_m: Option<Vec<f64>>,
}

impl Default for SimSettings {
    fn default() -> Self {
        SimSettings {
            solver: SolverKind::Harmonic,
            rate_hz: 1000.0,
            revolutions: 4,
            harmonic_samples_per_revolution: 128,
            position_m: None,
        }
    }
}

/// What failed while simulating or evaluating one test.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimulationFailure {
    /// The closed loop could not be built at the circle centre.
    #[error(transparent)]
    ClosedLoop(#[from] ControlError),
    /// The time-domain simulation failed.
    #[error(transparent)]
    Time(#[from] SimError),
    /// jωI − A is singular: a closed-loop pole at the circle frequency.
    #[error("the closed loop has a pole at the circle frequency")]
    Resonance,
    /// The simulated series could not be evaluated.
    #[error(transparent)]
    Evaluation(#[from] RtestError),
}

/// Errors of the prediction.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PredictError {
    /// A circle centre with the wrong number of axis positions.
    #[error("{test}: the circle centre has {given} axis positions, the machine {machine} has {axes} axes ({names})")]
    PositionLength {
        /// Index of the test in the slice given.
        index: usize,
        /// The test's label.
        test: String,
        /// Values given.
        given: usize,
        /// Machine name.
        machine: String,
        /// Number of axes of the machine.
        axes: usize,
        /// The axis names, comma separated.
        names: String,
    },
    /// A circle centre that is no pose of the machine (outside a stroke).
    #[error("{test}: test position")]
    Position {
        /// Index of the test in the slice given.
        index: usize,
        /// The test's label.
        test: String,
        /// Why it is no pose.
        #[source]
        source: Box<PoseError>,
    },
    /// Simulating a test on one of the machines failed.
    #[error("simulating {test}")]
    Simulation {
        /// The test's label (`closed loop` when the closed loop itself failed).
        test: String,
        /// Index of the machine in the slice given.
        machine: usize,
        /// What failed.
        #[source]
        source: Box<SimulationFailure>,
    },
}

impl PredictError {
    /// Index of the test whose conditions do not fit the machine, if that is the error.
    pub(crate) fn test_index(&self) -> Option<usize> {
        match self {
            PredictError::PositionLength { index, .. } | PredictError::Position { index, .. } => {
                Some(*index)
            }
            PredictError::Simulation { .. } => None,
        }
    }
}

/// Circle tests prepared for repeated simulation: circle centres resolved and checked against
/// the machine once, the distinct centres found (one closed loop per machine and centre).
#[derive(Debug, Clone)]
pub struct Prediction {
    tests: Vec<CircleTest>,
    settings: SimSettings,
    /// Distinct circle-centre positions of the tests.
    poses: Vec<Pose>,
    /// Index into `poses` per test.
    test_pose: Vec<usize>,
    /// Per circle centre, what the closed loops there share: the support checked once, the
    /// stability certificate of the latest loop checked in full (see [`PoseChecks`]).
    checks: Arc<Vec<PoseChecks>>,
}

impl Prediction {
    /// Resolves the circle centres of `tests` on `machine` and checks each distinct one once
    /// into a [`Pose`] (every machine later simulated must have the same axes and strokes, e.g.
    /// the same machine with other stiffness factors).
    pub fn new(
        machine: &Machine,
        tests: Vec<CircleTest>,
        settings: SimSettings,
    ) -> Result<Prediction, PredictError> {
        let default = settings
            .position_m
            .clone()
            .unwrap_or_else(|| machine.reference_pose().to_vec());
        let mut poses: Vec<Pose> = Vec::new();
        let mut test_pose = Vec::with_capacity(tests.len());
        for (index, t) in tests.iter().enumerate() {
            let pose = t.position_m.as_ref().unwrap_or(&default);
            let i = match poses.iter().position(|p| **p == **pose) {
                Some(i) => i,
                None => {
                    let pose = Pose::new(machine, pose).map_err(|source| match source {
                        PoseError::Length { got, expected, .. } => PredictError::PositionLength {
                            index,
                            test: t.label(),
                            given: got,
                            machine: machine.name().to_string(),
                            axes: expected,
                            names: machine
                                .axes()
                                .iter()
                                .map(|a| a.axis.name())
                                .collect::<Vec<_>>()
                                .join(", "),
                        },
                        source => PredictError::Position {
                            index,
                            test: t.label(),
                            source: Box::new(source),
                        },
                    })?;
                    poses.push(pose);
                    poses.len() - 1
                }
            };
            test_pose.push(i);
        }
        let checks = Arc::new(poses.iter().map(|_| PoseChecks::default()).collect());
        Ok(Prediction {
            tests,
            settings,
            poses,
            test_pose,
            checks,
        })
    }

    /// The tests.
    pub fn tests(&self) -> &[CircleTest] {
        &self.tests
    }

    /// The simulation settings.
    pub fn settings(&self) -> &SimSettings {
        &self.settings
    }

    /// The circle centre test `index` is simulated at: its own, else the settings', else the
    /// machine's reference position (m, machine axis order).
    pub fn position_m(&self, index: usize) -> &[f64] {
        &self.poses[self.test_pose[index]]
    }

    /// Simulated EIJ of every test on every machine (`result[machine][test]`), with the
    /// settings' solver.
    pub fn simulate(&self, machines: &[Machine]) -> Result<Vec<Vec<EijMap>>, PredictError> {
        self.simulate_with(machines, self.settings.solver)
    }

    /// As [`Prediction::simulate`] with an explicit solver; in parallel over all (machine,
    /// centre) closed loops, then over all (machine, test) pairs.
    pub(crate) fn simulate_with(
        &self,
        machines: &[Machine],
        solver: SolverKind,
    ) -> Result<Vec<Vec<EijMap>>, PredictError> {
        let np = self.poses.len();
        let loops: Vec<Result<(ClosedLoop, Prepared), PredictError>> = (0..machines.len() * np)
            .into_par_iter()
            .map(|k| {
                let (m, p) = (&machines[k / np], k % np);
                let cl = ClosedLoop::new_near(m, &self.poses[p], &self.checks[p]).map_err(|e| {
                    PredictError::Simulation {
                        test: "closed loop".into(),
                        machine: k / np,
                        source: Box::new(e.into()),
                    }
                })?;
                let prepared = match solver {
                    SolverKind::Time => {
                        Prepared::Time(Discrete::new(&cl, 1.0 / self.settings.rate_hz))
                    }
                    SolverKind::Harmonic => Prepared::Harmonic(cl.frequency_form()),
                };
                Ok((cl, prepared))
            })
            .collect();
        let loops: Vec<(ClosedLoop, Prepared)> = loops.into_iter().collect::<Result<_, _>>()?;
        let nt = self.tests.len();
        let flat: Vec<Result<EijMap, PredictError>> = (0..machines.len() * nt)
            .into_par_iter()
            .map(|k| {
                let (s, t) = (k / nt, k % nt);
                let (cl, prepared) = &loops[s * np + self.test_pose[t]];
                run_test(cl, prepared, &self.tests[t], &self.settings).map_err(|source| {
                    PredictError::Simulation {
                        test: self.tests[t].label(),
                        machine: s,
                        source: Box::new(source),
                    }
                })
            })
            .collect();
        let mut out = Vec::with_capacity(machines.len());
        let mut it = flat.into_iter();
        for _ in 0..machines.len() {
            out.push((&mut it).take(nt).collect::<Result<Vec<_>, _>>()?);
        }
        Ok(out)
    }
}

/// Simulated EIJ of `tests` on every machine of `machines` (`result[machine][test]`), in
/// parallel; circle centres are checked against each machine.
pub fn simulated_eij(
    machines: &[Machine],
    tests: &[CircleTest],
    settings: &SimSettings,
) -> Result<Vec<Vec<EijMap>>, PredictError> {
    let mut out = Vec::with_capacity(machines.len());
    for m in machines {
        let prediction = Prediction::new(m, tests.to_vec(), settings.clone())?;
        out.push(prediction.simulate(std::slice::from_ref(m))?.remove(0));
    }
    Ok(out)
}

/// A closed loop prepared for one solver: discretised for the time domain, reduced to
/// Hessenberg form for the harmonic steady state (once for all tests at its circle centre).
enum Prepared {
    Time(Discrete),
    Harmonic(FrequencyForm),
}

/// Simulates and evaluates one test on a prepared closed loop: the time domain sampled and
/// evaluated like a measurement, the harmonic steady state by the closed form of that
/// evaluation ([`rtest::harmonic`]) on the window the sampled route would keep.
fn run_test(
    cl: &ClosedLoop,
    prepared: &Prepared,
    test: &CircleTest,
    settings: &SimSettings,
) -> Result<EijMap, SimulationFailure> {
    let radius_m = test.radius_mm * 1e-3;
    match prepared {
        Prepared::Time(disc) => {
            let mut circle = Circle::new(test.plane, radius_m, test.accel_m_s2, test.direction);
            circle.steady_revolutions = settings.revolutions;
            let run = simulate_discrete(cl, disc, &circle)?;
            let series = output::to_series(cl, &run, "simulated series".into())?;
            let opts = EvalOptions {
                plane: Some(test.plane),
                radius_mm: Some(test.radius_mm),
            };
            let (_, joint) = rtest::evaluate_joint(&series, &opts)?;
            Ok(joint.eij.value_map())
        }
        Prepared::Harmonic(form) => {
            let ph = harmonic::circle_phasors_in(
                form,
                &cl.axes,
                test.plane,
                radius_m,
                test.accel_m_s2,
                test.direction,
            )
            .ok_or(SimulationFailure::Resonance)?;
            let steady = harmonic::steady_harmonic(cl, test.plane, &ph);
            let window = harmonic::steady_window(
                ph.omega,
                settings.harmonic_samples_per_revolution,
                settings.revolutions as usize,
            );
            Ok(rtest::harmonic::joint_eij(
                &steady,
                test.radius_mm,
                &window,
                &test.label(),
            )?)
        }
    }
}
