//! Elastic bodies from finite-element (FE) models: import, beam generation, and Craig–Bampton
//! reduction to the coordinates a multi-body model uses.
//!
//! An FE model ([`FeModel`]) is a sparse symmetric mass matrix M and stiffness matrix K with a DOF
//! map (matrix row → node and direction, 3-DOF solid nodes and 6-DOF beam/shell nodes mixed) and
//! the node coordinates. It comes from files an FE program exported ([`FeModel::from_files`]:
//! Matrix Market matrices, `node,dof` and `node,x_m,y_m,z_m` CSV), from a 3D Timoshenko beam
//! ([`FeModel::beam`], [`Beam`]) or from a block of hexahedral solid elements
//! ([`FeModel::hex8_block`], for tests, benchmarks and examples).
//!
//! [`reduce`] turns it into a [`ReducedBody`]: the 6 rigid-body coordinates (translation and
//! rotation at the centre of gravity) plus mass-normalised elastic free-free modes of the
//! Craig–Bampton model, so that the body's mass matrix is blockdiag(rigid mass and inertia, I) and
//! its stiffness blockdiag(0, diag ω²). Points attached to the body ([`Attachment`]) move with a
//! 6 × w matrix ([`ReducedBody::point_motion`]); travelling points (carriages on a rail) blend the
//! two stations that bracket them, continuous along the travel.
//!
//! Everything on the FE side is sparse (faer's supernodal Cholesky, shift-invert restarted
//! Lanczos from faer's matrix-free eigensolver); only the reduced matrices are dense.

// `!(x > limit)` is meant: a NaN must fail every check, which `x <= limit` would let through.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod attach;
mod beam;
mod files;
mod hex8;
pub mod mtx;
mod reduce;
mod sparse;
mod warning;

pub use attach::{Attachment, AttachmentKind, Station};
pub use beam::Beam;
pub use hex8::Hex8Block;
pub use reduce::{
    reduce, FeSummary, ReducedBody, ReductionSettings, StationSummary, CUTOFF_MARGIN,
};
pub use sparse::{free_free_frequencies_hz, lowest_modes, Modes};
pub use warning::{Warning, FIRST_MODE_OFF};

use faer::sparse::SparseColMat;
use nalgebra::{Matrix3, Matrix6, Vector3};

/// Sparse symmetric matrix, both triangles stored (compressed columns).
pub type SparseMatrix = SparseColMat<usize, f64>;

/// An FE model that cannot be read or reduced: where, and what is wrong, in one line.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FeError {
    /// A file, at a line.
    #[error("{file}: line {line}: {message}")]
    Line {
        /// The file as given.
        file: String,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A file as a whole.
    #[error("{file}: {message}")]
    File {
        /// The file as given (or the model's source, e.g. `beam`).
        file: String,
        /// What is wrong.
        message: String,
    },
}

impl FeError {
    pub(crate) fn line(file: &str, line: usize, message: impl Into<String>) -> FeError {
        FeError::Line {
            file: file.to_string(),
            line,
            message: message.into(),
        }
    }
    pub(crate) fn file(file: &str, message: impl Into<String>) -> FeError {
        FeError::File {
            file: file.to_string(),
            message: message.into(),
        }
    }
}

/// Direction of one nodal DOF: translations `ux uy uz`, rotations `rx ry rz`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum DofKind {
    /// Translation along x.
    Ux,
    /// Translation along y.
    Uy,
    /// Translation along z.
    Uz,
    /// Rotation about x.
    Rx,
    /// Rotation about y.
    Ry,
    /// Rotation about z.
    Rz,
}

impl DofKind {
    /// The six kinds in the order `ux uy uz rx ry rz`.
    pub const ALL: [DofKind; 6] = [
        DofKind::Ux,
        DofKind::Uy,
        DofKind::Uz,
        DofKind::Rx,
        DofKind::Ry,
        DofKind::Rz,
    ];
    /// Position in `ux uy uz rx ry rz` (0 … 5).
    pub fn index(self) -> usize {
        self as usize
    }
    /// The name used in DOF map files.
    pub fn name(self) -> &'static str {
        ["ux", "uy", "uz", "rx", "ry", "rz"][self.index()]
    }
    /// Parses `ux` … `rz` (any case; `rotx` etc. as ANSYS writes them are accepted too).
    pub fn parse(s: &str) -> Option<DofKind> {
        let s = s.trim().to_ascii_lowercase();
        let s = s.strip_prefix("rot").map(|r| format!("r{r}")).unwrap_or(s);
        DofKind::ALL.into_iter().find(|k| k.name() == s)
    }
}

/// A node of an FE model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Node {
    /// The node number of the FE program.
    pub id: u64,
    /// Machine coordinates at the reference position, m.
    pub position: Vector3<f64>,
}

/// Mass, centre of gravity and inertia of a body, from its FE mass matrix.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MassProperties {
    /// Mass, kg.
    pub mass_kg: f64,
    /// Centre of gravity, m.
    pub cog_m: Vector3<f64>,
    /// Inertia tensor about the centre of gravity in machine axes, kg·m².
    pub inertia_kg_m2: Matrix3<f64>,
}

/// A finite-element model: sparse symmetric M and K with the DOF map and the nodes.
#[derive(Debug, Clone)]
pub struct FeModel {
    /// Where the model came from (file name or `beam`), for messages.
    pub source: String,
    /// Mass matrix, kg (and kg·m² on rotations).
    pub mass: SparseMatrix,
    /// Stiffness matrix, N/m (and N·m/rad on rotations).
    pub stiffness: SparseMatrix,
    /// The nodes, in the order of the node file.
    pub nodes: Vec<Node>,
    /// Per matrix row: the node (index into `nodes`) and the direction.
    pub dofs: Vec<(usize, DofKind)>,
    /// Per node: the matrix row of each of `ux uy uz rx ry rz`, if the node has it.
    pub(crate) node_dofs: Vec<[Option<usize>; 6]>,
}

/// Relative force left by a rigid motion that still counts as none: exported matrices carry
/// 15 or more digits, so an exact model leaves ~1e-12.
const RIGID_FORCE_TOL: f64 = 1e-6;

impl FeModel {
    /// Builds a model from matrices and maps, checking the DOF map against the nodes. `dofs`:
    /// per matrix row the node id and direction.
    pub fn new(
        source: &str,
        mass: SparseMatrix,
        stiffness: SparseMatrix,
        nodes: Vec<Node>,
        dofs: &[(u64, DofKind)],
    ) -> Result<FeModel, FeError> {
        let n = stiffness.nrows();
        if mass.nrows() != n {
            return Err(FeError::file(
                source,
                format!(
                    "mass matrix is {0}×{0}, stiffness matrix {1}×{1}",
                    mass.nrows(),
                    n
                ),
            ));
        }
        if dofs.len() != n {
            return Err(FeError::file(
                source,
                format!("the DOF map has {} rows, the matrices {n}", dofs.len()),
            ));
        }
        let index: std::collections::HashMap<u64, usize> =
            nodes.iter().enumerate().map(|(i, p)| (p.id, i)).collect();
        let mut node_dofs = vec![[None; 6]; nodes.len()];
        let mut map = Vec::with_capacity(n);
        for (row, &(id, kind)) in dofs.iter().enumerate() {
            let Some(&i) = index.get(&id) else {
                return Err(FeError::file(
                    source,
                    format!("DOF map row {}: node {id} is not in the node list", row + 1),
                ));
            };
            if node_dofs[i][kind.index()].replace(row).is_some() {
                return Err(FeError::file(
                    source,
                    format!(
                        "DOF map row {}: node {id} {} given twice",
                        row + 1,
                        kind.name()
                    ),
                ));
            }
            map.push((i, kind));
        }
        for (node, d) in nodes.iter().zip(&node_dofs) {
            let translations = d[..3].iter().filter(|r| r.is_some()).count();
            let rotations = d[3..].iter().filter(|r| r.is_some()).count();
            if (translations + rotations > 0 && translations < 3)
                || (rotations > 0 && rotations < 3)
            {
                return Err(FeError::file(
                    source,
                    format!(
                        "node {} has {translations} translations and {rotations} rotations in the DOF map: \
                         a node needs ux uy uz (solid) or all six (beam, shell)",
                        node.id
                    ),
                ));
            }
        }
        Ok(FeModel {
            source: source.to_string(),
            mass,
            stiffness,
            nodes,
            dofs: map,
            node_dofs,
        })
    }

    /// Number of DOFs (matrix size).
    pub fn n_dofs(&self) -> usize {
        self.dofs.len()
    }

    /// Matrix rows of node `i`'s `ux uy uz rx ry rz`, where present.
    pub fn node_dofs(&self, i: usize) -> [Option<usize>; 6] {
        self.node_dofs[i]
    }

    /// True where node `i` carries rotations (beam and shell nodes).
    pub(crate) fn has_rotations(&self, i: usize) -> bool {
        self.node_dofs[i][3].is_some()
    }

    /// Smallest box around the nodes: (lowest corner, highest corner), m.
    pub fn bounds(&self) -> (Vector3<f64>, Vector3<f64>) {
        let mut lo = Vector3::repeat(f64::INFINITY);
        let mut hi = Vector3::repeat(f64::NEG_INFINITY);
        for (p, d) in self.nodes.iter().zip(&self.node_dofs) {
            if d[0].is_some() {
                lo = lo.inf(&p.position);
                hi = hi.sup(&p.position);
            }
        }
        (lo, hi)
    }

    /// Diagonal of the box around the nodes, m: the body's extent.
    pub(crate) fn extent_m(&self) -> f64 {
        let (lo, hi) = self.bounds();
        (hi - lo).norm()
    }

    /// Rigid-body motions of the model as six columns (translation x, y, z and rotation a, b, c
    /// about `centre`): a node at x moves by t + θ × (x − centre) and turns by θ. Stored as
    /// n × 6, column-major.
    pub(crate) fn rigid_modes(&self, centre: &Vector3<f64>) -> faer::Mat<f64> {
        let mut r = faer::Mat::zeros(self.n_dofs(), 6);
        for (row, &(i, kind)) in self.dofs.iter().enumerate() {
            let d = self.nodes[i].position - centre;
            let k = kind.index();
            if k < 3 {
                r[(row, k)] = 1.0;
                // (θ × d)_k = Σ_m ε_kmj θ_m d_j: the column of θ_m holds (e_m × d)_k.
                for m in 0..3 {
                    let e = Vector3::ith(m, 1.0);
                    r[(row, 3 + m)] = e.cross(&d)[k];
                }
            } else {
                r[(row, k)] = 1.0;
            }
        }
        r
    }

    /// Mass, centre of gravity and inertia from the mass matrix: the rigid-body mass matrix
    /// Rᵀ M R about the origin, with R the rigid-body motions. Errors where the rigid-body mass
    /// is not positive (a mass matrix that is not positive semi-definite, or empty).
    pub fn mass_properties(&self) -> Result<MassProperties, FeError> {
        let origin = Vector3::zeros();
        let r = self.rigid_modes(&origin);
        let m6 = to_matrix6(&sandwich(&self.mass, r.as_ref()));
        let mass = (m6[(0, 0)] + m6[(1, 1)] + m6[(2, 2)]) / 3.0;
        let spread = (0..3)
            .map(|k| (m6[(k, k)] - mass).abs())
            .fold(0.0, f64::max);
        if !(mass > 0.0) || !mass.is_finite() {
            return Err(FeError::file(
                &self.source,
                format!(
                    "mass matrix: rigid-body mass {mass:.6e} kg is not positive (the mass matrix must be positive semi-definite)"
                ),
            ));
        }
        if spread > 1e-6 * mass {
            return Err(FeError::file(
                &self.source,
                format!(
                    "mass matrix: the rigid-body mass differs by direction (x {:.6e}, y {:.6e}, z {:.6e} kg)",
                    m6[(0, 0)],
                    m6[(1, 1)],
                    m6[(2, 2)]
                ),
            ));
        }
        // Static moments: the block M_tθ = −m skew(c) about the origin.
        let s = m6.fixed_view::<3, 3>(0, 3).into_owned();
        let cog = Vector3::new(
            s[(1, 2)] - s[(2, 1)],
            s[(2, 0)] - s[(0, 2)],
            s[(0, 1)] - s[(1, 0)],
        ) / (2.0 * mass);
        let skew = cog.cross_matrix();
        // Parallel-axis theorem: J_origin = J_cog + m (|c|² I − c cᵀ) = J_cog − m skew(c)².
        let inertia = m6.fixed_view::<3, 3>(3, 3).into_owned() + mass * skew * skew;
        let inertia = 0.5 * (inertia + inertia.transpose());
        if inertia.symmetric_eigenvalues().min() <= -1e-9 * inertia.norm() {
            return Err(FeError::file(
                &self.source,
                "mass matrix: the rigid-body inertia is not positive semi-definite",
            ));
        }
        Ok(MassProperties {
            mass_kg: mass,
            cog_m: cog,
            inertia_kg_m2: inertia,
        })
    }

    /// Checks that rigid-body motion produces no elastic force: for each of the six rigid-body
    /// motions r, max |K r| is at most 1e-6 of max Σ|K_ij r_j| (the force left relative to the
    /// forces that cancel). A grounded model, or one whose rotations are not consistent with its
    /// translations, fails: it has fewer than 6 rigid-body modes.
    pub fn check_free(&self) -> Result<(), FeError> {
        let (lo, hi) = self.bounds();
        let r = self.rigid_modes(&(0.5 * (lo + hi)));
        let names = ["x", "y", "z", "a", "b", "c"];
        let k = &self.stiffness;
        for (j, name) in names.iter().enumerate() {
            let col = r.col(j);
            let mut net = vec![0.0; self.n_dofs()];
            let mut abs = vec![0.0; self.n_dofs()];
            for c in 0..k.ncols() {
                let rc = col[c];
                if rc == 0.0 {
                    continue;
                }
                for (i, v) in k.row_idx_of_col(c).zip(k.val_of_col(c)) {
                    net[i] += v * rc;
                    abs[i] += (v * rc).abs();
                }
            }
            let net = net.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            let scale = abs.iter().fold(0.0f64, |a, v| a.max(*v));
            if net > RIGID_FORCE_TOL * scale {
                return Err(FeError::file(
                    &self.source,
                    format!(
                        "stiffness matrix: a rigid-body {} {name} produces elastic forces ({:.1e} of the element forces): \
                         the model has fewer than 6 rigid-body modes (supports or springs to ground in the export?)",
                        if j < 3 { "translation" } else { "rotation" },
                        net / scale
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// Aᵀ S A for a sparse symmetric S and a dense A (n × k).
pub(crate) fn sandwich(s: &SparseMatrix, a: faer::MatRef<'_, f64>) -> faer::Mat<f64> {
    let mut sa = faer::Mat::zeros(s.nrows(), a.ncols());
    faer::sparse::linalg::matmul::sparse_dense_matmul(
        sa.as_mut(),
        faer::Accum::Replace,
        s.as_ref(),
        a,
        1.0,
        faer::Par::Seq,
    );
    let out = a.transpose() * &sa;
    let sym = (&out + out.transpose()) * faer::Scale(0.5);
    sym
}

pub(crate) fn to_matrix6(m: &faer::Mat<f64>) -> Matrix6<f64> {
    Matrix6::from_fn(|i, j| m[(i, j)])
}
