//! What a run prints.
//!
//! Standard output is collected and written once the run's files are written ([`flush`]: the
//! commands call it after their outputs, `main` at the end), so that a reader who stops early
//! (`eij identify | head -1`) or a full device never costs an output file, and a failure to
//! print never panics: `main` reports it once the work is done ([`finish`]). Lines on standard
//! error (warnings, status, errors) are written at once, a failure to write them ignored.
//! Control characters (an escape sequence in a file name, say) are shown escaped, never sent
//! to the terminal raw.

use std::io::Write;
use std::sync::{Mutex, MutexGuard};

/// Standard output not yet written.
static PENDING: Mutex<String> = Mutex::new(String::new());

/// The first failure to write standard output.
static FAILED: Mutex<Option<std::io::Error>> = Mutex::new(None);

/// Whether status lines and progress bars are off (`--quiet`).
static QUIET: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// `text` with every control character but those in `keep` escaped (`\u{1b}`, `\r`).
pub fn escape_controls(text: &str, keep: &[char]) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        if c.is_control() && !keep.contains(&c) {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    out
}

/// Adds to the run's standard output (written by [`flush`]).
pub fn print(args: std::fmt::Arguments) {
    let text = escape_controls(&args.to_string(), &['\n', '\t']);
    lock(&PENDING).push_str(&text);
}

/// Writes what the run has printed so far to standard output. After a first failure (a
/// closed pipe, a full device) nothing more is written; [`finish`] returns that failure.
pub fn flush() {
    let text = std::mem::take(&mut *lock(&PENDING));
    let mut failed = lock(&FAILED);
    if text.is_empty() || failed.is_some() {
        return;
    }
    let mut out = std::io::stdout().lock();
    if let Err(e) = out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        *failed = Some(e);
    }
}

/// Flushes standard output for the last time; the first failure to write it, if any.
pub fn finish() -> Option<std::io::Error> {
    flush();
    lock(&FAILED).take()
}

/// Writes one line to standard error, control characters (line ends too) escaped; a failure
/// to write is ignored (there is nowhere left to say it).
pub fn error_line(args: std::fmt::Arguments) {
    let line = escape_controls(&args.to_string(), &[]);
    let _ = writeln!(std::io::stderr().lock(), "{line}");
}

/// Turns status lines ([`status`]) and progress bars off (`--quiet`).
pub fn set_quiet(quiet: bool) {
    QUIET.store(quiet, std::sync::atomic::Ordering::SeqCst);
}

/// Whether `--quiet` was given.
pub fn quiet() -> bool {
    QUIET.load(std::sync::atomic::Ordering::SeqCst)
}

/// A status line on standard error (`eij: wrote out/map.csv`), after what the run printed on
/// standard output; none with `--quiet`.
pub fn status(args: std::fmt::Arguments) {
    flush();
    if !quiet() {
        error_line(format_args!("eij: {args}"));
    }
}

/// The status line of a run that wrote `paths`: `eij: wrote out/a.toml, out/b.json`.
pub fn wrote(paths: &[&std::path::Path]) {
    let list: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
    status(format_args!("wrote {}", list.join(", ")));
}

/// A progress bar on standard error while it lives (cleared when dropped): only on a terminal
/// and without `--quiet`; piped or quiet, nothing is drawn.
pub struct Progress(Option<indicatif::ProgressBar>);

impl Progress {
    /// A bar of `len` steps: `map 1200/3111 grid points [2s]`.
    pub fn bar(len: u64, what: &str, unit: &str) -> Progress {
        Progress::new(|| {
            let bar = indicatif::ProgressBar::new(len);
            bar.set_style(
                indicatif::ProgressStyle::with_template(&format!(
                    "{what} {{wide_bar}} {{pos}}/{{len}} {unit} [{{elapsed}}, ~{{eta}} left]"
                ))
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
            );
            bar
        })
    }

    /// A spinner for work without a count: `report: evaluating 36 circle tests [2s]`.
    pub fn spinner(what: &str) -> Progress {
        Progress::new(|| {
            let bar = indicatif::ProgressBar::new_spinner();
            bar.set_style(
                indicatif::ProgressStyle::with_template("{spinner} {msg} [{elapsed}]")
                    .unwrap_or_else(|_| indicatif::ProgressStyle::default_spinner()),
            );
            bar.set_message(what.to_string());
            bar.enable_steady_tick(std::time::Duration::from_millis(120));
            bar
        })
    }

    fn new(make: impl FnOnce() -> indicatif::ProgressBar) -> Progress {
        use std::io::IsTerminal;
        if quiet() || !std::io::stderr().is_terminal() {
            return Progress(None);
        }
        Progress(Some(make()))
    }

    /// Sets the position (steps done).
    pub fn set(&self, done: u64) {
        if let Some(b) = &self.0 {
            b.set_position(done);
        }
    }

    /// Sets the number of steps.
    pub fn set_len(&self, len: u64) {
        if let Some(b) = &self.0 {
            b.set_length(len);
        }
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        if let Some(b) = &self.0 {
            b.finish_and_clear();
        }
    }
}
