//! The measured inputs of a command as circle tests: files and folders expanded, each test with
//! the conditions its folder's `rtest.toml` gives it (folder keys, overridden by its `[[test]]`
//! entry).

use std::path::{Path, PathBuf};

use super::conditions::{
    folder_of, Coordinates, DataFiles, DiagnosisSettings, Session, TestConditions, TestEntry,
    MAX_TESTS,
};
use super::error::MeasuredError;
use super::layout::ColumnMap;
use super::recording::read_internal;
use super::traces::InternalRecording;
use crate::io::FileId;
use crate::rtest::diagnosis::tolerance::Tolerances;
use crate::rtest::CircleSeries;

pub use super::pairing::{PairedBy, PairedOn};

/// One circle test to read and evaluate, with everything known about its conditions.
#[derive(Debug, Clone, PartialEq)]
pub struct TestInput {
    /// Its data and the conditions it is evaluated at: its `[[test]]` entry's (with the
    /// entry's number), the folder's where the entry is silent or the test has no entry.
    pub test: TestEntry,
    /// The `rtest.toml` that states its conditions, if any.
    pub conditions_file: Option<PathBuf>,
    /// The `[[pairing]]` that made the test, if one did.
    pub paired: Option<PairedBy>,
    /// The clock group (two-system tests): the folder, or the folder and the entry's `clock`.
    pub clock_group: String,
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
        match &self.test.data {
            DataFiles::Single(f) => f.display().to_string(),
            DataFiles::Split { internal, external } => {
                format!("{} + {}", internal.display(), external.display())
            }
        }
    }

    /// Every file the test is read from: its data file(s) and its `rtest.toml`.
    pub fn files(&self) -> Vec<PathBuf> {
        let mut v = self.data_files();
        v.extend(self.conditions_file.clone());
        v
    }

    /// Its data file(s): the file, or the internal and the external file.
    pub fn data_files(&self) -> Vec<PathBuf> {
        match &self.test.data {
            DataFiles::Single(f) => vec![f.clone()],
            DataFiles::Split { internal, external } => vec![internal.clone(), external.clone()],
        }
    }

    /// The file that orders and labels the test: its file, or its internal file.
    pub fn primary_file(&self) -> &Path {
        match &self.test.data {
            DataFiles::Single(f) => f,
            DataFiles::Split { internal, .. } => internal,
        }
    }

    /// Whether its internal readings are absolute machine coordinates.
    pub fn absolute(&self) -> bool {
        self.test.internal_coordinates == Some(Coordinates::Absolute)
    }

    /// How its internal readings are placed about the circle centre.
    pub(crate) fn placement(&self) -> super::coordinates::Placement<'_> {
        super::coordinates::Placement {
            absolute: self.absolute(),
            position_mm: self.test.position_mm.as_deref(),
            conditions: self.conditions_file.as_deref(),
        }
    }

    /// Reads a single-file test (column map applied; with absolute internal coordinates, the
    /// circle centre subtracted). Two-system tests are read and brought onto one time base by
    /// [`crate::rtest::clock`].
    pub fn read_single(&self) -> Result<CircleSeries, MeasuredError> {
        match &self.test.data {
            DataFiles::Single(f) => {
                let name = f.display().to_string();
                let bytes = super::series::read_recording(f)?;
                let place = |int: &mut [Vec<f64>; 3]| {
                    super::coordinates::place(&self.placement(), &name, int, [false; 3])
                };
                CircleSeries::from_csv_placed(&name, &bytes, &self.columns, place)
            }
            DataFiles::Split { .. } => Err(MeasuredError::Io {
                path: self.name(),
                message: "a test recorded by two systems is read through rtest::clock".into(),
            }),
        }
    }

    /// The test of `entry` (its data paths resolved) with the folder's conditions where the
    /// entry is silent. Absolute internal coordinates without a circle centre are refused.
    fn from_entry(
        entry: &TestEntry,
        cond: &TestConditions,
        folder: &Path,
    ) -> Result<TestInput, MeasuredError> {
        let mut test = entry.clone();
        test.radius_mm = entry.radius_mm.or(cond.radius_mm);
        test.position_mm = entry
            .position_mm
            .clone()
            .or_else(|| cond.position_mm.clone());
        test.internal_coordinates = entry.internal_coordinates.or(cond.internal_coordinates);
        if test.internal_coordinates == Some(Coordinates::Absolute) && test.position_mm.is_none() {
            let key = match (entry.number, entry.internal_coordinates) {
                (Some(n), Some(_)) => format!("[[test]] #{n} internal_coordinates"),
                _ => "internal_coordinates".to_string(),
            };
            return Err(MeasuredError::Conditions {
                file: cond
                    .file
                    .as_ref()
                    .map_or(folder.display().to_string(), |f| f.display().to_string()),
                key,
                message: format!(
                    "\"absolute\" needs the circle centre position_mm (machine coordinates of \
                     the axes) to subtract from the internal readings of {}",
                    entry_name(&test.data)
                ),
            });
        }
        let clock_group = match &entry.clock {
            Some(c) => format!("{} clock {c}", folder.display()),
            None => folder.display().to_string(),
        };
        Ok(TestInput {
            test,
            conditions_file: cond.file.clone(),
            paired: None,
            clock_group,
            columns: cond.columns.clone(),
            internal_columns: cond.internal_columns.clone(),
            external_columns: cond.external_columns.clone(),
            tolerances: cond.tolerances.clone(),
            diagnosis: cond.diagnosis,
            session: cond.session.clone(),
        })
    }

    /// A file of the folder that no entry names, at the folder's conditions.
    fn new(
        data: DataFiles,
        cond: &TestConditions,
        folder: &Path,
    ) -> Result<TestInput, MeasuredError> {
        TestInput::from_entry(&TestEntry::of(data), cond, folder)
    }
}

/// A test's data in words, for messages.
fn entry_name(data: &DataFiles) -> String {
    match data {
        DataFiles::Single(f) => f.display().to_string(),
        DataFiles::Split { internal, .. } => internal.display().to_string(),
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

/// Checks that every file of the folder's entries and pairs exists and that no two of them
/// name the same file (by identity: `a.csv`, `./a.csv` and a link to it are one file);
/// returns the files they name.
fn check_entries(
    cond: &TestConditions,
    paired: &[(TestEntry, PairedBy)],
) -> Result<Vec<FileId>, MeasuredError> {
    let file = cond
        .file
        .as_ref()
        .map_or(String::new(), |f| f.display().to_string());
    let mut seen: Vec<(FileId, String)> = Vec::new();
    let entries = cond
        .tests
        .iter()
        .map(|e| (e, format!("[[test]] #{}", e.number.unwrap_or(0))))
        .chain(
            paired
                .iter()
                .map(|(e, by)| (e, format!("[[pairing]] #{}", by.pairing))),
        );
    for (e, table) in entries {
        for (key, path) in entry_files(e) {
            let at = format!("{table} {key}");
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
    Ok(seen.into_iter().map(|(id, _)| id).collect())
}

/// The tests of a folder (its entries, its pairs and the CSV files none of them names) and,
/// recursively, of its sub-folders, in path order. `ancestors` are the folders above it (by
/// identity): a folder inside itself (a symbolic-link loop) is an error, not a copy of its
/// data. `claimed` are the files that the entries and pairs of the folders above name (a
/// pairing's files lie in sub-folders): they are not tests of their own.
fn folder_tests(
    dir: &Path,
    ancestors: &mut Vec<FileId>,
    claimed: &mut Vec<FileId>,
) -> Result<Vec<TestInput>, MeasuredError> {
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
    let paired = super::pairing::expand(dir, &cond)?;
    let named = check_entries(&cond, &paired)?;
    let outer = claimed.len();
    claimed.extend(named);
    let mut items: Vec<(PathBuf, Vec<TestInput>)> = Vec::new();
    for e in &cond.tests {
        let t = TestInput::from_entry(e, &cond, dir)?;
        items.push((t.primary_file().to_path_buf(), vec![t]));
    }
    for (e, by) in &paired {
        let mut t = TestInput::from_entry(e, &cond, dir)?;
        t.paired = Some(*by);
        items.push((t.primary_file().to_path_buf(), vec![t]));
    }
    for p in paths {
        if p.is_dir() {
            items.push((p.clone(), folder_tests(&p, ancestors, claimed)?));
        } else if p.extension().is_some_and(|x| x.eq_ignore_ascii_case("csv"))
            && !FileId::of(&p).is_some_and(|id| claimed.contains(&id))
        {
            let t = TestInput::new(DataFiles::Single(p.clone()), &cond, dir)?;
            items.push((p, vec![t]));
        }
        if items.len() > MAX_TESTS {
            return Err(too_many(dir));
        }
    }
    claimed.truncate(outer);
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
            check_entries(
                &TestConditions {
                    tests: vec![e.clone()],
                    ..cond.clone()
                },
                &[],
            )?;
            let mut t = TestInput::from_entry(e, &cond, &dir)?;
            if let DataFiles::Single(_) = t.test.data {
                t.test.data = DataFiles::Single(file.to_path_buf());
            }
            return Ok(t);
        }
    }
    TestInput::new(DataFiles::Single(file.to_path_buf()), &cond, &dir)
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
            let inside = folder_tests(p, &mut Vec::new(), &mut Vec::new())?;
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
            let twice = matches!(t.test.data, DataFiles::Split { .. })
                && tests.iter().any(|o| o.test.data == t.test.data);
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
    let mut seen: Vec<(FileId, PathBuf)> = Vec::new();
    for t in tests {
        for f in t.data_files() {
            let Some(id) = FileId::of(&f) else { continue };
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
    let mut sized: Vec<(u64, PathBuf)> = Vec::new();
    for t in tests {
        for f in t.data_files() {
            let Ok(m) = std::fs::metadata(&f) else {
                continue;
            };
            if !m.is_file() {
                continue;
            }
            let copy_of = sized
                .iter()
                .filter(|(len, other)| *len == m.len() && FileId::of(other) != FileId::of(&f))
                .find(|(_, other)| same_content(other, &f));
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
        self.tests.iter().flat_map(TestInput::data_files).collect()
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

impl TestInput {
    /// Reads the internal file of a two-system test (`[[test]]` with `internal` and
    /// `external`): a TNCscope export, a Sinumerik trace or delimited text, with the test's
    /// column map and plane. `None` for a single-file test.
    ///
    /// ```no_run
    /// use eij::measured::inputs::expand_tests;
    ///
    /// # fn main() -> Result<(), eij::measured::MeasuredError> {
    /// let tests = expand_tests(&["shop/cnc-and-rtest".into()])?;
    /// if let Some(r) = tests[0].read_internal()? {
    ///     println!("{} samples, first x {} mm", r.t_s.len(), r.mm[0][0]);
    /// }
    /// # Ok(())
    /// # }
    /// ```
    pub fn read_internal(&self) -> Result<Option<InternalRecording>, MeasuredError> {
        let DataFiles::Split { internal, .. } = &self.test.data else {
            return Ok(None);
        };
        let r = read_internal(internal, &self.internal_columns, self.test.plane)?;
        Ok(Some(InternalRecording {
            lines: r.lines.unwrap_or_default(),
            t_s: r.t_s,
            mm: r.mm,
            absent: r.absent,
        }))
    }
}
