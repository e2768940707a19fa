//! `eij evaluate FILE.csv... [--plane xy|yz|zx] [--radius-mm R] [--json]`

use std::path::PathBuf;

/// Arguments of `eij evaluate`.
#[derive(Debug, clap::Args)]
pub struct EvaluateArgs {
    /// R-Test / circle-test CSV files.
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
}

/// Runs `eij evaluate`.
pub fn run(args: EvaluateArgs) -> anyhow::Result<()> {
    anyhow::bail!(
        "evaluate is not implemented yet ({} files)",
        args.files.len()
    )
}
