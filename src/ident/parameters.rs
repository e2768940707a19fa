//! The identified quantities: reduction factors on the catalogue data of one axis, and the
//! compliance factors θ = 1/p the optimiser works in.

use super::IdentError;
use crate::axes::Axis;
use crate::machine::{Machine, MachineError, Reduction};

/// What a parameter scales.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ParameterKind {
    /// Normal and lateral guideway stiffness together (`<axis>.guideway`).
    Guideway,
    /// Normal guideway stiffness (`<axis>.guideway_normal`).
    GuidewayNormal,
    /// Lateral guideway stiffness (`<axis>.guideway_lateral`).
    GuidewayLateral,
    /// Axial stiffness of the ball-screw drive (`<axis>.screw`).
    Screw,
}

/// One identified quantity: a reduction factor on the catalogue data of one axis.
#[derive(Debug, Clone, PartialEq)]
pub struct Parameter {
    /// Name, e.g. `z.guideway_normal`.
    pub name: String,
    /// Index of the axis in [`Machine::axes`].
    pub axis_index: usize,
    /// What it scales.
    pub kind: ParameterKind,
}

impl Parameter {
    /// Parses `<axis>.<kind>` for `machine`.
    pub fn parse(name: &str, machine: &Machine) -> Result<Parameter, IdentError> {
        let bad = |m: String| IdentError::Parameter {
            name: name.to_string(),
            message: m,
        };
        let (axis, kind) = name
            .split_once('.')
            .ok_or_else(|| bad("expected <axis>.<kind>, e.g. z.guideway_normal".into()))?;
        let axis: Axis = axis.parse().map_err(bad)?;
        let axis_index = machine
            .axes()
            .iter()
            .position(|a| a.axis == axis)
            .ok_or_else(|| bad(format!("the machine {} has no axis {axis}", machine.name())))?;
        let kind = match kind {
            "guideway" => ParameterKind::Guideway,
            "guideway_normal" => ParameterKind::GuidewayNormal,
            "guideway_lateral" => ParameterKind::GuidewayLateral,
            "screw" => ParameterKind::Screw,
            _ => {
                return Err(bad(format!(
                    "unknown kind '{kind}' (guideway, guideway_normal, guideway_lateral, screw)"
                )))
            }
        };
        let g = &machine.axes()[axis_index].guideway;
        if kind == ParameterKind::Guideway && g.reduction_normal != g.reduction_lateral {
            return Err(bad(format!(
                "the machine's normal ({}) and lateral ({}) factors differ: identify {axis}.guideway_normal and {axis}.guideway_lateral instead",
                g.reduction_normal, g.reduction_lateral
            )));
        }
        Ok(Parameter {
            name: name.to_string(),
            axis_index,
            kind,
        })
    }

    /// The default set: normal and lateral guideway factors of every axis.
    pub fn default_set(machine: &Machine) -> Vec<Parameter> {
        let mut v = Vec::new();
        for (i, a) in machine.axes().iter().enumerate() {
            for (suffix, kind) in [
                ("guideway_normal", ParameterKind::GuidewayNormal),
                ("guideway_lateral", ParameterKind::GuidewayLateral),
            ] {
                v.push(Parameter {
                    name: format!("{}.{suffix}", a.axis),
                    axis_index: i,
                    kind,
                });
            }
        }
        v
    }

    /// The factor's value in `machine`.
    pub fn get(&self, machine: &Machine) -> f64 {
        let which = match self.kind {
            ParameterKind::Guideway | ParameterKind::GuidewayNormal => Reduction::GuidewayNormal,
            ParameterKind::GuidewayLateral => Reduction::GuidewayLateral,
            ParameterKind::Screw => Reduction::Screw,
        };
        machine.reduction(self.axis_index, which)
    }

    /// Sets the factor in `machine` (finite and > 0).
    pub fn set(&self, machine: &mut Machine, value: f64) -> Result<(), MachineError> {
        let i = self.axis_index;
        match self.kind {
            ParameterKind::Guideway => {
                machine.set_reduction(i, Reduction::GuidewayNormal, value)?;
                machine.set_reduction(i, Reduction::GuidewayLateral, value)
            }
            ParameterKind::GuidewayNormal => {
                machine.set_reduction(i, Reduction::GuidewayNormal, value)
            }
            ParameterKind::GuidewayLateral => {
                machine.set_reduction(i, Reduction::GuidewayLateral, value)
            }
            ParameterKind::Screw => machine.set_reduction(i, Reduction::Screw, value),
        }
    }
}

/// Compliance factor θ = 1/p of a stiffness factor p.
pub(crate) fn to_theta(p: f64) -> f64 {
    1.0 / p
}

/// Stiffness factor p = 1/θ.
pub(crate) fn to_factor(theta: f64) -> f64 {
    1.0 / theta
}
