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
//!   two-system recordings, EIJ tables and JSON, moves) and evaluated as one suite.
//! * [`predict`]: simulated circle tests evaluated like measured ones: the EIJ a model predicts.
//! * [`ident`]: stiffness reduction factors fitted to measured EIJ, with their uncertainty.
//! * [`map`], [`compensation`]: EIJ over the workspace and compensation tables; `report`
//!   (feature `report`): figures and the HTML report; the `eij` binary's `cli` last.
//!
//! ## Where new things go
//!
//! * **A new file format of measured data** goes into `src/measured`: a CSV dialect or column
//!   map into `measured/layout.rs`, a controller's trace export as a file beside
//!   `measured/traces/tnc.rs` and `sinumerik.rs` (recognised by content in
//!   `measured/traces/mod.rs`), a table of EIJ into `measured/table.rs`. It reads into the
//!   types [`rtest`] evaluates ([`CircleSeries`]), its errors are [`MeasuredError`] (one line
//!   naming file, line or key), its keys and columns are described in
//!   docs/measurement-files.md, and its tests are `tests/measured_*.rs` or `tests/traces_*.rs`.
//!   The stages after `measured` see only what it reads, as from every other format.
//! * **A new kind of body** (beside fixed, rigid and elastic) goes into `src/machine`: a
//!   [`machine::BodyKind`] variant in `machine/body.rs` that answers the four questions every
//!   body answers (its number of coordinates, how a point on it moves, its own mass, stiffness
//!   and damping blocks, its rigid motion), its table in the machine file in `machine/raw.rs`,
//!   checked once in `machine/validate.rs` (elastic bodies: `machine/elastic.rs`, with the
//!   reduction in [`fe`]), described in docs/machine-file.md. [`mbs`] assembles a body only
//!   through those four answers, so the assembly and every later stage take the new kind as it
//!   is.
//!
//! Equation numbers (eq. 3–6, section 2.2/2.3) refer to the paper on acceleration correlated
//! position errors measured with the R-Test that this tool implements and extends.
//!
//! ## Calibrating a model from R-Test files
//!
//! [`Identification`] reads measured circle tests (CSV files, folders with `rtest.toml`, or EIJ
//! tables), simulates the same tests on the model and fits stiffness reduction factors, with
//! documented defaults for everything not given (the six guideway factors, Levenberg–Marquardt,
//! a set radius of 2 mm). The result says how far to trust it — the χ² test of the fit
//! ([`Chi2`]) and each factor's [`Standing`] — and writes the identified machine file with its
//! [`Provenance`] (what `eij identify` writes):
//!
//! ```
//! use eij::{Identification, Machine, Provenance};
//! use std::path::Path;
//!
//! let root = Path::new(env!("CARGO_MANIFEST_DIR"));
//! let machine_file = root.join("machines/demo-vmc.toml");
//! let measured = [root.join("measurements/demo-vmc")];
//! let result = Identification::new(Machine::from_file(&machine_file)?)
//!     .measured(&measured)
//!     .run()?;
//!
//! let chi2 = result.chi2();
//! println!("χ² test {}", chi2.describe());
//! for p in &result.parameters {
//!     let se = p.std_err.unwrap_or(f64::NAN);
//!     println!("{} = {:.3} ± {:.3} ({})", p.name, p.value, se, p.standing().label());
//! }
//! // measurements/demo-vmc was generated with the Z guideway's normal stiffness at 40 % of the
//! // catalogue value (its README); the fit finds it within three standard errors.
//! let z = result.parameters.iter().find(|p| p.name == "z.guideway_normal").unwrap();
//! assert!((z.value - 0.40).abs() < 3.0 * z.std_err.unwrap());
//! assert!(chi2.passed);
//!
//! let folder = std::env::temp_dir().join(format!("eij-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&folder)?;
//! let identified = folder.join("demo-vmc-identified.toml");
//! result.write_machine_file(&identified, &Provenance::now(&machine_file, &measured)?)?;
//! assert_eq!(Machine::from_file(&identified)?.name(), "demo-vmc-identified");
//! std::fs::remove_dir_all(&folder)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Lower down: [`identify`] runs a prepared [`ident::Problem`] (with a progress callback),
//! [`evaluate`] evaluates one R-Test series ([`CircleSeries`]) into EIJ, [`simulated_eij`]
//! predicts the EIJ of circle tests ([`CircleTest`]) on a machine, [`ClosedLoop`] is the
//! machine under control at a [`Pose`].
//!
//! ## Features
//!
//! * `cli` (default): the `eij` binary (clap, indicatif) and `report`.
//! * `report` (default through `cli`): SVG figures and the offline HTML report (plotters).
//!
//! `cargo build --lib --no-default-features` builds the bare library.

#![warn(unreachable_pub)]

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

pub use axes::{Axis, Direction, Eij, EijEstimates, Estimate, Plane};
pub use control::ClosedLoop;
pub use ident::report::{machine_toml, ExportError, Provenance};
pub use ident::verdict::{Chi2, Standing};
pub use ident::{
    identify, IdentError, IdentResult, Identification, Identified, Method, Parameter, Settings,
    TestCase,
};
pub use machine::{Machine, MachineError, Pose};
pub use measured::MeasuredError;
pub use predict::{simulated_eij, CircleTest, PredictError, SimSettings, SolverKind};
pub use rtest::{evaluate, CircleResult, CircleSeries, EvalOptions, RtestError};
