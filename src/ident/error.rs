//! Errors of the identification, layered over those of the stages below it.

use crate::predict::{PredictError, SimulationFailure};

/// Errors of the identification (the errors of the stages below boxed, as they are large).
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
    /// A test or setting that cannot be used.
    #[error("{input}: {message}")]
    Test {
        /// Where the test or setting came from.
        input: String,
        /// What is wrong.
        message: String,
    },
    /// A test whose conditions the model cannot simulate (e.g. a circle centre outside a stroke).
    #[error("{input}")]
    Conditions {
        /// Where the test came from.
        input: String,
        /// What is wrong with its conditions.
        #[source]
        source: Box<PredictError>,
    },
    /// A prediction error not tied to one measured test.
    #[error(transparent)]
    Predict(Box<PredictError>),
    /// Reading or evaluating measured data (the message names file and line).
    #[error(transparent)]
    Rtest(#[from] crate::rtest::RtestError),
    /// Reading measured files (the message names file and line or key).
    #[error(transparent)]
    Measured(#[from] crate::measured::MeasuredError),
    /// A settings file that cannot be parsed (the message names file and place).
    #[error(transparent)]
    File(#[from] crate::machine::MachineError),
    /// Nothing to fit.
    #[error("{0}")]
    NoData(String),
    /// The simulation of a test failed for some parameter set.
    #[error("simulating {test} at {params}")]
    Simulation {
        /// The test.
        test: String,
        /// The parameter values.
        params: String,
        /// What failed.
        #[source]
        source: Box<SimulationFailure>,
    },
    /// The optimiser ran out of iterations.
    #[error("the optimiser did not converge in {iterations} iterations")]
    NotConverged {
        /// Iterations run.
        iterations: u64,
    },
    /// A parameter ended on a bound: the data want a value outside the bounds.
    #[error(
        "{name} ended at its bound {bound} ({value:.6}, allowed [{min}, {max}]): the data want a value outside"
    )]
    AtBound {
        /// Parameter name.
        name: String,
        /// The value it ended at.
        value: f64,
        /// The bound it ended on.
        bound: f64,
        /// Lower bound of the factors.
        min: f64,
        /// Upper bound of the factors.
        max: f64,
    },
    /// The fit ended where a neighbouring parameter value cannot be simulated (the closed
    /// loop's stability limit): the data want a value the model cannot run with.
    #[error("{names} ended at the limit of what the model can simulate ({detail}): the data want a value beyond it")]
    AtSimulationLimit {
        /// The parameters (with their values) at the limit.
        names: String,
        /// What fails beyond it.
        detail: String,
    },
    /// The singular value decomposition of the Jacobian did not converge.
    #[error("the singular value decomposition of the Jacobian did not converge")]
    Svd,
    /// An error of the optimiser itself.
    #[error("optimiser: {0}")]
    Optimiser(String),
}

impl From<PredictError> for IdentError {
    fn from(e: PredictError) -> Self {
        IdentError::Predict(Box::new(e))
    }
}
