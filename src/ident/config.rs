//! Identification settings from TOML (`--config FILE.toml`) and known-good regression files
//! (`eij verify`).

use super::measured::MeasuredOptions;
use super::{IdentError, Method, Settings};
use crate::text::num;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Optional settings; absent keys keep the defaults of [`Settings`] and [`MeasuredOptions`].
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IdentConfig {
    /// Parameter names, e.g. `["x.guideway_normal", "z.screw"]`.
    pub parameters: Option<Vec<String>>,
    /// `harmonic` (default) or `time`.
    pub solver: Option<super::SolverKind>,
    /// `lm` or `nelder-mead`.
    pub method: Option<Method>,
    /// Iteration limit (a whole number; read as a number so that `1e3` is accepted and
    /// `1e30` refused by its size, not by its notation).
    pub max_iters: Option<f64>,
    /// Relative decrease of Σr² that counts as converged.
    pub tol_cost: Option<f64>,
    /// Step in θ = 1/p that counts as converged.
    pub tol_step: Option<f64>,
    /// Gauss–Newton step left, in standard errors, that counts as converged.
    pub tol_noise: Option<f64>,
    /// Lower bound of every factor.
    pub min_factor: Option<f64>,
    /// Upper bound of every factor.
    pub max_factor: Option<f64>,
    /// Output rate of the simulated tests, Hz.
    pub rate_hz: Option<f64>,
    /// Steady revolutions per simulated test (a whole number, like `max_iters`).
    pub revolutions: Option<f64>,
    /// Set radius of the circle tests, mm (2).
    pub radius_mm: Option<f64>,
    /// Axis positions of the circle centre, mm (for tests whose folder does not say).
    pub position_mm: Option<Vec<f64>>,
    /// σ of table values without a standard error, µm·s²/m.
    pub table_std_err_um_s2_per_m: Option<f64>,
    /// Static terms fitted with the EIJ: `auto`, `shared`, `per-direction`, `none`.
    pub static_terms: Option<super::StaticTerms>,
    /// Rank candidate additional tests after the fit.
    pub design: Option<bool>,
    /// Correct single-file tests by the clock offset the evaluation fits per folder.
    pub fit_time_offset: Option<bool>,
    /// The file the settings were read from (for messages).
    #[serde(skip)]
    pub source: Option<String>,
}

impl IdentConfig {
    /// Reads a config file.
    pub fn from_file(path: &Path) -> Result<IdentConfig, IdentError> {
        let (name, mut c): (String, IdentConfig) = read_toml(path)?;
        c.source = Some(name);
        Ok(c)
    }

    /// Applies the present keys, validating them: each within the range an identification can
    /// use (the error names the key, the file and the range).
    pub fn apply(&self, s: &mut Settings, m: &mut MeasuredOptions) -> Result<(), IdentError> {
        let from = self.source.clone().unwrap_or_else(|| "command line".into());
        let bad = |k: &str, v: String| IdentError::Test {
            input: from.clone(),
            message: format!("{k} = {v}"),
        };
        let range = |k: &str, v: f64, lo: f64, hi: f64, unit: &str| {
            if v.is_finite() && v > lo && v <= hi {
                Ok(v)
            } else {
                Err(bad(
                    k,
                    format!(
                        "{} is not allowed: must lie in ({}, {}]{unit}",
                        num(v),
                        num(lo),
                        num(hi)
                    ),
                ))
            }
        };
        let whole = |k: &str, v: f64, hi: f64| {
            let v = range(k, v, 0.0, hi, "")?;
            if v.fract() != 0.0 {
                return Err(bad(
                    k,
                    format!("{} is not allowed: must be a whole number", num(v)),
                ));
            }
            Ok(v)
        };
        if self.parameters.as_ref().is_some_and(|p| p.is_empty()) {
            return Err(bad(
                "parameters",
                "[] names no parameter: name at least one, or leave the key out for the default set (normal and lateral guideway factor of every axis, the stiffness factor of every elastic body)".into(),
            ));
        }
        if let Some(v) = self.method {
            s.method = v;
        }
        if let Some(v) = self.solver {
            s.simulation.solver = v;
        }
        if let Some(v) = self.static_terms {
            s.static_terms = v;
        }
        if let Some(v) = self.design {
            s.design = v;
        }
        if let Some(v) = self.fit_time_offset {
            m.fit_time_offset = v;
        }
        if let Some(v) = self.max_iters {
            s.max_iters = Some(whole("max_iters", v, MAX_ITERS)? as u64);
        }
        if let Some(v) = self.revolutions {
            s.simulation.revolutions = whole("revolutions", v, MAX_REVOLUTIONS)? as u32;
        }
        for (k, src, dst, hi, unit) in [
            (
                "min_factor",
                self.min_factor,
                &mut s.min_factor,
                MAX_FACTOR,
                "",
            ),
            ("tol_cost", self.tol_cost, &mut s.tol_cost, 1.0, ""),
            ("tol_step", self.tol_step, &mut s.tol_step, 1.0, ""),
            ("tol_noise", self.tol_noise, &mut s.tol_noise, 1.0, ""),
            (
                "max_factor",
                self.max_factor,
                &mut s.max_factor,
                MAX_FACTOR,
                "",
            ),
            (
                "rate_hz",
                self.rate_hz,
                &mut s.simulation.rate_hz,
                MAX_RATE_HZ,
                " Hz",
            ),
            (
                "radius_mm",
                self.radius_mm,
                &mut m.radius_mm,
                3.0,
                " mm (the R-Test's range)",
            ),
            (
                "table_std_err_um_s2_per_m",
                self.table_std_err_um_s2_per_m,
                &mut m.table_std_err,
                1e6,
                " µm·s²/m",
            ),
        ] {
            if let Some(v) = src {
                *dst = range(k, v, 0.0, hi, unit)?;
            }
        }
        if let Some(p) = &self.position_mm {
            if p.len() > 3 || p.iter().any(|v| !(v.is_finite() && v.abs() <= 1e5)) {
                return Err(bad(
                    "position_mm",
                    format!(
                        "{} is not allowed: give one finite position per machine axis (at most 3, within ±1e5 mm)",
                        crate::text::nums(p)
                    ),
                ));
            }
            s.simulation.position_m = Some(p.iter().map(|v| v * 1e-3).collect());
        }
        if s.min_factor >= s.max_factor {
            return Err(bad(
                "min_factor",
                format!(
                    "{} is not allowed: must lie below max_factor {}",
                    num(s.min_factor),
                    num(s.max_factor)
                ),
            ));
        }
        Ok(())
    }
}

/// Reads a TOML file (within the size limit of description files): its name and its content.
fn read_toml<T: serde::de::DeserializeOwned>(path: &Path) -> Result<(String, T), IdentError> {
    let name = path.display().to_string();
    let text = crate::io::read_input_text(path, crate::io::read::MAX_TEXT_BYTES).map_err(|e| {
        IdentError::Test {
            input: name.clone(),
            message: format!("cannot read: {e}"),
        }
    })?;
    let value =
        toml::from_str(&text).map_err(|e| crate::machine::MachineError::toml(&name, &text, &e))?;
    Ok((name, value))
}

/// Most optimiser iterations a config may ask for.
pub(crate) const MAX_ITERS: f64 = 1e6;
/// Most steady revolutions per simulated test.
pub const MAX_REVOLUTIONS: f64 = 1000.0;
/// Highest output rate of the simulated tests, Hz.
pub(crate) const MAX_RATE_HZ: f64 = 1e6;
/// Largest bound of a reduction factor.
pub(crate) const MAX_FACTOR: f64 = 1000.0;

/// An expected identified value with its tolerance.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Expected {
    /// The known-good value.
    pub value: f64,
    /// Allowed relative deviation.
    pub rel_tol: f64,
}

/// A stored identification whose result must not drift (`tests/known-good/*.toml`).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KnownGood {
    /// What it checks.
    pub description: String,
    /// Machine file, relative to the known-good file.
    pub machine: PathBuf,
    /// Measured inputs, relative to the known-good file.
    pub measured: Vec<PathBuf>,
    /// Settings.
    #[serde(default)]
    pub settings: IdentConfig,
    /// Expected factors by parameter name.
    pub expected: BTreeMap<String, Expected>,
}

impl KnownGood {
    /// Reads a known-good file and resolves its paths relative to it.
    pub fn from_file(path: &Path) -> Result<KnownGood, IdentError> {
        let (name, mut k): (String, KnownGood) = read_toml(path)?;
        k.settings.source = Some(name.clone());
        for (param, e) in &k.expected {
            let bad = |what: &str, v: f64, rule: &str| IdentError::Test {
                input: name.clone(),
                message: format!(
                    "expected.\"{param}\".{what} = {} is not allowed: {rule}",
                    num(v)
                ),
            };
            if !(e.value.is_finite() && e.value > 0.0) {
                return Err(bad("value", e.value, "a factor must be finite and > 0"));
            }
            if !(e.rel_tol.is_finite() && e.rel_tol > 0.0 && e.rel_tol < 1.0) {
                return Err(bad(
                    "rel_tol",
                    e.rel_tol,
                    "a relative tolerance must lie in (0, 1)",
                ));
            }
        }
        let dir = path.parent().unwrap_or(Path::new("."));
        k.machine = dir.join(&k.machine);
        k.measured = k.measured.iter().map(|m| dir.join(m)).collect();
        Ok(k)
    }
}
