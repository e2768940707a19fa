//! Clocks of a suite: two-system tests aligned on their trajectories and refined by the joint
//! clock-offset fit; single-file tests checked for an external lag (see [`crate::rtest::clock`]
//! and [`crate::rtest::clock_fit`]).

use super::{group_key, series_at, Data, Prepared, SuiteOptions};
use crate::measured::inputs::TestInput;
use crate::measured::MeasuredError;
use crate::rtest::clock;
use crate::rtest::clock_fit::{fit_offset, OffsetFit, OffsetTest};
use crate::rtest::error::{Location, RtestError};
use crate::rtest::normalise::{normalise, Normalised};
use crate::rtest::Warning;

/// How a test's clock offset was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OffsetSource {
    /// Given in `rtest.toml` (`time_offset_ms`).
    Given,
    /// Trajectory alignment, refined by the joint fit over the tests of its clock.
    JointFit,
    /// Trajectory alignment only: the tests cannot separate the offset from cross-talk.
    Trajectory,
}

impl OffsetSource {
    /// The JSON name: `rtest.toml`, `joint-fit`, `trajectory`.
    pub fn name(self) -> &'static str {
        match self {
            OffsetSource::Given => "rtest.toml",
            OffsetSource::JointFit => "joint-fit",
            OffsetSource::Trajectory => "trajectory",
        }
    }
}

/// The clock offset a test was evaluated with.
#[derive(Debug, Clone, PartialEq)]
pub struct TimeOffset {
    /// Internal clock minus external clock, ms.
    pub offset_ms: f64,
    /// Its standard error, ms, where fitted.
    pub std_err_ms: Option<f64>,
    /// How it was found.
    pub source: OffsetSource,
    /// The clock group it belongs to.
    pub clock: String,
    /// This test's own trajectory alignment, ms (two-system tests).
    pub alignment_ms: Option<f64>,
}

impl TimeOffset {
    /// An offset given in `rtest.toml`.
    fn given(offset_ms: f64, clock: &str) -> Self {
        TimeOffset {
            offset_ms,
            std_err_ms: None,
            source: OffsetSource::Given,
            clock: clock.to_string(),
            alignment_ms: None,
        }
    }
}

/// What was found about one clock (the tests sharing one offset).
#[derive(Debug, Clone, PartialEq)]
pub struct ClockReport {
    /// The group: a folder, or a folder and its `[[test]]` `clock`.
    pub clock: String,
    /// Names of its tests.
    pub tests: Vec<String>,
    /// Whether its tests are two-system recordings.
    pub two_systems: bool,
    /// The offset used, ms (single-file tests: the fitted lag, applied only with
    /// `fit_time_offset`).
    pub offset_ms: f64,
    /// Its standard error, ms, where fitted.
    pub std_err_ms: Option<f64>,
    /// Whether the tests separate the offset from antisymmetric cross-talk.
    pub separable: bool,
    /// Whether the offset was applied to the tests.
    pub applied: bool,
    /// The joint fit's χ² per degree of freedom, where fitted.
    pub chi2_per_dof: Option<f64>,
    /// Why (not) separable, and other remarks.
    pub notes: Vec<Warning>,
}

/// Trajectory alignments of one clock that differ by more than this are not one constant
/// offset, s (the cross-talk bias of an alignment stays well below: (E_ab − E_ba)·ω/2 is
/// 0.15 ms for 10 µm·s²/m at 30 rad/s).
const SAME_CLOCK_SPREAD_S: f64 = 2e-3;
/// An alignment whose next-best (a whole period away) misfit is not this many times worse is
/// ambiguous (a record without start or stop of the motion).
const UNIQUE_ALIGNMENT_RATIO: f64 = 3.0;

/// Two-system tests of one clock: aligned one by one on their trajectories, then (one constant
/// offset) refined by the joint fit where the tests separate it from cross-talk.
pub(super) fn align_clock(
    clock: &str,
    members: &[usize],
    inputs: &[TestInput],
    prepared: &[Prepared],
    offsets: &mut [Option<TimeOffset>],
) -> Result<Vec<ClockReport>, MeasuredError> {
    let mut aligned = Vec::new();
    for &i in members {
        let Data::Split { internal, external } = &prepared[i].data else {
            continue;
        };
        if let Some(o) = inputs[i].test.time_offset_ms {
            offsets[i] = Some(TimeOffset::given(o, clock));
            continue;
        }
        let Some(period) = prepared[i].period_s else {
            continue;
        };
        let a = clock::align(internal, external, period)?;
        if a.next_best_rms_um < UNIQUE_ALIGNMENT_RATIO * a.rms_um {
            return Err(RtestError::Pooling {
                at: Location::source(&inputs[i].name()),
                detail: format!(
                    "the clock offset is ambiguous by whole revolutions (the records hold no \
                     start or stop of the motion: misfit {:.2} µm at {:.3} ms, {:.2} µm a \
                     period away); give time_offset_ms in its [[test]] entry",
                    a.rms_um,
                    a.offset_s * 1e3,
                    a.next_best_rms_um
                ),
            }
            .into());
        }
        aligned.push((i, a.offset_s));
    }
    if aligned.is_empty() {
        return Ok(Vec::new());
    }
    let mut sorted: Vec<f64> = aligned.iter().map(|a| a.1).collect();
    sorted.sort_by(f64::total_cmp);
    let base = sorted[sorted.len() / 2];
    let spread = sorted[sorted.len() - 1] - sorted[0];
    let names = |set: &[(usize, f64)]| set.iter().map(|(i, _)| inputs[*i].name()).collect();
    let mut notes = Vec::new();
    let one_clock = spread <= SAME_CLOCK_SPREAD_S;
    let fit = if one_clock {
        let norms = aligned
            .iter()
            .map(|&(i, _)| -> Result<_, MeasuredError> {
                let s = series_at(&inputs[i], &prepared[i].data, Some(base))?;
                Ok(normalise(&s, &prepared[i].opts)?)
            })
            .collect::<Result<Vec<_>, _>>()?;
        joint_offset(clock, &aligned, inputs, &norms)?
    } else {
        notes.push(Warning::AlignmentsDiffer {
            spread_ms: spread * 1e3,
        });
        None
    };
    let separable = fit.as_ref().is_some_and(|f| f.separable);
    for &(i, own) in &aligned {
        let (offset_s, std_err, source) = match (&fit, one_clock) {
            (Some(f), _) if f.separable => (
                base + f.offset_s,
                Some(f.std_err_s * 1e3),
                OffsetSource::JointFit,
            ),
            (_, true) => (base, None, OffsetSource::Trajectory),
            (_, false) => (own, None, OffsetSource::Trajectory),
        };
        offsets[i] = Some(TimeOffset {
            offset_ms: offset_s * 1e3,
            std_err_ms: std_err,
            source,
            clock: clock.to_string(),
            alignment_ms: Some(own * 1e3),
        });
    }
    if let Some(f) = &fit {
        if !f.separable {
            notes.push(Warning::ClockOffsetFromTrajectories {
                offset_ms: base * 1e3,
                reason: f.reason.clone(),
            });
        }
    }
    Ok(vec![ClockReport {
        clock: clock.to_string(),
        tests: names(&aligned),
        two_systems: true,
        offset_ms: fit
            .as_ref()
            .filter(|f| f.separable)
            .map_or(base, |f| base + f.offset_s)
            * 1e3,
        std_err_ms: fit
            .as_ref()
            .filter(|f| f.separable)
            .map(|f| f.std_err_s * 1e3),
        separable,
        applied: true,
        chi2_per_dof: fit
            .as_ref()
            .map(|f| f.chi2_per_dof)
            .filter(|c| c.is_finite()),
        notes,
    }])
}

/// The joint offset fit over normalised tests of one clock.
fn joint_offset(
    clock: &str,
    members: &[(usize, f64)],
    inputs: &[TestInput],
    norms: &[Normalised],
) -> Result<Option<OffsetFit>, MeasuredError> {
    let keys: Vec<String> = members
        .iter()
        .zip(norms)
        .map(|((i, _), n)| group_key(&inputs[*i], n))
        .collect();
    let tests: Vec<OffsetTest> = norms
        .iter()
        .zip(&keys)
        .map(|(norm, group)| OffsetTest { norm, group })
        .collect();
    fit_offset(&tests)
        .ok_or_else(|| RtestError::Singular {
            at: Location::source(clock),
            detail: "the joint clock-offset fit has no unique solution".into(),
        })
        .map(Some)
        .map_err(MeasuredError::from)
}

/// Single-file tests of one clock (folder): the lag of the external readings, fitted jointly
/// where the tests separate it; applied with `fit_time_offset`, else reported where it is
/// significant. Known offsets (`time_offset_ms`) are applied as given.
pub(super) fn lag_of_clock(
    clock: &str,
    members: &[usize],
    inputs: &[TestInput],
    prepared: &[Prepared],
    opts: &SuiteOptions,
    offsets: &mut [Option<TimeOffset>],
) -> Result<Vec<ClockReport>, MeasuredError> {
    let mut free = Vec::new();
    for &i in members {
        match inputs[i].test.time_offset_ms {
            Some(o) => offsets[i] = Some(TimeOffset::given(o, clock)),
            None => free.push((i, 0.0)),
        }
    }
    if free.len() < 2 {
        return Ok(Vec::new());
    }
    let norms = free
        .iter()
        .map(|&(i, _)| match &prepared[i].data {
            Data::Single(s) => normalise(s, &prepared[i].opts),
            Data::Split { internal, external } => normalise(
                &clock::merge(inputs[i].name(), internal, external, 0.0)?,
                &prepared[i].opts,
            ),
        })
        .collect::<Result<Vec<_>, _>>()?;
    let Some(fit) = joint_offset(clock, &free, inputs, &norms)? else {
        return Ok(Vec::new());
    };
    if !fit.separable {
        return Ok(Vec::new());
    }
    let significant = fit.offset_s.abs() > 3.0 * fit.std_err_s && fit.offset_s.abs() > 1e-6;
    let mut notes = Vec::new();
    if opts.fit_time_offset {
        for &(i, _) in &free {
            offsets[i] = Some(TimeOffset {
                offset_ms: fit.offset_s * 1e3,
                std_err_ms: Some(fit.std_err_s * 1e3),
                source: OffsetSource::JointFit,
                clock: clock.to_string(),
                alignment_ms: None,
            });
        }
    } else if significant {
        notes.push(Warning::ClockOffsetNotCorrected {
            offset_ms: fit.offset_s.abs() * 1e3,
            std_err_ms: fit.std_err_s * 1e3,
            external_late: fit.offset_s < 0.0,
            reason: fit.reason.clone(),
        });
    }
    Ok(vec![ClockReport {
        clock: clock.to_string(),
        tests: free.iter().map(|(i, _)| inputs[*i].name()).collect(),
        two_systems: false,
        offset_ms: fit.offset_s * 1e3,
        std_err_ms: Some(fit.std_err_s * 1e3),
        separable: true,
        applied: opts.fit_time_offset,
        chi2_per_dof: Some(fit.chi2_per_dof).filter(|c| c.is_finite()),
        notes,
    }])
}

/// The clock reports as JSON.
pub fn clocks_json(clocks: &[ClockReport]) -> serde_json::Value {
    serde_json::Value::Array(
        clocks
            .iter()
            .map(|c| {
                serde_json::json!({
                    "clock": c.clock,
                    "tests": c.tests,
                    "two_systems": c.two_systems,
                    "time_offset_ms": c.offset_ms,
                    "std_err_ms": c.std_err_ms,
                    "separable": c.separable,
                    "applied": c.applied,
                    "chi2_per_dof": c.chi2_per_dof,
                    "notes": c.notes,
                })
            })
            .collect(),
    )
}
