//! Options shared by the commands that load a machine.

use eij::machine::{Machine, Pose, PoseError};
use std::path::PathBuf;

/// `--machine FILE.toml [--position-mm X,Y,Z]`.
#[derive(Debug, clap::Args)]
pub struct MachineArgs {
    /// Machine description (TOML).
    #[arg(long, value_name = "FILE.toml")]
    pub machine: PathBuf,
    /// Axis positions at which the model is assembled, mm, comma separated in the machine's axis
    /// order (default: the reference positions of the machine file).
    #[arg(
        long,
        value_name = "X,Y,Z",
        value_delimiter = ',',
        allow_hyphen_values = true
    )]
    pub position_mm: Option<Vec<f64>>,
}

impl MachineArgs {
    /// Loads the machine and the pose, checked once here ([`Pose::new`]).
    pub fn load(&self) -> anyhow::Result<(Machine, Pose)> {
        let machine = Machine::from_file(&self.machine)?;
        let pose = match &self.position_mm {
            None => machine.reference_pose(),
            Some(p) => {
                let m: Vec<f64> = p.iter().map(|v| v * 1e-3).collect();
                Pose::new(&machine, &m).map_err(|e| match e {
                    PoseError::Length { got, expected, .. } => anyhow::anyhow!(
                        "--position-mm: {got} values given, machine {} has {expected} axes ({})",
                        self.machine.display(),
                        machine
                            .axes()
                            .iter()
                            .map(|a| a.axis.name())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                    PoseError::OutOfStroke {
                        index,
                        axis,
                        min_m,
                        max_m,
                        ..
                    } => anyhow::anyhow!(
                        "--position-mm: {axis} = {} mm is outside the stroke [{}, {}] mm of {}",
                        p[index],
                        min_m * 1e3,
                        max_m * 1e3,
                        self.machine.display()
                    ),
                })?
            }
        };
        Ok((machine, pose))
    }
}

/// Writes `bytes` atomically to `out`, refusing to overwrite any of `inputs` or any file the
/// run has read.
pub fn write_output(
    out: &std::path::Path,
    bytes: &[u8],
    inputs: &[&std::path::Path],
) -> anyhow::Result<()> {
    write_outputs(&[(out, bytes)], inputs)
}

/// Writes the outputs of a run as one set ([`eij::io::write_set`]): all or none, never
/// replacing any of `inputs` or any file the run has read; then says what it wrote.
pub fn write_outputs(
    files: &[(&std::path::Path, &[u8])],
    inputs: &[&std::path::Path],
) -> anyhow::Result<()> {
    eij::io::write_set(files, inputs)?;
    let written: Vec<&std::path::Path> = files.iter().map(|(p, _)| *p).collect();
    super::console::wrote(&written);
    Ok(())
}

/// `--accel-m-s2`: positive, and within what circle tests and moves use.
pub fn accel_m_s2(v: f64) -> anyhow::Result<f64> {
    let (lo, hi) = eij::rtest::checks::PLAUSIBLE_ACCEL_M_S2;
    if !(v.is_finite() && v > 0.0) {
        anyhow::bail!(
            "--accel-m-s2: {} must be a positive number",
            eij::text::num(v)
        );
    }
    if !(lo..=hi).contains(&v) {
        anyhow::bail!(
            "--accel-m-s2: {} m/s² is outside what circle tests and moves use ({lo}–{hi} m/s²)",
            eij::text::num(v)
        );
    }
    Ok(v)
}
