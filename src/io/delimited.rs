//! Delimited text as eij's inputs write it: lines with their numbers, the separator of a header
//! line, physical line numbers of CSV records, CSV reader errors and cells in one-line messages,
//! numbers with a decimal point or comma. Shared by every reader of CSV files (measured series
//! and EIJ tables, maps, compensation tables, moves); the readers own their columns and errors.

/// File text as it may appear inside a one-line message: control characters (line ends in a
/// quoted cell, NUL, …) escaped, and long text cut after 40 characters.
pub(crate) fn quote_cell(text: &str) -> String {
    const MAX_CHARS: usize = 40;
    let mut out = String::new();
    for (i, c) in text.chars().enumerate() {
        if i == MAX_CHARS {
            out.push('…');
            break;
        }
        if c.is_control() {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    out
}

/// The lines of a text, without line ends, with their 1-based numbers and byte offsets.
pub(crate) fn lines(bytes: &[u8]) -> impl Iterator<Item = (u64, usize, &[u8])> {
    let mut start = 0;
    let mut number = 0;
    std::iter::from_fn(move || {
        if start >= bytes.len() {
            return None;
        }
        let end = bytes[start..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |p| start + p);
        let line = &bytes[start..end];
        let line = line.strip_suffix(b"\r").unwrap_or(line);
        number += 1;
        let item = (number, start, line);
        start = end + 1;
        Some(item)
    })
}

/// Whether a line is blank or a `#` comment.
pub(crate) fn is_comment_or_blank(line: &[u8]) -> bool {
    let trimmed = line.trim_ascii_start();
    trimmed.is_empty() || trimmed[0] == b'#'
}

/// The separator of a header line: the candidate that splits it into the most cells (`,` on a
/// tie, and for a line without any).
pub(crate) fn separator_of(line: &[u8]) -> u8 {
    let mut best = (0, b',');
    for sep in [b',', b';', b'\t'] {
        let count = line.iter().filter(|&&b| b == sep).count();
        if count > best.0 {
            best = (count, sep);
        }
    }
    best.1
}

/// The first line that is no comment and not blank (a byte-order mark dropped).
pub(crate) fn header_line(bytes: &[u8]) -> Option<&[u8]> {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    lines(bytes)
        .map(|(_, _, l)| l)
        .find(|l| !is_comment_or_blank(l))
}

/// The separator of a file's header line (see [`separator_of`]).
pub(crate) fn header_separator(bytes: &[u8]) -> u8 {
    header_line(bytes).map_or(b',', separator_of)
}

/// Physical line numbers (1-based) of byte offsets, counted forward through the file: the CSV
/// reader's own line count leaves out blank lines.
pub(crate) struct LineCounter<'a> {
    bytes: &'a [u8],
    byte: usize,
    line: u64,
}

impl<'a> LineCounter<'a> {
    /// A counter at the start of `bytes` (line 1).
    pub(crate) fn new(bytes: &'a [u8]) -> Self {
        Self::starting_at(bytes, 1)
    }

    /// A counter at the start of `bytes`, which begin on line `line` of their file.
    pub(crate) fn starting_at(bytes: &'a [u8], line: u64) -> Self {
        LineCounter {
            bytes,
            byte: 0,
            line,
        }
    }

    /// The line holding byte `offset`; offsets must not decrease between calls.
    pub(crate) fn line_of(&mut self, offset: u64) -> u64 {
        let end = (offset as usize).min(self.bytes.len());
        if end > self.byte {
            let newlines = self.bytes[self.byte..end]
                .iter()
                .filter(|&&b| b == b'\n')
                .count();
            self.line += newlines as u64;
            self.byte = end;
        }
        self.line
    }

    /// The line of a record: of its first byte that is not a line end (the reader's record
    /// position may point at the end of the previous line or at skipped blank lines).
    pub(crate) fn line_of_record(&mut self, record: &csv::StringRecord) -> u64 {
        match record.position() {
            Some(p) => self.line_of_position(p),
            None => self.line,
        }
    }

    /// The line of a reader position, skipping line ends as [`Self::line_of_record`] does.
    pub(crate) fn line_of_position(&mut self, p: &csv::Position) -> u64 {
        let mut start = p.byte() as usize;
        while self
            .bytes
            .get(start)
            .is_some_and(|b| *b == b'\r' || *b == b'\n')
        {
            start += 1;
        }
        self.line_of(start as u64)
    }
}

/// What a CSV reader's error says, without its own position (the caller names file and line:
/// the reader's "CSV error: record 2 (line: 3, byte: 120)" would repeat them).
pub(crate) fn csv_message(e: &csv::Error) -> String {
    match e.kind() {
        csv::ErrorKind::UnequalLengths {
            expected_len, len, ..
        } => format!("{len} field(s), the header has {expected_len}"),
        csv::ErrorKind::Utf8 { .. } => "not valid UTF-8 text".to_string(),
        csv::ErrorKind::Io(io) => io.to_string(),
        _ => e.to_string(),
    }
}

/// Why a cell is not a number eij can use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum BadNumber {
    /// The text is no number.
    NotANumber,
    /// NaN or infinite.
    NotFinite,
}

/// Parses one finite number; with `decimal_comma`, a cell with `,` and no `.` is read with the
/// comma as decimal point (files whose separator is not `,`).
pub(crate) fn parse_number(text: &str, decimal_comma: bool) -> Result<f64, BadNumber> {
    let parsed = if decimal_comma && text.contains(',') && !text.contains('.') {
        text.replace(',', ".").parse::<f64>()
    } else {
        text.parse::<f64>()
    };
    match parsed {
        Err(_) => Err(BadNumber::NotANumber),
        Ok(v) if !v.is_finite() => Err(BadNumber::NotFinite),
        Ok(v) => Ok(v),
    }
}
