//! EIJ of a positioning move (`eij evaluate-move`): the deviation external − internal of every
//! direction I against the set acceleration of the moved axis J, by least squares over the
//! whole record, d_I(t) = E_IJ·a_J(t) + F_I·v_J(t) + c_I + g_I·s_J(t) (µm): the acceleration
//! term is the EIJ; the velocity term takes what is proportional to speed (damping, friction),
//! the constant and the position term the static geometry along the travel (straightness,
//! angular errors), so that neither is mistaken for an acceleration effect.
//!
//! A move's acceleration is not a single line like a circle's: a jerk-limited move of 10 m/s²
//! and 250 m/s³ holds its acceleration for tens of milliseconds between ramps of 40 ms, so its
//! content spreads over 0–30 Hz. Its EIJ is the quasi-static deflection weighted by that
//! content, and agrees with circle EIJ (8 Hz) as far as the structure's response is flat over
//! that band (see docs/compensation.md).

use super::lstsq::lstsq;
use crate::axes::{Axis, Eij, EijEstimates, EijMap};
use nalgebra::DMatrix;

/// A move file that cannot be evaluated: file, where, what.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{file}: {at}: {message}")]
pub struct MoveError {
    /// The file.
    pub file: String,
    /// `line N`, `header` or `fit`.
    pub at: String,
    /// What is wrong.
    pub message: String,
}

/// The EIJ of the moved axis from one move.
#[derive(Debug, Clone, PartialEq)]
pub struct MoveEij {
    /// The file.
    pub source: String,
    /// The moved axis J.
    pub axis: Axis,
    /// E_XJ, E_YJ, E_ZJ with their standard errors (white-noise residuals assumed), µm·s²/m.
    pub eij: EijEstimates,
    /// Residual RMS per direction x, y, z, µm.
    pub rms_residual_um: [f64; 3],
    /// Largest |set acceleration|, m/s².
    pub peak_accel_m_s2: f64,
    /// Samples used.
    pub samples: usize,
}

/// A move record: time, internal and external readings (mm) and the moved axis's set
/// position (m), velocity (m/s) and acceleration (m/s²); read from a file by
/// [`crate::measured::moves`].
#[derive(Debug, Clone, PartialEq)]
pub struct MoveRecord {
    /// Time, s.
    pub t: Vec<f64>,
    /// The reference of the deviation x, y, z, mm: the internal readings, or the nominal path
    /// when the move is measured against it (`eij evaluate-move --nominal`).
    pub int_mm: [Vec<f64>; 3],
    /// External readings x, y, z, mm.
    pub ext_mm: [Vec<f64>; 3],
    /// Set position (m), velocity (m/s) and acceleration (m/s²) of the moved axis.
    pub set: [Vec<f64>; 3],
}

/// Evaluates a move of axis `axis` (`source` names its file in messages).
pub(crate) fn evaluate_record(
    rec: &MoveRecord,
    source: String,
    axis: Axis,
) -> Result<MoveEij, MoveError> {
    let n = rec.t.len();
    let peak = rec.set[2].iter().fold(0.0_f64, |m, a| m.max(a.abs()));
    let fit_err = |message: String| MoveError {
        file: source.clone(),
        at: "fit".into(),
        message,
    };
    if peak < 1e-6 {
        return Err(fit_err(format!(
            "axis {axis} is not accelerated (peak set acceleration {peak:.3e} m/s²)"
        )));
    }
    // Columns: a, v, 1, s (position centred and in m, so that the columns are of like size).
    let s_mean = rec.set[0].iter().sum::<f64>() / n as f64;
    let x = DMatrix::from_fn(n, 4, |i, j| match j {
        0 => rec.set[2][i],
        1 => rec.set[1][i],
        2 => 1.0,
        _ => rec.set[0][i] - s_mean,
    });
    let y = DMatrix::from_fn(n, 3, |i, k| (rec.ext_mm[k][i] - rec.int_mm[k][i]) * 1e3);
    let fit = lstsq(x, y).ok_or_else(|| {
        fit_err(
            "acceleration, velocity and position of the move cannot be told apart (too short, \
             or not a move)"
                .into(),
        )
    })?;
    let mut eij = EijEstimates::new();
    let mut rms = [0.0; 3];
    for (k, dev) in Axis::ALL.into_iter().enumerate() {
        eij.insert(Eij::new(dev, axis), fit.coef[(0, k)], fit.std_err(0, k));
        rms[k] = (fit.rss[k] / n as f64).sqrt();
    }
    Ok(MoveEij {
        source,
        axis,
        eij,
        rms_residual_um: rms,
        peak_accel_m_s2: peak,
        samples: n,
    })
}

impl MoveEij {
    /// The docs/commands.md JSON: `axis`, `eij_um_s2_per_m`, `std_err_um_s2_per_m`, plus `file`,
    /// `rms_residual_um` (x, y, z), `peak_accel_m_s2` and `samples`.
    pub fn to_json(&self) -> serde_json::Value {
        let names = |m: &EijMap| -> serde_json::Map<String, serde_json::Value> {
            m.iter().map(|(k, v)| (k.name(), (*v).into())).collect()
        };
        serde_json::json!({
            "file": self.source,
            "axis": self.axis.name(),
            "eij_um_s2_per_m": names(&self.eij.value_map()),
            "std_err_um_s2_per_m": names(&self.eij.std_err_map()),
            "rms_residual_um": self.rms_residual_um,
            "peak_accel_m_s2": self.peak_accel_m_s2,
            "samples": self.samples,
        })
    }
}
