//! What a diagnosis says beside its figures, as data: terms one test cannot separate, what a
//! value may also be, and what tests at several accelerations or in both directions told.
//! Rendered to text only where it is shown (`Display`: the command line, the report page, the
//! JSON's `notes`), as [`crate::rtest::Warning`].

use std::fmt;

use super::terms::UM_PER_M;
use super::Source;
use crate::axes::Axis;

/// A note of a circle diagnosis: on a test's source, on one of its terms, or on a group of tests.
#[derive(Debug, Clone, PartialEq)]
pub enum Note {
    /// Terms that have no unique solution in this test and were left out of its fit.
    LeftOut {
        /// Their names.
        terms: Vec<String>,
    },
    /// One test's 45° ellipse is squareness and servo mismatch together.
    SquarenessWithServo,
    /// A group at one acceleration: geometry and EIJ not separated.
    OneAcceleration,
    /// A group in one direction: squareness and servo mismatch not separated.
    OneDirection,
    /// Squareness as the direction-independent part of the 45° ellipse over tests in both
    /// directions.
    DirectionIndependent {
        /// This test's 45° ellipse alone, µm/m.
        apparent: f64,
        /// Of which servo mismatch, µm/m.
        servo_part: f64,
    },
    /// A term that grows with the acceleration over the group's tests.
    GrowsWithAcceleration {
        /// Its slope, in the term's unit per m/s².
        per_m_s2: f64,
        /// The slope's standard error.
        per_m_s2_std_err: f64,
        /// The term's unit.
        unit: &'static str,
        /// The tests' set accelerations, m/s².
        accelerations_m_s2: Vec<f64>,
        /// The source: what growing with the acceleration means there.
        source: Source,
        /// The part at no acceleration, in the term's unit.
        geometric: f64,
        /// Its standard error.
        geometric_std_err: f64,
    },
    /// The servo mismatch term: the lag of one axis minus that of the other.
    ServoLag {
        /// The plane's first axis.
        first: Axis,
        /// Its second axis.
        second: Axis,
        /// The tests' feed, mm/min.
        feed_mm_min: f64,
    },
    /// A structure term of EIJ shape in tests at one acceleration.
    CouldBeEij,
}

impl Note {
    /// What a term that grows with the acceleration is, by source.
    fn growth(source: Source) -> &'static str {
        match source {
            Source::Internal => "a dynamic control error",
            Source::Structure => "EIJ",
            Source::Tcp => {
                "EIJ or a dynamic control error (the internal and the structure source tell which)"
            }
        }
    }
}

impl fmt::Display for Note {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Note::LeftOut { terms } => write!(
                f,
                "not separable from the other terms in this test, left out: {}",
                terms.join(", ")
            ),
            Note::SquarenessWithServo => f.write_str(
                "the 45° ellipse of this test: squareness and servo mismatch together until a test \
                 in the opposite direction separates them",
            ),
            Note::OneAcceleration => f.write_str(
                "one acceleration: geometry and acceleration-correlated terms (EIJ) not separated",
            ),
            Note::OneDirection => f.write_str(
                "one direction: squareness and servo mismatch not separated (the 45° ellipse is \
                 reported as squareness)",
            ),
            Note::DirectionIndependent {
                apparent,
                servo_part,
            } => write!(
                f,
                "direction-independent part of the 45° ellipse over the tests in both directions \
                 (this test alone: {apparent:.3} {UM_PER_M}, of which {servo_part:.3} servo mismatch)"
            ),
            Note::GrowsWithAcceleration {
                per_m_s2,
                per_m_s2_std_err,
                unit,
                accelerations_m_s2,
                source,
                geometric,
                geometric_std_err,
            } => {
                let accels: Vec<String> =
                    accelerations_m_s2.iter().map(|a| format!("{a:.2}")).collect();
                write!(
                    f,
                    "grows with acceleration, {per_m_s2:.4} ± {per_m_s2_std_err:.4} {unit} per m/s² \
                     over the tests at {} m/s²: not geometry but {}; the part at no acceleration \
                     is {geometric:.3} ± {geometric_std_err:.3}",
                    accels.join(", "),
                    Note::growth(*source)
                )
            }
            Note::ServoLag {
                first,
                second,
                feed_mm_min,
            } => write!(
                f,
                "lag of axis {first} minus lag of axis {second} (the 45° ellipse that flips with the \
                 direction), at {feed_mm_min:.0} mm/min"
            ),
            Note::CouldBeEij => f.write_str(
                "could be EIJ (the structure's deviation under acceleration): tests at another \
                 acceleration tell",
            ),
        }
    }
}

impl serde::Serialize for Note {
    /// As its text (the JSON's `notes` are sentences).
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn notes_with_numbers_render_them() {
        let grows = Note::GrowsWithAcceleration {
            per_m_s2: -0.81234,
            per_m_s2_std_err: 0.05,
            unit: UM_PER_M,
            accelerations_m_s2: vec![2.0, 5.0, 8.0],
            source: Source::Structure,
            geometric: 1.23456,
            geometric_std_err: 0.1,
        };
        assert_eq!(
            grows.to_string(),
            "grows with acceleration, -0.8123 ± 0.0500 um_per_m per m/s² over the tests at 2.00, \
             5.00, 8.00 m/s²: not geometry but EIJ; the part at no acceleration is 1.235 ± 0.100"
        );
        let mut internal = grows.clone();
        if let Note::GrowsWithAcceleration { source, .. } = &mut internal {
            *source = Source::Internal;
        }
        assert!(internal
            .to_string()
            .contains("not geometry but a dynamic control error;"));
        assert_eq!(
            Note::DirectionIndependent {
                apparent: 12.3456,
                servo_part: -2.5
            }
            .to_string(),
            "direction-independent part of the 45° ellipse over the tests in both directions \
             (this test alone: 12.346 um_per_m, of which -2.500 servo mismatch)"
        );
        assert_eq!(
            Note::ServoLag {
                first: Axis::Z,
                second: Axis::X,
                feed_mm_min: 1234.56
            }
            .to_string(),
            "lag of axis z minus lag of axis x (the 45° ellipse that flips with the direction), \
             at 1235 mm/min"
        );
        assert_eq!(
            Note::LeftOut {
                terms: vec!["cyclic_x".into(), "spike_y".into()]
            }
            .to_string(),
            "not separable from the other terms in this test, left out: cyclic_x, spike_y"
        );
    }
}
