//! `eij modal --machine FILE.toml [--json]`

use super::machine_args::MachineArgs;
use eij::mbs::modal;
use serde_json::json;

/// Arguments of `eij modal`.
#[derive(Debug, clap::Args)]
pub struct ModalArgs {
    #[command(flatten)]
    machine: MachineArgs,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    json: bool,
}

/// Runs `eij modal`.
pub fn run(args: ModalArgs) -> anyhow::Result<()> {
    let (machine, pose) = args.machine.load()?;
    // The same checks as every other command (support, stable closed loop), so that no machine
    // that `export` or `simulate` refuses gets frequencies here.
    let model = eij::control::ClosedLoop::new(&machine, &pose)?.model;
    let modes = modal::modes(&model)?;
    if let Some(m) = modes.iter().find(|m| !m.frequency_hz.is_finite()) {
        anyhow::bail!(
            "{}: the modal analysis gave a frequency of {} Hz (dominant DOF {}): the model is numerically degenerate",
            machine.source(),
            m.frequency_hz,
            m.dominant_dof
        );
    }
    if args.json {
        let out = json!({
            "machine": machine.source(),
            "pose_m": &*pose,
            "frequencies_hz": modes.iter().map(|m| m.frequency_hz).collect::<Vec<_>>(),
            "modes": modes.iter().map(|m| json!({
                "frequency_hz": m.frequency_hz,
                "dominant_dof": m.dominant_dof,
                "dominant_share": m.dominant_share,
            })).collect::<Vec<_>>(),
        });
        outln!("{out}");
        return Ok(());
    }
    // A machine without axes (a body on its supports) has no pose and no drives.
    if machine.axes().is_empty() {
        outln!("Undamped modes of {} (no axes)", machine.name());
    } else {
        outln!(
            "Undamped modes of {} at {} (rigid-body modes of the drives at 0 Hz)",
            machine.name(),
            machine
                .axes()
                .iter()
                .zip(&pose)
                .map(|(a, p)| format!("{}={:.1} mm", a.axis, p * 1e3))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    outln!(
        "{:>4}  {:>10}  {:<14} {:>6}",
        "mode",
        "f / Hz",
        "dominant DOF",
        "share"
    );
    for (i, m) in modes.iter().enumerate() {
        outln!(
            "{:>4}  {:>10.2}  {:<14} {:>5.0}%",
            i + 1,
            m.frequency_hz,
            m.dominant_dof,
            100.0 * m.dominant_share
        );
    }
    Ok(())
}
