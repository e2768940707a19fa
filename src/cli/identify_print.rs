//! What `eij identify` prints on standard output: parameters, correlations, tests, static
//! terms, the ranking of candidate tests and the hold-out validation.

use eij::ident::design::Design;
use eij::ident::validation::Validation;
use eij::ident::{IdentResult, Problem};
use eij::rtest::pooled::geometric_name;

/// The tables of an identification on standard output (warnings go to standard error).
pub(super) fn print_result(p: &Problem, result: &IdentResult, seconds: f64) {
    let verb = if result.refusal.is_some() {
        "Fit REFUSED (nothing exported) for"
    } else {
        "Identified"
    };
    println!(
        "{verb} {} from {} tests ({} values), {} iterations, {:.1} s",
        p.machine().name(),
        p.tests().len(),
        result.residuals,
        result.iterations,
        seconds
    );
    println!(
        "cost Σr² {:.4e} -> {:.4e}   residual std s = {:.3}",
        result.cost_initial, result.cost_final, result.residual_std
    );
    println!("\n  parameter              initial   identified    std err");
    for q in &result.parameters {
        match q.std_err {
            Some(s) => println!(
                "  {:<22} {:>7.4}   {:>10.4}   {:>8.4}",
                q.name, q.initial, q.value, s
            ),
            None => println!(
                "  {:<22} {:>7.4}   {:>10}   not identifiable",
                q.name, q.initial, "-"
            ),
        }
    }
    let n = result.parameters.len();
    if n > 1 {
        println!("\n  correlation");
        for i in 0..n {
            let row: Vec<String> = (0..n)
                .map(|k| format!("{:>6.2}", result.correlation[(i, k)]))
                .collect();
            println!("  {:<22} {}", result.parameters[i].name, row.join(" "));
        }
    }
    println!(
        "\n  {:<36} EIJ   measured ± σ       catalogue (ratio)   identified (ratio)   (µm·s²/m)",
        "test"
    );
    for (i, t) in p.tests().iter().enumerate() {
        for (e, (m, s)) in &t.measured {
            let a = result.simulated_initial[i]
                .get(e)
                .copied()
                .unwrap_or(f64::NAN);
            let b = result.simulated_final[i]
                .get(e)
                .copied()
                .unwrap_or(f64::NAN);
            let ratio = |x: f64| {
                if m.abs() > 3.0 * s {
                    format!("{:>5.2}", x / m)
                } else {
                    "    -".to_string()
                }
            };
            println!(
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
    let (mut before, mut after) = (Vec::new(), Vec::new());
    for (i, t) in p.tests().iter().enumerate() {
        for (e, (m, s)) in &t.measured {
            if m.abs() > 3.0 * s {
                before.push(result.simulated_initial[i][e] / m);
                after.push(result.simulated_final[i][e] / m);
            }
        }
    }
    if !before.is_empty() {
        let median = |v: &mut Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        println!(
            "\nsimulated/measured over the {} values beyond 3σ: median {:.2} with the catalogue model, {:.2} identified",
            before.len(),
            median(&mut before),
            median(&mut after)
        );
    }
    print_statics(result);
    print_fitted_clocks(result);
    if let Some(d) = &result.design {
        print_design(d);
    }
    for n in &result.notes {
        println!("note: {n}");
    }
}

/// The fitted static terms per group.
fn print_statics(result: &IdentResult) {
    if result.static_estimates.is_empty() {
        return;
    }
    println!("\n  static terms (µm per mm of set position; acceleration-independent, fitted with the EIJ)");
    for (g, group) in result.statics.groups.iter().enumerate() {
        let terms: Vec<String> = result
            .static_estimates
            .iter()
            .filter(|e| e.group == g && e.clock.is_none())
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
            println!("  {:<28} {}", group.label(), terms.join("  "));
        }
    }
}

/// The clock offsets fitted with the EIJ.
fn print_fitted_clocks(result: &IdentResult) {
    let fitted = eij::ident::diagnosis::fitted_clocks(result);
    if fitted.is_empty() {
        return;
    }
    println!(
        "\n  clock offsets fitted with the EIJ (external readings late against the internal ones)"
    );
    for c in fitted {
        println!(
            "  {:<40} {:+.4} ± {:.4} ms",
            c.clock, c.external_late_ms, c.std_err_ms
        );
    }
}

/// The ranking of candidate additional tests.
fn print_design(d: &Design) {
    if d.candidates.is_empty() {
        return;
    }
    let (now, name) = d.worst_now();
    println!(
        "\n  candidate additional tests ({} evaluated), ranked by the worst relative standard error they leave (now {} at {:.1} %)",
        d.evaluated,
        name,
        100.0 * now
    );
    for (k, c) in d.candidates.iter().enumerate() {
        let pos: Vec<String> = c
            .circle
            .position_m
            .as_deref()
            .unwrap_or_default()
            .iter()
            .map(|v| format!("{:.0}", v * 1e3))
            .collect();
        println!(
            "  {:>2}. {} {:<3} {:>5.2} m/s² @ {:<16} -> worst {:.1} % ({})",
            k + 1,
            c.circle.plane,
            c.circle.direction,
            c.circle.accel_m_s2,
            format!("{} mm", pos.join(",")),
            100.0 * c.worst_rel_std_err,
            c.worst_parameter
        );
    }
}

/// The hold-out validation.
pub(super) fn print_validation(v: &Validation) {
    println!(
        "\n  hold-out validation: {} values, χ²/dof = {:.2} ({})",
        v.values,
        v.chi2_per_dof,
        if v.passed {
            "predicted within the measurement uncertainty"
        } else {
            "NOT predicted within the measurement uncertainty"
        }
    );
    println!(
        "  {:<40} rms z   max |z|   rms error   rms σ  (µm·s²/m)",
        "test"
    );
    for t in &v.tests {
        println!(
            "  {:<40} {:>5.2}   {:>7.2}   {:>9.4}   {:>6.4}",
            t.label, t.rms_z, t.max_abs_z, t.rms_error_um_s2_per_m, t.rms_sigma_um_s2_per_m
        );
    }
}

/// The clock offsets the evaluation estimated.
pub(super) fn print_clocks(clocks: &[eij::rtest::suite::ClockReport]) {
    if clocks.is_empty() {
        return;
    }
    println!(
        "\n  clock offsets (internal minus external clock; a lagging probe logger is negative)"
    );
    for c in clocks {
        let se = c
            .std_err_ms
            .map(|s| format!(" ± {s:.4}"))
            .unwrap_or_default();
        println!(
            "  {:<40} {:+.4}{se} ms  {} tests, {}",
            c.clock,
            c.offset_ms,
            c.tests.len(),
            if c.applied { "applied" } else { "not applied" }
        );
    }
}
