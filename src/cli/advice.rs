//! Flag advice that the command line adds to the library's errors: the library speaks of
//! physics and files and never names a flag; only here are its errors tied to the options of
//! a command.

use eij::ident::IdentError;
use eij::map::MapError;
use eij::measured::MeasuredError;
use eij::predict::PredictError;
use eij::rtest::{Named, RtestError, Warning};

/// The error's message with its causes, `a: b: c`, as anyhow prints it.
fn chain(e: impl std::error::Error + Send + Sync + 'static) -> String {
    format!("{:#}", anyhow::Error::new(e))
}

/// `eij evaluate`: an ambiguous plane can be given with `--plane`.
pub fn evaluate(e: MeasuredError) -> anyhow::Error {
    match e {
        MeasuredError::Evaluation(RtestError::AmbiguousPlane { .. }) => {
            anyhow::anyhow!("{e}; give --plane")
        }
        e => e.into(),
    }
}

/// A warning of the evaluation with the option that answers it.
pub fn evaluate_warning(w: &Warning) -> String {
    match w {
        Warning::NoSetRadius { .. } => format!("{w}; give --radius-mm"),
        _ => w.to_string(),
    }
}

/// A warning of `eij identify` (its own or of the measured data it read), with the option
/// that answers it.
pub fn identify_warning(w: &eij::ident::Warning) -> String {
    match w {
        eij::ident::Warning::Measured(Named {
            warning: Warning::DefaultRadius { .. },
            ..
        }) => {
            format!("{w}; give --radius-mm or radius_mm in rtest.toml")
        }
        _ => w.to_string(),
    }
}

/// `eij identify` and `eij verify`: where the settings come from, and that nothing is exported
/// after a failed fit.
pub fn identify(e: IdentError) -> anyhow::Error {
    match e {
        IdentError::NotConverged { .. } => anyhow::anyhow!(
            "{e} (raise --max-iters, or check the data); nothing exported"
        ),
        IdentError::AtBound { .. } => anyhow::anyhow!(
            "{e}; widen the bounds or check the data; nothing exported"
        ),
        IdentError::AtSimulationLimit { .. } => anyhow::anyhow!(
            "{e}; check the model (a compliance missing elsewhere, the controller gains) or the data; nothing exported"
        ),
        IdentError::Conditions { ref source, .. }
            if matches!(**source, PredictError::PositionLength { .. }) =>
        {
            anyhow::anyhow!(
                "{} (the circle centre is position_mm from the folder's rtest.toml, --position-mm or the config)",
                chain(e)
            )
        }
        e => e.into(),
    }
}

/// `eij map`: grid and plane are flags.
pub fn map(e: MapError) -> anyhow::Error {
    match e {
        MapError::Grid { .. } | MapError::Plane { .. } => anyhow::anyhow!("--{e}"),
        e => e.into(),
    }
}
