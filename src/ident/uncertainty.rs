//! Uncertainty of the identified parameters from one singular value decomposition of the
//! weighted Jacobian J = ∂r/∂θ at the solution, J = U Σ Vᵀ:
//!
//! * covariance cov(θ) = s²·(JᵀJ)⁻¹ = s²·V Σ⁻² Vᵀ with s² = rᵀr/dof (DESIGN.md,
//!   identification; dof = m − n − q with q static terms eliminated, see
//!   [`super::statics`]), directions with σ_k below the rank threshold left out;
//! * correlation cov_ab/√(cov_aa·cov_bb);
//! * the singular values themselves (how well the tests separate parameter combinations);
//! * warnings: a near-singular combination, a failed χ² test, a weakly determined parameter.

use super::parameters::to_factor;
use super::settings::{NEAR_SINGULAR, WEAK_REL_STD_ERR};
use super::{IdentError, Warning};
use nalgebra::DMatrix;

/// The uncertainty of the free parameters at the solution.
#[derive(Debug, Clone, PartialEq)]
pub struct Uncertainty {
    /// Standard error of each free factor p = 1/θ (delta method: σ_p = σ_θ/θ²).
    pub std_err: Vec<f64>,
    /// Correlation matrix of the free parameters.
    pub correlation: DMatrix<f64>,
    /// Singular values of J, descending.
    pub singular_values: Vec<f64>,
    /// Residual standard deviation s = √(rᵀr/dof).
    pub residual_std: f64,
    /// Covariance of the free θ = 1/p.
    pub covariance: DMatrix<f64>,
    /// Whether the χ² test failed (s ≫ 1).
    pub chi2_failed: bool,
    /// Warnings, in the order near-singular, χ², weakly determined parameters.
    pub warnings: Vec<Warning>,
}

impl Uncertainty {
    /// The uncertainty of the free parameters `theta` (θ = 1/p, named `names`) from the weighted
    /// Jacobian `j` (m × n), the cost rᵀr at the solution and its degrees of freedom.
    pub fn at(
        j: &DMatrix<f64>,
        cost: f64,
        theta: &[f64],
        names: &[&str],
        dof: usize,
    ) -> Result<Uncertainty, IdentError> {
        let (m, n) = j.shape();
        let dof = dof.max(1) as f64;
        let s2 = cost / dof;
        let svd = j
            .clone()
            .try_svd(false, true, f64::EPSILON, 10_000)
            .ok_or(IdentError::Svd)?;
        let v_t = svd.v_t.as_ref().ok_or(IdentError::Svd)?;
        let sv = &svd.singular_values;
        let mut singular_values: Vec<f64> = sv.iter().copied().collect();
        singular_values.sort_by(|a, b| b.total_cmp(a));
        let largest = singular_values.first().copied().unwrap_or(0.0);
        let mut warnings = Vec::new();
        if let Some(last) = singular_values.last() {
            if *last < NEAR_SINGULAR * largest {
                warnings.push(Warning::NearSingular {
                    largest,
                    smallest: *last,
                });
            }
        }
        // χ² test of the fit: with honest σ, s² = χ²/(m − n) scatters about 1 by √(2/(m − n)).
        let chi2_failed = !super::verdict::Chi2::new(s2.sqrt(), dof as usize).passed;
        if chi2_failed {
            warnings.push(Warning::Chi2Failed {
                residual_std: s2.sqrt(),
            });
        }
        // cov = s² V Σ⁻² Vᵀ over the directions above the rank threshold.
        let threshold = largest * f64::EPSILON * m.max(n) as f64;
        let mut cov = DMatrix::zeros(n, n);
        for (k, &sigma) in sv.iter().enumerate() {
            if sigma > threshold && sigma > 0.0 {
                let row = v_t.row(k);
                cov += row.transpose() * row * (s2 / (sigma * sigma));
            }
        }
        let correlation = DMatrix::from_fn(n, n, |a, b| {
            let d = (cov[(a, a)] * cov[(b, b)]).sqrt();
            if d > 0.0 {
                cov[(a, b)] / d
            } else {
                0.0
            }
        });
        let std_err: Vec<f64> = (0..n)
            .map(|k| cov[(k, k)].max(0.0).sqrt() / (theta[k] * theta[k]))
            .collect();
        for k in 0..n {
            let value = to_factor(theta[k]);
            if std_err[k] > WEAK_REL_STD_ERR * value {
                warnings.push(Warning::WeaklyDetermined {
                    name: names[k].to_string(),
                    value,
                    std_err: std_err[k],
                });
            }
        }
        Ok(Uncertainty {
            std_err,
            correlation,
            singular_values,
            residual_std: s2.sqrt(),
            covariance: cov,
            chi2_failed,
            warnings,
        })
    }
}
