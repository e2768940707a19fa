//! The least-squares decomposition of one source's deviation into the named terms.
//!
//! In-plane: the radial and the tangential deviation of every sample are two rows of one
//! linear system, each column a term's regressor ([`super::basis::InPlane`]) projected on
//! u = (cos θ, sin θ) and t = (−sin θ, cos θ). The two components have their own noise (a
//! probe's radial noise, the timing noise that the tangential deviation adds), so the fit is
//! weighted in two passes: ordinary least squares, then rows scaled by 1/σ of their component
//! (σ² = rss/(n − p/2) of that component) and solved again (feasible generalised least
//! squares); standard errors √(s² (XᵀWX)⁻¹ᵢᵢ) with s² the weighted residual variance.
//! Out-of-plane: the normal deviation alone, ordinary least squares.
//! Both by Householder QR ([`crate::rtest::lstsq`]).

use nalgebra::DMatrix;

use super::basis::{Circle, InPlane, Normal};
use crate::rtest::iso230::path_figures;
use crate::rtest::lstsq::{lstsq, Lstsq};

/// A solved design: coefficients and their covariance.
#[derive(Debug, Clone)]
pub(crate) struct Solved {
    /// Coefficient per column.
    pub coef: Vec<f64>,
    /// Covariance of the coefficients, s² (XᵀWX)⁻¹.
    pub cov: DMatrix<f64>,
}

impl Solved {
    fn from_lstsq(fit: &Lstsq) -> Self {
        let s2 = fit.residual_variance(0);
        Solved {
            coef: fit.coef.column(0).iter().copied().collect(),
            cov: &fit.cov_unscaled * s2,
        }
    }

    /// Standard error of the linear combination Σ wᵢ coef[colᵢ]: √(wᵀ Σ w).
    pub(crate) fn std_err_of(&self, cols: &[usize], weights: &[f64]) -> f64 {
        let mut var = 0.0;
        for (i, &ci) in cols.iter().enumerate() {
            for (j, &cj) in cols.iter().enumerate() {
                var += weights[i] * weights[j] * self.cov[(ci, cj)];
            }
        }
        var.max(0.0).sqrt()
    }
}

/// The in-plane design evaluated at the samples: radial rows and tangential rows.
#[derive(Debug, Clone)]
pub(crate) struct InPlaneDesign {
    /// Radial projection of every column, n × p.
    pub radial: DMatrix<f64>,
    /// Tangential projection of every column, n × p.
    pub tangential: DMatrix<f64>,
}

impl InPlaneDesign {
    /// The design of `columns` at the nominal angles `theta`.
    pub(crate) fn new(columns: &[InPlane], circle: &Circle, theta: &[f64]) -> Self {
        let n = theta.len();
        let p = columns.len();
        let mut radial = DMatrix::zeros(n, p);
        let mut tangential = DMatrix::zeros(n, p);
        for (i, &th) in theta.iter().enumerate() {
            let (s, c) = th.sin_cos();
            for (j, col) in columns.iter().enumerate() {
                let g = col.vector(circle, th);
                radial[(i, j)] = c * g[0] + s * g[1];
                tangential[(i, j)] = -s * g[0] + c * g[1];
            }
        }
        InPlaneDesign { radial, tangential }
    }

    /// The radial and tangential deviation, µm, of the columns `cols` at values `coef[col]`.
    pub(crate) fn model(&self, coef: &[f64], cols: &[usize]) -> [Vec<f64>; 2] {
        [&self.radial, &self.tangential].map(|x| {
            (0..x.nrows())
                .map(|i| cols.iter().map(|&j| x[(i, j)] * coef[j]).sum())
                .collect()
        })
    }
}

/// Residual RMS per block and the weighted fit of the in-plane rows; `None` when the design
/// is rank deficient.
pub(crate) fn solve_in_plane(
    design: &InPlaneDesign,
    radial_um: &[f64],
    tangential_um: &[f64],
) -> Option<Solved> {
    let n = radial_um.len();
    let p = design.radial.ncols();
    if 2 * n <= p + 2 {
        return None;
    }
    let stack = |w: [f64; 2]| {
        let x = DMatrix::from_fn(2 * n, p, |i, j| {
            if i < n {
                design.radial[(i, j)] * w[0]
            } else {
                design.tangential[(i - n, j)] * w[1]
            }
        });
        let y = DMatrix::from_fn(2 * n, 1, |i, _| {
            if i < n {
                radial_um[i] * w[0]
            } else {
                tangential_um[i - n] * w[1]
            }
        });
        (x, y)
    };
    let (x, y) = stack([1.0, 1.0]);
    let first = lstsq(x, y)?;
    let coef: Vec<f64> = first.coef.column(0).iter().copied().collect();
    let all: Vec<usize> = (0..p).collect();
    let [mr, mt] = design.model(&coef, &all);
    let dof = (n as f64 - 0.5 * p as f64).max(1.0);
    let sigma = |data: &[f64], model: &[f64]| {
        let rss: f64 = data.iter().zip(model).map(|(d, m)| (d - m).powi(2)).sum();
        (rss / dof).sqrt()
    };
    let (sr, st) = (sigma(radial_um, &mr), sigma(tangential_um, &mt));
    // A noise-free component would get an infinite weight: floor it at 1e-3 of the other.
    let floor = (1e-3 * sr.max(st)).max(1e-9);
    let (x, y) = stack([1.0 / sr.max(floor), 1.0 / st.max(floor)]);
    Some(Solved::from_lstsq(&lstsq(x, y)?))
}

/// The out-of-plane design of `columns` at `theta`, n × q.
pub(crate) fn normal_design(columns: &[Normal], circle: &Circle, theta: &[f64]) -> DMatrix<f64> {
    DMatrix::from_fn(theta.len(), columns.len(), |i, j| {
        columns[j].value(circle, theta[i])
    })
}

/// Ordinary least squares of the normal deviation; `None` when rank deficient.
pub(crate) fn solve_normal(design: &DMatrix<f64>, normal_um: &[f64]) -> Option<Solved> {
    let y = DMatrix::from_column_slice(normal_um.len(), 1, normal_um);
    Some(Solved::from_lstsq(&lstsq(design.clone(), y)?))
}

/// The normal deviation, µm, of the columns `cols` at values `coef[col]`.
pub(crate) fn normal_model(design: &DMatrix<f64>, coef: &[f64], cols: &[usize]) -> Vec<f64> {
    (0..design.nrows())
        .map(|i| cols.iter().map(|&j| design[(i, j)] * coef[j]).sum())
        .collect()
}

/// ISO 230-4 circular deviation G, µm, of the path r·u(θ) displaced by the radial and
/// tangential deviations (µm): the points (r + e_r)·u(θ) + e_t·t(θ), about their
/// least-squares centre ([`crate::rtest::iso230::path_figures`], as every path of a test). 0 where no centre
/// can be fitted.
pub(crate) fn circular_deviation(radius_mm: f64, theta: &[f64], dev: [&[f64]; 2]) -> f64 {
    let n = theta.len();
    let (mut a, mut b) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for i in 0..n {
        let rho = radius_mm + dev[0][i] * 1e-3;
        let tangential = dev[1][i] * 1e-3;
        let (s, c) = theta[i].sin_cos();
        a.push(rho * c - tangential * s);
        b.push(rho * s + tangential * c);
    }
    path_figures(&a, &b, radius_mm).map_or(0.0, |f| f.circular_deviation_um)
}

/// Peak-to-valley of a series, µm.
pub(crate) fn range(v: &[f64]) -> f64 {
    let (lo, hi) = v
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &x| {
            (l.min(x), h.max(x))
        });
    if hi >= lo {
        hi - lo
    } else {
        0.0
    }
}

/// Root mean square, µm.
pub(crate) fn rms(v: &[f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
}
