//! The JSON of one evaluated circle test (`eij evaluate --json`, docs/commands.md), as one serde type
//! that writes and reads it: [`CircleJson`]. The keys are docs/commands.md's (`file`, `plane`,
//! `direction`, `radius_mm`, `accel_m_s2`, `freq_hz`, `eij_um_s2_per_m`, `std_err_um_s2_per_m`,
//! `rms_residual_um`) and eij's own additions documented in docs/measurement-files.md.

use crate::axes::EijMap;
use crate::rtest::iso230::{CircleFigures, PathFigures};
use crate::rtest::CircleResult;
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::collections::BTreeMap;

/// EIJ (or their standard errors) keyed by name (`EZZ`, …), µm·s²/m.
pub(crate) type EijByName = BTreeMap<String, f64>;

fn by_name(map: &EijMap) -> EijByName {
    map.iter().map(|(k, v)| (k.name(), *v)).collect()
}

/// The evaluation of one circle test as written by `eij evaluate --json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CircleJson {
    /// File path or in-memory name.
    pub file: String,
    /// `xy`, `yz` or `zx`.
    pub plane: String,
    /// `cw` or `ccw`.
    pub direction: String,
    /// Radius used for the set points, mm.
    pub radius_mm: f64,
    /// Set acceleration r ω², m/s².
    pub accel_m_s2: f64,
    /// Circle frequency, Hz.
    pub freq_hz: f64,
    /// The six EIJ of the plane from the joint fit.
    pub eij_um_s2_per_m: EijByName,
    /// Their standard errors.
    pub std_err_um_s2_per_m: EijByName,
    /// Residual RMS of the joint fit, µm.
    pub rms_residual_um: f64,
    /// Mean internal radius over the steady revolutions, mm.
    pub measured_radius_mm: f64,
    /// Constant deviations per axis (`x`, `y`, `z`), µm.
    pub offsets_um: BTreeMap<String, f64>,
    /// Steady whole revolutions used.
    pub revolutions: usize,
    /// Samples used.
    pub samples_used: usize,
    /// The paper's plane-fit route to the cross-talk.
    pub plane_fit: PlaneFitJson,
    /// The paper's ellipse route to the in-talk (`null` where a path is no ellipse).
    pub ellipse_fit: Option<EllipseJson>,
    /// ISO 230-4 circular deviation of the internal and external path, µm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub circular_deviation_um: Option<InternalExternal>,
    /// ISO 230-4 figures of both paths.
    #[serde(default, rename = "iso230_4", skip_serializing_if = "Option::is_none")]
    pub iso230_4: Option<CircleFigures>,
    /// Disagreements between the evaluation routes beyond noise.
    pub warnings: Vec<String>,
}

/// The plane-fit route's EIJ and standard errors.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlaneFitJson {
    /// E_ka, E_kb.
    pub eij_um_s2_per_m: EijByName,
    /// Their standard errors.
    pub std_err_um_s2_per_m: EijByName,
}

/// The ellipse route's in-talk and the ellipses' half widths.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EllipseJson {
    /// E_aa, E_bb.
    pub eij_um_s2_per_m: EijByName,
    /// Half widths of the internal path's ellipse, mm.
    pub half_width_int_mm: [f64; 2],
    /// Half widths of the external path's ellipse, mm.
    pub half_width_ext_mm: [f64; 2],
    /// The in-talk the joint fit predicts for the ellipse route.
    pub predicted_from_joint_um_s2_per_m: EijByName,
}

/// One figure of the internal and the external path.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct InternalExternal {
    /// Internal (the axes' readings).
    pub internal: f64,
    /// External (the R-Test).
    pub external: f64,
}

impl From<&CircleResult> for CircleJson {
    fn from(r: &CircleResult) -> Self {
        let path = |p: &PathFigures| p.circular_deviation_um;
        CircleJson {
            file: r.source.clone(),
            plane: r.plane.name().to_string(),
            direction: r.direction.name().to_string(),
            radius_mm: r.radius_mm,
            accel_m_s2: r.accel_m_s2,
            freq_hz: r.freq_hz,
            eij_um_s2_per_m: by_name(&r.eij.value_map()),
            std_err_um_s2_per_m: by_name(&r.eij.std_err_map()),
            rms_residual_um: r.rms_residual_um,
            measured_radius_mm: r.measured_radius_mm,
            offsets_um: r
                .offsets_um
                .iter()
                .map(|(k, v)| (k.name().to_string(), *v))
                .collect(),
            revolutions: r.revolutions,
            samples_used: r.samples_used,
            plane_fit: PlaneFitJson {
                eij_um_s2_per_m: by_name(&r.plane_fit.value_map()),
                std_err_um_s2_per_m: by_name(&r.plane_fit.std_err_map()),
            },
            ellipse_fit: r.ellipse_fit.as_ref().map(|e| EllipseJson {
                eij_um_s2_per_m: by_name(&e.eij),
                half_width_int_mm: e.half_width_int_mm,
                half_width_ext_mm: e.half_width_ext_mm,
                predicted_from_joint_um_s2_per_m: by_name(&e.predicted_from_joint),
            }),
            circular_deviation_um: r.iso230.as_ref().map(|iso| InternalExternal {
                internal: path(&iso.internal),
                external: path(&iso.external),
            }),
            iso230_4: r.iso230,
            warnings: r.warnings.iter().map(ToString::to_string).collect(),
        }
    }
}

/// One test of `eij evaluate --json`'s `tests` array: the circle's evaluation plus where its
/// conditions came from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TestJson {
    /// The evaluation.
    #[serde(flatten)]
    pub circle: CircleJson,
    /// Where the set radius came from: `command-line`, `rtest.toml`, `default`, `internal-mean`.
    pub radius_source: String,
    /// Offset applied to the external clock, ms (recordings aligned in time).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_offset_ms: Option<f64>,
    /// How that offset was found.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_offset: Option<TimeOffsetJson>,
    /// Circle centre, mm, where the conditions give it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub position_mm: Option<Vec<f64>>,
    /// The conditions' note.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
    /// The machine, where `rtest.toml` names it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub machine: Option<String>,
    /// Date of the measurement, where `rtest.toml` gives it (ISO 8601).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub date: Option<String>,
}

/// How a clock offset was found.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TimeOffsetJson {
    /// Standard error, ms (`null` where the offset was given).
    pub std_err_ms: Option<f64>,
    /// `fitted`, `given`, …
    pub source: String,
    /// The clock it belongs to.
    pub clock: String,
    /// Coarse alignment of the two recordings, ms.
    pub alignment_ms: Option<f64>,
}

impl CircleResult {
    /// The docs/commands.md JSON object of one test (`file`, `plane`, `direction`, `radius_mm`,
    /// `accel_m_s2`, `freq_hz`, `eij_um_s2_per_m`, `std_err_um_s2_per_m`, `rms_residual_um`)
    /// plus `measured_radius_mm`, `offsets_um`, `revolutions`, `samples_used`, `plane_fit`,
    /// `ellipse_fit` (null when it failed) and `warnings`.
    pub fn to_json(&self) -> Value {
        serde_json::to_value(CircleJson::from(self)).unwrap_or(Value::Null)
    }
}
