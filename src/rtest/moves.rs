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
use crate::axes::{Axis, Eij};
use nalgebra::DMatrix;
use std::collections::BTreeMap;
use std::path::Path;

/// Most samples read from one move file (100 s at 10 kHz).
pub const MAX_SAMPLES: usize = 1_000_000;

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
    /// E_XJ, E_YJ, E_ZJ, µm·s²/m.
    pub eij: BTreeMap<Eij, f64>,
    /// Their standard errors (white-noise residuals assumed), µm·s²/m.
    pub std_err: BTreeMap<Eij, f64>,
    /// Residual RMS per direction x, y, z, µm.
    pub rms_residual_um: [f64; 3],
    /// Largest |set acceleration|, m/s².
    pub peak_accel_m_s2: f64,
    /// Samples used.
    pub samples: usize,
}

/// A move record: time, internal and external readings (mm) and the moved axis's set
/// position (m), velocity (m/s) and acceleration (m/s²).
struct Record {
    t: Vec<f64>,
    int_mm: [Vec<f64>; 3],
    ext_mm: [Vec<f64>; 3],
    set: [Vec<f64>; 3],
}

fn read(path: &Path, axis: Axis) -> Result<Record, MoveError> {
    let file = path.display().to_string();
    let err = |at: String, message: String| MoveError {
        file: file.clone(),
        at,
        message,
    };
    let bytes = crate::io::read_input(path, crate::io::read::MAX_SERIES_BYTES)
        .map_err(|e| err("file".into(), format!("cannot read: {e}")))?;
    let mut rdr = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .from_reader(bytes.as_slice());
    let header: Vec<String> = rdr
        .headers()
        .map_err(|e| err("header".into(), super::layout::csv_message(&e)))?
        .iter()
        .map(str::to_string)
        .collect();
    let col = |name: &str| header.iter().position(|h| h == name);
    let need = |name: &str| {
        col(name).ok_or_else(|| err("header".into(), format!("missing column '{name}'")))
    };
    let t_col = need("t_s")?;
    let int_cols = Axis::ALL.map(|a| need(&format!("{a}_int_mm")));
    let ext_cols = Axis::ALL.map(|a| need(&format!("{a}_ext_mm")));
    let [ix, iy, iz] = int_cols;
    let [ex, ey, ez] = ext_cols;
    let (int_cols, ext_cols) = ([ix?, iy?, iz?], [ex?, ey?, ez?]);
    let acc_col = col(&format!("{axis}_acc_set_m_s2"));
    let vel_col = col(&format!("{axis}_vel_set_m_s"));
    let pos_col = col(&format!("{axis}_set_mm"));
    if acc_col.is_none() && pos_col.is_none() {
        return Err(err(
            "header".into(),
            format!(
                "no set acceleration of axis {axis}: needs column '{axis}_acc_set_m_s2' (or \
                 '{axis}_set_mm' to differentiate)"
            ),
        ));
    }
    let mut rec = Record {
        t: Vec::new(),
        int_mm: Default::default(),
        ext_mm: Default::default(),
        set: Default::default(),
    };
    let mut raw_set: [Vec<f64>; 3] = Default::default();
    for r in rdr.records() {
        let r = r.map_err(|e| {
            let at = e
                .position()
                .map_or("CSV".to_string(), |p| format!("line {}", p.line()));
            err(at, super::layout::csv_message(&e))
        })?;
        let line = r.position().map_or(0, |p| p.line());
        if rec.t.len() >= MAX_SAMPLES {
            return Err(err(
                format!("line {line}"),
                format!("more than {MAX_SAMPLES} samples"),
            ));
        }
        let num = |c: usize| -> Result<f64, MoveError> {
            let s = r.get(c).unwrap_or("");
            let v: f64 = s.parse().map_err(|_| {
                err(
                    format!("line {line}"),
                    format!("column '{}': '{s}' is not a number", header[c]),
                )
            })?;
            if !v.is_finite() {
                return Err(err(
                    format!("line {line}"),
                    format!("column '{}': {s} is not finite", header[c]),
                ));
            }
            Ok(v)
        };
        let t = num(t_col)?;
        if let Some(&prev) = rec.t.last() {
            if t <= prev {
                return Err(err(
                    format!("line {line}"),
                    format!("t_s {t} does not increase (previous {prev})"),
                ));
            }
        }
        rec.t.push(t);
        for k in 0..3 {
            rec.int_mm[k].push(num(int_cols[k])?);
            rec.ext_mm[k].push(num(ext_cols[k])?);
        }
        for (k, c) in [pos_col, vel_col, acc_col].into_iter().enumerate() {
            if let Some(c) = c {
                raw_set[k].push(num(c)?);
            }
        }
    }
    let n = rec.t.len();
    if n < 10 {
        return Err(err(
            "file".into(),
            format!("{n} samples, at least 10 needed"),
        ));
    }
    // Position: the set position, else the internal reading of the axis.
    rec.set[0] = if raw_set[0].len() == n {
        raw_set[0].iter().map(|v| v * 1e-3).collect()
    } else {
        rec.int_mm[axis.index()].iter().map(|v| v * 1e-3).collect()
    };
    let diff = |y: &[f64]| -> Vec<f64> {
        (0..n)
            .map(|i| {
                let (a, b) = (i.saturating_sub(1), (i + 1).min(n - 1));
                (y[b] - y[a]) / (rec.t[b] - rec.t[a])
            })
            .collect()
    };
    rec.set[1] = if raw_set[1].len() == n {
        raw_set[1].clone()
    } else {
        diff(&rec.set[0])
    };
    rec.set[2] = if raw_set[2].len() == n {
        raw_set[2].clone()
    } else {
        diff(&rec.set[1])
    };
    Ok(rec)
}

/// Evaluates a move of axis `axis` recorded in `path` (CONTRACT.md columns plus the set point of
/// the moved axis).
pub fn evaluate_move(path: &Path, axis: Axis) -> Result<MoveEij, MoveError> {
    let rec = read(path, axis)?;
    let source = path.display().to_string();
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
    let mut eij = BTreeMap::new();
    let mut std_err = BTreeMap::new();
    let mut rms = [0.0; 3];
    for (k, dev) in Axis::ALL.into_iter().enumerate() {
        let e = Eij::new(dev, axis);
        eij.insert(e, fit.coef[(0, k)]);
        std_err.insert(e, fit.std_err(0, k));
        rms[k] = (fit.rss[k] / n as f64).sqrt();
    }
    Ok(MoveEij {
        source,
        axis,
        eij,
        std_err,
        rms_residual_um: rms,
        peak_accel_m_s2: peak,
        samples: n,
    })
}

impl MoveEij {
    /// The CONTRACT.md JSON: `axis`, `eij_um_s2_per_m`, `std_err_um_s2_per_m`, plus `file`,
    /// `rms_residual_um` (x, y, z), `peak_accel_m_s2` and `samples`.
    pub fn to_json(&self) -> serde_json::Value {
        let names = |m: &BTreeMap<Eij, f64>| -> serde_json::Map<String, serde_json::Value> {
            m.iter().map(|(k, v)| (k.name(), (*v).into())).collect()
        };
        serde_json::json!({
            "file": self.source,
            "axis": self.axis.name(),
            "eij_um_s2_per_m": names(&self.eij),
            "std_err_um_s2_per_m": names(&self.std_err),
            "rms_residual_um": self.rms_residual_um,
            "peak_accel_m_s2": self.peak_accel_m_s2,
            "samples": self.samples,
        })
    }
}
