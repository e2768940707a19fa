//! Elastic bodies from `[body.fe]` and `[body.beam]`: the FE model ([`crate::fe`]) reduced for
//! the points the machine attaches to the body, and coupled through those attachments
//! (docs/fe.md):
//!
//! * a point fixed on the body (a carriage or the nut on the moving body, joints, the TCP)
//!   attaches by the contract's rule (nearest 6-DOF node through the lever arm, or an RBE3 patch
//!   of solid nodes); the R-Test nest, which lies under the tool, keeps the attachment of its
//!   reference position and is carried from there through the lever arm;
//! * a point that travels along the body with an axis (the carriages on the carrier's rails,
//!   the scale's read position) blends the two stations that bracket it, continuous in the
//!   axis position;
//! * the ball screw's axial force, its thread torque and the motor stator reach the carrier at
//!   the fixed bearing; on a fixed-fixed screw at both bearings, as the two shaft segments share
//!   the load: (L − l₁)/L at the first and l₁/L at the second, l₁ the nut's distance from the
//!   first (continuous in the axis position).
//!
//! Each body is reduced once per run: reductions are kept by what they were made from (the
//! files with their sizes and modification times, or the beam; the settings; the attachments),
//! so that reading the same machine again, or a copy of it, reuses them.

use super::attach::BodySite;
use super::body::{ElasticBody, ElasticModel, Site};
use super::raw::{RawBeam, RawBody, RawFe, Support};
use super::{Machine, MachineError};
use crate::fe::{self, Attachment, Beam, FeModel, ReducedBody, ReductionSettings};
use nalgebra::{DMatrix, Matrix6, Vector3};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, OnceLock};

/// Default number of fixed-interface modes where neither `modes` nor `cutoff_hz` is given.
pub(crate) const DEFAULT_MODES: usize = 20;

/// How far given mass properties may differ from the FE model's (docs/fe.md): mass and inertia
/// relative, COG relative to the body's extent.
const MASS_AGREEMENT: f64 = 0.01;

/// A reduction with the body's extent (for the COG check).
#[derive(Debug)]
pub struct Reduction {
    /// The reduced body.
    pub reduced: ReducedBody,
    /// Diagonal of the box around the FE nodes, m.
    pub extent_m: f64,
}

/// How one site reaches the reduced body.
#[derive(Debug, Clone)]
enum Reach {
    /// Attachment `index` at `point_m`; a point elsewhere is carried through the lever arm.
    Fixed { index: usize, point_m: Vector3<f64> },
    /// Attachment `index` travelling from `start_m` along the unit vector `unit`; at the
    /// machine's reference position it lies `reference_s` m from the start.
    Travel {
        index: usize,
        start_m: Vector3<f64>,
        unit: Vector3<f64>,
        reference_s: f64,
    },
    /// The two bearings of a fixed-fixed screw (attachments `indices`), the first at
    /// `bearing_m`, the second `length_m` further along `unit`.
    Bearings {
        indices: [usize; 2],
        bearing_m: [Vector3<f64>; 2],
        unit: Vector3<f64>,
        length_m: f64,
    },
}

/// A reduced FE body as the assembly sees it ([`ElasticModel`]).
#[derive(Debug)]
pub struct FeBody {
    reduction: Arc<Reduction>,
    mass: DMatrix<f64>,
    stiffness: DMatrix<f64>,
    reach: Vec<(Site, Reach)>,
}

impl FeBody {
    /// The reduction it couples.
    pub fn reduction(&self) -> &Arc<Reduction> {
        &self.reduction
    }

    /// Per attachment of the reduction, its position at the machine's reference position
    /// (metres along the travel; 0 for a fixed point), for `eij fe`'s summary.
    pub(crate) fn reference_positions(&self) -> Vec<f64> {
        let mut s = vec![0.0; self.reduction.reduced.attachments.len()];
        for (_, r) in &self.reach {
            if let Reach::Travel {
                index, reference_s, ..
            } = r
            {
                s[*index] = *reference_s;
            }
        }
        s
    }
}

/// (u, θ) at a point carried to a point at offset d: (u + θ × d, θ).
fn lever(d: &Vector3<f64>) -> Matrix6<f64> {
    let mut t = Matrix6::identity();
    t.fixed_view_mut::<3, 3>(0, 3)
        .copy_from(&(-d.cross_matrix()));
    t
}

impl ElasticModel for FeBody {
    fn cog_m(&self) -> Vector3<f64> {
        self.reduction.reduced.mass.cog_m
    }
    fn mass(&self) -> &DMatrix<f64> {
        &self.mass
    }
    fn stiffness(&self) -> &DMatrix<f64> {
        &self.stiffness
    }
    fn point_motion(&self, site: Site, p: &Vector3<f64>) -> Option<DMatrix<f64>> {
        let reduced = &self.reduction.reduced;
        let (_, reach) = self.reach.iter().find(|(s, _)| *s == site)?;
        let g = match reach {
            Reach::Fixed { index, point_m } => {
                lever(&(p - point_m)) * reduced.point_motion(*index, 0.0)
            }
            Reach::Travel {
                index,
                start_m,
                unit,
                ..
            } => reduced.point_motion(*index, unit.dot(&(p - start_m))),
            Reach::Bearings {
                indices,
                bearing_m,
                unit,
                length_m,
            } => {
                let share = (unit.dot(&(p - bearing_m[0])) / length_m).clamp(0.0, 1.0);
                lever(&(p - bearing_m[0])) * reduced.point_motion(indices[0], 0.0) * (1.0 - share)
                    + lever(&(p - bearing_m[1])) * reduced.point_motion(indices[1], 0.0) * share
            }
        };
        Some(DMatrix::from_iterator(6, g.ncols(), g.iter().copied()))
    }
    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
}

/// The FE model and reduction settings of a body, as the machine file says.
enum Source<'a> {
    Files(&'a RawFe, [PathBuf; 4]),
    Beam(&'a RawBeam),
}

fn cache() -> &'static Mutex<HashMap<String, Arc<Reduction>>> {
    static CACHE: OnceLock<Mutex<HashMap<String, Arc<Reduction>>>> = OnceLock::new();
    CACHE.get_or_init(Mutex::default)
}

/// What a reduction is made from, as a cache key: files by path, size and modification time.
fn key(source: &Source, settings: &ReductionSettings, attachments: &[Attachment]) -> String {
    let origin = match source {
        Source::Files(_, paths) => paths
            .iter()
            .map(|p| {
                let meta = std::fs::metadata(p).ok();
                let stamp = meta.as_ref().map(|m| (m.len(), m.modified().ok()));
                format!("{}:{stamp:?}", p.display())
            })
            .collect::<Vec<_>>()
            .join(","),
        Source::Beam(b) => format!("{b:?}"),
    };
    format!("{origin}|{settings:?}|{attachments:?}")
}

/// The body's FE model, read from its files or built as a beam.
fn model(source: &Source) -> Result<FeModel, fe::FeError> {
    match source {
        Source::Files(_, [m, k, d, n]) => FeModel::from_files(m, k, d, n),
        Source::Beam(b) => FeModel::beam(&Beam::from(*b)),
    }
}

/// Where a body's FE model comes from (`[body.fe]` paths relative to `base`, the machine file's
/// folder); `None` for a body without one.
fn source<'a>(rb: &'a RawBody, base: &Path) -> Result<Option<Source<'a>>, &'static str> {
    match (&rb.fe, &rb.beam) {
        (Some(f), None) => {
            let path = |rel: &str| base.join(rel);
            Ok(Some(Source::Files(
                f,
                [
                    path(&f.mass_matrix),
                    path(&f.stiffness_matrix),
                    path(&f.dofs),
                    path(&f.nodes),
                ],
            )))
        }
        (None, Some(beam)) => Ok(Some(Source::Beam(beam))),
        (None, None) => Ok(None),
        (Some(_), Some(_)) => Err("give either [body.fe] or [body.beam], not both"),
    }
}

fn reduce(
    source: &Source,
    settings: &ReductionSettings,
    attachments: &[Attachment],
) -> Result<Arc<Reduction>, fe::FeError> {
    let key = key(source, settings, attachments);
    if let Some(r) = cache().lock().ok().and_then(|c| c.get(&key).cloned()) {
        return Ok(r);
    }
    let model = model(source)?;
    let reduced = fe::reduce(&model, attachments, settings)?;
    let r = Arc::new(Reduction {
        reduced,
        extent_m: model.extent_m(),
    });
    if let Ok(mut c) = cache().lock() {
        c.insert(key, r.clone());
    }
    Ok(r)
}

impl From<&RawBeam> for Beam {
    fn from(b: &RawBeam) -> Beam {
        Beam {
            from_m: b.from_m,
            to_m: b.to_m,
            elements: b.elements,
            y_axis: b.y_axis,
            area_m2: b.area_m2,
            iy_m4: b.iy_m4,
            iz_m4: b.iz_m4,
            torsion_m4: b.torsion_m4,
            shear_factor: b.shear_factor,
            youngs_modulus_pa: b.youngs_modulus_pa,
            shear_modulus_pa: b.shear_modulus_pa,
            density_kg_m3: b.density_kg_m3,
        }
    }
}

impl Machine {
    /// The name of a site in `eij fe`'s attachments: `z.carriage[0]`, `z.nut`, `z.scale`,
    /// `joint[foot-front-left]`, `tcp`, `workpiece`.
    pub(crate) fn site_label(&self, site: Site) -> String {
        match site {
            Site::Joint(j) => format!("joint[{}]", self.joints[j].name),
            other => other.to_string(),
        }
    }

    /// `eij fe`'s summary of body `b` (docs/fe.md): its FE model, its reduction
    /// for this machine's attachments (at the reference position) and, for comparison, the full
    /// model's elastic free-free frequencies (the model read or built again, a sparse
    /// eigensolution of the whole model). Frequencies hold at the body's stiffness factor.
    /// `None` where body `b` has no `[body.fe]` or `[body.beam]` (a rigid or fixed body).
    pub fn fe_summary(&self, b: usize) -> Result<Option<fe::FeSummary>, MachineError> {
        let Some(body) = self.bodies.get(b) else {
            return Ok(None);
        };
        let Some(elastic) = body.elastic() else {
            return Ok(None);
        };
        let Some(fe_body) = elastic.model().as_any().downcast_ref::<FeBody>() else {
            return Ok(None);
        };
        let rb = &self.raw.bodies[b];
        // The machine's construction made the [body.fe] paths absolute.
        let Ok(Some(source)) = source(rb, Path::new("")) else {
            return Ok(None);
        };
        let key = match source {
            Source::Files(..) => "fe",
            Source::Beam(_) => "beam",
        };
        let err = |e: fe::FeError| {
            MachineError::new(
                &self.source,
                format!("body[{}].{key}", rb.name),
                e.to_string(),
            )
        };
        let model = model(&source).map_err(err)?;
        let mut reduced = fe_body.reduction.reduced.clone();
        reduced.add_full_reference(&model).map_err(err)?;
        Ok(Some(reduced.summary(
            &body.name,
            &fe_body.reference_positions(),
            elastic.stiffness_factor(),
        )))
    }

    /// The attachments of body `b` for its reduction, and how each site reaches them.
    fn attachments(&self, b: usize) -> (Vec<Attachment>, Vec<(Site, Reach)>) {
        let mut atts = Vec::new();
        let mut reach = Vec::new();
        let fixed = |atts: &mut Vec<Attachment>, name: String, p: &Vector3<f64>| {
            atts.push(Attachment::fixed(&name, (*p).into()));
            atts.len() - 1
        };
        for s in self.sites().into_iter().filter(|s: &BodySite| s.body == b) {
            let name = self.site_label(s.site);
            let r = match (s.site, s.travel.as_slice()) {
                (Site::Nut(axis), [_]) => {
                    let a = self.axis(axis).expect("a site's axis exists");
                    let d = &a.drive;
                    let unit = (s.point_m - d.bearing_m).normalize();
                    let first = fixed(&mut atts, format!("{axis}.bearing"), &d.bearing_m);
                    match (d.support, d.screw_length_m) {
                        (Support::FixedFixed, Some(length_m)) => {
                            let far = d.bearing_m + unit * length_m;
                            let second = fixed(&mut atts, format!("{axis}.bearing[far]"), &far);
                            Reach::Bearings {
                                indices: [first, second],
                                bearing_m: [d.bearing_m, far],
                                unit,
                                length_m,
                            }
                        }
                        _ => Reach::Fixed {
                            index: first,
                            point_m: d.bearing_m,
                        },
                    }
                }
                (_, [(ai, dir)]) => {
                    let a = &self.axes[*ai];
                    let at = |v: f64| s.point_m + dir * (v - a.reference_m);
                    let (start, end) = (at(a.stroke_m[0]), at(a.stroke_m[1]));
                    atts.push(Attachment::travel(&name, start.into(), end.into()));
                    Reach::Travel {
                        index: atts.len() - 1,
                        start_m: start,
                        unit: (end - start).normalize(),
                        reference_s: (s.point_m - start).norm(),
                    }
                }
                _ => Reach::Fixed {
                    index: fixed(&mut atts, name, &s.point_m),
                    point_m: s.point_m,
                },
            };
            reach.push((s.site, r));
        }
        (atts, reach)
    }

    /// Makes every body with `[body.fe]` or `[body.beam]` elastic: reduces its FE model for the
    /// machine's attachments (or takes the run's earlier reduction of it) and checks the mass
    /// properties the file gives against the FE model's.
    pub(super) fn with_elastic_bodies(
        mut self,
        raw_bodies: &[RawBody],
    ) -> Result<Machine, MachineError> {
        let base = Path::new(&self.source)
            .parent()
            .unwrap_or(Path::new(""))
            .to_path_buf();
        for (b, rb) in raw_bodies.iter().enumerate() {
            let source = match source(rb, &base) {
                Ok(Some(source)) => source,
                Ok(None) => continue,
                Err(m) => {
                    return Err(MachineError::new(
                        &self.source,
                        format!("body[{}]", rb.name),
                        m,
                    ))
                }
            };
            let key = match source {
                Source::Files(..) => "fe",
                Source::Beam(_) => "beam",
            };
            let err = |k: &str, m: String| {
                MachineError::new(&self.source, format!("body[{}].{key}{k}", rb.name), m)
            };
            let (damping, factor) = match &source {
                Source::Files(f, _) => (f.damping_ratio, f.stiffness_factor),
                Source::Beam(b) => (b.damping_ratio, b.stiffness_factor),
            };
            let settings = settings(&source).map_err(|(k, m)| err(k, m))?;
            let (attachments, reach) = self.attachments(b);
            let reduction =
                reduce(&source, &settings, &attachments).map_err(|e| err("", e.to_string()))?;
            check_given_mass(rb, &reduction).map_err(|(k, m)| {
                MachineError::new(&self.source, format!("body[{}].{k}", rb.name), m)
            })?;
            let fe_body = FeBody {
                mass: reduction.reduced.mass_matrix(),
                stiffness: reduction.reduced.stiffness_matrix(1.0),
                reduction,
                reach,
            };
            let elastic = ElasticBody::new(Arc::new(fe_body), damping, factor)
                .map_err(|e| err("", e.to_string()))?;
            self = self.with_elastic_body(&rb.name, elastic)?;
            if let Source::Files(_, paths) = &source {
                // Exported machine files must find the matrices from wherever they are written.
                let fe = Arc::make_mut(&mut self.raw).bodies[b]
                    .fe
                    .as_mut()
                    .expect("a [body.fe]");
                let absolute = |p: &PathBuf| {
                    std::path::absolute(p)
                        .unwrap_or_else(|_| p.clone())
                        .display()
                        .to_string()
                };
                fe.mass_matrix = absolute(&paths[0]);
                fe.stiffness_matrix = absolute(&paths[1]);
                fe.dofs = absolute(&paths[2]);
                fe.nodes = absolute(&paths[3]);
            }
        }
        Ok(self)
    }
}

type FieldError = (&'static str, String);

/// Most interface coordinates `interface_modes` may ask for beyond the six rigid-body motions.
const MAX_INTERFACE_MODES: usize = 1000;

/// The reduction settings a `[body.fe]` or `[body.beam]` gives, checked: an error names the
/// key (relative to the block).
fn settings(source: &Source) -> Result<ReductionSettings, FieldError> {
    let (modes, cutoff_hz, factor, radius, interface_modes) = match source {
        Source::Files(f, _) => (
            f.modes,
            f.cutoff_hz,
            f.stiffness_factor,
            f.attach_radius_m,
            f.interface_modes,
        ),
        Source::Beam(b) => (
            b.modes,
            b.cutoff_hz,
            b.stiffness_factor,
            None,
            b.interface_modes,
        ),
    };
    check_settings(modes, cutoff_hz, factor, radius)?;
    if let Some(k) = interface_modes {
        if !(1..=MAX_INTERFACE_MODES).contains(&k) {
            return Err((
                ".interface_modes",
                format!(
                    "{k} must be in 1 … {MAX_INTERFACE_MODES} (interface coordinates kept beside the six rigid-body motions)"
                ),
            ));
        }
    }
    Ok(ReductionSettings {
        modes: modes.unwrap_or(DEFAULT_MODES),
        cutoff_hz,
        attach_radius_m: radius,
        interface_modes,
        full_reference: false,
    })
}

fn check_settings(
    modes: Option<usize>,
    cutoff_hz: Option<f64>,
    factor: f64,
    radius: Option<f64>,
) -> Result<(), FieldError> {
    if modes.is_some() && cutoff_hz.is_some() {
        return Err((".modes", "give either modes or cutoff_hz, not both".into()));
    }
    if let Some(f) = cutoff_hz {
        if !(f.is_finite() && f > 0.0 && f < 1e6) {
            return Err((".cutoff_hz", format!("{f} must be in (0, 1e6) Hz")));
        }
    }
    if modes.is_some_and(|m| m > 1000) {
        return Err((".modes", "at most 1000 modes".into()));
    }
    if !(factor.is_finite() && (1e-4..=1e6).contains(&factor)) {
        return Err((
            ".stiffness_factor",
            format!("{factor} must be in [1e-4, 1e6] (times the FE stiffness)"),
        ));
    }
    if let Some(r) = radius {
        if !(r.is_finite() && r > 0.0 && r < 100.0) {
            return Err((".attach_radius_m", format!("{r} must be in (0, 100) m")));
        }
    }
    Ok(())
}

/// Whether a difference is within [`MASS_AGREEMENT`] of `scale` (false for NaN).
fn agrees(difference: f64, scale: f64) -> bool {
    difference <= MASS_AGREEMENT * scale
}

/// Mass, COG and inertia given beside an FE model must agree with it (docs/fe.md): mass within
/// 1 %, COG within 1 % of the body's extent, inertia within 1 % of its largest principal value.
fn check_given_mass(rb: &RawBody, r: &Reduction) -> Result<(), FieldError> {
    let fe = &r.reduced.mass;
    if let Some(m) = rb.mass_kg {
        if !agrees((m - fe.mass_kg).abs(), fe.mass_kg) {
            return Err((
                "mass_kg",
                format!(
                    "{m} kg differs from the FE model's {:.6} kg by more than 1 %",
                    fe.mass_kg
                ),
            ));
        }
    }
    if let Some(c) = rb.cog_m {
        let off = (Vector3::from(c) - fe.cog_m).norm();
        if !agrees(off, r.extent_m) {
            return Err((
                "cog_m",
                format!(
                    "{} m lies {off:.6} m from the FE model's centre of gravity [{:.6}, {:.6}, {:.6}] m, more than 1 % of the body's extent {:.6} m",
                    crate::text::nums(&c),
                    fe.cog_m.x,
                    fe.cog_m.y,
                    fe.cog_m.z,
                    r.extent_m
                ),
            ));
        }
    }
    if let Some(j) = rb.inertia_kg_m2 {
        let given = nalgebra::Matrix3::from_fn(|r, c| j[r][c]);
        let largest = fe.inertia_kg_m2.symmetric_eigenvalues().max();
        let off = (given - fe.inertia_kg_m2).abs().max();
        if !agrees(off, largest) {
            return Err((
                "inertia_kg_m2",
                format!(
                    "differs from the FE model's inertia by {off:.6} kg·m², more than 1 % of its largest principal moment {largest:.6} kg·m²"
                ),
            ));
        }
    }
    Ok(())
}
