//! The catalogue of named terms: which design columns each term owns, its unit and how its
//! value is read from the columns' coefficients (one coefficient, the mean of two reversal
//! points, or the amplitude and phase of a cos/sin pair).

use super::basis::{Crossing, InPlane, Normal};
use super::DiagnosisOptions;
use crate::axes::{Axis, Plane};

/// Micrometres.
pub(crate) const UM: &str = "um";
/// Micrometres per metre (µrad).
pub(crate) const UM_PER_M: &str = "um_per_m";
/// Milliseconds.
pub(crate) const MS: &str = "ms";

/// Terms of the tangential reference: fitted in every source, reported only for the structure.
/// The nominal angle θ(t) is fitted to the internal path, so that a rotation or a speed of
/// the internal path (and hence of the TCP) is zero by definition; what the fit still finds
/// there is the straight line's bias (a harmonic of the phase tilts a line through it), not
/// an error of the machine. In external − internal they are errors: a rotation of the TCP
/// against the scales, a clock of the R-Test running at another rate.
pub(crate) const REFERENCE: [&str; 2] = ["rotation", "feed_deviation"];

/// How a term's value follows from its columns' coefficients.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Combine {
    /// The coefficient of one column.
    One,
    /// The mean of the two reversal points' coefficients (each reported on its own too).
    Mean([Crossing; 2]),
    /// √(c² + s²) of a cos/sin pair, phase atan2(s, c).
    Amplitude,
}

/// A family of terms the fit may drop, last first, when the design is rank deficient.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) enum Family {
    /// Always fitted.
    Core,
    /// Lateral play.
    LateralPlay,
    /// Straightness.
    Straightness,
    /// Reversal spikes.
    Spike,
    /// Cyclic error.
    Cyclic,
}

/// One named term of the design.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Spec {
    /// docs/commands.md name, e.g. `backlash_x`.
    pub name: String,
    /// Unit of the value.
    pub unit: &'static str,
    /// The machine axis it belongs to, if one.
    pub axis: Option<Axis>,
    /// Indices of its columns in the design.
    pub columns: Vec<usize>,
    /// How the value is read.
    pub combine: Combine,
    /// Its family.
    pub family: Family,
}

/// The column of a term at one reversal point.
type AtReversal = fn(Crossing) -> InPlane;

/// The in-plane columns and terms of `plane` under `opts`, families up to `keep` included.
pub(crate) fn in_plane(
    plane: Plane,
    opts: &DiagnosisOptions,
    keep: Family,
) -> (Vec<InPlane>, Vec<Spec>) {
    let (a, b) = plane.axes();
    let axes = [a, b];
    let mut cols = Vec::new();
    let mut specs = Vec::new();
    let mut add = |name: String,
                   unit: &'static str,
                   axis: Option<Axis>,
                   new: Vec<InPlane>,
                   combine: Combine,
                   family: Family| {
        if family > keep {
            return;
        }
        let first = cols.len();
        cols.extend(new.iter().copied());
        specs.push(Spec {
            name,
            unit,
            axis,
            columns: (first..cols.len()).collect(),
            combine,
            family,
        });
    };
    use Combine::One;
    use Family::*;
    let single = [
        ("centre_offset_a", UM, Some(a), InPlane::CentreA),
        ("centre_offset_b", UM, Some(b), InPlane::CentreB),
        ("radius_deviation", UM, None, InPlane::Radius),
        ("rotation", UM_PER_M, None, InPlane::Rotation),
        ("feed_deviation", UM_PER_M, None, InPlane::FeedDeviation),
        ("scale_mismatch", UM, None, InPlane::ScaleMismatch),
        ("squareness", UM_PER_M, None, InPlane::Squareness),
    ];
    for (name, unit, axis, col) in single {
        add(name.into(), unit, axis, vec![col], One, Core);
    }
    // Per in-plane axis: terms at its two reversal points, and terms of one column.
    let at_reversals: [(&str, AtReversal, Family); 2] = [
        ("backlash", InPlane::Backlash, Core),
        ("reversal_spike", InPlane::Spike, Spike),
    ];
    let per_axis: [(&str, [InPlane; 2], Family); 2] = [
        (
            "lateral_play",
            [InPlane::LateralPlay(0), InPlane::LateralPlay(1)],
            LateralPlay,
        ),
        (
            "straightness",
            [InPlane::StraightnessA, InPlane::StraightnessB],
            Straightness,
        ),
    ];
    for (i, ax) in axes.into_iter().enumerate() {
        let pair = [Crossing::ALL[2 * i], Crossing::ALL[2 * i + 1]];
        for (prefix, column, family) in at_reversals {
            let cols = pair.iter().map(|&x| column(x)).collect();
            add(
                format!("{prefix}_{ax}"),
                UM,
                Some(ax),
                cols,
                Combine::Mean(pair),
                family,
            );
        }
        for (prefix, columns, family) in per_axis {
            add(
                format!("{prefix}_{ax}"),
                UM,
                Some(ax),
                vec![columns[i]],
                One,
                family,
            );
        }
    }
    if opts.cyclic_pitch_mm.is_some() {
        for (i, ax) in axes.into_iter().enumerate() {
            for h in 1..=opts.cyclic_harmonics {
                let name = if h == 1 {
                    format!("cyclic_{ax}")
                } else {
                    format!("cyclic_{ax}_h{h}")
                };
                let pair = vec![InPlane::Cyclic(i, h, false), InPlane::Cyclic(i, h, true)];
                add(name, UM, Some(ax), pair, Combine::Amplitude, Cyclic);
            }
        }
    }
    (cols, specs)
}

/// The out-of-plane columns and terms of `plane`.
pub(crate) fn normal(plane: Plane) -> (Vec<Normal>, Vec<Spec>) {
    let (a, b) = plane.axes();
    let k = plane.normal();
    let cols = vec![
        Normal::Offset,
        Normal::Tilt(false),
        Normal::Tilt(true),
        Normal::Saddle(false),
        Normal::Saddle(true),
        Normal::Play(0),
        Normal::Play(1),
    ];
    let spec = |name: String, unit, axis, columns: Vec<usize>, combine| Spec {
        name,
        unit,
        axis,
        columns,
        combine,
        family: Family::Core,
    };
    let specs = vec![
        spec(
            "out_of_plane_offset".into(),
            UM,
            Some(k),
            vec![0],
            Combine::One,
        ),
        spec(
            "out_of_plane_tilt".into(),
            UM_PER_M,
            None,
            vec![1, 2],
            Combine::Amplitude,
        ),
        spec(
            "out_of_plane_saddle".into(),
            UM,
            None,
            vec![3, 4],
            Combine::Amplitude,
        ),
        spec(
            format!("out_of_plane_play_{a}"),
            UM,
            Some(a),
            vec![5],
            Combine::One,
        ),
        spec(
            format!("out_of_plane_play_{b}"),
            UM,
            Some(b),
            vec![6],
            Combine::One,
        ),
    ];
    (cols, specs)
}
