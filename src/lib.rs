//! # eij — acceleration correlated position errors of machine tools
//!
//! eij calibrates a multi-body (MB) model of a machine tool from R-Test circle measurements so that
//! the model predicts the acceleration correlated position errors `EIJ` at the tool centre point
//! (deviation in direction I per set acceleration of axis J, µm·s²/m).
//!
//! The module tree follows the data path; a module imports only from its own stage and the
//! stages before it (`tests/architecture.rs` checks this, and that no import circle exists):
//!
//! ```text
//! text, axes, io ─► fe ─► machine ─► mbs ─► control ─► rtest ─► sim ─► measured
//!                ─► predict ─► ident ─► map ─► compensation ─► report ─► cli
//! ```
//!
//! * [`text`], [`axes`], [`io`]: numbers in messages, the names shared along the data path
//!   (axes, planes, EIJ), files in and out (size limits, atomic outputs, delimited text).
//! * [`fe`]: elastic bodies from finite-element models, reduced (Craig–Bampton) to the
//!   coordinates of the multi-body model.
//! * [`machine`]: the validated machine description (bodies, axes, guideways, drives, control),
//!   read from TOML with catalogue look-up of carriage stiffness.
//! * [`mbs`]: assembly of the mass, damping and stiffness matrices at an axis position; modal
//!   analysis.
//! * [`control`]: drives under cascaded P-PI control; the closed loop in state space.
//! * [`rtest`]: the evaluation of R-Test circle tests into EIJ with standard errors (the math
//!   alone; before `sim`, which hands its runs over as the evaluation's `CircleSeries`).
//! * [`sim`]: set points (circle, jerk-limited move) and exact time-domain discretisation.
//! * [`measured`]: what was measured, read from files (CSV layouts, `rtest.toml` conditions,
//!   two-system recordings, EIJ tables and JSON, moves) and evaluated as one suite. A new file
//!   format goes here; a new kind of body into [`machine`] and [`mbs`].
//! * [`predict`]: simulated circle tests evaluated like measured ones: the EIJ a model predicts.
//! * [`ident`]: stiffness reduction factors fitted to measured EIJ, with their uncertainty.
//! * [`map`], [`compensation`]: EIJ over the workspace and compensation tables; `report`
//!   (feature `report`): figures and the HTML report; the `eij` binary's `cli` last.
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
pub mod measured;
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
pub use measured::MeasuredError;
pub use predict::{simulated_eij, CircleTest, PredictError, SimSettings, SolverKind};
pub use rtest::{evaluate, CircleResult, CircleSeries, EvalOptions, RtestError};
