//! What a reduction leaves doubtful, as data: a reduced body whose first free-free mode is off
//! the full model's. Rendered to text only where it is shown (`Display`: the command line and
//! the JSON's `warnings`), as [`crate::ident::Warning`].

use std::fmt;

use super::FeSummary;

/// The relative difference of the reduced body's first free-free frequency from the full
/// model's beyond which the reduction does not resolve the body: 1 %.
pub const FIRST_MODE_OFF: f64 = 1e-2;

/// A warning about an elastic body's reduction.
#[derive(Debug, Clone, PartialEq)]
pub enum Warning {
    /// The reduced body's first free-free mode is more than [`FIRST_MODE_OFF`] off the full
    /// model's.
    FirstModeOff {
        /// The body.
        body: String,
        /// The reduced body's first elastic free-free frequency, Hz.
        reduced_hz: f64,
        /// The full model's, Hz.
        full_hz: f64,
    },
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Warning::FirstModeOff {
                body,
                reduced_hz,
                full_hz,
            } => write!(
                f,
                "body {body}: the reduced body's first free-free mode ({reduced_hz:.2} Hz) is \
                 {:+.2} % off the full model's ({full_hz:.2} Hz): the reduction does not resolve \
                 the body; keep more modes (`modes` or `cutoff_hz`)",
                100.0 * (reduced_hz - full_hz) / full_hz
            ),
        }
    }
}

impl serde::Serialize for Warning {
    /// As its text (the JSON's `warnings` are sentences).
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

impl FeSummary {
    /// Doubts about the reduction: the first free-free mode more than [`FIRST_MODE_OFF`] off
    /// the full model's (none where the full model's frequencies were not computed).
    pub fn warnings(&self) -> Vec<Warning> {
        match (
            self.free_frequencies_hz.first(),
            self.full_free_frequencies_hz.first(),
        ) {
            (Some(&reduced_hz), Some(&full_hz))
                if ((reduced_hz - full_hz) / full_hz).abs() > FIRST_MODE_OFF =>
            {
                vec![Warning::FirstModeOff {
                    body: self.body.clone(),
                    reduced_hz,
                    full_hz,
                }]
            }
            _ => Vec::new(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn summary(reduced: &[f64], full: &[f64]) -> FeSummary {
        FeSummary {
            body: "column".into(),
            dofs: 0,
            interface_dofs: 0,
            modes: 0,
            mass_kg: 0.0,
            cog_m: [0.0; 3],
            inertia_kg_m2: [[0.0; 3]; 3],
            free_frequencies_hz: reduced.to_vec(),
            full_free_frequencies_hz: full.to_vec(),
            stiffness_factor: 1.0,
            interface_coordinates: 0,
            reduction_s: 0.0,
            attachments: Vec::new(),
        }
    }

    #[test]
    fn a_first_mode_two_per_cent_stiff_is_said_with_its_numbers() {
        // 204 Hz against 200 Hz: (204 − 200)/200 = +2 %.
        let w = summary(&[204.0, 500.0], &[200.0, 480.0]).warnings();
        assert_eq!(
            w,
            vec![Warning::FirstModeOff {
                body: "column".into(),
                reduced_hz: 204.0,
                full_hz: 200.0
            }]
        );
        assert_eq!(
            w[0].to_string(),
            "body column: the reduced body's first free-free mode (204.00 Hz) is +2.00 % off the \
             full model's (200.00 Hz): the reduction does not resolve the body; keep more modes \
             (`modes` or `cutoff_hz`)"
        );
        // 201 Hz is 0.5 % off: within 1 %, no warning; without the full model, none either.
        assert!(summary(&[201.0], &[200.0]).warnings().is_empty());
        assert!(summary(&[201.0], &[]).warnings().is_empty());
    }
}
