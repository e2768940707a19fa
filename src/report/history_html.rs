//! The history section of the report (`eij report --history RUN…`): the runs, the quantities
//! that drifted, and per plane and circle centre a table of every EIJ and every term that stands
//! out, value ± standard error per run, with a small trend plot each (value over the days since
//! the first run, ±1 standard error bars, the first run's value as a grey line, drift in the
//! verdict's red).

use std::fmt::Write as _;

use plotters::prelude::*;

use super::diagnosis_html::FAIL;
use super::page::{escape, Page};
use super::svg::{self, padded_range, render};
use super::ReportError;
use crate::measured::history::{History, QuantityHistory, DRIFT_Z};
use crate::text::unit_symbol;

/// The colour of a run within its noise of the first.
pub(crate) const STEADY: RGBColor = RGBColor(31, 119, 180);
/// The colour of drift: the verdict's FAIL red.
pub(crate) const DRIFT: RGBColor = RGBColor(187, 34, 34);
/// Size of a trend plot, px.
const SIZE: (u32, u32) = (280, 110);

/// The trend plot of one quantity: value ± standard error over the days since the first run.
pub(crate) fn trend_svg(h: &History, q: &QuantityHistory) -> Result<String, ReportError> {
    let days = |run: usize| h.runs[run].days;
    let (x0, x1) = padded_range(q.points.iter().map(|p| days(p.run)), 0.08);
    let (y0, y1) = padded_range(
        q.points
            .iter()
            .flat_map(|p| [p.value - p.std_err, p.value + p.std_err]),
        0.1,
    );
    let decimals = svg::decimals_for(y1 - y0);
    render(SIZE, |area| {
        let mut chart = ChartBuilder::on(area)
            .margin(6)
            .x_label_area_size(18)
            .y_label_area_size(52)
            .build_cartesian_2d(x0..x1, y0..y1)?;
        let yf = move |v: &f64| super::short(*v, decimals);
        let xf = |v: &f64| super::short(*v, 0);
        chart
            .configure_mesh()
            .light_line_style(WHITE)
            .x_labels(4)
            .y_labels(3)
            .x_label_formatter(&xf)
            .y_label_formatter(&yf)
            .label_style((svg::FONT, 11.0))
            .draw()?;
        if let Some(first) = q.points.first() {
            chart.draw_series(LineSeries::new(
                [(x0, first.value), (x1, first.value)],
                RGBColor(170, 170, 170).stroke_width(1),
            ))?;
        }
        chart.draw_series(LineSeries::new(
            q.points.iter().map(|p| (days(p.run), p.value)),
            STEADY.stroke_width(1),
        ))?;
        for p in &q.points {
            let c = if p.drift { DRIFT } else { STEADY };
            let x = days(p.run);
            chart.draw_series(LineSeries::new(
                [(x, p.value - p.std_err), (x, p.value + p.std_err)],
                c.stroke_width(2),
            ))?;
            chart.draw_series([Circle::new((x, p.value), 3, c.filled())])?;
        }
        Ok(())
    })
}

/// Appends the history section to `page`.
pub(crate) fn section(page: &mut Page, h: &History) -> Result<(), ReportError> {
    page.heading(2, "history", "History");
    let mut out = String::new();
    let machine = h
        .machine
        .as_deref()
        .unwrap_or("a machine not named in rtest.toml");
    let _ = writeln!(
        out,
        "<p>{} runs of {}. Per plane and circle centre: each EIJ as the weighted mean over the \
         run's tests, each term of the diagnosis as its part at no acceleration over the run's \
         tests (docs/diagnosis.md); drift: a change from the first run beyond {DRIFT_Z} combined \
         standard errors, |Δ| &gt; {DRIFT_Z}·√(σ² + σ₁²).</p>\n<table>\n<tr><th>run</th>\
         <th class=\"l\">date</th><th>days</th><th>tests</th><th class=\"l\">source</th></tr>",
        h.runs.len(),
        escape(machine)
    );
    for (i, r) in h.runs.iter().enumerate() {
        let _ = writeln!(
            out,
            "<tr><td>{}</td><td class=\"l\">{}</td><td>{:.1}</td><td>{}</td><td class=\"l\">{}</td></tr>",
            i + 1,
            escape(&r.date),
            r.days,
            r.tests,
            escape(&r.source)
        );
    }
    out.push_str("</table>\n");
    let drifted: Vec<&QuantityHistory> = h.drifted().collect();
    if drifted.is_empty() {
        out.push_str("<p><b>Drift:</b> none.</p>\n");
    } else {
        let _ = writeln!(
            out,
            "<p class=\"{FAIL}\"><b>Drift in {} quantities:</b></p>\n<ul class=\"warn\">",
            drifted.len()
        );
        for q in &drifted {
            for p in q.points.iter().filter(|p| p.drift) {
                let _ = writeln!(
                    out,
                    "<li class=\"{FAIL}\">{} {}: {:+.4} ± {:.4} {} by {} (z = {:+.1})</li>",
                    escape(&q.group),
                    escape(&q.label()),
                    p.change.unwrap_or(f64::NAN),
                    p.change_std_err.unwrap_or(f64::NAN),
                    unit_symbol(&q.unit),
                    escape(&p.date),
                    p.z.unwrap_or(f64::NAN)
                );
            }
        }
        out.push_str("</ul>\n");
    }
    let mut group = None;
    for q in h.quantities.iter().filter(|q| q.stands_out || q.drift) {
        if group != Some(&q.group) {
            if group.is_some() {
                out.push_str("</table>\n");
            }
            let _ = write!(
                out,
                "<h4>{}</h4>\n<table class=\"history\">\n<tr><th class=\"l\">quantity</th>\
                 <th class=\"l\">unit</th>",
                escape(&q.group)
            );
            for r in &h.runs {
                let _ = write!(out, "<th>{}</th>", escape(&r.date));
            }
            out.push_str("<th>trend over the days since the first run</th></tr>\n");
            group = Some(&q.group);
        }
        let _ = write!(
            out,
            "<tr><th class=\"l\">{}</th><td class=\"l\">{}</td>",
            escape(&q.label()),
            unit_symbol(&q.unit)
        );
        for i in 0..h.runs.len() {
            match q.points.iter().find(|p| p.run == i) {
                Some(p) if p.drift => {
                    let _ = write!(
                        out,
                        "<td class=\"{FAIL}\">{:.4} ± {:.4}<br><small>z = {:+.1}</small></td>",
                        p.value,
                        p.std_err,
                        p.z.unwrap_or(f64::NAN)
                    );
                }
                Some(p) => {
                    let _ = write!(out, "<td>{:.4} ± {:.4}</td>", p.value, p.std_err);
                }
                None => out.push_str("<td>–</td>"),
            }
        }
        let svg = super::page::inline_svg(
            &trend_svg(h, q)?,
            &format!("{} {} over time", q.group, q.label()),
        );
        let _ = writeln!(out, "<td class=\"trend\">{svg}</td></tr>");
    }
    if group.is_some() {
        out.push_str("</table>\n");
    }
    page.push(&out);
    Ok(())
}
