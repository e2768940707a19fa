//! A builder for an identification with documented defaults: the front door for library users.

use super::measured::{self, MeasuredOptions};
use super::{identify, IdentError, IdentResult, Method, Parameter, Problem, Settings, TestCase};
use crate::machine::Machine;
use crate::predict::SolverKind;
use std::path::{Path, PathBuf};

/// An identification to run: a machine, measured tests and what to fit.
///
/// Defaults (see [`Settings::default`] and [`MeasuredOptions::default`]): the normal and lateral
/// guideway factor of every axis and the stiffness factor of every elastic body
/// ([`Parameter::default_set`]); Levenberg–Marquardt with at most 50
/// iterations (Nelder–Mead: 2000); factors bounded to [0.01, 10]; tests simulated in the harmonic
/// steady state and the result confirmed in the time domain; measured R-Test series evaluated at
/// a set radius of 2 mm unless their folder's `rtest.toml` says otherwise.
///
/// ```
/// use eij::ident::{Identification, TestCase};
/// use eij::predict::{simulated_eij, CircleTest, SimSettings};
/// use eij::machine::Reduction;
/// use eij::{Direction, EijEstimates, Machine, Plane};
///
/// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/machines/demo-vmc.toml");
/// let machine = Machine::from_file(std::path::Path::new(path))?;
/// // "Measured" EIJ: the model with a Z guideway at 60 % of its catalogue stiffness.
/// let mut truth = machine.clone();
/// truth.set_reduction(2, Reduction::GuidewayNormal, 0.6)?;
/// let circles = vec![
///     CircleTest::new(Plane::Zx, Direction::Ccw, 2.0, 4.0),
///     CircleTest::new(Plane::Yz, Direction::Cw, 2.0, 6.0),
/// ];
/// let eij = simulated_eij(&[truth], &circles, &SimSettings::default())?.remove(0);
/// let tests = circles.into_iter().zip(eij).map(|(circle, values)| TestCase {
///     source: "synthetic".into(),
///     circle,
///     measured: EijEstimates::with_std_err(values, 0.02),
///     clock: None,
/// });
///
/// let result = Identification::new(machine)
///     .parameters(["z.guideway_normal"])
///     .tests(tests)
///     .run()?;
/// assert!((result.parameters[0].value - 0.6).abs() < 1e-3);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone)]
pub struct Identification {
    machine: Machine,
    parameters: Option<Vec<String>>,
    tests: Vec<TestCase>,
    measured: Vec<PathBuf>,
    measured_options: MeasuredOptions,
    settings: Settings,
}

impl Identification {
    /// An identification of `machine` with the defaults above and no tests yet.
    pub fn new(machine: Machine) -> Self {
        Identification {
            machine,
            parameters: None,
            tests: Vec::new(),
            measured: Vec::new(),
            measured_options: MeasuredOptions::default(),
            settings: Settings::default(),
        }
    }

    /// The parameters to fit, by name (`<axis>.<kind>`, kinds `guideway`, `guideway_normal`,
    /// `guideway_lateral`, `screw`; `<body>.stiffness` for an elastic body); default:
    /// [`Parameter::default_set`].
    pub fn parameters<S: Into<String>>(mut self, names: impl IntoIterator<Item = S>) -> Self {
        self.parameters = Some(names.into_iter().map(Into::into).collect());
        self
    }

    /// Adds tests with measured EIJ already at hand.
    pub fn tests(mut self, tests: impl IntoIterator<Item = TestCase>) -> Self {
        self.tests.extend(tests);
        self
    }

    /// Adds measured inputs, read when the identification runs: R-Test CSV files, folders of
    /// them (with `rtest.toml`), or EIJ tables.
    pub fn measured<P: AsRef<Path>>(mut self, paths: impl IntoIterator<Item = P>) -> Self {
        self.measured
            .extend(paths.into_iter().map(|p| p.as_ref().to_path_buf()));
        self
    }

    /// How measured inputs are read (set radius, σ of table values).
    pub fn measured_options(mut self, options: MeasuredOptions) -> Self {
        self.measured_options = options;
        self
    }

    /// The optimiser (default Levenberg–Marquardt).
    pub fn method(mut self, method: Method) -> Self {
        self.settings.method = method;
        self
    }

    /// How the tests are simulated during the optimisation (default harmonic).
    pub fn solver(mut self, solver: SolverKind) -> Self {
        self.settings.simulation.solver = solver;
        self
    }

    /// The iteration limit (default: the method's, [`Method::default_max_iters`]).
    pub fn max_iters(mut self, max_iters: u64) -> Self {
        self.settings.max_iters = Some(max_iters);
        self
    }

    /// Bounds of every factor (default [0.01, 10]).
    pub fn bounds(mut self, min_factor: f64, max_factor: f64) -> Self {
        self.settings.min_factor = min_factor;
        self.settings.max_factor = max_factor;
        self
    }

    /// All settings at once.
    pub fn settings(mut self, settings: Settings) -> Self {
        self.settings = settings;
        self
    }

    /// Reads the measured inputs, resolves the parameters and checks that the model can run
    /// every test.
    pub fn problem(self) -> Result<Problem, IdentError> {
        let params = match &self.parameters {
            None => Parameter::default_set(&self.machine),
            Some(names) => names
                .iter()
                .map(|n| Parameter::parse(n, &self.machine))
                .collect::<Result<_, _>>()?,
        };
        let mut tests = self.tests;
        if !self.measured.is_empty() {
            tests.extend(measured::load(&self.measured, &self.measured_options)?);
        }
        Problem::new(self.machine, params, tests, self.settings)
    }

    /// Runs the identification ([`identify`]).
    pub fn run(self) -> Result<IdentResult, IdentError> {
        identify(&self.problem()?, None)
    }
}
