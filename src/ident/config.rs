//! Identification settings from TOML (`--config FILE.toml`) and known-good regression files
//! (`eij verify`).

use super::measured::MeasuredOptions;
use super::{IdentError, Method, Settings};
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
    /// Iteration limit.
    pub max_iters: Option<u64>,
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
    /// Steady revolutions per simulated test.
    pub revolutions: Option<u32>,
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
        let name = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| IdentError::Test {
            input: name.clone(),
            message: format!("cannot read: {e}"),
        })?;
        let mut c: IdentConfig = toml::from_str(&text)
            .map_err(|e| crate::machine::MachineError::toml(&name, &text, &e))?;
        c.source = Some(name);
        Ok(c)
    }

    /// Applies the present keys, validating them.
    pub fn apply(&self, s: &mut Settings, m: &mut MeasuredOptions) -> Result<(), IdentError> {
        let from = self.source.clone().unwrap_or_else(|| "command line".into());
        let bad = |k: &str, v: String| IdentError::Test {
            input: from.clone(),
            message: format!("{k} = {v} is not allowed"),
        };
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
            if v == 0 {
                return Err(bad("max_iters", v.to_string()));
            }
            s.max_iters = Some(v);
        }
        for (k, src, dst) in [
            ("min_factor", self.min_factor, &mut s.min_factor),
            ("tol_cost", self.tol_cost, &mut s.tol_cost),
            ("tol_step", self.tol_step, &mut s.tol_step),
            ("tol_noise", self.tol_noise, &mut s.tol_noise),
            ("max_factor", self.max_factor, &mut s.max_factor),
            ("rate_hz", self.rate_hz, &mut s.simulation.rate_hz),
            ("radius_mm", self.radius_mm, &mut m.radius_mm),
            (
                "table_std_err_um_s2_per_m",
                self.table_std_err_um_s2_per_m,
                &mut m.table_std_err,
            ),
        ] {
            if let Some(v) = src {
                if !(v.is_finite() && v > 0.0) {
                    return Err(bad(k, v.to_string()));
                }
                *dst = v;
            }
        }
        if m.radius_mm > 3.0 {
            return Err(bad(
                "radius_mm",
                format!("{} (beyond the R-Test's ±3 mm range)", m.radius_mm),
            ));
        }
        if let Some(v) = self.revolutions {
            if v == 0 {
                return Err(bad("revolutions", v.to_string()));
            }
            s.simulation.revolutions = v;
        }
        if let Some(p) = &self.position_mm {
            if p.iter().any(|v| !v.is_finite()) {
                return Err(bad("position_mm", format!("{p:?}")));
            }
            s.simulation.position_m = Some(p.iter().map(|v| v * 1e-3).collect());
        }
        if s.min_factor >= s.max_factor {
            return Err(bad(
                "min_factor",
                format!("{} (not below max_factor {})", s.min_factor, s.max_factor),
            ));
        }
        Ok(())
    }
}

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
        let name = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| IdentError::Test {
            input: name.clone(),
            message: format!("cannot read: {e}"),
        })?;
        let mut k: KnownGood = toml::from_str(&text)
            .map_err(|e| crate::machine::MachineError::toml(&name, &text, &e))?;
        let dir = path.parent().unwrap_or(Path::new("."));
        k.machine = dir.join(&k.machine);
        k.measured = k.measured.iter().map(|m| dir.join(m)).collect();
        Ok(k)
    }
}
