//! Internal readings in absolute machine coordinates (`internal_coordinates = "absolute"` in
//! `rtest.toml`): a controller trace records where the axes are, not where they are relative to
//! the circle centre. With the key, the centre `position_mm` is subtracted from the internal
//! readings as they are read; without it, readings that lie far from the centre are refused with
//! a message that names the key (evaluated as they are, they would give a clock offset that
//! means nothing and an external − internal deviation of the whole machine position).
//!
//! "Far" is more than the R-Test range ([`PROBE_RANGE_MM`], 3 mm) from the centre on some axis,
//! for the mean of the recording: a circle about its centre (radius ≤ 3 mm), with its ramps and
//! rests, has its mean within the radius of the centre. A recording that spans more than twice
//! that range on some axis is no circle test in mm (µm read as mm): it is left to the
//! evaluation's unit checks, which say so.

use std::path::Path;

use super::error::MeasuredError;
use crate::rtest::checks::PROBE_RANGE_MM;
use crate::text::num;

/// The circle centre of a test as x, y, z, mm (missing trailing axes 0).
fn centre(position_mm: Option<&[f64]>) -> Option<[f64; 3]> {
    position_mm.map(|p| {
        let mut xyz = [0.0; 3];
        for (dst, src) in xyz.iter_mut().zip(p) {
            *dst = *src;
        }
        xyz
    })
}

/// `[x, y, z]` in mm, for messages.
fn point(p: &[f64; 3]) -> String {
    format!("[{}, {}, {}] mm", num3(p[0]), num3(p[1]), num3(p[2]))
}

fn num3(v: f64) -> String {
    num((v * 1e3).round() / 1e3)
}

/// Whether `a` and `b` lie within the R-Test range of each other on every axis.
fn near(a: &[f64; 3], b: &[f64; 3]) -> bool {
    a.iter()
        .zip(b)
        .all(|(x, y)| (x - y).abs() <= PROBE_RANGE_MM)
}

/// How a test's internal readings are to be placed: whether they are absolute, its circle
/// centre (`position_mm`) and the `rtest.toml` that says so.
pub(crate) struct Placement<'a> {
    /// `internal_coordinates = "absolute"`.
    pub absolute: bool,
    /// The circle centre, mm.
    pub position_mm: Option<&'a [f64]>,
    /// The conditions file, for messages.
    pub conditions: Option<&'a Path>,
}

/// Makes the internal readings `int` (x, y, z, mm) of the file `name` relative to the circle
/// centre: subtracts `position_mm` where the internal coordinates are absolute, and refuses
/// readings that do not lie about the centre (see the module docs). `absent` axes (a trace of
/// the plane's two axes) hold 0, the axis at the centre, and are left alone.
pub(crate) fn place(
    how: &Placement,
    name: &str,
    int: &mut [Vec<f64>; 3],
    absent: [bool; 3],
) -> Result<(), MeasuredError> {
    let n = int[0].len();
    if n == 0 || int.iter().any(|c| c.len() != n) {
        return Ok(()); // the series' own checks name what is wrong
    }
    let mut mean = int.each_ref().map(|c| c.iter().sum::<f64>() / n as f64);
    if !mean.iter().all(|m| m.is_finite()) {
        return Ok(());
    }
    // A recording wider than a circle in the R-Test's range is not a circle test in mm at all
    // (µm read as mm, a wrong column): the evaluation's unit checks name that.
    let wide = int.iter().any(|c| {
        let (lo, hi) = c
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(*v), hi.max(*v))
            });
        hi - lo > 2.0 * PROBE_RANGE_MM
    });
    if wide {
        return Ok(());
    }
    let zero = [0.0; 3];
    let conditions = how
        .conditions
        .map_or("rtest.toml".to_string(), |f| f.display().to_string());
    let bad = |message: String| MeasuredError::Conditions {
        file: name.to_string(),
        key: "internal_coordinates".into(),
        message,
    };
    let centre = centre(how.position_mm).map(|mut c| {
        // An absent axis stands at the centre in either coordinates.
        for k in 0..3 {
            if absent[k] {
                c[k] = 0.0;
                mean[k] = 0.0;
            }
        }
        c
    });
    match (how.absolute, centre) {
        (true, Some(c)) => {
            let relative = [mean[0] - c[0], mean[1] - c[1], mean[2] - c[2]];
            if !near(&relative, &zero) {
                return Err(bad(format!(
                    "\"absolute\": the internal readings lie about {}, {} away from the circle \
                     centre position_mm = {} of {conditions} (more than the R-Test range of \
                     {} mm): is position_mm where this circle was run, and are the readings \
                     absolute?",
                    point(&mean),
                    point(&relative),
                    point(&c),
                    num(PROBE_RANGE_MM)
                )));
            }
            for (col, c) in int.iter_mut().zip(c) {
                col.iter_mut().for_each(|v| *v -= c);
            }
            Ok(())
        }
        // Refused when the conditions are resolved (inputs.rs); nothing to subtract.
        (true, None) => Ok(()),
        (false, _) if near(&mean, &zero) => Ok(()),
        (false, Some(c)) if near(&mean, &c) => Err(bad(format!(
            "the internal readings lie about {}, at the circle centre position_mm = {} and not \
             about 0: they are absolute machine coordinates (a controller trace); write \
             internal_coordinates = \"absolute\" in {conditions} (folder or [[test]]) to \
             subtract the centre",
            point(&mean),
            point(&c)
        ))),
        (false, c) => Err(bad(format!(
            "the internal readings lie about {}, not about the circle centre at 0 (more than \
             the R-Test range of {} mm away{}): readings relative to the centre are expected; \
             for absolute machine coordinates write internal_coordinates = \"absolute\" and the \
             circle centre as position_mm in {conditions}",
            point(&mean),
            num(PROBE_RANGE_MM),
            c.map_or(String::new(), |c| format!(
                "; position_mm = {} is not it either",
                point(&c)
            ))
        ))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A circle of radius 2 mm about `c` in x, y, sampled at 100 instants.
    fn xy_circle(c: [f64; 2]) -> [Vec<f64>; 3] {
        let phi = (0..100).map(|k| k as f64 * std::f64::consts::TAU / 100.0);
        [
            phi.clone().map(|p| c[0] + 2.0 * p.cos()).collect(),
            phi.map(|p| c[1] + 2.0 * p.sin()).collect(),
            vec![0.0; 100],
        ]
    }

    #[test]
    fn an_absent_axis_stays_at_the_centre_in_absolute_coordinates() {
        let centre = [150.0, -100.0, -200.0];
        let how = Placement {
            absolute: true,
            position_mm: Some(&centre),
            conditions: None,
        };
        // A trace of X and Y only: Z is absent and holds 0 (the axis at the centre).
        let mut int = xy_circle([150.0, -100.0]);
        place(&how, "xy.sco", &mut int, [false, false, true]).unwrap();
        // x, y relative to the centre: a circle of radius 2 about 0; z untouched (not +200).
        assert!(int.iter().all(|a| a.len() == 100));
        for ((x, y), z) in int[0].iter().zip(&int[1]).zip(&int[2]).take(100) {
            let r = x.hypot(*y);
            assert!((r - 2.0).abs() < 1e-12, "radius {r}");
            assert_eq!(*z, 0.0);
        }
        // Without the absent mark the same readings lie 200 mm from the centre in z: refused.
        let mut int = xy_circle([150.0, -100.0]);
        assert!(place(&how, "xy.sco", &mut int, [false; 3]).is_err());
    }
}
