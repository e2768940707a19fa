//! What an identification did on its own account, as data ([`Note`]): apart from the warnings
//! ([`super::Warning`]) so that the static terms can say why they are not fitted without
//! importing what the warnings are about.

use std::fmt;

use crate::predict::PredictError;

/// A note of an identification: what it did on its own account (terms it added or could not
/// fit, parameters fitted again, steps rejected, candidate tests left out). Not a doubt about
/// the result, rendered to text where it is shown, as [`Warning`].
#[derive(Debug, Clone, PartialEq)]
pub enum Note {
    /// A group measured at one acceleration: its static geometry is part of its EIJ.
    StaticsNotSeparable {
        /// The group ([`super::statics::StaticGroup::label`]).
        group: String,
    },
    /// Reversal terms fitted at a group because the data need them.
    ReversalTermsFitted {
        /// The group ([`super::statics::StaticGroup::label`]).
        group: String,
    },
    /// The identifiability at the solution differs from that at the start values: the fit was
    /// run again.
    IdentifiabilityChanged {
        /// Parameters determined now.
        determined: Vec<String>,
        /// Parameters not determined now, back at their start values.
        not_determined: Vec<String>,
    },
    /// Trial steps of the optimisation that could not be simulated and were rejected.
    RejectedSteps {
        /// How many.
        count: u64,
    },
    /// The candidate additional tests could not be simulated.
    CandidatesNotSimulated(PredictError),
    /// A candidate at a new circle-centre position counts as one test there.
    NewPositionCountsOnce,
}

impl fmt::Display for Note {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Note::StaticsNotSeparable { group } => write!(
                f,
                "static geometry not separable at {group} (one acceleration): taken as part of the EIJ"
            ),
            Note::ReversalTermsFitted { group } => write!(
                f,
                "reversal terms (static, sign flipping with the direction) fitted at {group}: the data need them"
            ),
            Note::IdentifiabilityChanged {
                determined,
                not_determined,
            } => {
                f.write_str("identifiability at the solution differs from that at the start values")?;
                if !determined.is_empty() {
                    write!(f, "; determined now: {}", determined.join(", "))?;
                }
                if !not_determined.is_empty() {
                    write!(
                        f,
                        "; not determined now (back to the start value): {}",
                        not_determined.join(", ")
                    )?;
                }
                f.write_str(": fitted again")
            }
            Note::RejectedSteps { count } => write!(
                f,
                "{count} trial step(s) could not be simulated (e.g. an unstable closed loop) and were rejected"
            ),
            Note::CandidatesNotSimulated(e) => {
                write!(f, "candidate tests could not be simulated: {e}")
            }
            Note::NewPositionCountsOnce => f.write_str(
                "a candidate at a new circle-centre position counts as one test there: its static geometry would be taken as part of its EIJ; measure it at two accelerations to separate it",
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn notes_with_numbers_and_names_render_them() {
        let changed = Note::IdentifiabilityChanged {
            determined: vec!["x.screw".into(), "y.screw".into()],
            not_determined: vec!["z.guideway".into()],
        };
        assert_eq!(
            changed.to_string(),
            "identifiability at the solution differs from that at the start values; determined \
             now: x.screw, y.screw; not determined now (back to the start value): z.guideway: \
             fitted again"
        );
        let released = Note::IdentifiabilityChanged {
            determined: vec!["x.screw".into()],
            not_determined: Vec::new(),
        };
        assert_eq!(
            released.to_string(),
            "identifiability at the solution differs from that at the start values; determined \
             now: x.screw: fitted again"
        );
        assert_eq!(
            Note::RejectedSteps { count: 3 }.to_string(),
            "3 trial step(s) could not be simulated (e.g. an unstable closed loop) and were rejected"
        );
        assert_eq!(
            Note::StaticsNotSeparable {
                group: "zx @ 150,-100,0 mm".into()
            }
            .to_string(),
            "static geometry not separable at zx @ 150,-100,0 mm (one acceleration): taken as \
             part of the EIJ"
        );
        assert_eq!(
            Note::ReversalTermsFitted {
                group: "xy @ 0,0,0 mm".into()
            }
            .to_string(),
            "reversal terms (static, sign flipping with the direction) fitted at xy @ 0,0,0 mm: \
             the data need them"
        );
    }
}
