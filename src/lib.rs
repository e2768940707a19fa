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
//! * [`machine`]: the validated machine description (bodies, axes, guideways, drives, control),
//!   read from TOML with catalogue look-up of carriage stiffness.
//! * [`mbs`]: assembly of the mass, damping and stiffness matrices at an axis position; modal
//!   analysis.
//! * [`control`]: drives under cascaded P-PI control; the closed loop in state space.
//! * [`sim`]: set points (circle, jerk-limited move) and exact time-domain discretisation.
//! * [`rtest`]: reading and evaluating R-Test circle tests into EIJ with standard errors.
//! * [`predict`]: simulated circle tests evaluated like measured ones: the EIJ a model predicts.
//! * [`ident`]: stiffness reduction factors fitted to measured EIJ, with their uncertainty.
//! * [`map`]: EIJ over the workspace; [`report`]: figures and the HTML report.
//!
//! Equation numbers (eq. 3–6, section 2.2/2.3) refer to the paper on acceleration correlated
//! position errors measured with the R-Test that this tool implements and extends.

pub mod axes;
pub mod control;
pub mod ident;
pub mod io;
pub mod machine;
pub mod map;
pub mod mbs;
pub mod predict;
pub mod report;
pub mod rtest;
pub mod sim;
