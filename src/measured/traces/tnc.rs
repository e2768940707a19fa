//! Heidenhain TNCscope text exports (`.sco`, recognised by the first line `%TNCscopeNT data
//! file`): a `%[GLOBAL]` block (`%SAMPLING=` µs), one `%[CURVEn]` block per channel (`%NAME=`,
//! `%CHANNELTYPE=`, `%AXISTYPE=`, `%DIMENSION=`, `%CYCLETIME=` µs, `%COLUMN=`), then after
//! `%[DATA]` one row per sample instant, `time_us; v1; v2; …;`.
//!
//! The internal readings are the `s ist` (actual position) channels of X, Y and Z: the channel
//! type from `%CHANNELTYPE=` (else the part of `%NAME=` before `/`), the axis from `%AXISTYPE=`
//! (else the part after `/`); a channel whose `%NAME=` is the name `[columns]` gives an
//! `_int_mm` column is taken for that axis instead. Units from `%DIMENSION=` (`mm`, `µm`/`um`,
//! `inch`/`in`), time from the first column in µs; other channels are left aside. A channel
//! without `%COLUMN=` is in the column of its block's order. An empty cell is no sample; a
//! channel with a `%CYCLETIME=` k times the row interval (`%SAMPLING=`, else the rows' median
//! interval) whose cells are all filled and hold runs of k equal values from the first row is
//! read as held and keeps the first row of each run.

use super::{assemble, text_of, Channel, Found};
use crate::axes::{Axis, Plane};
use crate::io::delimited::{parse_number, quote_cell};
use crate::measured::error::MeasuredError;
use crate::measured::layout::{parse_decimal, ColumnMap};
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

enum Section {
    Global,
    Curve,
    Data,
    Other,
}

/// Millimetres per unit of a `%DIMENSION=` of positions.
fn mm_per(dimension: &str) -> Option<f64> {
    match dimension.trim().to_lowercase().as_str() {
        "mm" => Some(1.0),
        "µm" | "μm" | "um" => Some(1e-3),
        "inch" | "in" | "\"" => Some(25.4),
        _ => None,
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
                    curves[i].channel_type() == "s ist"
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
    for (k, ch) in channels.iter_mut().enumerate() {
        let (Some(ch), Some(i), Some(row_us)) = (ch.as_mut(), chosen[k], row_us) else {
            continue;
        };
        if let Some(cycle) = curves[i].cycle_us {
            thin_held(ch, cycle / row_us, rows.len());
        }
    }
    assemble(source, channels, plane, &found)
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
