//! Committing the outputs of a run together.
//!
//! 1. The output folders are locked ([`FolderLocks`]: a concurrent run waits), and what a
//!    killed run left there for these outputs is recovered ([`recover`]).
//! 2. Every new file is written in full to a temporary file beside its target,
//!    `.eij-<pid>-<n>-<h>.tmp` (short, whatever the target's name: a 255-byte name still fits;
//!    `<h>` ties it to its target), with the permissions and owner of the file it replaces,
//!    and synced.
//! 3. For more than one file, a journal `.eij-<pid>-<n>.commit` listing the renames is written
//!    into every folder involved, and synced.
//! 4. The temporary files are renamed over their targets, the folders synced, the journals
//!    removed, the folders unlocked.
//!
//! Interrupt, terminate and hang-up signals that arrive during 2–4 are held until the commit
//! ends, so such a kill leaves the old set (before 2) or the new set. Only a SIGKILL or a power
//! loss can stop the commit half-way: then the next commit of one of those outputs finds the
//! journal of the dead process and completes its renames (or, without a complete journal,
//! removes its temporary files), before writing its own outputs ([`recover`]).

pub use super::journal::recover;
use super::journal::{name_hash, FolderLocks, Journal, PREFIX};
use super::{check_outputs, folder_of, WriteError};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// Numbers the temporary names of one process.
static NEXT: AtomicUsize = AtomicUsize::new(0);

/// One commit at a time per process (the signal handling is process-wide).
static COMMIT: Mutex<()> = Mutex::new(());

fn next_name(dir: &Path, tail: &str) -> PathBuf {
    let n = NEXT.fetch_add(1, Ordering::SeqCst);
    dir.join(format!("{PREFIX}{}-{n}{tail}", std::process::id()))
}

/// A new temporary name for the output `target`, in its folder.
fn temp_name(target: &Path) -> PathBuf {
    let hash = name_hash(target.file_name().unwrap_or_default());
    next_name(&folder_of(target), &format!("-{hash}.tmp"))
}

/// Checks that the folder of `path` takes new files, by creating and removing one.
pub(super) fn probe_folder(path: &Path) -> Result<(), WriteError> {
    // Like a commit: a kill between creating and removing the probe would leave it behind.
    let _one = COMMIT.lock().unwrap_or_else(|e| e.into_inner());
    let _held = signals::Held::new();
    let probe = temp_name(path);
    std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe)
        .map_err(|cause| WriteError::Io {
            path: path.to_path_buf(),
            cause,
        })?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

/// Writes every `(path, bytes)` as one set (module docs): after an error, nothing of the set is
/// written and every old file is as it was; after a commit stopped by a kill, the old set or
/// (once recovered) the new set. `inputs` and every file the run has read are never replaced;
/// every output is checked by [`check_outputs`] first.
pub fn write_set(files: &[(&Path, &[u8])], inputs: &[&Path]) -> Result<(), WriteError> {
    let paths: Vec<&Path> = files.iter().map(|(p, _)| *p).collect();
    check_outputs(&paths, inputs)?;
    let mut folders: Vec<PathBuf> = Vec::new();
    for p in &paths {
        let d = folder_of(p);
        let d = d.canonicalize().unwrap_or(d);
        if !folders.contains(&d) {
            folders.push(d);
        }
    }
    let targets: Vec<PathBuf> = paths.iter().map(|p| target_of(p)).collect();
    let _one = COMMIT.lock().unwrap_or_else(|e| e.into_inner());
    let _locks = FolderLocks::new(&folders);
    for d in &folders {
        recover(d, &targets);
    }
    let _held = signals::Held::new();
    let mut staged: Vec<(PathBuf, PathBuf)> = Vec::new();
    let remove_all = |staged: &[(PathBuf, PathBuf)], journals: &[PathBuf]| {
        for (tmp, _) in staged {
            let _ = std::fs::remove_file(tmp);
        }
        for j in journals {
            let _ = std::fs::remove_file(j);
        }
    };
    for ((path, bytes), target) in files.iter().zip(&targets) {
        let target = target.clone();
        let tmp = temp_name(&target);
        if let Err(cause) = stage(&tmp, &target, bytes) {
            let _ = std::fs::remove_file(&tmp);
            remove_all(&staged, &[]);
            return Err(WriteError::Io {
                path: path.to_path_buf(),
                cause,
            });
        }
        staged.push((tmp, target));
    }
    let journals = if staged.len() > 1 {
        match write_journals(&staged, &folders) {
            Ok(j) => j,
            Err(cause) => {
                remove_all(&staged, &[]);
                return Err(WriteError::Io {
                    path: folders[0].clone(),
                    cause,
                });
            }
        }
    } else {
        Vec::new()
    };
    for (i, (tmp, target)) in staged.iter().enumerate() {
        if let Err(cause) = std::fs::rename(tmp, target) {
            remove_all(&staged[i..], &journals);
            return Err(WriteError::Io {
                path: paths[i].to_path_buf(),
                cause,
            });
        }
    }
    for d in &folders {
        sync_folder(d);
    }
    remove_all(&[], &journals);
    Ok(())
}

/// Writes `bytes` to the new file `tmp` with the permissions (and, where allowed, the owner)
/// of `target` if it exists, and syncs it.
fn stage(tmp: &Path, target: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let mut f = open_staged(tmp, target)?;
    f.write_all(bytes)?;
    f.sync_all()
}

/// Creates the new file `tmp` with the permissions (and, where allowed, the owner) of `target`
/// if it exists.
fn open_staged(tmp: &Path, target: &Path) -> std::io::Result<std::fs::File> {
    let f = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(tmp)?;
    if let Ok(old) = std::fs::metadata(target) {
        // Before the content goes in: a private file's new content is never readable by others.
        f.set_permissions(old.permissions())?;
        #[cfg(unix)]
        {
            use std::os::unix::fs::MetadataExt;
            let _ = std::os::unix::fs::fchown(&f, Some(old.uid()), Some(old.gid()));
        }
    }
    Ok(f)
}

/// The canonical target of an output path (its folder resolved, its name kept).
fn target_of(path: &Path) -> PathBuf {
    folder_of(path)
        .canonicalize()
        .map(|d| d.join(path.file_name().unwrap_or_default()))
        .unwrap_or_else(|_| path.to_path_buf())
}

/// A single output written piece by piece into its temporary file while the run computes it
/// (for output too long to hold in memory), then committed as a set of one file
/// ([`write_set`]'s steps 1 and 3: same temporary name, permissions, held signals, recovery).
/// Dropped without [`StreamedOutput::commit`] (an error, an early return), it removes its
/// temporary file and leaves the old output as it was.
pub struct StreamedOutput {
    path: PathBuf,
    target: PathBuf,
    tmp: PathBuf,
    file: std::io::BufWriter<std::fs::File>,
    committed: bool,
}

impl StreamedOutput {
    /// Checks `path` like every output ([`check_outputs`], `inputs` never replaced) and
    /// creates its temporary file.
    pub fn create(path: &Path, inputs: &[&Path]) -> Result<StreamedOutput, WriteError> {
        check_outputs(&[path], inputs)?;
        let target = target_of(path);
        let tmp = temp_name(&target);
        let file = open_staged(&tmp, &target).map_err(|cause| {
            let _ = std::fs::remove_file(&tmp);
            WriteError::Io {
                path: path.to_path_buf(),
                cause,
            }
        })?;
        Ok(StreamedOutput {
            path: path.to_path_buf(),
            target,
            tmp,
            file: std::io::BufWriter::with_capacity(1 << 16, file),
            committed: false,
        })
    }

    /// Where the content goes (buffered).
    pub fn writer(&mut self) -> &mut std::io::BufWriter<std::fs::File> {
        &mut self.file
    }

    /// Syncs the temporary file and renames it over the output.
    pub fn commit(mut self) -> Result<(), WriteError> {
        let io_err = |cause| WriteError::Io {
            path: self.path.clone(),
            cause,
        };
        self.file.flush().map_err(io_err)?;
        self.file.get_ref().sync_all().map_err(io_err)?;
        let folder = folder_of(&self.target);
        let _one = COMMIT.lock().unwrap_or_else(|e| e.into_inner());
        let _lock = FolderLocks::new(std::slice::from_ref(&folder));
        recover(&folder, std::slice::from_ref(&self.target));
        let _held = signals::Held::new();
        std::fs::rename(&self.tmp, &self.target).map_err(io_err)?;
        sync_folder(&folder);
        self.committed = true;
        Ok(())
    }
}

impl Drop for StreamedOutput {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

fn write_journals(
    staged: &[(PathBuf, PathBuf)],
    folders: &[PathBuf],
) -> std::io::Result<Vec<PathBuf>> {
    let copies: Vec<PathBuf> = folders.iter().map(|d| next_name(d, ".commit")).collect();
    let text = serde_json::to_vec(&Journal {
        renames: staged.to_vec(),
        copies: copies.clone(),
    })?;
    let mut written = Vec::new();
    for c in &copies {
        let result = std::fs::File::create(c).and_then(|mut f| {
            f.write_all(&text)?;
            f.sync_all()
        });
        written.push(c.clone());
        if let Err(e) = result {
            for w in &written {
                let _ = std::fs::remove_file(w);
            }
            return Err(e);
        }
    }
    for d in folders {
        sync_folder(d);
    }
    Ok(written)
}

fn sync_folder(dir: &Path) {
    if let Ok(f) = std::fs::File::open(dir) {
        let _ = f.sync_all();
    }
}

#[cfg(unix)]
mod signals {
    //! Interrupt, terminate, hang-up and quit held during a commit, delivered after it.
    use std::sync::atomic::{AtomicI32, Ordering};

    const HELD: [libc::c_int; 4] = [libc::SIGINT, libc::SIGTERM, libc::SIGHUP, libc::SIGQUIT];
    static PENDING: AtomicI32 = AtomicI32::new(0);

    extern "C" fn note(sig: libc::c_int) {
        PENDING.store(sig, Ordering::SeqCst);
    }

    /// While alive, the signals are noted instead of acted on; dropped, the previous
    /// dispositions return and a noted signal is raised again.
    pub(super) struct Held {
        old: Vec<(libc::c_int, libc::sigaction)>,
    }

    impl Held {
        pub(super) fn new() -> Held {
            let mut old = Vec::new();
            for sig in HELD {
                // SAFETY: plain sigaction calls with zero-initialised structs; the handler only
                // stores into an atomic, which is async-signal-safe.
                unsafe {
                    let mut new: libc::sigaction = std::mem::zeroed();
                    new.sa_sigaction = note as extern "C" fn(libc::c_int) as libc::sighandler_t;
                    libc::sigemptyset(&mut new.sa_mask);
                    let mut prev: libc::sigaction = std::mem::zeroed();
                    if libc::sigaction(sig, &new, &mut prev) == 0 {
                        old.push((sig, prev));
                    }
                }
            }
            Held { old }
        }
    }

    impl Drop for Held {
        fn drop(&mut self) {
            for (sig, prev) in &self.old {
                // SAFETY: restores the disposition saved in `new`.
                unsafe {
                    libc::sigaction(*sig, prev, std::ptr::null_mut());
                }
            }
            let sig = PENDING.swap(0, Ordering::SeqCst);
            if sig != 0 {
                // SAFETY: re-raises a signal that arrived during the commit, now under its
                // previous disposition.
                unsafe {
                    libc::raise(sig);
                }
            }
        }
    }
}

#[cfg(not(unix))]
mod signals {
    /// Nothing to hold on this platform.
    pub struct Held;

    impl Held {
        pub fn new() -> Held {
            Held
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A process id that runs nowhere (above any pid_max).
    const DEAD: u32 = i32::MAX as u32;

    fn scratch(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("eij-commit-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(d.join("b")).unwrap();
        d.canonicalize().unwrap()
    }

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    /// The temporary name a dead process gave output `name` in `dir`.
    fn dead_temporary(dir: &Path, n: u32, name: &str) -> PathBuf {
        let hash = name_hash(std::ffi::OsStr::new(name));
        dir.join(format!(".eij-{DEAD}-{n}-{hash}.tmp"))
    }

    /// The outputs `x` in `dir` and `y` in `dir/b`.
    fn outputs(dir: &Path) -> [PathBuf; 2] {
        [dir.join("x"), dir.join("b/y")]
    }

    /// What a commit killed after writing its temporary files and `copies` of its journal
    /// leaves behind, for outputs `x` in `dir` and `y` in `dir/b`.
    fn killed_commit(dir: &Path, copies: usize) {
        let staged = [
            (dead_temporary(dir, 1, "x"), dir.join("x")),
            (dead_temporary(&dir.join("b"), 2, "y"), dir.join("b/y")),
        ];
        for (tmp, _) in &staged {
            std::fs::write(tmp, "new").unwrap();
        }
        let journals = [
            dir.join(format!(".eij-{DEAD}-3.commit")),
            dir.join(format!("b/.eij-{DEAD}-4.commit")),
        ];
        let text = serde_json::to_vec(&Journal {
            renames: staged.to_vec(),
            copies: journals.to_vec(),
        })
        .unwrap();
        for j in &journals[..copies] {
            std::fs::write(j, &text).unwrap();
        }
    }

    #[test]
    fn a_journal_written_in_full_is_completed_from_either_folder() {
        for from_b in [false, true] {
            let dir = scratch(&format!("full-{from_b}"));
            std::fs::write(dir.join("x"), "old").unwrap();
            std::fs::write(dir.join("b/y"), "old").unwrap();
            killed_commit(&dir, 2);
            // The kill fell after the first rename.
            std::fs::rename(dead_temporary(&dir, 1, "x"), dir.join("x")).unwrap();
            recover(
                &if from_b { dir.join("b") } else { dir.clone() },
                &outputs(&dir),
            );
            assert_eq!(std::fs::read_to_string(dir.join("x")).unwrap(), "new");
            assert_eq!(std::fs::read_to_string(dir.join("b/y")).unwrap(), "new");
            assert_eq!(names(&dir), ["b", "x"]);
            assert_eq!(names(&dir.join("b")), ["y"]);
            std::fs::remove_dir_all(&dir).unwrap();
        }
    }

    #[test]
    fn a_journal_cut_short_leaves_the_old_set() {
        let dir = scratch("cut");
        std::fs::write(dir.join("x"), "old").unwrap();
        std::fs::write(dir.join("b/y"), "old").unwrap();
        killed_commit(&dir, 1);
        recover(&dir, &outputs(&dir));
        recover(&dir.join("b"), &outputs(&dir));
        assert_eq!(std::fs::read_to_string(dir.join("x")).unwrap(), "old");
        assert_eq!(std::fs::read_to_string(dir.join("b/y")).unwrap(), "old");
        assert_eq!(names(&dir), ["b", "x"]);
        assert_eq!(names(&dir.join("b")), ["y"]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_set_replaces_every_file_or_none() {
        let dir = scratch("set");
        let (x, y) = (dir.join("x"), dir.join("b/y"));
        write_set(&[(&x, b"1"), (&y, b"1")], &[]).unwrap();
        write_set(&[(&x, b"2"), (&y, b"2")], &[]).unwrap();
        assert_eq!(std::fs::read(&x).unwrap(), b"2");
        // One output an input: neither is written.
        let err = write_set(&[(&x, b"3"), (&y, b"3")], &[y.as_path()]).unwrap_err();
        assert!(matches!(err, WriteError::WouldClobberInput { .. }), "{err}");
        let err = write_set(&[(&x, b"3"), (&dir.join("./x"), b"3")], &[]).unwrap_err();
        assert!(matches!(err, WriteError::SameOutput { .. }), "{err}");
        let err = write_set(&[(&x, b"3"), (&dir.join("no/y"), b"3")], &[]).unwrap_err();
        assert!(matches!(err, WriteError::NoFolder { .. }), "{err}");
        let err = write_set(&[(&x, b"3"), (&dir.join("b"), b"3")], &[]).unwrap_err();
        assert!(matches!(err, WriteError::IsAFolder { .. }), "{err}");
        assert_eq!(std::fs::read(&x).unwrap(), b"2");
        assert_eq!(std::fs::read(&y).unwrap(), b"2");
        assert_eq!(names(&dir), ["b", "x"]);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
