//! Every default of an identification in one place: the optimiser's settings ([`Settings`]),
//! how measured data are read ([`MeasuredOptions`]), and the fixed thresholds of the method.
//! How the tests are simulated is [`crate::predict::SimSettings`] (inside [`Settings`]).

use super::statics::StaticTerms;
use crate::predict::SimSettings;

/// Which optimiser.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Levenberg–Marquardt on the weighted residuals (default).
    Lm,
    /// Nelder–Mead on the weighted sum of squares (robust fallback, slower).
    NelderMead,
}

impl Method {
    /// The iteration limit when none is given: 50 for Levenberg–Marquardt (it converges in
    /// about ten on the demo), 2000 for Nelder–Mead (many cheap iterations, one cost each).
    pub const fn default_max_iters(self) -> u64 {
        match self {
            Method::Lm => 50,
            Method::NelderMead => 2000,
        }
    }
}

/// Settings of an identification run; [`Settings::default`] documents the defaults.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    /// How the tests are simulated inside the optimisation ([`SimSettings::default`]: harmonic
    /// steady state evaluated in closed form as 4 steady revolutions of 128 samples; time domain
    /// at 1 kHz).
    pub simulation: SimSettings,
    /// Lower bound of every factor (0.01).
    pub min_factor: f64,
    /// Upper bound of every factor (10).
    pub max_factor: f64,
    /// Iteration limit (`None`: [`Method::default_max_iters`], 50 for Levenberg–Marquardt, 2000
    /// for Nelder–Mead).
    pub max_iters: Option<u64>,
    /// Relative cost decrease that counts as converged (1e-10).
    pub tol_cost: f64,
    /// Step in θ = 1/p that counts as converged (1e-8).
    pub tol_step: f64,
    /// Converged when the Gauss–Newton step left is shorter than this many standard errors
    /// (0.01; Levenberg–Marquardt only, see [`super::lm`]): further iterations would move
    /// neither the parameters nor χ² (by 1e-4 s²) by anything the noise lets one see.
    pub tol_noise: f64,
    /// Central-difference step, relative to θ (1e-3).
    pub fd_step: f64,
    /// Optimiser (Levenberg–Marquardt).
    pub method: Method,
    /// Smallest σ used to weight a measured value, µm·s²/m (1e-3): keeps noise-free data finite.
    pub sigma_floor: f64,
    /// Static terms fitted with the EIJ ([`StaticTerms::Auto`], see [`super::statics`]).
    pub static_terms: StaticTerms,
    /// Rank candidate additional tests after the fit (true; see [`super::design`]).
    pub design: bool,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            simulation: SimSettings::default(),
            min_factor: 0.01,
            max_factor: 10.0,
            max_iters: None,
            tol_cost: 1e-10,
            tol_step: 1e-8,
            tol_noise: 0.01,
            fd_step: 1e-3,
            method: Method::Lm,
            sigma_floor: 1e-3,
            static_terms: StaticTerms::Auto,
            design: true,
        }
    }
}

impl Settings {
    /// Bounds of θ = 1/p.
    pub(crate) fn theta_bounds(&self) -> (f64, f64) {
        (1.0 / self.max_factor, 1.0 / self.min_factor)
    }

    /// The iteration limit in force: the one given, else the method's default.
    pub fn max_iters(&self) -> u64 {
        self.max_iters
            .unwrap_or_else(|| self.method.default_max_iters())
    }
}

/// How to read measured data ([`MeasuredOptions::default`] documents the defaults).
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredOptions {
    /// Set radius of the circle tests, mm (2, the paper's radius): R-Test series are evaluated
    /// with it, table tests (tables carry no radius) take it, and the simulated tests run and are
    /// evaluated with it, so that measurement and model are compared like with like. A folder's
    /// `rtest.toml` overrides it.
    pub radius_mm: f64,
    /// σ for table values without a standard error, µm·s²/m (0.05).
    pub table_std_err: f64,
    /// Correct single-file tests by the clock offset (probe-logger lag) that the evaluation
    /// fits over the tests of their folder where the tests separate it from cross-talk (false;
    /// [`crate::rtest::clock_fit`]; the offsets are reported either way). Off by default: the
    /// evaluation's fit takes EIJ as equal for cw and ccw, so it also absorbs the structural
    /// deviation proportional to velocity (damping) that the model predicts and that flips with
    /// the direction like δ·v does (0.4 µs on the demo data, which have no lag).
    pub fit_time_offset: bool,
}

impl Default for MeasuredOptions {
    fn default() -> Self {
        MeasuredOptions {
            radius_mm: 2.0,
            table_std_err: 0.05,
            fit_time_offset: false,
        }
    }
}

/// Simulated EIJ that differ by less than this fraction of the test's largest EIJ differ by
/// rounding only (the harmonic simulation resolves ~1e-13 relative; a reduction factor that a test
/// sees moves its EIJ by far more over a finite-difference step): their difference counts as
/// zero in the Jacobian.
pub(crate) const SIMULATION_RESOLUTION: f64 = 1e-10;

/// A parameter whose Jacobian column norm at the start is below this fraction of the largest
/// is not seen by the tests: it is kept at its start value and reported not identifiable.
pub(crate) const UNIDENTIFIABLE_COLUMN: f64 = 1e-6;

/// A parameter whose standard error predicted at the start (σ taken at face value) exceeds
/// this fraction of its value is not determined by the tests: kept at its start value.
pub(crate) const NOT_IDENTIFIABLE_REL_STD_ERR: f64 = 1.0;

/// Singular values of the column-scaled Jacobian below this fraction of the largest are a
/// combination the tests do not see at all (central differences resolve ~1e-6 of a column).
pub(crate) const DEGENERATE_SINGULAR: f64 = 1e-6;

/// A parameter takes part in a null-space direction when its share of the singular vector is
/// at least this fraction of the largest share.
pub(crate) const TIE_SHARE: f64 = 0.2;

/// A factor within this fraction of a bound has ended on it (0.010006 against 0.01 has).
pub(crate) const AT_BOUND_REL: f64 = 1e-3;

/// Identified factors outside [this, [`PLAUSIBLE_MAX`]] are implausible for a reduction of
/// catalogue stiffness (a warning).
pub(crate) const PLAUSIBLE_MIN: f64 = 0.1;

/// A reduction factor above this makes the part stiffer than its catalogue data (a warning).
pub(crate) const PLAUSIBLE_MAX: f64 = 1.0;

/// An elastic body's stiffness factor (`<body>.stiffness`) outside [this,
/// [`BODY_PLAUSIBLE_MAX`]] is far from its FE model: a factor on Young's modulus of a cast or
/// welded part is known to some ten per cent, so a factor of 2 says the FE model (sections,
/// mesh, material) or the joints that hold the body (bolted flanges, feet) are wrong, rather than
/// the material (a warning).
pub const BODY_PLAUSIBLE_MIN: f64 = 0.5;

/// See [`BODY_PLAUSIBLE_MIN`].
pub const BODY_PLAUSIBLE_MAX: f64 = 2.0;

/// Singular values of the weighted Jacobian below this fraction of the largest mark a
/// parameter combination the tests hardly separate (a warning).
pub(crate) const NEAR_SINGULAR: f64 = 1e-8;

/// A standard error above this fraction of the value marks a weakly determined parameter
/// (a warning).
pub(crate) const WEAK_REL_STD_ERR: f64 = 0.5;

/// A standard error up to this fraction of the value marks a determined parameter (above it,
/// up to [`WEAK_REL_STD_ERR`], a loosely determined one; see [`super::verdict`]).
pub(crate) const DETERMINED_REL_STD_ERR: f64 = 0.1;

/// The χ² test fails (a warning) when s² exceeds 1 by more than this many of its standard
/// deviations √(2/(m − n)).
pub(crate) const CHI2_SIGMAS: f64 = 4.0;

/// The interval of an identified factor is its value ± this many standard errors, taken in the
/// compliance θ = 1/p and mapped to p ([`super::verdict::factor_interval`]).
pub const INTERVAL_SIGMAS: f64 = 3.0;

/// With a failed χ² test, a static term or clock offset beyond this many standard errors says
/// that it may be absorbing a model error ([`super::mismatch`]).
pub const MISMATCH_SIGMAS: f64 = 3.0;

/// Harmonic and time-domain EIJ of the final model must agree within this fraction of the
/// value …
pub(crate) const CONFIRM_REL: f64 = 0.01;

/// … or within this many µm·s²/m, whichever is larger (else a warning).
pub(crate) const CONFIRM_ABS_UM_S2_PER_M: f64 = 0.01;

/// Nelder–Mead's starting simplex: the start and one vertex per parameter with θ scaled by this.
pub(crate) const NELDER_MEAD_SIMPLEX_SCALE: f64 = 1.3;

/// Nelder–Mead has converged when the simplex costs spread by less than this fraction of the
/// starting cost (it has no gradient to test).
pub(crate) const NELDER_MEAD_REL_SPREAD: f64 = 1e-7;
