//! Controller traces as the internal recording of a two-system test (docs/measurement-files.md,
//! "Controller traces"): a Heidenhain TNCscope text export (`tnc`) or a Siemens Sinumerik
//! Operate trace (`sinumerik`), recognised by content, read into the same recording the
//! CSV route gives.
//!
//! Each reader gives the actual-position channels of X, Y and Z with their own sample times
//! (`Channel`); `assemble` puts them on one time base:
//! - channels sampled at the same instants (one cycle time) keep their samples; an instant where
//!   one of them has no sample (an empty TNCscope cell, a Sinumerik value above 9.2·10¹⁸ or a
//!   missing `fN`) is dropped for all, never filled in;
//! - channels with different cycle times: the time base is the samples of the slowest channel;
//!   the faster ones are interpolated onto it (cubic, four-point Lagrange on their own time
//!   stamps, as the clock alignment of two systems does), where they have a sample
//!   exactly at that instant it is taken as is. A base instant whose four neighbours in a faster
//!   channel span more than 4.5 of its sample intervals (a gap of more than one sample) is
//!   dropped.
//!
//! An axis the trace does not hold stands at the circle centre (its column holds 0, marked in
//! [`InternalRecording::absent`]); a circle needs the two axes of its plane, so a trace with fewer than
//! two axes, or without an axis of the plane the test states, is refused.

pub(crate) mod sinumerik;
pub(crate) mod tnc;

use super::error::MeasuredError;
use crate::axes::{Axis, Plane};
use crate::rtest::clock::{cubic_weights, Recording};
use crate::rtest::Location;

/// The internal recording of a test as eij reads it ([`super::inputs::TestInput::read_internal`]),
/// before the two systems are put on one time base: time on the recording's own clock, positions
/// in mm as the file holds them (a trace: converted from its units, on one time base, see the
/// module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct InternalRecording {
    /// Time, s.
    pub t_s: Vec<f64>,
    /// x, y, z, mm (an absent axis: 0).
    pub mm: [Vec<f64>; 3],
    /// File line of every sample.
    pub lines: Vec<u64>,
    /// Axes the file does not hold.
    pub absent: [bool; 3],
}

/// Values above this (9.2·10¹⁸, near the largest 64-bit integer) mark an instant without a
/// sample (Sinumerik writes them; TNCscope cells holding them are read alike).
pub(crate) const NO_SAMPLE: f64 = 9.2e18;

/// The file formats of an internal recording.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Format {
    /// Heidenhain TNCscope text export (`%TNCscopeNT data file`).
    Tnc,
    /// Siemens Sinumerik Operate trace (XML with `traceData`).
    Sinumerik,
    /// Delimited text (CSV dialects, [`super::layout`]).
    Delimited,
}

/// The format of a file, from its content: a first line starting `%TNCscope` is a TNCscope
/// export, text starting with `<` is XML (a Sinumerik trace or refused as not one), anything
/// else delimited text.
pub(crate) fn format_of(bytes: &[u8]) -> Format {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let start = bytes.trim_ascii_start();
    if start.len() >= 9 && start[..9].eq_ignore_ascii_case(b"%TNCscope") {
        Format::Tnc
    } else if start.first() == Some(&b'<') {
        Format::Sinumerik
    } else {
        Format::Delimited
    }
}

/// Text of a trace: UTF-8, else read as Latin-1 (controls write `µm` as byte 0xB5).
pub(crate) fn text_of(bytes: &[u8]) -> std::borrow::Cow<'_, str> {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    match std::str::from_utf8(bytes) {
        Ok(s) => s.into(),
        Err(_) => bytes.iter().map(|&b| b as char).collect::<String>().into(),
    }
}

/// One actual-position channel of a trace, in s and mm, with the file line of every sample.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Channel {
    /// The channel's name in the file (for messages).
    pub name: String,
    /// Sample times, s.
    pub t_s: Vec<f64>,
    /// Positions, mm.
    pub mm: Vec<f64>,
    /// File line of every sample.
    pub lines: Vec<u64>,
}

impl Channel {
    /// A channel without samples yet.
    pub(crate) fn new(name: String) -> Channel {
        Channel {
            name,
            t_s: Vec::new(),
            mm: Vec::new(),
            lines: Vec::new(),
        }
    }

    fn median_dt(&self) -> f64 {
        let mut dt: Vec<f64> = self.t_s.windows(2).map(|w| w[1] - w[0]).collect();
        let mid = dt.len() / 2;
        *dt.select_nth_unstable_by(mid, f64::total_cmp).1
    }

    /// The sample at exactly `t` (to 10⁻⁶ of the sample interval), else the cubic interpolation
    /// if this channel is `faster` and its four neighbours are not spread over a gap.
    fn at(&self, t: f64, dt: f64, faster: bool, hint: &mut usize) -> Option<f64> {
        let i = self.t_s.partition_point(|&x| x < t - 1e-6 * dt);
        if i < self.t_s.len() && (self.t_s[i] - t).abs() <= 1e-6 * dt {
            return Some(self.mm[i]);
        }
        if !faster {
            return None;
        }
        let (j, w) = cubic_weights(&self.t_s, t, hint)?;
        if self.t_s[j + 3] - self.t_s[j] > 4.5 * dt {
            return None;
        }
        Some((0..4).map(|k| w[k] * self.mm[j + k]).sum())
    }
}

/// What a trace holds beside its position channels, for messages: every channel found.
pub(crate) struct Found {
    /// The file's names of its channels or signals.
    pub names: Vec<String>,
    /// Appended to messages about missing axes (how to name them).
    pub hint: &'static str,
}

impl Found {
    fn list(&self) -> String {
        let names: Vec<String> = self
            .names
            .iter()
            .map(|n| format!("'{}'", crate::io::delimited::quote_cell(n)))
            .collect();
        if names.is_empty() {
            "none".into()
        } else {
            names.join(", ")
        }
    }
}

/// The recording of the `axes` channels of a trace (see the module docs). `plane` is the
/// test's plane where stated; `found` lists the file's channels for messages.
pub(crate) fn assemble(
    source: &str,
    axes: [Option<Channel>; 3],
    plane: Option<Plane>,
    found: &Found,
) -> Result<Recording, MeasuredError> {
    let held: Vec<char> = Axis::ALL
        .into_iter()
        .filter(|a| axes[a.index()].is_some())
        .map(Axis::letter)
        .collect();
    let holds = match held.len() {
        0 => "none".to_string(),
        1 => format!("that of {} only", held[0]),
        _ => format!(
            "those of {} only",
            held.iter()
                .map(char::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    let refuse = |need: String| MeasuredError::Trace {
        at: Location::source(source),
        message: format!(
            "{need}, the trace holds {holds} (channels: {}){}",
            found.list(),
            found.hint
        ),
    };
    if let Some(p) = plane {
        let (a, b) = p.axes();
        if let Some(m) = [a, b].into_iter().find(|m| axes[m.index()].is_none()) {
            return Err(refuse(format!(
                "plane {p} needs the actual position of {}",
                m.letter()
            )));
        }
    }
    if held.len() < 2 {
        return Err(refuse(
            "a circle needs the actual positions of two axes".into(),
        ));
    }
    for ch in axes.iter().flatten() {
        check_channel(source, ch)?;
    }
    // The base: the slowest channel (fewest samples on a tie: the one with gaps).
    let present: Vec<&Channel> = axes.iter().flatten().collect();
    let dts: Vec<f64> = present.iter().map(|c| c.median_dt()).collect();
    let base = (0..present.len())
        .max_by(|&i, &j| {
            let (a, b) = (dts[i], dts[j]);
            if (a - b).abs() <= 0.01 * a.max(b) {
                present[j].t_s.len().cmp(&present[i].t_s.len())
            } else {
                a.total_cmp(&b)
            }
        })
        .unwrap_or(0);
    let (b, bdt) = (present[base], dts[base]);
    let mut t_s = Vec::with_capacity(b.t_s.len());
    let mut lines = Vec::with_capacity(b.t_s.len());
    let mut mm: [Vec<f64>; 3] = Default::default();
    let mut hints = [0usize; 3];
    let axis_dt: [f64; 3] =
        std::array::from_fn(|k| axes[k].as_ref().map_or(0.0, Channel::median_dt));
    'samples: for (i, &t) in b.t_s.iter().enumerate() {
        let mut row = [0.0; 3];
        for (k, ch) in axes.iter().enumerate() {
            let Some(ch) = ch else { continue };
            let dt = axis_dt[k];
            let faster = dt < 0.99 * bdt;
            match ch.at(t, dt, faster, &mut hints[k]) {
                Some(v) => row[k] = v,
                None => continue 'samples,
            }
        }
        t_s.push(t);
        lines.push(b.lines[i]);
        for k in 0..3 {
            mm[k].push(row[k]);
        }
    }
    let mut r = Recording::with_lines(source.to_string(), t_s, mm, lines)?;
    r.absent = std::array::from_fn(|k| axes[k].is_none());
    Ok(r)
}

/// At least four samples, time strictly increasing, naming the line otherwise.
fn check_channel(source: &str, ch: &Channel) -> Result<(), MeasuredError> {
    if ch.t_s.len() < 4 {
        return Err(MeasuredError::Trace {
            at: Location::source(source),
            message: format!(
                "channel '{}' has {} sample(s), a circle test needs many (at least 4)",
                crate::io::delimited::quote_cell(&ch.name),
                ch.t_s.len()
            ),
        });
    }
    for i in 1..ch.t_s.len() {
        if ch.t_s[i] <= ch.t_s[i - 1] {
            return Err(MeasuredError::Trace {
                at: Location::file_line(source, ch.lines[i]),
                message: format!(
                    "time {} s does not follow {} s of the line before (time must increase)",
                    ch.t_s[i],
                    ch.t_s[i - 1]
                ),
            });
        }
    }
    Ok(())
}
