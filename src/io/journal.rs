//! The names eij gives its temporary files, the journal of a commit, the recovery of what a
//! killed run left, and the lock that lets one run at a time commit into a folder.
//!
//! Every temporary file is named `.eij-<pid>-<n>-<h>.tmp`, with `<h>` the hash of the name of
//! the output it will replace ([`name_hash`]), and every journal `.eij-<pid>-<n>.commit`. A
//! journal or a temporary file is only ever acted on when its process no longer runs, when it
//! is a regular file, and when it names nothing but eij's own temporary files of that process
//! beside the outputs they replace ([`recover`]); of those, recovery touches only the ones for
//! the outputs the current run was asked to write. A file merely named like a journal can
//! therefore neither delete a user's file nor move one over an input, and a FIFO so named is
//! never opened in a way that could block.

use std::io::Read;
use std::path::{Path, PathBuf};

/// Prefix of every temporary name.
pub(super) const PREFIX: &str = ".eij-";

/// Most bytes of a journal read back (a journal lists a few dozen paths).
const MAX_JOURNAL_BYTES: u64 = 1 << 20;

/// The journal of a commit: the renames (temporary file, output), and every folder's copy.
#[derive(serde::Serialize, serde::Deserialize, PartialEq)]
pub(super) struct Journal {
    pub renames: Vec<(PathBuf, PathBuf)>,
    pub copies: Vec<PathBuf>,
}

/// 16 hex digits (FNV-1a, 64 bit) of an output's file name: ties a temporary name to the
/// output it replaces without spelling that name out (a 255-byte name still fits).
pub(super) fn name_hash(name: &std::ffi::OsStr) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in name.as_encoded_bytes() {
        h ^= u64::from(*b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    format!("{h:016x}")
}

/// A name eij gives its own files.
#[derive(Debug, PartialEq)]
enum OwnName {
    /// `.eij-<pid>-<n>-<h>.tmp`: a new output, `h` the hash of the output's name.
    Temporary { pid: u32, hash: String },
    /// `.eij-<pid>-<n>.commit`.
    Journal { pid: u32 },
}

fn parse_name(name: &str) -> Option<OwnName> {
    let rest = name.strip_prefix(PREFIX)?;
    if let Some(stem) = rest.strip_suffix(".tmp") {
        let mut parts = stem.split('-');
        let pid = parts.next()?.parse().ok()?;
        parts.next()?.parse::<u64>().ok()?;
        let hash = parts.next()?;
        let hex = hash.len() == 16 && hash.bytes().all(|b| b.is_ascii_hexdigit());
        return (hex && parts.next().is_none()).then(|| OwnName::Temporary {
            pid,
            hash: hash.to_string(),
        });
    }
    let stem = rest.strip_suffix(".commit")?;
    let (pid, n) = stem.split_once('-')?;
    n.parse::<u64>().ok()?;
    Some(OwnName::Journal {
        pid: pid.parse().ok()?,
    })
}

fn file_name_of(path: &Path) -> Option<&str> {
    path.file_name()?.to_str()
}

/// Whether `path` is a regular file (a symbolic link is not followed).
fn is_regular(path: &Path) -> bool {
    std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_file())
}

/// Reads a journal without ever blocking: only a regular file, not through a symbolic link,
/// opened non-blocking (a FIFO put in its place between the check and the opening is then
/// refused rather than waited on), at most [`MAX_JOURNAL_BYTES`].
fn read_journal(path: &Path) -> Option<Journal> {
    if !is_regular(path) {
        return None;
    }
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK | libc::O_NOFOLLOW);
    }
    let file = options.open(path).ok()?;
    if !file.metadata().ok()?.file_type().is_file() {
        return None;
    }
    let mut bytes = Vec::new();
    file.take(MAX_JOURNAL_BYTES).read_to_end(&mut bytes).ok()?;
    serde_json::from_slice(&bytes).ok()
}

impl Journal {
    /// Whether the journal is one eij wrote as process `pid`: every rename moves a temporary
    /// file of `pid`, made for that very output and beside it, onto an absolute path; every
    /// copy is a journal name of `pid`, `copy` among them.
    fn is_own(&self, pid: u32, copy: &Path) -> bool {
        let temporary_for = |tmp: &Path, target: &Path| {
            let (Some(name), Some(target_name)) = (file_name_of(tmp), target.file_name()) else {
                return false;
            };
            target.is_absolute()
                && tmp.parent() == target.parent()
                && parse_name(name)
                    == Some(OwnName::Temporary {
                        pid,
                        hash: name_hash(target_name),
                    })
        };
        let journal_of_pid =
            |c: &Path| file_name_of(c).and_then(parse_name) == Some(OwnName::Journal { pid });
        !self.renames.is_empty()
            && self
                .renames
                .iter()
                .all(|(tmp, target)| temporary_for(tmp, target))
            && self.copies.iter().all(|c| journal_of_pid(c))
            && self.copies.iter().any(|c| c == copy)
    }
}

/// Whether process `pid` still runs (then its files are left alone).
fn alive(pid: u32) -> bool {
    if pid == std::process::id() {
        return true;
    }
    #[cfg(unix)]
    {
        let Ok(p) = libc::pid_t::try_from(pid) else {
            return false;
        };
        if p <= 0 {
            return true;
        }
        // SAFETY: signal 0 only checks that the process exists.
        let r = unsafe { libc::kill(p, 0) };
        r == 0 || std::io::Error::last_os_error().raw_os_error() == Some(libc::EPERM)
    }
    #[cfg(not(unix))]
    {
        true
    }
}

/// Completes or undoes, for the outputs of this run (`outputs`: absolute paths with their
/// folder resolved, as [`super::write_set`] writes them), what a killed eij left in `dir`:
/// where a journal of the dead process was written in full into every folder, its temporary
/// file for such an output is renamed over it (the new set); else that temporary file is
/// removed (the old set stays). Other temporary files in `dir` of dead processes made for one
/// of these outputs are removed; a journal goes once none of its temporary files is left. Nothing else
/// is touched: not another output's temporary files, not a file a journal names that is not
/// eij's temporary file beside its output, not a journal that is not eij's (module docs).
pub fn recover(dir: &Path, outputs: &[PathBuf]) {
    let hashes: Vec<String> = outputs
        .iter()
        .filter(|t| t.parent() == Some(dir))
        .filter_map(|t| t.file_name().map(name_hash))
        .collect();
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut journals: Vec<(PathBuf, u32)> = Vec::new();
    let mut temporaries: Vec<PathBuf> = Vec::new();
    for entry in entries.filter_map(|e| e.ok()) {
        let name = entry.file_name();
        let Some(own) = name.to_str().and_then(parse_name) else {
            continue;
        };
        let path = entry.path();
        match own {
            OwnName::Journal { pid } if !alive(pid) => journals.push((path, pid)),
            OwnName::Temporary { pid, hash } if !alive(pid) && hashes.contains(&hash) => {
                temporaries.push(path)
            }
            _ => {}
        }
    }
    let mut in_journals: Vec<PathBuf> = Vec::new();
    for (path, pid) in &journals {
        let Some(journal) = read_journal(path).filter(|j| j.is_own(*pid, path)) else {
            continue;
        };
        in_journals.extend(journal.renames.iter().map(|(tmp, _)| tmp.clone()));
        // Committed only once every copy was written in full: then the renames are
        // completed, else the new files are dropped and the old set stays.
        let committed = journal
            .copies
            .iter()
            .all(|c| read_journal(c).is_some_and(|o| o.renames == journal.renames));
        for (tmp, target) in &journal.renames {
            if !outputs.contains(target) || !is_regular(tmp) {
                continue;
            }
            if committed {
                let _ = std::fs::rename(tmp, target);
            } else {
                let _ = std::fs::remove_file(tmp);
            }
        }
        let settled = journal
            .renames
            .iter()
            .all(|(tmp, _)| std::fs::symlink_metadata(tmp).is_err());
        if settled {
            for c in journal.copies.iter().filter(|c| is_regular(c)) {
                let _ = std::fs::remove_file(c);
            }
        }
    }
    for t in temporaries {
        if !in_journals.contains(&t) && is_regular(&t) {
            let _ = std::fs::remove_file(t);
        }
    }
}

/// Exclusive locks on the output folders of one commit, released when dropped: two runs
/// committing into the same folder take turns, so the set of outputs is always one run's.
/// (An advisory `flock` on the folder itself: no lock file is left behind; a folder that
/// cannot be opened for reading is committed into without one.)
pub(super) struct FolderLocks {
    _held: Vec<std::fs::File>,
}

impl FolderLocks {
    /// Locks `folders` (resolved paths), in sorted order so that runs never wait on each other
    /// in a circle.
    pub(super) fn new(folders: &[PathBuf]) -> FolderLocks {
        let mut sorted: Vec<&PathBuf> = folders.iter().collect();
        sorted.sort();
        sorted.dedup();
        let held = sorted
            .into_iter()
            .filter_map(|d| {
                let f = std::fs::File::open(d).ok()?;
                lock(&f);
                Some(f)
            })
            .collect();
        FolderLocks { _held: held }
    }
}

#[cfg(unix)]
fn lock(f: &std::fs::File) {
    use std::os::fd::AsRawFd;
    loop {
        // SAFETY: flock on a file descriptor this function borrows; released on close.
        let r = unsafe { libc::flock(f.as_raw_fd(), libc::LOCK_EX) };
        if r == 0 || std::io::Error::last_os_error().kind() != std::io::ErrorKind::Interrupted {
            return;
        }
    }
}

#[cfg(not(unix))]
fn lock(_f: &std::fs::File) {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn own_names_are_told_from_others() {
        let h = name_hash(std::ffi::OsStr::new("report.json"));
        assert_eq!(h.len(), 16);
        assert_ne!(h, name_hash(std::ffi::OsStr::new("report.jsoN")));
        assert_eq!(
            parse_name(&format!(".eij-12-3-{h}.tmp")),
            Some(OwnName::Temporary { pid: 12, hash: h })
        );
        assert_eq!(
            parse_name(".eij-12-3.commit"),
            Some(OwnName::Journal { pid: 12 })
        );
        for other in [
            ".eij-12-3.tmp",
            ".eij-12-3-xyz.tmp",
            ".eij-x-3.commit",
            "eij-12-3.commit",
            ".eij-12.commit",
            "notes.txt",
        ] {
            assert_eq!(parse_name(other), None, "{other}");
        }
    }
}
