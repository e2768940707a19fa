//! The `eij` command line: a thin shell over the library; see `eij --help`.

#[macro_use]
mod cli;

use clap::Parser;

/// The first paragraph of a clap error on one line, without the leading `error: `.
fn first_paragraph(text: &str) -> String {
    text.trim_start()
        .split("\n\n")
        .next()
        .unwrap_or("")
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
        .trim_start_matches("error: ")
        .to_string()
}

/// Caps the worker threads at what the machine has: `RAYON_NUM_THREADS=100000` would start
/// that many threads and stall the machine for minutes; more threads than cores never run a
/// job faster.
fn cap_threads() {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let Some(asked) = std::env::var_os("RAYON_NUM_THREADS") else {
        return;
    };
    let Ok(n) = asked.to_string_lossy().trim().parse::<usize>() else {
        return;
    };
    if n > cores {
        errln!(
            "eij: warning: RAYON_NUM_THREADS={n} is more than the {cores} core(s) this process may use: {cores} worker threads"
        );
        let _ = rayon::ThreadPoolBuilder::new()
            .num_threads(cores)
            .build_global();
    }
}

fn main() -> std::process::ExitCode {
    // SIGPIPE stays ignored (Rust's default): a reader that goes away (`eij identify | head`)
    // is a failed write to standard output, which `console` turns into a quiet end, after
    // the run's files are written.
    let cli = match cli::Cli::try_parse() {
        Ok(cli) => cli,
        Err(e)
            if !e.use_stderr()
                || e.kind() == clap::error::ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand =>
        {
            e.exit()
        }
        Err(e) => {
            // clap's message spans several lines (usage, tips); the contract is one line.
            errln!("eij: error: {}", first_paragraph(&e.render().to_string()));
            return std::process::ExitCode::from(e.exit_code().clamp(1, 255) as u8);
        }
    };
    cap_threads();
    let result = cli.run();
    let printed = cli::console::finish();
    match (result, printed) {
        (Err(e), _) if e.is::<cli::evaluate_diagnosis::OutOfTolerance>() => {
            errln!("eij: {e}");
            std::process::ExitCode::from(cli::evaluate_diagnosis::EXIT_CODE)
        }
        (Err(e), _) if e.is::<cli::compare::NotReproduced>() => {
            errln!("eij: {e}");
            std::process::ExitCode::from(cli::compare::EXIT_CODE)
        }
        (Err(e), _) => {
            let line = eij::text::compact_numbers(&format!("{e:#}").replace('\n', " "));
            errln!("eij: error: {line}");
            std::process::ExitCode::FAILURE
        }
        // The reader stopped reading: what it wanted it has, the files are written.
        (Ok(()), Some(e)) if e.kind() == std::io::ErrorKind::BrokenPipe => {
            std::process::ExitCode::SUCCESS
        }
        (Ok(()), Some(e)) => {
            errln!("eij: error: standard output: cannot write: {e} (the output files, if any, are written)");
            std::process::ExitCode::FAILURE
        }
        (Ok(()), None) => std::process::ExitCode::SUCCESS,
    }
}
