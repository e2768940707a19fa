//! Identifiability before the fit: which parameters the tests determine, and for the others
//! why not (no influence, or tied to other parameters).
//!
//! From the Jacobian J of the residuals at the start (static terms already eliminated), with
//! columns scaled to unit norm (so that units and magnitudes of the parameters do not matter):
//! J_s = J·D⁻¹ = U Σ Vᵀ. A parameter is not identifiable when
//!
//! * its column is (nearly) zero: no test sees it; or
//! * the smallest singular value is below [`DEGENERATE_SINGULAR`] of the largest (a combination
//!   no test sees), or the standard error predicted with σ at face value,
//!   σ_θi = √((J_sᵀJ_s)⁻¹)_ii / ‖J_i‖, exceeds [`NOT_IDENTIFIABLE_REL_STD_ERR`]·θ_i.
//!
//! Then the right singular vector of the smallest singular value (the null-space direction)
//! names the parameters that move together without changing any residual: those with a share
//! of at least [`TIE_SHARE`] of the largest. For a degenerate combination the member with the
//! largest predicted relative standard error, else the parameter with the largest, is kept at
//! its start value, its tie (partners in the null direction, their correlation and weights)
//! reported, and the analysis repeated on the rest. A
//! bound error for such a parameter would be the wrong diagnosis: the data do not want a
//! value outside the bounds, they want none in particular.

use super::settings::{
    DEGENERATE_SINGULAR, NOT_IDENTIFIABLE_REL_STD_ERR, TIE_SHARE, UNIDENTIFIABLE_COLUMN,
};
use nalgebra::{DMatrix, DVector};

/// Why a parameter is kept at its start value.
#[derive(Debug, Clone, PartialEq)]
pub struct NotIdentifiable {
    /// Index of the parameter.
    pub index: usize,
    /// Parameters it is tied to, with their weight in the null-space direction relative to
    /// its own (a step of +1 in it and of `weight` in the partner changes no residual, in
    /// relative units δθ/θ).
    pub tied_to: Vec<(usize, f64)>,
    /// Correlation with each partner predicted from the start's Jacobian.
    pub correlation: Vec<f64>,
    /// Predicted relative standard error (∞ for a degenerate combination or no influence).
    pub rel_std_err: f64,
    /// No test sees it at all.
    pub no_influence: bool,
}

impl NotIdentifiable {
    /// The sentence for the warnings: `x.guideway_lateral cannot be separated by these tests
    /// from y.guideway_normal (correlation -1.00; …)`.
    pub fn describe(&self, names: &[String], kept_at: f64) -> String {
        let name = &names[self.index];
        if self.no_influence {
            return format!(
                "{name} is not identifiable from the tests given (no influence on any measured EIJ); kept at {kept_at}"
            );
        }
        if self.tied_to.is_empty() {
            return format!(
                "{name} is not identifiable from the tests given (predicted standard error {:.0} % of its value); kept at {kept_at}",
                100.0 * self.rel_std_err
            );
        }
        let partners: Vec<String> = self
            .tied_to
            .iter()
            .zip(&self.correlation)
            .map(|((k, w), c)| {
                format!(
                    "{} (correlation {c:+.3}, null direction weight {w:+.2})",
                    names[*k]
                )
            })
            .collect();
        let partner_names: Vec<&str> = self
            .tied_to
            .iter()
            .map(|(k, _)| names[*k].as_str())
            .collect();
        format!(
            "{name} is not identifiable: the tests cannot separate it from {} — changing them together along the null direction changes no measured EIJ{}; kept at {kept_at}, so the values identified for {} hold only for {name} = {kept_at} (their standard errors do not include that assumption)",
            partners.join(", "),
            if self.rel_std_err.is_finite() {
                format!(" (predicted standard error {:.0} % of its value)", 100.0 * self.rel_std_err)
            } else {
                String::new()
            },
            partner_names.join(", ")
        )
    }
}

/// The result of the analysis.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Analysis {
    /// Parameters the tests determine (indices, ascending).
    pub free: Vec<usize>,
    /// Those they do not, in the order found.
    pub not_identifiable: Vec<NotIdentifiable>,
    /// Singular values of the column-scaled Jacobian of all parameters with influence,
    /// descending.
    pub singular_values: Vec<f64>,
}

/// Predicted covariance (scaled units) of the columns `set` of the column-scaled `js`, and its
/// SVD's smallest singular vector and singular values.
struct Scaled {
    cov: DMatrix<f64>,
    smallest: DVector<f64>,
    sv: Vec<f64>,
}

fn scaled(js: &DMatrix<f64>, set: &[usize]) -> Option<Scaled> {
    if set.is_empty() || js.nrows() == 0 {
        return None;
    }
    let sub = DMatrix::from_fn(js.nrows(), set.len(), |r, c| js[(r, set[c])]);
    let svd = sub.try_svd(false, true, f64::EPSILON, 10_000)?;
    let v_t = svd.v_t.as_ref()?;
    let sv = &svd.singular_values;
    let largest = sv.max();
    let mut cov = DMatrix::zeros(set.len(), set.len());
    let mut k_min = 0;
    for k in 0..sv.len() {
        if sv[k] < sv[k_min] {
            k_min = k;
        }
        if sv[k] > 1e-14 * largest {
            let row = v_t.row(k);
            cov += row.transpose() * row / (sv[k] * sv[k]);
        } else {
            let row = v_t.row(k);
            cov += row.transpose() * row * 1e28;
        }
    }
    let mut values: Vec<f64> = sv.iter().copied().collect();
    values.sort_by(|a, b| b.total_cmp(a));
    Some(Scaled {
        cov,
        smallest: v_t.row(k_min).transpose(),
        sv: values,
    })
}

/// Analyses the Jacobian `j` (m × n) of the residuals at `theta` (θ = 1/p).
pub(crate) fn analyse(j: &DMatrix<f64>, theta: &DVector<f64>) -> Analysis {
    let n = theta.len();
    let norms: Vec<f64> = (0..n).map(|i| j.column(i).norm()).collect();
    let max_norm = norms.iter().cloned().fold(0.0, f64::max);
    let mut not_identifiable = Vec::new();
    let mut free: Vec<usize> = Vec::new();
    for (i, &norm) in norms.iter().enumerate() {
        if norm > UNIDENTIFIABLE_COLUMN * max_norm && norm > 1e-12 {
            free.push(i);
        } else {
            not_identifiable.push(NotIdentifiable {
                index: i,
                tied_to: Vec::new(),
                correlation: Vec::new(),
                rel_std_err: f64::INFINITY,
                no_influence: true,
            });
        }
    }
    let js = DMatrix::from_fn(j.nrows(), n, |r, c| {
        if norms[c] > 0.0 {
            j[(r, c)] / norms[c]
        } else {
            0.0
        }
    });
    let singular_values = scaled(&js, &free).map(|s| s.sv).unwrap_or_default();
    while !free.is_empty() {
        let Some(s) = scaled(&js, &free) else { break };
        // Relative standard error of θ_i: σ_θi/θ_i with σ_θi = √cov_ii/‖J_i‖.
        let rel: Vec<f64> = free
            .iter()
            .enumerate()
            .map(|(k, &i)| s.cov[(k, k)].max(0.0).sqrt() / norms[i] / theta[i].abs())
            .collect();
        let largest = s.sv.first().copied().unwrap_or(0.0);
        let smallest = s.sv.last().copied().unwrap_or(0.0);
        let degenerate = smallest < DEGENERATE_SINGULAR * largest;
        let weak = rel.iter().any(|&r| r > NOT_IDENTIFIABLE_REL_STD_ERR);
        if !degenerate && !weak {
            break;
        }
        // The null-space direction in relative units δθ/θ: v_k/‖J_k‖/θ_k.
        let rel_dir: Vec<f64> = free
            .iter()
            .enumerate()
            .map(|(k, &i)| s.smallest[k] / norms[i] / theta[i].abs())
            .collect();
        let share_max = s.smallest.amax();
        let members: Vec<usize> = (0..free.len())
            .filter(|&k| s.smallest[k].abs() >= TIE_SHARE * share_max)
            .collect();
        let by_rel = |a: &usize, b: &usize| rel[*a].total_cmp(&rel[*b]).then(b.cmp(a));
        // A degenerate combination: the member least determined; else the weakest parameter.
        let worst = if degenerate {
            members.iter().copied().max_by(by_rel).unwrap_or(0)
        } else {
            (0..free.len()).max_by(by_rel).unwrap_or(0)
        };
        let corr = |a: usize, b: usize| s.cov[(a, b)] / (s.cov[(a, a)] * s.cov[(b, b)]).sqrt();
        let partners: Vec<usize> = if members.contains(&worst) {
            members.iter().copied().filter(|&k| k != worst).collect()
        } else {
            Vec::new()
        };
        not_identifiable.push(NotIdentifiable {
            index: free[worst],
            tied_to: partners
                .iter()
                .map(|&k| (free[k], rel_dir[k] / rel_dir[worst]))
                .collect(),
            correlation: partners.iter().map(|&k| corr(worst, k)).collect(),
            rel_std_err: if degenerate {
                f64::INFINITY
            } else {
                rel[worst]
            },
            no_influence: false,
        });
        free.remove(worst);
    }
    Analysis {
        free,
        not_identifiable,
        singular_values,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tied_pair_and_a_blind_parameter_are_named() {
        // r = θ0 + θ1 (tied), 3·θ2 (fine), θ3 unseen; five rows.
        let j = DMatrix::from_fn(5, 4, |r, c| match c {
            0 | 1 => 1.0 + r as f64,
            2 => 3.0 * (r as f64 - 2.0),
            _ => 0.0,
        });
        let theta = DVector::from_element(4, 1.0);
        let a = analyse(&j, &theta);
        assert_eq!(a.free.len(), 2);
        assert!(a.free.contains(&2));
        let blind = &a.not_identifiable[0];
        assert!(blind.index == 3 && blind.no_influence);
        let tie = &a.not_identifiable[1];
        assert!(tie.index == 0 || tie.index == 1);
        let partner = 1 - tie.index;
        assert_eq!(tie.tied_to[0].0, partner);
        // θ0 + θ1 constant: the null direction moves them oppositely, equally.
        assert!((tie.tied_to[0].1 + 1.0).abs() < 1e-9, "{tie:?}");
        assert!(tie.correlation[0] < -0.999);
        let names: Vec<String> = ["a", "b", "c", "d"].iter().map(|s| s.to_string()).collect();
        let text = tie.describe(&names, 1.0);
        assert!(text.contains("cannot separate it from"), "{text}");
    }

    #[test]
    fn well_determined_parameters_stay_free() {
        let j = DMatrix::from_fn(6, 2, |r, c| if c == 0 { r as f64 } else { 5.0 - r as f64 });
        let a = analyse(&(j * 100.0), &DVector::from_element(2, 1.0));
        assert_eq!(a.free, vec![0, 1]);
        assert!(a.not_identifiable.is_empty());
    }
}
