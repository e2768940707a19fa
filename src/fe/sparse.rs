//! Sparse side of the reduction: supernodal Cholesky factors (faer) and the lowest modes of
//! K φ = λ M φ, optionally with linear constraints Dᵀ φ = 0, by shift-invert restarted Lanczos
//! (faer's `partial_self_adjoint_eigen`, a Krylov–Schur method).
//!
//! With A = K + αWᵀW − σM = Pᵀ L Lᵀ P (positive definite) the symmetric operator
//! C = Π L⁻¹ P M Pᵀ L⁻ᵀ Π, Π = I − QQᵀ with Q an orthonormal basis of L⁻¹ P D, has the eigenvalues
//! μ = 1/(λ − σ) of the constrained problem, with φ = Pᵀ L⁻ᵀ z (Dᵀφ = 0 because z ⊥ Q). M need
//! not be invertible (lumped masses without rotary inertia). The largest μ are the lowest λ.

use super::{FeError, FeModel, SparseMatrix};
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::matrix_free::eigen::{
    partial_self_adjoint_eigen, partial_self_adjoint_eigen_scratch, PartialEigenParams,
};
use faer::matrix_free::LinOp;
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, supernodal::SupernodalLltRef, CholeskySymbolicParams,
    SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::{Accum, Conj, Mat, MatMut, MatRef, Par, Side};

/// Pᵀ L Lᵀ P of a sparse symmetric positive definite matrix (supernodal, AMD ordering).
pub(crate) struct Factor {
    symbolic: SymbolicCholesky<usize>,
    values: Vec<f64>,
}

impl std::fmt::Debug for Factor {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "Factor(n = {}, nnz(L) = {})",
            self.symbolic.nrows(),
            self.values.len()
        )
    }
}

impl Factor {
    /// Factors `a` (both triangles stored; the lower one is read). `Err` where it is not
    /// numerically positive definite.
    pub(crate) fn new(a: &SparseMatrix) -> Result<Factor, String> {
        let params = CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
            ..Default::default()
        };
        let symbolic =
            factorize_symbolic_cholesky(a.symbolic(), Side::Lower, SymmetricOrdering::Amd, params)
                .map_err(|e| format!("symbolic Cholesky failed: {e:?}"))?;
        let mut values = vec![0.0; symbolic.len_val()];
        let par = Par::Seq;
        let mut mem =
            MemBuffer::new(symbolic.factorize_numeric_llt_scratch::<f64>(par, Default::default()));
        symbolic
            .factorize_numeric_llt(
                &mut values,
                a.as_ref(),
                Side::Lower,
                LltRegularization::default(),
                par,
                MemStack::new(&mut mem),
                Default::default(),
            )
            .map_err(|_| "the matrix is not positive definite".to_string())?;
        Ok(Factor { symbolic, values })
    }

    fn supernodal(&self) -> SupernodalLltRef<'_, usize, f64> {
        match self.symbolic.raw() {
            SymbolicCholeskyRaw::Supernodal(s) => SupernodalLltRef::new(s, &self.values),
            SymbolicCholeskyRaw::Simplicial(_) => {
                unreachable!("the factorisation is forced supernodal")
            }
        }
    }

    fn scratch(&self, k: usize) -> MemBuffer {
        MemBuffer::new(StackReq::any_of(&[self
            .symbolic
            .solve_in_place_scratch::<f64>(k, Par::Seq)]))
    }

    /// x ← L⁻¹ P x.
    pub(crate) fn l_solve(&self, x: MatMut<'_, f64>) {
        let mut x = x;
        if let Some(perm) = self.symbolic.perm() {
            let tmp = x.to_owned();
            faer::perm::permute_rows(x.rb_mut(), tmp.as_ref(), perm);
        }
        let mut mem = self.scratch(x.ncols());
        self.supernodal()
            .l_solve_with_conj(Conj::No, x, Par::Seq, MemStack::new(&mut mem));
    }

    /// x ← Pᵀ L⁻ᵀ x.
    pub(crate) fn lt_solve(&self, x: MatMut<'_, f64>) {
        let mut x = x;
        let mut mem = self.scratch(x.ncols());
        self.supernodal().l_transpose_solve_with_conj(
            Conj::No,
            x.rb_mut(),
            Par::Seq,
            MemStack::new(&mut mem),
        );
        if let Some(perm) = self.symbolic.perm() {
            let tmp = x.to_owned();
            faer::perm::permute_rows(x, tmp.as_ref(), perm.inverse());
        }
    }

    /// Nonzeros of L.
    pub(crate) fn nnz(&self) -> usize {
        self.values.len()
    }
}

/// y = S x for a sparse S.
pub(crate) fn spmm(s: &SparseMatrix, x: MatRef<'_, f64>) -> Mat<f64> {
    let mut y = Mat::zeros(s.nrows(), x.ncols());
    faer::sparse::linalg::matmul::sparse_dense_matmul(
        y.as_mut(),
        Accum::Replace,
        s.as_ref(),
        x,
        1.0,
        Par::Seq,
    );
    y
}

/// Orthonormal basis of the columns of `y` (thin QR), with R's diagonal for a rank check.
pub(crate) fn orthonormal(y: MatRef<'_, f64>) -> (Mat<f64>, Vec<f64>) {
    let qr = y.qr();
    let r = qr.R();
    let diag = (0..y.ncols()).map(|j| r[(j, j)].abs()).collect();
    (qr.compute_thin_Q(), diag)
}

/// The shift-inverted, projected operator C of the module doc, scaled by `scale`.
#[derive(Debug)]
struct Operator<'a> {
    factor: &'a Factor,
    mass: &'a SparseMatrix,
    q: Option<MatRef<'a, f64>>,
    scale: f64,
}

impl Operator<'_> {
    fn project(&self, mut x: MatMut<'_, f64>) {
        if let Some(q) = self.q {
            let c = q.transpose() * x.rb();
            x -= q * c;
        }
    }
}

impl LinOp<f64> for Operator<'_> {
    fn apply_scratch(&self, _rhs_ncols: usize, _par: Par) -> StackReq {
        StackReq::EMPTY
    }
    fn nrows(&self) -> usize {
        self.mass.nrows()
    }
    fn ncols(&self) -> usize {
        self.mass.nrows()
    }
    fn apply(&self, out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, _par: Par, _stack: &mut MemStack) {
        let mut out = out;
        let mut t = rhs.to_owned();
        self.project(t.as_mut());
        self.factor.lt_solve(t.as_mut());
        faer::sparse::linalg::matmul::sparse_dense_matmul(
            out.rb_mut(),
            Accum::Replace,
            self.mass.as_ref(),
            t.as_ref(),
            self.scale,
            Par::Seq,
        );
        self.factor.l_solve(out.rb_mut());
        self.project(out);
    }
    fn conj_apply(
        &self,
        out: MatMut<'_, f64>,
        rhs: MatRef<'_, f64>,
        par: Par,
        stack: &mut MemStack,
    ) {
        self.apply(out, rhs, par, stack);
    }
}

/// Eigenpairs K φ = λ M φ: λ ascending, φ mass-normalised (φᵀMφ = 1), one column each.
#[derive(Debug, Clone)]
pub struct Modes {
    /// λ = ω², (rad/s)².
    pub eigenvalues: Vec<f64>,
    /// n × count.
    pub vectors: Mat<f64>,
}

impl Modes {
    /// Frequencies f = √λ / 2π, Hz (negative round-off taken as 0).
    pub fn frequencies_hz(&self) -> Vec<f64> {
        self.eigenvalues
            .iter()
            .map(|l| l.max(0.0).sqrt() / std::f64::consts::TAU)
            .collect()
    }
}

/// The `count` lowest eigenpairs of K φ = λ M φ with Dᵀφ = 0 (D: n × c, may be empty), from the
/// factor of A = K − σM (+ any term that vanishes where Dᵀφ = 0).
pub(crate) fn shift_invert(
    factor: &Factor,
    mass: &SparseMatrix,
    constraints: MatRef<'_, f64>,
    sigma: f64,
    count: usize,
) -> Result<Modes, String> {
    let n = mass.nrows();
    let free = n - constraints.ncols();
    let count = count.min(free);
    if count == 0 {
        return Ok(Modes {
            eigenvalues: vec![],
            vectors: Mat::zeros(n, 0),
        });
    }
    let q = if constraints.ncols() > 0 {
        let mut y = constraints.to_owned();
        factor.l_solve(y.as_mut());
        let (q, diag) = orthonormal(y.as_ref());
        let top = diag.iter().fold(0.0f64, |a, &d| a.max(d));
        if diag.iter().any(|&d| !(d > 1e-10 * top)) {
            return Err("the interface constraints are not independent (attachments share all their nodes?)".into());
        }
        Some(q)
    } else {
        None
    };
    let mut op = Operator {
        factor,
        mass,
        q: q.as_ref().map(|q| q.as_ref()),
        scale: 1.0,
    };
    // Start vector: smooth and deterministic, inside the constrained space.
    let mut v0 = Mat::from_fn(n, 1, |i, _| {
        1.0 + 0.5 * ((i as f64) * 0.618_033_988_7).sin()
    });
    op.project(v0.as_mut());
    // Scale C so its largest eigenvalue is about 1: the Lanczos tolerance is absolute.
    let mut w = v0.clone();
    let mut stack_dummy = MemBuffer::new(StackReq::EMPTY);
    for _ in 0..4 {
        let norm = w.norm_l2();
        if !(norm > 0.0) {
            return Err("the start vector vanished".into());
        }
        w *= faer::Scale(1.0 / norm);
        let mut out = Mat::zeros(n, 1);
        op.apply(
            out.as_mut(),
            w.as_ref(),
            Par::Seq,
            MemStack::new(&mut stack_dummy),
        );
        w = out;
    }
    let top = w.norm_l2();
    if !(top > 0.0 && top.is_finite()) {
        return Err("the shift-inverted operator vanished (no mass in the free DOFs?)".into());
    }
    op.scale = 1.0 / top;
    let norm = v0.norm_l2();
    v0 *= faer::Scale(1.0 / norm);

    let (z, mu) = if n <= 4 * count + 128 {
        dense_eigen(&op, count)?
    } else {
        lanczos(&op, v0.as_ref(), count, free)?
    };
    let mut pairs: Vec<(f64, usize)> = mu
        .iter()
        .enumerate()
        .map(|(j, &m)| (sigma + op.scale / m, j))
        .collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut phi = Mat::zeros(n, count);
    for (c, &(_, j)) in pairs.iter().enumerate() {
        phi.col_mut(c).copy_from(z.col(j));
    }
    factor.lt_solve(phi.as_mut());
    let mphi = spmm(mass, phi.as_ref());
    for c in 0..count {
        let norm = (phi.col(c).transpose() * mphi.col(c)).sqrt();
        phi.col_mut(c).iter_mut().for_each(|v| *v /= norm);
    }
    Ok(Modes {
        eigenvalues: pairs.iter().map(|p| p.0).collect(),
        vectors: phi,
    })
}

/// The `count` largest eigenpairs of the operator by faer's restarted Lanczos (Krylov–Schur).
fn lanczos(
    op: &Operator<'_>,
    v0: MatRef<'_, f64>,
    count: usize,
    free: usize,
) -> Result<(Mat<f64>, Vec<f64>), String> {
    let n = op.nrows();
    let params = PartialEigenParams {
        min_dim: (count + 16).min(free),
        max_dim: (2 * count + 32).min(free),
        max_restarts: 2000,
        ..Default::default()
    };
    let mut mem = MemBuffer::new(partial_self_adjoint_eigen_scratch::<f64>(
        op,
        count,
        Par::Seq,
        params,
    ));
    let mut z = Mat::zeros(n, count);
    let mut mu = vec![0.0; count];
    let info = partial_self_adjoint_eigen(
        z.as_mut(),
        &mut mu,
        op,
        v0.col(0),
        1e-10,
        Par::Seq,
        MemStack::new(&mut mem),
        params,
    );
    if info.n_converged_eigen < count {
        return Err(format!(
            "the Lanczos eigensolver converged for {} of {count} modes",
            info.n_converged_eigen
        ));
    }
    Ok((z, mu))
}

/// The same for small models (faer's Lanczos needs a subspace smaller than the model): the
/// operator applied to the identity and decomposed densely.
fn dense_eigen(op: &Operator<'_>, count: usize) -> Result<(Mat<f64>, Vec<f64>), String> {
    let n = op.nrows();
    let mut c = Mat::zeros(n, n);
    let mut none = MemBuffer::new(StackReq::EMPTY);
    op.apply(
        c.as_mut(),
        Mat::<f64>::identity(n, n).as_ref(),
        Par::Seq,
        MemStack::new(&mut none),
    );
    let c = (&c + c.transpose()) * faer::Scale(0.5);
    let evd = c
        .self_adjoint_eigen(Side::Lower)
        .map_err(|_| "the dense eigensolution did not converge".to_string())?;
    // Ascending: the largest μ are the last columns.
    let z = Mat::from_fn(n, count, |i, j| evd.U()[(i, n - 1 - j)]);
    let mu = (0..count).map(|j| evd.S()[n - 1 - j]).collect();
    Ok((z, mu))
}

/// The `count` lowest modes of K φ = λ M φ of a model held at the DOFs `fixed` (matrix rows;
/// none for a free body, then σ < 0 is needed).
pub fn lowest_modes(
    model: &FeModel,
    fixed: &[usize],
    sigma: f64,
    count: usize,
) -> Result<Modes, FeError> {
    let n = model.n_dofs();
    let mut d = Mat::zeros(n, fixed.len());
    for (c, &row) in fixed.iter().enumerate() {
        d[(row, c)] = 1.0;
    }
    let mut a = shifted(&model.stiffness, &model.mass, -sigma);
    for &row in fixed {
        add_diagonal(&mut a, row);
    }
    let factor =
        Factor::new(&a).map_err(|e| FeError::file(&model.source, format!("K − σM: {e}")))?;
    drop(a);
    shift_invert(&factor, &model.mass, d.as_ref(), sigma, count)
        .map_err(|e| FeError::file(&model.source, e))
}

/// The `count` lowest elastic free-free frequencies of the full model, Hz: the rigid-body modes
/// deflated (Rᵀ M φ = 0), shift σ = −(2π·`shift_hz`)², which should lie below the first elastic
/// frequency (a tenth of it is a good choice).
pub fn free_free_frequencies_hz(
    model: &FeModel,
    count: usize,
    shift_hz: f64,
) -> Result<Vec<f64>, FeError> {
    let sigma = -(std::f64::consts::TAU * shift_hz).powi(2);
    let a = shifted(&model.stiffness, &model.mass, -sigma);
    let factor =
        Factor::new(&a).map_err(|e| FeError::file(&model.source, format!("K − σM: {e}")))?;
    drop(a);
    let (lo, hi) = model.bounds();
    let r = model.rigid_modes(&(0.5 * (lo + hi)));
    let mr = spmm(&model.mass, r.as_ref());
    let modes = shift_invert(&factor, &model.mass, mr.as_ref(), sigma, count)
        .map_err(|e| FeError::file(&model.source, e))?;
    Ok(modes.frequencies_hz())
}

/// A + c·B for two symmetric matrices (patterns merged).
pub(crate) fn shifted(a: &SparseMatrix, b: &SparseMatrix, c: f64) -> SparseMatrix {
    if c == 0.0 {
        return a.clone();
    }
    faer::sparse::ops::binary_op(a.as_ref(), b.as_ref(), |x, y| {
        x.copied().unwrap_or(0.0) + c * y.copied().unwrap_or(0.0)
    })
    .expect("memory for K − σM")
}

/// a_ii ← 2 a_ii (a term α e_i e_iᵀ that vanishes where the DOF is held), where the diagonal
/// entry exists (every diagonal of an FE matrix does).
fn add_diagonal(a: &mut SparseMatrix, i: usize) {
    let range = a.col_range(i);
    let rows: Vec<usize> = a.symbolic().row_idx()[range.clone()].to_vec();
    if let Some(p) = rows.iter().position(|&r| r == i) {
        let v = &mut a.val_mut()[range.start + p];
        *v += v.abs().max(1.0);
    }
}
