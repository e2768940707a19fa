//! File output that never leaves a half-written or clobbered file behind.

use std::io::Write;
use std::path::{Path, PathBuf};

/// Errors of [`write_atomic`].
#[derive(Debug, thiserror::Error)]
pub enum WriteError {
    /// Creating, writing or renaming the temporary file failed.
    #[error("{path}: cannot write: {source}")]
    Io {
        /// The output path asked for.
        path: PathBuf,
        /// The underlying I/O error.
        source: std::io::Error,
    },
    /// The output path names one of the inputs of the same run.
    #[error("{path}: refusing to overwrite an input file")]
    WouldClobberInput {
        /// The output path asked for.
        path: PathBuf,
    },
}

/// Writes `bytes` to `path` atomically: first to a temporary file in the same folder, then
/// renamed over `path`. A failure part-way leaves any previous `path` untouched.
///
/// `inputs` are the files read by the same run; an output that would replace one of them is
/// refused.
pub fn write_atomic(path: &Path, bytes: &[u8], inputs: &[&Path]) -> Result<(), WriteError> {
    let io_err = |source| WriteError::Io {
        path: path.to_path_buf(),
        source,
    };
    if let Ok(out) = path.canonicalize() {
        for input in inputs {
            if input.canonicalize().is_ok_and(|i| i == out) {
                return Err(WriteError::WouldClobberInput {
                    path: path.to_path_buf(),
                });
            }
        }
    }
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
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
