//! The simulated R-Test series in the CSV layout of CONTRACT.md.
//!
//! Columns: `t_s`; `x_int_mm`, `y_int_mm`, `z_int_mm` (linear-scale readings relative to the
//! circle centre or move start; 0 for an axis the machine lacks); `x_ext_mm`, `y_ext_mm`,
//! `z_ext_mm` (TCP relative to the workpiece); then per machine axis `<a>_set_mm`,
//! `<a>_vel_set_m_s`, `<a>_acc_set_m_s2` (set points exactly as fed to the model),
//! `<a>_acc_act_m_s2` (second derivative of the scale reading), `<a>_following_error_um`,
//! `<a>_torque_nm`; with a compensation ([`CsvOptions::correction`]) the set-point columns keep
//! the nominal path and `<a>_comp_mm` follows each `<a>_set_mm` with the added correction.

use super::Run;
use crate::axes::Axis;
use crate::control::ClosedLoop;
use crate::rtest::{CircleSeries, RtestError};
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};

/// How to write a run.
#[derive(Debug, Clone, PartialEq)]
pub struct CsvOptions {
    /// Only the columns an R-Test measurement has (`t_s`, `*_int_mm`, `*_ext_mm`).
    pub required_only: bool,
    /// Decimals of every number.
    pub decimals: usize,
    /// Gaussian noise added to each external (R-Test) coordinate, µm (0 = none).
    pub noise_um: f64,
    /// Seed of the noise generator (ChaCha8: the same seed gives the same file everywhere).
    pub seed: u64,
    /// A compensation added to the set points (sample-major, laid out like [`Run::inputs`]):
    /// the set-point columns then show the nominal path (inputs minus correction) and
    /// `<a>_comp_mm` the correction.
    pub correction: Option<Vec<f64>>,
}

impl Default for CsvOptions {
    fn default() -> Self {
        CsvOptions {
            required_only: false,
            decimals: 10,
            noise_um: 0.0,
            seed: 1,
            correction: None,
        }
    }
}

/// Column names and, per column, where its values come from.
enum Source {
    Time,
    Output(usize, f64),
    Input(usize, f64),
    Correction(usize, f64),
    Zero,
}

fn columns(cl: &ClosedLoop, required_only: bool, compensated: bool) -> Vec<(String, Source)> {
    let mut cols = vec![("t_s".to_string(), Source::Time)];
    let out = |name: &str, scale: f64| match cl.output(name) {
        Some(i) => Source::Output(i, scale),
        None => Source::Zero,
    };
    for a in Axis::ALL {
        cols.push((format!("{a}_int_mm"), out(&format!("{a}_int_m"), 1e3)));
    }
    for a in Axis::ALL {
        cols.push((format!("{a}_ext_mm"), out(&format!("{a}_tcp_m"), 1e3)));
    }
    if required_only {
        return cols;
    }
    for a in &cl.axes {
        let inp = |name: &str, scale: f64| match cl.input(name) {
            Some(i) => Source::Input(i, scale),
            None => Source::Zero,
        };
        cols.push((format!("{a}_set_mm"), inp(&format!("{a}_pos_set_m"), 1e3)));
        if compensated {
            if let Some(i) = cl.input(&format!("{a}_pos_set_m")) {
                cols.push((format!("{a}_comp_mm"), Source::Correction(i, 1e3)));
            }
        }
        cols.push((
            format!("{a}_vel_set_m_s"),
            inp(&format!("{a}_vel_set_m_s"), 1.0),
        ));
        cols.push((
            format!("{a}_acc_set_m_s2"),
            inp(&format!("{a}_acc_set_m_s2"), 1.0),
        ));
        cols.push((
            format!("{a}_acc_act_m_s2"),
            out(&format!("{a}_acc_act_m_s2"), 1.0),
        ));
        cols.push((
            format!("{a}_following_error_um"),
            out(&format!("{a}_following_error_m"), 1e6),
        ));
        cols.push((
            format!("{a}_torque_nm"),
            out(&format!("{a}_torque_nm"), 1.0),
        ));
    }
    cols
}

/// The run as CSV text (comma separated, one header line, a fixed number of decimals, so that
/// output is byte-identical across runs and machines).
pub fn to_csv(cl: &ClosedLoop, run: &Run, opts: &CsvOptions) -> Vec<u8> {
    let corr = opts
        .correction
        .as_deref()
        .filter(|c| c.len() == run.inputs.len());
    let cols = columns(cl, opts.required_only, corr.is_some());
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(opts.seed);
    let noise = Normal::new(0.0, opts.noise_um * 1e-3)
        .ok()
        .filter(|_| opts.noise_um > 0.0);
    let mut w = csv::Writer::from_writer(Vec::with_capacity(run.len() * cols.len() * 16));
    // Writing to memory cannot fail.
    let _ = w.write_record(cols.iter().map(|(n, _)| n.as_str()));
    let mut record = Vec::with_capacity(cols.len());
    for k in 0..run.len() {
        record.clear();
        for (name, src) in &cols {
            let mut v = match src {
                Source::Time => run.t_s[k],
                Source::Output(i, s) => run.outputs[k * run.ny + i] * s,
                Source::Input(i, s) => {
                    let c = corr.map_or(0.0, |c| c[k * run.nu + i]);
                    (run.inputs[k * run.nu + i] - c) * s
                }
                Source::Correction(i, s) => corr.map_or(0.0, |c| c[k * run.nu + i]) * s,
                Source::Zero => 0.0,
            };
            if let Some(n) = &noise {
                if name.ends_with("_ext_mm") {
                    v += n.sample(&mut rng);
                }
            }
            let text = format!("{v:.*}", opts.decimals);
            // A value that rounds to zero is written without a sign.
            if text.starts_with('-') && text[1..].bytes().all(|c| c == b'0' || c == b'.') {
                record.push(text[1..].to_string());
            } else {
                record.push(text);
            }
        }
        let _ = w.write_record(&record);
    }
    w.into_inner().unwrap_or_default()
}

/// The run as an in-memory R-Test series (internal = linear scales, external = TCP relative to
/// the workpiece, mm), for evaluation without a CSV round trip.
pub fn to_series(cl: &ClosedLoop, run: &Run, source: String) -> Result<CircleSeries, RtestError> {
    let column = |name: String| -> Vec<f64> {
        match cl.output(&name) {
            Some(i) => run.output(i).map(|v| v * 1e3).collect(),
            None => vec![0.0; run.len()],
        }
    };
    let int_mm = Axis::ALL.map(|a| column(format!("{a}_int_m")));
    let ext_mm = Axis::ALL.map(|a| column(format!("{a}_tcp_m")));
    CircleSeries::new(source, run.t_s.clone(), int_mm, ext_mm)
}
