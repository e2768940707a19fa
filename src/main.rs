//! The `eij` command line: a thin shell over the library; see `eij --help`.

mod cli;

use clap::Parser;

fn main() -> std::process::ExitCode {
    match cli::Cli::parse().run() {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            let line = format!("{e:#}").replace('\n', " ");
            eprintln!("eij: error: {line}");
            std::process::ExitCode::FAILURE
        }
    }
}
