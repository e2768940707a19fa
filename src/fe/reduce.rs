//! Craig–Bampton reduction of an FE model to the coordinates of an elastic body in the
//! multi-body model.
//!
//! Interface: the stations of the attachments (6 DOF each, [`super::attach`]): W u = q stacks
//! their motions. With K_α = K + α Σ ŵŵᵀ (ŵ the rows of W scaled to unit length; K_α = K where
//! W u = 0, positive definite once the stations hold the body):
//! - constraint modes Ψ = K_α⁻¹ Wᵀ (W K_α⁻¹ Wᵀ)⁻¹: the least-energy shapes with W Ψ = I (for
//!   nodal stations the classic Ψ = [I; −K_ii⁻¹K_ib]);
//! - fixed-interface normal modes Φ: K φ = ω² M φ with W φ = 0, the lowest `modes` (or all below
//!   `cutoff_hz`), by shift-invert Lanczos ([`super::sparse`]).
//!
//! T = [Ψ Φ], M_r = TᵀMT, K_r = TᵀKT (DESIGN: reduction). Any static load applied through the
//! stations is reproduced exactly, and the six rigid-body motions lie in span T (Ψ W R = R).
//!
//! Body coordinates: the six rigid-body motions about the centre of gravity X_r = [W R; 0], checked
//! to carry no elastic force (‖K_r X_r‖), and the elastic free-free modes of (K_r, M_r) in the
//! M_r-orthogonal complement of X_r, mass-normalised. In them the body's mass matrix is
//! blockdiag(m I, J_cog, I) and its stiffness blockdiag(0, diag ω²). A stiffness factor c scales
//! K, so it leaves Ψ, Φ and the modes unchanged and scales ω² by c exactly.

use super::attach::{layout, Attachment, Layout, Resolved};
use super::sparse::{free_free_frequencies_hz, orthonormal, shift_invert, Factor};
use super::{mtx, sandwich, FeError, FeModel, MassProperties};
use faer::{Mat, MatRef, Side};
use nalgebra::{DMatrix, Matrix6, Matrix6xX, Vector3};
use serde::Serialize;
use std::time::Instant;

/// Fixed-interface modes are kept up to this multiple of `cutoff_hz`. Craig–Bampton's free-free
/// frequencies converge from above roughly as (f / f_kept)³ to (f / f_kept)⁴; the common rule of
/// 1.5–2 × the range of interest leaves errors of a few per cent at half the range on solids held
/// by RBE3 patches (measured on the test column), 4 × holds them to 0.1 % there (docs/fe.md).
pub const CUTOFF_MARGIN: f64 = 4.0;

/// How to reduce a body.
#[derive(Debug, Clone, PartialEq)]
pub struct ReductionSettings {
    /// Fixed-interface modes kept (used where `cutoff_hz` is `None`).
    pub modes: usize,
    /// Resolve the body's free-free modes up to this frequency instead, Hz: every fixed-interface
    /// mode below [`CUTOFF_MARGIN`] × `cutoff_hz` is kept.
    pub cutoff_hz: Option<f64>,
    /// RBE3 radius on solid (3-DOF) nodes, m (docs/fe.md `attach_radius_m`).
    pub attach_radius_m: Option<f64>,
    /// Reduce the interface to the six rigid-body motions plus this many characteristic
    /// constraint modes (the lowest modes of the interface's Guyan model), where the stations
    /// carry more DOFs than that (a rail of many stations on a solid). Static loads at the
    /// stations are then no longer exact: [`ReducedBody::full_free_frequencies_hz`] and docs/fe.md
    /// show the error.
    pub interface_modes: Option<usize>,
    /// Also compute the full model's free-free frequencies for comparison (a second sparse
    /// eigensolution of the whole model: for small and medium models).
    pub full_reference: bool,
}

impl Default for ReductionSettings {
    /// 20 modes, no radius, no interface reduction, no full-model reference.
    fn default() -> Self {
        ReductionSettings {
            modes: 20,
            cutoff_hz: None,
            attach_radius_m: None,
            interface_modes: None,
            full_reference: false,
        }
    }
}

/// A reduced elastic body: 6 rigid-body coordinates (x, y, z, a, b, c at the centre of gravity)
/// followed by the elastic modal coordinates η.
#[derive(Debug, Clone)]
pub struct ReducedBody {
    /// Mass, centre of gravity and inertia from the FE mass matrix.
    pub mass: MassProperties,
    /// ω² of the elastic free-free modes at stiffness factor 1, ascending, (rad/s)².
    pub eigenvalues: Vec<f64>,
    /// ω² of the kept fixed-interface modes, (rad/s)².
    pub fixed_interface_eigenvalues: Vec<f64>,
    /// The full model's elastic free-free frequencies (as many as `eigenvalues`), Hz, where
    /// asked for.
    pub full_free_frequencies_hz: Option<Vec<f64>>,
    /// Number of FE DOFs.
    pub dofs: usize,
    /// Wall time of the reduction (factorisation, eigensolution, projection), s.
    pub reduction_s: f64,
    /// Nonzeros of the Cholesky factor of the interface-held stiffness.
    pub factor_nnz: usize,
    /// The attachments as given.
    pub attachments: Vec<Attachment>,
    pub(crate) stations: Vec<super::Station>,
    resolved: Vec<Resolved>,
    /// Per station: its 6-DOF motion per body coordinate (6 × w).
    station_motion: Vec<Matrix6xX<f64>>,
    node_ids: Vec<u64>,
}

/// One attachment's nodes and weights at a position (for `eij fe`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StationSummary {
    /// The attachment's name.
    pub point: String,
    /// FE node numbers.
    pub nodes: Vec<u64>,
    /// Their weights.
    pub weights: Vec<f64>,
}

/// What `eij fe` prints (docs/fe.md keys).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FeSummary {
    /// The body's name.
    pub body: String,
    /// FE DOFs.
    pub dofs: usize,
    /// Interface DOFs (6 per station).
    pub interface_dofs: usize,
    /// Fixed-interface modes kept.
    pub modes: usize,
    /// Mass, kg.
    pub mass_kg: f64,
    /// Centre of gravity, m.
    pub cog_m: [f64; 3],
    /// Inertia about the centre of gravity, kg·m².
    pub inertia_kg_m2: [[f64; 3]; 3],
    /// Elastic free-free frequencies of the reduced body, Hz, ascending.
    pub free_frequencies_hz: Vec<f64>,
    /// The same of the full FE model (empty where not computed).
    pub full_free_frequencies_hz: Vec<f64>,
    /// The factor on the body's elastic stiffness both frequency lists hold at.
    pub stiffness_factor: f64,
    /// Interface coordinates kept: `interface_dofs`, or 6 + `interface_modes` where the interface
    /// was reduced.
    pub interface_coordinates: usize,
    /// Wall time of the reduction, s.
    pub reduction_s: f64,
    /// Every attachment at the reference position.
    pub attachments: Vec<StationSummary>,
}

fn fail(model: &FeModel, m: impl Into<String>) -> FeError {
    FeError::file(&model.source, m)
}

/// Reduces `model` for the given attachments (module doc). Errors: mass or stiffness not fit for
/// a free body, attachments that cannot be resolved or do not hold the body, an eigensolution
/// that does not converge, rigid-body motion with elastic force.
pub fn reduce(
    model: &FeModel,
    attachments: &[Attachment],
    settings: &ReductionSettings,
) -> Result<ReducedBody, FeError> {
    let start = Instant::now();
    let mass = model.mass_properties()?;
    model.check_free()?;
    let Layout { stations, resolved } = layout(model, attachments, settings.attach_radius_m)?;
    let n = model.n_dofs();
    let nb = 6 * stations.len();
    if nb == 0 {
        return Err(fail(
            model,
            "no attachments: a body needs at least one attached point",
        ));
    }
    // Wᵀ (n × nb) and K_α.
    let mut wt = Mat::<f64>::zeros(n, nb);
    for (j, st) in stations.iter().enumerate() {
        for &(r, row, v) in &st.w {
            wt[(row, 6 * j + r)] += v;
        }
    }
    let diag_k = (0..n)
        .map(|i| diagonal(&model.stiffness, i).abs())
        .sum::<f64>()
        / n as f64;
    let mut penalty = Vec::new();
    for (j, st) in stations.iter().enumerate() {
        for r in 0..6 {
            let entries: Vec<(usize, f64)> =
                st.w.iter()
                    .filter(|e| e.0 == r)
                    .map(|e| (e.1, wt[(e.1, 6 * j + r)]))
                    .collect();
            let norm2: f64 = entries.iter().map(|e| e.1 * e.1).sum();
            let alpha = diag_k / norm2;
            for &(a, va) in &entries {
                for &(b, vb) in &entries {
                    if a >= b {
                        penalty.push((a as u32, b as u32, alpha * va * vb));
                    }
                }
            }
        }
    }
    let penalty = mtx::from_lower_triplets(n, penalty);
    let k_alpha =
        faer::sparse::ops::binary_op(model.stiffness.as_ref(), penalty.as_ref(), |x, y| {
            x.copied().unwrap_or(0.0) + y.copied().unwrap_or(0.0)
        })
        .map_err(|e| fail(model, format!("out of memory: {e:?}")))?;
    drop(penalty);
    let factor = Factor::new(&k_alpha).map_err(|e| {
        fail(
            model,
            format!("stiffness with the attachments held: {e}: the attachments do not hold the body (or K is not positive semi-definite)"),
        )
    })?;
    drop(k_alpha);

    // Constraint modes Ψ = Pᵀ L⁻ᵀ Q R⁻ᵀ with L⁻¹ P Wᵀ = Q R.
    let mut y = wt.clone();
    factor.l_solve(y.as_mut());
    let (q, diag) = orthonormal(y.as_ref());
    let top = diag.iter().fold(0.0f64, |a, &d| a.max(d));
    if let Some(k) = diag.iter().position(|&d| !(d > 1e-10 * top)) {
        return Err(dependent_station(
            model,
            attachments,
            &stations,
            &resolved,
            k / 6,
        ));
    }
    let r = y.qr().R().to_owned();
    drop(y);
    let mut psi_t = q.transpose().to_owned();
    faer::linalg::triangular_solve::solve_upper_triangular_in_place(
        r.as_ref(),
        psi_t.as_mut(),
        faer::Par::Seq,
    );
    drop(q);
    let mut psi = psi_t.transpose().to_owned();
    drop(psi_t);
    factor.lt_solve(psi.as_mut());

    // Fixed-interface modes.
    let phi = fixed_interface_modes(model, &factor, wt.as_ref(), settings)?;
    let m = phi.eigenvalues.len();
    let factor_nnz = factor.nnz();
    drop(factor);

    // The rigid-body motions must lie in span Ψ: Ψ (W R) = R.
    let rc = model.rigid_modes(&mass.cog_m);
    let wr = wt.transpose() * &rc;
    drop(wt);
    let back = &psi * &wr;
    let miss = (&back - &rc).norm_max() / rc.norm_max();
    if !(miss < 1e-6) {
        return Err(fail(
            model,
            format!("the constraint modes miss the rigid-body motions by {miss:.1e}: the attachments do not hold the body"),
        ));
    }
    drop(back);

    // Interface reduction: the station motions q = V ξ, V = [W R, lowest characteristic
    // constraint modes of (ΨᵀKΨ, ΨᵀMΨ) beside the rigid-body motions].
    let v = match settings.interface_modes {
        Some(k) if 6 + k < nb => {
            let kb = sandwich(&model.stiffness, psi.as_ref());
            let mb = sandwich(&model.mass, psi.as_ref());
            let (_, cc) = complement_modes(model, mb.as_ref(), kb.as_ref(), wr.as_ref())?;
            let mut v = Mat::zeros(nb, 6 + k);
            v.as_mut().subcols_mut(0, 6).copy_from(&wr);
            v.as_mut().subcols_mut(6, k).copy_from(cc.subcols(0, k));
            v
        }
        _ => Mat::identity(nb, nb),
    };
    let c = v.ncols();
    let mut t = Mat::zeros(n, c + m);
    t.as_mut().subcols_mut(0, c).copy_from(&psi * &v);
    t.as_mut().subcols_mut(c, m).copy_from(&phi.vectors);
    drop(psi);
    let mr = sandwich(&model.mass, t.as_ref());
    let kr = sandwich(&model.stiffness, t.as_ref());
    drop(t);
    // The rigid-body motions in CB coordinates: ξ with V ξ = W R.
    let mut xr = Mat::zeros(c + m, 6);
    if c == nb {
        xr.as_mut().subrows_mut(0, nb).copy_from(&wr);
    } else {
        xr.as_mut()
            .subrows_mut(0, 6)
            .copy_from(Mat::<f64>::identity(6, 6));
    }
    let basis = body_basis(model, mr.as_ref(), kr.as_ref(), xr.as_ref())?;
    let stations_q = &v * basis.vectors.subrows(0, c);
    let station_motion = (0..stations.len())
        .map(|j| Matrix6xX::from_fn(stations_q.ncols(), |r, col| stations_q[(6 * j + r, col)]))
        .collect();
    let reduction_s = start.elapsed().as_secs_f64();

    let mut body = ReducedBody {
        mass,
        eigenvalues: basis.eigenvalues,
        fixed_interface_eigenvalues: phi.eigenvalues,
        full_free_frequencies_hz: None,
        dofs: n,
        reduction_s,
        factor_nnz,
        attachments: attachments.to_vec(),
        stations,
        resolved,
        station_motion,
        node_ids: model.nodes.iter().map(|p| p.id).collect(),
    };
    if settings.full_reference {
        body.add_full_reference(model)?;
    }
    Ok(body)
}

/// The error for station `j`, whose motion the stations before it already fix (QR column
/// of W K⁻¹ Wᵀ that vanishes): which attachments use it, on which nodes.
fn dependent_station(
    model: &FeModel,
    attachments: &[Attachment],
    stations: &[super::Station],
    resolved: &[Resolved],
    j: usize,
) -> FeError {
    let users: Vec<&str> = attachments
        .iter()
        .zip(resolved)
        .filter(|(_, r)| r.stations.iter().any(|s| s.1 == j))
        .map(|(a, _)| a.name.as_str())
        .collect();
    let st = &stations[j];
    let nodes: Vec<String> = st
        .nodes
        .iter()
        .map(|&i| model.nodes[i].id.to_string())
        .collect();
    let c = st.reference_m;
    fail(
        model,
        format!(
            "the attachments' stations are not independent: the station of {} at ({:.4}, {:.4}, {:.4}) m \
             (nodes {}) moves only as the stations of other attachments make it (patches that share \
             most of their nodes: a smaller attach_radius_m, points further apart, or a finer mesh there)",
            users.join(", "),
            c.x,
            c.y,
            c.z,
            nodes.join(" ")
        ),
    )
}

fn diagonal(a: &super::SparseMatrix, i: usize) -> f64 {
    a.row_idx_of_col(i)
        .zip(a.val_of_col(i))
        .find(|(r, _)| *r == i)
        .map(|(_, v)| *v)
        .unwrap_or(0.0)
}

fn fixed_interface_modes(
    model: &FeModel,
    factor: &Factor,
    wt: MatRef<'_, f64>,
    settings: &ReductionSettings,
) -> Result<super::Modes, FeError> {
    let free = model.n_dofs() - wt.ncols();
    let run = |count: usize| {
        shift_invert(factor, &model.mass, wt, 0.0, count).map_err(|e| fail(model, e))
    };
    let Some(cutoff_hz) = settings.cutoff_hz else {
        return run(settings.modes);
    };
    if !(cutoff_hz > 0.0 && cutoff_hz.is_finite()) {
        return Err(fail(
            model,
            format!("cutoff_hz = {cutoff_hz}: must be a positive number"),
        ));
    }
    let cutoff = CUTOFF_MARGIN * cutoff_hz;
    let mut count = 16usize;
    loop {
        let modes = run(count.min(free))?;
        let f = modes.frequencies_hz();
        let below = f.iter().filter(|&&x| x <= cutoff).count();
        if below < modes.eigenvalues.len() || count >= free {
            let mut keep = modes;
            keep.eigenvalues.truncate(below);
            keep.vectors = keep.vectors.subcols(0, below).to_owned();
            return Ok(keep);
        }
        if count >= 1000 {
            return Err(fail(
                model,
                format!("more than 1000 fixed-interface modes below {CUTOFF_MARGIN} × cutoff_hz = {cutoff} Hz"),
            ));
        }
        count *= 2;
    }
}

struct Basis {
    /// ω² of the elastic modes.
    eigenvalues: Vec<f64>,
    /// CB coordinates per body coordinate: [X_r, X_e], size × (6 + elastic).
    vectors: Mat<f64>,
}

/// Rigid-body check and the elastic free-free modes in the M_r-orthogonal complement of X_r.
fn body_basis(
    model: &FeModel,
    mr: MatRef<'_, f64>,
    kr: MatRef<'_, f64>,
    xr: MatRef<'_, f64>,
) -> Result<Basis, FeError> {
    let size = mr.nrows();
    let kx = kr * xr;
    let scale = kr.norm_max() * xr.norm_max() * (size as f64).sqrt();
    let force = kx.norm_max() / scale;
    if !(force < 1e-8) {
        return Err(fail(
            model,
            format!("rigid-body motion of the reduced body produces elastic forces ({force:.1e}): fewer than 6 rigid-body modes"),
        ));
    }
    let (lambda, xe) = complement_modes(model, mr, kr, xr)?;
    let mut vectors = Mat::zeros(size, size);
    vectors.as_mut().subcols_mut(0, 6).copy_from(xr);
    vectors.as_mut().subcols_mut(6, size - 6).copy_from(&xe);
    Ok(Basis {
        eigenvalues: lambda,
        vectors,
    })
}

/// The modes of (K_r, M_r) in the M_r-orthogonal complement of the columns of `xr`: ω²
/// ascending (all positive, else a mechanism) and the mass-normalised vectors.
fn complement_modes(
    model: &FeModel,
    mr: MatRef<'_, f64>,
    kr: MatRef<'_, f64>,
    xr: MatRef<'_, f64>,
) -> Result<(Vec<f64>, Mat<f64>), FeError> {
    let size = mr.nrows();
    let fixed = xr.ncols();
    let mx = mr * xr;
    let full_q = mx.qr().compute_Q();
    let q2 = full_q.subcols(fixed, size - fixed);
    let ke = q2.transpose() * kr * q2;
    let me = q2.transpose() * mr * q2;
    let ke = (&ke + ke.transpose()) * faer::Scale(0.5);
    let me = (&me + me.transpose()) * faer::Scale(0.5);
    let llt = me.llt(Side::Lower).map_err(|_| {
        fail(
            model,
            "the reduced mass matrix is not positive definite (massless DOFs at the interface?)",
        )
    })?;
    let l = llt.L();
    // A = L⁻¹ Ke L⁻ᵀ.
    let mut a = ke.clone();
    faer::linalg::triangular_solve::solve_lower_triangular_in_place(l, a.as_mut(), faer::Par::Seq);
    let mut at = a.transpose().to_owned();
    faer::linalg::triangular_solve::solve_lower_triangular_in_place(l, at.as_mut(), faer::Par::Seq);
    let a = (&at + at.transpose()) * faer::Scale(0.5);
    let evd = a
        .self_adjoint_eigen(Side::Lower)
        .map_err(|_| fail(model, "the reduced eigenproblem did not converge"))?;
    let lambda: Vec<f64> = (0..size - fixed).map(|i| evd.S()[i]).collect();
    let top = lambda.iter().fold(0.0f64, |x, &v| x.max(v.abs()));
    if lambda.first().is_some_and(|&l| !(l > 1e-12 * top)) {
        return Err(fail(
            model,
            format!(
                "the reduced body has more than 6 rigid-body modes (elastic ω² = {:.3e}): a mechanism, or a part not connected",
                lambda[0]
            ),
        ));
    }
    // X_e = Q₂ L⁻ᵀ V.
    let mut v = evd.U().to_owned();
    faer::linalg::triangular_solve::solve_upper_triangular_in_place(
        l.transpose(),
        v.as_mut(),
        faer::Par::Seq,
    );
    let xe = q2 * &v;
    Ok((lambda, xe))
}

/// T(d): a station's motion (u, θ) carried to a point at offset d: (u + θ × d, θ).
fn lever(d: &Vector3<f64>) -> Matrix6<f64> {
    let mut t = Matrix6::identity();
    t.fixed_view_mut::<3, 3>(0, 3)
        .copy_from(&(-d.cross_matrix()));
    t
}

impl ReducedBody {
    /// Number of body coordinates: 6 rigid + elastic.
    pub fn width(&self) -> usize {
        6 + self.eigenvalues.len()
    }

    /// Number of elastic coordinates.
    pub fn elastic_modes(&self) -> usize {
        self.eigenvalues.len()
    }

    /// Interface DOFs: 6 per station.
    pub fn interface_dofs(&self) -> usize {
        6 * self.stations.len()
    }

    /// Interface coordinates kept: the interface DOFs, or 6 + `interface_modes` where the
    /// interface was reduced.
    pub fn interface_coordinates(&self) -> usize {
        self.width() - self.fixed_interface_eigenvalues.len()
    }

    /// Elastic free-free frequencies at stiffness factor `c`, Hz: √(c ω²)/2π.
    pub fn frequencies_hz(&self, stiffness_factor: f64) -> Vec<f64> {
        self.eigenvalues
            .iter()
            .map(|l| (stiffness_factor * l).max(0.0).sqrt() / std::f64::consts::TAU)
            .collect()
    }

    /// Mass matrix in body coordinates: blockdiag(m I, J_cog, I).
    pub fn mass_matrix(&self) -> DMatrix<f64> {
        let w = self.width();
        let mut m = DMatrix::identity(w, w);
        for k in 0..3 {
            m[(k, k)] = self.mass.mass_kg;
        }
        m.view_mut((3, 3), (3, 3))
            .copy_from(&self.mass.inertia_kg_m2);
        m
    }

    /// Stiffness matrix in body coordinates at stiffness factor `c`: blockdiag(0, c·diag ω²).
    pub fn stiffness_matrix(&self, stiffness_factor: f64) -> DMatrix<f64> {
        let w = self.width();
        let mut k = DMatrix::zeros(w, w);
        for (i, l) in self.eigenvalues.iter().enumerate() {
            k[(6 + i, 6 + i)] = stiffness_factor * l;
        }
        k
    }

    /// Translation and rotation of attachment `index` at travel position `s` m (ignored for a
    /// fixed point) per body coordinate: 6 × [`width`](Self::width). Rigid part: exactly
    /// [I, −skew(p − cog); 0, I].
    pub fn point_motion(&self, index: usize, s: f64) -> Matrix6xX<f64> {
        let p = self.attachments[index].point_at(s);
        let mut g = Matrix6xX::zeros(self.width());
        for (station, weight) in self.resolved[index].blend(s) {
            if weight != 0.0 {
                let st = &self.stations[station];
                g += weight * lever(&(p - st.reference_m)) * &self.station_motion[station];
            }
        }
        g
    }

    /// The nodes and weights attachment `index` uses at position `s`.
    pub fn attachment_nodes(&self, index: usize, s: f64) -> StationSummary {
        let mut nodes: Vec<(u64, f64)> = Vec::new();
        for (station, weight) in self.resolved[index].blend(s) {
            if weight == 0.0 {
                continue;
            }
            let st = &self.stations[station];
            for (&i, &w) in st.nodes.iter().zip(&st.weights) {
                let id = self.node_ids[i];
                match nodes.iter_mut().find(|x| x.0 == id) {
                    Some(x) => x.1 += weight * w,
                    None => nodes.push((id, weight * w)),
                }
            }
        }
        StationSummary {
            point: self.attachments[index].name.clone(),
            nodes: nodes.iter().map(|x| x.0).collect(),
            weights: nodes.iter().map(|x| x.1).collect(),
        }
    }

    /// Computes the full model's elastic free-free frequencies (as many as the reduced body
    /// has, [`free_free_frequencies_hz`]) for comparison, where not yet done: `model` must be the
    /// one this body was reduced from. The shift lies at a tenth of the first reduced frequency,
    /// below the full model's first (Craig–Bampton's frequencies are upper bounds).
    pub fn add_full_reference(&mut self, model: &FeModel) -> Result<(), FeError> {
        if self.full_free_frequencies_hz.is_some() {
            return Ok(());
        }
        if model.n_dofs() != self.dofs {
            return Err(fail(
                model,
                format!(
                    "the model has {} DOFs, the reduced body was made from {}",
                    model.n_dofs(),
                    self.dofs
                ),
            ));
        }
        let full = match self.eigenvalues.first() {
            None => Vec::new(),
            Some(first) => free_free_frequencies_hz(
                model,
                self.eigenvalues.len(),
                0.1 * first.sqrt() / std::f64::consts::TAU,
            )?,
        };
        self.full_free_frequencies_hz = Some(full);
        Ok(())
    }

    /// The `eij fe` summary, attachments at the positions `s` (one per attachment; travelling
    /// ones at their reference position), frequencies (reduced and full alike) at the stiffness
    /// factor `c`: ω² scales by c, so f by √c.
    pub fn summary(&self, body: &str, positions: &[f64], stiffness_factor: f64) -> FeSummary {
        let j = self.mass.inertia_kg_m2;
        let root = stiffness_factor.max(0.0).sqrt();
        FeSummary {
            body: body.to_string(),
            dofs: self.dofs,
            interface_dofs: self.interface_dofs(),
            modes: self.fixed_interface_eigenvalues.len(),
            mass_kg: self.mass.mass_kg,
            cog_m: self.mass.cog_m.into(),
            inertia_kg_m2: std::array::from_fn(|r| std::array::from_fn(|c| j[(r, c)])),
            free_frequencies_hz: self.frequencies_hz(stiffness_factor),
            full_free_frequencies_hz: self
                .full_free_frequencies_hz
                .iter()
                .flatten()
                .map(|f| f * root)
                .collect(),
            stiffness_factor,
            interface_coordinates: self.interface_coordinates(),
            reduction_s: self.reduction_s,
            attachments: (0..self.attachments.len())
                .map(|i| self.attachment_nodes(i, positions.get(i).copied().unwrap_or(0.0)))
                .collect(),
        }
    }
}
