//! Matrix Market files of FE matrices: `%%MatrixMarket matrix coordinate real symmetric` (one
//! triangle stored) or `general` (both, checked for symmetry), 1-based indices, `%` comment
//! lines, entries in any order, explicit zeros.
//!
//! The reader streams the file line by line and says on which line something is wrong. It is
//! written here rather than taken from nalgebra-sparse's `io` module for three reasons measured
//! or read in its source (docs/fe.md): that reader parses the whole file into a pest tree first
//! (several GiB for a 200 000-DOF model, against the 24 bytes per entry here), its entry errors
//! (index 0, out of range) carry no line number, and it rejects symmetric files that store the
//! upper triangle, which some FE programs write.

use super::{FeError, SparseMatrix};
use crate::io::read::open_input;
use faer::sparse::SymbolicSparseColMat;
use std::io::{BufRead, BufReader, Write};
use std::path::Path;

/// Most bytes of one matrix file: about 40 million entries.
pub(crate) const MAX_MATRIX_BYTES: u64 = 2 << 30;

#[derive(Clone, Copy)]
struct Entry {
    /// Row ≥ col (the lower triangle).
    row: u32,
    col: u32,
    value: f64,
    line: u32,
    /// Given in the upper triangle (row < col in the file).
    upper: bool,
}

/// Reads a square symmetric matrix. `file` is the name errors carry.
pub fn read_symmetric(path: &Path, file: &str) -> Result<SparseMatrix, FeError> {
    let reader =
        open_input(path, MAX_MATRIX_BYTES).map_err(|e| FeError::file(file, e.to_string()))?;
    parse(BufReader::with_capacity(1 << 20, reader), file)
}

/// Parses Matrix Market text (see [`read_symmetric`]).
pub fn parse(mut reader: impl BufRead, file: &str) -> Result<SparseMatrix, FeError> {
    let mut buf = Vec::new();
    let mut line_no = 0usize;
    let mut bytes = 0u64;
    let mut next_line = |buf: &mut Vec<u8>, line_no: &mut usize| -> Result<bool, FeError> {
        buf.clear();
        let got = reader
            .read_until(b'\n', buf)
            .map_err(|e| FeError::file(file, format!("cannot read: {e}")))?;
        bytes += got as u64;
        if bytes > MAX_MATRIX_BYTES {
            return Err(FeError::file(
                file,
                format!(
                    "holds more than {} MiB (the most eij reads from one matrix file)",
                    MAX_MATRIX_BYTES >> 20
                ),
            ));
        }
        *line_no += 1;
        Ok(got > 0)
    };
    let text = |buf: &[u8], line_no: usize| -> Result<String, FeError> {
        std::str::from_utf8(buf)
            .map(|s| s.trim().to_string())
            .map_err(|_| FeError::line(file, line_no, "not text (invalid UTF-8)"))
    };

    if !next_line(&mut buf, &mut line_no)? {
        return Err(FeError::file(file, "empty file, not a Matrix Market file"));
    }
    let header = text(&buf, line_no)?;
    let symmetric = parse_header(&header).map_err(|m| FeError::line(file, line_no, m))?;

    let (n, nnz) = loop {
        if !next_line(&mut buf, &mut line_no)? {
            return Err(FeError::line(
                file,
                line_no,
                "the size line `rows columns entries` is missing",
            ));
        }
        let line = text(&buf, line_no)?;
        if line.is_empty() || line.starts_with('%') {
            continue;
        }
        let f: Vec<&str> = line.split_ascii_whitespace().collect();
        let parsed: Vec<Option<usize>> = f.iter().map(|s| s.parse().ok()).collect();
        match parsed.as_slice() {
            [Some(r), Some(c), Some(e)] => {
                if r != c {
                    return Err(FeError::line(
                        file,
                        line_no,
                        format!("the matrix is {r}×{c}, not square"),
                    ));
                }
                if *r == 0 || *r > u32::MAX as usize {
                    return Err(FeError::line(
                        file,
                        line_no,
                        format!("matrix size {r} out of range"),
                    ));
                }
                break (*r, *e);
            }
            _ => {
                return Err(FeError::line(
                    file,
                    line_no,
                    format!(
                        "expected the size line `rows columns entries`, found `{}`",
                        clip(&line)
                    ),
                ))
            }
        }
    };

    let mut entries: Vec<Entry> = Vec::with_capacity(nnz.min(1 << 26));
    while next_line(&mut buf, &mut line_no)? {
        let line = std::str::from_utf8(&buf)
            .map_err(|_| FeError::line(file, line_no, "not text (invalid UTF-8)"))?;
        let line = line.trim();
        if line.is_empty() || line.starts_with('%') {
            continue;
        }
        if entries.len() == nnz {
            return Err(FeError::line(
                file,
                line_no,
                format!("more entries than the {nnz} the size line declares"),
            ));
        }
        let mut f = line.split_ascii_whitespace();
        let (Some(a), Some(b), Some(v), None) = (f.next(), f.next(), f.next(), f.next()) else {
            return Err(FeError::line(
                file,
                line_no,
                format!("expected `row column value`, found `{}`", clip(line)),
            ));
        };
        let index = |s: &str, what: &str| -> Result<u32, FeError> {
            match s.parse::<usize>() {
                Ok(0) => Err(FeError::line(
                    file,
                    line_no,
                    format!("{what} index 0: Matrix Market indices start at 1"),
                )),
                Ok(i) if i > n => Err(FeError::line(
                    file,
                    line_no,
                    format!("{what} index {i} beyond the matrix size {n}"),
                )),
                Ok(i) => Ok((i - 1) as u32),
                Err(_) => Err(FeError::line(
                    file,
                    line_no,
                    format!("{what} index `{}` is not a positive whole number", clip(s)),
                )),
            }
        };
        let (r, c) = (index(a, "row")?, index(b, "column")?);
        let value: f64 = v.parse().map_err(|_| {
            FeError::line(
                file,
                line_no,
                format!("value `{}` is not a number", clip(v)),
            )
        })?;
        if !value.is_finite() {
            return Err(FeError::line(
                file,
                line_no,
                format!("value {value} is not finite"),
            ));
        }
        entries.push(Entry {
            row: r.max(c),
            col: r.min(c),
            value,
            line: line_no.min(u32::MAX as usize) as u32,
            upper: r < c,
        });
    }
    if entries.len() != nnz {
        return Err(FeError::line(
            file,
            line_no,
            format!(
                "the file ends after {} entries, the size line declares {nnz}",
                entries.len()
            ),
        ));
    }
    assemble(entries, n, symmetric, file)
}

/// `Ok(true)` for symmetric storage, `Ok(false)` for general.
fn parse_header(header: &str) -> Result<bool, String> {
    let f: Vec<String> = header
        .split_ascii_whitespace()
        .map(|s| s.to_ascii_lowercase())
        .collect();
    if f.first().map(String::as_str) != Some("%%matrixmarket") {
        return Err(format!(
            "not a Matrix Market file: the first line must be `%%MatrixMarket matrix coordinate real symmetric` (or `general`), found `{}`",
            clip(header)
        ));
    }
    let [_, object, format, field, symmetry] = f.as_slice() else {
        return Err(format!(
            "Matrix Market header needs 5 words, found `{}`",
            clip(header)
        ));
    };
    if object != "matrix" || format != "coordinate" {
        return Err(format!(
            "only `matrix coordinate` files are read, found `{object} {format}`"
        ));
    }
    if field != "real" && field != "integer" && field != "double" {
        return Err(format!("only real matrices are read, found `{field}`"));
    }
    match symmetry.as_str() {
        "symmetric" => Ok(true),
        "general" => Ok(false),
        s => Err(format!(
            "storage `{s}`: FE matrices are read as `symmetric` or `general`"
        )),
    }
}

fn clip(s: &str) -> String {
    let s = s.trim();
    match s.char_indices().nth(60) {
        Some((i, _)) => format!("{}…", &s[..i]),
        None => s.to_string(),
    }
}

/// Pairs the entries of each position, checks symmetry and builds both triangles.
fn assemble(
    mut entries: Vec<Entry>,
    n: usize,
    symmetric: bool,
    file: &str,
) -> Result<SparseMatrix, FeError> {
    entries.sort_unstable_by_key(|e| (e.col, e.row, e.upper));
    let scale = entries.iter().fold(0.0f64, |a, e| a.max(e.value.abs()));
    let mut lower: Vec<(u32, u32, f64)> = Vec::with_capacity(entries.len());
    let mut k = 0;
    while k < entries.len() {
        let e = entries[k];
        let mut end = k + 1;
        while end < entries.len() && entries[end].row == e.row && entries[end].col == e.col {
            end += 1;
        }
        let group = &entries[k..end];
        let (i, j) = (e.row as usize + 1, e.col as usize + 1);
        let value = match group {
            [one] if symmetric || one.row == one.col => one.value,
            [one] => {
                let (a, b) = if one.upper { (j, i) } else { (i, j) };
                check_pair(one.value, 0.0, scale).map_err(|_| {
                    FeError::line(
                        file,
                        one.line as usize,
                        format!("the matrix is not symmetric: entry ({a}, {b}) = {} has no partner ({b}, {a})", one.value),
                    )
                })?;
                0.5 * one.value
            }
            [l, u] if !symmetric && !l.upper && u.upper => {
                check_pair(l.value, u.value, scale).map_err(|_| {
                    FeError::line(
                        file,
                        u.line as usize,
                        format!(
                            "the matrix is not symmetric: ({j}, {i}) = {} but ({i}, {j}) = {} (line {})",
                            u.value, l.value, l.line
                        ),
                    )
                })?;
                0.5 * (l.value + u.value)
            }
            [a, b, ..] if symmetric && a.upper != b.upper => {
                return Err(FeError::line(
                    file,
                    b.line.max(a.line) as usize,
                    format!(
                        "a symmetric file stores one triangle, but ({i}, {j}) and ({j}, {i}) are both given (lines {} and {})",
                        a.line.min(b.line),
                        a.line.max(b.line)
                    ),
                ))
            }
            [a, b, ..] => {
                let (first, second) = (a.line.min(b.line), a.line.max(b.line));
                return Err(FeError::line(
                    file,
                    second as usize,
                    format!("entry ({i}, {j}) given twice (lines {first} and {second})"),
                ));
            }
            [] => unreachable!("a group holds at least one entry"),
        };
        if value != 0.0 {
            lower.push((e.row, e.col, value));
        }
        k = end;
    }
    drop(entries);
    Ok(full_from_lower(n, &lower))
}

fn check_pair(a: f64, b: f64, scale: f64) -> Result<(), ()> {
    let d = (a - b).abs();
    if d <= 1e-6 * a.abs().max(b.abs()) || d <= 1e-12 * scale {
        Ok(())
    } else {
        Err(())
    }
}

/// Both triangles in compressed columns from the lower triangle sorted by (column, row): column j
/// receives the upper entries (j, c), c < j, first (in rising c, as they come), then its lower
/// ones, so every column comes out sorted.
pub(crate) fn full_from_lower(n: usize, lower: &[(u32, u32, f64)]) -> SparseMatrix {
    let mut count = vec![0usize; n + 1];
    for &(r, c, _) in lower {
        count[c as usize + 1] += 1;
        if r != c {
            count[r as usize + 1] += 1;
        }
    }
    for j in 0..n {
        count[j + 1] += count[j];
    }
    let col_ptr = count.clone();
    let mut next = count;
    let total = col_ptr[n];
    let mut row_idx = vec![0usize; total];
    let mut values = vec![0.0; total];
    for &(r, c, v) in lower {
        let (r, c) = (r as usize, c as usize);
        row_idx[next[c]] = r;
        values[next[c]] = v;
        next[c] += 1;
        if r != c {
            row_idx[next[r]] = c;
            values[next[r]] = v;
            next[r] += 1;
        }
    }
    let symbolic = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
    SparseMatrix::new(symbolic, values)
}

/// Writes a symmetric matrix as `coordinate real symmetric` (lower triangle, 17 digits), the
/// form FE programs export and scipy's `mmread` reads.
pub fn write_symmetric(
    out: &mut impl Write,
    a: &SparseMatrix,
    comment: &str,
) -> std::io::Result<()> {
    let nnz = (0..a.ncols())
        .map(|c| a.row_idx_of_col_raw(c).iter().filter(|&&r| r >= c).count())
        .sum::<usize>();
    writeln!(out, "%%MatrixMarket matrix coordinate real symmetric")?;
    for line in comment.lines() {
        writeln!(out, "% {line}")?;
    }
    writeln!(out, "{} {} {}", a.nrows(), a.ncols(), nnz)?;
    for c in 0..a.ncols() {
        for (r, v) in a.row_idx_of_col(c).zip(a.val_of_col(c)) {
            if r >= c {
                writeln!(out, "{} {} {:.17e}", r + 1, c + 1, v)?;
            }
        }
    }
    Ok(())
}

/// A symmetric matrix from lower-triangle triplets (row ≥ column) in any order, duplicates
/// summed (element assembly).
pub(crate) fn from_lower_triplets(n: usize, mut t: Vec<(u32, u32, f64)>) -> SparseMatrix {
    t.sort_unstable_by_key(|&(r, c, _)| (c, r));
    let mut merged: Vec<(u32, u32, f64)> = Vec::with_capacity(t.len() / 2);
    for (r, c, v) in t {
        match merged.last_mut() {
            Some(last) if last.0 == r && last.1 == c => last.2 += v,
            _ => merged.push((r, c, v)),
        }
    }
    full_from_lower(n, &merged)
}
