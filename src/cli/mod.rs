//! Command-line interface of the `eij` binary (names fixed by CONTRACT.md).

use clap::{Parser, Subcommand};

pub mod evaluate;
mod export;
mod machine_args;
mod modal;
mod simulate;

/// eij — acceleration correlated position errors of machine tools from R-Test circle tests.
#[derive(Debug, Parser)]
#[command(name = "eij", version, about)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Evaluate R-Test circle-test series into EIJ with standard errors.
    Evaluate(evaluate::EvaluateArgs),
    /// Simulate a circle test or a positioning move on a machine model.
    Simulate(simulate::SimulateArgs),
    /// Undamped modes of a machine model.
    Modal(modal::ModalArgs),
    /// Export the assembled model (M, D, K) and the closed loop (A, B, C, D) as JSON.
    Export(export::ExportArgs),
}

impl Cli {
    /// Runs the chosen subcommand.
    pub fn run(self) -> anyhow::Result<()> {
        match self.command {
            Command::Evaluate(args) => evaluate::run(args),
            Command::Simulate(args) => simulate::run(args),
            Command::Modal(args) => modal::run(args),
            Command::Export(args) => export::run(args),
        }
    }
}
