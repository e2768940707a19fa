//! Helpers of the FE tests: dense copies of sparse matrices and a dense generalized eigensolver
//! (nalgebra), independent of eij's sparse Lanczos.
#![allow(dead_code)]

use eij::fe::SparseMatrix;
use nalgebra::{DMatrix, DVector};

/// Dense copy of a sparse matrix.
pub fn dense(a: &SparseMatrix) -> DMatrix<f64> {
    let mut d = DMatrix::zeros(a.nrows(), a.ncols());
    for c in 0..a.ncols() {
        for (r, v) in a.row_idx_of_col(c).zip(a.val_of_col(c)) {
            d[(r, c)] += v;
        }
    }
    d
}

/// Rows and columns `keep` of `a`.
pub fn sub(a: &DMatrix<f64>, keep: &[usize]) -> DMatrix<f64> {
    DMatrix::from_fn(keep.len(), keep.len(), |i, j| a[(keep[i], keep[j])])
}

/// Eigenvalues λ of K x = λ M x (M positive definite), ascending.
pub fn generalized_eigenvalues(k: &DMatrix<f64>, m: &DMatrix<f64>) -> Vec<f64> {
    let l = m.clone().cholesky().expect("M positive definite").l();
    let li = l.clone().try_inverse().unwrap();
    let a = &li * k * li.transpose();
    let a = 0.5 * (&a + a.transpose());
    let mut e: Vec<f64> = a.symmetric_eigenvalues().iter().copied().collect();
    e.sort_by(|x, y| x.total_cmp(y));
    e
}

/// Hz from ω².
pub fn hz(lambda: f64) -> f64 {
    lambda.max(0.0).sqrt() / std::f64::consts::TAU
}

/// Solves K x = f with the rows `fixed` held at zero.
pub fn static_solve(k: &DMatrix<f64>, f: &DVector<f64>, fixed: &[usize]) -> DVector<f64> {
    let keep: Vec<usize> = (0..k.nrows()).filter(|i| !fixed.contains(i)).collect();
    let kk = sub(k, &keep);
    let ff = DVector::from_fn(keep.len(), |i, _| f[keep[i]]);
    let x = kk.lu().solve(&ff).expect("held model not singular");
    let mut out = DVector::zeros(k.nrows());
    for (i, &r) in keep.iter().enumerate() {
        out[r] = x[i];
    }
    out
}

/// Eigenvalues λ of K x = λ M x for a positive definite K, ascending, from the largest
/// eigenvalues 1/λ of L⁻¹ M L⁻ᵀ (K = LLᵀ): the low modes come out to round-off of themselves
/// rather than of the highest mode (which bounds [`generalized_eigenvalues`]).
pub fn held_eigenvalues(k: &DMatrix<f64>, m: &DMatrix<f64>) -> Vec<f64> {
    let l = k.clone().cholesky().expect("K positive definite").l();
    let li = l.try_inverse().unwrap();
    let a = &li * m * li.transpose();
    let a = 0.5 * (&a + a.transpose());
    let mut e: Vec<f64> = a
        .symmetric_eigenvalues()
        .iter()
        .map(|mu| 1.0 / mu)
        .collect();
    e.sort_by(|x, y| x.total_cmp(y));
    e
}

/// The `[body.beam]` of CONTRACT's example (a column along z) with `elements` elements and the
/// given E and G.
pub fn contract_beam(elements: usize, e: f64, g: f64) -> eij::fe::Beam {
    eij::fe::Beam {
        from_m: [0.0, 0.6, -0.1],
        to_m: [0.0, 0.6, 1.1],
        elements,
        y_axis: [1.0, 0.0, 0.0],
        area_m2: 0.05,
        iy_m4: 1.0e-3,
        iz_m4: 1.2e-3,
        torsion_m4: 1.5e-3,
        shear_factor: 0.5,
        youngs_modulus_pa: e,
        shear_modulus_pa: g,
        density_kg_m3: 7200.0,
    }
}
