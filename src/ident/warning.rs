//! What an identification found doubtful, as data: parameters the tests cannot determine,
//! a failed χ² test, bounds, implausible values, a suspected model mismatch, harmonic and
//! time-domain EIJ that disagree, and the warnings of reading the measured tests. Rendered to
//! text only where it is shown (`Display`: the command line, the report JSON's `warnings`), so
//! that a caller — the command line adding the option that answers a warning — matches the
//! variant, never the words ([`crate::rtest::Warning`] is the same for the evaluation).

use std::fmt;

use super::mismatch::ModelMismatch;
use super::verdict::Implausible;
use super::NotIdentifiable;
use crate::axes::Eij;
use crate::rtest::Named;

/// A warning of an identification.
#[derive(Debug, Clone, PartialEq)]
pub enum Warning {
    /// What reading a measured test or clock found (conditions, clocks).
    Measured(Named),
    /// A parameter kept at its start value: the tests cannot determine it.
    NotIdentifiable {
        /// Why, with the index of the parameter.
        parameter: NotIdentifiable,
        /// The names of all parameters.
        names: Vec<String>,
        /// The factor it is kept at.
        kept_at: f64,
    },
    /// The tests hardly separate some combination of parameters.
    NearSingular {
        /// The largest singular value of the weighted Jacobian.
        largest: f64,
        /// The smallest.
        smallest: f64,
    },
    /// The χ² test failed: the residual standard deviation s ≫ 1.
    Chi2Failed {
        /// s.
        residual_std: f64,
    },
    /// A parameter whose standard error is large against its value.
    WeaklyDetermined {
        /// The parameter.
        name: String,
        /// Its factor.
        value: f64,
        /// Its standard error.
        std_err: f64,
    },
    /// A parameter that ended on a bound of the factors.
    AtBound {
        /// The parameter.
        name: String,
        /// Its factor.
        value: f64,
        /// The lower bound of the factors.
        min: f64,
        /// The upper bound.
        max: f64,
    },
    /// An identified value no machine part plausibly has.
    Implausible {
        /// The parameter.
        name: String,
        /// Its factor.
        value: f64,
        /// Its standard error.
        std_err: Option<f64>,
        /// Which way it is implausible.
        why: Implausible,
    },
    /// Static terms or clock offsets that may absorb a model error.
    ModelMismatch(ModelMismatch),
    /// The harmonic optimisation's EIJ and the time-domain confirmation disagree.
    TimeDomainDisagrees {
        /// The test (its label).
        test: String,
        /// The parameter where they disagree most.
        eij: Eij,
        /// Harmonic, µm·s²/m.
        harmonic: f64,
        /// Time domain, µm·s²/m.
        time: f64,
    },
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Warning::Measured(n) => write!(f, "{n}"),
            Warning::NotIdentifiable {
                parameter,
                names,
                kept_at,
            } => f.write_str(&parameter.describe(names, *kept_at)),
            Warning::NearSingular { largest, smallest } => write!(
                f,
                "the tests hardly separate some parameter combination (singular values {largest:.3e} … {smallest:.3e}): correlated estimates"
            ),
            Warning::Chi2Failed { residual_std } => write!(
                f,
                "χ² test failed: residual std s = {residual_std:.2} ≫ 1, the model cannot reproduce the measured EIJ within their uncertainty (a missing parameter, a model error, or σ too small). The standard errors (scaled by s) do not cover such a model error: the identified factors may be off by more than they say"
            ),
            Warning::WeaklyDetermined {
                name,
                value,
                std_err,
            } => write!(
                f,
                "{name} = {value:.3} ± {std_err:.3} is only weakly determined by these tests (correlated with others, see the correlation matrix)"
            ),
            Warning::AtBound {
                name,
                value,
                min,
                max,
            } => write!(
                f,
                "{name} = {value} ended on a bound of the factors [{min}, {max}]: the data want a value outside"
            ),
            Warning::Implausible {
                name,
                value,
                std_err,
                why,
            } => f.write_str(&why.warning(name, *value, *std_err)),
            Warning::ModelMismatch(m) => f.write_str(&m.warning()),
            Warning::TimeDomainDisagrees {
                test,
                eij,
                harmonic,
                time,
            } => write!(
                f,
                "harmonic and time-domain EIJ disagree beyond 1 % / 0.01 µm·s²/m: {test} {eij}: harmonic {harmonic:.4}, time domain {time:.4}"
            ),
        }
    }
}
