//! Positioning-move records (`eij evaluate-move`): time, internal and external readings and the
//! moved axis's set point, read from CSV into what [`crate::rtest::moves`] evaluates.

use std::path::Path;

use crate::axes::Axis;
use crate::io::delimited::csv_message;
use crate::rtest::moves::{evaluate_record, MoveEij, MoveError, MoveRecord};

/// Most samples read from one move file (100 s at 10 kHz).
pub const MAX_SAMPLES: usize = 1_000_000;

/// What a move's deviation is measured against.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Reference {
    /// The axes' own readings: external − internal (`<i>_int_mm`), the structural deviation,
    /// which a compensation on the set points does not change.
    #[default]
    Internal,
    /// The nominal path: external − `<i>_set_mm` of every axis, the TCP's deviation from the
    /// path that was asked for, which is what a compensation reduces (`eij simulate …
    /// --compensation` keeps the nominal path in `<i>_set_mm`).
    Nominal,
}

/// Reads a move of axis `axis` (docs/commands.md columns plus the set point of the moved axis);
/// with [`Reference::Nominal`] the deviation's reference columns (the record's `int_mm`) are
/// the nominal path `<i>_set_mm` of every axis.
pub fn read(path: &Path, axis: Axis, reference: Reference) -> Result<MoveRecord, MoveError> {
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
        .map_err(|e| err("header".into(), csv_message(&e)))?
        .iter()
        .map(str::to_string)
        .collect();
    let col = |name: &str| header.iter().position(|h| h == name);
    let need = |name: &str| {
        col(name).ok_or_else(|| err("header".into(), format!("missing column '{name}'")))
    };
    let t_col = need("t_s")?;
    let int_cols = Axis::ALL.map(|a| match reference {
        Reference::Internal => need(&format!("{a}_int_mm")),
        Reference::Nominal => col(&format!("{a}_set_mm")).ok_or_else(|| {
            err(
                "header".into(),
                format!("missing column '{a}_set_mm' (the nominal path, which --nominal measures against)"),
            )
        }),
    });
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
    let mut rec = MoveRecord {
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
            err(at, csv_message(&e))
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

/// Evaluates a move of axis `axis` recorded in `path` (docs/commands.md columns plus the set point of
/// the moved axis): the deviation external − internal.
pub fn evaluate_move(path: &Path, axis: Axis) -> Result<MoveEij, MoveError> {
    evaluate_move_against(path, axis, Reference::Internal)
}

/// Evaluates a move of axis `axis` recorded in `path`, its deviation measured against
/// `reference`.
pub fn evaluate_move_against(
    path: &Path,
    axis: Axis,
    reference: Reference,
) -> Result<MoveEij, MoveError> {
    let rec = read(path, axis, reference)?;
    evaluate_record(&rec, path.display().to_string(), axis)
}
