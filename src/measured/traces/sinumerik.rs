//! Siemens Sinumerik Operate traces (XML, recognised by a `traceData` element holding
//! `dataFrame` elements): each frame lists its signals as `dataSignal` elements (attributes
//! `name`, the NC variable path, and `description`), then one `rec` element per sample instant
//! with `time` in s and `f1`, `f2`, … the values of the frame's first, second, … signal.
//!
//! The file does not say which signal is which axis: `[columns]` in `rtest.toml` does, its
//! `x_int_mm`, `y_int_mm`, `z_int_mm` names matched against a signal's `name` or `description`
//! (ignoring letter case, surrounding spaces and a trailing `(64 bit)`), with the unit of the
//! entry (mm when it gives none). A missing `fN`, or a value above 9.2·10¹⁸, is no sample of
//! that signal at that instant. Other signals are left aside.

use roxmltree::{Document, Node, ParsingOptions};

use super::{assemble, text_of, Channel, Found, NO_SAMPLE};
use crate::axes::{Axis, Plane};
use crate::io::delimited::quote_cell;
use crate::measured::error::MeasuredError;
use crate::measured::layout::{parse_decimal, ColumnMap};
use crate::rtest::clock::Recording;
use crate::rtest::series::INT_COLUMNS;
use crate::rtest::Location;

/// Most bytes of a Sinumerik trace eij reads (64 MiB): the XML is parsed whole, its tree
/// taking about seven times the file in memory. A circle test of 10 s traced at 8 kHz with four
/// signals is about 7 MB.
pub(crate) const MAX_XML_BYTES: usize = 64 << 20;

/// One `dataSignal`.
struct Signal<'a> {
    frame: usize,
    index: usize,
    name: &'a str,
    description: &'a str,
}

impl Signal<'_> {
    fn is(&self, wanted: &str) -> bool {
        let wanted = wanted.trim();
        let plain = |s: &str| {
            let s = s.trim();
            s.strip_suffix("(64 bit)")
                .map_or(s, str::trim_end)
                .to_string()
        };
        [self.name, self.description]
            .iter()
            .any(|s| s.trim().eq_ignore_ascii_case(wanted) || plain(s).eq_ignore_ascii_case(wanted))
    }

    fn label(&self) -> String {
        if self.description.trim().is_empty() {
            self.name.trim().to_string()
        } else {
            self.description.trim().to_string()
        }
    }
}

/// Reads a Sinumerik trace into the internal recording (see the module docs).
pub(crate) fn read(
    source: &str,
    bytes: &[u8],
    map: &ColumnMap,
    plane: Option<Plane>,
) -> Result<Recording, MeasuredError> {
    if bytes.len() > MAX_XML_BYTES {
        return Err(MeasuredError::Trace {
            at: Location::source(source),
            message: format!(
                "a Sinumerik trace of {:.1} MiB: eij reads traces of up to {} MiB (the XML is parsed whole, about seven times its size in memory); trace a shorter time or fewer signals",
                bytes.len() as f64 / f64::from(1u32 << 20),
                MAX_XML_BYTES >> 20
            ),
        });
    }
    let text = text_of(bytes);
    let starts: Vec<usize> = std::iter::once(0)
        .chain(text.match_indices('\n').map(|(i, _)| i + 1))
        .collect();
    let line_of = |offset: usize| starts.partition_point(|&s| s <= offset) as u64;
    let options = ParsingOptions {
        allow_dtd: true,
        ..ParsingOptions::default()
    };
    let doc = Document::parse_with_options(&text, options).map_err(|e| {
        use roxmltree::Error as E;
        let (line, message) = match e {
            E::UnexpectedEndOfStream | E::UnclosedRootNode | E::NoRootNode => (
                text.trim_end().lines().count().max(1) as u64,
                "the XML ends before its elements are closed (the file cut off?)".to_string(),
            ),
            e => (
                u64::from(e.pos().row),
                format!("not well-formed XML: {e} (the file cut off?)"),
            ),
        };
        MeasuredError::Trace {
            at: Location::file_line(source, line),
            message,
        }
    })?;
    let frames: Vec<Node> = doc
        .descendants()
        .filter(|n| {
            n.has_tag_name("dataFrame")
                && n.parent_element()
                    .is_some_and(|p| p.has_tag_name("traceData"))
        })
        .collect();
    if frames.is_empty() {
        return Err(MeasuredError::Trace {
            at: Location::source(source),
            message:
                "XML without traceData/dataFrame: not a Sinumerik Operate trace (nor a CSV file)"
                    .into(),
        });
    }
    let mut signals = Vec::new();
    for (f, frame) in frames.iter().enumerate() {
        let list = frame.children().filter(|n| n.has_tag_name("dataSignal"));
        for (i, s) in list.enumerate() {
            signals.push(Signal {
                frame: f,
                index: i + 1,
                name: s.attribute("name").unwrap_or(""),
                description: s.attribute("description").unwrap_or(""),
            });
        }
    }
    let found = Found {
        names: signals.iter().map(Signal::label).collect(),
        hint: "; rtest.toml [columns] says which signal is which axis, e.g. x_int_mm = { name = \"<its name or description>\" }",
    };
    let mut chosen: [Option<&Signal>; 3] = [None; 3];
    let mut scale = [1.0; 3];
    for axis in Axis::ALL {
        let column = INT_COLUMNS[axis.index()];
        let spec = map.spec(column);
        let matches: Vec<&Signal> = signals.iter().filter(|s| s.is(&spec.name)).collect();
        if let &[a, b, ..] = matches.as_slice() {
            return Err(MeasuredError::Trace {
                at: Location::source(source),
                message: format!(
                    "two signals match [columns] {column} '{}': '{}' and '{}' (give the one's name, its NC variable path)",
                    quote_cell(&spec.name),
                    quote_cell(a.name.trim()),
                    quote_cell(b.name.trim())
                ),
            });
        }
        chosen[axis.index()] = matches.first().copied();
        scale[axis.index()] = spec.unit.to_contract();
    }
    let mut channels: [Option<Channel>; 3] =
        std::array::from_fn(|k| chosen[k].map(|s| Channel::new(s.label())));
    for (f, frame) in frames.iter().enumerate() {
        for rec in frame.children().filter(|n| n.has_tag_name("rec")) {
            let line = line_of(rec.range().start);
            let time = rec.attribute("time").ok_or_else(|| MeasuredError::Trace {
                at: Location::file_line(source, line),
                message: "rec without a time attribute".into(),
            })?;
            let t_s = parse_decimal(time, false, source, line, "time")?;
            for (k, ch) in channels.iter_mut().enumerate() {
                let (Some(ch), Some(s)) = (ch.as_mut(), chosen[k]) else {
                    continue;
                };
                if s.frame != f {
                    continue;
                }
                let Some(cell) = rec.attribute(format!("f{}", s.index).as_str()) else {
                    continue;
                };
                let v = parse_decimal(cell, false, source, line, &s.label())?;
                if v.abs() > NO_SAMPLE {
                    continue;
                }
                ch.t_s.push(t_s);
                ch.mm.push(v * scale[k]);
                ch.lines.push(line);
            }
        }
    }
    assemble(source, channels, plane, &found)
}
