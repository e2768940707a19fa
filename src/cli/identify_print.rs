//! What `eij identify` prints on standard output. By default a short verdict: the fit, the
//! parameters with their standing, strong correlations, one line per plane and circle centre,
//! and one line each for the static terms, the clock offsets and the best additional test.
//! With `--tables` also the full tables: every measured and simulated EIJ, the correlation
//! matrix, the static terms, every candidate test, every clock. Warnings go to standard error
//! (printed by the caller), never only here.

use eij::ident::design::Design;
use eij::ident::report::IdentReport;
use eij::ident::validation::Validation;
use eij::ident::verdict::{format_interval, implausible, Standing};
use eij::ident::{IdentResult, Problem};
use eij::rtest::pooled::geometric_name;
use eij::Estimate;

/// Correlations at least this large in magnitude are listed in the short output.
const STRONG_CORRELATION: f64 = 0.9;

/// A value counts for the simulated/measured ratios when |measured| exceeds this many σ (a
/// ratio to a value that is zero within its uncertainty means nothing).
const RATIO_SIGMAS: f64 = 3.0;

/// The identification on standard output: the verdict, and with `tables` the full tables.
pub(super) fn print_result(
    p: &Problem,
    result: &IdentResult,
    report: &IdentReport,
    seconds: f64,
    tables: bool,
) {
    print_verdict(p, result, report, seconds);
    if tables {
        print_correlation(result);
        print_eij_table(p, result);
    }
    print_groups(p, result);
    print_ratios(p, result);
    print_statics(result, tables);
    print_fitted_clocks(result, tables);
    if let Some(d) = &result.design {
        print_design(d, tables);
    }
    for n in &result.notes {
        outln!("note: {n}");
    }
}

/// Status, fit quality, parameters with their standing, strong correlations, warnings.
fn print_verdict(p: &Problem, result: &IdentResult, report: &IdentReport, seconds: f64) {
    let verb = if result.refusal.is_some() {
        "Fit REFUSED (nothing exported) for"
    } else {
        "Identified"
    };
    outln!(
        "{verb} {} from {} tests ({} values), {} iterations, {:.1} s",
        p.machine().name(),
        p.tests().len(),
        result.residuals,
        result.iterations,
        seconds
    );
    outln!(
        "cost Σr² {:.4e} -> {:.4e}   residual std s = {:.3}   (r = (simulated − measured EIJ) / σ)",
        result.cost_initial,
        result.cost_final,
        result.residual_std
    );
    if let Some(c) = report.chi2() {
        outln!("χ² test {}", c.describe());
    }
    outln!(
        "\n  parameter              initial   identified    std err   σ/value   3σ interval (in 1/p)  standing"
    );
    for q in &report.parameters {
        let standing = report.standing(q);
        let rel = standing
            .rel_std_err()
            .map_or("-".to_string(), |r| format!("{:.1} %", 100.0 * r));
        let plausible = if standing != Standing::NotIdentifiable
            && implausible(&q.name, q.identified, q.std_err)
        {
            ", implausible factor"
        } else {
            ""
        };
        let interval = q.interval().map_or("-".to_string(), format_interval);
        match q.std_err {
            Some(s) => outln!(
                "  {:<22} {:>7.4}   {:>10.4}   {:>8.4}  {:>8}   {:<20}  {}{plausible}",
                q.name,
                q.initial,
                q.identified,
                s,
                rel,
                interval,
                standing.label()
            ),
            None => outln!(
                "  {:<22} {:>7.4}   {:>10.4}   {:>8}  {:>8}   {:<20}  {} (kept at its start value)",
                q.name,
                q.initial,
                q.identified,
                "-",
                rel,
                interval,
                standing.label()
            ),
        }
    }
    let legend = Standing::legend();
    let (a, b) = legend.split_once("; ").unwrap_or((&legend, ""));
    outln!("  ({a};\n   {b};\n   {})", interval_legend());
    let n = result.parameters.len();
    let strong: Vec<String> = (0..n)
        .flat_map(|i| (i + 1..n).map(move |k| (i, k)))
        .filter(|&(i, k)| result.correlation[(i, k)].abs() >= STRONG_CORRELATION)
        .map(|(i, k)| {
            format!(
                "{} / {} {:+.2}",
                result.parameters[i].name,
                result.parameters[k].name,
                result.correlation[(i, k)]
            )
        })
        .collect();
    if !strong.is_empty() {
        outln!(
            "  strongly correlated (|r| ≥ {STRONG_CORRELATION}): {}",
            strong.join(", ")
        );
    }
    match result.warnings.len() {
        0 => outln!("\nwarnings: none"),
        k => outln!("\nwarnings: {k} (on standard error above; also in the report JSON)"),
    }
}

/// What the 3σ interval column means.
pub(super) fn interval_legend() -> String {
    format!(
        "3σ interval: the value ± {:.0} standard errors taken in the compliance 1/p, where the fit is linear, and mapped to p: asymmetric, ∞ where the data cannot exclude an element that does not yield",
        eij::ident::settings::INTERVAL_SIGMAS
    )
}

/// The full correlation matrix.
fn print_correlation(result: &IdentResult) {
    let n = result.parameters.len();
    if n < 2 {
        return;
    }
    outln!("\n  correlation of the identified parameters");
    for i in 0..n {
        let row: Vec<String> = (0..n)
            .map(|k| format!("{:>6.2}", result.correlation[(i, k)]))
            .collect();
        outln!("  {:<22} {}", result.parameters[i].name, row.join(" "));
    }
}

/// Every measured EIJ beside its simulation before and after, with the ratios.
fn print_eij_table(p: &Problem, result: &IdentResult) {
    outln!(
        "\n  every EIJ, µm·s²/m: measured ± σ (the test's evaluation and its standard error), simulated with the\n  \
         catalogue (start) factors and with the identified ones; (ratio) = simulated / measured where |measured| > {RATIO_SIGMAS}σ,\n  \
         '-' where the measured value is zero within {RATIO_SIGMAS}σ (a ratio to it means nothing)"
    );
    outln!(
        "  {:<36} EIJ   measured ± σ       catalogue (ratio)   identified (ratio)",
        "test"
    );
    for (i, t) in p.tests().iter().enumerate() {
        for (
            e,
            &Estimate {
                value: m,
                std_err: s,
            },
        ) in &t.measured
        {
            let sim = |v: &eij::ident::EijMap| v.get(e).copied().unwrap_or(f64::NAN);
            let (a, b) = (
                sim(&result.simulated_initial[i]),
                sim(&result.simulated_final[i]),
            );
            let ratio = |x: f64| {
                if m.abs() > RATIO_SIGMAS * s {
                    format!("{:>5.2}", x / m)
                } else {
                    "    -".to_string()
                }
            };
            outln!(
                "  {:<36} {} {:>8.3} ± {:<6.3}  {:>8.3} ({})     {:>8.3} ({})",
                t.label(),
                e,
                m,
                s,
                a,
                ratio(a),
                b,
                ratio(b)
            );
        }
    }
}

/// One line per plane and circle centre: how well the identified model reproduces its tests,
/// with the static terms removed as in the χ² test ([`eij::ident::groups`]), so that the
/// groups add up to it.
fn print_groups(p: &Problem, result: &IdentResult) {
    outln!(
        "\n  per plane and circle centre: z = (identified model − measured − static terms) / σ over the EIJ of its tests\n  \
         {:<28} tests  values  rms z  max |z| (test, EIJ)",
        "plane @ circle centre"
    );
    for g in eij::ident::groups::group_fits(p, result) {
        outln!(
            "  {:<28} {:>5}  {:>6}  {:>5.2}  {:.1} ({})",
            g.label(),
            g.tests,
            g.values,
            g.rms_z,
            g.max_abs_z.0,
            g.max_abs_z.1
        );
    }
}

/// Median simulated/measured before and after over the values beyond 3σ.
fn print_ratios(p: &Problem, result: &IdentResult) {
    let (mut before, mut after) = (Vec::new(), Vec::new());
    for (i, t) in p.tests().iter().enumerate() {
        for (
            e,
            &Estimate {
                value: m,
                std_err: s,
            },
        ) in &t.measured
        {
            if m.abs() > RATIO_SIGMAS * s {
                before.push(result.simulated_initial[i][e] / m);
                after.push(result.simulated_final[i][e] / m);
            }
        }
    }
    if before.is_empty() {
        return;
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    outln!(
        "\nsimulated/measured over the {} values beyond {RATIO_SIGMAS}σ: median {:.2} with the catalogue model, {:.2} identified",
        before.len(),
        median(&mut before),
        median(&mut after)
    );
}

/// The fitted static terms: one summary line, with `tables` every group.
fn print_statics(result: &IdentResult, tables: bool) {
    let terms: Vec<_> = result
        .static_estimates
        .iter()
        .filter(|e| e.clock.is_none())
        .collect();
    let Some(largest) = terms
        .iter()
        .max_by(|a, b| a.value_um_per_mm.abs().total_cmp(&b.value_um_per_mm.abs()))
    else {
        return;
    };
    outln!(
        "\n  static terms (geometry fitted with the EIJ, µm per mm of set position): {} in {} groups, largest {} {:+.3} ± {:.3} ({})",
        terms.len(),
        result.statics.groups.len(),
        geometric_name(largest.eij),
        largest.value_um_per_mm,
        largest.std_err_um_per_mm,
        result.statics.groups[largest.group].label()
    );
    if !tables {
        return;
    }
    for (g, group) in result.statics.groups.iter().enumerate() {
        let terms: Vec<String> = terms
            .iter()
            .filter(|e| e.group == g)
            .map(|e| {
                format!(
                    "{}{} {:+.3} ± {:.3}",
                    geometric_name(e.eij),
                    if e.reversal { "(rev)" } else { "" },
                    e.value_um_per_mm,
                    e.std_err_um_per_mm
                )
            })
            .collect();
        if !terms.is_empty() {
            outln!("  {:<28} {}", group.label(), terms.join("  "));
        }
    }
}

/// The clock offsets fitted with the EIJ: the largest, with `tables` all. Printed in the sign
/// of every clock offset eij prints: internal clock minus external clock (the negative of the
/// report's `external_late_ms`).
fn print_fitted_clocks(result: &IdentResult, tables: bool) {
    let fitted = eij::ident::diagnosis::fitted_clocks(result);
    let Some(largest) = fitted.iter().max_by(|a, b| {
        a.external_late_ms
            .abs()
            .total_cmp(&b.external_late_ms.abs())
    }) else {
        return;
    };
    outln!(
        "  clock offsets fitted with the EIJ (internal minus external clock, negative: external readings late): {}, largest {:+.4} ± {:.4} ms ({})",
        fitted.len(),
        -largest.external_late_ms,
        largest.std_err_ms,
        largest.clock
    );
    if tables {
        for c in &fitted {
            outln!(
                "  {:<40} {:+.4} ± {:.4} ms",
                c.clock,
                -c.external_late_ms,
                c.std_err_ms
            );
        }
    }
}

/// The ranking of candidate additional tests: the best, with `tables` all that were kept.
fn print_design(d: &Design, tables: bool) {
    let Some(best) = d.candidates.first() else {
        return;
    };
    let (now, name) = d.worst_now();
    let label = |c: &eij::ident::design::Candidate| {
        let pos: Vec<String> = c
            .circle
            .position_m
            .as_deref()
            .unwrap_or_default()
            .iter()
            .map(|v| format!("{:.0}", v * 1e3))
            .collect();
        format!(
            "{} {:<3} {:>5.2} m/s² @ {:<16}",
            c.circle.plane,
            c.circle.direction,
            c.circle.accel_m_s2,
            format!("{} mm", pos.join(","))
        )
    };
    if !tables {
        outln!(
            "  best additional test (of {} candidates): {} -> worst σ/value {:.1} % → {:.1} % ({})",
            d.evaluated,
            label(best).trim_end(),
            100.0 * now,
            100.0 * best.worst_rel_std_err,
            best.worst_parameter
        );
        return;
    }
    outln!(
        "\n  candidate additional tests ({} evaluated), ranked by the worst relative standard error they leave (now {} at {:.1} %)",
        d.evaluated,
        name,
        100.0 * now
    );
    for (k, c) in d.candidates.iter().enumerate() {
        outln!(
            "  {:>2}. {} -> worst {:.1} % ({})",
            k + 1,
            label(c),
            100.0 * c.worst_rel_std_err,
            c.worst_parameter
        );
    }
}

/// The hold-out validation: the verdict, with `tables` one line per test.
pub(super) fn print_validation(v: &Validation, tables: bool) {
    outln!(
        "\n  hold-out validation: {} values, χ²/dof = {:.2} over {} degrees of freedom ({}; {:.2} counting the measurement uncertainty alone)",
        v.values,
        v.chi2_per_dof,
        v.dof,
        if v.passed {
            "predicted within the uncertainty of measurement and identified parameters"
        } else {
            "NOT predicted within the uncertainty of measurement and identified parameters"
        },
        v.chi2_per_dof_measurement_only
    );
    if !tables {
        return;
    }
    outln!(
        "  {:<40} rms z   max |z|   rms error   rms σ   rms σ_pred  (µm·s²/m; z = (predicted − measured)/√(σ² + σ_pred²))",
        "test"
    );
    for t in &v.tests {
        outln!(
            "  {:<40} {:>5.2}   {:>7.2}   {:>9.4}   {:>6.4}   {:>10.4}",
            t.label,
            t.rms_z,
            t.max_abs_z,
            t.rms_error_um_s2_per_m,
            t.rms_sigma_um_s2_per_m,
            t.rms_prediction_sigma_um_s2_per_m
        );
    }
}

/// The clock offsets the evaluation estimated: a summary, with `tables` every clock.
pub(super) fn print_clocks(clocks: &[eij::measured::suite::ClockReport], tables: bool) {
    if clocks.is_empty() {
        return;
    }
    let applied = clocks.iter().filter(|c| c.applied).count();
    outln!(
        "  clock offsets estimated by the evaluation (internal minus external clock, negative: external readings late): {}, {applied} applied",
        clocks.len()
    );
    if !tables {
        return;
    }
    for c in clocks {
        let se = c
            .std_err_ms
            .map(|s| format!(" ± {s:.4}"))
            .unwrap_or_default();
        outln!(
            "  {:<40} {:+.4}{se} ms  {} tests, {}",
            c.clock,
            c.offset_ms,
            c.tests.len(),
            if c.applied { "applied" } else { "not applied" }
        );
    }
}
