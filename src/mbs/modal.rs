//! Undamped modal analysis: K φ = ω² M φ, solved as the symmetric eigenproblem of
//! L⁻¹ K L⁻ᵀ with M = L Lᵀ (Cholesky), and the support check built on it.

use super::{MbsError, Model};
use crate::machine::Machine;
use nalgebra::{DMatrix, DVector, SymmetricEigen};

/// One undamped mode.
#[derive(Debug, Clone, PartialEq)]
pub struct Mode {
    /// Natural frequency, Hz (0 for rigid-body modes).
    pub frequency_hz: f64,
    /// The DOF holding the largest share of the mode's kinetic energy.
    pub dominant_dof: String,
    /// That share, 0…1.
    pub dominant_share: f64,
    /// Mass-normalised shape (φᵀ M φ = 1).
    pub shape: DVector<f64>,
}

/// Eigenvalues ω² below this fraction of the largest are rigid-body modes.
const RIGID_RELATIVE: f64 = 1e-10;

fn eigen_error(model: &Model, reason: &str) -> MbsError {
    MbsError::Eigen {
        machine: model.machine.clone(),
        reason: reason.to_string(),
    }
}

/// ω² and mass-normalised shapes, ascending.
fn eigen(model: &Model) -> Result<(Vec<f64>, DMatrix<f64>), MbsError> {
    let chol = model
        .mass
        .clone()
        .cholesky()
        .ok_or_else(|| eigen_error(model, "mass matrix not positive definite"))?;
    let l = chol.l();
    let x = l
        .solve_lower_triangular(&model.stiffness)
        .ok_or_else(|| eigen_error(model, "singular mass factor"))?;
    let a = l
        .solve_lower_triangular(&x.transpose())
        .ok_or_else(|| eigen_error(model, "singular mass factor"))?;
    let a = (&a + a.transpose()) * 0.5;
    let eig = SymmetricEigen::try_new(a, f64::EPSILON, 10_000)
        .ok_or_else(|| eigen_error(model, "symmetric eigen-solver did not converge"))?;
    let mut order: Vec<usize> = (0..eig.eigenvalues.len()).collect();
    order.sort_by(|&i, &j| eig.eigenvalues[i].total_cmp(&eig.eigenvalues[j]));
    let lt = l.transpose();
    let n = model.n_dof();
    let mut shapes = DMatrix::zeros(n, n);
    let mut values = Vec::with_capacity(n);
    for (col, &i) in order.iter().enumerate() {
        let phi = lt
            .solve_upper_triangular(&eig.eigenvectors.column(i).into_owned())
            .ok_or_else(|| eigen_error(model, "singular mass factor"))?;
        shapes.set_column(col, &phi);
        values.push(eig.eigenvalues[i]);
    }
    Ok((values, shapes))
}

fn dominant(model: &Model, phi: &DVector<f64>) -> (usize, f64) {
    let mphi = &model.mass * phi;
    let energy: Vec<f64> = phi.iter().zip(mphi.iter()).map(|(a, b)| a * b).collect();
    let total: f64 = energy.iter().sum();
    let (i, e) = energy
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .map(|(i, e)| (i, *e))
        .unwrap_or((0, 0.0));
    (i, if total > 0.0 { e / total } else { 0.0 })
}

/// All undamped modes, frequencies ascending; rigid-body modes are reported at 0 Hz.
pub fn modes(model: &Model) -> Result<Vec<Mode>, MbsError> {
    let (values, shapes) = eigen(model)?;
    let max = values.iter().cloned().fold(0.0, f64::max);
    Ok(values
        .iter()
        .enumerate()
        .map(|(c, &w2)| {
            let shape = shapes.column(c).into_owned();
            let (i, share) = dominant(model, &shape);
            let rigid = w2 <= RIGID_RELATIVE * max;
            Mode {
                frequency_hz: if rigid {
                    0.0
                } else {
                    w2.sqrt() / std::f64::consts::TAU
                },
                dominant_dof: model.dofs[i].clone(),
                dominant_share: share,
                shape,
            }
        })
        .collect())
}

/// Checks that guideways, drives and joints support the structure: the only rigid-body
/// modes allowed are the drives' own (the slide moving with its screw, one per axis).
pub fn check_support(model: &Model, machine: &Machine) -> Result<(), MbsError> {
    let (values, shapes) = eigen(model)?;
    let max = values.iter().cloned().fold(0.0, f64::max);
    let rigid: Vec<usize> = (0..values.len())
        .filter(|&i| values[i] <= RIGID_RELATIVE * max)
        .collect();
    let expected = machine.axes().len();
    if rigid.len() <= expected {
        return Ok(());
    }
    // Remove the drive motions from the rigid modes; what remains is unsupported.
    let drives = DMatrix::from_columns(
        &(0..expected)
            .map(|i| model.drive_mode(machine, i))
            .collect::<Vec<_>>(),
    );
    let mut worst: Option<(f64, DVector<f64>)> = None;
    for &r in &rigid {
        let v = shapes.column(r).into_owned();
        let rest = if expected > 0 {
            let coef = (drives.transpose() * &drives)
                .lu()
                .solve(&(drives.transpose() * &v))
                .unwrap_or_else(|| DVector::zeros(expected));
            &v - &drives * coef
        } else {
            v
        };
        let norm = rest.norm();
        if worst.as_ref().is_none_or(|(w, _)| norm > *w) {
            worst = Some((norm, rest));
        }
    }
    let dof = worst
        .map(|(_, v)| model.dofs[dominant(model, &v).0].clone())
        .unwrap_or_default();
    Err(MbsError::Unsupported {
        machine: model.machine.clone(),
        count: rigid.len() - expected,
        dof,
    })
}
