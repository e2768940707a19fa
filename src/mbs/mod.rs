//! Multi-body assembly: mass, damping and stiffness matrices of the machine at an axis position.
//!
//! Each free body has 6 DOF q = (x, y, z, a, b, c) at its centre of gravity c (small rotations);
//! each axis adds the rotor angle φ of its motor. A point p of a body moves by
//! u(p) = T(p)·q with T(p) = [I, −skew(p − c)].
//!
//! * A carriage is a spring/damper between the carriage point p of the moving body and the
//!   coincident point of the carrier, stiff across the rail (normal n, lateral l), free along it:
//!   K += Gᵀ k G with G = [T_moving(p), −T_carrier(p)] and k = k_n·nnᵀ + k_l·llᵀ.
//! * The ball screw is an axial spring between the nut point of the moving body and the screw,
//!   whose axial position is φ·h/(2π): δ = eᵀ(u_moving(p_nut) − u_carrier(p_nut))
//!   − (φ + eᵀ(θ_moving − θ_carrier))·h/(2π), K += k_ax·g gᵀ (right-hand thread, φ the rotor
//!   angle relative to the carrier): the screw force F on the nut comes with the torque
//!   −F·h/(2π) about e on the moving body and its reaction on the carrier. The drive force acts along the screw line, offset from the centre of gravity:
//!   accelerating the axis tilts the slide — the acceleration correlated error eij is about.
//! * Position dependence: at axis position s every body carried by the axis is shifted by
//!   σ·(s − s_ref)·e (σ = +1 tool side, −1 workpiece side, ISO 841), which moves the carriage
//!   contact points on the carrier and the nut on the screw (shaft stiffness E·A/l₁).

pub mod modal;

use crate::machine::Machine;
use nalgebra::{DMatrix, DVector, Matrix3, SMatrix, Vector3};

/// Errors of the assembly and of the support check.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MbsError {
    /// A pose with the wrong number of axes.
    #[error("{machine}: pose has {got} axis positions, the machine has {expected} axes")]
    PoseLength {
        /// Machine source.
        machine: String,
        /// Given.
        got: usize,
        /// Expected.
        expected: usize,
    },
    /// An axis position outside its stroke.
    #[error(
        "{machine}: axis {axis} position {position_m} m is outside the stroke [{min_m}, {max_m}] m"
    )]
    OutOfStroke {
        /// Machine source.
        machine: String,
        /// Axis name.
        axis: String,
        /// Position asked for.
        position_m: f64,
        /// Stroke minimum.
        min_m: f64,
        /// Stroke maximum.
        max_m: f64,
    },
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
    /// DOF names: `body.x` … `body.c` per free body, then `axis.motor` per axis.
    pub dofs: Vec<String>,
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

/// T(p) = [I, −skew(p − c)]: displacement of point p of a body with DOF at c.
fn point_map(p: &Vector3<f64>, c: &Vector3<f64>) -> SMatrix<f64, 3, 6> {
    let r = p - c;
    let mut t = SMatrix::<f64, 3, 6>::zeros();
    t.fixed_view_mut::<3, 3>(0, 0).fill_with_identity();
    t.fixed_view_mut::<3, 3>(0, 3)
        .copy_from(&(-r.cross_matrix()));
    t
}

/// One side of a two-point element: DOF offset and point map, or nothing for a fixed body.
type Port = Option<(usize, SMatrix<f64, 3, 6>)>;

/// Adds Gᵀ k G with G = [T_a, −T_b] for a 3×3 spring/damper matrix k.
fn add_point_element(target: &mut DMatrix<f64>, a: &Port, b: &Port, k: &Matrix3<f64>) {
    let sides = [(a, 1.0), (b, -1.0)];
    for (pi, si) in &sides {
        let Some((i, ti)) = pi else { continue };
        for (pj, sj) in &sides {
            let Some((j, tj)) = pj else { continue };
            let block = ti.transpose() * k * tj * (si * sj);
            let mut view = target.view_mut((*i, *j), (6, 6));
            view += block;
        }
    }
}

impl Model {
    /// Assembles M, D, K at axis position `pose_m` (m, machine axis order).
    pub fn assemble(machine: &Machine, pose_m: &[f64]) -> Result<Model, MbsError> {
        if pose_m.len() != machine.axes().len() {
            return Err(MbsError::PoseLength {
                machine: machine.source().to_string(),
                got: pose_m.len(),
                expected: machine.axes().len(),
            });
        }
        for (a, &s) in machine.axes().iter().zip(pose_m) {
            let [lo, hi] = a.stroke_m;
            if !(s.is_finite() && lo <= s && s <= hi) {
                return Err(MbsError::OutOfStroke {
                    machine: machine.source().to_string(),
                    axis: a.axis.to_string(),
                    position_m: s,
                    min_m: lo,
                    max_m: hi,
                });
            }
        }
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
        let mut body_dof = vec![None; nb];
        let mut dofs = Vec::new();
        for (b, body) in machine.bodies().iter().enumerate() {
            if !body.fixed {
                body_dof[b] = Some(dofs.len());
                for d in ["x", "y", "z", "a", "b", "c"] {
                    dofs.push(format!("{}.{d}", body.name));
                }
            }
        }
        let first_rotor = dofs.len();
        for a in machine.axes() {
            dofs.push(format!("{}.motor", a.axis));
        }
        let n = dofs.len();
        let cog: Vec<Vector3<f64>> = (0..nb)
            .map(|b| machine.bodies()[b].cog_m + shift[b])
            .collect();
        // A point of body b given at the reference position, at this pose.
        let port = |b: usize, p_ref: &Vector3<f64>| -> Port {
            body_dof[b].map(|i| (i, point_map(&(p_ref + shift[b]), &cog[b])))
        };
        // A point given on body `on`, seen as the coincident point of body `b`.
        let port_at = |b: usize, p: &Vector3<f64>| -> Port {
            body_dof[b].map(|i| (i, point_map(p, &cog[b])))
        };

        let mut mass = DMatrix::zeros(n, n);
        for (b, body) in machine.bodies().iter().enumerate() {
            if let Some(i) = body_dof[b] {
                for d in 0..3 {
                    mass[(i + d, i + d)] = body.mass_kg;
                }
                mass.view_mut((i + 3, i + 3), (3, 3))
                    .copy_from(&body.inertia_kg_m2);
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
            for rail in &g.rails {
                let nn = rail.normal * rail.normal.transpose();
                let ll = rail.lateral * rail.lateral.transpose();
                let k = nn * kn + ll * kl;
                let c = nn * g.damping_normal_n_s_per_m + ll * g.damping_lateral_n_s_per_m;
                for p_ref in &rail.carriages_m {
                    let p = p_ref + shift[a.moving];
                    let pm = port(a.moving, p_ref);
                    let pc = port_at(a.carrier, &p);
                    add_point_element(&mut stiffness, &pm, &pc, &k);
                    add_point_element(&mut damping, &pm, &pc, &c);
                }
            }
            // Screw: δ = eᵀ(u_m(p_nut) − u_c(p_nut)) − φ·h/(2π).
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
            let mut twist = SMatrix::<f64, 6, 1>::zeros();
            twist.fixed_rows_mut::<3>(3).copy_from(&(e * h));
            if let Some((i, t)) = port(a.moving, &d.nut_m) {
                gvec.rows_mut(i, 6).copy_from(&(t.transpose() * e - twist));
            }
            if let Some((i, t)) = port_at(a.carrier, &nut) {
                let mut rows = gvec.rows_mut(i, 6);
                rows -= t.transpose() * e - twist;
            }
            gvec[rotor] = -d.transmission_m_per_rad();
            stiffness.ger(k_ax, &gvec, &gvec, 1.0);
            damping.ger(d.damping_n_s_per_m, &gvec, &gvec, 1.0);
            mass[(rotor, rotor)] = d.rotor_inertia_kg_m2;
            damping[(rotor, rotor)] += d.friction_nm_s_per_rad;

            // Linear scale: σ·eᵀ(u_m(p_s) − u_c(p_s)), in axis coordinates.
            let sigma = a.side.sign();
            let mut scale = DVector::zeros(n);
            let ps = d.scale_m + shift[a.moving];
            if let Some((i, t)) = port(a.moving, &d.scale_m) {
                scale.rows_mut(i, 6).copy_from(&(t.transpose() * e * sigma));
            }
            if let Some((i, t)) = port_at(a.carrier, &ps) {
                let mut rows = scale.rows_mut(i, 6);
                rows -= t.transpose() * e * sigma;
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

        for j in machine.joints() {
            let p = j.point_m + shift[j.body];
            let k = Matrix3::from_diagonal(&j.stiffness_n_per_m);
            let c = Matrix3::from_diagonal(&j.damping_n_s_per_m);
            let pa = port_at(j.body, &p);
            let pb = port_at(j.other, &p);
            add_point_element(&mut stiffness, &pa, &pb, &k);
            add_point_element(&mut damping, &pa, &pb, &c);
        }
        if machine.rayleigh_beta_s() > 0.0 {
            damping += &stiffness * machine.rayleigh_beta_s();
        }

        let mut tcp = DMatrix::zeros(3, n);
        if let Some((i, t)) = port(machine.tcp().body, &machine.tcp().point_m) {
            tcp.view_mut((0, i), (3, 6)).copy_from(&t);
        }
        // The nest is set up under the tool at this circle centre: the point of the workpiece
        // body that coincides with the TCP at this pose (CONTRACT: x_ext_mm).
        let nest = machine.tcp().point_m + shift[machine.tcp().body];
        if let Some((i, t)) = port_at(machine.workpiece().body, &nest) {
            let mut v = tcp.view_mut((0, i), (3, 6));
            v -= t;
        }
        let mut nest_rotation = DMatrix::zeros(3, n);
        if let Some(i) = body_dof[machine.workpiece().body] {
            nest_rotation
                .view_mut((0, i + 3), (3, 3))
                .fill_with_identity();
        }
        Ok(Model {
            dofs,
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
        let mut dof = 0;
        for (b, body) in machine.bodies().iter().enumerate() {
            if body.fixed {
                continue;
            }
            if machine.is_carried_by(b, i) {
                for (d, e) in a.axis.unit().iter().enumerate() {
                    v[dof + d] = *e;
                }
            }
            dof += 6;
        }
        v[self.axes[i].rotor_dof] = 1.0 / machine.axes()[i].drive.transmission_m_per_rad();
        v
    }
}
