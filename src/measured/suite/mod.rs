//! Evaluation of the circle tests of a command (`eij evaluate`, `identify`, `report`): every
//! test read with its folder's conditions, tests recorded by two systems brought onto one time
//! base, clock offsets estimated per clock (see [`crate::rtest::clock`], [`crate::rtest::clock_fit`]), each
//! test evaluated at its set radius, and cw/ccw pairs given their ISO 230-4 bi-directional
//! circular deviation.

use super::conditions::DataFiles;
use super::error::MeasuredError;
use super::inputs::TestInput;
use super::json::{CircleJson, TestJson, TimeOffsetJson};
use crate::axes::{Direction, Eij, Plane};
use crate::rtest::clock::{self, Recording};
use crate::rtest::normalise::Normalised;
use crate::rtest::{evaluate, iso230, CircleResult, CircleSeries, EvalOptions, Named, Warning};
use rayon::prelude::*;

mod clocks;
pub mod diagnose;
mod partners;
use clocks::{align_clock, lag_of_clock};
pub use clocks::{clocks_json, ClockReport, OffsetSource, TimeOffset};

/// Options of [`evaluate_tests`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SuiteOptions {
    /// Circle plane of every test (command line); else the test's `[[test]]` plane, else
    /// inferred from the data.
    pub plane: Option<Plane>,
    /// Set radius of every test (command line); else `rtest.toml`.
    pub radius_mm: Option<f64>,
    /// Set radius where neither the command line nor `rtest.toml` gives one (e.g. identify's
    /// configuration); else the mean internal radius, with a warning.
    pub fallback_radius_mm: Option<f64>,
    /// Correct single-file tests by the clock offset fitted over the tests of their folder
    /// (a probe logger that lags the scales); two-system tests are always aligned.
    pub fit_time_offset: bool,
}

/// Where a test's set radius came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RadiusSource {
    /// `--radius-mm`.
    CommandLine,
    /// The folder's `rtest.toml` (folder key or `[[test]]` entry).
    Conditions,
    /// The caller's fallback (identify's configuration).
    Fallback,
    /// Nothing gave it: the mean internal radius (EIJ then per measured, not set, acceleration).
    InternalMean,
}

impl RadiusSource {
    /// The JSON name: `command-line`, `rtest.toml`, `default`, `internal-mean`.
    pub fn name(self) -> &'static str {
        match self {
            RadiusSource::CommandLine => "command-line",
            RadiusSource::Conditions => "rtest.toml",
            RadiusSource::Fallback => "default",
            RadiusSource::InternalMean => "internal-mean",
        }
    }
}

/// One evaluated test.
#[derive(Debug, Clone, PartialEq)]
pub struct EvaluatedTest {
    /// The test and its conditions.
    pub input: TestInput,
    /// The series evaluated (two-system tests: merged at the offset used).
    pub series: CircleSeries,
    /// The evaluation (its warnings include those of the conditions: direction, feed, radius).
    pub result: CircleResult,
    /// Where the set radius came from.
    pub radius_source: RadiusSource,
    /// The clock offset applied (two-system tests, and single-file tests corrected by it).
    pub time_offset: Option<TimeOffset>,
    /// What the test's conditions and clock add to the evaluation's own warnings (also in
    /// `result.warnings`): a missing set radius, a direction or feed that disagree with the
    /// data, a clock offset not separable from cross-talk.
    pub notes: Vec<Warning>,
}

/// A cw/ccw pair with its ISO 230-4 bi-directional circular deviations.
#[derive(Debug, Clone, PartialEq)]
pub struct Bidirectional {
    /// Indices of the cw and the ccw test in [`Suite::tests`].
    pub tests: [usize; 2],
    /// G(b) of the internal paths, µm.
    pub internal_um: f64,
    /// G(b) of the external paths, µm.
    pub external_um: f64,
}

/// The evaluated tests of a command.
#[derive(Debug, Clone, PartialEq)]
pub struct Suite {
    /// The tests, in input order.
    pub tests: Vec<EvaluatedTest>,
    /// The clocks whose offsets were estimated.
    pub clocks: Vec<ClockReport>,
    /// cw/ccw pairs (same plane, position, radius, acceleration within 5 %).
    pub bidirectional: Vec<Bidirectional>,
    /// Warnings about the whole set (clocks), each naming its clock.
    pub warnings: Vec<Named>,
}

/// Accelerations closer than this ratio pair up as cw/ccw.
const PAIR_ACCEL_RATIO: f64 = 1.05;
pub(super) struct Prepared {
    opts: EvalOptions,
    source: RadiusSource,
    data: Data,
    /// Period of the internal recording's circle, s (two-system tests).
    period_s: Option<f64>,
}

pub(super) enum Data {
    Single(CircleSeries),
    Split {
        internal: Recording,
        external: Recording,
    },
}

fn eval_options(input: &TestInput, opts: &SuiteOptions) -> (EvalOptions, RadiusSource) {
    let plane = opts.plane.or(input.test.plane);
    let (radius_mm, source) = match (
        opts.radius_mm,
        input.test.radius_mm,
        opts.fallback_radius_mm,
    ) {
        (Some(r), _, _) => (Some(r), RadiusSource::CommandLine),
        (None, Some(r), _) => (Some(r), RadiusSource::Conditions),
        (None, None, Some(r)) => (Some(r), RadiusSource::Fallback),
        (None, None, None) => (None, RadiusSource::InternalMean),
    };
    (EvalOptions { plane, radius_mm }, source)
}

/// The tests of one E group share plane and position.
pub(super) fn group_key(input: &TestInput, norm: &Normalised) -> String {
    match &input.test.position_mm {
        None => norm.plane.to_string(),
        Some(p) => {
            let p: Vec<String> = p.iter().map(|v| format!("{v}")).collect();
            format!("{} at [{}] mm", norm.plane, p.join(", "))
        }
    }
}

/// Reads, aligns and evaluates `inputs` (see the module docs).
pub fn evaluate_tests(inputs: &[TestInput], opts: &SuiteOptions) -> Result<Suite, MeasuredError> {
    // Files are read and evaluated in parallel; the first error in input order is reported.
    let prepared: Vec<Prepared> = inputs
        .par_iter()
        .map(|input| -> Result<Prepared, MeasuredError> {
            let (eval, source) = eval_options(input, opts);
            let (data, period_s) = match &input.test.data {
                DataFiles::Single(_) => (Data::Single(input.read_single()?), None),
                DataFiles::Split { internal, external } => {
                    let mut int = super::recording::read_internal(
                        internal,
                        &input.internal_columns,
                        eval.plane,
                    )?;
                    let name = int.source.clone();
                    super::coordinates::place(&input.placement(), &name, &mut int.mm, int.absent)?;
                    let ext = super::recording::read_external(external, &input.external_columns)?;
                    let period = partners::check(input, &int, &ext, &eval)?;
                    (
                        Data::Split {
                            internal: int,
                            external: ext,
                        },
                        Some(period),
                    )
                }
            };
            Ok(Prepared {
                opts: eval,
                source,
                data,
                period_s,
            })
        })
        .collect::<Vec<_>>()
        .into_iter()
        .collect::<Result<_, _>>()?;
    // Clock groups, in order of first appearance; single-file and two-system tests apart.
    let mut groups: Vec<(String, bool, Vec<usize>)> = Vec::new();
    for (i, (input, p)) in inputs.iter().zip(&prepared).enumerate() {
        let split = matches!(p.data, Data::Split { .. });
        match groups
            .iter_mut()
            .find(|g| g.0 == input.clock_group && g.1 == split)
        {
            Some(g) => g.2.push(i),
            None => groups.push((input.clock_group.clone(), split, vec![i])),
        }
    }
    let mut offsets: Vec<Option<TimeOffset>> = vec![None; inputs.len()];
    let mut clocks = Vec::new();
    for (clock, split, members) in &groups {
        let report = if *split {
            align_clock(clock, members, inputs, &prepared, &mut offsets)?
        } else {
            lag_of_clock(clock, members, inputs, &prepared, opts, &mut offsets)?
        };
        clocks.extend(report);
    }
    let evaluated: Vec<(CircleSeries, CircleResult)> = inputs
        .par_iter()
        .zip(&prepared)
        .zip(&offsets)
        .map(|((input, p), offset)| {
            let series = series_at(input, &p.data, offset.as_ref().map(|o| o.offset_ms * 1e-3))?;
            let result = evaluate(&series, &p.opts)?;
            Ok((series, result))
        })
        .collect::<Vec<_>>()
        .into_iter()
        .collect::<Result<_, MeasuredError>>()?;
    let mut tests = Vec::with_capacity(inputs.len());
    for (((input, p), offset), (series, mut result)) in
        inputs.iter().zip(prepared).zip(offsets).zip(evaluated)
    {
        let mut notes = condition_warnings(input, &result, p.source);
        if let Some(o) = offset
            .as_ref()
            .filter(|o| o.source == OffsetSource::Trajectory)
        {
            let (a, b) = result.plane.axes();
            notes.push(Warning::TestOffsetFromTrajectories {
                offset_ms: o.offset_ms,
                ab: Eij::new(a, b),
                ba: Eij::new(b, a),
            });
        }
        result.warnings.extend(notes.iter().cloned());
        tests.push(EvaluatedTest {
            input: input.clone(),
            series,
            result,
            radius_source: p.source,
            time_offset: offset,
            notes,
        });
    }
    let bidirectional = pairs(&tests);
    let warnings = clocks
        .iter()
        .filter(|c| !c.separable || !c.notes.is_empty())
        .flat_map(|c| {
            c.notes.iter().map(move |n| Named {
                name: Some(format!("clock {}", c.clock)),
                warning: n.clone(),
            })
        })
        .collect();
    Ok(Suite {
        tests,
        clocks,
        bidirectional,
        warnings,
    })
}

/// The series of a test at a clock offset (two-system tests: merged; single files: external
/// shifted, or as read without an offset).
pub(super) fn series_at(
    input: &TestInput,
    data: &Data,
    offset_s: Option<f64>,
) -> Result<CircleSeries, MeasuredError> {
    match (data, offset_s) {
        (Data::Single(s), None) => Ok(s.clone()),
        (Data::Single(s), Some(o)) => {
            let (int, ext) = split_series(s)?;
            Ok(clock::merge(input.name(), &int, &ext, o)?)
        }
        (Data::Split { internal, external }, o) => Ok(clock::merge(
            input.name(),
            internal,
            external,
            o.unwrap_or(0.0),
        )?),
    }
}

/// A single-file series as its two recordings on the same clock.
fn split_series(s: &CircleSeries) -> Result<(Recording, Recording), MeasuredError> {
    use crate::axes::Axis;
    let int = Axis::ALL.map(|a| s.int_mm(a).to_vec());
    let ext = Axis::ALL.map(|a| s.ext_mm(a).to_vec());
    Ok((
        Recording::new(s.source().to_string(), s.t_s().to_vec(), int)?,
        Recording::new(s.source().to_string(), s.t_s().to_vec(), ext)?,
    ))
}

/// Warnings from comparing a test's stated conditions with its data.
fn condition_warnings(input: &TestInput, r: &CircleResult, source: RadiusSource) -> Vec<Warning> {
    let mut w = Vec::new();
    if source == RadiusSource::InternalMean {
        w.push(Warning::NoSetRadius {
            mean_internal_radius_mm: r.radius_mm,
        });
    }
    if source == RadiusSource::Fallback {
        w.push(Warning::DefaultRadius {
            radius_mm: r.radius_mm,
            mean_internal_radius_mm: r.measured_radius_mm,
        });
    }
    if let Some(d) = input.test.direction {
        if d != r.direction {
            w.push(Warning::DirectionDisagrees {
                stated: d,
                measured: r.direction,
                plane: r.plane,
            });
        }
    }
    if let Some(feed) = input.test.feed_mm_min {
        let measured = r.freq_hz * std::f64::consts::TAU * r.radius_mm * 60.0;
        if (measured / feed - 1.0).abs() > 0.05 {
            w.push(Warning::FeedDisagrees {
                programmed_mm_min: feed,
                measured_mm_min: measured,
            });
        }
    }
    w
}

/// cw/ccw pairs of equal plane, position, radius and acceleration, and their G(b).
fn pairs(tests: &[EvaluatedTest]) -> Vec<Bidirectional> {
    let mut used = vec![false; tests.len()];
    let mut out = Vec::new();
    let same = |a: &EvaluatedTest, b: &EvaluatedTest| {
        let (ra, rb) = (&a.result, &b.result);
        ra.plane == rb.plane
            && a.input.test.position_mm == b.input.test.position_mm
            && a.input.clock_group == b.input.clock_group
            && (ra.radius_mm - rb.radius_mm).abs() <= 1e-9 * ra.radius_mm
            && ra.accel_m_s2.max(rb.accel_m_s2)
                <= PAIR_ACCEL_RATIO * ra.accel_m_s2.min(rb.accel_m_s2)
    };
    for i in 0..tests.len() {
        if used[i] || tests[i].result.direction != Direction::Cw {
            continue;
        }
        let partner = (0..tests.len()).find(|&j| {
            !used[j] && tests[j].result.direction == Direction::Ccw && same(&tests[i], &tests[j])
        });
        let Some(j) = partner else { continue };
        let path = |t: &EvaluatedTest, ext: bool| {
            let (a, b) = t.result.plane.axes();
            let cols = |ax| {
                let v = if ext {
                    t.series.ext_mm(ax)
                } else {
                    t.series.int_mm(ax)
                };
                v[t.result.steady.clone()].to_vec()
            };
            (cols(a), cols(b))
        };
        let g = |ext: bool| {
            let (p, q) = (path(&tests[i], ext), path(&tests[j], ext));
            iso230::bidirectional_deviation([(&p.0, &p.1), (&q.0, &q.1)])
        };
        if let (Some(internal_um), Some(external_um)) = (g(false), g(true)) {
            used[i] = true;
            used[j] = true;
            out.push(Bidirectional {
                tests: [i, j],
                internal_um,
                external_um,
            });
        }
    }
    out
}

impl EvaluatedTest {
    /// The test's JSON object: [`CircleResult::to_json`] plus `radius_source`, and where known
    /// `time_offset_ms` with `time_offset` (`std_err_ms`, `source`, `clock`, `alignment_ms`),
    /// `position_mm`, `note`, `machine` and `date`.
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::to_value(self.to_typed()).unwrap_or(serde_json::Value::Null)
    }

    /// The same as the typed [`TestJson`].
    pub fn to_typed(&self) -> TestJson {
        let mut circle = CircleJson::from(&self.result);
        circle.file = self.input.name().to_string();
        TestJson {
            circle,
            radius_source: self.radius_source.name().to_string(),
            time_offset_ms: self.time_offset.as_ref().map(|o| o.offset_ms),
            time_offset: self.time_offset.as_ref().map(|o| TimeOffsetJson {
                std_err_ms: o.std_err_ms,
                source: o.source.name().to_string(),
                clock: o.clock.clone(),
                alignment_ms: o.alignment_ms,
            }),
            position_mm: self.input.test.position_mm.clone(),
            note: self.input.test.note.clone(),
            machine: self.input.session.machine.clone(),
            date: self.input.session.date.clone(),
        }
    }
}

impl Suite {
    /// The evaluate JSON document (docs/commands.md): `tests`, and `bidirectional` (cw/ccw pairs
    /// with `files`, `plane`, `accel_m_s2`, `bidirectional_circular_deviation_um` internal and
    /// external), `clocks` and `warnings`.
    pub fn to_json_map(&self) -> serde_json::Map<String, serde_json::Value> {
        let mut doc = serde_json::Map::new();
        doc.insert(
            "tests".into(),
            self.tests.iter().map(EvaluatedTest::to_json).collect(),
        );
        let pairs: Vec<serde_json::Value> = self
            .bidirectional
            .iter()
            .map(|b| {
                let (cw, ccw) = (&self.tests[b.tests[0]], &self.tests[b.tests[1]]);
                serde_json::json!({
                    "files": [cw.input.name(), ccw.input.name()],
                    "plane": cw.result.plane.name(),
                    "accel_m_s2": 0.5 * (cw.result.accel_m_s2 + ccw.result.accel_m_s2),
                    "bidirectional_circular_deviation_um": {
                        "internal": b.internal_um,
                        "external": b.external_um,
                    },
                })
            })
            .collect();
        doc.insert("bidirectional".into(), pairs.into());
        doc.insert("clocks".into(), clocks_json(&self.clocks));
        doc.insert("warnings".into(), serde_json::json!(self.warnings));
        doc
    }
}
