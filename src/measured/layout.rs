//! File layouts of R-Test series (docs/measurement-files.md): CSV dialects recognised without
//! options, and the column map with units of a folder's `rtest.toml` (`[columns]`).
//!
//! Recognised without options:
//! - separator `,`, `;` or tab, taken from the header line (the one of the three that splits it
//!   into the most cells);
//! - decimal comma in `;` and tab files (a data cell with `,` and no `.`);
//! - `#` comment lines anywhere, blank lines, a UTF-8 byte-order mark, CRLF line ends;
//! - a metadata block before the header: the header is the first line (of the first 200 that
//!   are not comments) that holds every required column; the lines before it are skipped;
//! - a units row right under the header (`[ms]`, `(µm)`, `mm` in the required columns, no
//!   number among them): the units of the columns where `[columns]` states none, checked
//!   against `[columns]` where it does (a conflict names file, line and column);
//! - column names in any letter case, surrounded by spaces or quotes.
//!
//! What the files call the contract columns, and in which unit, comes from a [`ColumnMap`].

use std::collections::BTreeMap;

use serde::Deserialize;

use super::error::MeasuredError;
use crate::io::delimited::{
    csv_message, is_comment_or_blank, lines, parse_number, quote_cell, separator_of, BadNumber,
    LineCounter,
};
use crate::rtest::{Line, Location};

/// Lines (not comments) searched for the header: a metadata block longer than this is not
/// recognised.
const HEADER_SEARCH_LINES: usize = 200;

/// The unit of a column in a file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Unit {
    /// Seconds.
    S,
    /// Milliseconds.
    Ms,
    /// Microseconds.
    Us,
    /// Metres.
    M,
    /// Millimetres.
    Mm,
    /// Micrometres.
    Um,
}

impl Unit {
    /// The unit's name as written in `rtest.toml` (`s`, `ms`, `us`, `m`, `mm`, `um`).
    pub fn name(self) -> &'static str {
        match self {
            Unit::S => "s",
            Unit::Ms => "ms",
            Unit::Us => "us",
            Unit::M => "m",
            Unit::Mm => "mm",
            Unit::Um => "um",
        }
    }

    /// Parses a unit name; `µm`/`μm` and `µs`/`μs` are accepted for `um`/`us`.
    pub fn parse(text: &str) -> Option<Unit> {
        Some(match text.trim() {
            "s" => Unit::S,
            "ms" => Unit::Ms,
            "us" | "µs" | "μs" => Unit::Us,
            "m" => Unit::M,
            "mm" => Unit::Mm,
            "um" | "µm" | "μm" => Unit::Um,
            _ => return None,
        })
    }

    /// Whether this is a unit of time (else of length).
    pub fn is_time(self) -> bool {
        matches!(self, Unit::S | Unit::Ms | Unit::Us)
    }

    /// The factor from this unit to the contract's unit of its kind (s for time, mm for
    /// length).
    pub fn to_contract(self) -> f64 {
        match self {
            Unit::S => 1.0,
            Unit::Ms => 1e-3,
            Unit::Us => 1e-6,
            Unit::M => 1e3,
            Unit::Mm => 1.0,
            Unit::Um => 1e-3,
        }
    }
}

impl std::fmt::Display for Unit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// What a file calls one contract column, and its unit.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ColumnSpec {
    /// The name in the file's header (matched ignoring letter case and surrounding spaces).
    pub name: String,
    /// The unit of its values.
    pub unit: Unit,
    /// Whether `[columns]` states the unit (else it is the contract's, and a units row under
    /// the header may give it).
    pub stated: bool,
}

/// One entry of `[columns]` as written: `x_int_mm = "X_ACT"` or
/// `x_int_mm = { name = "X_ACT", unit = "um" }` (either key may be left out).
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
#[serde(untagged)]
pub enum ColumnEntry {
    /// The file's name, unit as in the contract.
    Name(String),
    /// Name and/or unit.
    Spec {
        /// The file's name; the contract name when absent.
        name: Option<String>,
        /// The unit; the contract's when absent.
        unit: Option<String>,
    },
}

/// The contract columns of an R-Test series with the kind of their unit.
pub(crate) const CONTRACT_COLUMNS: [&str; 7] = [
    "t_s", "x_int_mm", "y_int_mm", "z_int_mm", "x_ext_mm", "y_ext_mm", "z_ext_mm",
];

/// How the files of a folder name the contract columns and in which unit (`rtest.toml`
/// `[columns]`). Unmapped columns keep their contract names and units.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ColumnMap {
    specs: BTreeMap<String, ColumnSpec>,
}

impl ColumnMap {
    /// Validates the entries of a `[columns]` table; `table` names it in errors (e.g.
    /// `columns`), `file` is the `rtest.toml`.
    pub fn from_entries(
        entries: &BTreeMap<String, ColumnEntry>,
        file: &str,
        table: &str,
    ) -> Result<ColumnMap, MeasuredError> {
        let mut specs = BTreeMap::new();
        for (key, entry) in entries {
            let bad = |k: String, message: String| MeasuredError::Conditions {
                file: file.to_string(),
                key: k,
                message,
            };
            if !CONTRACT_COLUMNS.contains(&key.as_str()) {
                return Err(bad(
                    format!("{table}.{}", quote_cell(key)),
                    format!(
                        "not a contract column (expected one of {})",
                        CONTRACT_COLUMNS.join(", ")
                    ),
                ));
            }
            let time = key == "t_s";
            let contract_unit = if time { Unit::S } else { Unit::Mm };
            let (name, unit) = match entry {
                ColumnEntry::Name(n) => (Some(n.clone()), None),
                ColumnEntry::Spec { name, unit } => (name.clone(), unit.clone()),
            };
            let name = name.unwrap_or_else(|| key.clone());
            if name.trim().is_empty() {
                return Err(bad(
                    format!("{table}.{key}.name"),
                    "empty column name".into(),
                ));
            }
            let stated = unit.is_some();
            let unit = match unit {
                None => contract_unit,
                Some(u) => {
                    let expected = if time { "s, ms or us" } else { "m, mm or um" };
                    match Unit::parse(&u) {
                        Some(unit) if unit.is_time() == time => unit,
                        _ => {
                            return Err(bad(
                                format!("{table}.{key}.unit"),
                                format!(
                                    "'{}' is no unit of this column (expected {expected})",
                                    quote_cell(&u)
                                ),
                            ))
                        }
                    }
                }
            };
            specs.insert(
                key.clone(),
                ColumnSpec {
                    name: name.trim().to_string(),
                    unit,
                    stated,
                },
            );
        }
        // One file column feeds one contract column: two would read the same numbers twice
        // (an unmapped contract column keeps its own name).
        let effective = |c: &str| specs.get(c).map_or(c.to_string(), |s| s.name.clone());
        for (i, c) in CONTRACT_COLUMNS.iter().enumerate() {
            let name = effective(c);
            if let Some(other) = CONTRACT_COLUMNS[..i]
                .iter()
                .find(|o| effective(o).eq_ignore_ascii_case(&name))
            {
                let key = if specs.contains_key(*c) { c } else { other };
                return Err(MeasuredError::Conditions {
                    file: file.to_string(),
                    key: format!("{table}.{key}.name"),
                    message: format!(
                        "'{}' is the file column of both {other} and {c}; each contract column needs its own",
                        quote_cell(&name)
                    ),
                });
            }
        }
        Ok(ColumnMap { specs })
    }

    /// This map with the entries of `other` replacing its own.
    pub fn overridden_by(&self, other: &ColumnMap) -> ColumnMap {
        let mut specs = self.specs.clone();
        specs.extend(other.specs.iter().map(|(k, v)| (k.clone(), v.clone())));
        ColumnMap { specs }
    }

    /// Whether nothing is mapped.
    pub fn is_empty(&self) -> bool {
        self.specs.is_empty()
    }

    /// What the files call `contract` (a contract column name) and its unit.
    pub fn spec(&self, contract: &str) -> ColumnSpec {
        self.specs
            .get(contract)
            .cloned()
            .unwrap_or_else(|| ColumnSpec {
                name: contract.to_string(),
                unit: if contract == "t_s" { Unit::S } else { Unit::Mm },
                stated: false,
            })
    }
}

/// The dialect recognised in a file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Dialect {
    /// `,`, `;` or tab.
    pub separator: u8,
    /// Numbers written with a decimal comma (`;` and tab files).
    pub decimal_comma: bool,
    /// The line of the header, 1-based (after comment lines and a metadata block).
    pub header_line: u64,
}

impl Dialect {
    /// The separator in words, for messages.
    pub(crate) fn separator_name(&self) -> &'static str {
        match self.separator {
            b';' => "';'",
            b'\t' => "tab",
            _ => "','",
        }
    }
}

/// Columns read from a file, converted to the contract's units, in the order asked for.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Table {
    /// Values per wanted column.
    pub columns: Vec<Vec<f64>>,
    /// File line of every row.
    pub lines: Vec<u64>,
    /// The file's name of every wanted column.
    pub names: Vec<String>,
    /// The dialect recognised.
    pub dialect: Dialect,
}

/// A header cell as compared with column names: trimmed, quotes removed, lower case.
fn normalise_name(cell: &str) -> String {
    let t = cell.trim();
    let t = t
        .strip_prefix('"')
        .and_then(|s| s.strip_suffix('"'))
        .unwrap_or(t);
    t.trim().to_lowercase()
}

fn split_header(line: &[u8], sep: u8) -> Vec<String> {
    String::from_utf8_lossy(line)
        .split(sep as char)
        .map(|c| c.trim().to_string())
        .collect()
}

/// Reads the `wanted` contract columns of a delimited text (dialect recognised, names and units
/// from `map`); other columns are ignored. `name` stands for the file in messages. At least one
/// data row is not required here; callers check the row count.
pub(crate) fn read_table(
    name: &str,
    bytes: &[u8],
    wanted: &[&str],
    map: &ColumnMap,
) -> Result<Table, MeasuredError> {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let specs: Vec<ColumnSpec> = wanted.iter().map(|w| map.spec(w)).collect();
    let keys: Vec<String> = specs.iter().map(|s| normalise_name(&s.name)).collect();
    // The header: the first line holding every wanted column; else the one holding most of
    // them (or the first line) is reported as the header read.
    let mut first: Option<(u64, usize, &[u8], usize)> = None;
    let mut header = None;
    for (number, offset, line) in lines(bytes)
        .filter(|(_, _, l)| !is_comment_or_blank(l))
        .take(HEADER_SEARCH_LINES)
    {
        let cells: Vec<String> = split_header(line, separator_of(line))
            .iter()
            .map(|c| normalise_name(c))
            .collect();
        let found = keys.iter().filter(|k| cells.contains(k)).count();
        if found == keys.len() {
            header = Some((number, offset));
            break;
        }
        if first.is_none_or(|f| found > f.3) {
            first = Some((number, offset, line, found));
        }
    }
    let Some((header_line, offset)) = header else {
        return Err(match first {
            None => MeasuredError::Empty {
                at: Location::source(name),
                expected: specs
                    .iter()
                    .map(|s| s.name.as_str())
                    .collect::<Vec<_>>()
                    .join(","),
            },
            Some((number, _, line, _)) if std::str::from_utf8(line).is_err() => {
                MeasuredError::Csv {
                    at: Location::file_line(name, number),
                    message: "not valid UTF-8 text".into(),
                }
            }
            Some((number, _, line, _)) => {
                let sep = separator_of(line);
                let cells = split_header(line, sep);
                let missing = specs
                    .iter()
                    .zip(&keys)
                    .zip(wanted)
                    .filter(|((_, k), _)| !cells.iter().any(|c| normalise_name(c) == **k))
                    .map(|((s, _), w)| {
                        if s.name == *w {
                            s.name.clone()
                        } else {
                            format!("{} (for {w})", s.name)
                        }
                    })
                    .collect();
                let dialect = Dialect {
                    separator: sep,
                    decimal_comma: false,
                    header_line: number,
                };
                MeasuredError::MissingColumns {
                    at: Location::file_line(name, number),
                    columns: missing,
                    header: Some(format!(
                        "'{}' separated by {}",
                        quote_cell(&cells.join(&(sep as char).to_string())),
                        dialect.separator_name()
                    )),
                }
            }
        });
    };
    let body = &bytes[offset..];
    let separator = separator_of(lines(body).next().map_or(&[][..], |l| l.2));
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .delimiter(separator)
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .from_reader(body);
    let mut counter = LineCounter::starting_at(body, header_line);
    let mut records = reader.records();
    let head = match records.next() {
        Some(r) => r.map_err(|e| csv_error(name, &mut counter, e))?,
        None => unreachable!("the header line was found in these bytes"),
    };
    let header_at = Location::file_line(name, header_line);
    let mut index = vec![usize::MAX; keys.len()];
    for (i, cell) in head.iter().enumerate() {
        let cell = normalise_name(cell);
        if let Some(k) = keys.iter().position(|key| *key == cell) {
            if index[k] != usize::MAX {
                return Err(MeasuredError::DuplicateColumn {
                    at: header_at,
                    column: quote_cell(&specs[k].name),
                });
            }
            index[k] = i;
        }
    }
    // A units row under the header (`[ms]`, `(µm)`, `mm`): the units where `[columns]` states
    // none, checked against them where it does.
    let mut factor: Vec<f64> = specs.iter().map(|s| s.unit.to_contract()).collect();
    let mut first = match records.next() {
        Some(r) => Some(r.map_err(|e| csv_error(name, &mut counter, e))?),
        None => None,
    };
    if let Some(units) = first.as_ref().and_then(|r| units_row(r, &index)) {
        let line = first.as_ref().map_or(0, |r| counter.line_of_record(r));
        for (k, cell) in units.into_iter().enumerate() {
            if let Some(cell) = cell {
                factor[k] = row_unit(name, line, &specs[k], wanted[k], &cell)?.to_contract();
            }
        }
        first = None;
    }
    let mut columns = vec![Vec::new(); keys.len()];
    let mut row_lines = Vec::new();
    let mut decimal_comma = false;
    for record in first.map(Ok).into_iter().chain(records) {
        let record = record.map_err(|e| csv_error(name, &mut counter, e))?;
        let line = counter.line_of_record(&record);
        for (k, col) in columns.iter_mut().enumerate() {
            let text = record.get(index[k]).unwrap_or("");
            // A decimal comma: only where `,` cannot be the separator, and never beside a `.`.
            let comma = separator != b',';
            decimal_comma |= comma && text.contains(',');
            let value = parse_decimal(text, comma, name, line, &specs[k].name)?;
            col.push(value * factor[k]);
        }
        row_lines.push(line);
    }
    Ok(Table {
        columns,
        lines: row_lines,
        names: specs.into_iter().map(|s| s.name).collect(),
        dialect: Dialect {
            separator,
            decimal_comma,
            header_line,
        },
    })
}

/// The unit text of a units-row cell: `[ms]`, `(µm)` or a bare unit name; `None` for a cell
/// that is no unit (a number, other text).
fn unit_text(cell: &str) -> Option<String> {
    let t = cell.trim();
    let inner = t
        .strip_prefix('[')
        .and_then(|s| s.strip_suffix(']'))
        .or_else(|| t.strip_prefix('(').and_then(|s| s.strip_suffix(')')));
    match inner {
        Some(u) if !u.trim().is_empty() && parse_number(u.trim(), true).is_err() => {
            Some(u.trim().to_string())
        }
        Some(_) => None,
        None => Unit::parse(t).map(|_| t.to_string()),
    }
}

/// The unit texts of the wanted columns (`index`) when `record` is a units row: no wanted
/// cell is a number and at least one is a unit; an empty cell gives no unit.
fn units_row(record: &csv::StringRecord, index: &[usize]) -> Option<Vec<Option<String>>> {
    let cells: Vec<&str> = index.iter().map(|&i| record.get(i).unwrap_or("")).collect();
    let units: Vec<Option<String>> = cells.iter().map(|c| unit_text(c)).collect();
    let is_row = units.iter().any(Option::is_some)
        && cells
            .iter()
            .zip(&units)
            .all(|(c, u)| u.is_some() || c.trim().is_empty());
    is_row.then_some(units)
}

/// The unit a units-row cell gives column `spec` (contract column `contract`): known, of the
/// column's kind, and the one `[columns]` states if it states one.
fn row_unit(
    source: &str,
    line: u64,
    spec: &ColumnSpec,
    contract: &str,
    text: &str,
) -> Result<Unit, MeasuredError> {
    let time = contract == "t_s";
    let bad = |message: String| MeasuredError::BadValue {
        at: Location::file_line(source, line),
        column: spec.name.clone(),
        message,
    };
    let expected = if time { "s, ms or us" } else { "m, mm or um" };
    let unit = match Unit::parse(text) {
        Some(u) if u.is_time() == time => u,
        Some(_) => {
            return Err(bad(format!(
                "the units row gives '{}', no unit of {} (expected {expected})",
                quote_cell(text),
                if time { "time" } else { "length" }
            )))
        }
        None => {
            return Err(bad(format!(
                "the units row gives '{}', not a unit eij reads (expected {expected})",
                quote_cell(text)
            )))
        }
    };
    if spec.stated && unit != spec.unit {
        return Err(bad(format!(
            "the units row says {unit}, rtest.toml [columns] says {}",
            spec.unit
        )));
    }
    Ok(unit)
}

/// Turns a CSV reader error into a one-line error naming the line.
pub(crate) fn csv_error(source: &str, lines: &mut LineCounter, e: csv::Error) -> MeasuredError {
    let line = e.position().map(|p| lines.line_of_position(p));
    let message = csv_message(&e);
    MeasuredError::Csv {
        at: Location {
            source: source.to_string(),
            line: line.map(Line::File),
        },
        message,
    }
}

/// Parses one finite number, naming file, line and column otherwise; with `decimal_comma`, a cell with `,` and no `.` is read with the comma
/// as decimal point (files whose separator is not `,`). Errors quote the cell as written.
pub(crate) fn parse_decimal(
    text: &str,
    decimal_comma: bool,
    source: &str,
    line: u64,
    column: &str,
) -> Result<f64, MeasuredError> {
    let at = || Location::file_line(source, line);
    parse_number(text, decimal_comma).map_err(|bad| {
        let (at, column, value) = (at(), column.to_string(), quote_cell(text));
        match bad {
            BadNumber::NotANumber => MeasuredError::NotANumber { at, column, value },
            BadNumber::NotFinite => MeasuredError::NotFinite { at, column, value },
        }
    })
}
