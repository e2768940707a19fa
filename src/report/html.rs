//! The report folder: `report.html` with inline tables and `<img>` links to the SVG figures it
//! writes next to it. Readable offline: no external CSS, scripts, fonts or links; the only
//! references are to files of the report itself.
//!
//! Files the report owns in its folder (and the only ones it writes): `report.html`,
//! `circle-NN-<stem>.svg`, `out-of-plane-NN-<stem>.svg`, `move-NN-<stem>.svg`,
//! `identification.svg`, and the `file_name`s of [`ReportRequest::extra_figures`]. NN is the
//! 1-based index of the input, so equal file names from different folders do not collide.
//! Everything is read, evaluated and drawn before the first file is written; each file is
//! written atomically.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::ident_plot::test_label;
use super::{identification_svg, move_svg, short, CircleView, Conditions, MoveData, ReportError};
use crate::axes::Plane;
use crate::ident::report::IdentReport;
use crate::rtest::suite::EvaluatedTest;
use crate::rtest::{CircleResult, EvalOptions};

/// The report page's file name.
pub const REPORT_FILE: &str = "report.html";

/// A figure of the report: an SVG written as `file_name` into the report folder and shown
/// with its caption. The hook for further figures (e.g. EIJ maps over the workspace).
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// File name inside the report folder (no folders), ending in `.svg`.
    pub file_name: String,
    /// Caption below the figure.
    pub caption: String,
    /// The SVG text.
    pub svg: String,
}

/// What goes into a report.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ReportRequest {
    /// R-Test CSV files and folders of them (folders: every `*.csv`, sorted).
    pub measured: Vec<PathBuf>,
    /// Report JSON of `eij identify`.
    pub identify_report: Option<PathBuf>,
    /// Simulated move CSVs (`eij simulate move`).
    pub moves: Vec<PathBuf>,
    /// Further figures, e.g. EIJ maps.
    pub extra_figures: Vec<Figure>,
    /// The report folder (created if missing; an existing file there is refused).
    pub out_dir: PathBuf,
}

/// One evaluated circle test with its figures.
struct CircleEntry {
    path: PathBuf,
    result: CircleResult,
    circle: Figure,
    out_of_plane: Figure,
    conditions: Conditions,
}

/// Expands files and folders (see [`crate::rtest::inputs::expand_inputs`]).
pub fn expand_measured(paths: &[PathBuf]) -> Result<Vec<PathBuf>, ReportError> {
    Ok(crate::rtest::inputs::expand_inputs(paths)?)
}

/// `folder/name` of a path: the name alone is ambiguous when several folders (test positions)
/// hold files of the same name.
fn folder_and_name(path: &Path) -> String {
    let name = path
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_default();
    match path.parent().and_then(|p| p.file_name()) {
        Some(dir) => format!("{}/{name}", dir.to_string_lossy()),
        None => name,
    }
}

/// A file-name-safe stem of `path`.
fn stem(path: &Path) -> String {
    let s: String = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' || c == '.' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if s.is_empty() {
        "data".into()
    } else {
        s
    }
}

/// Text made safe inside HTML.
pub(crate) fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// An EIJ value as written in the tables (4 decimals).
pub fn fmt_eij(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.4}")
    } else {
        "–".into()
    }
}

/// The figures of an evaluated test (evaluated as `eij evaluate` does, see
/// [`crate::rtest::suite`]).
fn circle_entry(t: EvaluatedTest, index: usize) -> Result<CircleEntry, ReportError> {
    let path = t.input.primary_file().to_path_buf();
    let path = path.as_path();
    let opts = EvalOptions {
        plane: Some(t.result.plane),
        radius_mm: Some(t.result.radius_mm),
    };
    let result = t.result;
    let view = CircleView::new(&t.series, &opts)?;
    let conditions = Conditions {
        source: t.input.name(),
        machine: None,
        position_mm: t.input.position_mm.clone(),
    };
    let s = stem(path);
    let caption = format!(
        "{}: plane {}, {}, r = {} mm, {} m/s², {} Hz",
        conditions.source,
        result.plane,
        result.direction,
        short(result.radius_mm, 4),
        short(result.accel_m_s2, 3),
        short(result.freq_hz, 3)
    );
    Ok(CircleEntry {
        circle: Figure {
            file_name: format!("circle-{index:02}-{s}.svg"),
            caption: format!("{caption}; deviations ×{}", short(view.magnification, 0)),
            svg: view.magnified_svg(&conditions)?,
        },
        out_of_plane: Figure {
            file_name: format!("out-of-plane-{index:02}-{s}.svg"),
            caption: format!("{caption}; out-of-plane deviation and fitted plane"),
            svg: view.out_of_plane_svg(&conditions)?,
        },
        path: path.to_path_buf(),
        result,
        conditions,
    })
}

fn read_identification(path: &Path) -> Result<(IdentReport, Figure), ReportError> {
    let name = path.display().to_string();
    let bytes = super::read_file(path)?;
    if let Err(e) = serde_json::from_slice::<serde::de::IgnoredAny>(&bytes) {
        return Err(ReportError::BadInput {
            source_name: name,
            message: format!("not valid JSON: {e}"),
        });
    }
    let rep = IdentReport::from_json(&bytes).map_err(|e| ReportError::BadInput {
        source_name: name.clone(),
        message: e.to_string(),
    })?;
    let svg = identification_svg(&rep)?;
    Ok((
        rep,
        Figure {
            file_name: "identification.svg".into(),
            caption: format!(
                "Identification {}: measured EIJ (± 2 std err) and simulated before/after per test; cost per iteration",
                path.display()
            ),
            svg,
        },
    ))
}

/// Reads, evaluates and draws everything, then writes the report folder. Returns the files
/// written (report.html last).
pub fn generate(req: &ReportRequest) -> Result<Vec<PathBuf>, ReportError> {
    let out = &req.out_dir;
    let out_name = out.display().to_string();
    if out.exists() && !out.is_dir() {
        return Err(ReportError::Output {
            path: out_name,
            message: "exists and is not a folder".into(),
        });
    }
    // The report folder itself may be created, its parent must exist (like every output).
    if let Some(parent) = out.parent().filter(|p| !p.as_os_str().is_empty()) {
        if !parent.is_dir() {
            return Err(ReportError::Output {
                path: out_name,
                message: format!("folder {} does not exist", parent.display()),
            });
        }
    }
    // Never write the report into a folder of measured inputs.
    if let Ok(o) = out.canonicalize() {
        if req.measured.iter().any(|m| {
            m.is_dir()
                && m.canonicalize()
                    .is_ok_and(|m| o.starts_with(&m) || m.starts_with(&o))
        }) {
            return Err(ReportError::Output {
                path: out_name,
                message: "is (or holds) a folder of measured inputs; choose another report folder"
                    .into(),
            });
        }
    }
    for f in &req.extra_figures {
        if f.file_name.contains(['/', '\\']) || !f.file_name.ends_with(".svg") {
            return Err(ReportError::Output {
                path: f.file_name.clone(),
                message: "an extra figure needs a plain file name ending in .svg".into(),
            });
        }
    }
    let files = expand_measured(&req.measured)?;
    let tests = crate::rtest::inputs::expand_tests(&req.measured)?;
    let suite = crate::rtest::suite::evaluate_tests(&tests, &Default::default())?;
    let circles = suite
        .tests
        .into_iter()
        .enumerate()
        .map(|(i, t)| circle_entry(t, i + 1))
        .collect::<Result<Vec<_>, _>>()?;
    let ident = req
        .identify_report
        .as_deref()
        .map(read_identification)
        .transpose()?;
    let moves = req
        .moves
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let data = MoveData::read_csv(p)?;
            let cond = Conditions {
                source: p.display().to_string(),
                ..Default::default()
            };
            Ok((
                data.clone(),
                Figure {
                    file_name: format!("move-{:02}-{}.svg", i + 1, stem(p)),
                    caption: format!(
                        "{}: move of {} by {} mm, peak set acceleration {} m/s²",
                        p.display(),
                        data.axis,
                        short(data.distance_mm(), 3),
                        short(data.peak_accel_m_s2(), 3)
                    ),
                    svg: move_svg(&data, &cond)?,
                },
            ))
        })
        .collect::<Result<Vec<_>, ReportError>>()?;

    let html = page(req, &circles, ident.as_ref(), &moves);
    let mut outputs: Vec<(String, Vec<u8>)> = Vec::new();
    for c in &circles {
        for f in [&c.circle, &c.out_of_plane] {
            outputs.push((f.file_name.clone(), f.svg.clone().into_bytes()));
        }
    }
    for (_, f) in &moves {
        outputs.push((f.file_name.clone(), f.svg.clone().into_bytes()));
    }
    if let Some((_, f)) = &ident {
        outputs.push((f.file_name.clone(), f.svg.clone().into_bytes()));
    }
    for f in &req.extra_figures {
        outputs.push((f.file_name.clone(), f.svg.clone().into_bytes()));
    }
    outputs.push((REPORT_FILE.into(), html.into_bytes()));

    let mut inputs: Vec<&Path> = files.iter().map(PathBuf::as_path).collect();
    inputs.extend(req.identify_report.as_deref());
    inputs.extend(req.moves.iter().map(PathBuf::as_path));
    std::fs::create_dir(out)
        .or_else(|e| if out.is_dir() { Ok(()) } else { Err(e) })
        .map_err(|e| ReportError::Output {
            path: out_name,
            message: format!("cannot create folder: {e}"),
        })?;
    let written: Vec<PathBuf> = outputs.iter().map(|(name, _)| out.join(name)).collect();
    let files: Vec<(&Path, &[u8])> = written
        .iter()
        .zip(&outputs)
        .map(|(p, (_, b))| (p.as_path(), b.as_slice()))
        .collect();
    crate::io::write_set(&files, &inputs)?;
    Ok(written)
}

const STYLE: &str = "body{font-family:sans-serif;margin:24px;color:#222;max-width:1500px}\
h1{font-size:26px}h2{font-size:21px;margin-top:36px;border-bottom:1px solid #ccc}\
h3{font-size:16px;margin-bottom:4px}\
table{border-collapse:collapse;margin:8px 0 16px 0;font-size:13px}\
th,td{border:1px solid #ccc;padding:3px 7px;text-align:right;white-space:nowrap}\
th{background:#f0f0f0}td.l,th.l{text-align:left}\
figure{margin:8px 0 24px 0}figcaption{font-size:13px;color:#444}\
img{max-width:100%;height:auto;border:1px solid #ddd}\
.warn{color:#a33;font-size:13px}\
p.note{font-size:13px;color:#444}";

fn figure_html(h: &mut String, f: &Figure) {
    let _ = writeln!(
        h,
        "<figure><img src=\"{}\" alt=\"{}\"><figcaption>{}</figcaption></figure>",
        escape(&f.file_name),
        escape(&f.caption),
        escape(&f.caption)
    );
}

fn page(
    req: &ReportRequest,
    circles: &[CircleEntry],
    ident: Option<&(IdentReport, Figure)>,
    moves: &[(MoveData, Figure)],
) -> String {
    let mut h = String::new();
    let _ = writeln!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <title>eij report</title>\n<style>{STYLE}</style>\n</head>\n<body>"
    );
    let _ = writeln!(
        h,
        "<h1>eij report: acceleration correlated position errors EIJ</h1>"
    );
    let _ = writeln!(
        h,
        "<p class=\"note\">eij {}. EIJ = deviation of the TCP in direction I per set acceleration \
         of axis J, in µm·s²/m (= µm per m/s²), from the joint least-squares fit of \
         d = external − internal over the steady revolutions (paper section 2.2/2.3); standard \
         errors from the residual variance. Inputs: {} circle test(s){}{}.</p>",
        env!("CARGO_PKG_VERSION"),
        circles.len(),
        if moves.is_empty() {
            String::new()
        } else {
            format!(", {} move(s)", moves.len())
        },
        if ident.is_some() {
            ", an identification report"
        } else {
            ""
        }
    );
    if !circles.is_empty() {
        circle_tables(&mut h, circles);
        let _ = writeln!(h, "<h2>Circle tests: figures</h2>");
        let _ = writeln!(
            h,
            "<p class=\"note\">Per test: first the set circle, internal and external paths over the steady \
             revolutions with radial deviations magnified (drawn radius r + M·(ρ − r)) and the \
             fitted ellipses (paper Fig. 5, 8), then the out-of-plane deviation over the phase \
             with the fitted plane (paper Fig. 4, 7).</p>"
        );
        for (i, c) in circles.iter().enumerate() {
            let _ = writeln!(
                h,
                "<h3>{}. {}</h3>\n<p class=\"note\">{}</p>",
                i + 1,
                escape(&c.path.display().to_string()),
                escape(&c.conditions.line("circle centre"))
            );
            for w in &c.result.warnings {
                let _ = writeln!(h, "<p class=\"warn\">warning: {}</p>", escape(w));
            }
            figure_html(&mut h, &c.circle);
            figure_html(&mut h, &c.out_of_plane);
        }
    }
    if !moves.is_empty() {
        let _ = writeln!(h, "<h2>Positioning moves</h2>");
        for (_, f) in moves {
            figure_html(&mut h, f);
        }
        move_vs_circle_html(&mut h, &req.moves, moves, circles);
    }
    if let Some((rep, fig)) = ident {
        identification_html(&mut h, rep, fig);
    }
    if !req.extra_figures.is_empty() {
        let _ = writeln!(h, "<h2>Further figures</h2>");
        for f in &req.extra_figures {
            figure_html(&mut h, f);
        }
    }
    let _ = writeln!(h, "</body>\n</html>");
    h
}

/// EIJ of each move (`eij evaluate-move`) beside the mean of the circle tests that accelerate
/// the same axis.
fn move_vs_circle_html(
    h: &mut String,
    paths: &[PathBuf],
    moves: &[(MoveData, Figure)],
    circles: &[CircleEntry],
) {
    let _ = writeln!(
        h,
        "<h3>EIJ from the moves and from the circles</h3>\n<p class=\"note\">Move: external − \
         internal against the set acceleration over the whole move (with velocity, constant and \
         position terms; docs/compensation.md). Circles: mean over the circle tests above whose \
         plane holds the moved axis. A move's acceleration spreads over 0–30 Hz, a circle's is \
         one line near 8 Hz: they agree where the structure responds alike over that band.</p>"
    );
    let _ = writeln!(
        h,
        "<table>\n<tr><th>move</th><th>EIJ</th><th>move</th><th>± std err</th><th>circles (n)</th></tr>"
    );
    for (path, (data, _)) in paths.iter().zip(moves) {
        let Ok(m) = crate::rtest::moves::evaluate_move(path, data.axis) else {
            let _ = writeln!(
                h,
                "<tr><td>{}</td><td colspan=\"4\">no set acceleration to evaluate</td></tr>",
                escape(&path.display().to_string())
            );
            continue;
        };
        for (e, v) in &m.eij {
            let vals: Vec<f64> = circles
                .iter()
                .filter_map(|c| c.result.eij.get(e))
                .copied()
                .collect();
            let circle = if vals.is_empty() {
                "–".to_string()
            } else {
                format!(
                    "{} ({})",
                    fmt_eij(vals.iter().sum::<f64>() / vals.len() as f64),
                    vals.len()
                )
            };
            let _ = writeln!(
                h,
                "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                escape(&path.display().to_string()),
                e.name(),
                fmt_eij(*v),
                fmt_eij(m.std_err[e]),
                circle
            );
        }
    }
    let _ = writeln!(h, "</table>");
}

fn circle_tables(h: &mut String, circles: &[CircleEntry]) {
    let _ = writeln!(
        h,
        "<h2>Circle tests: EIJ per test (µm·s²/m, ± standard error)</h2>"
    );
    let mut by_plane: BTreeMap<Plane, Vec<(usize, &CircleEntry)>> = BTreeMap::new();
    for (i, c) in circles.iter().enumerate() {
        by_plane.entry(c.result.plane).or_default().push((i + 1, c));
    }
    for (plane, entries) in by_plane {
        let params = plane.parameters();
        let _ = writeln!(h, "<h3>plane {plane}</h3>\n<table>\n<tr><th>#</th><th class=\"l\">file</th><th>dir</th><th>r / mm</th><th>a / (m/s²)</th><th>f / Hz</th><th>rev.</th>");
        for p in params {
            let _ = write!(h, "<th>{p}</th><th>± s.e.</th>");
        }
        let _ = writeln!(h, "<th>rms / µm</th></tr>");
        for (i, c) in entries {
            let r = &c.result;
            let file = folder_and_name(&c.path);
            let _ = write!(
                h,
                "<tr><td>{i}</td><td class=\"l\">{}</td><td>{}</td><td>{}</td><td>{:.3}</td><td>{:.3}</td><td>{}</td>",
                escape(&file),
                r.direction,
                short(r.radius_mm, 4),
                r.accel_m_s2,
                r.freq_hz,
                r.revolutions
            );
            for p in params {
                let _ = write!(
                    h,
                    "<td>{}</td><td>{}</td>",
                    fmt_eij(r.eij[&p]),
                    fmt_eij(r.std_err[&p])
                );
            }
            let _ = writeln!(h, "<td>{:.3}</td></tr>", r.rms_residual_um);
        }
        let _ = writeln!(h, "</table>");
    }
}

fn identification_html(h: &mut String, rep: &IdentReport, fig: &Figure) {
    let _ = writeln!(h, "<h2>Identification</h2>");
    let _ = writeln!(
        h,
        "<p class=\"note\">{}cost (sum of squared weighted residuals) {} → {}.</p>",
        rep.machine
            .as_ref()
            .map(|m| format!("Machine {}; ", escape(m)))
            .unwrap_or_default(),
        short(rep.cost_initial, 6),
        short(rep.cost_final, 6)
    );
    let _ = writeln!(h, "<h3>Parameters</h3>\n<table>\n<tr><th class=\"l\">parameter</th><th>initial</th><th>identified</th><th>std err</th><th>identifiable</th></tr>");
    for p in &rep.parameters {
        let _ = writeln!(
            h,
            "<tr><td class=\"l\">{}</td><td>{}</td><td>{:.4}</td><td>{}</td><td>{}</td></tr>",
            escape(&p.name),
            short(p.initial, 6),
            p.identified,
            p.std_err.map_or("–".into(), |s| format!("{s:.4}")),
            p.identifiable.map_or("–", |b| if b { "yes" } else { "no" })
        );
    }
    let _ = writeln!(
        h,
        "</table>\n<h3>Correlation matrix</h3>\n<table>\n<tr><th></th>"
    );
    for p in &rep.parameters {
        let _ = write!(h, "<th>{}</th>", escape(&p.name));
    }
    let _ = writeln!(h, "</tr>");
    for (p, row) in rep.parameters.iter().zip(&rep.correlation) {
        let _ = write!(h, "<tr><th class=\"l\">{}</th>", escape(&p.name));
        for c in row {
            let _ = write!(h, "<td>{c:.3}</td>");
        }
        let _ = writeln!(h, "</tr>");
    }
    let _ = writeln!(h, "</table>");
    h.push_str(&super::stiffness_html(
        rep.stiffness.as_deref().unwrap_or_default(),
    ));
    figure_html(h, fig);
    let _ = writeln!(
        h,
        "<h3>Per test: measured vs simulated EIJ before and after (µm·s²/m)</h3>\n<table>\n\
         <tr><th>#</th><th class=\"l\">test</th><th class=\"l\">source</th><th>parameter</th>\
         <th>measured</th><th>± s.e.</th><th>simulated initial</th><th>simulated identified</th>\
         <th>identified − measured</th></tr>"
    );
    for (i, t) in rep.tests.iter().enumerate() {
        let source = t
            .source
            .as_deref()
            .map(|s| folder_and_name(Path::new(s)))
            .unwrap_or_default();
        for (p, m) in &t.measured {
            let fin = t.simulated_final.get(p).copied().unwrap_or(f64::NAN);
            let _ = writeln!(
                h,
                "<tr><td>{}</td><td class=\"l\">{}</td><td class=\"l\">{}</td><td>{p}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                i + 1,
                escape(&test_label(t)),
                escape(&source),
                fmt_eij(*m),
                fmt_eij(t.measured_std_err.get(p).copied().unwrap_or(f64::NAN)),
                fmt_eij(t.simulated_initial.get(p).copied().unwrap_or(f64::NAN)),
                fmt_eij(fin),
                fmt_eij(fin - m)
            );
        }
    }
    let _ = writeln!(h, "</table>");
}
