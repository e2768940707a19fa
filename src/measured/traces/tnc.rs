//! Heidenhain TNCscope text exports (`.sco`, recognised by the first line `%TNCscopeNT data
//! file`): a `%[GLOBAL]` block (`%SAMPLING=` µs), one `%[CURVEn]` block per channel (`%NAME=`,
//! `%CHANNELTYPE=`, `%AXISTYPE=`, `%DIMENSION=`, `%COUNT=`, `%CYCLETIME=` µs, `%COLUMN=`), each
//! block possibly closed by a line holding only `%`, then after `%[DATA]` one row per sample
//! instant, `time_us; v1; v2; …;`.
//!
//! The internal readings are the actual-position channels of X, Y and Z (`s ist`, in English
//! exports `s actual`): the channel type from `%CHANNELTYPE=` (else the part of `%NAME=` before
//! `/`), the axis from `%AXISTYPE=` (else the part after `/`); a channel whose `%NAME=` is the
//! name `[columns]` gives an `_int_mm` column is taken for that axis instead. Units from
//! `%DIMENSION=` (`mm`, `µm`/`um`, `inch`/`in`), time from the first column in µs; other
//! channels are left aside. A channel without `%COLUMN=` is in the column of its block's order.
//! An empty cell is no sample; a channel with a `%CYCLETIME=` k times the row interval
//! (`%SAMPLING=`, else the rows' median interval) whose cells are all filled and hold runs of k
//! equal values from the first row is read as held and keeps the first row of each run. A
//! channel's `%COUNT=`, where given, must be the number of its samples, or, for a slower
//! channel packed into the first rows of its column, the number of those rows (then timed by
//! its cycle time from the first row).

use super::{assemble, text_of, Channel, Found};
use crate::axes::{Axis, Plane};
use crate::io::delimited::{parse_number, quote_cell};
use crate::measured::error::MeasuredError;
use crate::measured::layout::{parse_decimal, ColumnMap, Unit};
use crate::rtest::clock::Recording;
use crate::rtest::series::INT_COLUMNS;
use crate::rtest::Location;

/// One `%[CURVEn]` block.
#[derive(Debug, Default)]
struct Curve {
    line: u64,
    name: String,
    channel_type: Option<String>,
    axis_type: Option<String>,
    dimension: Option<(String, u64)>,
    cycle_us: Option<f64>,
    column: Option<usize>,
    /// `%COUNT=` and its line.
    count: Option<(usize, u64)>,
}

impl Curve {
    fn channel_type(&self) -> String {
        let t = self
            .channel_type
            .clone()
            .unwrap_or_else(|| self.name.split('/').next().unwrap_or("").to_string());
        t.split_whitespace()
            .collect::<Vec<_>>()
            .join(" ")
            .to_lowercase()
    }

    fn axis(&self) -> String {
        self.axis_type
            .clone()
            .or_else(|| self.name.split_once('/').map(|(_, a)| a.to_string()))
            .unwrap_or_default()
            .trim()
            .to_uppercase()
    }
}

/// The channel types of the actual position (German and English TNCscope).
const ACTUAL_POSITION: [&str; 2] = ["s ist", "s actual"];

enum Section {
    Global,
    Curve,
    Data,
    Other,
}

/// Millimetres per unit of a `%DIMENSION=` of positions: mm and µm as [`Unit`] reads them, and
/// inch.
fn mm_per(dimension: &str) -> Option<f64> {
    let d = dimension.trim().to_lowercase();
    match d.as_str() {
        "inch" | "in" | "\"" => Some(25.4),
        _ => Unit::parse(&d)
            .filter(|u| matches!(u, Unit::Mm | Unit::Um))
            .map(Unit::to_contract),
    }
}

/// Reads a TNCscope export into the internal recording (see the module docs).
pub(crate) fn read(
    source: &str,
    bytes: &[u8],
    map: &ColumnMap,
    plane: Option<Plane>,
) -> Result<Recording, MeasuredError> {
    let text = text_of(bytes);
    let bad = |line: u64, message: String| MeasuredError::Trace {
        at: Location::file_line(source, line),
        message,
    };
    let mut section = Section::Other;
    let mut sampling_us: Option<f64> = None;
    let mut curves: Vec<Curve> = Vec::new();
    let mut rows: Vec<(u64, &str)> = Vec::new();
    let mut data_seen = false;
    for (i, raw) in text.split('\n').enumerate() {
        let number = i as u64 + 1;
        let line = raw.trim_end_matches('\r').trim();
        if let Some(name) = line.strip_prefix("%[").and_then(|l| l.strip_suffix(']')) {
            let name = name.trim().to_uppercase();
            section = if name == "GLOBAL" {
                Section::Global
            } else if name.starts_with("CURVE") {
                curves.push(Curve {
                    line: number,
                    ..Curve::default()
                });
                Section::Curve
            } else if name == "DATA" {
                data_seen = true;
                Section::Data
            } else {
                Section::Other
            };
            continue;
        }
        if line.is_empty() {
            continue;
        }
        if let Section::Data = section {
            if !line.starts_with('%') {
                rows.push((number, line));
            }
            continue;
        }
        let Some((key, value)) = line.strip_prefix('%').and_then(|l| l.split_once('=')) else {
            continue;
        };
        let (key, value) = (key.trim().to_uppercase(), value.trim());
        let number_of = |what: &str| -> Result<f64, MeasuredError> {
            match parse_number(value, true) {
                Ok(v) if v > 0.0 => Ok(v),
                _ => Err(bad(
                    number,
                    format!("%{what}={} is not a positive number", quote_cell(value)),
                )),
            }
        };
        match section {
            Section::Global if key == "SAMPLING" => sampling_us = Some(number_of("SAMPLING")?),
            Section::Curve => {
                let c = curves.last_mut().expect("a curve section has its curve");
                match key.as_str() {
                    "NAME" => c.name = value.to_string(),
                    "CHANNELTYPE" => c.channel_type = Some(value.to_string()),
                    "AXISTYPE" => c.axis_type = Some(value.to_string()),
                    "DIMENSION" => c.dimension = Some((value.to_string(), number)),
                    "CYCLETIME" => c.cycle_us = Some(number_of("CYCLETIME")?),
                    "COUNT" => {
                        let n = value.parse::<usize>().map_err(|_| {
                            bad(
                                number,
                                format!(
                                    "%COUNT={} is not a number of samples (0, 1, 2, …)",
                                    quote_cell(value)
                                ),
                            )
                        })?;
                        c.count = Some((n, number));
                    }
                    "COLUMN" => {
                        c.column =
                            Some(value.parse::<usize>().ok().filter(|&n| n >= 1).ok_or_else(
                                || {
                                    bad(
                                        number,
                                        format!(
                                            "%COLUMN={} is not a column number (1, 2, …)",
                                            quote_cell(value)
                                        ),
                                    )
                                },
                            )?)
                    }
                    _ => {}
                }
            }
            _ => {}
        }
    }
    if !data_seen {
        return Err(MeasuredError::Trace {
            at: Location::source(source),
            message: "TNCscope export without a %[DATA] section: it holds no samples".into(),
        });
    }
    for (k, c) in curves.iter_mut().enumerate() {
        c.column.get_or_insert(k + 1);
    }
    let found = Found {
        names: curves.iter().map(|c| c.name.clone()).collect(),
        hint: "",
    };
    // The curve of each axis.
    let mut chosen: [Option<usize>; 3] = [None; 3];
    for axis in Axis::ALL {
        let spec = map.spec(INT_COLUMNS[axis.index()]);
        let named = curves
            .iter()
            .position(|c| c.name.trim().eq_ignore_ascii_case(&spec.name));
        let candidates: Vec<usize> = match named {
            Some(i) => vec![i],
            None => (0..curves.len())
                .filter(|&i| {
                    ACTUAL_POSITION.contains(&curves[i].channel_type().as_str())
                        && curves[i].axis() == axis.letter().to_string()
                })
                .collect(),
        };
        if let &[first, second, ..] = candidates.as_slice() {
            return Err(bad(
                curves[second].line,
                format!(
                    "a second s ist channel of {} ('{}', the first at line {}): name the one to use in rtest.toml [columns], e.g. {} = {{ name = \"{}\" }}",
                    axis.letter(),
                    quote_cell(&curves[second].name),
                    curves[first].line,
                    INT_COLUMNS[axis.index()],
                    quote_cell(&curves[first].name)
                ),
            ));
        }
        chosen[axis.index()] = candidates.first().copied();
    }
    let mut scale = [1.0; 3];
    for k in 0..3 {
        let Some(i) = chosen[k] else { continue };
        let c = &curves[i];
        scale[k] = match &c.dimension {
            None => {
                return Err(bad(
                    c.line,
                    format!(
                        "channel '{}' has no %DIMENSION=: the unit of its positions is not known",
                        quote_cell(&c.name)
                    ),
                ))
            }
            Some((d, line)) => mm_per(d).ok_or_else(|| {
                bad(
                    *line,
                    format!(
                        "%DIMENSION={} of channel '{}' is no unit of length (expected mm, µm or inch)",
                        quote_cell(d),
                        quote_cell(&c.name)
                    ),
                )
            })?,
        };
    }
    let columns = curves.iter().filter_map(|c| c.column).max().unwrap_or(0);
    let closing = rows.first().is_some_and(|(_, l)| l.ends_with(';'));
    let mut channels: [Option<Channel>; 3] =
        std::array::from_fn(|k| chosen[k].map(|i| Channel::new(curves[i].name.clone())));
    let mut row_times = Vec::with_capacity(rows.len());
    for &(number, line) in &rows {
        let body = if closing {
            line.strip_suffix(';')
        } else {
            Some(line)
        };
        let cells: Vec<&str> = body.unwrap_or(line).split(';').map(str::trim).collect();
        if body.is_none() || cells.len() < columns + 1 {
            return Err(bad(
                number,
                if body.is_none() {
                    format!(
                        "row cut off: {} of {} values and no closing ';' (the file ends mid-row?)",
                        cells.len(),
                        columns + 1
                    )
                } else {
                    format!(
                        "row has {} values, the header declares a time and {columns} channel column(s)",
                        cells.len()
                    )
                },
            ));
        }
        let t_us = parse_decimal(cells[0], true, source, number, "time")?;
        row_times.push(t_us);
        for (k, ch) in channels.iter_mut().enumerate() {
            let Some(ch) = ch else { continue };
            let c = &curves[chosen[k].unwrap_or_default()];
            let cell = cells[c.column.unwrap_or(1)];
            if cell.is_empty() {
                continue;
            }
            let v = parse_decimal(cell, true, source, number, &c.name)?;
            if v.abs() > super::NO_SAMPLE {
                continue;
            }
            ch.t_s.push(t_us * 1e-6);
            ch.mm.push(v * scale[k]);
            ch.lines.push(number);
        }
    }
    let row_us = sampling_us.or_else(|| median_step(&row_times));
    let first_rows: Vec<u64> = rows.iter().map(|&(n, _)| n).collect();
    for (k, ch) in channels.iter_mut().enumerate() {
        let (Some(ch), Some(i)) = (ch.as_mut(), chosen[k]) else {
            continue;
        };
        let c = &curves[i];
        if let (Some(cycle), Some(row_us)) = (c.cycle_us, row_us) {
            thin_held(ch, cycle / row_us, rows.len());
        }
        if let Some((count, line)) = c.count {
            check_count(source, ch, c, count, line, row_us, &first_rows)?;
        }
    }
    assemble(source, channels, plane, &found)
}

/// Holds a channel to its `%COUNT=`: the samples read (after [`thin_held`]) are that many;
/// else, where the column holds exactly its first `count` rows and `%CYCLETIME=` is longer
/// than the row interval, the channel is packed (its samples one after another from the first
/// row, as TNCscope writes a slower channel beside faster ones) and is timed from its first
/// row by its cycle time; anything else is refused naming the `%COUNT=` line.
fn check_count(
    source: &str,
    ch: &mut Channel,
    c: &Curve,
    count: usize,
    line: u64,
    row_us: Option<f64>,
    rows: &[u64],
) -> Result<(), MeasuredError> {
    let packed = count < rows.len()
        && ch.lines.as_slice() == &rows[..count]
        && c.cycle_us.zip(row_us).is_some_and(|(cy, r)| cy > 1.01 * r);
    if let (true, Some(cycle), Some(&t0)) = (packed, c.cycle_us, ch.t_s.first()) {
        for (i, t) in ch.t_s.iter_mut().enumerate() {
            *t = t0 + i as f64 * cycle * 1e-6;
        }
        return Ok(());
    }
    if ch.t_s.len() == count {
        return Ok(());
    }
    Err(MeasuredError::Trace {
        at: Location::file_line(source, line),
        message: format!(
            "%COUNT={count} of channel '{}', but its column holds {} sample(s) (the file cut off, or edited?)",
            quote_cell(&c.name),
            ch.t_s.len()
        ),
    })
}

/// Keeps the first row of each run of `ratio` equal values (a channel held between its own
/// samples), when `ratio` is an integer above 1, the channel has a value in every one of `rows`
/// and every run is constant.
fn thin_held(ch: &mut Channel, ratio: f64, rows: usize) {
    let k = ratio.round();
    if k < 2.0 || (ratio - k).abs() > 0.01 || ch.mm.len() != rows {
        return;
    }
    let k = k as usize;
    if !ch.mm.chunks(k).all(|run| run.iter().all(|v| *v == run[0])) {
        return;
    }
    let keep = |v: &mut Vec<f64>| *v = v.iter().step_by(k).copied().collect();
    keep(&mut ch.t_s);
    keep(&mut ch.mm);
    ch.lines = ch.lines.iter().step_by(k).copied().collect();
}

/// The median step of increasing times.
fn median_step(t: &[f64]) -> Option<f64> {
    let mut dt: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    if dt.is_empty() {
        return None;
    }
    let mid = dt.len() / 2;
    Some(*dt.select_nth_unstable_by(mid, f64::total_cmp).1)
}
