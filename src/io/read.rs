//! Reading input files: bounded in size (an endless device or pipe stops at the limit instead of
//! filling the memory), and, in a command-line run, recorded so that no output of the run can
//! replace any file it read, directly or through another file.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

/// Most bytes of one measured series (R-Test CSV, split recording, move CSV): about 8 million
/// rows of seven numbers with ten digits each.
pub(crate) const MAX_SERIES_BYTES: u64 = 512 << 20;

/// Most bytes of one description file (machine, catalogue, `rtest.toml`, config, EIJ table,
/// map, compensation table, report JSON).
pub(crate) const MAX_TEXT_BYTES: u64 = 64 << 20;

/// Why an input could not be read.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ReadError {
    /// Nothing at that path.
    #[error("file not found")]
    NotFound,
    /// The path names a folder.
    #[error("is a folder, not a file")]
    IsAFolder,
    /// The input holds more than the limit (or never ends: a device, a pipe).
    #[error("holds more than {} (the most eij reads from one input; an endless device or pipe?)", bytes_text(*limit))]
    TooLarge {
        /// The limit, bytes.
        limit: u64,
    },
    /// Any other failure, as the system reports it.
    #[error("{0}")]
    Io(String),
}

/// `512 MiB`, `64 MiB`, `12 bytes`.
fn bytes_text(b: u64) -> String {
    if b >= 1 << 20 && b % (1 << 20) == 0 {
        format!("{} MiB", b >> 20)
    } else {
        format!("{b} bytes")
    }
}

/// What identifies a file whatever path names it (hard links, symbolic links, `./a` and `a`).
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct FileId(Id);

#[cfg(unix)]
type Id = (u64, u64);
#[cfg(not(unix))]
type Id = PathBuf;

impl FileId {
    /// The identity of the file `path` names (symbolic links followed), if it exists.
    pub fn of(path: &Path) -> Option<FileId> {
        #[cfg(unix)]
        {
            use std::os::unix::fs::MetadataExt;
            let m = std::fs::metadata(path).ok()?;
            Some(FileId((m.dev(), m.ino())))
        }
        #[cfg(not(unix))]
        {
            path.canonicalize().ok().map(FileId)
        }
    }
}

static TRACKING: AtomicBool = AtomicBool::new(false);
static READ: Mutex<Vec<(FileId, PathBuf)>> = Mutex::new(Vec::new());

/// From now on, every file read through [`read_input`] is remembered, and no output written
/// through [`super::write_set`] may replace any of them. The `eij` binary turns this on for its
/// one run; a library user that runs several jobs in one process checks its inputs explicitly.
pub fn track_inputs() {
    TRACKING.store(true, Ordering::SeqCst);
}

/// The files read so far (while [`track_inputs`] is on), with the path they were read by.
pub(crate) fn inputs_read() -> Vec<(FileId, PathBuf)> {
    READ.lock().map(|r| r.clone()).unwrap_or_default()
}

/// Remembers `path` as an input of the run (while [`track_inputs`] is on).
pub(crate) fn record_input(path: &Path) {
    if !TRACKING.load(Ordering::SeqCst) {
        return;
    }
    if let (Some(id), Ok(mut read)) = (FileId::of(path), READ.lock()) {
        if !read.iter().any(|(i, _)| *i == id) {
            read.push((id, path.to_path_buf()));
        }
    }
}

/// Reads a whole input file of at most `max_bytes` bytes. Devices and pipes are read like
/// files, up to the limit; a missing path and a folder are told apart from other failures.
/// Lines ending in CR alone come back ending in LF ([`unix_line_ends`]).
pub fn read_input(path: &Path, max_bytes: u64) -> Result<Vec<u8>, ReadError> {
    let mut bytes = Vec::new();
    open_input(path, max_bytes)?
        .read_to_end(&mut bytes)
        .map_err(|e| ReadError::Io(e.to_string()))?;
    if bytes.len() as u64 > max_bytes {
        return Err(ReadError::TooLarge { limit: max_bytes });
    }
    Ok(unix_line_ends(bytes))
}

/// A text whose lines end in CR alone (classic Mac OS exports) with LF line ends instead, so
/// that it is read line by line rather than as one line; other texts as they are (CR LF is
/// read as a line end everywhere).
pub(crate) fn unix_line_ends(mut bytes: Vec<u8>) -> Vec<u8> {
    if bytes.contains(&b'\r') && !bytes.contains(&b'\n') {
        for b in &mut bytes {
            if *b == b'\r' {
                *b = b'\n';
            }
        }
    }
    bytes
}

/// [`read_input`] as UTF-8 text.
pub fn read_input_text(path: &Path, max_bytes: u64) -> Result<String, ReadError> {
    String::from_utf8(read_input(path, max_bytes)?).map_err(|e| {
        ReadError::Io(format!(
            "not valid UTF-8 text (byte {})",
            e.utf8_error().valid_up_to()
        ))
    })
}

/// Opens an input file to be read as a stream of at most `max_bytes` bytes (large FE matrices
/// are parsed line by line rather than held whole): the same checks and recording as
/// [`read_input`]; the reader stops after `max_bytes + 1` bytes, so a caller that reads more
/// than `max_bytes` knows the input is too large.
pub(crate) fn open_input(
    path: &Path,
    max_bytes: u64,
) -> Result<std::io::Take<std::fs::File>, ReadError> {
    let meta = std::fs::metadata(path).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => ReadError::NotFound,
        _ => ReadError::Io(e.to_string()),
    })?;
    if meta.is_dir() {
        return Err(ReadError::IsAFolder);
    }
    if meta.is_file() && meta.len() > max_bytes {
        return Err(ReadError::TooLarge { limit: max_bytes });
    }
    let file = std::fs::File::open(path).map_err(|e| ReadError::Io(e.to_string()))?;
    record_input(path);
    Ok(file.take(max_bytes + 1))
}
