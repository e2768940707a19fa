//! A body's coordinates: what the assembly needs to know of a body, whatever its kind.
//!
//! Every free body has w coordinates. The first six are the rigid motion of a body frame at the
//! centre of gravity c, q = (x, y, z, a, b, c) (small rotations); an elastic body adds m elastic
//! coordinates η₁ … η_m after them (DESIGN.md "Elastic bodies"). Whatever the kind, the assembly
//! asks a body the same four things:
//!
//! * its width w ([`Body::width`]) and the names of its coordinates;
//! * how a point on it moves: the 6 × w map from its coordinates to the translation (rows 0–2)
//!   and the rotation (rows 3–5) of the point where something attaches ([`Body::point_motion`]).
//!   A rigid body gives [[I, −skew(p − c)], [0, I]] (DESIGN.md "Structure"); an elastic body the
//!   attachment of its reduced model, which for a point that travels along the body with an
//!   axis is continuous in the axis position;
//! * its own mass, stiffness and damping blocks (w × w);
//! * the coordinates of a rigid motion of the body ([`Body::rigid_coordinates`]): the same for
//!   both kinds, since elastic coordinates are zero in a rigid motion.

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use std::fmt;
use std::sync::Arc;

use crate::axes::Axis;

/// What attaches to a body at a point. An elastic body holds one attachment per site on it (its
/// nodes and weights); a rigid body needs only the point. Displayed as in `eij fe`'s
/// `attachments` (`z.carriage[0]`, `joint[2]`, `tcp`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Site {
    /// Carriage `index` of an axis's guideway (counted over its rails in file order): fixed on
    /// the moving body, travelling along the carrier's rail.
    Carriage {
        /// The axis.
        axis: Axis,
        /// Carriage number over all rails of the axis.
        index: usize,
    },
    /// The ball-screw nut: fixed on the moving body, travelling along the screw on the carrier.
    /// The screw's axial force and thread torque reach the carrier at its fixed bearing (with the
    /// motor stator): an elastic carrier takes them at the bearing; a rigid carrier feels them
    /// alike anywhere on the screw line and takes them at the nut.
    Nut(Axis),
    /// The linear scale's reading head: fixed on the moving body, travelling along the scale
    /// on the carrier.
    Scale(Axis),
    /// A compliant joint (index in the machine's joints), fixed on both bodies.
    Joint(usize),
    /// The tool centre point on the tool-side body.
    Tcp,
    /// The R-Test nest on the workpiece-side body: the point under the TCP, which travels over
    /// the body with every axis between them.
    Workpiece,
}

impl fmt::Display for Site {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Site::Carriage { axis, index } => write!(f, "{axis}.carriage[{index}]"),
            Site::Nut(axis) => write!(f, "{axis}.nut"),
            Site::Scale(axis) => write!(f, "{axis}.scale"),
            Site::Joint(j) => write!(f, "joint[{j}]"),
            Site::Tcp => f.write_str("tcp"),
            Site::Workpiece => f.write_str("workpiece"),
        }
    }
}

/// What the assembly needs of an elastic body's reduced model: reduced mass and stiffness over
/// the body coordinates (six rigid coordinates at the centre of gravity, then the elastic ones)
/// and the motion of every attachment. A reduction of an FE model provides it; so can a model
/// made by hand.
pub trait ElasticModel: fmt::Debug + Send + Sync {
    /// Centre of gravity at the reference position, m: the origin of the rigid coordinates.
    fn cog_m(&self) -> Vector3<f64>;
    /// Reduced mass matrix, w × w (w = 6 + elastic coordinates), SI. Its rigid block is
    /// blockdiag(m·I, J) with J the inertia tensor about the centre of gravity.
    fn mass(&self) -> &DMatrix<f64>;
    /// Reduced stiffness matrix at stiffness factor 1, w × w, N/m and N·m/rad; it is zero for a
    /// rigid motion (its first six rows and columns vanish).
    fn stiffness(&self) -> &DMatrix<f64>;
    /// The 6 × w motion (translation rows 0–2, rotation rows 3–5) of the attachment of `site`
    /// when it lies at `point_m` (reference frame of the body, m); `None` if nothing of that
    /// kind attaches to the body.
    fn point_motion(&self, site: Site, point_m: &Vector3<f64>) -> Option<DMatrix<f64>>;
    /// The model as [`std::any::Any`], so a caller can reach the concrete type behind it (e.g.
    /// the reduced FE model of `[body.fe]`/`[body.beam]`, `machine::elastic::FeBody`) without
    /// this module knowing that type (no import circle).
    fn as_any(&self) -> &dyn std::any::Any;
}

/// An elastic body: its reduced model (shared, computed once per run) with the factor on its
/// elastic stiffness and the modal damping of its elastic coordinates.
#[derive(Debug, Clone)]
pub struct ElasticBody {
    model: Arc<dyn ElasticModel>,
    /// Modal damping at stiffness factor 1: D₁ = M Φ diag(2ζω) Φᵀ M over the elastic modes
    /// (Φ mass-normalised), scaled by √factor since ω ∝ √factor.
    damping_unit: Arc<DMatrix<f64>>,
    /// ω² of the elastic modes at stiffness factor 1, ascending (rigid modes left out).
    eigenvalues_unit: Arc<Vec<f64>>,
    damping_ratio: f64,
    stiffness_factor: f64,
}

impl PartialEq for ElasticBody {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.model, &other.model)
            && self.damping_ratio == other.damping_ratio
            && self.stiffness_factor == other.stiffness_factor
    }
}

/// Why an elastic model cannot serve as a body.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ElasticModelError {
    /// Matrices of the wrong size or shape.
    #[error("{0}")]
    Shape(String),
    /// Mass or stiffness not what a physical body has.
    #[error("{0}")]
    Physics(String),
}

impl ElasticBody {
    /// Checks a reduced model (sizes, symmetry, a positive definite mass, a stiffness that is
    /// positive semi-definite and free of rigid-body stiffness) and computes its modal damping:
    /// ratio ζ (0 ≤ ζ < 1) on every elastic mode of K φ = ω² M φ.
    pub fn new(
        model: Arc<dyn ElasticModel>,
        damping_ratio: f64,
        stiffness_factor: f64,
    ) -> Result<ElasticBody, ElasticModelError> {
        let (m, k) = (model.mass(), model.stiffness());
        let w = m.nrows();
        if w < 6 || m.shape() != (w, w) || k.shape() != (w, w) {
            return Err(ElasticModelError::Shape(format!(
                "mass {:?} and stiffness {:?} must be square, of the same size, at least 6 (the rigid coordinates)",
                m.shape(),
                k.shape()
            )));
        }
        if !(m.iter().chain(k.iter()).all(|x| x.is_finite())) {
            return Err(ElasticModelError::Physics(
                "mass or stiffness has entries that are not finite".into(),
            ));
        }
        let asym = |a: &DMatrix<f64>| (a - a.transpose()).abs().max() > 1e-9 * a.abs().max();
        if asym(m) || asym(k) {
            return Err(ElasticModelError::Physics(
                "mass and stiffness must be symmetric".into(),
            ));
        }
        let rigid_stiffness = k.columns(0, 6).abs().max();
        if rigid_stiffness > 1e-9 * k.abs().max() {
            return Err(ElasticModelError::Physics(format!(
                "a rigid motion of the body meets stiffness ({rigid_stiffness:.3e} against {:.3e}): the elastic coordinates must leave rigid motion free",
                k.abs().max()
            )));
        }
        if !(damping_ratio.is_finite() && (0.0..1.0).contains(&damping_ratio)) {
            return Err(ElasticModelError::Physics(format!(
                "damping ratio {damping_ratio} must be in [0, 1)"
            )));
        }
        if !(stiffness_factor.is_finite() && stiffness_factor > 0.0) {
            return Err(ElasticModelError::Physics(format!(
                "stiffness factor {stiffness_factor} must be > 0"
            )));
        }
        let (damping_unit, eigenvalues_unit) = modal_damping(m, k, damping_ratio)?;
        Ok(ElasticBody {
            model,
            damping_unit: Arc::new(damping_unit),
            eigenvalues_unit: Arc::new(eigenvalues_unit),
            damping_ratio,
            stiffness_factor,
        })
    }

    /// The reduced model.
    pub fn model(&self) -> &Arc<dyn ElasticModel> {
        &self.model
    }

    /// Number of elastic coordinates.
    pub fn modes(&self) -> usize {
        self.model.mass().nrows() - 6
    }

    /// Factor on the elastic stiffness (E and G alike).
    pub fn stiffness_factor(&self) -> f64 {
        self.stiffness_factor
    }

    /// Modal damping ratio of the elastic modes.
    pub fn damping_ratio(&self) -> f64 {
        self.damping_ratio
    }

    /// The body's elastic free-free frequencies at its stiffness factor, Hz, ascending (the
    /// reduced body alone, rigid modes left out): √(factor · ω²)/2π.
    pub fn frequencies_hz(&self) -> Vec<f64> {
        self.eigenvalues_unit
            .iter()
            .map(|l| (self.stiffness_factor * l).sqrt() / std::f64::consts::TAU)
            .collect()
    }

    pub(crate) fn set_stiffness_factor(&mut self, factor: f64) {
        self.stiffness_factor = factor;
    }
}

/// D = M Φ diag(2ζω) Φᵀ M over the modes of K φ = ω² M φ (Φᵀ M Φ = I), so that Φᵀ D Φ =
/// diag(2ζω): every mode damped by ζ, the rigid modes (ω = 0) not at all; and the ω² of the
/// elastic modes, ascending (the six smallest, the rigid modes, left out).
fn modal_damping(
    m: &DMatrix<f64>,
    k: &DMatrix<f64>,
    zeta: f64,
) -> Result<(DMatrix<f64>, Vec<f64>), ElasticModelError> {
    let chol = m.clone().cholesky().ok_or_else(|| {
        ElasticModelError::Physics("the mass matrix is not positive definite".into())
    })?;
    let l = chol.l();
    let linv = l
        .clone()
        .try_inverse()
        .ok_or_else(|| ElasticModelError::Physics("singular mass matrix".into()))?;
    let a = &linv * k * linv.transpose();
    let a = (&a + a.transpose()) * 0.5;
    let eig = nalgebra::SymmetricEigen::try_new(a, f64::EPSILON, 10_000).ok_or_else(|| {
        ElasticModelError::Physics("the eigen-solution of the body did not converge".into())
    })?;
    let scale = eig.eigenvalues.abs().max();
    if eig.eigenvalues.min() < -1e-9 * scale {
        return Err(ElasticModelError::Physics(
            "the stiffness matrix is not positive semi-definite".into(),
        ));
    }
    let omega = eig.eigenvalues.map(|w2| 2.0 * zeta * w2.max(0.0).sqrt());
    // With y = Lᵀq the problem is standard; M Φ = L V, so D = L V diag V ᵀ Lᵀ.
    let lv = &l * &eig.eigenvectors;
    let mut elastic: Vec<f64> = eig.eigenvalues.iter().map(|w2| w2.max(0.0)).collect();
    elastic.sort_by(f64::total_cmp);
    Ok((
        &lv * DMatrix::from_diagonal(&omega) * lv.transpose(),
        elastic.split_off(6.min(elastic.len())),
    ))
}

/// What kind of body, and what that kind carries.
#[derive(Debug, Clone, PartialEq)]
pub enum BodyKind {
    /// Fixed to the ground: no coordinates.
    Fixed,
    /// A rigid body: six coordinates at its centre of gravity.
    Rigid,
    /// An elastic body: six rigid coordinates and its reduced model's elastic ones.
    Elastic(ElasticBody),
}

/// A body of the machine. Its mass properties hold for every kind (an elastic body's come from
/// its FE mass matrix); its coordinates are described by [`Body::width`],
/// [`Body::point_motion`] and the matrices, the same questions for every kind.
#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    /// Unique name.
    pub name: String,
    /// Mass, kg (0 for fixed bodies).
    pub mass_kg: f64,
    /// Centre of gravity at the reference position, m.
    pub cog_m: Vector3<f64>,
    /// Inertia tensor about the COG, kg·m².
    pub inertia_kg_m2: Matrix3<f64>,
    /// Fixed, rigid or elastic.
    pub kind: BodyKind,
}

/// Names of the six rigid coordinates.
pub(crate) const RIGID_COORDINATES: [&str; 6] = ["x", "y", "z", "a", "b", "c"];

impl Body {
    /// Fixed to the ground (no coordinates).
    pub fn is_fixed(&self) -> bool {
        matches!(self.kind, BodyKind::Fixed)
    }

    /// Number of coordinates w: 0 fixed, 6 rigid, 6 + m elastic.
    pub fn width(&self) -> usize {
        match &self.kind {
            BodyKind::Fixed => 0,
            BodyKind::Rigid => 6,
            BodyKind::Elastic(e) => 6 + e.modes(),
        }
    }

    /// Coordinate names without the body's name: `x` … `c`, then `mode1` … `mode<m>`.
    pub(crate) fn coordinate_names(&self) -> Vec<String> {
        let w = self.width();
        (0..w)
            .map(|i| match RIGID_COORDINATES.get(i) {
                Some(n) => n.to_string(),
                None => format!("mode{}", i - 5),
            })
            .collect()
    }

    /// The 6 × w motion of `site` on this body: translation (rows 0–2) and rotation (rows 3–5)
    /// per body coordinate. `point_m` is where the site lies at this pose and `shift_m` how far
    /// the axes have carried the body from its reference position (machine coordinates, m), so
    /// that `point_m − shift_m` is the point of the body. A rigid body gives
    /// [[I, −skew(p − c)], [0, I]] with c its centre of gravity at this pose (DESIGN.md
    /// "Structure"). `None` for a fixed body, or an elastic one with nothing of the kind attached.
    pub fn point_motion(
        &self,
        site: Site,
        point_m: &Vector3<f64>,
        shift_m: &Vector3<f64>,
    ) -> Option<DMatrix<f64>> {
        match &self.kind {
            BodyKind::Fixed => None,
            BodyKind::Rigid => Some(rigid_point_motion(point_m, &(self.cog_m + shift_m))),
            BodyKind::Elastic(e) => e.model.point_motion(site, &(point_m - shift_m)),
        }
    }

    /// The body's own mass matrix, w × w: blockdiag(m·I, J) for a rigid body, the reduced mass
    /// for an elastic one.
    pub fn mass_matrix(&self) -> DMatrix<f64> {
        match &self.kind {
            BodyKind::Elastic(e) => e.model.mass().clone(),
            _ => {
                let w = self.width();
                let mut m = DMatrix::zeros(w, w);
                if w == 6 {
                    for d in 0..3 {
                        m[(d, d)] = self.mass_kg;
                    }
                    m.view_mut((3, 3), (3, 3)).copy_from(&self.inertia_kg_m2);
                }
                m
            }
        }
    }

    /// The body's own stiffness (w × w, the reduced stiffness times the stiffness factor) and
    /// damping (modal), for bodies that have elastic coordinates; `None` for the others.
    pub fn elastic_matrices(&self) -> Option<(DMatrix<f64>, DMatrix<f64>)> {
        match &self.kind {
            BodyKind::Elastic(e) => Some((
                e.model.stiffness() * e.stiffness_factor,
                &*e.damping_unit * e.stiffness_factor.sqrt(),
            )),
            _ => None,
        }
    }

    /// The coordinates (length w) of a rigid motion that translates the centre of gravity by
    /// `translation_m` and turns the body by `rotation_rad` (small angles); elastic coordinates
    /// are zero in it.
    pub fn rigid_coordinates(
        &self,
        translation_m: &Vector3<f64>,
        rotation_rad: &Vector3<f64>,
    ) -> DVector<f64> {
        let mut q = DVector::zeros(self.width());
        if q.len() >= 6 {
            q.rows_mut(0, 3).copy_from(translation_m);
            q.rows_mut(3, 3).copy_from(rotation_rad);
        }
        q
    }

    /// The elastic body, if it is one.
    pub fn elastic(&self) -> Option<&ElasticBody> {
        match &self.kind {
            BodyKind::Elastic(e) => Some(e),
            _ => None,
        }
    }
}

/// [[I, −skew(p − c)], [0, I]]: translation and rotation of point p of a rigid body with its
/// coordinates at c.
pub(crate) fn rigid_point_motion(p: &Vector3<f64>, c: &Vector3<f64>) -> DMatrix<f64> {
    let r = p - c;
    let mut t = DMatrix::zeros(6, 6);
    t.view_mut((0, 0), (3, 3)).fill_with_identity();
    t.view_mut((0, 3), (3, 3)).copy_from(&(-r.cross_matrix()));
    t.view_mut((3, 3), (3, 3)).fill_with_identity();
    t
}
