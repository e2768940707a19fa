//! # eij — acceleration correlated position errors of machine tools
//!
//! eij calibrates a multi-body (MB) model of a machine tool from R-Test circle measurements so that
//! the model predicts the acceleration correlated position errors `EIJ` at the tool centre point
//! (deviation in direction I per set acceleration of axis J, µm·s²/m).
//!
//! The module tree follows the data path:
//!
//! ```text
//! machine ─► mbs ─► control ─► sim ─► rtest ─► predict ─► ident ─► report
//! ```
//!
//! * [`fe`]: elastic bodies: FE models exported from an FE program or built as Timoshenko beams,
//!   reduced by Craig–Bampton to rigid-body plus modal coordinates (feeds `machine`).
//! * [`machine`]: the validated machine description (bodies, axes, guideways, drives, control),
//!   read from TOML with catalogue look-up of carriage stiffness.
//! * [`mbs`]: assembly of the mass, damping and stiffness matrices at an axis position; modal
//!   analysis.
//! * [`control`]: drives under cascaded P-PI control; the closed loop in state space.
//! * [`sim`]: set points (circle, jerk-limited move) and exact time-domain discretisation.
//! * [`rtest`]: reading and evaluating R-Test circle tests into EIJ with standard errors.
//! * [`predict`]: simulated circle tests evaluated like measured ones: the EIJ a model predicts.
//! * [`ident`]: stiffness reduction factors fitted to measured EIJ, with their uncertainty.
//! * [`map`]: EIJ over the workspace; `report` (feature `report`): figures and the HTML report.
//!
//! Equation numbers (eq. 3–6, section 2.2/2.3) refer to the paper on acceleration correlated
//! position errors measured with the R-Test that this tool implements and extends.
//!
//! ## Calibrating a model from R-Test files
//!
//! [`Identification`] reads measured circle tests (CSV files, folders with `rtest.toml`, or EIJ
//! tables), simulates the same tests on the model and fits stiffness reduction factors, with
//! documented defaults for everything not given:
//!
//! ```
//! use eij::{Identification, Machine};
//! use std::path::Path;
//!
//! let root = Path::new(env!("CARGO_MANIFEST_DIR"));
//! let machine = Machine::from_file(&root.join("machines/demo-vmc.toml"))?;
//! let demo = root.join("measurements/demo-vmc");
//! let result = Identification::new(machine)
//!     .parameters(["z.guideway_normal", "z.guideway_lateral"])
//!     .measured([demo.join("pos-a/zx_ccw_5.csv"), demo.join("pos-a/zx_cw_8.csv"), demo.join("pos-b/zx_ccw_8.csv")])
//!     .run()?;
//! for p in &result.parameters {
//!     println!("{} = {:.3} ± {:.3}", p.name, p.value, p.std_err.unwrap_or(f64::NAN));
//! }
//! // measurements/demo-vmc was generated with the Z guideway's normal stiffness at 40 % of the
//! // catalogue value (its README); the fit finds it within three standard errors.
//! let z = &result.parameters[0];
//! assert!((z.value - 0.40).abs() < 3.0 * z.std_err.unwrap());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! ## Features
//!
//! * `cli` (default): the `eij` binary (clap, indicatif) and `report`.
//! * `report` (default through `cli`): SVG figures and the offline HTML report (plotters).
//!
//! `cargo build --lib --no-default-features` builds the bare library.

pub mod axes;
pub mod compensation;
pub mod control;
pub mod fe;
pub mod ident;
pub mod io;
pub mod machine;
pub mod map;
pub mod mbs;
pub mod predict;
#[cfg(feature = "report")]
pub mod report;
pub mod rtest;
pub mod sim;
pub mod text;

pub use axes::{Axis, Direction, Eij, Plane};
pub use control::ClosedLoop;
pub use ident::{IdentError, IdentResult, Identification, Method, Parameter, Settings, TestCase};
pub use machine::{Machine, MachineError};
pub use predict::{simulated_eij, CircleTest, PredictError, SimSettings, SolverKind};
pub use rtest::{evaluate, CircleResult, CircleSeries, EvalOptions, RtestError};
