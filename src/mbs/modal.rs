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

/// All undamped modes, frequencies ascending; rigid-body modes are reported at 0 Hz, first,
/// in a fixed order: one per drive in the machine's axis order, each the drive's own rigid
/// motion (its rotor and everything its slide carries), whatever basis of the zero-frequency
/// space the eigen-solver returned (any basis of a repeated eigenvalue is one; the solver's
/// depends on rounding). Modes of equal frequency follow the order of their dominant DOF.
pub fn modes(model: &Model) -> Result<Vec<Mode>, MbsError> {
    let (values, mut shapes) = eigen(model)?;
    let max = values.iter().cloned().fold(0.0, f64::max);
    let rigid = values
        .iter()
        .take_while(|&&w2| w2 <= RIGID_RELATIVE * max)
        .count();
    canonical_rigid_basis(model, &mut shapes, rigid);
    let mut modes: Vec<Mode> = values
        .iter()
        .enumerate()
        .map(|(c, &w2)| {
            let shape = shapes.column(c).into_owned();
            let (i, share) = dominant(model, &shape);
            Mode {
                frequency_hz: if c < rigid {
                    0.0
                } else {
                    w2.sqrt() / std::f64::consts::TAU
                },
                dominant_dof: model.dofs[i].clone(),
                dominant_share: share,
                shape,
            }
        })
        .collect();
    // Ties (the rigid modes, or repeated frequencies of a symmetric structure) in the order of
    // their dominant DOF; a stable sort keeps the drives' order among the rigid ones.
    let dof_index = |m: &Mode| model.dofs.iter().position(|d| *d == m.dominant_dof);
    let rounded = |f: f64| (f * 1e6).round() as i64;
    modes[rigid..].sort_by(|a, b| {
        rounded(a.frequency_hz)
            .cmp(&rounded(b.frequency_hz))
            .then(dof_index(a).cmp(&dof_index(b)))
    });
    Ok(modes)
}

/// Replaces the first `rigid` columns of `shapes` (a basis of the zero-frequency space) by one
/// basis fixed by the model: the vector that moves one pivot DOF by one and the other pivots
/// not at all, for each pivot in turn, mass-normalised. The pivots are the drives' rotors when
/// there is one rigid mode per drive (the supported machine: each vector is then that drive's
/// rigid motion), else the DOFs chosen one by one by the largest remaining share (ties to the
/// first DOF).
fn canonical_rigid_basis(model: &Model, shapes: &mut DMatrix<f64>, rigid: usize) {
    if rigid == 0 {
        return;
    }
    let basis = shapes.columns(0, rigid).into_owned();
    let pivots: Vec<usize> = if model.axes.len() == rigid {
        model.axes.iter().map(|a| a.rotor_dof).collect()
    } else {
        greedy_pivots(&basis, rigid)
    };
    let p = DMatrix::from_fn(rigid, rigid, |k, l| basis[(pivots[k], l)]);
    let Some(p_inv) = p.try_inverse() else {
        return; // the pivots do not span the space: keep the solver's basis
    };
    let canonical = &basis * p_inv;
    for k in 0..rigid {
        let v = canonical.column(k).into_owned();
        let m = (v.transpose() * &model.mass * &v)[(0, 0)];
        if m > 0.0 && m.is_finite() {
            shapes.set_column(k, &(v / m.sqrt()));
        }
    }
}

/// `count` rows of `basis` (DOFs) that span its columns, by a pivoted Gram–Schmidt on the rows.
fn greedy_pivots(basis: &DMatrix<f64>, count: usize) -> Vec<usize> {
    let mut rows = basis.clone();
    let mut pivots = Vec::with_capacity(count);
    for _ in 0..count {
        let (best, norm) = (0..rows.nrows())
            .filter(|i| !pivots.contains(i))
            .map(|i| (i, rows.row(i).norm()))
            .fold(
                (0, -1.0),
                |acc, x| if x.1 > acc.1 * (1.0 + 1e-9) { x } else { acc },
            );
        if norm <= 0.0 {
            break;
        }
        pivots.push(best);
        let q = rows.row(best).into_owned() / norm;
        for i in 0..rows.nrows() {
            let c = rows.row(i).dot(&q);
            let updated = rows.row(i) - &q * c;
            rows.set_row(i, &updated);
        }
    }
    while pivots.len() < count {
        pivots.push(
            (0..basis.nrows())
                .find(|i| !pivots.contains(i))
                .unwrap_or(0),
        );
    }
    pivots
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::machine::Pose;

    fn demo() -> (Machine, Model) {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("machines/demo-vmc.toml");
        let machine = Machine::from_file(&path).unwrap();
        let model = Model::assemble(&machine, &Pose::reference(&machine)).unwrap();
        (machine, model)
    }

    /// |cos| of the angle between two vectors.
    fn parallel(a: &DVector<f64>, b: &DVector<f64>) -> f64 {
        a.dot(b).abs() / (a.norm() * b.norm())
    }

    #[test]
    fn rigid_modes_are_the_drives_motions_in_axis_order() {
        // Independent truth: the drive's rigid motion from the kinematics (Model::drive_mode:
        // its rotor and every body its slide carries), not from an eigen-solution.
        let (machine, model) = demo();
        let modes = modes(&model).unwrap();
        let n = machine.axes().len();
        assert!(modes[..n].iter().all(|m| m.frequency_hz == 0.0));
        assert!(modes[n].frequency_hz > 1.0);
        for (i, m) in modes[..n].iter().enumerate() {
            let c = parallel(&m.shape, &model.drive_mode(&machine, i));
            assert!(c > 1.0 - 1e-9, "mode {} vs drive {i}: cos {c}", i + 1);
            let mass = (m.shape.transpose() * &model.mass * &m.shape)[(0, 0)];
            assert!((mass - 1.0).abs() < 1e-9, "mode {}: φᵀMφ = {mass}", i + 1);
        }
    }

    #[test]
    fn any_basis_of_the_rigid_space_gives_the_same_modes() {
        // A repeated eigenvalue has no preferred basis: mix the solver's rigid shapes by a
        // rotation (as other rounding could) and find the same canonical ones, in both pivot
        // rules.
        let (machine, model) = demo();
        let n = machine.axes().len();
        let (_, shapes) = eigen(&model).unwrap();
        let (c, s) = (0.6f64, 0.8f64);
        let rot = DMatrix::from_row_slice(
            3,
            3,
            &[c, -s, 0.0, s * 0.6, c * 0.6, -0.8, s * 0.8, c * 0.8, 0.6],
        );
        let mut want = shapes.clone();
        canonical_rigid_basis(&model, &mut want, n);
        let mut mixed = shapes.clone();
        let rotated = shapes.columns(0, n) * rot;
        mixed.columns_mut(0, n).copy_from(&rotated);
        canonical_rigid_basis(&model, &mut mixed, n);
        for k in 0..n {
            let (a, b) = (want.column(k).into_owned(), mixed.column(k).into_owned());
            assert!(parallel(&a, &b) > 1.0 - 1e-9, "mode {}", k + 1);
        }
        // The generic rule pivots on DOFs each moved by one drive only: the same vectors.
        let basis = shapes.columns(0, n).into_owned();
        let pivots = greedy_pivots(&basis, n);
        let p = DMatrix::from_fn(n, n, |k, l| basis[(pivots[k], l)]);
        let generic = &basis * p.try_inverse().unwrap();
        for k in 0..n {
            let best = (0..n)
                .map(|j| {
                    parallel(
                        &generic.column(k).into_owned(),
                        &want.column(j).into_owned(),
                    )
                })
                .fold(0.0, f64::max);
            assert!(best > 1.0 - 1e-9, "generic pivot {k}: {best}");
        }
    }
}
