//! Positioning-move figure (paper Fig. 9): set vs actual position, set vs actual acceleration
//! and the TCP cross-talk deviation (external − internal) of the other axes over time.

use std::path::Path;

use plotters::prelude::*;

use super::svg::{self, Entry, Mark};
use super::{short, Conditions, ReportError};
use crate::axes::Axis;
use crate::control::ClosedLoop;
use crate::sim::setpoint::JerkLimitedMove;
use crate::sim::Run;

/// Points per polyline at most.
const MAX_POINTS: usize = 3000;

/// A positioning move of one axis, in the units of the move CSV.
#[derive(Debug, Clone, PartialEq)]
pub struct MoveData {
    /// File path or in-memory name.
    pub source: String,
    /// The moving axis (the one whose set position spans the largest range).
    pub axis: Axis,
    /// Time, s.
    pub t_s: Vec<f64>,
    /// Set position of the moving axis, mm.
    pub set_mm: Vec<f64>,
    /// Internal reading (scale) of the moving axis, mm.
    pub int_mm: Vec<f64>,
    /// Set acceleration of the moving axis, m/s².
    pub acc_set_m_s2: Vec<f64>,
    /// Actual acceleration of the moving axis (second derivative of the scale reading), m/s².
    pub acc_act_m_s2: Vec<f64>,
    /// Cross-talk deviations ext − int of the other axes, µm: the structural deviation, which is
    /// the TCP's deviation from the path without compensation.
    pub cross_talk_um: Vec<(Axis, Vec<f64>)>,
    /// For a compensated move (`<b>_comp_mm` columns), the TCP's deviation from the nominal
    /// path ext − set of the other axes, µm: what remains with the compensation.
    pub compensated_um: Vec<(Axis, Vec<f64>)>,
    /// The TCP's deviation from the path in the file's set columns, ext − set of the other
    /// axes, µm, for any move file that has them (a compensated one: its nominal path): how a
    /// compensated move on the same page finds the same move run without the table
    /// ([`MoveData::same_nominal_move`]).
    pub path_deviation_um: Vec<(Axis, Vec<f64>)>,
    /// The planned profile of the move, when known ([`MoveData::planned`]): the header then
    /// states its peak velocity, acceleration and jerk (the numbers `eij simulate move`
    /// prints) instead of estimates from the samples.
    pub plan: Option<JerkLimitedMove>,
    /// The TCP's deviation from the nominal path (TCP − set) of the other axes in the same move
    /// simulated without the compensation, µm (`eij simulate move --compensation` runs both):
    /// drawn as "without compensation" in place of the structural cross-talk.
    pub uncompensated_um: Vec<(Axis, Vec<f64>)>,
}

impl MoveData {
    /// Reads a simulated move CSV (`eij simulate move`): `t_s`, and per axis `<a>_set_mm`,
    /// `<a>_acc_set_m_s2`, `<a>_acc_act_m_s2`, `<a>_int_mm`, `<a>_ext_mm`. The moving axis is
    /// the one whose `<a>_set_mm` spans the largest range; cross-talk is drawn for every other
    /// axis with `<b>_int_mm` and `<b>_ext_mm`.
    pub fn read_csv(path: &Path) -> Result<Self, ReportError> {
        let name = path.display().to_string();
        let bad = |message: String| ReportError::BadInput {
            source_name: name.clone(),
            message,
        };
        if path.is_dir() {
            return Err(bad("is a folder, expected a move CSV file".into()));
        }
        let bytes = super::read_file(path)?;
        let mut reader = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .from_reader(bytes.as_slice());
        let header: Vec<String> = reader
            .headers()
            .map_err(|e| bad(format!("line 1: {e}")))?
            .iter()
            .map(str::to_string)
            .collect();
        let find = |c: &str| header.iter().position(|h| h == c);
        let mut columns: Vec<Vec<f64>> = vec![Vec::new(); header.len()];
        for (row, record) in reader.records().enumerate() {
            let line = row + 2;
            let record = record.map_err(|e| bad(format!("line {line}: {e}")))?;
            for (i, col) in columns.iter_mut().enumerate() {
                let text = record.get(i).unwrap_or("");
                let v: f64 = text.parse().map_err(|_| {
                    bad(format!(
                        "line {line}, column {}: '{text}' is not a number",
                        header[i]
                    ))
                })?;
                if !v.is_finite() {
                    return Err(bad(format!(
                        "line {line}, column {}: '{text}' is not finite",
                        header[i]
                    )));
                }
                col.push(v);
            }
        }
        let column = |c: &str| find(c).map(|i| columns[i].clone());
        let t_s = column("t_s").ok_or_else(|| bad("missing column t_s".into()))?;
        if t_s.len() < 2 {
            return Err(bad(format!("{} data row(s), at least 2 needed", t_s.len())));
        }
        let span = |v: &[f64]| {
            v.iter().cloned().fold(f64::NEG_INFINITY, f64::max)
                - v.iter().cloned().fold(f64::INFINITY, f64::min)
        };
        let axis = Axis::ALL
            .into_iter()
            .filter_map(|a| column(&format!("{a}_set_mm")).map(|v| (a, span(&v))))
            .max_by(|x, y| x.1.total_cmp(&y.1))
            .map(|(a, _)| a)
            .ok_or_else(|| bad("no <axis>_set_mm column (not a simulated move?)".into()))?;
        let need = |suffix: &str| {
            let c = format!("{axis}_{suffix}");
            column(&c).ok_or_else(|| bad(format!("missing column {c}")))
        };
        let cross_talk_um = Axis::ALL
            .into_iter()
            .filter(|&b| b != axis)
            .filter_map(|b| {
                let int = column(&format!("{b}_int_mm"))?;
                let ext = column(&format!("{b}_ext_mm"))?;
                Some((
                    b,
                    ext.iter().zip(&int).map(|(e, i)| (e - i) * 1e3).collect(),
                ))
            })
            .collect();
        let path_deviation_um: Vec<(Axis, Vec<f64>)> = Axis::ALL
            .into_iter()
            .filter(|&b| b != axis)
            .filter_map(|b| {
                let set = column(&format!("{b}_set_mm"))?;
                let ext = column(&format!("{b}_ext_mm"))?;
                Some((
                    b,
                    ext.iter().zip(&set).map(|(e, s)| (e - s) * 1e3).collect(),
                ))
            })
            .collect();
        let compensated_um = path_deviation_um
            .iter()
            .filter(|(b, _)| find(&format!("{b}_comp_mm")).is_some())
            .cloned()
            .collect();
        Ok(MoveData {
            axis,
            compensated_um,
            path_deviation_um,
            plan: None,
            uncompensated_um: Vec::new(),
            set_mm: need("set_mm")?,
            int_mm: need("int_mm")?,
            acc_set_m_s2: need("acc_set_m_s2")?,
            acc_act_m_s2: need("acc_act_m_s2")?,
            t_s,
            cross_talk_um,
            source: name,
        })
    }

    /// The move of `axis` from a simulated run of the closed loop `cl`.
    pub fn from_run(
        cl: &ClosedLoop,
        run: &Run,
        axis: Axis,
        source: String,
    ) -> Result<Self, ReportError> {
        let get = |name: String, input: bool, scale: f64| -> Result<Vec<f64>, ReportError> {
            let v = if input {
                run.input_series(cl, &name)
            } else {
                run.output_series(cl, &name)
            };
            v.map(|v| v.into_iter().map(|x| x * scale).collect())
                .ok_or_else(|| ReportError::BadInput {
                    source_name: source.clone(),
                    message: format!("the closed loop has no signal {name}"),
                })
        };
        let mut cross_talk_um = Vec::new();
        for b in Axis::ALL.into_iter().filter(|&b| b != axis) {
            if let (Some(i), Some(e)) = (
                run.output_series(cl, &format!("{b}_int_m")),
                run.output_series(cl, &format!("{b}_tcp_m")),
            ) {
                cross_talk_um.push((b, e.iter().zip(&i).map(|(e, i)| (e - i) * 1e6).collect()));
            }
        }
        Ok(MoveData {
            axis,
            t_s: run.t_s.clone(),
            set_mm: get(format!("{axis}_pos_set_m"), true, 1e3)?,
            int_mm: get(format!("{axis}_int_m"), false, 1e3)?,
            acc_set_m_s2: get(format!("{axis}_acc_set_m_s2"), true, 1.0)?,
            acc_act_m_s2: get(format!("{axis}_acc_act_m_s2"), false, 1.0)?,
            cross_talk_um,
            compensated_um: Vec::new(),
            path_deviation_um: Vec::new(),
            plan: None,
            uncompensated_um: Vec::new(),
            source,
        })
    }

    /// The same move with its planned profile (the header's peak values come from it).
    pub fn planned(mut self, plan: &JerkLimitedMove) -> Self {
        self.plan = Some(plan.clone());
        self
    }

    /// For a run with a compensation: `correction` (laid out like [`Run::inputs`], as
    /// `Compensated::correction` gives it) is taken off the set points, so that set position
    /// and set acceleration show the nominal move (as the CSV's `<a>_set_mm` columns do), and
    /// the TCP's deviation from the nominal path (TCP − nominal set) of the other axes becomes
    /// [`MoveData::compensated_um`].
    pub fn nominal(
        mut self,
        cl: &ClosedLoop,
        run: &Run,
        correction: &[f64],
    ) -> Result<Self, ReportError> {
        let nominal = |name: String| -> Option<Vec<f64>> {
            let i = cl.input(&name)?;
            Some(
                run.input(i)
                    .enumerate()
                    .map(|(k, v)| v - correction.get(k * run.nu + i).copied().unwrap_or(0.0))
                    .collect(),
            )
        };
        let missing = |name: &str| ReportError::BadInput {
            source_name: self.source.clone(),
            message: format!("the closed loop has no signal {name}"),
        };
        let ax = self.axis;
        let set = format!("{ax}_pos_set_m");
        let acc = format!("{ax}_acc_set_m_s2");
        self.set_mm = nominal(set.clone())
            .ok_or_else(|| missing(&set))?
            .iter()
            .map(|v| v * 1e3)
            .collect();
        self.acc_set_m_s2 = nominal(acc.clone()).ok_or_else(|| missing(&acc))?;
        self.compensated_um = Axis::ALL
            .into_iter()
            .filter(|&b| b != ax)
            .filter_map(|b| {
                let set = nominal(format!("{b}_pos_set_m"))?;
                let tcp = run.output_series(cl, &format!("{b}_tcp_m"))?;
                Some((
                    b,
                    tcp.iter().zip(&set).map(|(e, s)| (e - s) * 1e6).collect(),
                ))
            })
            .collect();
        Ok(self)
    }

    /// Whether the move ran with a compensation table: it has the TCP's deviation from the
    /// nominal path ([`MoveData::compensated_um`]).
    pub fn is_compensated(&self) -> bool {
        !self.compensated_um.is_empty()
    }

    /// Whether `plain`, a move without compensation, is this compensated move run without
    /// its table: the same moved axis, the same instants and the same nominal path of every
    /// axis (set columns equal to 1 nm).
    pub fn same_nominal_move(&self, plain: &MoveData) -> bool {
        let close = |a: &[f64], b: &[f64]| {
            a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() <= 1e-6)
        };
        self.is_compensated()
            && !plain.is_compensated()
            && plain.axis == self.axis
            && close(&plain.t_s, &self.t_s)
            && close(&plain.set_mm, &self.set_mm)
            && plain.path_deviation_um.len() == self.compensated_um.len()
            && plain
                .path_deviation_um
                .iter()
                .zip(&self.compensated_um)
                .all(|((a, _), (b, _))| a == b)
    }

    /// Signed distance of the set position, mm.
    pub fn distance_mm(&self) -> f64 {
        self.set_mm.last().copied().unwrap_or(0.0) - self.set_mm.first().copied().unwrap_or(0.0)
    }

    /// Largest |set acceleration|, m/s².
    pub fn peak_accel_m_s2(&self) -> f64 {
        self.acc_set_m_s2.iter().fold(0.0, |m, a| m.max(a.abs()))
    }

    /// Largest |set velocity| from differences of the set position, m/s.
    pub fn peak_velocity_m_s(&self) -> f64 {
        peak_rate(&self.t_s, &self.set_mm) * 1e-3
    }

    /// Largest |set jerk| from differences of the set acceleration, m/s³.
    pub fn peak_jerk_m_s3(&self) -> f64 {
        peak_rate(&self.t_s, &self.acc_set_m_s2)
    }
}

fn peak_rate(t: &[f64], v: &[f64]) -> f64 {
    t.windows(2)
        .zip(v.windows(2))
        .map(|(t, v)| ((v[1] - v[0]) / (t[1] - t[0])).abs())
        .fold(0.0, f64::max)
}

/// The move figure: three panels over time with a shared time axis.
pub fn move_svg(data: &MoveData, cond: &Conditions) -> Result<String, ReportError> {
    let ax = data.axis;
    let n = data.t_s.len();
    let idx: Vec<usize> = svg::decimate(n, MAX_POINTS).collect();
    let series =
        |v: &[f64]| -> Vec<(f64, f64)> { idx.iter().map(|&i| (data.t_s[i], v[i])).collect() };
    let (t0, t1) = (data.t_s[0], data.t_s[n - 1]);
    let title = format!(
        "Positioning move of axis {}: set vs actual, TCP cross-talk",
        ax.letter()
    );
    // The planned profile where known; else estimates from the samples (marked ≈).
    let (v, a, j, approx) = match &data.plan {
        Some(p) => (p.peak_velocity_m_s, p.peak_accel_m_s2, p.jerk_m_s3, ""),
        None => (
            data.peak_velocity_m_s(),
            data.peak_accel_m_s2(),
            data.peak_jerk_m_s3(),
            "≈ ",
        ),
    };
    let lines = vec![
        format!(
            "distance {} mm  ·  peak set velocity {approx}{} m/s ({} mm/min)  ·  peak set acceleration {approx}{} m/s²  ·  peak set jerk {approx}{} m/s³",
            short(data.distance_mm(), 3),
            short(v, 4),
            short(v * 60_000.0, 0),
            short(a, 3),
            short(j, 0)
        ),
        cond.line("move start"),
    ];
    let t_dec = svg::decimals_for(t1 - t0);
    type Panel<'a> = (
        String,
        Vec<(String, RGBColor, Vec<(f64, f64)>)>,
        Vec<String>,
    );
    let panels: Vec<Panel> = vec![
        (
            format!("{ax} / mm"),
            vec![
                (format!("{ax} set"), svg::SET, series(&data.set_mm)),
                (
                    format!("{ax} internal (scale)"),
                    svg::INTERNAL,
                    series(&data.int_mm),
                ),
            ],
            vec![],
        ),
        (
            format!("ä{ax} / (m/s²)"),
            vec![
                (format!("ä{ax} set"), svg::SET, series(&data.acc_set_m_s2)),
                (
                    format!("ä{ax} actual (scale)"),
                    svg::INTERNAL,
                    series(&data.acc_act_m_s2),
                ),
            ],
            vec![],
        ),
        (
            "deviation / µm".to_string(),
            if data.uncompensated_um.is_empty() {
                &data.cross_talk_um
            } else {
                &data.uncompensated_um
            }
            .iter()
            .zip([svg::EXTERNAL, svg::SECOND])
            .map(|((b, v), c)| {
                let label = if !data.uncompensated_um.is_empty() {
                    format!("d{b} without compensation (TCP − nominal path)")
                } else if data.compensated_um.is_empty() {
                    format!("d{b} = {b}_ext − {b}_int")
                } else {
                    format!("d{b} ≈ without compensation ({b}_ext − {b}_int)")
                };
                (label, c, series(v))
            })
            .chain(
                data.compensated_um
                    .iter()
                    .zip([svg::SET, svg::INTERNAL])
                    .map(|((b, v), c)| {
                        (
                            format!("d{b} with compensation (TCP − nominal path)"),
                            c,
                            series(v),
                        )
                    }),
            )
            .collect(),
            if data.compensated_um.is_empty() {
                vec![
                    format!("cross-talk: TCP deviation of"),
                    format!("the other axes while {ax} moves"),
                ]
            } else if !data.uncompensated_um.is_empty() {
                vec![
                    format!("cross-talk while {ax} moves:"),
                    format!("TCP − nominal path of the"),
                    format!("same move without and with"),
                    format!("the compensation table"),
                ]
            } else {
                vec![
                    format!("cross-talk while {ax} moves:"),
                    format!("TCP − nominal path with the"),
                    format!("compensation table; the"),
                    format!("structure's ext − int, which"),
                    format!("it does not change, stands"),
                    format!("for the move without it (the"),
                    format!("plain move's file on the same"),
                    format!("page replaces it exactly)"),
                ]
            },
        ),
    ];
    let header_px = 16 + 30 + 22 * lines.len() as u32 + 6;
    let panel_px = 300u32;
    svg::render((1400, header_px + 3 * panel_px), |root| {
        let body = svg::header(root, &title, &lines)?;
        let rows = body.split_evenly((3, 1));
        for (row, (y_desc, curves, notes)) in rows.iter().zip(&panels) {
            let (left, right) = row.split_horizontally(1060);
            let (lo, hi) =
                svg::padded_range(curves.iter().flat_map(|c| c.2.iter().map(|p| p.1)), 0.06);
            let mut chart = ChartBuilder::on(&left)
                .margin(10)
                .x_label_area_size(45)
                .y_label_area_size(80)
                .build_cartesian_2d(t0..t1, lo..hi)?;
            svg::mesh(
                &mut chart,
                "time t / s",
                y_desc,
                t_dec,
                svg::decimals_for(hi - lo),
            )?;
            // The first curve (the set point, or the main trace) is drawn last and thinner,
            // over wider ones: where traces coincide (zero after the move) the one on top
            // shows with an even rim instead of alternating dashes of both colours.
            for (i, (_, color, pts)) in curves.iter().enumerate().rev() {
                let width = if i == 0 { 1 } else { 3 };
                chart.draw_series(LineSeries::new(pts.clone(), color.stroke_width(width)))?;
            }
            let legend: Vec<Entry> = curves
                .iter()
                .map(|(label, color, _)| Entry::new(label.clone(), *color, Mark::Line))
                .collect();
            svg::side_panel(&right, &legend, notes)?;
        }
        Ok(())
    })
}
