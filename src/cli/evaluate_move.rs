//! `eij evaluate-move FILE.csv --axis J [--json]`: EIJ of the moved axis from a positioning move.

use eij::axes::Axis;
use eij::measured::moves::evaluate_move;
use std::path::PathBuf;

/// Arguments of `eij evaluate-move`.
#[derive(Debug, clap::Args)]
pub struct EvaluateMoveArgs {
    /// The move record (t_s, *_int_mm, *_ext_mm and the moved axis's `<j>_acc_set_m_s2` or
    /// `<j>_set_mm`).
    file: PathBuf,
    /// The moved axis: x, y or z.
    #[arg(long)]
    axis: Axis,
    /// JSON on standard output instead of the table.
    #[arg(long)]
    json: bool,
}

/// Runs `eij evaluate-move`.
pub fn run(args: EvaluateMoveArgs) -> anyhow::Result<()> {
    let m = evaluate_move(&args.file, args.axis)?;
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&m.to_json())?);
        return Ok(());
    }
    outln!(
        "{}: move of {} ({} samples, peak set acceleration {:.3} m/s²)",
        m.source,
        m.axis,
        m.samples,
        m.peak_accel_m_s2
    );
    outln!(
        "  {:<5} {:>10} {:>10}   (µm·s²/m)",
        "EIJ",
        "value",
        "std err"
    );
    for (e, v) in &m.eij {
        outln!("  {:<5} {:>10.4} {:>10.4}", e.name(), v.value, v.std_err);
    }
    Ok(())
}
