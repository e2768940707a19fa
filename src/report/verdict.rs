//! The verdict at the top of the report: per identification whether it may be used (status,
//! fit quality with the χ² test, every warning, each parameter's standing and bound), and every
//! warning of the circle evaluations. The standing of a parameter follows
//! [`crate::ident::verdict`], the same rule `eij identify` prints.

use std::fmt::Write as _;
use std::path::PathBuf;

use super::page::escape;
use super::short;
use crate::ident::report::IdentReport;
use crate::ident::verdict::{format_interval, Implausible, Standing};

/// An identify report read for the page, with its letter (`A`, `B`, …) for the comparison.
#[derive(Debug, Clone)]
pub struct LoadedIdent {
    /// `A`, `B`, ….
    pub letter: String,
    /// The file it was read from.
    pub path: PathBuf,
    /// Its content.
    pub report: IdentReport,
}

impl LoadedIdent {
    /// `A: out/x.json (machines/m.toml, 2026-11-25T00:17:21Z)`.
    pub fn title(&self) -> String {
        let mut extra = Vec::new();
        if let Some(m) = &self.report.machine {
            extra.push(m.clone());
        }
        if !self.report.date.is_empty() {
            extra.push(self.report.date.clone());
        }
        if extra.is_empty() {
            format!("{}: {}", self.letter, self.path.display())
        } else {
            format!(
                "{}: {} ({})",
                self.letter,
                self.path.display(),
                extra.join(", ")
            )
        }
    }

    /// Whether the fit was refused (nothing exported).
    pub fn refused(&self) -> bool {
        self.report.status.as_deref() == Some("refused") || self.report.refusal.is_some()
    }
}

/// How much an identification may be trusted, with the reasons.
#[derive(Debug, Clone, PartialEq)]
pub struct Headline {
    /// `ok`, `weak` or `bad` (the CSS class).
    pub class: &'static str,
    /// The sentence.
    pub text: String,
}

/// The headline of one identification: refused, doubtful (a parameter not determined, not
/// identifiable or on a bound, or a failed χ² test), usable with care (a weak or loose
/// parameter, warnings), or usable.
pub fn headline(id: &LoadedIdent) -> Headline {
    let r = &id.report;
    if id.refused() {
        return Headline {
            class: "bad",
            text: format!(
                "NOT USABLE: the fit was refused and nothing was exported: {}",
                r.refusal.as_deref().unwrap_or("status refused")
            ),
        };
    }
    let mut bad = Vec::new();
    let mut care = Vec::new();
    for p in &r.parameters {
        match r.standing(p) {
            s
            @ (Standing::NotDetermined { .. } | Standing::NotIdentifiable | Standing::OnBound) => {
                bad.push(format!("{} {}", p.name, s.label()))
            }
            s @ (Standing::Weak { .. } | Standing::Loose { .. }) => {
                care.push(format!("{} {}", p.name, s.label()))
            }
            Standing::Determined { .. } => {}
        }
    }
    match r.chi2() {
        Some(c) if !c.passed => bad.push(format!("χ² test failed (s = {:.2})", c.s)),
        Some(_) => {}
        None => care.push("χ² test not recorded (older report)".into()),
    }
    if !r.warnings.is_empty() {
        care.push(format!("{} warning(s)", r.warnings.len()));
    }
    if !bad.is_empty() {
        bad.extend(care);
        Headline {
            class: "bad",
            text: format!("DOUBTFUL: {}", bad.join("; ")),
        }
    } else if !care.is_empty() {
        Headline {
            class: "weak",
            text: format!("usable with care: {}", care.join("; ")),
        }
    } else {
        Headline {
            class: "ok",
            text:
                "usable: every parameter determined (σ/value ≤ 10 %), χ² test passed, no warnings"
                    .into(),
        }
    }
}

/// The class that colours a standing.
fn standing_class(s: Standing) -> &'static str {
    match s {
        Standing::Determined { .. } => "ok",
        Standing::Loose { .. } | Standing::Weak { .. } => "weak",
        _ => "bad",
    }
}

/// `accepted: the machine file was exported` or `REFUSED (nothing exported): …`. Only a
/// refusal is coloured (red, like its verdict): whether an exported result may be used is the
/// verdict's to say, in the verdict's one colour, never a second, green "accepted" beside a
/// red verdict.
pub(crate) fn status_html(id: &LoadedIdent) -> String {
    if id.refused() {
        format!(
            "<span class=\"bad\">REFUSED</span> (nothing exported): {}",
            escape(id.report.refusal.as_deref().unwrap_or(""))
        )
    } else {
        let status = id.report.status.as_deref().unwrap_or("status not recorded");
        format!(
            "{}: the identified machine file was exported (the fit converged within the bounds); whether to use it: see the verdict",
            escape(status)
        )
    }
}

/// `s = 0.949 over 172 degrees of freedom: χ² test passed …`.
pub(crate) fn fit_quality(r: &IdentReport) -> String {
    match (r.chi2(), r.residual_std) {
        (Some(c), _) => format!("residual std s = {:.3}; χ² test {}", c.s, c.describe()),
        (None, Some(s)) => format!(
            "residual std s = {s:.3} (degrees of freedom not recorded: no χ² test; s ≈ 1 means the model reproduces the measured EIJ within their uncertainty)"
        ),
        (None, None) => "residual std s not recorded (older report)".into(),
    }
}

/// The warnings as a list (`none` when there are none).
pub(crate) fn warnings_html(warnings: &[String]) -> String {
    if warnings.is_empty() {
        return "<p><b>Warnings:</b> none.</p>\n".into();
    }
    let mut h = format!(
        "<p><b>Warnings ({}):</b></p>\n<ul class=\"warn\">\n",
        warnings.len()
    );
    for w in warnings {
        let _ = writeln!(h, "<li>{}</li>", escape(w));
    }
    h.push_str("</ul>\n");
    h
}

/// The parameter table of one identification: value ± standard error, σ/value, standing,
/// bound and plausibility.
pub(crate) fn parameters_html(r: &IdentReport) -> String {
    let mut h = String::from(
        "<table>\n<tr><th class=\"l\">parameter</th><th>initial</th><th>identified</th>\
         <th>± std err</th><th>σ/value</th><th>3σ interval (in 1/p)</th><th class=\"l\">standing</th><th class=\"l\">remark</th></tr>\n",
    );
    let bounds = r.settings.as_ref().map(|s| (s.min_factor, s.max_factor));
    for p in &r.parameters {
        let s = r.standing(p);
        let mut remark = Vec::new();
        if let Some(n) = r.not_identifiable.iter().find(|n| n.name == p.name) {
            remark.push(n.reason.clone());
        } else if s == Standing::NotIdentifiable {
            remark.push("kept at its start value".into());
        }
        if s == Standing::OnBound {
            if let Some((lo, hi)) = bounds {
                remark.push(format!("bounds [{}, {}]", short(lo, 4), short(hi, 4)));
            }
        }
        if let Some(why) = Implausible::of(&p.name, p.identified, p.std_err) {
            if s != Standing::NotIdentifiable {
                remark.push(format!("implausible: {}", why.remark()));
            }
        }
        let _ = writeln!(
            h,
            "<tr><td class=\"l\">{}</td><td>{}</td><td>{:.4}</td><td>{}</td><td>{}</td><td>{}</td>\
             <td class=\"l {}\">{}</td><td class=\"w\">{}</td></tr>",
            escape(&p.name),
            short(p.initial, 6),
            p.identified,
            p.std_err.map_or("–".into(), |s| format!("{s:.4}")),
            s.rel_std_err()
                .map_or("–".into(), |r| format!("{:.1} %", 100.0 * r)),
            p.interval().map_or("–".into(), format_interval),
            standing_class(s),
            s.label(),
            escape(&remark.join("; "))
        );
    }
    h.push_str("</table>\n");
    let _ = writeln!(
        h,
        "<p class=\"note\">{}. 3σ interval: the value ± {:.0} standard errors taken in the compliance 1/p, where the fit is linear, and mapped to p (asymmetric; ∞ where the data cannot exclude an element that does not yield).</p>",
        escape(&Standing::legend()),
        crate::ident::settings::INTERVAL_SIGMAS
    );
    h
}

/// The verdict of one identification as a framed block.
pub(crate) fn ident_verdict_html(id: &LoadedIdent) -> String {
    let r = &id.report;
    let head = headline(id);
    let mut h = format!(
        "<div class=\"verdict v-{}\">\n<h3>{}</h3>\n<p><b>Verdict: <span class=\"{}\">{}</span></b></p>\n",
        head.class,
        escape(&id.title()),
        head.class,
        escape(&head.text)
    );
    let _ = writeln!(h, "<p><b>Status:</b> {}</p>", status_html(id));
    let values = r
        .residuals
        .map(|m| format!(", {m} values"))
        .unwrap_or_default();
    let iterations = r
        .iterations
        .map(|k| format!(", {k} iterations"))
        .unwrap_or_default();
    let _ = writeln!(
        h,
        "<p><b>Fit:</b> {}. {} tests{values}{iterations}; cost Σr² {:.4e} → {:.4e} (r = (simulated − measured EIJ)/σ).</p>",
        escape(&fit_quality(r)),
        r.tests.len(),
        r.cost_initial,
        r.cost_final
    );
    h.push_str(&warnings_html(&r.warnings));
    for n in &r.notes {
        let _ = writeln!(h, "<p class=\"note\">note: {}</p>", escape(n));
    }
    h.push_str(&parameters_html(r));
    h.push_str("</div>\n");
    h
}

/// Every warning of the circle evaluations, per test, and of the set (clocks).
pub(crate) fn circle_warnings_html(tests: &[(String, Vec<String>)], set: &[String]) -> String {
    let n: usize = tests.iter().map(|(_, w)| w.len()).sum::<usize>() + set.len();
    if n == 0 {
        return "<p><b>Circle-test evaluation:</b> no warnings (the paper's plane and ellipse routes agree with the joint fit within noise, conditions agree with the data).</p>\n".into();
    }
    let mut h =
        format!("<p><b>Circle-test evaluation: {n} warning(s)</b></p>\n<ul class=\"warn\">\n");
    for w in set {
        let _ = writeln!(h, "<li>{}</li>", escape(w));
    }
    for (name, ws) in tests {
        for w in ws {
            let _ = writeln!(h, "<li>{}: {}</li>", escape(name), escape(w));
        }
    }
    h.push_str("</ul>\n");
    h
}
