//! Ordinary least squares by Householder QR, shared by the normalisation (circle centre and
//! phase fits), the EIJ fits, the pooled fit and the clock-offset fit.

use nalgebra::DMatrix;

/// Solution of an ordinary least-squares problem X·B = Y (several right-hand sides), by
/// Householder QR of X.
#[derive(Debug, Clone)]
pub(crate) struct Lstsq {
    /// Coefficients B, p × m.
    pub coef: DMatrix<f64>,
    /// Residual sum of squares per right-hand side.
    pub rss: Vec<f64>,
    /// (XᵀX)⁻¹ = R⁻¹R⁻ᵀ, p × p.
    pub cov_unscaled: DMatrix<f64>,
    /// Rows of X.
    pub n: usize,
}

impl Lstsq {
    /// Residual variance s² = rᵀr / (n − p) of right-hand side `col`.
    pub(crate) fn residual_variance(&self, col: usize) -> f64 {
        self.rss[col] / (self.n - self.coef.nrows()) as f64
    }

    /// Standard error of coefficient `row` for right-hand side `col`: √(s² (XᵀX)⁻¹ᵢᵢ).
    pub(crate) fn std_err(&self, row: usize, col: usize) -> f64 {
        (self.residual_variance(col) * self.cov_unscaled[(row, row)]).sqrt()
    }
}

/// Least squares X·B ≈ Y by QR. `None` when n ≤ p or X is rank deficient (a diagonal entry
/// of R below 1e-10 of its column's norm).
pub(crate) fn lstsq(x: DMatrix<f64>, mut y: DMatrix<f64>) -> Option<Lstsq> {
    let (n, p) = x.shape();
    if n <= p || y.nrows() != n {
        return None;
    }
    let col_norms: Vec<f64> = x.column_iter().map(|c| c.norm()).collect();
    let qr = x.qr();
    let r = qr.r();
    for (i, norm) in col_norms.iter().enumerate() {
        if r[(i, i)].is_nan() || r[(i, i)].abs() <= 1e-10 * norm {
            return None;
        }
    }
    qr.q_tr_mul(&mut y);
    let coef = r.solve_upper_triangular(&y.rows(0, p).into_owned())?;
    let rss = (0..y.ncols())
        .map(|j| y.view((p, j), (n - p, 1)).norm_squared())
        .collect();
    let r_inv = r.solve_upper_triangular(&DMatrix::identity(p, p))?;
    let cov_unscaled = &r_inv * r_inv.transpose();
    Some(Lstsq {
        coef,
        rss,
        cov_unscaled,
        n,
    })
}
