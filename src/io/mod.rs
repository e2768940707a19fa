//! Files in and out: inputs read within a size limit and remembered ([`read`]); the outputs of a
//! run checked before any work ([`check_outputs`]) and committed together ([`write_set`]), so
//! that a failure or a kill leaves either every old output or every new one.

use std::path::{Path, PathBuf};

mod commit;
pub(crate) mod delimited;
mod journal;
pub(crate) mod read;

pub use commit::{recover, write_set, StreamedOutput};
pub use read::{read_input, read_input_text, track_inputs, FileId, ReadError};

/// Errors of [`check_outputs`] and [`write_set`].
#[derive(Debug, thiserror::Error)]
pub enum WriteError {
    /// Creating, writing or renaming a file failed.
    // The I/O error is part of the message rather than a `source`, so that `{:#}` chains
    // (`eij: error: …`) do not print it twice.
    #[error("{path}: cannot write: {cause}")]
    Io {
        /// The output path asked for.
        path: PathBuf,
        /// The underlying I/O error.
        cause: std::io::Error,
    },
    /// The output path ends in a path separator, which names a folder, not a file.
    #[error("{path}: ends in a path separator, so it names a folder; give a file name")]
    EndsInSeparator {
        /// The output path asked for.
        path: PathBuf,
    },
    /// The output path names an existing folder.
    #[error("{path}: is a folder, not a file")]
    IsAFolder {
        /// The output path asked for.
        path: PathBuf,
    },
    /// The output path names something other than a regular file: eij never replaces a
    /// device, a FIFO, a socket or a symbolic link by a file.
    #[error("{path}: is a {kind}, not a regular file; eij replaces only regular files{hint}")]
    NotRegular {
        /// The output path asked for.
        path: PathBuf,
        /// `symbolic link`, `FIFO`, `character device`, …
        kind: &'static str,
        /// What to give instead, where there is something.
        hint: &'static str,
    },
    /// The output exists but cannot be replaced by a new file (immutable, append-only, a
    /// mount point, or another user's file in a folder with the sticky bit).
    #[error("{path}: cannot be replaced: {why}")]
    NotReplaceable {
        /// The output path asked for.
        path: PathBuf,
        /// Why not.
        why: &'static str,
    },
    /// The folder the output should go into does not exist.
    #[error("{path}: cannot write: folder {} does not exist", folder.display())]
    NoFolder {
        /// The output path asked for.
        path: PathBuf,
        /// Its parent folder.
        folder: PathBuf,
    },
    /// Two outputs of the same run name the same file.
    #[error("{path}: given for two outputs of the same run")]
    SameOutput {
        /// The output path asked for.
        path: PathBuf,
    },
    /// The output path names one of the inputs of the same run.
    #[error("{path}: refusing to overwrite an input file{via}")]
    WouldClobberInput {
        /// The output path asked for.
        path: PathBuf,
        /// ` (read as …)` where the input was named by another path.
        via: String,
    },
}

/// The folder an output goes into (`.` for a bare name).
pub(crate) fn folder_of(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// What kind of non-regular file `meta` describes, and what to give instead.
fn special_kind(meta: &std::fs::Metadata) -> Option<(&'static str, &'static str)> {
    let t = meta.file_type();
    if t.is_symlink() {
        return Some(("symbolic link", " (give the path of its target)"));
    }
    if t.is_file() || t.is_dir() {
        return None;
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return Some(("FIFO", ""));
        }
        if t.is_char_device() {
            return Some(("character device", ""));
        }
        if t.is_block_device() {
            return Some(("block device", ""));
        }
        if t.is_socket() {
            return Some(("socket", ""));
        }
    }
    Some(("special file", ""))
}

/// Why the existing regular file `path` (metadata `meta`) could not be replaced by renaming a
/// new file over it, where the system says so without trying: an immutable or append-only
/// file, a mount point, or, in a folder with the sticky bit, a file of another user.
fn not_replaceable(path: &Path, meta: &std::fs::Metadata) -> Option<&'static str> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        let folder = std::fs::metadata(folder_of(path)).ok()?;
        if folder.dev() != meta.dev() {
            return Some("it is a mount point");
        }
        // SAFETY: geteuid has no preconditions.
        let me = unsafe { libc::geteuid() };
        if folder.mode() & 0o1000 != 0 && me != 0 && me != meta.uid() && me != folder.uid() {
            return Some("another user's file in a folder with the sticky bit");
        }
    }
    #[cfg(all(target_os = "linux", any(target_env = "gnu", target_env = "musl")))]
    {
        use std::os::unix::ffi::OsStrExt;
        let c = std::ffi::CString::new(path.as_os_str().as_bytes()).ok()?;
        // SAFETY: statx writes into a zeroed struct of the right type; the path is a valid
        // C string; no link is followed.
        let attributes = unsafe {
            let mut x: libc::statx = std::mem::zeroed();
            let r = libc::statx(
                libc::AT_FDCWD,
                c.as_ptr(),
                libc::AT_SYMLINK_NOFOLLOW,
                libc::STATX_BASIC_STATS,
                &mut x,
            );
            if r != 0 {
                return None;
            }
            x.stx_attributes & x.stx_attributes_mask
        };
        if attributes & libc::STATX_ATTR_IMMUTABLE as u64 != 0 {
            return Some("it is immutable (chattr +i)");
        }
        if attributes & libc::STATX_ATTR_APPEND as u64 != 0 {
            return Some("it is append-only (chattr +a)");
        }
        if attributes & libc::STATX_ATTR_MOUNT_ROOT as u64 != 0 {
            return Some("it is a mount point");
        }
    }
    let _ = (path, meta);
    None
}

/// The path an output will have once written: its folder made absolute and without links,
/// plus its name (for comparing outputs that do not exist yet).
fn resolved(path: &Path) -> Option<PathBuf> {
    Some(folder_of(path).canonicalize().ok()?.join(path.file_name()?))
}

/// Checks, before anything is computed or written, that every one of `outputs` can be written
/// by [`write_set`]: a regular file or nothing yet (never a folder, a device, a FIFO, a socket
/// or a symbolic link), in a folder that exists and takes new files, not one of `inputs` nor
/// any file the run has read so far ([`read::track_inputs`]), whatever path names it, and no
/// two outputs the same file. A run that checks all its outputs first writes all or none of
/// them.
pub fn check_outputs(outputs: &[&Path], inputs: &[&Path]) -> Result<(), WriteError> {
    let mut known: Vec<(FileId, PathBuf)> = read::inputs_read();
    known.extend(
        inputs
            .iter()
            .filter_map(|p| Some((FileId::of(p)?, p.to_path_buf()))),
    );
    let mut seen: Vec<PathBuf> = Vec::new();
    for path in outputs {
        let out = path.to_path_buf();
        // `out/` names a folder whether or not it exists (`Path` would read it as `out`).
        let text = path.as_os_str().as_encoded_bytes();
        if text
            .last()
            .is_some_and(|b| std::path::is_separator(char::from(*b)))
        {
            return Err(WriteError::EndsInSeparator { path: out });
        }
        if path.file_name().is_none() {
            return Err(WriteError::IsAFolder { path: out });
        }
        match std::fs::symlink_metadata(path) {
            Ok(m) if m.is_dir() => return Err(WriteError::IsAFolder { path: out }),
            Ok(m) => {
                if let Some((kind, hint)) = special_kind(&m) {
                    return Err(WriteError::NotRegular {
                        path: out,
                        kind,
                        hint,
                    });
                }
                if let Some(why) = not_replaceable(path, &m) {
                    return Err(WriteError::NotReplaceable { path: out, why });
                }
                let id = FileId::of(path);
                if let Some((_, input)) = known.iter().find(|(i, _)| Some(i) == id.as_ref()) {
                    let via = if input == *path {
                        String::new()
                    } else {
                        format!(" (read as {})", input.display())
                    };
                    return Err(WriteError::WouldClobberInput { path: out, via });
                }
            }
            Err(e) => {
                let dir = folder_of(path);
                if !dir.is_dir() {
                    return Err(WriteError::NoFolder {
                        path: out,
                        folder: dir,
                    });
                }
                // A name too long, no permission to look: found now, not after the work.
                if e.kind() != std::io::ErrorKind::NotFound {
                    return Err(WriteError::Io {
                        path: out,
                        cause: e,
                    });
                }
            }
        }
        let name = resolved(path).unwrap_or_else(|| out.clone());
        if seen.contains(&name) {
            return Err(WriteError::SameOutput { path: out });
        }
        commit::probe_folder(path)?;
        seen.push(name);
    }
    Ok(())
}

/// Writes `bytes` to `path` like [`write_set`] with one file.
pub fn write_atomic(path: &Path, bytes: &[u8], inputs: &[&Path]) -> Result<(), WriteError> {
    write_set(&[(path, bytes)], inputs)
}
