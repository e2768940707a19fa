//! Validation of a raw machine description: every physical and topological check, once, on
//! the way from [`RawMachine`] (as parsed, unknown keys rejected) to the [`Machine`] the later
//! stages rely on. Errors name the file and the key path (`axis[x].guideway.reduction_normal`).

use super::catalogue::Catalogue;
use super::raw::{self, RawMachine, Support};
use super::{
    Body, BodyKind, BodyPoint, Control, Drive, Guideway, Joint, LinearAxis, Machine, MachineError,
    Rail, Side,
};
use crate::axes::Axis;
use nalgebra::{Matrix3, Vector3};

/// Most bodies of a machine (each adds six degrees of freedom).
pub(super) const MAX_BODIES: usize = 100;
/// Most joints between bodies.
pub(super) const MAX_JOINTS: usize = 1000;
/// Most carriages over all guideways.
pub(super) const MAX_CARRIAGES: usize = 1000;
/// Most extra catalogue files.
pub(super) const MAX_CATALOGUES: usize = 16;

/// How far a given `workpiece.point_m` may lie from the TCP at the reference position, m.
const NEST_TOLERANCE_M: f64 = 1e-6;

fn finite3(v: [f64; 3]) -> bool {
    v.iter().all(|x| x.is_finite())
}

impl Machine {
    /// Validates a raw description: every physical and topological check happens here.
    pub fn from_raw(
        raw: RawMachine,
        catalogue: &Catalogue,
        file: &str,
    ) -> Result<Self, MachineError> {
        let err = |key: String, msg: String| MachineError::new(file, key, msg);
        // Counts first: the model's matrices grow with the square of the bodies.
        let carriages = raw
            .axes
            .iter()
            .flat_map(|a| &a.guideway.rails)
            .map(|r| r.carriages_m.len())
            .sum::<usize>();
        for (key, n, max) in [
            ("body", raw.bodies.len(), MAX_BODIES),
            ("axis", raw.axes.len(), 3),
            ("joint", raw.joints.len(), MAX_JOINTS),
            ("catalogue", raw.catalogue.len(), MAX_CATALOGUES),
            (
                "axis[].guideway.rail[].carriages_m",
                carriages,
                MAX_CARRIAGES,
            ),
        ] {
            if n > max {
                return Err(err(
                    key.into(),
                    format!("{n} given, at most {max} (a machine tool model has far fewer)"),
                ));
            }
        }
        non_negative(
            raw.rayleigh_beta_s,
            "rayleigh_beta_s".into(),
            Range(0.0, 1.0, "s"),
        )
        .map_err(|(k, m)| err(k, m))?;
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
            coords(&cog).map_err(|m| err(key("cog_m"), m))?;
            let elastic = b.fe.is_some() || b.beam.is_some();
            if b.fixed && elastic {
                let which = if b.fe.is_some() { "fe" } else { "beam" };
                return Err(err(
                    key(which),
                    "a fixed body cannot be elastic (it has no coordinates)".into(),
                ));
            }
            if elastic {
                // Mass properties come from the FE model (with_elastic_bodies below), checked
                // against these where they are given.
                bodies.push(Body {
                    name: b.name.clone(),
                    mass_kg: b.mass_kg.unwrap_or(0.0),
                    cog_m: Vector3::from(cog),
                    inertia_kg_m2: Matrix3::zeros(),
                    kind: BodyKind::Rigid,
                });
                continue;
            }
            if b.fixed {
                bodies.push(Body {
                    name: b.name.clone(),
                    mass_kg: b.mass_kg.unwrap_or(0.0),
                    cog_m: Vector3::from(cog),
                    inertia_kg_m2: Matrix3::zeros(),
                    kind: BodyKind::Fixed,
                });
                continue;
            }
            let mass = b
                .mass_kg
                .ok_or_else(|| err(key("mass_kg"), "missing (free bodies need a mass)".into()))?;
            positive(mass, key("mass_kg"), Range(1e-3, 1e6, "kg")).map_err(|(k, m)| err(k, m))?;
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
                mass_kg: mass,
                cog_m: Vector3::from(cog),
                inertia_kg_m2: inertia,
                kind: BodyKind::Rigid,
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
            coords(&p.point_m).map_err(|m| err(format!("{what}.point_m"), m))?;
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
            if bodies[moving].is_fixed() {
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
            coords(&ra.stroke_m).map_err(|m| err(key("stroke_m"), m))?;
            if lo >= hi {
                return Err(err(
                    key("stroke_m"),
                    format!("{} must have min < max", crate::text::nums(&ra.stroke_m)),
                ));
            }
            if !(ra.reference_m.is_finite() && lo <= ra.reference_m && ra.reference_m <= hi) {
                return Err(err(
                    key("reference_m"),
                    format!(
                        "{} outside the stroke {}",
                        crate::text::num(ra.reference_m),
                        crate::text::nums(&ra.stroke_m)
                    ),
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
        for (i, j) in raw.joints.iter().enumerate() {
            let key = |k: &str| format!("joint[{}].{k}", j.name);
            // A block pasted twice would double the joint's stiffness unseen.
            if raw.joints[..i].iter().any(|o| o.name == j.name) {
                return Err(err(
                    key("name"),
                    "duplicate joint name (a [[joint]] block given twice?)".into(),
                ));
            }
            if let Some(o) = raw.joints[..i].iter().find(|o| {
                o.point_m == j.point_m
                    && [(&o.body, &o.other), (&o.other, &o.body)].contains(&(&j.body, &j.other))
            }) {
                return Err(err(
                    key("point_m"),
                    format!(
                        "joint {} already joins {} and {} at this point (one joint per point; give its stiffness once)",
                        o.name, j.body, j.other
                    ),
                ));
            }
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
            coords(&j.point_m).map_err(|m| err(key("point_m"), m))?;
            for (k, v, max) in [
                ("stiffness_n_per_m", j.stiffness_n_per_m, 1e13),
                ("damping_n_s_per_m", j.damping_n_s_per_m, DAMPING.1),
            ] {
                if !v.iter().all(|x| x.is_finite() && *x >= 0.0) {
                    return Err(err(
                        key(k),
                        format!("{}: values must be ≥ 0", crate::text::nums(&v)),
                    ));
                }
                if v.iter().any(|x| *x > max) {
                    return Err(err(
                        key(k),
                        format!(
                            "{}: beyond {}, more than any machine tool has (a typo or a unit slip?)",
                            crate::text::nums(&v),
                            crate::text::num(max)
                        ),
                    ));
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

        let raw_bodies = raw.bodies.clone();
        Machine {
            name: raw.name.clone(),
            source: file.to_string(),
            rayleigh_beta_s: raw.rayleigh_beta_s,
            bodies,
            tcp,
            workpiece,
            axes,
            joints,
            moved_by,
            raw: std::sync::Arc::new(raw),
        }
        .with_elastic_bodies(&raw_bodies)
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
    if principal.min() < 1e-8 {
        return Err(format!(
            "principal moment {} kg·m² is below 1e-8 kg·m², less than any machine tool part has (a typo or a unit slip?)",
            crate::text::num(principal.min())
        ));
    }
    if principal.max() > 1e7 {
        return Err(format!(
            "principal moment {} kg·m² is beyond 1e7 kg·m², more than any machine tool has (a typo or a unit slip?)",
            crate::text::num(principal.max())
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

/// The range of a quantity in any machine tool, smallest positive and largest value, with its
/// unit: outside it a value is a typo or a unit slip, and is named as such before it can
/// surface as a numerical failure (a singular model, NaN frequencies, an unstable loop).
#[derive(Clone, Copy)]
struct Range(f64, f64, &'static str);

const COORD: Range = Range(0.0, 100.0, "m");
const STIFFNESS_N_PER_UM: Range = Range(1e-3, 1e5, "N/µm");
const FACTOR: Range = Range(1e-4, 100.0, "(times the file value)");
const DAMPING: Range = Range(0.0, 1e9, "N·s/m");
const LENGTH: Range = Range(1e-3, 10.0, "m");

fn in_range(v: f64, key: String, positive: bool, range: Range) -> Result<f64, FieldError> {
    let v_text = crate::text::num(v);
    if !(v.is_finite() && (v > 0.0 || (!positive && v == 0.0))) {
        let rel = if positive { ">" } else { "≥" };
        return Err((key, format!("{v_text} must be {rel} 0")));
    }
    let slip = "(a typo or a unit slip?)";
    if v > range.1 {
        return Err((
            key,
            format!(
                "{v_text} is beyond {} {}, more than any machine tool has {slip}",
                crate::text::num(range.1),
                range.2
            ),
        ));
    }
    if v > 0.0 && v < range.0 {
        return Err((
            key,
            format!(
                "{v_text} is below {} {}, less than any machine tool has {slip}",
                crate::text::num(range.0),
                range.2
            ),
        ));
    }
    Ok(v)
}

fn positive(v: f64, key: String, range: Range) -> Result<f64, FieldError> {
    in_range(v, key, true, range)
}

fn non_negative(v: f64, key: String, range: Range) -> Result<f64, FieldError> {
    in_range(v, key, false, range)
}

/// Every coordinate finite and within [`COORD`].
fn coords(p: &[f64]) -> Result<(), String> {
    if !p.iter().all(|x| x.is_finite()) {
        return Err("must be finite".into());
    }
    if p.iter().any(|x| x.abs() > COORD.1) {
        return Err(format!(
            "{} m lies beyond ±{} m, farther than any machine tool reaches (mm given as m?)",
            crate::text::nums(p),
            COORD.1
        ));
    }
    Ok(())
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
            positive(n, key("stiffness_normal_n_per_um"), STIFFNESS_N_PER_UM)? * 1e6,
            positive(l, key("stiffness_lateral_n_per_um"), STIFFNESS_N_PER_UM)? * 1e6,
        ),
        _ => {
            return Err((
                key("carriage"),
                "give either a catalogue 'carriage' or both 'stiffness_normal_n_per_um' and 'stiffness_lateral_n_per_um'".into(),
            ))
        }
    };
    let reduction_normal = positive(g.reduction_normal, key("reduction_normal"), FACTOR)?;
    let reduction_lateral = positive(g.reduction_lateral, key("reduction_lateral"), FACTOR)?;
    let damping_normal = non_negative(
        g.damping_normal_n_s_per_m,
        key("damping_normal_n_s_per_m"),
        DAMPING,
    )?;
    let damping_lateral = non_negative(
        g.damping_lateral_n_s_per_m,
        key("damping_lateral_n_s_per_m"),
        DAMPING,
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
        if let Some(m) = rail.carriages_m.iter().find_map(|p| coords(p).err()) {
            return Err((key(&format!("rail[{r}].carriages_m")), m));
        }
        if rail.carriages_m.is_empty() {
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
        coords(&p).map_err(|m| (key(k), m))?;
    }
    let diameter = positive(
        d.screw_diameter_m,
        key("screw_diameter_m"),
        Range(1e-3, 1.0, "m"),
    )?;
    let drive = Drive {
        nut_m: Vector3::from(d.nut_m),
        bearing_m: Vector3::from(d.bearing_m),
        scale_m: Vector3::from(d.scale_m),
        lead_m: positive(d.lead_m, key("lead_m"), Range(1e-4, 1.0, "m"))?,
        screw_area_m2: std::f64::consts::PI * diameter * diameter / 4.0,
        screw_modulus_pa: positive(
            d.screw_modulus_pa,
            key("screw_modulus_pa"),
            Range(1e9, 1e13, "Pa"),
        )?,
        support: d.support,
        screw_length_m: match (d.support, d.screw_length_m) {
            (Support::FixedFixed, Some(l)) => Some(positive(l, key("screw_length_m"), LENGTH)?),
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
        nut_stiffness_n_per_m: positive(
            d.nut_stiffness_n_per_um,
            key("nut_stiffness_n_per_um"),
            STIFFNESS_N_PER_UM,
        )? * 1e6,
        bearing_stiffness_n_per_m: positive(
            d.bearing_stiffness_n_per_um,
            key("bearing_stiffness_n_per_um"),
            STIFFNESS_N_PER_UM,
        )? * 1e6,
        reduction: positive(d.reduction, key("reduction"), FACTOR)?,
        damping_n_s_per_m: non_negative(d.damping_n_s_per_m, key("damping_n_s_per_m"), DAMPING)?,
        rotor_inertia_kg_m2: positive(
            d.rotor_inertia_kg_m2,
            key("rotor_inertia_kg_m2"),
            Range(1e-8, 100.0, "kg·m²"),
        )?,
        friction_nm_s_per_rad: non_negative(
            d.friction_nm_s_per_rad,
            key("friction_nm_s_per_rad"),
            Range(0.0, 1e6, "N·m·s/rad"),
        )?,
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
        kv_per_s: positive(c.kv_per_s, key("kv_per_s"), Range(0.1, 1e4, "1/s"))?,
        kp_nm_s_per_rad: positive(
            c.kp_nm_s_per_rad,
            key("kp_nm_s_per_rad"),
            Range(1e-6, 1e6, "N·m·s/rad"),
        )?,
        tn_s: positive(c.tn_s, key("tn_s"), Range(1e-5, 100.0, "s"))?,
        current_lag_s: non_negative(c.current_lag_s, key("current_lag_s"), Range(0.0, 0.1, "s"))?,
        setpoint_filter_s: non_negative(
            c.setpoint_filter_s,
            key("setpoint_filter_s"),
            Range(0.0, 10.0, "s"),
        )?,
        feedback: c.feedback,
        velocity_feedforward: non_negative(
            c.velocity_feedforward,
            key("velocity_feedforward"),
            Range(0.0, 2.0, ""),
        )?,
        acceleration_feedforward: non_negative(
            c.acceleration_feedforward,
            key("acceleration_feedforward"),
            Range(0.0, 2.0, ""),
        )?,
    })
}
