//! Axis positions of a machine, checked once against its axes and strokes: a [`Pose`] is what
//! the assembly ([`crate::mbs::Model::assemble`]), the closed loop and the prediction take, so
//! that none of them checks again. Stiffness factors do not change axes or strokes: a pose of a
//! machine is a pose of its identified variants as well.

use std::ops::Deref;

use super::Machine;

/// Axis positions, m, in the machine's axis order, each within its stroke.
#[derive(Debug, Clone, PartialEq)]
pub struct Pose(Vec<f64>);

/// Positions that are no pose of a machine.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PoseError {
    /// A pose with the wrong number of axes.
    #[error("{machine}: pose has {got} axis positions, the machine has {expected} axes")]
    Length {
        /// Machine source.
        machine: String,
        /// Given.
        got: usize,
        /// Expected.
        expected: usize,
    },
    /// An axis position outside its stroke (or not finite).
    #[error(
        "{machine}: axis {axis} position {position_m} m is outside the stroke [{min_m}, {max_m}] m"
    )]
    OutOfStroke {
        /// Machine source.
        machine: String,
        /// Index of the axis in the machine's axis order.
        index: usize,
        /// Axis name.
        axis: String,
        /// Position asked for.
        position_m: f64,
        /// Stroke minimum.
        min_m: f64,
        /// Stroke maximum.
        max_m: f64,
    },
}

impl Pose {
    /// Checks `positions_m` (m, machine axis order): one per axis, each finite and within its
    /// axis's stroke.
    pub fn new(machine: &Machine, positions_m: &[f64]) -> Result<Pose, PoseError> {
        if positions_m.len() != machine.axes().len() {
            return Err(PoseError::Length {
                machine: machine.source().to_string(),
                got: positions_m.len(),
                expected: machine.axes().len(),
            });
        }
        for (index, (a, &s)) in machine.axes().iter().zip(positions_m).enumerate() {
            let [lo, hi] = a.stroke_m;
            if !(s.is_finite() && lo <= s && s <= hi) {
                return Err(PoseError::OutOfStroke {
                    machine: machine.source().to_string(),
                    index,
                    axis: a.axis.to_string(),
                    position_m: s,
                    min_m: lo,
                    max_m: hi,
                });
            }
        }
        Ok(Pose(positions_m.to_vec()))
    }

    /// The reference positions of the machine file (checked within the strokes when the
    /// machine was read).
    pub fn reference(machine: &Machine) -> Pose {
        Pose(machine.axes().iter().map(|a| a.reference_m).collect())
    }
}

impl Deref for Pose {
    type Target = [f64];

    /// The positions, m.
    fn deref(&self) -> &[f64] {
        &self.0
    }
}

impl<'a> IntoIterator for &'a Pose {
    type Item = &'a f64;
    type IntoIter = std::slice::Iter<'a, f64>;

    fn into_iter(self) -> Self::IntoIter {
        self.0.iter()
    }
}
