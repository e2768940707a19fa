//! Command-line interface of the `eij` binary (names fixed by CONTRACT.md).

use clap::{Parser, Subcommand};

pub mod evaluate;

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
}

impl Cli {
    /// Runs the chosen subcommand.
    pub fn run(self) -> anyhow::Result<()> {
        match self.command {
            Command::Evaluate(args) => evaluate::run(args),
        }
    }
}
