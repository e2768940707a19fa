//! Compensation: from a calibrated model to the controller's cross-talk compensation.
//!
//! CNC controllers correct acceleration correlated errors with a list of coefficients
//! Δs_I = −k_IJ(s_K)·a_J: the set position of axis I is shifted against the deviation that the
//! set acceleration of axis J causes, with a coefficient that may depend linearly on the position
//! of one adaptation axis K (Heidenhain's cross-talk compensation, ISG's crosstalk compensation).
//! The coefficients are the EIJ (paper section 2.2), so a calibrated model delivers them:
//! [`CompensationTable::of`] evaluates the model's EIJ over a grid of the whole workspace
//! ([`crate::map`], the same simulation and evaluation as the identification) and fits
//! k_IJ(s_K) = offset + slope·s_K for the axis K that explains most of its variation (or
//! none), with the worst residual of that linear form over the grid.
//!
//! [`Compensated`] applies a table as feed-forward on any set point ([`SetPoint`]): the
//! correction c_I = −Σ_J k_IJ(s_K)·a_J is added to the position set point, and its velocity
//! and acceleration (central differences over [`DIFF_STEP_S`], as a controller's interpolator
//! differentiates its set points) to the feed-forward inputs.

use crate::axes::{Axis, Direction, Eij, Plane};
use crate::machine::Machine;
use crate::map::{eij_map_with_progress, AxisGrid, MapError, MapSpec};
use crate::sim::setpoint::SetPoint;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

/// Grid points per axis over its stroke (5: the ends, the middle and the quarters).
pub const DEFAULT_POINTS: usize = 5;
/// At most this many points per axis.
pub(crate) const MAX_POINTS_PER_AXIS: usize = 21;
/// A linear form in the best axis is kept only where it lowers the worst residual of the constant
/// by at least this fraction; otherwise the coefficient is constant (`none`).
pub(crate) const MIN_IMPROVEMENT: f64 = 0.2;
/// Step of the central differences that give the correction's velocity and acceleration, s.
pub const DIFF_STEP_S: f64 = 2.5e-4;

/// The CSV header of a compensation table (docs/commands.md, then eij's own column).
pub const HEADER: &str = "parameter,adaptation_axis,offset_um_s2_per_m,slope_um_s2_per_m_per_mm,worst_residual_um_s2_per_m";

/// Errors of building or reading a compensation table.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CompensationError {
    /// The EIJ map over the workspace failed.
    #[error(transparent)]
    Map(#[from] MapError),
    /// A setting is out of range.
    #[error("{key}: {message}")]
    Setting {
        /// The option or key.
        key: String,
        /// What is wrong.
        message: String,
    },
    /// A table file is wrong: file, line, what.
    #[error("{file}: {at}: {message}")]
    File {
        /// The file.
        file: String,
        /// `line N` or `header`.
        at: String,
        /// What is wrong.
        message: String,
    },
}

/// One coefficient k_IJ(s_K) = offset + slope·s_K.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coefficient {
    /// The parameter EIJ it compensates.
    pub parameter: Eij,
    /// The adaptation axis K (`None`: constant).
    pub adaptation_axis: Option<Axis>,
    /// Value at s_K = 0, µm·s²/m.
    pub offset_um_s2_per_m: f64,
    /// Change per mm of s_K, µm·s²/m per mm.
    pub slope_um_s2_per_m_per_mm: f64,
    /// Largest |EIJ − linear form| over the grid, µm·s²/m (NaN where unknown: a table read
    /// from a file without that column).
    pub worst_residual_um_s2_per_m: f64,
}

impl Coefficient {
    /// k at axis positions `pos_mm` (x, y, z in mm; axes the machine lacks at 0).
    pub fn at(&self, pos_mm: [f64; 3]) -> f64 {
        let s = self.adaptation_axis.map_or(0.0, |k| pos_mm[k.index()]);
        self.offset_um_s2_per_m + self.slope_um_s2_per_m_per_mm * s
    }
}

/// A compensation table: one coefficient per EIJ of the machine's axes.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct CompensationTable {
    /// Coefficients, in parameter order.
    pub coefficients: Vec<Coefficient>,
}

/// How the table is computed.
#[derive(Debug, Clone, PartialEq)]
pub struct TableSpec {
    /// Circle radius of the simulated tests, mm (2).
    pub radius_mm: f64,
    /// Set acceleration of the simulated tests, m/s² (5).
    pub accel_m_s2: f64,
    /// Grid points per axis over its stroke (5).
    pub points: usize,
}

impl Default for TableSpec {
    fn default() -> Self {
        TableSpec {
            radius_mm: 2.0,
            accel_m_s2: 5.0,
            points: DEFAULT_POINTS,
        }
    }
}

/// Linear least squares y ≈ a + b·x with the worst residual.
fn line_fit(x: &[f64], y: &[f64]) -> (f64, f64, f64) {
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxx: f64 = x.iter().map(|v| (v - mx) * (v - mx)).sum();
    let sxy: f64 = x.iter().zip(y).map(|(u, v)| (u - mx) * (v - my)).sum();
    let b = if sxx > 0.0 { sxy / sxx } else { 0.0 };
    let a = my - b * mx;
    let worst = x
        .iter()
        .zip(y)
        .map(|(u, v)| (v - a - b * u).abs())
        .fold(0.0, f64::max);
    (a, b, worst)
}

impl CompensationTable {
    /// The table of `machine`: its EIJ at every point of a grid of `spec.points` per axis over
    /// the strokes, from circle tests (ccw, `spec.radius_mm`, `spec.accel_m_s2`) in the three
    /// planes; an EIJ that two planes give (J in both) is their mean.
    pub fn of(machine: &Machine, spec: &TableSpec) -> Result<Self, CompensationError> {
        Self::of_with_progress(machine, spec, &|_, _| {})
    }

    /// As [`CompensationTable::of`], calling `progress(done, total)` with the circles
    /// simulated so far (for a progress bar).
    pub fn of_with_progress(
        machine: &Machine,
        spec: &TableSpec,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> Result<Self, CompensationError> {
        let setting = |key: &str, message: String| CompensationError::Setting {
            key: key.to_string(),
            message,
        };
        if !(2..=MAX_POINTS_PER_AXIS).contains(&spec.points) {
            return Err(setting(
                "points",
                format!("{} per axis, allowed 2…{MAX_POINTS_PER_AXIS}", spec.points),
            ));
        }
        if !(spec.radius_mm.is_finite() && spec.radius_mm > 0.0 && spec.radius_mm <= 3.0) {
            return Err(setting(
                "radius-mm",
                format!("{} must be in (0, 3] (the R-Test's range)", spec.radius_mm),
            ));
        }
        if !(spec.accel_m_s2.is_finite() && spec.accel_m_s2 > 0.0) {
            return Err(setting(
                "accel-m-s2",
                format!("{} must be > 0", spec.accel_m_s2),
            ));
        }
        let n = spec.points;
        let grids: Vec<AxisGrid> = machine
            .axes()
            .iter()
            .map(|a| {
                let [lo, hi] = a.stroke_m;
                AxisGrid {
                    axis: a.axis,
                    values_m: (0..n)
                        .map(|i| (lo + (hi - lo) * i as f64 / (n - 1) as f64).min(hi))
                        .collect(),
                }
            })
            .collect();
        // EIJ samples per parameter: positions in mm, values summed over the planes, and how
        // many planes gave each.
        type Samples = (Vec<[f64; 3]>, Vec<f64>, Vec<u32>);
        let mut sums: BTreeMap<Eij, Samples> = BTreeMap::new();
        let planes: Vec<Plane> = Plane::ALL
            .into_iter()
            .filter(|p| machine.axis(p.axes().0).is_some() && machine.axis(p.axes().1).is_some())
            .collect();
        let per_plane = grids.iter().map(|g| g.values_m.len()).product::<usize>();
        for (k, &plane) in planes.iter().enumerate() {
            let map_spec = MapSpec {
                plane,
                direction: Direction::Ccw,
                radius_m: spec.radius_mm * 1e-3,
                accel_m_s2: spec.accel_m_s2,
            };
            let total = planes.len() * per_plane;
            let points = eij_map_with_progress(machine, &grids, &map_spec, &|done, _| {
                progress(k * per_plane + done, total)
            })?;
            for (e, _) in points[0].eij.iter() {
                if machine.axis(e.deviation).is_none() {
                    continue;
                }
                let entry = sums.entry(*e).or_insert_with(|| {
                    let pos = points
                        .iter()
                        .map(|p| {
                            let mut mm = [0.0; 3];
                            for (ax, v) in machine.axes().iter().zip(&p.position_m) {
                                mm[ax.axis.index()] = v * 1e3;
                            }
                            mm
                        })
                        .collect();
                    (pos, vec![0.0; points.len()], vec![0; points.len()])
                });
                for (k, p) in points.iter().enumerate() {
                    entry.1[k] += p.eij[e];
                    entry.2[k] += 1;
                }
            }
        }
        let mut coefficients = Vec::new();
        for (e, (pos, sum, count)) in sums {
            let y: Vec<f64> = sum.iter().zip(&count).map(|(s, c)| s / *c as f64).collect();
            let mean = y.iter().sum::<f64>() / y.len() as f64;
            let constant_worst = y.iter().map(|v| (v - mean).abs()).fold(0.0, f64::max);
            let mut best = (None, mean, 0.0, constant_worst);
            for ax in machine.axes() {
                let x: Vec<f64> = pos.iter().map(|p| p[ax.axis.index()]).collect();
                let (a, b, worst) = line_fit(&x, &y);
                if worst < best.3 {
                    best = (Some(ax.axis), a, b, worst);
                }
            }
            if best.0.is_some() && best.3 > (1.0 - MIN_IMPROVEMENT) * constant_worst {
                best = (None, mean, 0.0, constant_worst);
            }
            coefficients.push(Coefficient {
                parameter: e,
                adaptation_axis: best.0,
                offset_um_s2_per_m: best.1,
                slope_um_s2_per_m_per_mm: best.2,
                worst_residual_um_s2_per_m: best.3,
            });
        }
        Ok(CompensationTable { coefficients })
    }

    /// The coefficient of `e`, if the table has one.
    pub fn get(&self, e: Eij) -> Option<&Coefficient> {
        self.coefficients.iter().find(|c| c.parameter == e)
    }

    /// The correction of the set positions, m, at positions `pos_mm` (x, y, z) for set
    /// accelerations `acc_m_s2` (x, y, z): c_I = −Σ_J k_IJ(s_K)·a_J.
    pub(crate) fn correction_m(&self, pos_mm: [f64; 3], acc_m_s2: [f64; 3]) -> [f64; 3] {
        let mut c = [0.0; 3];
        for k in &self.coefficients {
            c[k.parameter.deviation.index()] -=
                k.at(pos_mm) * 1e-6 * acc_m_s2[k.parameter.accelerated.index()];
        }
        c
    }

    /// The table as CSV ([`HEADER`]; numbers with 6 decimals, `none` for a constant).
    pub fn to_csv(&self) -> String {
        let mut s = String::from(HEADER);
        s.push('\n');
        for c in &self.coefficients {
            let _ = writeln!(
                s,
                "{},{},{:.6},{:.9},{:.6}",
                c.parameter,
                c.adaptation_axis
                    .map_or("none".to_string(), |a| a.to_string()),
                c.offset_um_s2_per_m,
                c.slope_um_s2_per_m_per_mm,
                c.worst_residual_um_s2_per_m
            );
        }
        s
    }

    /// Reads a table for `machine`: the docs/commands.md columns in any order (the worst residual
    /// optional, other columns refused as a likely unit mistake); every parameter at most once,
    /// its axes and adaptation axis on the machine, every number finite.
    pub fn read(path: &Path, machine: &Machine) -> Result<Self, CompensationError> {
        let file = path.display().to_string();
        let err = |at: String, message: String| CompensationError::File {
            file: file.clone(),
            at,
            message,
        };
        let text = crate::io::read_input_text(path, crate::io::read::MAX_TEXT_BYTES)
            .map_err(|e| err("file".into(), format!("cannot read: {e}")))?;
        let mut rdr = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .comment(Some(b'#'))
            .from_reader(text.as_bytes());
        let header: Vec<String> = rdr
            .headers()
            .map_err(|e| err("header".into(), crate::io::delimited::csv_message(&e)))?
            .iter()
            .map(str::to_string)
            .collect();
        let known: Vec<&str> = HEADER.split(',').collect();
        for h in &header {
            if !known.contains(&h.as_str()) {
                return Err(err(
                    "header".into(),
                    format!(
                        "unknown column '{h}' (expected {}; coefficients in µm·s²/m, slopes per mm)",
                        HEADER
                    ),
                ));
            }
        }
        let col = |name: &str| header.iter().position(|h| h == name);
        let mut idx = Vec::new();
        for name in &known[..4] {
            idx.push(
                col(name)
                    .ok_or_else(|| err("header".into(), format!("missing column '{name}'")))?,
            );
        }
        let worst_col = col(known[4]);
        let mut coefficients: Vec<Coefficient> = Vec::new();
        for rec in rdr.records() {
            let rec = rec.map_err(|e| {
                let at = e
                    .position()
                    .map_or("CSV".to_string(), |p| format!("line {}", p.line()));
                err(at, crate::io::delimited::csv_message(&e))
            })?;
            let line = rec.position().map_or(0, |p| p.line());
            let at = || format!("line {line}");
            let field = |i: usize| rec.get(i).unwrap_or("");
            let parameter: Eij = field(idx[0]).parse().map_err(|m: String| err(at(), m))?;
            for ax in [parameter.deviation, parameter.accelerated] {
                if machine.axis(ax).is_none() {
                    return Err(err(
                        at(),
                        format!(
                            "{parameter}: the machine {} has no axis {ax}",
                            machine.name()
                        ),
                    ));
                }
            }
            let adaptation_axis = match field(idx[1]) {
                "none" => None,
                s => {
                    let ax: Axis = s.parse().map_err(|m: String| {
                        err(at(), format!("adaptation_axis: {m} (or none)"))
                    })?;
                    if machine.axis(ax).is_none() {
                        return Err(err(
                            at(),
                            format!(
                                "adaptation_axis {ax}: the machine {} has no such axis",
                                machine.name()
                            ),
                        ));
                    }
                    Some(ax)
                }
            };
            let number = |i: usize, name: &str| -> Result<f64, CompensationError> {
                let s = field(i);
                let v: f64 = s
                    .parse()
                    .map_err(|_| err(at(), format!("{name}: '{s}' is not a number")))?;
                if !v.is_finite() {
                    return Err(err(at(), format!("{name}: {s} is not finite")));
                }
                Ok(v)
            };
            let offset = number(idx[2], known[2])?;
            let slope = number(idx[3], known[3])?;
            if adaptation_axis.is_none() && slope != 0.0 {
                return Err(err(
                    at(),
                    format!("{parameter}: a slope {slope} without an adaptation axis"),
                ));
            }
            // EIJ of machine tools are a few µm·s²/m; 1000 is a unit mistake (nm, or per m).
            if offset.abs() > 1000.0 {
                return Err(err(
                    at(),
                    format!("{parameter}: offset {offset} µm·s²/m is implausible (units?)"),
                ));
            }
            let worst = match worst_col {
                Some(i) => number(i, known[4])?,
                None => f64::NAN,
            };
            if coefficients.iter().any(|c| c.parameter == parameter) {
                return Err(err(at(), format!("{parameter} given twice")));
            }
            coefficients.push(Coefficient {
                parameter,
                adaptation_axis,
                offset_um_s2_per_m: offset,
                slope_um_s2_per_m_per_mm: slope,
                worst_residual_um_s2_per_m: worst,
            });
        }
        if coefficients.is_empty() {
            return Err(err("file".into(), "no coefficients".into()));
        }
        Ok(CompensationTable { coefficients })
    }
}

/// A set point with a compensation table applied as feed-forward: the correction of every axis
/// is added to its position set point, and the correction's derivatives to the velocity and
/// acceleration feed-forward. `origin_mm` is where the set point's zero lies (circle centre or
/// move start, x, y, z in mm), for the adaptation axis.
pub struct Compensated<'a> {
    /// The nominal set point.
    pub nominal: &'a dyn SetPoint,
    /// The table.
    pub table: &'a CompensationTable,
    /// Axis positions of the set point's origin, mm (x, y, z).
    pub origin_mm: [f64; 3],
}

impl Compensated<'_> {
    /// The correction (position, velocity, acceleration per axis of `axes`, like
    /// [`SetPoint::eval`]) at time `t`.
    pub fn correction(&self, t: f64, axes: &[Axis], out: &mut [f64]) {
        let h = DIFF_STEP_S;
        let end = self.nominal.duration_s();
        let mut buf = vec![0.0; 3 * axes.len()];
        let mut at = |t: f64| -> [f64; 3] {
            self.nominal.eval(t.clamp(0.0, end), axes, &mut buf);
            let (mut pos, mut acc) = (self.origin_mm, [0.0; 3]);
            for (i, a) in axes.iter().enumerate() {
                pos[a.index()] += buf[3 * i] * 1e3;
                acc[a.index()] = buf[3 * i + 2];
            }
            self.table.correction_m(pos, acc)
        };
        let (before, now, after) = (at(t - h), at(t), at(t + h));
        for (i, a) in axes.iter().enumerate() {
            let k = a.index();
            out[3 * i] = now[k];
            out[3 * i + 1] = (after[k] - before[k]) / (2.0 * h);
            out[3 * i + 2] = (after[k] - 2.0 * now[k] + before[k]) / (h * h);
        }
    }
}

impl SetPoint for Compensated<'_> {
    fn duration_s(&self) -> f64 {
        self.nominal.duration_s()
    }

    fn eval(&self, t: f64, axes: &[Axis], out: &mut [f64]) {
        self.nominal.eval(t, axes, out);
        let mut c = vec![0.0; out.len()];
        self.correction(t, axes, &mut c);
        for (o, c) in out.iter_mut().zip(&c) {
            *o += c;
        }
    }
}
