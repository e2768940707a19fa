//! The simulated R-Test series in the CSV layout of docs/commands.md.
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
#[derive(Debug)]
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
    let buffer = Vec::with_capacity(run.len() * 30 * 16);
    // Writing to memory cannot fail.
    let Ok(mut stream) = CsvStream::new(cl, opts, corr.is_some(), buffer) else {
        return Vec::new();
    };
    let _ = stream.write(run, corr);
    stream.finish().unwrap_or_default()
}

/// CSV output written block by block as a simulation runs ([`crate::sim::simulate_blocks`]):
/// the same bytes as [`to_csv`] of the whole run, the noise drawn in the same order.
pub struct CsvStream<W: std::io::Write> {
    writer: csv::Writer<W>,
    cols: Vec<(String, Source)>,
    rng: rand_chacha::ChaCha8Rng,
    noise: Option<Normal<f64>>,
    decimals: usize,
    record: Vec<String>,
}

impl<W: std::io::Write> CsvStream<W> {
    /// Writes the header to `inner`; `compensated`: with the `<axis>_comp_mm` columns (the
    /// corrections then come with every block). `opts.correction` is not used.
    pub fn new(
        cl: &ClosedLoop,
        opts: &CsvOptions,
        compensated: bool,
        inner: W,
    ) -> Result<Self, csv::Error> {
        let cols = columns(cl, opts.required_only, compensated);
        let mut writer = csv::Writer::from_writer(inner);
        writer.write_record(cols.iter().map(|(n, _)| n.as_str()))?;
        Ok(CsvStream {
            writer,
            rng: rand_chacha::ChaCha8Rng::seed_from_u64(opts.seed),
            noise: Normal::new(0.0, opts.noise_um * 1e-3)
                .ok()
                .filter(|_| opts.noise_um > 0.0),
            decimals: opts.decimals,
            record: Vec::with_capacity(cols.len()),
            cols,
        })
    }

    /// Writes the samples of `run`; `correction` (laid out like [`Run::inputs`]) is the
    /// compensation added to its set points.
    pub fn write(&mut self, run: &Run, correction: Option<&[f64]>) -> Result<(), csv::Error> {
        for k in 0..run.len() {
            self.record.clear();
            for (name, src) in &self.cols {
                let mut v = match src {
                    Source::Time => run.t_s[k],
                    Source::Output(i, s) => run.outputs[k * run.ny + i] * s,
                    Source::Input(i, s) => {
                        let c = correction.map_or(0.0, |c| c[k * run.nu + i]);
                        (run.inputs[k * run.nu + i] - c) * s
                    }
                    Source::Correction(i, s) => correction.map_or(0.0, |c| c[k * run.nu + i]) * s,
                    Source::Zero => 0.0,
                };
                if let Some(n) = &self.noise {
                    if name.ends_with("_ext_mm") {
                        v += n.sample(&mut self.rng);
                    }
                }
                let text = format!("{v:.*}", self.decimals);
                // A value that rounds to zero is written without a sign.
                if text.starts_with('-') && text[1..].bytes().all(|c| c == b'0' || c == b'.') {
                    self.record.push(text[1..].to_string());
                } else {
                    self.record.push(text);
                }
            }
            self.writer.write_record(&self.record)?;
        }
        Ok(())
    }

    /// Flushes and returns the writer.
    pub fn finish(self) -> Result<W, std::io::Error> {
        self.writer
            .into_inner()
            .map_err(|e| std::io::Error::other(e.to_string()))
    }
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
