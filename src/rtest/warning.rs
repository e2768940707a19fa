//! What an evaluation found doubtful, as data: the evaluation's routes that disagree, a test's
//! stated conditions at odds with its data, clocks that cannot be aligned. Rendered to text only
//! where it is shown (`Display`: the command line, the report page, the JSON's `warnings`), so
//! that a caller — the command line adding the option that answers a warning — matches the
//! variant, never the words.

use std::fmt;

use crate::axes::{Direction, Eij, Estimate, Plane};

/// A warning of the evaluation of R-Test circle tests.
#[derive(Debug, Clone, PartialEq)]
pub enum Warning {
    /// The paper's plane fit differs from the joint fit by more than noise.
    PlaneFitDiffers {
        /// The cross-talk parameter.
        eij: Eij,
        /// Its plane-fit value, µm·s²/m.
        plane_fit: f64,
        /// The joint fit's estimate, µm·s²/m.
        joint: Estimate,
    },
    /// The paper's ellipse fit failed: a path is no ellipse.
    EllipseFitFailed,
    /// The paper's ellipse fit differs from what the joint fit's model gives on that route.
    EllipseFitDiffers {
        /// The in-talk parameter.
        eij: Eij,
        /// Its ellipse-fit value, µm·s²/m.
        ellipse_fit: f64,
        /// The value the route gives on the joint fit's model, µm·s²/m.
        expected: f64,
        /// The joint fit's standard error, µm·s²/m.
        std_err: f64,
    },
    /// A pooled evaluation's cw and ccw tests give different EIJ beyond noise.
    CwCcwDiffer {
        /// The parameter.
        eij: Eij,
        /// From the cw tests, µm·s²/m.
        cw: f64,
        /// From the ccw tests, µm·s²/m.
        ccw: f64,
        /// Their difference in combined standard errors.
        z: f64,
    },
    /// A pooled evaluation could not compare cw and ccw.
    CwCcwNotChecked,
    /// No set radius anywhere: the EIJ are per the acceleration of the mean internal radius.
    NoSetRadius {
        /// The mean internal radius used, mm.
        mean_internal_radius_mm: f64,
    },
    /// No set radius in the test's conditions: the identification's default radius is taken.
    DefaultRadius {
        /// The radius taken, mm.
        radius_mm: f64,
        /// The data's mean internal radius, mm.
        mean_internal_radius_mm: f64,
    },
    /// `rtest.toml` states one direction, the data turn the other way.
    DirectionDisagrees {
        /// As stated.
        stated: Direction,
        /// As the data turn.
        measured: Direction,
        /// The circle plane.
        plane: Plane,
    },
    /// The steady circle runs at another feed than the programmed one.
    FeedDisagrees {
        /// As programmed, mm/min.
        programmed_mm_min: f64,
        /// As measured, mm/min.
        measured_mm_min: f64,
    },
    /// A test's clock offset comes from the trajectories alone, so its antisymmetric in-plane
    /// cross-talk `ab − ba` is not measured.
    TestOffsetFromTrajectories {
        /// The offset applied, ms.
        offset_ms: f64,
        /// E_ab.
        ab: Eij,
        /// E_ba.
        ba: Eij,
    },
    /// The trajectory alignments of one clock's tests differ: no constant offset.
    AlignmentsDiffer {
        /// Their spread, ms.
        spread_ms: f64,
    },
    /// A clock's offset comes from the trajectories alone.
    ClockOffsetFromTrajectories {
        /// The offset, ms.
        offset_ms: f64,
        /// Why its tests cannot separate it from cross-talk.
        reason: String,
    },
    /// A clock offset between the systems was found and not corrected.
    ClockOffsetNotCorrected {
        /// Its size, ms.
        offset_ms: f64,
        /// Its standard error, ms.
        std_err_ms: f64,
        /// The external readings are late (else early) against the internal ones.
        external_late: bool,
        /// Which tests separate it.
        reason: String,
    },
    /// With the clock offset fitted: tests whose offset is not separable from cross-talk.
    ClockOffsetNotSeparable {
        /// Their names.
        tests: Vec<String>,
    },
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Warning::PlaneFitDiffers {
                eij,
                plane_fit,
                joint,
            } => write!(
                f,
                "plane fit {eij} = {plane_fit:.4} differs from the joint fit {:.4} ± {:.4} µm·s²/m",
                joint.value, joint.std_err
            ),
            Warning::EllipseFitFailed => {
                f.write_str("ellipse fit failed: a path is not an ellipse")
            }
            Warning::EllipseFitDiffers {
                eij,
                ellipse_fit,
                expected,
                std_err,
            } => write!(
                f,
                "ellipse fit {eij} = {ellipse_fit:.4} differs from {expected:.4} ± {std_err:.4} \
                 µm·s²/m expected from the joint fit"
            ),
            Warning::CwCcwDiffer { eij, cw, ccw, z } => write!(
                f,
                "{eij}: cw {cw:.4} and ccw {ccw:.4} µm·s²/m differ by {z:.1} combined standard \
                 errors"
            ),
            Warning::CwCcwNotChecked => f.write_str(
                "cw/ccw consistency not checked: each direction needs tests at two or more \
                 accelerations",
            ),
            Warning::NoSetRadius {
                mean_internal_radius_mm,
            } => write!(
                f,
                "no set radius given (rtest.toml radius_mm, or a set radius with the evaluation's \
                 options): EIJ are per the acceleration of the mean internal radius \
                 {mean_internal_radius_mm:.4} mm, not per set acceleration"
            ),
            Warning::DefaultRadius {
                radius_mm,
                mean_internal_radius_mm,
            } => write!(
                f,
                "no set radius in the test's conditions (rtest.toml radius_mm or [[test]]): the \
                 identification's default radius {radius_mm:.4} mm (its settings' radius_mm, 2 mm \
                 unless set) is taken as the set radius; the data's mean internal radius is \
                 {mean_internal_radius_mm:.4} mm"
            ),
            Warning::DirectionDisagrees {
                stated,
                measured,
                plane,
            } => write!(
                f,
                "rtest.toml says {stated}, the data turn {measured} (docs/commands.md: ccw is ω > 0 in \
                 a = r cos ωt, b = r sin ωt of plane {plane})"
            ),
            Warning::FeedDisagrees {
                programmed_mm_min,
                measured_mm_min,
            } => write!(
                f,
                "programmed feed {programmed_mm_min} mm/min, the steady circle runs at \
                 {measured_mm_min:.1} mm/min (override, or the machine's limits)"
            ),
            Warning::TestOffsetFromTrajectories { offset_ms, ab, ba } => write!(
                f,
                "clock offset {offset_ms:.4} ms from the trajectories only (its clock's tests \
                 cannot separate it from cross-talk): {ab} − {ba} is not measured"
            ),
            Warning::AlignmentsDiffer { spread_ms } => write!(
                f,
                "the trajectory alignments of its tests differ by {spread_ms:.3} ms: not one \
                 constant offset (clocks restarted or drifting), each test keeps its own, which \
                 cannot tell a clock offset from antisymmetric cross-talk"
            ),
            Warning::ClockOffsetFromTrajectories { offset_ms, reason } => write!(
                f,
                "offset {offset_ms:.4} ms from the trajectories only: {reason}; the antisymmetric \
                 in-plane cross-talk (e.g. EXZ − EZX) of these tests is not measured (an offset \
                 error δ shifts it by 2·10⁶·δ/ω µm·s²/m)"
            ),
            Warning::ClockOffsetNotCorrected {
                offset_ms,
                std_err_ms,
                external_late,
                reason,
            } => write!(
                f,
                "the external readings are {offset_ms:.4} ± {std_err_ms:.4} ms {} the internal \
                 ones ({reason}); not corrected (give --fit-time-offset, or time_offset_ms in \
                 rtest.toml): the antisymmetric in-plane cross-talk of these tests carries it",
                if *external_late {
                    "late against"
                } else {
                    "early against"
                }
            ),
            Warning::ClockOffsetNotSeparable { tests } => write!(
                f,
                "the clock offset between scales and R-Test is not separable from cross-talk for \
                 {} test(s) ({}{}): a probe-logger lag there would pass as antisymmetric in-plane \
                 cross-talk (separable with cw and ccw at one acceleration, or three circle \
                 speeds, per folder)",
                tests.len(),
                tests.iter().take(3).cloned().collect::<Vec<_>>().join(", "),
                if tests.len() > 3 { ", …" } else { "" }
            ),
        }
    }
}

impl serde::Serialize for Warning {
    /// As its text (the JSON's `warnings` are sentences).
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

/// A warning about one test or clock, named: `<name>: <warning>`.
#[derive(Debug, Clone, PartialEq)]
pub struct Named {
    /// The test's name or `clock <group>`; `None` for a warning about several.
    pub name: Option<String>,
    /// The warning.
    pub warning: Warning,
}

impl fmt::Display for Named {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.name {
            Some(name) => write!(f, "{name}: {}", self.warning),
            None => self.warning.fmt(f),
        }
    }
}

impl serde::Serialize for Named {
    /// As its text.
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}
