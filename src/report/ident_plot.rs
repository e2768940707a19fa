//! Identification figure from the report JSON of `eij identify` (keys of
//! [`crate::ident::report::report_json`]): measured vs simulated EIJ before and after, one panel
//! per parameter with one column per test, and the cost over the iterations (log scale).

use std::collections::BTreeMap;

use plotters::prelude::*;
use serde_json::Value;

use super::svg::{self, Entry, Mark};
use super::{short, ReportError};
use crate::axes::Eij;

/// One test of the identification report.
#[derive(Debug, Clone, PartialEq)]
pub struct IdentTest {
    /// Source file or table, where given.
    pub source: Option<String>,
    /// Plane name.
    pub plane: String,
    /// Direction name.
    pub direction: String,
    /// Set acceleration, m/s².
    pub accel_m_s2: f64,
    /// Measured EIJ, µm·s²/m.
    pub measured: BTreeMap<Eij, f64>,
    /// Their standard errors, where given.
    pub measured_std_err: BTreeMap<Eij, f64>,
    /// Simulated before identification.
    pub simulated_initial: BTreeMap<Eij, f64>,
    /// Simulated after identification.
    pub simulated_final: BTreeMap<Eij, f64>,
}

impl IdentTest {
    /// Short label, e.g. `zx ccw 4`.
    pub fn label(&self) -> String {
        format!(
            "{} {} {}",
            self.plane,
            self.direction,
            short(self.accel_m_s2, 2)
        )
    }
}

/// One identified parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct IdentParameter {
    /// Name, e.g. `z.guideway_normal`.
    pub name: String,
    /// Start value.
    pub initial: f64,
    /// Identified value.
    pub identified: f64,
    /// Standard error (absent when not identifiable).
    pub std_err: Option<f64>,
    /// Whether the data determine it.
    pub identifiable: Option<bool>,
}

/// The parts of the identification report the report draws and tabulates.
#[derive(Debug, Clone, PartialEq)]
pub struct IdentReport {
    /// Parameters.
    pub parameters: Vec<IdentParameter>,
    /// Correlation matrix of the parameters.
    pub correlation: Vec<Vec<f64>>,
    /// Cost before.
    pub cost_initial: f64,
    /// Cost after.
    pub cost_final: f64,
    /// Cost per iteration (`cost_history`; [initial, final] when absent).
    pub cost_history: Vec<f64>,
    /// Machine file, where given.
    pub machine: Option<String>,
    /// Tests.
    pub tests: Vec<IdentTest>,
}

fn key_err(key: &str, message: &str) -> ReportError {
    ReportError::Key {
        key: key.to_string(),
        message: message.to_string(),
    }
}

fn field<'a>(v: &'a Value, path: &str, key: &str) -> Result<&'a Value, ReportError> {
    let full = if path.is_empty() {
        key.to_string()
    } else {
        format!("{path}.{key}")
    };
    v.get(key).ok_or_else(|| key_err(&full, "missing"))
}

fn number(v: &Value, key: &str) -> Result<f64, ReportError> {
    v.as_f64().ok_or_else(|| key_err(key, "expected a number"))
}

fn eij_map(v: &Value, key: &str) -> Result<BTreeMap<Eij, f64>, ReportError> {
    let obj = v
        .as_object()
        .ok_or_else(|| key_err(key, "expected an object of EIJ values"))?;
    obj.iter()
        .map(|(k, x)| {
            let p: Eij = k
                .parse()
                .map_err(|e: String| key_err(&format!("{key}.{k}"), &e))?;
            // The report writes NaN (as null) where a simulation lacks a parameter.
            let val = if x.is_null() {
                f64::NAN
            } else {
                number(x, &format!("{key}.{k}"))?
            };
            Ok((p, val))
        })
        .collect()
}

impl IdentReport {
    /// Reads the keys the report needs, naming the first missing or malformed one.
    pub fn parse(report: &Value) -> Result<Self, ReportError> {
        let params = field(report, "", "parameters")?
            .as_array()
            .ok_or_else(|| key_err("parameters", "expected an array"))?;
        let parameters = params
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let at = format!("parameters[{i}]");
                let name = field(p, &at, "name")?
                    .as_str()
                    .ok_or_else(|| key_err(&format!("{at}.name"), "expected a string"))?
                    .to_string();
                Ok(IdentParameter {
                    name,
                    initial: number(field(p, &at, "initial")?, &format!("{at}.initial"))?,
                    identified: number(field(p, &at, "identified")?, &format!("{at}.identified"))?,
                    std_err: p.get("std_err").and_then(Value::as_f64),
                    identifiable: p.get("identifiable").and_then(Value::as_bool),
                })
            })
            .collect::<Result<Vec<_>, ReportError>>()?;
        let n = parameters.len();
        let correlation = field(report, "", "correlation")?
            .as_array()
            .ok_or_else(|| key_err("correlation", "expected an array of rows"))?
            .iter()
            .enumerate()
            .map(|(i, row)| {
                let at = format!("correlation[{i}]");
                let row = row
                    .as_array()
                    .filter(|r| r.len() == n)
                    .ok_or_else(|| key_err(&at, &format!("expected a row of {n} numbers")))?;
                Ok(row.iter().map(|x| x.as_f64().unwrap_or(f64::NAN)).collect())
            })
            .collect::<Result<Vec<Vec<f64>>, ReportError>>()?;
        if correlation.len() != n {
            return Err(key_err(
                "correlation",
                &format!("{} rows for {n} parameters", correlation.len()),
            ));
        }
        let cost_initial = number(field(report, "", "cost_initial")?, "cost_initial")?;
        let cost_final = number(field(report, "", "cost_final")?, "cost_final")?;
        let cost_history = match report.get("cost_history") {
            None => vec![cost_initial, cost_final],
            Some(h) => h
                .as_array()
                .ok_or_else(|| key_err("cost_history", "expected an array of numbers"))?
                .iter()
                .enumerate()
                .map(|(i, c)| number(c, &format!("cost_history[{i}]")))
                .collect::<Result<_, _>>()?,
        };
        let tests = field(report, "", "tests")?
            .as_array()
            .ok_or_else(|| key_err("tests", "expected an array"))?
            .iter()
            .enumerate()
            .map(|(i, t)| {
                let at = format!("tests[{i}]");
                let text = |k: &str| -> Result<String, ReportError> {
                    Ok(field(t, &at, k)?
                        .as_str()
                        .ok_or_else(|| key_err(&format!("{at}.{k}"), "expected a string"))?
                        .to_string())
                };
                let map = |k: &str| eij_map(field(t, &at, k)?, &format!("{at}.{k}"));
                Ok(IdentTest {
                    source: t.get("source").and_then(Value::as_str).map(str::to_string),
                    plane: text("plane")?,
                    direction: text("direction")?,
                    accel_m_s2: number(field(t, &at, "accel_m_s2")?, &format!("{at}.accel_m_s2"))?,
                    measured: map("measured")?,
                    measured_std_err: match t.get("measured_std_err") {
                        Some(v) => eij_map(v, &format!("{at}.measured_std_err"))?,
                        None => BTreeMap::new(),
                    },
                    simulated_initial: map("simulated_initial")?,
                    simulated_final: map("simulated_final")?,
                })
            })
            .collect::<Result<Vec<_>, ReportError>>()?;
        if tests.is_empty() {
            return Err(key_err("tests", "no tests"));
        }
        Ok(IdentReport {
            parameters,
            correlation,
            cost_initial,
            cost_final,
            cost_history,
            machine: report
                .get("machine")
                .and_then(Value::as_str)
                .map(str::to_string),
            tests,
        })
    }

    /// The EIJ measured in at least one test, in parameter order.
    pub fn eij_parameters(&self) -> Vec<Eij> {
        let mut all: Vec<Eij> = self
            .tests
            .iter()
            .flat_map(|t| t.measured.keys().copied())
            .collect();
        all.sort();
        all.dedup();
        all
    }
}

/// The identification figure from the report JSON of `eij identify`: per EIJ one panel with
/// the measured values (± 2 standard errors) and the simulated values before and after, per
/// test; and the cost over the iterations on a log scale.
pub fn identification_svg(report: &Value) -> Result<String, ReportError> {
    let rep = IdentReport::parse(report)?;
    let params = rep.eij_parameters();
    let cols = 3usize;
    let cells = params.len() + 1;
    let rows = cells.div_ceil(cols);
    let (cell_w, cell_h) = (520u32, 380u32);
    let title = "Identification: measured vs simulated EIJ before and after, cost";
    let mut lines = vec![format!(
        "{} tests  ·  {} parameters  ·  cost {} → {} in {} iterations (sum of squared weighted residuals)",
        rep.tests.len(),
        rep.parameters.len(),
        short(rep.cost_initial, 4),
        short(rep.cost_final, 4),
        rep.cost_history.len().saturating_sub(1)
    )];
    if let Some(h0) = rep.cost_history.first() {
        if (h0 - rep.cost_initial).abs() > 0.01 * rep.cost_initial.abs() {
            lines.push(format!(
                "note: the cost history starts at {} (cost_history[0]), not at cost_initial = {}",
                short(*h0, 4),
                short(rep.cost_initial, 4)
            ));
        }
    }
    if let Some(m) = &rep.machine {
        lines.push(format!(
            "machine: {m}  ·  tests labelled plane, direction, set acceleration / (m/s²)"
        ));
    } else {
        lines.push("tests labelled plane, direction, set acceleration / (m/s²)".into());
    }
    let legend = vec![
        Entry::new("measured ± 2 std err", svg::SET, Mark::DotBar),
        Entry::new("simulated, initial", svg::INITIAL, Mark::Ring),
        Entry::new("simulated, identified", svg::FIT, Mark::Dot),
        Entry::new("cost per iteration", svg::INTERNAL, Mark::Line),
    ];
    let header_px = 16 + 30 + 22 * lines.len() as u32 + 6;
    let side_px = 260u32;
    svg::render(
        (
            cols as u32 * cell_w + side_px,
            header_px + rows as u32 * cell_h,
        ),
        |root| {
            let body = svg::header(root, title, &lines)?;
            let (grid, side) = body.split_horizontally(cols as u32 * cell_w);
            let areas = grid.split_evenly((rows, cols));
            for (area, p) in areas.iter().zip(&params) {
                parameter_panel(area, &rep, *p)?;
            }
            cost_panel(&areas[params.len()], &rep.cost_history)?;
            svg::side_panel(&side, &legend, &[])
        },
    )
}

fn parameter_panel(area: &svg::Area, rep: &IdentReport, p: Eij) -> Result<(), ReportError> {
    let tests: Vec<&IdentTest> = rep
        .tests
        .iter()
        .filter(|t| t.measured.contains_key(&p))
        .collect();
    let n = tests.len();
    let se = |t: &IdentTest| t.measured_std_err.get(&p).copied().unwrap_or(0.0);
    let values = tests.iter().flat_map(|t| {
        let m = t.measured[&p];
        [
            m - 2.0 * se(t),
            m + 2.0 * se(t),
            t.simulated_initial.get(&p).copied().unwrap_or(f64::NAN),
            t.simulated_final.get(&p).copied().unwrap_or(f64::NAN),
        ]
    });
    let (lo, hi) = svg::padded_range(values, 0.08);
    let labels: Vec<String> = tests.iter().map(|t| t.label()).collect();
    let label_of = move |v: &SegmentValue<usize>| match v {
        SegmentValue::CenterOf(i) | SegmentValue::Exact(i) => {
            labels.get(*i).cloned().unwrap_or_default()
        }
        SegmentValue::Last => String::new(),
    };
    let dec = svg::decimals_for(hi - lo);
    let yf = move |v: &f64| short(*v, dec);
    let mut chart = ChartBuilder::on(area)
        .margin(8)
        .caption(
            format!("{p} / (µm·s²/m)"),
            (svg::FONT, svg::DESC_SIZE + 2.0),
        )
        .x_label_area_size(78)
        .y_label_area_size(62)
        .build_cartesian_2d((0..n).into_segmented(), lo..hi)?;
    chart
        .configure_mesh()
        .light_line_style(WHITE)
        .bold_line_style(RGBColor(225, 225, 225))
        .disable_x_mesh()
        .x_labels(n + 1)
        .y_labels(8)
        .x_label_formatter(&label_of)
        .y_label_formatter(&yf)
        .x_label_style(
            (svg::FONT, svg::LABEL_SIZE - 2.0)
                .into_font()
                .transform(FontTransform::Rotate90),
        )
        .y_label_style((svg::FONT, svg::LABEL_SIZE))
        .draw()?;
    for (i, t) in tests.iter().enumerate() {
        let m = t.measured[&p];
        let x = || SegmentValue::CenterOf(i);
        let s = se(t);
        if s > 0.0 {
            chart.draw_series(std::iter::once(PathElement::new(
                vec![(x(), m - 2.0 * s), (x(), m + 2.0 * s)],
                svg::ERROR_BAR.stroke_width(1),
            )))?;
        }
        chart.draw_series(std::iter::once(Circle::new((x(), m), 4, svg::SET.filled())))?;
        if let Some(v) = t.simulated_initial.get(&p).filter(|v| v.is_finite()) {
            chart.draw_series(std::iter::once(Circle::new(
                (x(), *v),
                5,
                svg::INITIAL.stroke_width(2),
            )))?;
        }
        if let Some(v) = t.simulated_final.get(&p).filter(|v| v.is_finite()) {
            chart.draw_series(std::iter::once(Circle::new(
                (x(), *v),
                3,
                svg::FIT.filled(),
            )))?;
        }
    }
    Ok(())
}

fn cost_panel(area: &svg::Area, history: &[f64]) -> Result<(), ReportError> {
    let positive: Vec<f64> = history
        .iter()
        .copied()
        .filter(|c| c.is_finite() && *c > 0.0)
        .collect();
    let lo = positive.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = positive.iter().copied().fold(0.0, f64::max);
    let (lo, hi) = if lo.is_finite() && hi > 0.0 {
        (lo / 2.0, hi * 2.0)
    } else {
        (1e-3, 1.0)
    };
    let last = history.len().saturating_sub(1).max(1) as f64;
    let mut chart = ChartBuilder::on(area)
        .margin(8)
        .caption(
            "cost over iterations (log scale)",
            (svg::FONT, svg::DESC_SIZE + 2.0),
        )
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d(-0.2..last + 0.2, (lo..hi).log_scale())?;
    let xf = |v: &f64| short(*v, 1);
    let yf = |v: &f64| format!("{v:.1e}");
    chart
        .configure_mesh()
        .light_line_style(WHITE)
        .bold_line_style(RGBColor(225, 225, 225))
        .x_desc("iteration")
        .y_desc("cost (dimensionless)")
        .x_labels(history.len().clamp(2, 10))
        .x_label_formatter(&xf)
        .y_label_formatter(&yf)
        .label_style((svg::FONT, svg::LABEL_SIZE))
        .axis_desc_style((svg::FONT, svg::DESC_SIZE))
        .draw()?;
    let pts: Vec<(f64, f64)> = history
        .iter()
        .enumerate()
        .filter(|(_, c)| c.is_finite() && **c > 0.0)
        .map(|(i, c)| (i as f64, *c))
        .collect();
    chart.draw_series(LineSeries::new(pts.clone(), svg::INTERNAL.stroke_width(2)))?;
    chart.draw_series(
        pts.into_iter()
            .map(|p| Circle::new(p, 3, svg::INTERNAL.filled())),
    )?;
    Ok(())
}
