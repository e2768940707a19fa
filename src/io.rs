//! File output that never leaves a half-written or clobbered file behind.

use std::io::Write;
use std::path::{Path, PathBuf};

/// Errors of [`write_atomic`].
#[derive(Debug, thiserror::Error)]
pub enum WriteError {
    /// Creating, writing or renaming the temporary file failed.
    // The I/O error is part of the message rather than a `source`, so that `{:#}` chains
    // (`eij: error: …`) do not print it twice.
    #[error("{path}: cannot write: {cause}")]
    Io {
        /// The output path asked for.
        path: PathBuf,
        /// The underlying I/O error.
        cause: std::io::Error,
    },
    /// The output path names an existing folder.
    #[error("{path}: is a folder, not a file")]
    IsAFolder {
        /// The output path asked for.
        path: PathBuf,
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
    #[error("{path}: refusing to overwrite an input file")]
    WouldClobberInput {
        /// The output path asked for.
        path: PathBuf,
    },
}

/// Checks, before anything is computed or written, that every one of `outputs` can be written
/// by [`write_atomic`]: not a folder, in a folder that exists, not one of `inputs`, and no two
/// outputs the same file. A run that checks all its outputs first writes all or none of them
/// (short of a failing disk).
pub fn check_outputs(outputs: &[&Path], inputs: &[&Path]) -> Result<(), WriteError> {
    for (i, path) in outputs.iter().enumerate() {
        if path.is_dir() {
            return Err(WriteError::IsAFolder {
                path: path.to_path_buf(),
            });
        }
        let dir = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        if !dir.is_dir() {
            return Err(WriteError::NoFolder {
                path: path.to_path_buf(),
                folder: dir.to_path_buf(),
            });
        }
        if inputs.iter().any(|input| same_file(path, input)) {
            return Err(WriteError::WouldClobberInput {
                path: path.to_path_buf(),
            });
        }
        if outputs[..i].iter().any(|other| same_file(path, other)) {
            return Err(WriteError::SameOutput {
                path: path.to_path_buf(),
            });
        }
    }
    Ok(())
}

/// Whether two paths name the same file: the same existing file, or the same name in the same
/// existing folder (for outputs that do not exist yet).
fn same_file(a: &Path, b: &Path) -> bool {
    let canonical = |p: &Path| -> Option<PathBuf> {
        if let Ok(c) = p.canonicalize() {
            return Some(c);
        }
        let dir = match p.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        Some(dir.canonicalize().ok()?.join(p.file_name()?))
    };
    match (canonical(a), canonical(b)) {
        (Some(x), Some(y)) => x == y,
        _ => a == b,
    }
}

/// Writes `bytes` to `path` atomically: first to a temporary file in the same folder, then
/// renamed over `path`. A failure part-way leaves any previous `path` untouched.
///
/// `inputs` are the files read by the same run; an output that would replace one of them is
/// refused, and so is an output path that names a folder or lies in a folder that does not
/// exist (folders are never created).
pub fn write_atomic(path: &Path, bytes: &[u8], inputs: &[&Path]) -> Result<(), WriteError> {
    let io_err = |cause| WriteError::Io {
        path: path.to_path_buf(),
        cause,
    };
    check_outputs(&[path], inputs)?;
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let file_name = path
        .file_name()
        .ok_or_else(|| io_err(std::io::Error::other("not a file name")))?;
    let mut tmp_name = std::ffi::OsString::from(".");
    tmp_name.push(file_name);
    tmp_name.push(format!(".{}.tmp", std::process::id()));
    let tmp = dir.join(tmp_name);
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(io_err(e));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_and_replaces_but_never_an_input() {
        let dir = std::env::temp_dir().join(format!("eij-io-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let out = dir.join("out.txt");
        write_atomic(&out, b"first", &[]).unwrap();
        write_atomic(&out, b"second", &[]).unwrap();
        assert_eq!(std::fs::read(&out).unwrap(), b"second");
        let err = write_atomic(&out, b"third", &[out.as_path()]).unwrap_err();
        assert!(matches!(err, WriteError::WouldClobberInput { .. }));
        assert_eq!(std::fs::read(&out).unwrap(), b"second");
        let leftovers: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
            .collect();
        assert!(leftovers.is_empty());
        let other = dir.join("other.txt");
        let err = check_outputs(&[&other, &dir.join(".").join("other.txt")], &[]).unwrap_err();
        assert!(matches!(err, WriteError::SameOutput { .. }), "{err}");
        let err = write_atomic(&dir, b"x", &[]).unwrap_err();
        assert!(matches!(err, WriteError::IsAFolder { .. }), "{err}");
        let err = write_atomic(&dir.join("no/such.txt"), b"x", &[]).unwrap_err();
        assert!(matches!(err, WriteError::NoFolder { .. }), "{err}");
        assert!(!other.exists() && !dir.join("no").exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
