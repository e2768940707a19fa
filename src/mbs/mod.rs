//! Multi-body assembly: mass, damping and stiffness matrices of the machine at an axis position.
//!
//! Each free body has its coordinates ([`crate::machine::body`]): a rigid body the six
//! q = (x, y, z, a, b, c) at its centre of gravity c (small rotations), an elastic body those and
//! its elastic coordinates; each axis adds the rotor angle φ of its motor. The point where
//! something attaches moves by u(p) = T(p)·q, with T(p) = [I, −skew(p − c)] on a rigid body; the
//! assembly below only asks each body for T (and the rotation rows R), never for its kind.
//!
//! * A carriage is a spring/damper between the carriage point p of the moving body and the
//!   coincident point of the carrier, stiff across the rail (normal n, lateral l), free along it:
//!   K += Gᵀ k G with G = [T_moving(p), −T_carrier(p)] and k = k_n·nnᵀ + k_l·llᵀ.
//! * The ball screw is an axial spring between the nut point of the moving body and the screw,
//!   whose axial position is φ·h/(2π): δ = eᵀ(u_moving(p_nut) − u_carrier(p_nut))
//!   − (φ + eᵀ(θ_moving − θ_carrier))·h/(2π), K += k_ax·g gᵀ (right-hand thread, φ the rotor
//!   angle relative to the carrier): the screw force F on the nut comes with the torque
//!   −F·h/(2π) about e on the moving body and its reaction on the carrier. The rotor (inertia J)
//!   spins at φ̇ + eᵀω_carrier, its stator being on the carrier: M += J·s sᵀ over (φ, carrier). The drive force acts along the screw line, offset from the centre of gravity:
//!   accelerating the axis tilts the slide — the acceleration correlated error eij is about.
//! * Position dependence: at axis position s every body carried by the axis is shifted by
//!   σ·(s − s_ref)·e (σ = +1 tool side, −1 workpiece side, ISO 841), which moves the carriage
//!   contact points on the carrier and the nut on the screw (shaft stiffness E·A/l₁).
//! * An elastic body adds its reduced stiffness and modal damping to its own block (not scaled
//!   by the Rayleigh β, which is for the joints and guideways).

pub mod modal;

use crate::machine::{Machine, Pose, Site};
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

/// Errors of the assembly and of the support check.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MbsError {
    /// The structure has rigid-body modes beyond the one per drive: some body is not supported.
    #[error("{machine}: the guideways and joints cannot support the structure: {count} unsupported motion(s), dominated by DOF {dof} (check the carriage and joint arrangement)")]
    Unsupported {
        /// Machine source.
        machine: String,
        /// Number of extra rigid-body modes.
        count: usize,
        /// Dominant DOF of the first of them.
        dof: String,
    },
    /// An elastic body has no attachment for something that acts on it.
    #[error("{machine}: body '{body}' has no attachment for {site}")]
    Attachment {
        /// Machine source.
        machine: String,
        /// Body name.
        body: String,
        /// What attaches (`z.carriage[0]`).
        site: String,
    },
    /// The eigen-solver failed.
    #[error("{machine}: modal analysis failed: {reason}")]
    Eigen {
        /// Machine source.
        machine: String,
        /// Why.
        reason: String,
    },
}

/// The measurement and actuation ports of one axis in the assembled model.
#[derive(Debug, Clone, PartialEq)]
pub struct AxisPorts {
    /// Linear-scale reading in axis coordinates (ISO 841), m: `scale · q`.
    pub scale: DVector<f64>,
    /// Motor-encoder reading converted to axis coordinates, m: `encoder · q`.
    pub encoder: DVector<f64>,
    /// Index of the rotor-angle DOF (the motor torque acts on it).
    pub rotor_dof: usize,
    /// Rotor angle per metre of axis motion, rad/m: σ·2π/h.
    pub rad_per_m: f64,
    /// Inertia of everything the motor accelerates, referred to the rotor:
    /// J_rotor + m_moved·(h/2π)², kg·m² (for the acceleration feed-forward).
    pub inertia_eq_kg_m2: f64,
}

/// The assembled linear model M q̈ + D q̇ + K q = f at one axis position.
#[derive(Debug, Clone, PartialEq)]
pub struct Model {
    /// DOF names: `body.x` … `body.c` per free body (then `body.mode1` … for an elastic
    /// one), then `axis.motor` per axis.
    pub dofs: Vec<String>,
    /// Per body (machine order), the index of its first coordinate; `None` for a fixed body.
    pub body_dofs: Vec<Option<usize>>,
    /// Mass matrix, SI.
    pub mass: DMatrix<f64>,
    /// Damping matrix, SI.
    pub damping: DMatrix<f64>,
    /// Stiffness matrix, SI.
    pub stiffness: DMatrix<f64>,
    /// Per axis (machine order).
    pub axes: Vec<AxisPorts>,
    /// TCP displacement relative to the workpiece point in machine coordinates: `tcp · q` (3 × n).
    /// The workpiece point is the point of the workpiece body under the TCP at this pose.
    pub tcp: DMatrix<f64>,
    /// Rotation of the workpiece body, rad: `nest_rotation · q` (3 × n; zero if it is fixed).
    /// Where the TCP has moved by Δr relative to the workpiece since this pose (a long move),
    /// the point under it has moved with it, and the deviation there is
    /// `tcp · q + Δr × (nest_rotation · q)`.
    pub nest_rotation: DMatrix<f64>,
    /// Axis positions of this assembly, m.
    pub pose_m: Vec<f64>,
    /// Machine source, for messages.
    pub machine: String,
}

/// One side of a two-point element: the body's first coordinate and the 6 × w motion of the
/// point ([`crate::machine::Body::point_motion`]), or nothing for a fixed body.
type Port = Option<(usize, DMatrix<f64>)>;

/// Adds Gᵀ k G with G = [T_a, −T_b] for a 3×3 spring/damper matrix k, T the translation rows
/// of each side's point motion.
fn add_point_element(target: &mut DMatrix<f64>, a: &Port, b: &Port, k: &Matrix3<f64>) {
    let sides = [(a, 1.0), (b, -1.0)];
    for (pi, si) in &sides {
        let Some((i, ti)) = pi else { continue };
        let ti = ti.rows(0, 3);
        for (pj, sj) in &sides {
            let Some((j, tj)) = pj else { continue };
            let tj = tj.rows(0, 3);
            let block = ti.transpose() * k * tj * (si * sj);
            let mut view = target.view_mut((*i, *j), block.shape());
            view += block;
        }
    }
}

/// The generalised force of a unit axial drive force at a point with motion `t` (6 × w):
/// Tᵀe for the force along e plus, for a right-hand thread of h = lead/(2π) m/rad, the torque
/// −h·e that comes with it, −h·Rᵀe (R the rotation rows).
fn screw_force(t: &DMatrix<f64>, e: &Vector3<f64>, h: f64) -> DVector<f64> {
    let twist = t.rows(3, 3).transpose() * e * h;
    t.rows(0, 3).transpose() * e - twist
}

impl Model {
    /// Assembles M, D, K at the axis positions `pose` (checked against the machine's axes and
    /// strokes when the pose was made).
    pub fn assemble(machine: &Machine, pose: &Pose) -> Result<Model, MbsError> {
        let pose_m: &[f64] = pose;
        let nb = machine.bodies().len();
        // Shift of every body at this pose.
        let shift: Vec<Vector3<f64>> = (0..nb)
            .map(|b| {
                machine
                    .axes()
                    .iter()
                    .enumerate()
                    .filter(|(ai, _)| machine.is_carried_by(b, *ai))
                    .map(|(ai, a)| a.direction() * (a.side.sign() * (pose_m[ai] - a.reference_m)))
                    .sum()
            })
            .collect();
        let mut body_dofs = vec![None; nb];
        let mut dofs = Vec::new();
        for (b, body) in machine.bodies().iter().enumerate() {
            if body.width() > 0 {
                body_dofs[b] = Some(dofs.len());
                for d in body.coordinate_names() {
                    dofs.push(format!("{}.{d}", body.name));
                }
            }
        }
        let first_rotor = dofs.len();
        for a in machine.axes() {
            dofs.push(format!("{}.motor", a.axis));
        }
        let n = dofs.len();
        // Where `site` on body b lies at this pose (machine coordinates `p`): its motion.
        let port = |b: usize, site: Site, p: &Vector3<f64>| -> Result<Port, MbsError> {
            let Some(i) = body_dofs[b] else {
                return Ok(None);
            };
            let body = &machine.bodies()[b];
            match body.point_motion(site, p, &shift[b]) {
                Some(t) => Ok(Some((i, t))),
                None => Err(MbsError::Attachment {
                    machine: machine.source().to_string(),
                    body: body.name.clone(),
                    site: site.to_string(),
                }),
            }
        };

        let mut mass = DMatrix::zeros(n, n);
        for (b, body) in machine.bodies().iter().enumerate() {
            if let Some(i) = body_dofs[b] {
                let m = body.mass_matrix();
                mass.view_mut((i, i), m.shape()).copy_from(&m);
            }
        }
        let mut stiffness = DMatrix::zeros(n, n);
        let mut damping = DMatrix::zeros(n, n);
        let mut ports = Vec::with_capacity(machine.axes().len());

        for (ai, a) in machine.axes().iter().enumerate() {
            let e = a.direction();
            let g = &a.guideway;
            let kn = g.normal_n_per_m * g.reduction_normal;
            let kl = g.lateral_n_per_m * g.reduction_lateral;
            let mut index = 0;
            for rail in &g.rails {
                let nn = rail.normal * rail.normal.transpose();
                let ll = rail.lateral * rail.lateral.transpose();
                let k = nn * kn + ll * kl;
                let c = nn * g.damping_normal_n_s_per_m + ll * g.damping_lateral_n_s_per_m;
                for p_ref in &rail.carriages_m {
                    let site = Site::Carriage {
                        axis: a.axis,
                        index,
                    };
                    index += 1;
                    // The carriage and the point of the carrier's rail under it.
                    let p = p_ref + shift[a.moving];
                    let pm = port(a.moving, site, &p)?;
                    let pc = port(a.carrier, site, &p)?;
                    add_point_element(&mut stiffness, &pm, &pc, &k);
                    add_point_element(&mut damping, &pm, &pc, &c);
                }
            }
            // Screw: δ = eᵀ(u_m(p_nut) − u_c(p_nut)) − (φ + eᵀ(θ_m − θ_c))·h/(2π).
            let d = &a.drive;
            let nut = d.nut_m + shift[a.moving];
            let bearing = d.bearing_m + shift[a.carrier];
            let l1 = e.dot(&(nut - bearing)).abs();
            let k_ax = d.axial_stiffness_n_per_m(l1);
            let rotor = first_rotor + ai;
            let mut gvec = DVector::zeros(n);
            // Right-hand thread: turning the nut by θ about e relative to the screw moves it by
            // θ·h/(2π) along e, so the spring force F on the nut comes with the torque −F·h/(2π)·e,
            // and its reaction acts on the carrier (screw bearing and motor stator).
            let h = d.transmission_m_per_rad();
            if let Some((i, t)) = port(a.moving, Site::Nut(a.axis), &nut)? {
                gvec.rows_mut(i, t.ncols())
                    .copy_from(&screw_force(&t, &e, h));
            }
            // φ is measured against the stator on the carrier, so the rotor spins at
            // φ̇ + eᵀω_carrier: kinetic energy J(φ̇ + eᵀω_c)²/2, M += J·s sᵀ with s the unit on φ
            // plus Rᵀe on the carrier (its rotation about the screw axis at the motor).
            let mut spin = DVector::zeros(n);
            spin[rotor] = 1.0;
            if let Some((i, t)) = port(a.carrier, Site::Nut(a.axis), &nut)? {
                let mut rows = gvec.rows_mut(i, t.ncols());
                rows -= screw_force(&t, &e, h);
                spin.rows_mut(i, t.ncols())
                    .copy_from(&(t.rows(3, 3).transpose() * e));
            }
            gvec[rotor] = -d.transmission_m_per_rad();
            stiffness.ger(k_ax, &gvec, &gvec, 1.0);
            damping.ger(d.damping_n_s_per_m, &gvec, &gvec, 1.0);
            mass.ger(d.rotor_inertia_kg_m2, &spin, &spin, 1.0);
            // Friction acts on the rotor's speed relative to its stator, φ̇.
            damping[(rotor, rotor)] += d.friction_nm_s_per_rad;

            // Linear scale: σ·eᵀ(u_m(p_s) − u_c(p_s)), in axis coordinates.
            let sigma = a.side.sign();
            let mut scale = DVector::zeros(n);
            let ps = d.scale_m + shift[a.moving];
            if let Some((i, t)) = port(a.moving, Site::Scale(a.axis), &ps)? {
                scale
                    .rows_mut(i, t.ncols())
                    .copy_from(&(t.rows(0, 3).transpose() * e * sigma));
            }
            if let Some((i, t)) = port(a.carrier, Site::Scale(a.axis), &ps)? {
                let mut rows = scale.rows_mut(i, t.ncols());
                rows -= t.rows(0, 3).transpose() * e * sigma;
            }
            let mut encoder = DVector::zeros(n);
            encoder[rotor] = sigma * d.transmission_m_per_rad();
            ports.push(AxisPorts {
                scale,
                encoder,
                rotor_dof: rotor,
                rad_per_m: sigma / h,
                inertia_eq_kg_m2: d.rotor_inertia_kg_m2 + machine.moved_mass_kg(ai) * h * h,
            });
        }

        for (ji, j) in machine.joints().iter().enumerate() {
            let p = j.point_m + shift[j.body];
            let k = Matrix3::from_diagonal(&j.stiffness_n_per_m);
            let c = Matrix3::from_diagonal(&j.damping_n_s_per_m);
            let pa = port(j.body, Site::Joint(ji), &p)?;
            let pb = port(j.other, Site::Joint(ji), &p)?;
            add_point_element(&mut stiffness, &pa, &pb, &k);
            add_point_element(&mut damping, &pa, &pb, &c);
        }
        if machine.rayleigh_beta_s() > 0.0 {
            damping += &stiffness * machine.rayleigh_beta_s();
        }
        // The bodies' own elastic stiffness and modal damping (after the Rayleigh term: their
        // damping is given as a modal ratio of their own).
        for (b, body) in machine.bodies().iter().enumerate() {
            if let (Some(i), Some((k, c))) = (body_dofs[b], body.elastic_matrices()) {
                let mut view = stiffness.view_mut((i, i), k.shape());
                view += k;
                let mut view = damping.view_mut((i, i), c.shape());
                view += c;
            }
        }

        let mut tcp = DMatrix::zeros(3, n);
        let tcp_point = machine.tcp().point_m + shift[machine.tcp().body];
        if let Some((i, t)) = port(machine.tcp().body, Site::Tcp, &tcp_point)? {
            tcp.view_mut((0, i), (3, t.ncols()))
                .copy_from(&t.rows(0, 3));
        }
        // The nest is set up under the tool at this circle centre: the point of the workpiece
        // body that coincides with the TCP at this pose (docs/commands.md: x_ext_mm).
        let mut nest_rotation = DMatrix::zeros(3, n);
        if let Some((i, t)) = port(machine.workpiece().body, Site::Workpiece, &tcp_point)? {
            let mut v = tcp.view_mut((0, i), (3, t.ncols()));
            v -= t.rows(0, 3);
            nest_rotation
                .view_mut((0, i), (3, t.ncols()))
                .copy_from(&t.rows(3, 3));
        }
        Ok(Model {
            dofs,
            body_dofs,
            mass,
            damping,
            stiffness,
            axes: ports,
            tcp,
            nest_rotation,
            pose_m: pose_m.to_vec(),
            machine: machine.source().to_string(),
        })
    }

    /// Number of DOF.
    pub fn n_dof(&self) -> usize {
        self.dofs.len()
    }

    /// The rigid-body motion of axis `i`: every body it carries translates by +1 m along the
    /// axis in the physical sense σ·e and the rotor turns with it; K·v = 0 for a supported
    /// structure.
    pub fn drive_mode(&self, machine: &Machine, i: usize) -> DVector<f64> {
        let a = &machine.axes()[i];
        let mut v = DVector::zeros(self.n_dof());
        let none = Vector3::zeros();
        for (b, body) in machine.bodies().iter().enumerate() {
            if let Some(first) = self.body_dofs[b] {
                if machine.is_carried_by(b, i) {
                    let q = body.rigid_coordinates(&a.direction(), &none);
                    v.rows_mut(first, q.len()).copy_from(&q);
                }
            }
        }
        v[self.axes[i].rotor_dof] = 1.0 / machine.axes()[i].drive.transmission_m_per_rad();
        v
    }
}
