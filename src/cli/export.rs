//! `eij export --machine FILE.toml --out FILE.json`: the assembled model and closed loop.

use super::machine_args::{write_output, MachineArgs};
use eij::control::ClosedLoop;
use nalgebra::DMatrix;
use serde_json::json;
use std::path::PathBuf;

/// Arguments of `eij export`.
#[derive(Debug, clap::Args)]
pub struct ExportArgs {
    #[command(flatten)]
    machine: MachineArgs,
    /// Output JSON file.
    #[arg(long, value_name = "FILE.json")]
    out: PathBuf,
}

fn rows(m: &DMatrix<f64>) -> Vec<Vec<f64>> {
    (0..m.nrows())
        .map(|i| m.row(i).iter().copied().collect())
        .collect()
}

/// Runs `eij export`.
pub fn run(args: ExportArgs) -> anyhow::Result<()> {
    let (machine, pose) = args.machine.load()?;
    eij::io::check_outputs(&[&args.out], &[&args.machine.machine])?;
    let cl = ClosedLoop::new(&machine, &pose)?;
    let m = &cl.model;
    let out = json!({
        "machine": machine.name(),
        "source": machine.source(),
        "pose_m": &*pose,
        "units": "SI: m, rad, kg, N, s",
        "dofs": m.dofs,
        "M": rows(&m.mass),
        "D": rows(&m.damping),
        "K": rows(&m.stiffness),
        "state_space": {
            "A": rows(&cl.a),
            "B": rows(&cl.b),
            "C": rows(&cl.c),
            "D": rows(&cl.d),
            "inputs": cl.inputs,
            "outputs": cl.outputs,
            "states": cl.states,
        },
    });
    let mut text = serde_json::to_vec_pretty(&out)?;
    text.push(b'\n');
    write_output(&args.out, &text, &[&args.machine.machine])
}
