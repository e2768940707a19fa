//! Two time bases made one: a circle test recorded by two systems (a CNC trace of the axes'
//! readings and an R-Test logger, each with its own clock and sample rate) brought onto one
//! time base, and the clock offset between them estimated from the trajectories.
//!
//! Conventions: the clock offset o is the internal clock minus the external clock at the same
//! instant (docs/commands.md `time_offset_ms`), so an external sample stamped τ belongs to internal
//! time τ + o. Interpolation is cubic (four-point Lagrange on the samples' own times): on a
//! 2 mm circle at 8 Hz sampled at 1 kHz its error is below 1 nm, three orders under the
//! R-Test's noise, where a straight line between samples would err by 0.6 µm.
//!
//! The trajectory alignment ([`align`]) minimises the mean square distance between the
//! external and the internal path over the whole overlap, ramps and rests included, so that it
//! has one minimum and not one per revolution. It cannot tell a clock offset from the
//! structural deviation itself: on a steady circle a residual offset δ (internal minus external
//! clock; negative for late external readings) adds δ·v, and v_a has
//! the shape of the acceleration of the other axis, so the alignment absorbs the antisymmetric
//! in-plane cross-talk (E_ab − E_ba)·ω/2 (tens of µs). [`super::clock_fit`] separates the two
//! across tests.

use argmin::core::{CostFunction, Executor};
use argmin::solver::brent::BrentOpt;

use super::error::{Location, RtestError};
use super::series::CircleSeries;

/// Least overlap of the two records, as a share of the shorter one.
pub(crate) const MIN_OVERLAP: f64 = 0.5;

/// One system's recording of a two-system test: its time and its three position columns.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Recording {
    /// The file (or in-memory name).
    pub source: String,
    /// Time on this system's clock, s, strictly increasing.
    pub t_s: Vec<f64>,
    /// x, y, z, mm.
    pub mm: [Vec<f64>; 3],
    /// File line of every row, where read from a file.
    pub lines: Option<Vec<u64>>,
    /// Axes the file does not record (a controller trace of the two axes of the plane): their
    /// column holds 0, the axis standing at the circle centre; a change of coordinates (the
    /// circle centre subtracted) leaves them alone.
    pub absent: [bool; 3],
}

impl Recording {
    /// A recording from memory, validated: equal lengths, at least four rows, finite values,
    /// time strictly increasing.
    pub(crate) fn new(
        source: String,
        t_s: Vec<f64>,
        mm: [Vec<f64>; 3],
    ) -> Result<Self, RtestError> {
        let r = Recording {
            source,
            t_s,
            mm,
            lines: None,
            absent: [false; 3],
        };
        r.check()?;
        Ok(r)
    }

    /// A recording read from a file (`lines`: the file line of every row), validated as
    /// [`Recording::new`]; the readers are in [`crate::measured`].
    pub(crate) fn with_lines(
        source: String,
        t_s: Vec<f64>,
        mm: [Vec<f64>; 3],
        lines: Vec<u64>,
    ) -> Result<Self, RtestError> {
        let r = Recording {
            source,
            t_s,
            mm,
            lines: Some(lines),
            absent: [false; 3],
        };
        r.check()?;
        Ok(r)
    }

    fn at_row(&self, i: usize) -> Location {
        match &self.lines {
            Some(l) => Location::file_line(&self.source, l[i]),
            None => Location {
                source: self.source.clone(),
                line: Some(super::error::Line::Row(i + 1)),
            },
        }
    }

    fn check(&self) -> Result<(), RtestError> {
        let n = self.t_s.len();
        for (col, name) in self.mm.iter().zip(["x", "y", "z"]) {
            if col.len() != n {
                return Err(RtestError::LengthMismatch {
                    at: Location::source(&self.source),
                    column: name.into(),
                    len: col.len(),
                    expected: n,
                });
            }
        }
        if n < 4 {
            return Err(RtestError::TooFewRows {
                at: Location::source(&self.source),
                rows: n,
                needed: 4,
            });
        }
        for i in 0..n {
            let values = std::iter::once(self.t_s[i]).chain(self.mm.iter().map(|c| c[i]));
            if let Some(k) = values.into_iter().position(|v| !v.is_finite()) {
                let v = if k == 0 {
                    self.t_s[i]
                } else {
                    self.mm[k - 1][i]
                };
                return Err(RtestError::NotFinite {
                    at: self.at_row(i),
                    column: ["t", "x", "y", "z"][k].into(),
                    value: v.to_string(),
                });
            }
            if i > 0 && self.t_s[i] <= self.t_s[i - 1] {
                return Err(RtestError::TimeNotIncreasing {
                    at: self.at_row(i),
                    t_s: self.t_s[i],
                    previous_t_s: self.t_s[i - 1],
                });
            }
        }
        Ok(())
    }

    /// Median sample interval, s.
    pub(crate) fn median_dt(&self) -> f64 {
        let mut dt: Vec<f64> = self.t_s.windows(2).map(|w| w[1] - w[0]).collect();
        let mid = dt.len() / 2;
        *dt.select_nth_unstable_by(mid, f64::total_cmp).1
    }

    /// Duration, s.
    pub(crate) fn span_s(&self) -> f64 {
        self.t_s[self.t_s.len() - 1] - self.t_s[0]
    }

    /// The recording's values at times `t` of its own clock (cubic, see the module docs), or
    /// `None` outside its second to second-last sample.
    pub(crate) fn sample(&self, t: f64, hint: &mut usize) -> Option<[f64; 3]> {
        let w = cubic_weights(&self.t_s, t, hint)?;
        Some(std::array::from_fn(|c| {
            (0..4).map(|k| w.1[k] * self.mm[c][w.0 + k]).sum()
        }))
    }
}

/// Four-point Lagrange weights for `t` on `times`: the first of the four samples and the
/// weights; `None` unless `times[1] <= t <= times[n−2]`. `hint` is the previous answer's
/// interval, walked from (successive calls mostly move forward).
pub(crate) fn cubic_weights(times: &[f64], t: f64, hint: &mut usize) -> Option<(usize, [f64; 4])> {
    let n = times.len();
    if n < 4 || !(t >= times[1] && t <= times[n - 2]) {
        return None;
    }
    // Interval j: times[j] <= t < times[j+1] with 1 <= j <= n − 3; found by bisection when the
    // hint is more than a few samples off (the first call of a pass over a long record).
    let mut j = (*hint).clamp(1, n - 3);
    let near = |k: usize| times[k.saturating_sub(8).max(1)] <= t && t < times[(k + 8).min(n - 2)];
    if !near(j) {
        j = times
            .partition_point(|&x| x <= t)
            .saturating_sub(1)
            .clamp(1, n - 3);
    }
    while j > 1 && times[j] > t {
        j -= 1;
    }
    while j < n - 3 && times[j + 1] <= t {
        j += 1;
    }
    *hint = j;
    let x = [times[j - 1], times[j], times[j + 1], times[j + 2]];
    let mut w = [1.0; 4];
    for (i, wi) in w.iter_mut().enumerate() {
        for (k, xk) in x.iter().enumerate() {
            if k != i {
                *wi *= (t - xk) / (x[i] - xk);
            }
        }
    }
    Some((j - 1, w))
}

/// The two recordings on one time base, the external shifted by the clock `offset_s`
/// (internal clock minus external clock). The base is the recording with the lower sample rate
/// (its samples stay as recorded, the other one is interpolated onto them, so that no sample
/// is invented and the residuals stay independent); time is on the internal clock. Samples
/// where the other recording does not reach are dropped.
pub(crate) fn merge(
    name: String,
    internal: &Recording,
    external: &Recording,
    offset_s: f64,
) -> Result<CircleSeries, RtestError> {
    let mut t_s = Vec::new();
    let (mut int_mm, mut ext_mm): ([Vec<f64>; 3], [Vec<f64>; 3]) = Default::default();
    let mut lines = Vec::new();
    let mut hint = 0;
    let external_base = external.median_dt() > internal.median_dt();
    let (base, other) = if external_base {
        (external, internal)
    } else {
        (internal, external)
    };
    // Time of the base samples on the other recording's clock.
    let shift = if external_base { offset_s } else { -offset_s };
    for (i, &tb) in base.t_s.iter().enumerate() {
        let Some(v) = other.sample(tb + shift, &mut hint) else {
            continue;
        };
        let (int, ext) = if external_base {
            (v, [0, 1, 2].map(|c| base.mm[c][i]))
        } else {
            ([0, 1, 2].map(|c| base.mm[c][i]), v)
        };
        for c in 0..3 {
            int_mm[c].push(int[c]);
            ext_mm[c].push(ext[c]);
        }
        t_s.push(if external_base { tb + offset_s } else { tb });
        if let Some(l) = &base.lines {
            lines.push(l[i]);
        }
    }
    if t_s.len() < 2 {
        return Err(RtestError::Pooling {
            at: Location::source(&name),
            detail: format!(
                "the recordings do not overlap with a clock offset of {:.3} ms",
                offset_s * 1e3
            ),
        });
    }
    let lines = base.lines.as_ref().map(|_| lines);
    CircleSeries::from_parts(name, t_s, int_mm, ext_mm, lines, None)
}

/// The clock offset that best aligns the two paths, from the trajectories alone.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Alignment {
    /// Internal clock minus external clock, s.
    pub offset_s: f64,
    /// RMS distance of the aligned paths over the overlap, µm.
    pub rms_um: f64,
    /// RMS distance at the best alignment one circle period or more away, µm (how clearly the
    /// alignment is unique).
    pub next_best_rms_um: f64,
    /// Overlap of the aligned records, s.
    pub overlap_s: f64,
}

/// Mean square distance of the paths (µm²) with the external shifted by `offset_s`, over the
/// base samples every `stride`; `None` with less than [`MIN_OVERLAP`] overlap.
fn mean_square(
    internal: &Recording,
    external: &Recording,
    offset_s: f64,
    stride: usize,
) -> Option<(f64, f64)> {
    let (mut sum, mut count, mut hint) = (0.0, 0usize, 0);
    let (mut first, mut last) = (f64::INFINITY, f64::NEG_INFINITY);
    for i in (0..internal.t_s.len()).step_by(stride) {
        let t = internal.t_s[i];
        if let Some(e) = external.sample(t - offset_s, &mut hint) {
            for (e_c, mm_c) in e.iter().zip(&internal.mm) {
                let d = (e_c - mm_c[i]) * 1e3;
                sum += d * d;
            }
            count += 1;
            first = first.min(t);
            last = last.max(t);
        }
    }
    let shorter = internal.span_s().min(external.span_s());
    let overlap = last - first;
    (count > 3 && overlap >= MIN_OVERLAP * shorter).then(|| (sum / (3 * count) as f64, overlap))
}

struct Misfit<'a> {
    internal: &'a Recording,
    external: &'a Recording,
    stride: usize,
}

impl CostFunction for Misfit<'_> {
    type Param = f64;
    type Output = f64;
    /// Mean square distance at the offset `p` in ms.
    fn cost(&self, p: &f64) -> Result<f64, argmin::core::Error> {
        Ok(
            mean_square(self.internal, self.external, p * 1e-3, self.stride)
                .map_or(f64::MAX, |m| m.0),
        )
    }
}

/// Aligns the external path on the internal one: a grid over every offset that leaves
/// [`MIN_OVERLAP`] of overlap (steps of 1/20 of the circle period, at most 200 000 steps; the
/// misfit of the grid on about 25 internal samples per period), then Brent's method (argmin,
/// on every sample) between the grid neighbours of the best point. `period_s` is the circle's period, for the grid step and the uniqueness check.
pub(crate) fn align(
    internal: &Recording,
    external: &Recording,
    period_s: f64,
) -> Result<Alignment, RtestError> {
    let name = format!("{} + {}", internal.source, external.source);
    let lo = internal.t_s[0] - external.t_s[external.t_s.len() - 1];
    let hi = internal.t_s[internal.t_s.len() - 1] - external.t_s[0];
    // A long external record (a logger running through a whole session) makes the grid long;
    // beyond 200 000 steps it is coarsened.
    let step = (period_s / 20.0).max((hi - lo) / 200_000.0);
    // About 25 internal samples per circle period, at most 1000, per evaluation of the misfit.
    let samples = (25.0 * internal.span_s() / period_s).clamp(100.0, 1000.0) as usize;
    let stride = (internal.t_s.len() / samples).max(1);
    let steps = ((hi - lo) / step).ceil() as usize;
    let grid: Vec<(f64, f64)> = (0..=steps)
        .filter_map(|k| {
            let o = lo + k as f64 * step;
            mean_square(internal, external, o, stride).map(|(m, _)| (o, m))
        })
        .collect();
    let Some(&(best, _)) = grid.iter().min_by(|a, b| a.1.total_cmp(&b.1)) else {
        return Err(RtestError::Pooling {
            at: Location::source(&name),
            detail: format!(
                "the records overlap by less than {:.0} % at any clock offset",
                MIN_OVERLAP * 100.0
            ),
        });
    };
    let misfit = Misfit {
        internal,
        external,
        stride: 1,
    };
    let solver = BrentOpt::new((best - step) * 1e3, (best + step) * 1e3).set_tolerance(1e-9, 1e-5);
    let offset_ms = Executor::new(misfit, solver)
        .configure(|s| s.max_iters(200))
        .run()
        .ok()
        .and_then(|r| r.state.best_param)
        .unwrap_or(best * 1e3);
    let offset_s = offset_ms * 1e-3;
    let (ms, overlap_s) =
        mean_square(internal, external, offset_s, 1).ok_or_else(|| RtestError::Pooling {
            at: Location::source(&name),
            detail: "the aligned records do not overlap".into(),
        })?;
    let next_best = grid
        .iter()
        .filter(|(o, _)| (o - offset_s).abs() >= 0.5 * period_s)
        .map(|(_, m)| *m)
        .fold(f64::INFINITY, f64::min);
    Ok(Alignment {
        offset_s,
        rms_um: ms.sqrt(),
        next_best_rms_um: next_best.sqrt(),
        overlap_s,
    })
}
