//! A model comparison (`eij compare --report F.json`) in the report: the verdict first, then
//! one table of the candidates (status, s, χ² test, k, BIC, AIC, hold-out, worst group) and the
//! reason of each; every candidate's identification then joins the page's identifications
//! (verdict, side-by-side comparison, details with its elastic bodies).

use std::fmt::Write as _;
use std::path::Path;

use super::page::{escape, Page};
use super::verdict::LoadedIdent;
use super::ReportError;
use crate::ident::compare_report::CompareReport;

/// Reads a comparison report, naming the file and the key on failure.
pub(crate) fn read(path: &Path) -> Result<CompareReport, ReportError> {
    let bytes = super::read_file(path)?;
    let name = path.display().to_string();
    if let Err(e) = serde_json::from_slice::<serde::de::IgnoredAny>(&bytes) {
        return Err(ReportError::BadInput {
            source_name: name,
            message: format!("not valid JSON: {e}"),
        });
    }
    CompareReport::from_json(&bytes).map_err(|message| ReportError::BadInput {
        source_name: name,
        message,
    })
}

/// The candidates' identifications as identifications of the page, lettered from `first`
/// on (with `letter`, the page's own lettering), each with its label.
pub(crate) fn idents(
    r: &CompareReport,
    path: &Path,
    first: usize,
    letter: impl Fn(usize) -> String,
) -> Vec<(String, LoadedIdent)> {
    r.candidates
        .iter()
        .filter_map(|c| Some((c.label.clone(), c.identify_report.clone()?)))
        .enumerate()
        .map(|(k, (label, report))| {
            (
                label,
                LoadedIdent {
                    letter: letter(first + k),
                    path: path.to_path_buf(),
                    report,
                },
            )
        })
        .collect()
}

fn opt(v: Option<f64>, digits: usize) -> String {
    v.map_or("–".into(), |x| format!("{x:.digits$}"))
}

/// The comparison section: verdict, candidates, reasons. `letters`: the page letter of each
/// candidate's identification, by label.
pub(crate) fn section(page: &mut Page, r: &CompareReport, letters: &[(String, String)]) {
    page.heading(2, "model-comparison", "Which model do the data support");
    let class = if r.reproduced { "ok" } else { "bad" };
    let mut h = format!(
        "<div class=\"verdict v-{class}\">\n<p><b>Verdict: <span class=\"{class}\">{}</span></b></p>\n<ul>\n",
        escape(&r.verdict)
    );
    let preferred_first = r
        .candidates
        .iter()
        .filter(|c| c.status == "preferred")
        .chain(r.candidates.iter().filter(|c| c.status != "preferred"));
    for c in preferred_first.clone() {
        let _ = writeln!(h, "<li>{}</li>", escape(&c.reason));
    }
    h.push_str("</ul>\n</div>\n");
    let _ = writeln!(
        h,
        "<table>\n<tr><th class=\"l\">candidate</th><th class=\"l\">identification</th><th class=\"l\">status</th>\
         <th>s</th><th class=\"l\">χ² test</th><th>k</th><th>BIC</th><th>ΔBIC</th><th>AIC</th><th>ΔAIC</th>\
         <th class=\"l\">hold-out (one circle centre left out)</th><th class=\"l\">worst group (rms z)</th></tr>"
    );
    for c in preferred_first {
        let letter = letters
            .iter()
            .find(|(l, _)| *l == c.label)
            .map_or("–".to_string(), |(_, x)| x.clone());
        let status_class = match c.status.as_str() {
            "preferred" => "ok",
            "behind" => "weak",
            _ => "bad",
        };
        let chi2 = match c.chi2_passed {
            Some(true) => "<span class=\"ok\">passed</span>".to_string(),
            Some(false) => "<span class=\"bad\">FAILED</span>".to_string(),
            None => "–".into(),
        };
        let hold = c.holdout.as_ref().map_or("–".to_string(), |hd| {
            format!(
                "{}/{} centres predicted{}",
                hd.passed_folds,
                hd.folds.len(),
                hd.chi2_per_dof
                    .map(|x| format!(" (χ²/dof {x:.2})"))
                    .unwrap_or_default()
            )
        });
        let worst = c.worst_group.as_ref().map_or("–".to_string(), |g| {
            let p: Vec<String> = g.position_mm.iter().map(|v| format!("{v:.0}")).collect();
            format!(
                "{} of {} @ {} mm ({:.2})",
                g.worst_eij,
                g.plane,
                p.join(","),
                g.worst_eij_rms_z
            )
        });
        let _ = writeln!(
            h,
            "<tr><td class=\"l\">{}</td><td class=\"l\">{}</td><td class=\"l {status_class}\">{}</td>\
             <td>{}</td><td class=\"l\">{chi2}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td>\
             <td class=\"l\">{}</td><td class=\"l\">{}</td></tr>",
            escape(&c.label),
            escape(&letter),
            escape(&c.status),
            opt(c.residual_std, 3),
            c.k.map_or("–".into(), |k| k.to_string()),
            opt(c.bic, 1),
            c.delta_bic.map_or("–".into(), |d| format!("{d:+.1}")),
            opt(c.aic, 1),
            c.delta_aic.map_or("–".into(), |d| format!("{d:+.1}")),
            escape(&hold),
            escape(&worst)
        );
    }
    h.push_str("</table>\n");
    let _ = writeln!(
        h,
        "<p class=\"note\">{} candidates on {} weighted residuals of {} measured file(s). {}. ΔBIC against the preferred: \
         below 2 not worth more than a bare mention, 2–6 positive, 6–10 strong, above 10 very strong \
         evidence. Worst group: the plane, circle centre and EIJ a candidate reproduces worst, \
         z with the fitted static terms removed.</p>",
        r.candidates.len(),
        r.residuals,
        escape(&r.measured_inputs.len().to_string()),
        escape(&r.criterion)
    );
    page.push(&h);
}
