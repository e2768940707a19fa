//! The `eij` command line: a thin shell over the library; see `eij --help`.

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

fn main() -> std::process::ExitCode {
    // Like other Unix tools, end quietly when the reader of our output goes away
    // (`eij identify | head`) instead of panicking on a broken pipe.
    #[cfg(unix)]
    // SAFETY: restoring the default disposition of SIGPIPE before any thread is started.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
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
            eprintln!("eij: error: {}", first_paragraph(&e.render().to_string()));
            return std::process::ExitCode::from(e.exit_code().clamp(1, 255) as u8);
        }
    };
    match cli.run() {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            let line = eij::text::compact_numbers(&format!("{e:#}").replace('\n', " "));
            eprintln!("eij: error: {line}");
            std::process::ExitCode::FAILURE
        }
    }
}
