//! The validated machine description: bodies, linear axes with guideways, ball-screw drives and
//! controllers, compliant joints, TCP and workpiece points.
//!
//! Machine files (`machines/*.toml`) are parsed into [`raw`] structures with unknown keys rejected
//! and validated once by [`Machine::from_raw`]; every later stage relies on the checks made here.
//! Errors name the file and the key path (`axis[x].guideway.reduction_normal`).

pub mod catalogue;
pub mod raw;
pub mod stiffness;

use crate::axes::Axis;
use catalogue::{CarriageData, Catalogue};
use nalgebra::{Matrix3, Vector3};
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

/// A rigid body; free bodies have 6 DOF (x, y, z, a, b, c) at their centre of gravity.
#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    /// Unique name.
    pub name: String,
    /// Fixed to the ground.
    pub fixed: bool,
    /// Mass, kg (0 for fixed bodies).
    pub mass_kg: f64,
    /// Centre of gravity at the reference position, m.
    pub cog_m: Vector3<f64>,
    /// Inertia tensor about the COG, kg·m².
    pub inertia_kg_m2: Matrix3<f64>,
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

/// A validated machine.
#[derive(Debug, Clone, PartialEq)]
pub struct Machine {
    /// Name.
    pub name: String,
    /// The file it was read from (or `<memory>`).
    pub source: String,
    /// Rayleigh β, s.
    pub rayleigh_beta_s: f64,
    /// Bodies (fixed and free).
    pub bodies: Vec<Body>,
    /// TCP on the tool-side body.
    pub tcp: BodyPoint,
    /// The R-Test nest on the workpiece-side body at the reference position: the point that
    /// coincides with the TCP there. At any other axis position the nest is again the point of
    /// the workpiece body under the TCP (the nest is set up under the tool at each circle centre),
    /// so a rigid motion of the whole machine never shows as a deviation.
    pub workpiece: BodyPoint,
    /// Linear axes.
    pub axes: Vec<LinearAxis>,
    /// Joints.
    pub joints: Vec<Joint>,
    /// For each body, the axis that moves it (it is that axis's moving body), if any.
    pub moved_by: Vec<Option<usize>>,
    raw: RawMachine,
}

/// How far a given `workpiece.point_m` may lie from the TCP at the reference position, m.
const NEST_TOLERANCE_M: f64 = 1e-6;

fn finite3(v: [f64; 3]) -> bool {
    v.iter().all(|x| x.is_finite())
}

impl Machine {
    /// Reads and validates a machine file; extra catalogues are resolved relative to it.
    pub fn from_file(path: &Path) -> Result<Self, MachineError> {
        let file = path.display().to_string();
        if path.is_dir() {
            return Err(MachineError::new(&file, "file", "is a folder, not a file"));
        }
        let text = std::fs::read_to_string(path)
            .map_err(|e| MachineError::new(&file, "file", format!("cannot read: {e}")))?;
        let raw: RawMachine =
            toml::from_str(&text).map_err(|e| MachineError::toml(&file, &text, &e))?;
        let mut catalogue = Catalogue::bundled()?;
        for (i, extra) in raw.catalogue.iter().enumerate() {
            let p = path.parent().unwrap_or(Path::new(".")).join(extra);
            let t = std::fs::read_to_string(&p).map_err(|e| {
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

    /// The raw description with the current reduction factors and damping written back, e.g.
    /// for exporting an identified machine.
    pub fn to_raw(&self) -> RawMachine {
        let mut raw = self.raw.clone();
        for (ra, a) in raw.axes.iter_mut().zip(&self.axes) {
            ra.guideway.reduction_normal = a.guideway.reduction_normal;
            ra.guideway.reduction_lateral = a.guideway.reduction_lateral;
            ra.guideway.damping_normal_n_s_per_m = a.guideway.damping_normal_n_s_per_m;
            ra.guideway.damping_lateral_n_s_per_m = a.guideway.damping_lateral_n_s_per_m;
            ra.drive.reduction = a.drive.reduction;
        }
        raw
    }

    /// Validates a raw description: every physical and topological check happens here.
    pub fn from_raw(
        raw: RawMachine,
        catalogue: &Catalogue,
        file: &str,
    ) -> Result<Self, MachineError> {
        let err = |key: String, msg: String| MachineError::new(file, key, msg);
        if !(raw.rayleigh_beta_s.is_finite() && raw.rayleigh_beta_s >= 0.0) {
            return Err(err("rayleigh_beta_s".into(), "must be ≥ 0".into()));
        }
        let mut bodies = Vec::with_capacity(raw.bodies.len());
        for (i, b) in raw.bodies.iter().enumerate() {
            let key = |k: &str| format!("body[{}].{k}", b.name);
            if b.name.trim().is_empty() {
                return Err(err(format!("body[{i}].name"), "must not be empty".into()));
            }
            if raw.bodies[..i].iter().any(|o| o.name == b.name) {
                return Err(err(key("name"), "duplicate body name".into()));
            }
            let cog = b.cog_m.unwrap_or([0.0; 3]);
            if !finite3(cog) {
                return Err(err(key("cog_m"), "must be finite".into()));
            }
            if b.fixed {
                bodies.push(Body {
                    name: b.name.clone(),
                    fixed: true,
                    mass_kg: b.mass_kg.unwrap_or(0.0),
                    cog_m: Vector3::from(cog),
                    inertia_kg_m2: Matrix3::zeros(),
                });
                continue;
            }
            let mass = b
                .mass_kg
                .ok_or_else(|| err(key("mass_kg"), "missing (free bodies need a mass)".into()))?;
            if !(mass.is_finite() && mass > 0.0) {
                return Err(err(key("mass_kg"), format!("{mass} must be > 0")));
            }
            if b.cog_m.is_none() {
                return Err(err(
                    key("cog_m"),
                    "missing (free bodies need a centre of gravity)".into(),
                ));
            }
            let j = b
                .inertia_kg_m2
                .ok_or_else(|| err(key("inertia_kg_m2"), "missing".into()))?;
            let inertia = Matrix3::from_fn(|r, c| j[r][c]);
            check_inertia(&inertia).map_err(|m| err(key("inertia_kg_m2"), m))?;
            bodies.push(Body {
                name: b.name.clone(),
                fixed: false,
                mass_kg: mass,
                cog_m: Vector3::from(cog),
                inertia_kg_m2: inertia,
            });
        }
        let body_index = |name: &str, key: String| {
            bodies
                .iter()
                .position(|b| b.name == name)
                .ok_or_else(|| err(key, format!("unknown body '{name}'")))
        };
        let point = |p: &raw::RawBodyPoint, what: &str| -> Result<BodyPoint, MachineError> {
            let body = body_index(&p.body, format!("{what}.body"))?;
            if !finite3(p.point_m) {
                return Err(err(format!("{what}.point_m"), "must be finite".into()));
            }
            Ok(BodyPoint {
                body,
                point_m: Vector3::from(p.point_m),
            })
        };
        let tcp = point(&raw.tcp, "tcp")?;
        let workpiece = BodyPoint {
            body: body_index(&raw.workpiece.body, "workpiece.body".into())?,
            point_m: tcp.point_m,
        };
        if let Some(p) = raw.workpiece.point_m {
            let given = Vector3::from(p);
            if !finite3(p) {
                return Err(err("workpiece.point_m".into(), "must be finite".into()));
            }
            if (given - tcp.point_m).norm() > NEST_TOLERANCE_M {
                return Err(err(
                    "workpiece.point_m".into(),
                    format!(
                        "[{}, {}, {}] m is not the TCP at the reference position [{}, {}, {}] m: \
                         the R-Test nest is set up under the tool (omit point_m)",
                        p[0], p[1], p[2], tcp.point_m.x, tcp.point_m.y, tcp.point_m.z
                    ),
                ));
            }
        }

        let mut axes: Vec<LinearAxis> = Vec::with_capacity(raw.axes.len());
        let mut moved_by = vec![None; bodies.len()];
        for (i, ra) in raw.axes.iter().enumerate() {
            let axis: Axis = ra
                .name
                .parse()
                .map_err(|m: String| err(format!("axis[{i}].name"), m))?;
            let key = |k: &str| format!("axis[{axis}].{k}");
            if axes.iter().any(|a| a.axis == axis) {
                return Err(err(key("name"), "axis defined twice".into()));
            }
            let carrier = body_index(&ra.carrier, key("carrier"))?;
            let moving = body_index(&ra.moving, key("moving"))?;
            if carrier == moving {
                return Err(err(key("moving"), "moving body equals the carrier".into()));
            }
            if bodies[moving].fixed {
                return Err(err(key("moving"), format!("body '{}' is fixed", ra.moving)));
            }
            if let Some(other) = moved_by[moving] {
                let other: &LinearAxis = &axes[other];
                return Err(err(
                    key("moving"),
                    format!(
                        "body '{}' is already moved by axis {}",
                        ra.moving, other.axis
                    ),
                ));
            }
            moved_by[moving] = Some(i);
            let [lo, hi] = ra.stroke_m;
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                return Err(err(
                    key("stroke_m"),
                    format!("[{lo}, {hi}] must be finite with min < max"),
                ));
            }
            if !(ra.reference_m.is_finite() && lo <= ra.reference_m && ra.reference_m <= hi) {
                return Err(err(
                    key("reference_m"),
                    format!("{} outside the stroke [{lo}, {hi}]", ra.reference_m),
                ));
            }
            let e = Vector3::from(axis.unit());
            let guideway = validate_guideway(&ra.guideway, &e, catalogue, &|k| {
                key(&format!("guideway.{k}"))
            })
            .map_err(|(k, m)| err(k, m))?;
            let drive = validate_drive(&ra.drive, &|k| key(&format!("drive.{k}")))
                .map_err(|(k, m)| err(k, m))?;
            let control = validate_control(&ra.control, &|k| key(&format!("control.{k}")))
                .map_err(|(k, m)| err(k, m))?;
            axes.push(LinearAxis {
                axis,
                carrier,
                moving,
                side: Side::Tool,
                stroke_m: ra.stroke_m,
                reference_m: ra.reference_m,
                guideway,
                drive,
                control,
            });
        }

        // The structural loop: the chains from the TCP body and from the workpiece body down
        // through the axes; each axis belongs to exactly one of them (ISO 841 side).
        let carriers: Vec<usize> = axes.iter().map(|a| a.carrier).collect();
        let chain = |start: usize| {
            let mut on = Vec::new();
            let mut b = start;
            while let Some(a) = moved_by[b] {
                if on.contains(&a) {
                    break;
                }
                on.push(a);
                b = carriers[a];
            }
            on
        };
        let tool_chain = chain(tcp.body);
        let wp_chain = chain(workpiece.body);
        for (i, a) in axes.iter_mut().enumerate() {
            let key = format!("axis[{}].moving", a.axis);
            match (tool_chain.contains(&i), wp_chain.contains(&i)) {
                (true, false) => a.side = Side::Tool,
                (false, true) => a.side = Side::Workpiece,
                (true, true) => {
                    return Err(err(
                        key,
                        "the axis carries both the tool and the workpiece".into(),
                    ))
                }
                (false, false) => {
                    return Err(err(
                        key,
                        format!(
                            "body '{}' carries neither the tool nor the workpiece",
                            bodies[a.moving].name
                        ),
                    ))
                }
            }
        }

        for a in &axes {
            check_nut_travel(a).map_err(|m| err(format!("axis[{}].drive.bearing_m", a.axis), m))?;
        }

        let mut joints = Vec::with_capacity(raw.joints.len());
        for j in &raw.joints {
            let key = |k: &str| format!("joint[{}].{k}", j.name);
            let body = body_index(&j.body, key("body"))?;
            let other = body_index(&j.other, key("other"))?;
            if body == other {
                return Err(err(
                    key("other"),
                    "a joint needs two different bodies".into(),
                ));
            }
            if chain(body) != chain(other) {
                return Err(err(
                    key("other"),
                    "the two bodies move relative to each other along an axis".into(),
                ));
            }
            if !finite3(j.point_m) {
                return Err(err(key("point_m"), "must be finite".into()));
            }
            for (k, v) in [
                ("stiffness_n_per_m", j.stiffness_n_per_m),
                ("damping_n_s_per_m", j.damping_n_s_per_m),
            ] {
                if !v.iter().all(|x| x.is_finite() && *x >= 0.0) {
                    return Err(err(key(k), format!("{v:?}: values must be ≥ 0")));
                }
            }
            joints.push(Joint {
                name: j.name.clone(),
                body,
                other,
                point_m: Vector3::from(j.point_m),
                stiffness_n_per_m: Vector3::from(j.stiffness_n_per_m),
                damping_n_s_per_m: Vector3::from(j.damping_n_s_per_m),
            });
        }

        Ok(Machine {
            name: raw.name.clone(),
            source: file.to_string(),
            rayleigh_beta_s: raw.rayleigh_beta_s,
            bodies,
            tcp,
            workpiece,
            axes,
            joints,
            moved_by,
            raw,
        })
    }

    /// The axis of the machine with this name, if it has one.
    pub fn axis(&self, axis: Axis) -> Option<&LinearAxis> {
        self.axes.iter().find(|a| a.axis == axis)
    }

    /// Reference position of every axis (in [`Machine::axes`] order), m.
    pub fn reference_pose(&self) -> Vec<f64> {
        self.axes.iter().map(|a| a.reference_m).collect()
    }

    /// Total mass carried by an axis (its moving body and every body it carries), kg.
    pub fn moved_mass_kg(&self, axis_index: usize) -> f64 {
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

fn check_inertia(j: &Matrix3<f64>) -> Result<(), String> {
    if !j.iter().all(|x| x.is_finite()) {
        return Err("must be finite".into());
    }
    let scale = j.abs().max();
    if (j - j.transpose()).abs().max() > 1e-9 * scale {
        return Err("must be symmetric".into());
    }
    let principal = j.symmetric_eigenvalues();
    if principal.min() <= 0.0 || j.cholesky().is_none() {
        return Err(format!(
            "not positive definite (principal moments {:.4}, {:.4}, {:.4} kg·m²)",
            principal[0], principal[1], principal[2]
        ));
    }
    let sum = principal.sum();
    if principal.iter().any(|&p| p > 0.5 * sum * (1.0 + 1e-9)) {
        return Err(format!(
            "principal moments {:.4}, {:.4}, {:.4} kg·m² violate the triangle inequality (no real body has them)",
            principal[0], principal[1], principal[2]
        ));
    }
    Ok(())
}

type FieldError = (String, String);

fn positive(v: f64, key: String) -> Result<f64, FieldError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err((key, format!("{v} must be > 0")))
    }
}

fn non_negative(v: f64, key: String) -> Result<f64, FieldError> {
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err((key, format!("{v} must be ≥ 0")))
    }
}

fn validate_guideway(
    g: &raw::RawGuideway,
    e: &Vector3<f64>,
    catalogue: &Catalogue,
    key: &dyn Fn(&str) -> String,
) -> Result<Guideway, FieldError> {
    let (carriage, normal, lateral) = match (&g.carriage, g.stiffness_normal_n_per_um, g.stiffness_lateral_n_per_um) {
        (Some(id), None, None) => {
            let c = catalogue.get(id).ok_or_else(|| {
                (
                    key("carriage"),
                    format!(
                        "unknown catalogue entry '{id}' (known: {})",
                        catalogue.ids().collect::<Vec<_>>().join(", ")
                    ),
                )
            })?;
            (Some(c.clone()), c.normal_n_per_m(), c.lateral_n_per_m)
        }
        (None, Some(n), Some(l)) => (
            None,
            positive(n, key("stiffness_normal_n_per_um"))? * 1e6,
            positive(l, key("stiffness_lateral_n_per_um"))? * 1e6,
        ),
        _ => {
            return Err((
                key("carriage"),
                "give either a catalogue 'carriage' or both 'stiffness_normal_n_per_um' and 'stiffness_lateral_n_per_um'".into(),
            ))
        }
    };
    let reduction_normal = positive(g.reduction_normal, key("reduction_normal"))?;
    let reduction_lateral = positive(g.reduction_lateral, key("reduction_lateral"))?;
    let damping_normal = non_negative(g.damping_normal_n_s_per_m, key("damping_normal_n_s_per_m"))?;
    let damping_lateral = non_negative(
        g.damping_lateral_n_s_per_m,
        key("damping_lateral_n_s_per_m"),
    )?;
    if g.rails.is_empty() {
        return Err((key("rail"), "at least one rail is needed".into()));
    }
    let mut rails = Vec::with_capacity(g.rails.len());
    for (r, rail) in g.rails.iter().enumerate() {
        let n = Vector3::from(rail.normal);
        if !finite3(rail.normal) || n.norm() == 0.0 {
            return Err((
                key(&format!("rail[{r}].normal")),
                "must be a finite, non-zero vector".into(),
            ));
        }
        let n = n.normalize();
        if n.dot(e).abs() > 1e-9 {
            return Err((
                key(&format!("rail[{r}].normal")),
                "must be perpendicular to the axis".into(),
            ));
        }
        if rail.carriages_m.is_empty() || !rail.carriages_m.iter().all(|p| finite3(*p)) {
            return Err((
                key(&format!("rail[{r}].carriages_m")),
                "at least one carriage with finite coordinates is needed".into(),
            ));
        }
        rails.push(Rail {
            normal: n,
            lateral: e.cross(&n),
            carriages_m: rail.carriages_m.iter().map(|p| Vector3::from(*p)).collect(),
        });
    }
    Ok(Guideway {
        carriage,
        normal_n_per_m: normal,
        lateral_n_per_m: lateral,
        reduction_normal,
        reduction_lateral,
        damping_normal_n_s_per_m: damping_normal,
        damping_lateral_n_s_per_m: damping_lateral,
        rails,
    })
}

fn validate_drive(d: &raw::RawDrive, key: &dyn Fn(&str) -> String) -> Result<Drive, FieldError> {
    for (k, p) in [
        ("nut_m", d.nut_m),
        ("bearing_m", d.bearing_m),
        ("scale_m", d.scale_m),
    ] {
        if !finite3(p) {
            return Err((key(k), "must be finite".into()));
        }
    }
    let diameter = positive(d.screw_diameter_m, key("screw_diameter_m"))?;
    let drive = Drive {
        nut_m: Vector3::from(d.nut_m),
        bearing_m: Vector3::from(d.bearing_m),
        scale_m: Vector3::from(d.scale_m),
        lead_m: positive(d.lead_m, key("lead_m"))?,
        screw_area_m2: std::f64::consts::PI * diameter * diameter / 4.0,
        screw_modulus_pa: positive(d.screw_modulus_pa, key("screw_modulus_pa"))?,
        support: d.support,
        screw_length_m: match (d.support, d.screw_length_m) {
            (Support::FixedFixed, Some(l)) => Some(positive(l, key("screw_length_m"))?),
            (Support::FixedFixed, None) => {
                return Err((
                    key("screw_length_m"),
                    "needed for a fixed-fixed screw".into(),
                ))
            }
            (Support::FixedFree, Some(_)) => {
                return Err((key("screw_length_m"), "only for a fixed-fixed screw".into()))
            }
            (Support::FixedFree, None) => None,
        },
        nut_stiffness_n_per_m: positive(d.nut_stiffness_n_per_um, key("nut_stiffness_n_per_um"))?
            * 1e6,
        bearing_stiffness_n_per_m: positive(
            d.bearing_stiffness_n_per_um,
            key("bearing_stiffness_n_per_um"),
        )? * 1e6,
        reduction: positive(d.reduction, key("reduction"))?,
        damping_n_s_per_m: non_negative(d.damping_n_s_per_m, key("damping_n_s_per_m"))?,
        rotor_inertia_kg_m2: positive(d.rotor_inertia_kg_m2, key("rotor_inertia_kg_m2"))?,
        friction_nm_s_per_rad: non_negative(d.friction_nm_s_per_rad, key("friction_nm_s_per_rad"))?,
    };
    Ok(drive)
}

/// The nut must stay on its side of the fixed bearing (and short of the far bearing of a
/// fixed-fixed screw) over the whole stroke.
fn check_nut_travel(a: &LinearAxis) -> Result<(), String> {
    let e = a.direction();
    let d = &a.drive;
    let l_ref = e.dot(&(d.nut_m - d.bearing_m));
    for s in a.stroke_m {
        let l = l_ref + a.side.sign() * (s - a.reference_m);
        let beyond = d
            .screw_length_m
            .is_some_and(|total| l.abs() >= total - 1e-3);
        if l.abs() < 1e-3 || l.signum() != l_ref.signum() || beyond {
            return Err(format!(
                "the nut would reach a screw bearing at axis position {s} m (nut-to-bearing distance {:.4} m there)",
                l.abs()
            ));
        }
    }
    Ok(())
}

fn validate_control(
    c: &raw::RawControl,
    key: &dyn Fn(&str) -> String,
) -> Result<Control, FieldError> {
    Ok(Control {
        kv_per_s: positive(c.kv_per_s, key("kv_per_s"))?,
        kp_nm_s_per_rad: positive(c.kp_nm_s_per_rad, key("kp_nm_s_per_rad"))?,
        tn_s: positive(c.tn_s, key("tn_s"))?,
        current_lag_s: non_negative(c.current_lag_s, key("current_lag_s"))?,
        setpoint_filter_s: non_negative(c.setpoint_filter_s, key("setpoint_filter_s"))?,
        feedback: c.feedback,
        velocity_feedforward: non_negative(c.velocity_feedforward, key("velocity_feedforward"))?,
        acceleration_feedforward: non_negative(
            c.acceleration_feedforward,
            key("acceleration_feedforward"),
        )?,
    })
}
