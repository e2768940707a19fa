//! Whether the two recordings of a two-system test are of one circle: the internal and the
//! external recording each give a plane, a sense of rotation and a circle frequency, which must
//! agree (files paired wrongly — by a `[[pairing]]` in recording order, or a `[[test]]` entry
//! with a typo — are refused before their clocks are aligned).

use crate::measured::inputs::TestInput;
use crate::measured::MeasuredError;
use crate::rtest::clock::Recording;
use crate::rtest::error::{Location, RtestError};
use crate::rtest::normalise::{normalise, Normalised};
use crate::rtest::{CircleSeries, EvalOptions};

/// Circle frequencies of one test's two recordings differ by less than this share (the
/// clocks' rates differ by ppm).
const SAME_FREQUENCY: f64 = 0.02;

/// One recording alone, as a series, normalised (its circle, plane and speed).
fn circle_of(r: &Recording, opts: &EvalOptions) -> Result<Normalised, RtestError> {
    let s = CircleSeries::new(r.source.clone(), r.t_s.clone(), r.mm.clone(), r.mm.clone())?;
    normalise(&s, opts)
}

/// The period of the internal recording's circle, s, after checking that the external
/// recording shows the same plane, direction and frequency (where its circle can be found at
/// all: a dead probe channel is left to the evaluation's own checks, which name it).
pub(super) fn check(
    input: &TestInput,
    internal: &Recording,
    external: &Recording,
    opts: &EvalOptions,
) -> Result<f64, MeasuredError> {
    let int = circle_of(internal, opts).map_err(|e| match e {
        RtestError::TooShort { detail, .. } => RtestError::TooShort {
            at: Location::source(&input.name()),
            detail,
        },
        e => e,
    })?;
    let period = std::f64::consts::TAU / int.omega_rad_s.abs();
    let free = EvalOptions {
        plane: opts.plane,
        radius_mm: None,
    };
    let Ok(ext) = circle_of(external, &free) else {
        return Ok(period);
    };
    let describe = |n: &Normalised| {
        format!(
            "{} {} circle at {:.3} Hz",
            n.plane,
            if n.omega_rad_s > 0.0 { "ccw" } else { "cw" },
            n.omega_rad_s.abs() / std::f64::consts::TAU
        )
    };
    let same_plane = opts.plane.is_some() || ext.plane == int.plane;
    let same_sense = (ext.omega_rad_s > 0.0) == (int.omega_rad_s > 0.0);
    let same_speed = (ext.omega_rad_s.abs() / int.omega_rad_s.abs() - 1.0).abs() <= SAME_FREQUENCY;
    if same_plane && same_sense && same_speed {
        return Ok(period);
    }
    let how = match (&input.paired, &input.conditions_file) {
        (Some(p), Some(f)) => format!(
            "paired {} by [[pairing]] #{} of {}: check which files belong together",
            p.on.describe(),
            p.pairing,
            f.display()
        ),
        _ => "check that the two files belong to one test".to_string(),
    };
    Err(MeasuredError::NotOnePair {
        test: input.name(),
        message: format!(
            "the internal recording is a {}, the external one a {}; {how}",
            describe(&int),
            describe(&ext)
        ),
    })
}
