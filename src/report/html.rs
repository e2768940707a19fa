//! The report: one self-contained page `report.html` — header (machine, date, eij version,
//! data folders, conditions), table of contents, the verdict of every identification and of the
//! circle evaluations first, the comparison of several identifications, then the circle tests,
//! the moves, the identifications in detail and further figures (EIJ maps). Every figure is
//! inline SVG; the page links to nothing outside itself ([`super::page`]), so it can be mailed
//! or archived as one file.
//!
//! Everything is read, evaluated and drawn before the page is written, atomically: `report.html`
//! is the only file the report writes into its folder.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::labels::{
    conditions_line, distinct, feed_mm_min, fmt_eij, folder_and_name, folders_of_tests,
    position_label, test_name,
};
pub use super::page::Figure;
use super::page::{anchor, escape, Page};
use super::verdict::{self, LoadedIdent};
use super::{
    certificate, circle_group, clocks_html, compare, diagnosis_html, ident_html, model_compare,
    move_svg, short, Conditions, MoveData, ReportError,
};
use crate::axes::Plane;
use crate::ident::report::IdentReport;
use crate::measured::inputs::MeasuredInputs;
use crate::measured::suite::diagnose::SuiteDiagnosis;
use crate::measured::suite::{EvaluatedTest, Suite};

/// The report page's file name.
pub const REPORT_FILE: &str = "report.html";

/// What goes into a report.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ReportRequest {
    /// R-Test CSV files and folders of them (folders: every `*.csv`, sorted).
    pub measured: Vec<PathBuf>,
    /// Report JSONs of `eij identify`; several are compared side by side, in this order.
    pub identify_reports: Vec<PathBuf>,
    /// Simulated move CSVs (`eij simulate move`).
    pub moves: Vec<PathBuf>,
    /// Further figures, e.g. EIJ maps.
    pub extra_figures: Vec<Figure>,
    /// Dated runs of one machine for the history (folders or evaluate JSON files).
    pub history: Vec<PathBuf>,
    /// The report folder (created if missing; an existing file there is refused).
    pub out_dir: PathBuf,
    /// A model comparison (`eij compare --report`): its verdict and candidates first, their
    /// identifications with the others.
    pub compare_report: Option<PathBuf>,
}

/// The page letter of the identification at `index`: `A` … `Z`, then `A1` ….
fn letter(index: usize) -> String {
    let letter = char::from_u32('A' as u32 + (index % 26) as u32).unwrap_or('?');
    if index < 26 {
        letter.to_string()
    } else {
        format!("{letter}{}", index / 26)
    }
}

/// Reads an identify report, naming the file and the key on failure.
fn read_identification(path: &Path, index: usize) -> Result<LoadedIdent, ReportError> {
    let name = path.display().to_string();
    let bytes = super::read_file(path)?;
    if let Err(e) = serde_json::from_slice::<serde::de::IgnoredAny>(&bytes) {
        return Err(ReportError::BadInput {
            source_name: name,
            message: format!("not valid JSON: {e}"),
        });
    }
    let report = IdentReport::from_json(&bytes).map_err(|e| ReportError::BadInput {
        source_name: name,
        message: e.to_string(),
    })?;
    Ok(LoadedIdent {
        letter: letter(index),
        path: path.to_path_buf(),
        report,
    })
}

/// Checks the report folder: not a file, its parent exists, not a folder of measured inputs.
fn check_out_dir(req: &ReportRequest) -> Result<(), ReportError> {
    let out = &req.out_dir;
    let bad = |message: String| ReportError::Output {
        path: out.display().to_string(),
        message,
    };
    if out.exists() && !out.is_dir() {
        return Err(bad("exists and is not a folder".into()));
    }
    // The report folder itself may be created, its parent must exist (like every output).
    if let Some(parent) = out.parent().filter(|p| !p.as_os_str().is_empty()) {
        if !parent.is_dir() {
            return Err(bad(format!("folder {} does not exist", parent.display())));
        }
    }
    // Never write the report into a folder of measured inputs.
    if let Ok(o) = out.canonicalize() {
        if req.measured.iter().chain(&req.history).any(|m| {
            m.is_dir()
                && m.canonicalize()
                    .is_ok_and(|m| o.starts_with(&m) || m.starts_with(&o))
        }) {
            return Err(bad(
                "is (or holds) a folder of measured inputs; choose another report folder".into(),
            ));
        }
    }
    Ok(())
}

/// Reads, evaluates and draws everything, then writes `report.html` into the report folder.
/// Returns its path.
pub fn generate(req: &ReportRequest) -> Result<PathBuf, ReportError> {
    check_out_dir(req)?;
    let date = crate::ident::report::utc_timestamp()?;
    let measured = MeasuredInputs::expand(&req.measured)?;
    let files = measured.data_files();
    let suite = crate::measured::suite::evaluate_tests(&measured.tests, &Default::default())?;
    // A test the diagnosis cannot decompose does not stop the report: the page says so.
    let diagnosis = (!suite.tests.is_empty())
        .then(|| crate::measured::suite::diagnose::diagnose(&suite, Default::default()));
    let (diagnosis, diagnosis_error) = match diagnosis {
        Some(Ok(d)) => (Some(d), None),
        Some(Err(e)) => (None, Some(e.to_string())),
        None => (None, None),
    };
    let groups = circle_group::groups(&suite)?;
    let scale = circle_group::page_scale(&groups);
    let circle_figures = groups
        .iter()
        .enumerate()
        .map(|(i, g)| circle_group::figures(g, i + 1, &scale))
        .collect::<Result<Vec<_>, _>>()?;
    let mut idents = req
        .identify_reports
        .iter()
        .enumerate()
        .map(|(i, p)| read_identification(p, i))
        .collect::<Result<Vec<_>, _>>()?;
    let comparison = match &req.compare_report {
        Some(path) => {
            let r = model_compare::read(path)?;
            let candidates = model_compare::idents(&r, path, idents.len(), letter);
            let letters: Vec<(String, String)> = candidates
                .iter()
                .map(|(label, id)| (label.clone(), id.letter.clone()))
                .collect();
            idents.extend(candidates.into_iter().map(|(_, id)| id));
            Some((r, letters))
        }
        None => None,
    };
    let ident_figures = idents
        .iter()
        .map(ident_html::figure)
        .collect::<Result<Vec<_>, _>>()?;
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
                    id: format!("move-{}", i + 1),
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
    let moves = with_plain_runs(moves)?;

    let history = if req.history.is_empty() {
        None
    } else {
        Some(crate::measured::history::history(&req.history)?)
    };

    let mut page = Page::default();
    if let Some((r, letters)) = &comparison {
        model_compare::section(&mut page, r, letters);
    }
    verdict_section(&mut page, &idents, &suite);
    if let Some(e) = &diagnosis_error {
        page.push(&format!(
            "<p class=\"warn\">The circle diagnosis could not be made: {}</p>\n",
            escape(e)
        ));
    }
    if let Some(d) = &diagnosis {
        page.push(&tolerance_verdict_html(d, &suite));
    }
    if !suite.tests.is_empty() {
        certificate::certificate(
            &mut page,
            &certificate::CertificateInput {
                suite: &suite,
                diagnosis: diagnosis.as_ref(),
                machines_elsewhere: machines(&idents),
                written: format!("{date} by eij {}", env!("CARGO_PKG_VERSION")),
                conditions: conditions_line(&suite.tests),
                folders: folders_of_tests(&suite.tests).join("; "),
            },
        );
    }
    if idents.len() > 1 {
        compare::comparison(&mut page, &idents);
    }
    if !suite.tests.is_empty() {
        page.heading(2, "circles", "Circle tests");
        let mut h = String::new();
        circle_tables(&mut h, &suite.tests);
        clocks_html::section(&mut h, &suite);
        page.push(&h);
        circle_group::section(
            &mut page,
            &groups,
            &circle_figures,
            &scale,
            diagnosis.as_ref(),
        );
    }
    if !moves.is_empty() {
        page.heading(2, "moves", "Positioning moves");
        for (_, f) in &moves {
            page.figure(f);
        }
        let mut h = String::new();
        move_vs_circle_html(&mut h, &req.moves, &moves, &suite.tests);
        page.push(&h);
    }
    if !idents.is_empty() {
        page.heading(2, "identification", "Identification in detail");
        for (id, fig) in idents.iter().zip(&ident_figures) {
            ident_html::details(&mut page, id, fig);
        }
    }
    if let Some(h) = &history {
        super::history_html::section(&mut page, h)?;
    }
    if !req.extra_figures.is_empty() {
        page.heading(2, "maps", "EIJ maps over the workspace");
        for f in &req.extra_figures {
            page.figure(f);
        }
    }
    let header = header_html(req, &files, &suite, &idents, &date);
    let html = page.finish(&title(&idents), &header);

    let mut inputs: Vec<&Path> = files.iter().map(PathBuf::as_path).collect();
    inputs.extend(req.identify_reports.iter().map(PathBuf::as_path));
    inputs.extend(req.compare_report.iter().map(PathBuf::as_path));
    inputs.extend(req.moves.iter().map(PathBuf::as_path));
    let out = &req.out_dir;
    let created = match std::fs::create_dir(out) {
        Ok(()) => true,
        Err(_) if out.is_dir() => false,
        Err(e) => {
            return Err(ReportError::Output {
                path: out.display().to_string(),
                message: format!("cannot create folder: {e}"),
            })
        }
    };
    let path = out.join(REPORT_FILE);
    if let Err(e) = crate::io::write_atomic(&path, html.as_bytes(), &inputs) {
        // A report that could not be written (a full disk) leaves no empty folder behind.
        if created {
            let _ = std::fs::remove_dir(out);
        }
        return Err(e.into());
    }
    Ok(path)
}

/// The machine names of the identifications, for the title.
fn machines(idents: &[LoadedIdent]) -> Vec<String> {
    let mut m: Vec<String> = Vec::new();
    for id in idents {
        if let Some(name) = &id.report.machine {
            if !m.contains(name) {
                m.push(name.clone());
            }
        }
    }
    m
}

fn title(idents: &[LoadedIdent]) -> String {
    let m = machines(idents);
    if m.is_empty() {
        "eij report: acceleration correlated position errors EIJ".into()
    } else {
        format!("eij report: {}", m.join(" / "))
    }
}

/// The header: machine, date, version, data folders, conditions of the tests.
fn header_html(
    req: &ReportRequest,
    files: &[PathBuf],
    suite: &Suite,
    idents: &[LoadedIdent],
    date: &str,
) -> String {
    let mut rows: Vec<(&str, String)> = Vec::new();
    let mut machines = machines(idents);
    for t in &suite.tests {
        if let Some(m) = &t.input.session.machine {
            if !machines.contains(m) {
                machines.push(m.clone());
            }
        }
    }
    rows.push((
        "machine",
        if machines.is_empty() {
            "not stated (give machine = \"…\" in rtest.toml; an identify report names it too)"
                .into()
        } else {
            machines.join(", ")
        },
    ));
    rows.push((
        "report written",
        format!("{date} by eij {}", env!("CARGO_PKG_VERSION")),
    ));
    for id in idents {
        rows.push(("identification", id.title()));
    }
    rows.push((
        "data folders",
        if files.is_empty() {
            "none given: no circle test on this page".into()
        } else {
            folders_of_tests(&suite.tests).join("; ")
        },
    ));
    if !suite.tests.is_empty() {
        rows.push(("conditions", conditions_line(&suite.tests)));
    }
    if !req.moves.is_empty() {
        rows.push((
            "moves",
            req.moves
                .iter()
                .map(|m| m.display().to_string())
                .collect::<Vec<_>>()
                .join(", "),
        ));
    }
    let mut h = String::from("<table class=\"head\">\n");
    for (k, v) in rows {
        let _ = writeln!(h, "<tr><th>{k}</th><td>{}</td></tr>", escape(&v));
    }
    h.push_str("</table>\n");
    let _ = writeln!(
        h,
        "<p class=\"note\">EIJ = deviation of the TCP in direction I per set acceleration of axis J, \
         in µm·s²/m (= µm per m/s²), from the joint least-squares fit of d = external − internal \
         over the steady revolutions (paper section 2.2/2.3); standard errors from the residual \
         variance.</p>"
    );
    h
}

/// The verdict first: each identification's, then the circle evaluation's warnings.
fn verdict_section(page: &mut Page, idents: &[LoadedIdent], suite: &Suite) {
    page.heading(2, "verdict", "Verdict");
    let mut h = String::new();
    if idents.is_empty() {
        let _ = writeln!(
            h,
            "<p>No identification given (<code>--identify-report</code>): the page shows the \
             measured circle tests only.</p>"
        );
    }
    for id in idents {
        h.push_str(&verdict::ident_verdict_html(id));
    }
    if suite.tests.is_empty() {
        // No circle test on the page: nothing evaluated, so nothing to vouch for.
        page.push(&h);
        return;
    }
    let tests: Vec<(String, Vec<String>)> = suite
        .tests
        .iter()
        .map(|t| {
            let warnings = t.result.warnings.iter().map(ToString::to_string);
            (test_name(t), warnings.collect())
        })
        .collect();
    let set: Vec<String> = suite.warnings.iter().map(ToString::to_string).collect();
    h.push_str(&verdict::circle_warnings_html(&tests, &set));
    page.push(&h);
}

/// The tolerance verdict of the circle tests: overall, and each failed test with its checks.
fn tolerance_verdict_html(d: &SuiteDiagnosis, suite: &Suite) -> String {
    let judged = d.verdicts.iter().flatten().count();
    let Some(v) = d.verdict() else {
        return "<p><b>Tolerances:</b> none given (<code>[tolerances]</code> in rtest.toml): \
                the circle tests are diagnosed, not judged.</p>\n"
            .into();
    };
    let failed = d.failed();
    let mut h = format!(
        "<p><b>Tolerances:</b> {} {} of {judged} judged circle tests within tolerance \
         (<a href=\"#{}\">certificate</a>)</p>\n",
        diagnosis_html::badge(Some(v)),
        judged - failed.len(),
        certificate::ID
    );
    if !failed.is_empty() {
        h.push_str("<ul class=\"warn\">\n");
        for i in failed {
            let checks = d.verdicts[i]
                .as_ref()
                .map_or(Vec::new(), diagnosis_html::failed_checks);
            let _ = writeln!(
                h,
                "<li class=\"{}\">{}: {}</li>",
                diagnosis_html::FAIL,
                escape(&test_name(&suite.tests[i])),
                escape(&checks.join("; "))
            );
        }
        h.push_str("</ul>\n");
    }
    h
}

/// A compensated move whose plain run (the same move without the table, [`MoveData::
/// same_nominal_move`]) is on the page draws that run's TCP − nominal path as "without
/// compensation", as `eij simulate move --compensation --plot` does, instead of the structural
/// deviation that stands in for it.
fn with_plain_runs(moves: Vec<(MoveData, Figure)>) -> Result<Vec<(MoveData, Figure)>, ReportError> {
    let plain: Vec<MoveData> = moves.iter().map(|(d, _)| d.clone()).collect();
    moves
        .into_iter()
        .map(|(mut data, mut figure)| {
            if let Some(p) = plain.iter().find(|p| data.same_nominal_move(p)) {
                data.uncompensated_um = p.path_deviation_um.clone();
                figure.svg = move_svg(
                    &data,
                    &Conditions {
                        source: data.source.clone(),
                        ..Default::default()
                    },
                )?;
            }
            Ok((data, figure))
        })
        .collect()
}

/// EIJ of each move (`eij evaluate-move`) beside the mean of the circle tests that accelerate
/// the same axis: the structure's (external − internal) and, for a move with a compensation
/// (`<b>_comp_mm` columns), what the compensation leaves (external − nominal path, as
/// `eij evaluate-move --nominal` fits it).
fn move_vs_circle_html(
    h: &mut String,
    paths: &[PathBuf],
    moves: &[(MoveData, Figure)],
    circles: &[EvaluatedTest],
) {
    use crate::measured::moves::{evaluate_move_against, Reference};
    let compensated = moves.iter().any(|(d, _)| d.is_compensated());
    let _ = writeln!(
        h,
        "<h3 id=\"{}\">EIJ from the moves and from the circles</h3>\n<p class=\"note\">Move: external − \
         internal against the set acceleration over the whole move (with velocity, constant and \
         position terms; docs/compensation.md){}. Circles: mean over the circle tests above whose \
         plane holds the moved axis. A move's acceleration spreads over 0–30 Hz, a circle's is \
         one line near 8 Hz: they agree where the structure responds alike over that band.</p>",
        anchor("move-vs-circle"),
        if compensated {
            "; for a move with a compensation table also external − nominal path, the TCP's \
             deviation from the path asked for: what the compensation leaves of the structure's \
             EIJ (external − internal, which a compensation of the set points does not change). \
             Against the nominal path the moved axis's own E<sub>JJ</sub> holds its following \
             error too: read the cross-talk rows"
        } else {
            ""
        }
    );
    let _ = writeln!(
        h,
        "<table>\n<tr><th>move</th><th>EIJ</th><th>move (ext − int)</th><th>± std err</th>{}<th>circles (n)</th></tr>",
        if compensated {
            "<th>with compensation (TCP − nominal path)</th><th>± std err</th>"
        } else {
            ""
        }
    );
    for (path, (data, _)) in paths.iter().zip(moves) {
        let name = escape(&path.display().to_string());
        let Ok(m) = evaluate_move_against(path, data.axis, Reference::Internal) else {
            let _ = writeln!(
                h,
                "<tr><td>{name}</td><td colspan=\"{}\">no set acceleration to evaluate</td></tr>",
                if compensated { 6 } else { 4 }
            );
            continue;
        };
        let nominal = data
            .is_compensated()
            .then(|| evaluate_move_against(path, data.axis, Reference::Nominal).ok())
            .flatten();
        for (e, v) in &m.eij {
            let vals: Vec<f64> = circles
                .iter()
                .filter_map(|c| c.result.eij.value(e))
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
            let with = match (&nominal, compensated) {
                (_, false) => String::new(),
                (Some(n), true) => match n.eij.get(e) {
                    Some(w) => format!(
                        "<td>{}</td><td>{}</td>",
                        fmt_eij(w.value),
                        fmt_eij(w.std_err)
                    ),
                    None => "<td>–</td><td>–</td>".into(),
                },
                (None, true) => "<td>–</td><td>–</td>".into(),
            };
            let _ = writeln!(
                h,
                "<tr><td>{name}</td><td>{}</td><td>{}</td><td>{}</td>{with}<td>{}</td></tr>",
                e.name(),
                fmt_eij(v.value),
                fmt_eij(v.std_err),
                circle
            );
        }
    }
    let _ = writeln!(h, "</table>");
}

fn circle_tables(h: &mut String, circles: &[EvaluatedTest]) {
    let _ = writeln!(
        h,
        "<h3 id=\"circle-eij\">EIJ per test (µm·s²/m, ± standard error)</h3>\n<p class=\"note\">Set radius {} mm; feed = 2π·r·f, the path speed of the steady revolutions; rms = residual of the joint fit.</p>",
        distinct(circles.iter().map(|c| c.result.radius_mm), 4)
    );
    let mut by_plane: std::collections::BTreeMap<Plane, Vec<(usize, &EvaluatedTest)>> =
        Default::default();
    for (i, c) in circles.iter().enumerate() {
        by_plane.entry(c.result.plane).or_default().push((i + 1, c));
    }
    for (plane, entries) in by_plane {
        let params = plane.parameters();
        let _ = writeln!(h, "<h4>plane {plane}</h4>\n<table>\n<tr><th>#</th><th class=\"l\">file</th><th class=\"l\">circle centre / mm</th><th>dir</th><th>a / (m/s²)</th><th>feed / (mm/min)</th><th>rev.</th>");
        for p in params {
            let _ = write!(h, "<th>{p} ± s.e.</th>");
        }
        let _ = writeln!(h, "<th>rms / µm</th></tr>");
        for (i, c) in entries {
            let r = &c.result;
            let _ = write!(
                h,
                "<tr><td>{i}</td><td class=\"l\">{}</td><td class=\"l\">{}</td><td>{}</td><td>{:.3}</td><td>{:.0}</td><td>{}</td>",
                escape(&folder_and_name(c.input.primary_file())),
                c.input
                    .test
                .position_mm
                    .as_deref()
                    .map_or("–".into(), position_label),
                r.direction,
                r.accel_m_s2,
                feed_mm_min(r),
                r.revolutions
            );
            for p in params {
                let _ = write!(
                    h,
                    "<td>{} ± {}</td>",
                    fmt_eij(r.eij[&p].value),
                    fmt_eij(r.eij[&p].std_err)
                );
            }
            let _ = writeln!(h, "<td>{:.3}</td></tr>", r.rms_residual_um);
        }
        let _ = writeln!(h, "</table>");
    }
}
