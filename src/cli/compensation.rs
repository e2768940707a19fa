//! `eij compensation --machine FILE.toml --out TABLE.csv`: the controller's cross-talk
//! compensation coefficients k_IJ(s_K) from a (calibrated) model (docs/compensation.md).

use super::machine_args::write_output;
use eij::compensation::{CompensationTable, TableSpec, DEFAULT_POINTS};
use eij::machine::Machine;
use std::path::PathBuf;

/// A coefficient's worst residual above this (and above 10 % of its offset) is warned about,
/// µm·s²/m (0.05 µm·s²/m is 0.5 µm at 10 m/s², a third of the R-Test's σ).
const WARN_RESIDUAL: f64 = 0.05;

/// Arguments of `eij compensation`.
#[derive(Debug, clap::Args)]
pub struct CompensationArgs {
    /// Machine description (an identified one, e.g. out/<name>-identified.toml).
    #[arg(long, value_name = "FILE.toml")]
    machine: PathBuf,
    /// The table (CSV: parameter, adaptation_axis, offset_um_s2_per_m,
    /// slope_um_s2_per_m_per_mm, worst_residual_um_s2_per_m).
    #[arg(long, value_name = "TABLE.csv")]
    out: PathBuf,
    /// Grid points per axis over its stroke.
    #[arg(long, default_value_t = DEFAULT_POINTS)]
    points: usize,
    /// Set acceleration of the simulated circle tests, m/s².
    #[arg(long, default_value_t = 5.0, allow_hyphen_values = true)]
    accel_m_s2: f64,
    /// Radius of the simulated circle tests, mm.
    #[arg(long, default_value_t = 2.0, allow_hyphen_values = true)]
    radius_mm: f64,
}

/// Runs `eij compensation`.
pub fn run(args: CompensationArgs) -> anyhow::Result<()> {
    super::machine_args::accel_m_s2(args.accel_m_s2)?;
    let machine = Machine::from_file(&args.machine)?;
    eij::io::check_outputs(&[args.out.as_path()], &[args.machine.as_path()])?;
    let spec = TableSpec {
        radius_mm: args.radius_mm,
        accel_m_s2: args.accel_m_s2,
        points: args.points,
    };
    let bar = super::console::Progress::bar(0, "compensation", "circles");
    let table = CompensationTable::of_with_progress(&machine, &spec, &|done, total| {
        bar.set_len(total as u64);
        bar.set(done as u64);
    })?;
    drop(bar);
    for c in &table.coefficients {
        let worst = c.worst_residual_um_s2_per_m;
        if worst > WARN_RESIDUAL && worst > 0.1 * c.offset_um_s2_per_m.abs() {
            errln!(
                "warning: {}: the linear form in {} leaves up to {worst:.3} µm·s²/m over the \
                 workspace (offset {:.3}): a compensation with one adaptation axis follows it only \
                 partly (see `eij map` for where it changes)",
                c.parameter,
                c.adaptation_axis
                    .map_or("no axis".to_string(), |a| format!("axis {a}")),
                c.offset_um_s2_per_m
            );
        }
    }
    outln!(
        "Compensation of {} ({} circles per plane at {} m/s², r = {} mm, {} points per axis)",
        machine.name(),
        spec.points.pow(machine.axes().len() as u32),
        spec.accel_m_s2,
        spec.radius_mm,
        spec.points
    );
    outln!(
        "  {:<5} {:<5} {:>12} {:>16} {:>14}",
        "EIJ",
        "axis",
        "offset",
        "slope per mm",
        "worst resid."
    );
    for c in &table.coefficients {
        outln!(
            "  {:<5} {:<5} {:>12.4} {:>16.6} {:>14.4}",
            c.parameter.name(),
            c.adaptation_axis
                .map_or("none".to_string(), |a| a.to_string()),
            c.offset_um_s2_per_m,
            c.slope_um_s2_per_m_per_mm,
            c.worst_residual_um_s2_per_m
        );
    }
    // Printing only collects (`console`): the table is written before anything is shown.
    write_output(&args.out, table.to_csv().as_bytes(), &[&args.machine])
}
