//! `eij evaluate-move FILE.csv --axis J [--nominal] [--json]`: EIJ of the moved axis from a
//! positioning move.

use eij::axes::Axis;
use eij::measured::moves::{evaluate_move_against, Reference};
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
    /// Measure the deviation against the nominal path (external − `<i>_set_mm` of every axis)
    /// instead of external − internal: what a compensation on the set points reduces, so that a
    /// compensated move (`eij simulate move … --compensation`) shows the EIJ that remain.
    #[arg(long)]
    nominal: bool,
    /// JSON on standard output instead of the table.
    #[arg(long)]
    json: bool,
}

/// Runs `eij evaluate-move`.
pub fn run(args: EvaluateMoveArgs) -> anyhow::Result<()> {
    let reference = if args.nominal {
        Reference::Nominal
    } else {
        Reference::Internal
    };
    let m = evaluate_move_against(&args.file, args.axis, reference)?;
    let deviation = match reference {
        Reference::Internal => "external − internal",
        Reference::Nominal => "external − nominal path",
    };
    if args.json {
        let mut json = m.to_json();
        json["deviation"] = deviation.into();
        outln!("{}", serde_json::to_string_pretty(&json)?);
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
        "  {:<5} {:>10} {:>10}   (µm·s²/m, deviation {deviation})",
        "EIJ",
        "value",
        "std err"
    );
    for (e, v) in &m.eij {
        outln!("  {:<5} {:>10.4} {:>10.4}", e.name(), v.value, v.std_err);
    }
    if reference == Reference::Nominal {
        let j = m.axis.letter();
        outln!(
            "  (E{j}{j} against the nominal path holds axis {}'s own following error too)",
            m.axis
        );
    }
    Ok(())
}
