//! The measured inputs of a command as circle tests: files and folders expanded, each test with
//! the conditions its folder's `rtest.toml` gives it (folder keys, overridden by its `[[test]]`
//! entry).

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use super::conditions::{
    folder_of, DataFiles, DiagnosisSettings, Session, TestConditions, TestEntry, MAX_TESTS,
};
use super::error::MeasuredError;
use super::layout::ColumnMap;
use crate::axes::{Direction, Plane};
use crate::io::FileId;
use crate::rtest::diagnosis::tolerance::Tolerances;
use crate::rtest::CircleSeries;

/// One circle test to read and evaluate, with everything known about its conditions.
#[derive(Debug, Clone, PartialEq)]
pub struct TestInput {
    /// Its data.
    pub data: DataFiles,
    /// The `rtest.toml` that states its conditions, if any.
    pub conditions_file: Option<PathBuf>,
    /// The number of its `[[test]]` entry, if it has one.
    pub entry: Option<usize>,
    /// Set radius, mm.
    pub radius_mm: Option<f64>,
    /// Circle-centre position, mm.
    pub position_mm: Option<Vec<f64>>,
    /// Circle plane, where stated.
    pub plane: Option<Plane>,
    /// Sense of rotation, where stated.
    pub direction: Option<Direction>,
    /// Programmed feed, mm/min.
    pub feed_mm_min: Option<f64>,
    /// Free text.
    pub note: Option<String>,
    /// The clock group (two-system tests): the folder, or the folder and the entry's `clock`.
    pub clock_group: String,
    /// A known clock offset, ms (internal clock minus external clock).
    pub time_offset_ms: Option<f64>,
    /// Column map of a single file.
    pub columns: ColumnMap,
    /// Column map of the internal file of a two-system test.
    pub internal_columns: ColumnMap,
    /// Column map of its external file.
    pub external_columns: ColumnMap,
    /// The limits it is judged against (`[tolerances]`).
    pub tolerances: Tolerances,
    /// Settings of its diagnosis (`[diagnosis]`).
    pub diagnosis: DiagnosisSettings,
    /// Machine, date, instrument and temperature of its measurement.
    pub session: Session,
}

impl TestInput {
    /// The test's name in outputs: its file, or `internal + external`.
    pub fn name(&self) -> String {
        match &self.data {
            DataFiles::Single(f) => f.display().to_string(),
            DataFiles::Split { internal, external } => {
                format!("{} + {}", internal.display(), external.display())
            }
        }
    }

    /// Every file the test is read from: its data file(s) and its `rtest.toml`.
    pub fn files(&self) -> Vec<PathBuf> {
        let mut v = match &self.data {
            DataFiles::Single(f) => vec![f.clone()],
            DataFiles::Split { internal, external } => vec![internal.clone(), external.clone()],
        };
        v.extend(self.conditions_file.clone());
        v
    }

    /// The file that orders and labels the test: its file, or its internal file.
    pub fn primary_file(&self) -> &Path {
        match &self.data {
            DataFiles::Single(f) => f,
            DataFiles::Split { internal, .. } => internal,
        }
    }

    /// Reads a single-file test (column map applied). Two-system tests are read and brought
    /// onto one time base by [`crate::rtest::clock`].
    pub fn read_single(&self) -> Result<CircleSeries, MeasuredError> {
        match &self.data {
            DataFiles::Single(f) => CircleSeries::read_csv_with(f, &self.columns),
            DataFiles::Split { .. } => Err(MeasuredError::Io {
                path: self.name(),
                message: "a test recorded by two systems is read through rtest::clock".into(),
            }),
        }
    }

    fn new(data: DataFiles, cond: &TestConditions, folder: &Path) -> TestInput {
        TestInput {
            data,
            conditions_file: cond.file.clone(),
            entry: None,
            radius_mm: cond.radius_mm,
            position_mm: cond.position_mm.clone(),
            plane: None,
            direction: None,
            feed_mm_min: None,
            note: None,
            clock_group: folder.display().to_string(),
            time_offset_ms: None,
            columns: cond.columns.clone(),
            internal_columns: cond.internal_columns.clone(),
            external_columns: cond.external_columns.clone(),
            tolerances: cond.tolerances.clone(),
            diagnosis: cond.diagnosis,
            session: cond.session.clone(),
        }
    }

    fn from_entry(e: &TestEntry, cond: &TestConditions, folder: &Path) -> TestInput {
        let mut t = TestInput::new(e.data.clone(), cond, folder);
        t.entry = Some(e.number);
        t.radius_mm = e.radius_mm.or(cond.radius_mm);
        t.position_mm = e.position_mm.clone().or_else(|| cond.position_mm.clone());
        t.plane = e.plane;
        t.direction = e.direction;
        t.feed_mm_min = e.feed_mm_min;
        t.note = e.note.clone();
        if let Some(c) = &e.clock {
            t.clock_group = format!("{} clock {c}", folder.display());
        }
        t.time_offset_ms = e.time_offset_ms;
        t
    }
}

/// The files an entry names, with the key that names them.
fn entry_files(e: &TestEntry) -> Vec<(&'static str, &Path)> {
    match &e.data {
        DataFiles::Single(f) => vec![("file", f)],
        DataFiles::Split { internal, external } => {
            vec![("internal", internal), ("external", external)]
        }
    }
}

/// Checks that every file of the folder's entries exists and that no two entries name the
/// same file (by identity: `a.csv`, `./a.csv` and a link to it are one file).
fn check_entries(cond: &TestConditions) -> Result<(), MeasuredError> {
    let file = cond
        .file
        .as_ref()
        .map_or(String::new(), |f| f.display().to_string());
    let mut seen: Vec<(FileId, String)> = Vec::new();
    for e in &cond.tests {
        for (key, path) in entry_files(e) {
            let at = format!("[[test]] #{} {key}", e.number);
            let bad = |message: String| MeasuredError::Conditions {
                file: file.clone(),
                key: at.clone(),
                message,
            };
            if path.is_dir() {
                return Err(bad(format!("{}: is a folder, not a file", path.display())));
            }
            let Some(id) = FileId::of(path) else {
                return Err(bad(format!("{}: file not found", path.display())));
            };
            if let Some((_, first)) = seen.iter().find(|(i, _)| *i == id) {
                return Err(bad(format!(
                    "{}: already named by {first} (each file is one test)",
                    path.display()
                )));
            }
            seen.push((id, at));
        }
    }
    Ok(())
}

/// The tests of a folder (its entries and the CSV files no entry names) and, recursively, of
/// its sub-folders, in path order. `ancestors` are the folders above it (by identity): a
/// folder inside itself (a symbolic-link loop) is an error, not a copy of its data.
fn folder_tests(dir: &Path, ancestors: &mut Vec<FileId>) -> Result<Vec<TestInput>, MeasuredError> {
    if let Some(id) = FileId::of(dir) {
        if ancestors.contains(&id) {
            return Err(MeasuredError::Io {
                path: dir.display().to_string(),
                message: "the folder lies inside itself (a symbolic-link loop)".into(),
            });
        }
        ancestors.push(id);
    }
    let mut paths: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| MeasuredError::Io {
            path: dir.display().to_string(),
            message: format!("cannot read folder: {e}"),
        })?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    paths.sort();
    let cond = TestConditions::of_folder(dir)?;
    check_entries(&cond)?;
    let named: BTreeSet<PathBuf> = cond
        .tests
        .iter()
        .flat_map(|e| entry_files(e).into_iter().map(|(_, p)| p.to_path_buf()))
        .collect();
    let mut items: Vec<(PathBuf, Vec<TestInput>)> = cond
        .tests
        .iter()
        .map(|e| {
            let t = TestInput::from_entry(e, &cond, dir);
            (t.primary_file().to_path_buf(), vec![t])
        })
        .collect();
    for p in paths {
        if p.is_dir() {
            items.push((p.clone(), folder_tests(&p, ancestors)?));
        } else if p.extension().is_some_and(|x| x.eq_ignore_ascii_case("csv"))
            && !named.contains(&p)
        {
            items.push((
                p.clone(),
                vec![TestInput::new(DataFiles::Single(p), &cond, dir)],
            ));
        }
        if items.len() > MAX_TESTS {
            return Err(too_many(dir));
        }
    }
    ancestors.pop();
    items.sort_by(|a, b| a.0.cmp(&b.0));
    Ok(items.into_iter().flat_map(|(_, t)| t).collect())
}

fn too_many(path: &Path) -> MeasuredError {
    MeasuredError::Io {
        path: path.display().to_string(),
        message: format!("more than {MAX_TESTS} tests"),
    }
}

/// The test a file given on its own belongs to: its `[[test]]` entry (a two-system test when
/// the file is its internal or external file), else a single-file test with the folder's
/// conditions.
fn file_test(file: &Path) -> Result<TestInput, MeasuredError> {
    let dir = folder_of(file);
    let cond = TestConditions::of_folder(&dir)?;
    let same = |p: &Path| {
        p == file
            || (p.file_name() == file.file_name()
                && std::fs::canonicalize(p).ok() == std::fs::canonicalize(file).ok())
    };
    for e in &cond.tests {
        if entry_files(e).iter().any(|(_, p)| same(p)) {
            check_entries(&TestConditions {
                tests: vec![e.clone()],
                ..cond.clone()
            })?;
            let mut t = TestInput::from_entry(e, &cond, &dir);
            if let DataFiles::Single(_) = t.data {
                t.data = DataFiles::Single(file.to_path_buf());
            }
            return Ok(t);
        }
    }
    Ok(TestInput::new(
        DataFiles::Single(file.to_path_buf()),
        &cond,
        &dir,
    ))
}

/// Expands the measured inputs of a command into circle tests: a file is one test (or, named
/// by a two-system `[[test]]` entry, that test), a folder gives its entries, its `*.csv` files
/// that no entry names, and those of its sub-folders, in path order. A test named twice (both
/// files of a two-system test given) is kept once. A missing path, a folder without tests or
/// an entry naming a missing file is an error.
pub fn expand_tests(paths: &[PathBuf]) -> Result<Vec<TestInput>, MeasuredError> {
    let mut tests: Vec<TestInput> = Vec::new();
    for p in paths {
        if p.is_dir() {
            let inside = folder_tests(p, &mut Vec::new())?;
            if inside.is_empty() {
                return Err(MeasuredError::Io {
                    path: p.display().to_string(),
                    message: "folder holds no .csv files".into(),
                });
            }
            tests.extend(inside);
        } else if std::fs::metadata(p).is_ok() {
            // A file, or a pipe or device read like one (within the size limit).
            let t = file_test(p)?;
            let twice =
                matches!(t.data, DataFiles::Split { .. }) && tests.iter().any(|o| o.data == t.data);
            if !twice {
                tests.push(t);
            }
        } else {
            return Err(MeasuredError::Io {
                path: p.display().to_string(),
                message: "file not found".into(),
            });
        }
        if tests.len() > MAX_TESTS {
            return Err(too_many(p));
        }
    }
    once_each(&tests)?;
    Ok(tests)
}

/// Whether the regular files `a` and `b`, of equal size, hold the same bytes (read in chunks,
/// stopping at the first difference).
fn same_content(a: &Path, b: &Path) -> bool {
    use std::io::Read;
    let (Ok(fa), Ok(fb)) = (std::fs::File::open(a), std::fs::File::open(b)) else {
        return false;
    };
    let (mut ra, mut rb) = (std::io::BufReader::new(fa), std::io::BufReader::new(fb));
    let (mut ba, mut bb) = (vec![0u8; 1 << 16], vec![0u8; 1 << 16]);
    loop {
        let (Ok(na), Ok(nb)) = (
            ra.read(&mut ba).and_then(|n| fill(&mut ra, &mut ba, n)),
            rb.read(&mut bb).and_then(|n| fill(&mut rb, &mut bb, n)),
        ) else {
            return false;
        };
        if na != nb || ba[..na] != bb[..nb] {
            return false;
        }
        if na == 0 {
            return true;
        }
    }
}

/// Reads on until `buf` is full or the file ends, `n` bytes already in it.
fn fill(r: &mut impl std::io::Read, buf: &mut [u8], mut n: usize) -> std::io::Result<usize> {
    while n > 0 && n < buf.len() {
        match r.read(&mut buf[n..])? {
            0 => break,
            k => n += k,
        }
    }
    Ok(n)
}

/// Refuses a measured file reached twice (named twice, in two folders given, through a link),
/// and a byte-identical copy of one (a folder copied beside itself): either would count its
/// test twice and make the standard errors too small.
fn once_each(tests: &[TestInput]) -> Result<(), MeasuredError> {
    refuse_copies(tests)?;
    let mut seen: Vec<(FileId, &Path)> = Vec::new();
    for t in tests {
        let files: Vec<&Path> = match &t.data {
            DataFiles::Single(f) => vec![f],
            DataFiles::Split { internal, external } => vec![internal, external],
        };
        for f in files {
            let Some(id) = FileId::of(f) else { continue };
            if let Some((_, first)) = seen.iter().find(|(i, _)| *i == id) {
                return Err(MeasuredError::Io {
                    path: f.display().to_string(),
                    message: format!(
                        "the same file as {} (each measured file counts once)",
                        first.display()
                    ),
                });
            }
            seen.push((id, f));
        }
    }
    Ok(())
}

/// Refuses two measured files with the same bytes (regular files of equal size compared).
fn refuse_copies(tests: &[TestInput]) -> Result<(), MeasuredError> {
    let mut sized: Vec<(u64, &Path)> = Vec::new();
    for t in tests {
        let files: Vec<&Path> = match &t.data {
            DataFiles::Single(f) => vec![f],
            DataFiles::Split { internal, external } => vec![internal, external],
        };
        for f in files {
            let Ok(m) = std::fs::metadata(f) else {
                continue;
            };
            if !m.is_file() {
                continue;
            }
            let copy_of = sized
                .iter()
                .filter(|(len, other)| *len == m.len() && FileId::of(other) != FileId::of(f))
                .find(|(_, other)| same_content(other, f));
            if let Some((_, first)) = copy_of {
                return Err(MeasuredError::Io {
                    path: f.display().to_string(),
                    message: format!(
                        "the same content as {} (a copy would count its test twice; give one of them)",
                        first.display()
                    ),
                });
            }
            sized.push((m.len(), f));
        }
    }
    Ok(())
}

/// The measured inputs of a command, expanded once: its circle tests (see [`expand_tests`]),
/// from which the files it reads (for provenance and for refusing to write over an input) and
/// the tests it evaluates both come.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MeasuredInputs {
    /// The tests, in path order.
    pub tests: Vec<TestInput>,
}

impl MeasuredInputs {
    /// Expands files and folders into tests ([`expand_tests`]); no paths, no tests.
    pub fn expand(paths: &[PathBuf]) -> Result<MeasuredInputs, MeasuredError> {
        Ok(MeasuredInputs {
            tests: expand_tests(paths)?,
        })
    }

    /// The data files of every test, in test order (both files of a two-system test).
    pub fn data_files(&self) -> Vec<PathBuf> {
        self.tests
            .iter()
            .flat_map(|t| match &t.data {
                DataFiles::Single(f) => vec![f.clone()],
                DataFiles::Split { internal, external } => vec![internal.clone(), external.clone()],
            })
            .collect()
    }

    /// The `rtest.toml` files the tests' conditions come from, each once.
    pub fn conditions_files(&self) -> Vec<PathBuf> {
        let mut files: Vec<PathBuf> = Vec::new();
        for f in self.tests.iter().filter_map(|t| t.conditions_file.as_ref()) {
            if !files.contains(f) {
                files.push(f.clone());
            }
        }
        files
    }
}
