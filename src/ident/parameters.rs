//! The identified quantities: reduction factors on the catalogue data of one axis, or the factor
//! on an elastic body's stiffness, and the compliance factors θ = 1/p the optimiser works in.

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
    /// The whole elastic stiffness of an elastic body (`<body>.stiffness`, as on Young's
    /// modulus).
    BodyStiffness,
}

/// One identified quantity: a reduction factor on the catalogue data of one axis, or the
/// stiffness factor of an elastic body.
#[derive(Debug, Clone, PartialEq)]
pub struct Parameter {
    /// Name, e.g. `z.guideway_normal` or `column.stiffness`.
    pub name: String,
    /// What it scales.
    pub kind: ParameterKind,
    /// Index of its axis in [`Machine::axes`], or of its body in [`Machine::bodies`] for
    /// [`ParameterKind::BodyStiffness`].
    index: usize,
}

impl Parameter {
    /// Parses `<axis>.<kind>` or `<body>.stiffness` for `machine`.
    pub fn parse(name: &str, machine: &Machine) -> Result<Parameter, IdentError> {
        let bad = |m: String| IdentError::Parameter {
            name: name.to_string(),
            message: m,
        };
        let (axis, kind) = name.rsplit_once('.').ok_or_else(|| {
            bad("expected <axis>.<kind> or <body>.stiffness, e.g. z.guideway_normal".into())
        })?;
        if kind == "stiffness" {
            let body = machine
                .bodies()
                .iter()
                .position(|b| b.name == axis)
                .ok_or_else(|| bad(format!("the machine {} has no body {axis}", machine.name())))?;
            if machine.bodies()[body].elastic().is_none() {
                return Err(bad(format!(
                    "body {axis} is rigid: only an elastic body ([body.fe] or [body.beam]) has a stiffness factor"
                )));
            }
            return Ok(Parameter {
                name: name.to_string(),
                kind: ParameterKind::BodyStiffness,
                index: body,
            });
        }
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
                    "unknown kind '{kind}' (guideway, guideway_normal, guideway_lateral, screw; <body>.stiffness for an elastic body)"
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
            kind,
            index: axis_index,
        })
    }

    /// The default set: normal and lateral guideway factors of every axis, then the stiffness
    /// factor of every elastic body (`<body>.stiffness`).
    pub fn default_set(machine: &Machine) -> Vec<Parameter> {
        let mut v = Vec::new();
        for (i, a) in machine.axes().iter().enumerate() {
            for (suffix, kind) in [
                ("guideway_normal", ParameterKind::GuidewayNormal),
                ("guideway_lateral", ParameterKind::GuidewayLateral),
            ] {
                v.push(Parameter {
                    name: format!("{}.{suffix}", a.axis),
                    kind,
                    index: i,
                });
            }
        }
        for (i, b) in machine.bodies().iter().enumerate() {
            if b.elastic().is_some() {
                v.push(Parameter {
                    name: format!("{}.stiffness", b.name),
                    kind: ParameterKind::BodyStiffness,
                    index: i,
                });
            }
        }
        v
    }

    /// Index of its axis in [`Machine::axes`] (`None` for a body's stiffness).
    pub fn axis_index(&self) -> Option<usize> {
        (self.kind != ParameterKind::BodyStiffness).then_some(self.index)
    }

    /// Index of its body in [`Machine::bodies`] (`Some` for a body's stiffness only).
    pub(crate) fn body_index(&self) -> Option<usize> {
        (self.kind == ParameterKind::BodyStiffness).then_some(self.index)
    }

    /// The factor's value in `machine`.
    pub fn get(&self, machine: &Machine) -> f64 {
        let which = match self.kind {
            ParameterKind::Guideway | ParameterKind::GuidewayNormal => Reduction::GuidewayNormal,
            ParameterKind::GuidewayLateral => Reduction::GuidewayLateral,
            ParameterKind::Screw => Reduction::Screw,
            ParameterKind::BodyStiffness => {
                return machine.bodies()[self.index]
                    .elastic()
                    .map_or(1.0, |e| e.stiffness_factor())
            }
        };
        machine.reduction(self.index, which)
    }

    /// Sets the factor in `machine` (finite and > 0).
    pub fn set(&self, machine: &mut Machine, value: f64) -> Result<(), MachineError> {
        let i = self.index;
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
            ParameterKind::BodyStiffness => machine.set_body_stiffness(i, value),
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
