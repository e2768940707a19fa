//! Outputs of an identification: the identified machine file and the report JSON
//! (CONTRACT.md keys).

use super::{IdentResult, Problem, Settings};
use crate::rtest::eij_json;
use serde_json::{json, Value};

/// Provenance written into exports: what produced them and when.
#[derive(Debug, Clone, PartialEq)]
pub struct Provenance {
    /// The machine file identified.
    pub machine_file: String,
    /// The measured inputs.
    pub measured: Vec<String>,
    /// UTC time stamp (RFC 3339); from SOURCE_DATE_EPOCH when set, for reproducible outputs.
    pub date: String,
}

impl Provenance {
    /// Provenance with the current (or SOURCE_DATE_EPOCH) time.
    pub fn now(machine_file: String, measured: Vec<String>) -> Self {
        let time = std::env::var("SOURCE_DATE_EPOCH")
            .ok()
            .and_then(|s| s.trim().parse::<u64>().ok())
            .map(|s| std::time::UNIX_EPOCH + std::time::Duration::from_secs(s))
            .unwrap_or_else(std::time::SystemTime::now);
        Provenance {
            machine_file,
            measured,
            date: humantime::format_rfc3339_seconds(time).to_string(),
        }
    }
}

fn settings_json(s: &Settings) -> Value {
    json!({
        "method": s.method,
        "solver": s.simulation.solver,
        "rate_hz": s.simulation.rate_hz,
        "revolutions": s.simulation.revolutions,
        "min_factor": s.min_factor,
        "max_factor": s.max_factor,
        "max_iters": s.max_iters(),
        "tol_cost": s.tol_cost,
        "tol_step": s.tol_step,
        "fd_step": s.fd_step,
        "sigma_floor_um_s2_per_m": s.sigma_floor,
    })
}

/// The report JSON: parameters with standard errors and correlations, costs, and per test the
/// measured and simulated EIJ before and after, with the simulated/measured ratios.
pub fn report_json(problem: &Problem, result: &IdentResult, prov: &Provenance) -> Value {
    let n = result.parameters.len();
    let tests: Vec<Value> = problem
        .tests()
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let measured: std::collections::BTreeMap<_, _> =
                t.measured.iter().map(|(p, (v, _))| (*p, *v)).collect();
            let sigma: std::collections::BTreeMap<_, _> =
                t.measured.iter().map(|(p, (_, s))| (*p, *s)).collect();
            let ratio = |sim: &std::collections::BTreeMap<crate::axes::Eij, f64>| {
                let r: std::collections::BTreeMap<_, _> = measured
                    .iter()
                    .filter(|(_, m)| m.abs() > 0.0)
                    .map(|(p, m)| (*p, sim.get(p).copied().unwrap_or(f64::NAN) / m))
                    .collect();
                eij_json(&r)
            };
            let only_measured = |sim: &std::collections::BTreeMap<crate::axes::Eij, f64>| {
                let r: std::collections::BTreeMap<_, _> = measured
                    .keys()
                    .map(|p| (*p, sim.get(p).copied().unwrap_or(f64::NAN)))
                    .collect();
                eij_json(&r)
            };
            json!({
                "source": t.source,
                "plane": t.circle.plane.name(),
                "direction": t.circle.direction.name(),
                "radius_mm": t.circle.radius_mm,
                "accel_m_s2": t.circle.accel_m_s2,
                "measured": eij_json(&measured),
                "measured_std_err": eij_json(&sigma),
                "simulated_initial": only_measured(&result.simulated_initial[i]),
                "simulated_final": only_measured(&result.simulated_final[i]),
                "simulated_final_time_domain": result.simulated_final_time.as_ref().map(|t| only_measured(&t[i])),
                "ratio_initial": ratio(&result.simulated_initial[i]),
                "ratio_final": ratio(&result.simulated_final[i]),
            })
        })
        .collect();
    json!({
        "eij_version": env!("CARGO_PKG_VERSION"),
        "date": prov.date,
        "machine": prov.machine_file,
        "measured_inputs": prov.measured,
        "parameters": result.parameters.iter().map(|p| json!({
            "name": p.name,
            "initial": p.initial,
            "identified": p.value,
            "std_err": p.std_err,
            "identifiable": p.identifiable,
        })).collect::<Vec<_>>(),
        "correlation": (0..n).map(|i| (0..n).map(|k| result.correlation[(i, k)]).collect::<Vec<_>>()).collect::<Vec<_>>(),
        "jacobian_singular_values": result.singular_values,
        "cost_initial": result.cost_initial,
        "cost_final": result.cost_final,
        "cost_history": result.cost_history,
        "cost_definition": "sum of squared weighted residuals ((E_sim - E_meas) / sigma)^2",
        "residual_std": result.residual_std,
        "residuals": result.residuals,
        "iterations": result.iterations,
        "warnings": result.warnings,
        "settings": settings_json(problem.settings()),
        "tests": tests,
    })
}

/// The identified machine as TOML text: the machine file with the identified factors, a
/// comment header and a `[provenance]` table saying from what and how it was identified.
pub fn machine_toml(
    problem: &Problem,
    result: &IdentResult,
    prov: &Provenance,
) -> Result<String, String> {
    let mut raw = result.machine.to_raw();
    let mut p = toml::Table::new();
    p.insert(
        "identified_by".into(),
        format!("eij {}", env!("CARGO_PKG_VERSION")).into(),
    );
    p.insert("date".into(), prov.date.clone().into());
    p.insert("from_machine".into(), prov.machine_file.clone().into());
    p.insert(
        "measured".into(),
        toml::Value::Array(prov.measured.iter().map(|m| m.clone().into()).collect()),
    );
    p.insert("tests".into(), (problem.tests().len() as i64).into());
    p.insert("cost_initial".into(), result.cost_initial.into());
    p.insert("cost_final".into(), result.cost_final.into());
    let mut params = toml::Table::new();
    for q in &result.parameters {
        let mut e = toml::Table::new();
        e.insert("initial".into(), q.initial.into());
        e.insert("identified".into(), q.value.into());
        if let Some(s) = q.std_err {
            e.insert("std_err".into(), s.into());
        }
        e.insert("identifiable".into(), q.identifiable.into());
        params.insert(q.name.clone(), toml::Value::Table(e));
    }
    p.insert("parameters".into(), toml::Value::Table(params));
    raw.provenance = Some(p);
    raw.name = format!("{}-identified", problem.machine().name);
    let body = toml::to_string_pretty(&raw).map_err(|e| e.to_string())?;
    let mut header = format!(
        "# Identified by eij {} on {} from {} and {} measured input(s).\n",
        env!("CARGO_PKG_VERSION"),
        prov.date,
        prov.machine_file,
        prov.measured.len()
    );
    header.push_str("# Stiffness = catalogue value × reduction factor; identified factors:\n");
    for q in &result.parameters {
        match q.std_err {
            Some(s) => header.push_str(&format!(
                "#   {} = {:.4} ± {:.4} (start {})\n",
                q.name, q.value, s, q.initial
            )),
            None => header.push_str(&format!(
                "#   {} = {} (not identifiable, unchanged)\n",
                q.name, q.value
            )),
        }
    }
    header.push('\n');
    Ok(header + &body)
}
