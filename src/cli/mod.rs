//! Command-line interface of the `eij` binary (names fixed by docs/commands.md).

use clap::{Parser, Subcommand};

/// `println!` into the run's standard output, written once the run's files are ([`console`]).
macro_rules! outln {
    () => {
        crate::cli::console::print(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        crate::cli::console::print(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// `print!` into the run's standard output ([`console`]).
macro_rules! out {
    ($($arg:tt)*) => {
        crate::cli::console::print(format_args!($($arg)*))
    };
}

/// `eprintln!` that never panics and escapes control characters ([`console`]).
macro_rules! errln {
    ($($arg:tt)*) => {
        crate::cli::console::error_line(format_args!($($arg)*))
    };
}

mod advice;
pub mod compare;
mod compensation;
pub mod console;
pub mod evaluate;
pub mod evaluate_diagnosis;
mod evaluate_move;
mod export;
mod fe;
mod history;
mod identify;
mod identify_print;
mod machine_args;
mod map;
mod modal;
mod report;
mod simulate;
mod stiffness;

/// eij — acceleration correlated position errors of machine tools from R-Test circle tests.
#[derive(Debug, Parser)]
#[command(name = "eij", version, about)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Nothing on standard output, no progress bar and no status line; warnings and errors
    /// still go to standard error.
    #[arg(long, short, global = true)]
    quiet: bool,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Evaluate R-Test circle-test series into EIJ with standard errors.
    Evaluate(evaluate::EvaluateArgs),
    /// EIJ of the moved axis from a positioning move (external − internal against the set
    /// acceleration).
    EvaluateMove(evaluate_move::EvaluateMoveArgs),
    /// Simulate a circle test or a positioning move on a machine model.
    Simulate(simulate::SimulateArgs),
    /// Undamped modes of a machine model.
    Modal(modal::ModalArgs),
    /// Export the assembled model (M, D, K) and the closed loop (A, B, C, D) as JSON.
    Export(export::ExportArgs),
    /// An elastic body's FE model and its reduction: mass properties, reduced vs full free-free
    /// frequencies, attachments.
    Fe(fe::FeArgs),
    /// Identify stiffness reduction factors from measured EIJ (defaults: the bundled demo).
    Identify(identify::IdentifyArgs),
    /// Which of several candidate machine models the measured EIJ support: each identified on
    /// the same tests, ranked by BIC, with χ² tests, hold-out and a verdict in words.
    Compare(compare::CompareArgs),
    /// Re-run stored known-good identifications and fail if a result drifts.
    Verify(identify::VerifyArgs),
    /// EIJ over a grid of axis positions (compensation table).
    Map(map::MapArgs),
    /// The stiffness set of a machine file as a table (catalogue × factor, N/µm).
    Stiffness(stiffness::StiffnessArgs),
    /// Cross-talk compensation coefficients k_IJ(s_K) = offset + slope·s_K from a model.
    Compensation(compensation::CompensationArgs),
    /// Write an offline HTML report with SVG figures (circle tests, moves, identification).
    Report(report::ReportArgs),
    /// Line up dated evaluations of one machine: diagnosis terms and EIJ over time, drift.
    History(history::HistoryArgs),
}

impl Cli {
    /// Runs the chosen subcommand.
    pub fn run(self) -> anyhow::Result<()> {
        // One run per process: every file it reads is an input no output may replace.
        eij::io::track_inputs();
        console::set_quiet(self.quiet);
        match self.command {
            Command::Evaluate(args) => evaluate::run(args),
            Command::EvaluateMove(args) => evaluate_move::run(args),
            Command::Simulate(args) => simulate::run(args),
            Command::Modal(args) => modal::run(args),
            Command::Export(args) => export::run(args),
            Command::Fe(args) => fe::run(args),
            Command::Identify(args) => identify::run(args),
            Command::Compare(args) => compare::run(args),
            Command::Verify(args) => identify::verify(args),
            Command::Map(args) => map::run(args),
            Command::Report(args) => report::run(args),
            Command::History(args) => history::run(args),
            Command::Stiffness(args) => stiffness::run(args),
            Command::Compensation(args) => compensation::run(args),
        }
    }
}
