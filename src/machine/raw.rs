//! The machine file as written: serde structures, unknown keys rejected. Validation into
//! [`super::Machine`] happens once, in [`super::Machine::from_raw`].

use serde::{Deserialize, Serialize};

fn one() -> f64 {
    1.0
}
fn is_one(x: &f64) -> bool {
    *x == 1.0
}
fn is_zero(x: &f64) -> bool {
    *x == 0.0
}
fn steel_modulus() -> f64 {
    2.1e11
}

/// A whole machine file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawMachine {
    /// Short machine name.
    pub name: String,
    /// Free text.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub description: String,
    /// Extra carriage catalogues (TOML, same layout as `machines/catalogue/carriages.toml`),
    /// relative to the machine file; the bundled catalogue is always available.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub catalogue: Vec<String>,
    /// Stiffness-proportional (Rayleigh) damping D += β·K, in s.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub rayleigh_beta_s: f64,
    /// Where the file came from (written by `eij identify`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub provenance: Option<RawProvenance>,
    /// Tool centre point: a point of the tool-side body.
    pub tcp: RawBodyPoint,
    /// Workpiece side of the R-Test: the body that carries the nest. The nest is set up under the
    /// tool, so its point is the TCP at the reference position; `point_m`, if given, must say so.
    pub workpiece: RawWorkpiece,
    /// Rigid bodies.
    #[serde(rename = "body")]
    pub bodies: Vec<RawBody>,
    /// Linear axes.
    #[serde(rename = "axis", default)]
    pub axes: Vec<RawAxis>,
    /// Compliant joints (levelling feet, bolted joints).
    #[serde(rename = "joint", default, skip_serializing_if = "Vec::is_empty")]
    pub joints: Vec<RawJoint>,
}

/// A point fixed to a named body, machine coordinates at the reference position, m.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawBodyPoint {
    /// Body name.
    pub body: String,
    /// Point, m.
    pub point_m: [f64; 3],
}

/// The workpiece body (R-Test nest carrier). The nest sits under the tool at every test's circle
/// centre, so the point is not free: if `point_m` is given it must coincide with the TCP at the
/// reference position (it is accepted for files written before the nest moved with the tool).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawWorkpiece {
    /// Body name.
    pub body: String,
    /// Nest point at the reference position, m: the TCP there (optional).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub point_m: Option<[f64; 3]>,
}

/// A rigid body.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawBody {
    /// Unique name.
    pub name: String,
    /// Fixed to the ground (no degrees of freedom).
    #[serde(default)]
    pub fixed: bool,
    /// Mass, kg (free bodies).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass_kg: Option<f64>,
    /// Centre of gravity, m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cog_m: Option<[f64; 3]>,
    /// Inertia tensor about the centre of gravity in machine axes, kg·m².
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inertia_kg_m2: Option<[[f64; 3]; 3]>,
    /// An elastic body from an FE model an FE program exported.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fe: Option<RawFe>,
    /// An elastic body eij builds as a Timoshenko beam.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub beam: Option<RawBeam>,
}

fn default_damping_ratio() -> f64 {
    0.02
}

/// `[body.fe]`: an FE model as exported (docs/fe.md). Files are relative to the
/// machine file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawFe {
    /// Matrix Market mass matrix (`coordinate real symmetric` or `general`, 1-based, SI).
    pub mass_matrix: String,
    /// Matrix Market stiffness matrix.
    pub stiffness_matrix: String,
    /// `node,dof` per matrix row, in row order.
    pub dofs: String,
    /// `node,x_m,y_m,z_m`: machine coordinates at the reference position.
    pub nodes: String,
    /// Fixed-interface modes kept (default 20 where `cutoff_hz` is not given).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub modes: Option<usize>,
    /// Resolve the body's modes up to this frequency instead, Hz.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cutoff_hz: Option<f64>,
    /// Modal damping ratio of the elastic modes (0.02).
    #[serde(default = "default_damping_ratio")]
    pub damping_ratio: f64,
    /// Factor on the whole elastic stiffness (E and G alike); identification writes it.
    #[serde(default = "one", skip_serializing_if = "is_one")]
    pub stiffness_factor: f64,
    /// RBE3 radius on solid (3-DOF) nodes, m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub attach_radius_m: Option<f64>,
    /// Interface coordinates beyond the six rigid-body motions (characteristic constraint
    /// modes), where the attachments' stations carry more DOFs than that: keeps the elastic
    /// coordinate count small on a body with long rails (docs/machine-file.md).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub interface_modes: Option<usize>,
}

/// `[body.beam]`: a straight 3D Timoshenko beam eij builds (6 DOF per node).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawBeam {
    /// Start point, m.
    pub from_m: [f64; 3],
    /// End point, m.
    pub to_m: [f64; 3],
    /// Number of elements.
    pub elements: usize,
    /// The section's local y direction.
    pub y_axis: [f64; 3],
    /// Section area, m².
    pub area_m2: f64,
    /// Second moment of area about local y, m⁴.
    pub iy_m4: f64,
    /// Second moment of area about local z, m⁴.
    pub iz_m4: f64,
    /// Torsion constant, m⁴.
    pub torsion_m4: f64,
    /// Shear area / area.
    pub shear_factor: f64,
    /// Young's modulus, Pa.
    pub youngs_modulus_pa: f64,
    /// Shear modulus, Pa.
    pub shear_modulus_pa: f64,
    /// Density, kg/m³.
    pub density_kg_m3: f64,
    /// Fixed-interface modes kept (default 20 where `cutoff_hz` is not given).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub modes: Option<usize>,
    /// Resolve the body's modes up to this frequency instead, Hz.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cutoff_hz: Option<f64>,
    /// Modal damping ratio of the elastic modes (0.02).
    #[serde(default = "default_damping_ratio")]
    pub damping_ratio: f64,
    /// Factor on the whole elastic stiffness (E and G alike); identification writes it.
    #[serde(default = "one", skip_serializing_if = "is_one")]
    pub stiffness_factor: f64,
    /// Interface coordinates beyond the six rigid-body motions, as in [`RawFe`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub interface_modes: Option<usize>,
}

/// A linear axis: the moving body runs on guideways of the carrier body, driven by a ball screw.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawAxis {
    /// `x`, `y` or `z`.
    pub name: String,
    /// Body carrying the rails (and the motor and screw bearing).
    pub carrier: String,
    /// Body carrying the carriages and the nut.
    pub moving: String,
    /// Axis range [min, max], m, in axis coordinates (ISO 841).
    pub stroke_m: [f64; 2],
    /// Axis position at which the points of this file are given, m.
    #[serde(default)]
    pub reference_m: f64,
    /// Guideway.
    pub guideway: RawGuideway,
    /// Ball-screw drive.
    pub drive: RawDrive,
    /// Cascaded P-PI controller.
    pub control: RawControl,
}

/// Guideway of an axis.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawGuideway {
    /// Catalogue id of the carriage, e.g. `HIWIN HGH25CA ZA`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub carriage: Option<String>,
    /// Normal stiffness per carriage, N/µm, instead of a catalogue entry.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stiffness_normal_n_per_um: Option<f64>,
    /// Lateral stiffness per carriage, N/µm, instead of a catalogue entry.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stiffness_lateral_n_per_um: Option<f64>,
    /// Reduction factor on the normal stiffness.
    #[serde(default = "one", skip_serializing_if = "is_one")]
    pub reduction_normal: f64,
    /// Reduction factor on the lateral stiffness.
    #[serde(default = "one", skip_serializing_if = "is_one")]
    pub reduction_lateral: f64,
    /// Viscous damping per carriage in the normal direction, N·s/m.
    #[serde(default)]
    pub damping_normal_n_s_per_m: f64,
    /// Viscous damping per carriage in the lateral direction, N·s/m.
    #[serde(default)]
    pub damping_lateral_n_s_per_m: f64,
    /// Rails.
    #[serde(rename = "rail")]
    pub rails: Vec<RawRail>,
}

/// One rail and the carriages running on it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawRail {
    /// Normal (radial load) direction of the carriages, from rail to carriage.
    pub normal: [f64; 3],
    /// Carriage points on the moving body, m, at the reference position.
    pub carriages_m: Vec<[f64; 3]>,
}

/// Screw support arrangement.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Support {
    /// Fixed bearing at `bearing_m`, free (or floating) far end: shaft stiffness E·A/L.
    FixedFree,
    /// Fixed bearings at both ends: E·A·L/(l₁·(L − l₁)).
    FixedFixed,
}

/// Ball-screw drive of an axis.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawDrive {
    /// Nut point on the moving body (line of the drive force), m, at the reference position.
    pub nut_m: [f64; 3],
    /// Fixed bearing of the screw on the carrier, m.
    pub bearing_m: [f64; 3],
    /// Reading head of the linear scale on the moving body, m, at the reference position.
    pub scale_m: [f64; 3],
    /// Screw lead, m per revolution.
    pub lead_m: f64,
    /// Screw root diameter, m.
    pub screw_diameter_m: f64,
    /// Young's modulus of the screw, Pa.
    #[serde(default = "steel_modulus")]
    pub screw_modulus_pa: f64,
    /// Bearing arrangement.
    pub support: Support,
    /// Distance between the two fixed bearings (fixed-fixed only), m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub screw_length_m: Option<f64>,
    /// Axial stiffness of the nut, N/µm.
    pub nut_stiffness_n_per_um: f64,
    /// Axial stiffness of the support bearing(s), N/µm.
    pub bearing_stiffness_n_per_um: f64,
    /// Reduction factor on the total axial stiffness.
    #[serde(default = "one", skip_serializing_if = "is_one")]
    pub reduction: f64,
    /// Axial damping of the screw, N·s/m.
    #[serde(default)]
    pub damping_n_s_per_m: f64,
    /// Rotor inertia of motor + coupling + screw, kg·m².
    pub rotor_inertia_kg_m2: f64,
    /// Viscous friction on the rotor, N·m·s/rad.
    #[serde(default)]
    pub friction_nm_s_per_rad: f64,
}

/// Feedback of the position loop.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Feedback {
    /// Linear scale (direct measuring system).
    Scale,
    /// Motor encoder through the screw lead (indirect).
    Encoder,
}

fn scale() -> Feedback {
    Feedback::Scale
}

/// Cascaded P-PI controller of an axis.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawControl {
    /// Position-loop gain Kv, 1/s.
    pub kv_per_s: f64,
    /// Velocity-loop proportional gain Kp, N·m·s/rad (motor side).
    pub kp_nm_s_per_rad: f64,
    /// Velocity-loop integral time Tn, s.
    pub tn_s: f64,
    /// Current-loop time constant, s (0 = ideal current loop).
    #[serde(default)]
    pub current_lag_s: f64,
    /// Time constant of the CNC's first-order position set-point smoothing, s (0 = none).
    /// It acts on position, velocity and acceleration commands alike.
    #[serde(default)]
    pub setpoint_filter_s: f64,
    /// Position feedback.
    #[serde(default = "scale")]
    pub feedback: Feedback,
    /// Velocity feed-forward gain (0…1).
    #[serde(default = "one")]
    pub velocity_feedforward: f64,
    /// Acceleration (torque) feed-forward gain (0…1).
    #[serde(default = "one")]
    pub acceleration_feedforward: f64,
}

/// A compliant joint between two bodies at a point (translational springs in machine axes).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawJoint {
    /// Name.
    pub name: String,
    /// First body.
    pub body: String,
    /// Second body (often a fixed one, e.g. the floor).
    pub other: String,
    /// Joint point, m.
    pub point_m: [f64; 3],
    /// Stiffness along x, y, z, N/m.
    pub stiffness_n_per_m: [f64; 3],
    /// Damping along x, y, z, N·s/m.
    #[serde(default)]
    pub damping_n_s_per_m: [f64; 3],
}

/// A carriage catalogue file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawCatalogue {
    /// Entries.
    #[serde(rename = "carriage")]
    pub carriages: Vec<RawCarriage>,
}

/// A catalogue entry.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawCarriage {
    /// Id used in machine files.
    pub id: String,
    /// Compressive (radial) stiffness, N/µm.
    pub radial_n_per_um: f64,
    /// Tensile (reverse-radial) stiffness, N/µm.
    pub reverse_radial_n_per_um: f64,
    /// Lateral stiffness, N/µm.
    pub lateral_n_per_um: f64,
    /// Which values are estimates.
    #[serde(default)]
    pub estimated: Vec<String>,
    /// Published source.
    pub source: String,
}

/// The `[provenance]` table of an identified machine file: what produced it, from what, and
/// the identified factors (fields in alphabetical order, as TOML tables list them).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawProvenance {
    /// Σr² at the solution.
    pub cost_final: f64,
    /// Σr² at the start.
    pub cost_initial: f64,
    /// UTC time stamp (RFC 3339).
    pub date: String,
    /// The machine file identified.
    pub from_machine: String,
    /// `eij <version>`.
    pub identified_by: String,
    /// The measured inputs.
    pub measured: Vec<String>,
    /// Identified factors by parameter name.
    pub parameters: std::collections::BTreeMap<String, RawProvenanceParameter>,
    /// Number of circle tests fitted.
    pub tests: usize,
}

/// One identified factor in [`RawProvenance`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawProvenanceParameter {
    /// Whether the tests determine it.
    pub identifiable: bool,
    /// Identified value.
    pub identified: f64,
    /// Start value.
    pub initial: f64,
    /// Standard error (absent when not identifiable).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub std_err: Option<f64>,
}
