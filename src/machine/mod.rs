//! The validated machine description: bodies, linear axes with guideways, ball-screw drives and
//! controllers, compliant joints, TCP and workpiece points.
//!
//! Machine files (`machines/*.toml`) are parsed into [`raw`] structures with unknown keys rejected
//! and validated once by [`Machine::from_raw`]; every later stage relies on the checks made here.
//! Errors name the file and the key path (`axis[x].guideway.reduction_normal`).

mod attach;
pub(crate) mod body;
pub mod catalogue;
pub mod elastic;
mod pose;
pub mod raw;
pub mod stiffness;
mod validate;

use crate::axes::Axis;
pub use attach::BodySite;
pub use body::{Body, BodyKind, ElasticBody, ElasticModel, Site};
use catalogue::{CarriageData, Catalogue};
use nalgebra::Vector3;
pub use pose::{Pose, PoseError};
use raw::{Feedback, RawMachine, Support};
use std::path::Path;

/// An invalid machine file or catalogue: file, key path, what is wrong.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{file}: {key}: {message}")]
pub struct MachineError {
    /// The file (or `<memory>`).
    pub file: String,
    /// Key path or `line L, column C`.
    pub key: String,
    /// What is wrong.
    pub message: String,
}

impl MachineError {
    /// A new error.
    pub fn new(file: &str, key: impl Into<String>, message: impl Into<String>) -> Self {
        MachineError {
            file: file.to_string(),
            key: key.into(),
            message: message.into(),
        }
    }

    /// A TOML syntax or schema error, located by line and column.
    pub fn toml(file: &str, text: &str, e: &toml::de::Error) -> Self {
        let key = match e.span() {
            Some(span) => {
                let before = &text[..span.start.min(text.len())];
                let line = before.matches('\n').count() + 1;
                let col = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
                format!("line {line}, column {col}")
            }
            None => "TOML".to_string(),
        };
        MachineError::new(file, key, e.message().trim().replace('\n', " "))
    }
}

/// Which side of the machine's structural loop an axis belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// The axis moves the tool: positive axis motion moves its moving body along +axis.
    Tool,
    /// The axis moves the workpiece: positive axis motion (tool relative to workpiece, ISO 841)
    /// moves its moving body along −axis.
    Workpiece,
}

impl Side {
    /// σ = +1 (tool side) or −1 (workpiece side): moving-body displacement per axis value.
    pub fn sign(self) -> f64 {
        match self {
            Side::Tool => 1.0,
            Side::Workpiece => -1.0,
        }
    }
}

/// A point fixed to a body, at the reference position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyPoint {
    /// Body index in [`Machine::bodies`].
    pub body: usize,
    /// Point, m.
    pub point_m: Vector3<f64>,
}

/// One rail and its carriages.
#[derive(Debug, Clone, PartialEq)]
pub struct Rail {
    /// Unit normal (radial) direction.
    pub normal: Vector3<f64>,
    /// Unit lateral direction, axis × normal.
    pub lateral: Vector3<f64>,
    /// Carriage points on the moving body at the reference position, m.
    pub carriages_m: Vec<Vector3<f64>>,
}

/// The guideway of an axis.
#[derive(Debug, Clone, PartialEq)]
pub struct Guideway {
    /// The catalogue entry, if the stiffness comes from the catalogue.
    pub carriage: Option<CarriageData>,
    /// Nominal normal stiffness per carriage (catalogue or given), N/m, before reduction.
    pub normal_n_per_m: f64,
    /// Nominal lateral stiffness per carriage, N/m, before reduction.
    pub lateral_n_per_m: f64,
    /// Reduction factor on the normal stiffness.
    pub reduction_normal: f64,
    /// Reduction factor on the lateral stiffness.
    pub reduction_lateral: f64,
    /// Damping per carriage, normal, N·s/m.
    pub damping_normal_n_s_per_m: f64,
    /// Damping per carriage, lateral, N·s/m.
    pub damping_lateral_n_s_per_m: f64,
    /// Rails.
    pub rails: Vec<Rail>,
}

/// Ball-screw drive of an axis.
#[derive(Debug, Clone, PartialEq)]
pub struct Drive {
    /// Nut point on the moving body at the reference position, m.
    pub nut_m: Vector3<f64>,
    /// Fixed screw bearing on the carrier, m.
    pub bearing_m: Vector3<f64>,
    /// Scale reading head on the moving body at the reference position, m.
    pub scale_m: Vector3<f64>,
    /// Lead, m/rev.
    pub lead_m: f64,
    /// Screw root cross-section, m².
    pub screw_area_m2: f64,
    /// Young's modulus, Pa.
    pub screw_modulus_pa: f64,
    /// Bearing arrangement.
    pub support: Support,
    /// Bearing-to-bearing length (fixed-fixed), m.
    pub screw_length_m: Option<f64>,
    /// Nut stiffness, N/m.
    pub nut_stiffness_n_per_m: f64,
    /// Bearing stiffness, N/m.
    pub bearing_stiffness_n_per_m: f64,
    /// Reduction factor on the total axial stiffness.
    pub reduction: f64,
    /// Axial damping, N·s/m.
    pub damping_n_s_per_m: f64,
    /// Rotor inertia (motor, coupling, screw), kg·m².
    pub rotor_inertia_kg_m2: f64,
    /// Viscous friction on the rotor, N·m·s/rad.
    pub friction_nm_s_per_rad: f64,
}

impl Drive {
    /// Screw displacement per rotor angle, m/rad: h/(2π).
    pub fn transmission_m_per_rad(&self) -> f64 {
        self.lead_m / std::f64::consts::TAU
    }

    /// Total axial stiffness with the nut at distance `l1` from the fixed bearing: screw shaft
    /// (E·A/l₁ fixed-free, E·A·L/(l₁(L − l₁)) fixed-fixed) in series with nut and bearing,
    /// times the reduction factor, N/m.
    pub fn axial_stiffness_n_per_m(&self, l1: f64) -> f64 {
        let ea = self.screw_modulus_pa * self.screw_area_m2;
        let shaft = match (self.support, self.screw_length_m) {
            (Support::FixedFixed, Some(l)) => ea * l / (l1 * (l - l1)),
            _ => ea / l1,
        };
        self.reduction
            / (1.0 / shaft
                + 1.0 / self.nut_stiffness_n_per_m
                + 1.0 / self.bearing_stiffness_n_per_m)
    }
}

/// Cascaded P-PI controller settings of an axis.
#[derive(Debug, Clone, PartialEq)]
pub struct Control {
    /// Position gain Kv, 1/s.
    pub kv_per_s: f64,
    /// Velocity gain Kp, N·m·s/rad.
    pub kp_nm_s_per_rad: f64,
    /// Integral time Tn, s.
    pub tn_s: f64,
    /// Current-loop lag, s (0 = ideal).
    pub current_lag_s: f64,
    /// Set-point smoothing time constant, s (0 = none).
    pub setpoint_filter_s: f64,
    /// Position feedback.
    pub feedback: Feedback,
    /// Velocity feed-forward gain.
    pub velocity_feedforward: f64,
    /// Acceleration feed-forward gain.
    pub acceleration_feedforward: f64,
}

/// A linear axis.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearAxis {
    /// Which axis.
    pub axis: Axis,
    /// Carrier body index.
    pub carrier: usize,
    /// Moving body index.
    pub moving: usize,
    /// Tool or workpiece side.
    pub side: Side,
    /// Stroke [min, max], m.
    pub stroke_m: [f64; 2],
    /// Reference position, m.
    pub reference_m: f64,
    /// Guideway.
    pub guideway: Guideway,
    /// Drive.
    pub drive: Drive,
    /// Controller.
    pub control: Control,
}

impl LinearAxis {
    /// Unit vector of the axis in machine coordinates.
    pub fn direction(&self) -> Vector3<f64> {
        Vector3::from(self.axis.unit())
    }
}

/// A compliant joint (translational springs along x, y, z) between two bodies.
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    /// Name.
    pub name: String,
    /// First body index.
    pub body: usize,
    /// Second body index.
    pub other: usize,
    /// Point, m.
    pub point_m: Vector3<f64>,
    /// Stiffness along x, y, z, N/m.
    pub stiffness_n_per_m: Vector3<f64>,
    /// Damping along x, y, z, N·s/m.
    pub damping_n_s_per_m: Vector3<f64>,
}

/// A validated machine. Its fields are private: every value passed the checks of
/// [`Machine::from_raw`], and the only change allowed afterwards, a stiffness reduction factor
/// ([`Machine::set_reduction`]), is checked again.
#[derive(Debug, Clone, PartialEq)]
pub struct Machine {
    name: String,
    source: String,
    rayleigh_beta_s: f64,
    bodies: Vec<Body>,
    tcp: BodyPoint,
    workpiece: BodyPoint,
    axes: Vec<LinearAxis>,
    joints: Vec<Joint>,
    moved_by: Vec<Option<usize>>,
    /// The file as read, for [`Machine::to_raw`]; shared, so that the machines of an
    /// identification's parameter sets (clones with other factors) do not copy it.
    raw: std::sync::Arc<RawMachine>,
}

/// A stiffness reduction factor of an axis, the quantities an identification adjusts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reduction {
    /// Guideway carriages, normal (radial) direction.
    GuidewayNormal,
    /// Guideway carriages, lateral direction.
    GuidewayLateral,
    /// Total axial stiffness of the ball-screw drive.
    Screw,
}

impl Machine {
    /// Name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The file it was read from (or `<memory>`).
    pub fn source(&self) -> &str {
        &self.source
    }

    /// Rayleigh β, s.
    pub fn rayleigh_beta_s(&self) -> f64 {
        self.rayleigh_beta_s
    }

    /// Bodies (fixed and free).
    pub fn bodies(&self) -> &[Body] {
        &self.bodies
    }

    /// TCP on the tool-side body.
    pub fn tcp(&self) -> &BodyPoint {
        &self.tcp
    }

    /// The R-Test nest on the workpiece-side body at the reference position: the point that
    /// coincides with the TCP there. At any other axis position the nest is again the point of
    /// the workpiece body under the TCP (the nest is set up under the tool at each circle centre),
    /// so a rigid motion of the whole machine never shows as a deviation.
    pub fn workpiece(&self) -> &BodyPoint {
        &self.workpiece
    }

    /// Linear axes.
    pub fn axes(&self) -> &[LinearAxis] {
        &self.axes
    }

    /// Joints.
    pub fn joints(&self) -> &[Joint] {
        &self.joints
    }

    /// Sets a reduction factor of axis `axis_index` (finite and > 0, else an error naming the key).
    pub fn set_reduction(
        &mut self,
        axis_index: usize,
        which: Reduction,
        value: f64,
    ) -> Result<(), MachineError> {
        let Some(a) = self.axes.get_mut(axis_index) else {
            return Err(MachineError::new(
                &self.source,
                format!("axis[{axis_index}]"),
                format!("the machine has {} axes", self.axes.len()),
            ));
        };
        let key = match which {
            Reduction::GuidewayNormal => "guideway.reduction_normal",
            Reduction::GuidewayLateral => "guideway.reduction_lateral",
            Reduction::Screw => "drive.reduction",
        };
        if !(value.is_finite() && value > 0.0) {
            return Err(MachineError::new(
                &self.source,
                format!("axis[{}].{key}", a.axis),
                format!("{value} must be > 0"),
            ));
        }
        match which {
            Reduction::GuidewayNormal => a.guideway.reduction_normal = value,
            Reduction::GuidewayLateral => a.guideway.reduction_lateral = value,
            Reduction::Screw => a.drive.reduction = value,
        }
        Ok(())
    }

    /// The reduction factor of axis `axis_index`.
    pub fn reduction(&self, axis_index: usize, which: Reduction) -> f64 {
        let a = &self.axes[axis_index];
        match which {
            Reduction::GuidewayNormal => a.guideway.reduction_normal,
            Reduction::GuidewayLateral => a.guideway.reduction_lateral,
            Reduction::Screw => a.drive.reduction,
        }
    }
}

impl Machine {
    /// Reads and validates a machine file; extra catalogues are resolved relative to it.
    pub fn from_file(path: &Path) -> Result<Self, MachineError> {
        let file = path.display().to_string();
        let max = crate::io::read::MAX_TEXT_BYTES;
        let text = crate::io::read_input_text(path, max).map_err(|e| match e {
            crate::io::ReadError::IsAFolder => MachineError::new(&file, "file", e.to_string()),
            e => MachineError::new(&file, "file", format!("cannot read: {e}")),
        })?;
        let raw: RawMachine =
            toml::from_str(&text).map_err(|e| MachineError::toml(&file, &text, &e))?;
        let mut catalogue = Catalogue::bundled()?;
        for (i, extra) in raw.catalogue.iter().enumerate() {
            let p = path.parent().unwrap_or(Path::new(".")).join(extra);
            let t = crate::io::read_input_text(&p, max).map_err(|e| {
                MachineError::new(
                    &file,
                    format!("catalogue[{i}]"),
                    format!("{}: {e}", p.display()),
                )
            })?;
            catalogue.add_toml(&t, &p.display().to_string())?;
        }
        Machine::from_raw(raw, &catalogue, &file)
    }

    /// Parses and validates machine TOML text with the bundled catalogue only.
    pub fn from_toml_str(text: &str, file: &str) -> Result<Self, MachineError> {
        let raw: RawMachine =
            toml::from_str(text).map_err(|e| MachineError::toml(file, text, &e))?;
        Machine::from_raw(raw, &Catalogue::bundled()?, file)
    }

    /// The raw description with the current reduction factors, damping and body stiffness
    /// factors written back, e.g. for exporting an identified machine (FE files by their
    /// absolute paths, so that the exported file finds them from wherever it is written).
    pub fn to_raw(&self) -> RawMachine {
        let mut raw = RawMachine::clone(&self.raw);
        for (ra, a) in raw.axes.iter_mut().zip(&self.axes) {
            ra.guideway.reduction_normal = a.guideway.reduction_normal;
            ra.guideway.reduction_lateral = a.guideway.reduction_lateral;
            ra.guideway.damping_normal_n_s_per_m = a.guideway.damping_normal_n_s_per_m;
            ra.guideway.damping_lateral_n_s_per_m = a.guideway.damping_lateral_n_s_per_m;
            ra.drive.reduction = a.drive.reduction;
        }
        for (rb, b) in raw.bodies.iter_mut().zip(&self.bodies) {
            if let Some(e) = b.elastic() {
                if let Some(fe) = rb.fe.as_mut() {
                    fe.stiffness_factor = e.stiffness_factor();
                }
                if let Some(beam) = rb.beam.as_mut() {
                    beam.stiffness_factor = e.stiffness_factor();
                }
            }
        }
        raw
    }

    /// The axis of the machine with this name, if it has one.
    pub fn axis(&self, axis: Axis) -> Option<&LinearAxis> {
        self.axes.iter().find(|a| a.axis == axis)
    }

    /// Reference position of every axis (in [`Machine::axes`] order), m.
    pub fn reference_pose(&self) -> Pose {
        Pose::reference(self)
    }

    /// Total mass carried by an axis (its moving body and every body it carries), kg.
    pub(crate) fn moved_mass_kg(&self, axis_index: usize) -> f64 {
        (0..self.bodies.len())
            .filter(|&b| self.is_carried_by(b, axis_index))
            .map(|b| self.bodies[b].mass_kg)
            .sum()
    }

    /// Whether body `b` moves with axis `axis_index` (is its moving body or carried by it).
    pub fn is_carried_by(&self, mut b: usize, axis_index: usize) -> bool {
        let mut steps = 0;
        while let Some(a) = self.moved_by[b] {
            if a == axis_index {
                return true;
            }
            b = self.axes[a].carrier;
            steps += 1;
            if steps > self.axes.len() {
                break;
            }
        }
        false
    }
}
