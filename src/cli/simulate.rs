//! `eij simulate circle|move …`: closed-loop time-domain simulation to an R-Test-like CSV.

use super::machine_args::{write_outputs, MachineArgs};
use anyhow::{bail, Context};
use eij::axes::{Axis, Direction, Plane};
use eij::compensation::{Compensated, CompensationTable};
use eij::control::ClosedLoop;
use eij::machine::{Machine, Pose};
use eij::report::{move_svg, CircleView, Conditions, MoveData};
use eij::rtest::EvalOptions;
use eij::sim::setpoint::{Circle, JerkLimitedMove, SetPoint};
use eij::sim::{output, simulate};
use std::path::PathBuf;

/// Arguments of `eij simulate`.
#[derive(Debug, clap::Args)]
pub struct SimulateArgs {
    #[command(subcommand)]
    test: Test,
}

#[derive(Debug, clap::Subcommand)]
enum Test {
    /// A circle test (paper eq. 3–4) with smooth ramps.
    Circle(CircleArgs),
    /// A jerk-limited positioning move of one axis.
    Move(MoveArgs),
}

/// Options of every simulation.
#[derive(Debug, clap::Args)]
struct Common {
    #[command(flatten)]
    machine: MachineArgs,
    /// Output CSV file (docs/commands.md columns).
    #[arg(long, value_name = "FILE.csv")]
    out: PathBuf,
    /// Output sample rate, Hz.
    #[arg(long, default_value_t = 10_000.0, allow_hyphen_values = true)]
    rate_hz: f64,
    /// Add Gaussian noise of this standard deviation to the external (R-Test) columns, µm,
    /// to generate realistic test data (the R-Test's U(k=2) = 2.8 µm is σ = 1.4 µm).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    noise_um: f64,
    /// Seed of the noise.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Write only the columns an R-Test measurement has (t, internal, external).
    #[arg(long)]
    required_only: bool,
    /// Decimals of every number in the CSV.
    #[arg(long, default_value_t = 10)]
    decimals: usize,
    /// Also write a figure (SVG): the magnified circle plot of the noise-free simulated
    /// series, or the move plot (position, acceleration, cross-talk over time).
    #[arg(long, value_name = "FILE.svg")]
    plot: Option<PathBuf>,
    /// Apply a compensation table (`eij compensation`) as feed-forward on the set points:
    /// `<axis>_set_mm` stays the nominal path, `<axis>_comp_mm` holds the correction.
    #[arg(long, value_name = "TABLE.csv")]
    compensation: Option<PathBuf>,
}

impl Common {
    /// Every file the run reads.
    fn inputs(&self) -> Vec<&std::path::Path> {
        let mut v = vec![self.machine.machine.as_path()];
        v.extend(self.compensation.as_deref());
        v
    }

    /// The compensation table, if one is given.
    fn table(&self, machine: &Machine) -> anyhow::Result<Option<CompensationTable>> {
        Ok(match &self.compensation {
            Some(p) => Some(CompensationTable::read(p, machine)?),
            None => None,
        })
    }
}

/// The set point with the compensation applied (if any), and the correction per output sample.
fn compensate<'a>(
    sp: &'a dyn SetPoint,
    table: Option<&'a CompensationTable>,
    pose: &[f64],
    machine: &Machine,
) -> Option<Compensated<'a>> {
    let table = table?;
    let mut origin_mm = [0.0; 3];
    for (a, p) in machine.axes().iter().zip(pose) {
        origin_mm[a.axis.index()] = p * 1e3;
    }
    Some(Compensated {
        nominal: sp,
        table,
        origin_mm,
    })
}

/// The correction at every sample of `run`, laid out like its inputs.
fn corrections(comp: &Compensated, cl: &ClosedLoop, run: &eij::sim::Run) -> Vec<f64> {
    let mut out = vec![0.0; run.inputs.len()];
    for (k, t) in run.t_s.iter().enumerate() {
        comp.correction(*t, &cl.axes, &mut out[k * run.nu..(k + 1) * run.nu]);
    }
    out
}

/// What `--plot` draws.
enum PlotKind {
    Circle { radius_mm: f64 },
    Move(Box<MoveData>),
}

#[derive(Debug, clap::Args)]
struct CircleArgs {
    #[command(flatten)]
    common: Common,
    /// Plane: xy, yz or zx.
    #[arg(long)]
    plane: Plane,
    /// Circle radius, mm (the R-Test range is ±3 mm).
    #[arg(long, allow_hyphen_values = true)]
    radius_mm: f64,
    /// Steady set acceleration r·ω², m/s².
    #[arg(long, allow_hyphen_values = true)]
    accel_m_s2: f64,
    /// cw or ccw.
    #[arg(long)]
    direction: Direction,
    /// Number of whole steady revolutions.
    #[arg(long, default_value_t = 5)]
    revolutions: u32,
}

#[derive(Debug, clap::Args)]
struct MoveArgs {
    #[command(flatten)]
    common: Common,
    /// The moving axis: x, y or z.
    #[arg(long)]
    axis: Axis,
    /// Signed distance, mm.
    #[arg(long, allow_hyphen_values = true)]
    distance_mm: f64,
    /// Feed (velocity limit), mm/min.
    #[arg(long, allow_hyphen_values = true)]
    feed_mm_min: f64,
    /// Acceleration limit, m/s².
    #[arg(long, allow_hyphen_values = true)]
    accel_m_s2: f64,
    /// Jerk limit, m/s³.
    #[arg(long, allow_hyphen_values = true)]
    jerk_m_s3: f64,
}

/// Most steady revolutions of a simulated circle.
const MAX_REVOLUTIONS: u32 = 1000;

/// Most samples one simulation writes: bounds memory and file size (100 s at 10 kHz).
const MAX_SAMPLES: f64 = 1e6;

/// Refuses a rate or a length that the output could not hold, and (for circles) a rate too low
/// for the evaluation to see the circle.
fn check_samples(common: &Common, sp: &dyn SetPoint, freq_hz: Option<f64>) -> anyhow::Result<()> {
    let rate = positive("rate-hz", common.rate_hz)?;
    // Beyond 15 decimals an f64 has no more digits to give.
    if common.decimals > 15 {
        bail!(
            "--decimals: {} is more than the 15 an f64 holds",
            common.decimals
        );
    }
    // Rounded times must still tell the samples apart, to a tenth of a sample, and lengths
    // in mm need at least 1 µm (else `t_s` repeats and eij's own evaluation refuses the file).
    let needed = ((10.0 * rate).log10().ceil() as usize).max(3);
    if common.decimals < needed {
        bail!(
            "--decimals {}: at {rate} Hz (a sample every {} s) t_s needs at least {needed} decimals",
            common.decimals,
            eij::text::num(1.0 / rate)
        );
    }
    let samples = sp.duration_s() * rate;
    if samples.is_nan() || samples > MAX_SAMPLES {
        bail!(
            "--rate-hz {rate}: {:.4} s of simulation would give {samples:.3e} samples, at most \
             {MAX_SAMPLES:.0e} are written (lower --rate-hz or shorten the test)",
            sp.duration_s()
        );
    }
    if let Some(f) = freq_hz {
        let min = eij::rtest::normalise::MIN_SAMPLES_PER_REVOLUTION as f64;
        if rate < min * f {
            bail!(
                "--rate-hz {rate}: {:.1} samples per revolution of the {f:.3} Hz circle, at least \
                 {min} needed (--rate-hz ≥ {:.0})",
                rate / f,
                (min * f).ceil()
            );
        }
    }
    Ok(())
}

impl Common {
    /// Loads the machine and its pose, the compensation table, then checks the outputs (with
    /// every file read so far: the machine's catalogues and the table count as inputs).
    fn load(&self) -> anyhow::Result<(Machine, Pose, Option<CompensationTable>)> {
        let (machine, pose) = self.machine.load()?;
        let table = self.table(&machine)?;
        let mut outputs = vec![self.out.as_path()];
        outputs.extend(self.plot.as_deref());
        eij::io::check_outputs(&outputs, &self.inputs())?;
        Ok((machine, pose, table))
    }
}

fn positive(name: &str, v: f64) -> anyhow::Result<f64> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        bail!("--{name}: {v} must be a positive number")
    }
}

/// Runs `eij simulate`.
pub fn run(args: SimulateArgs) -> anyhow::Result<()> {
    match args.test {
        Test::Circle(c) => {
            let radius_mm = positive("radius-mm", c.radius_mm)?;
            if radius_mm > 3.0 {
                bail!("--radius-mm: {radius_mm} mm exceeds the R-Test probe range of ±3 mm");
            }
            let accel = super::machine_args::accel_m_s2(c.accel_m_s2)?;
            if !(1..=MAX_REVOLUTIONS).contains(&c.revolutions) {
                bail!(
                    "--revolutions: {} must lie in 1…{MAX_REVOLUTIONS} steady revolutions",
                    c.revolutions
                );
            }
            let mut circle = Circle::new(c.plane, radius_mm * 1e-3, accel, c.direction);
            circle.steady_revolutions = c.revolutions;
            check_samples(&c.common, &circle, Some(circle.frequency_hz()))?;
            run_setpoint(&c.common, &circle, c.plane, radius_mm)
        }
        Test::Move(m) => {
            if !(m.distance_mm.is_finite() && m.distance_mm != 0.0) {
                bail!("--distance-mm: {} must be a non-zero number", m.distance_mm);
            }
            let v = positive("feed-mm-min", m.feed_mm_min)? / 60_000.0;
            let a = super::machine_args::accel_m_s2(m.accel_m_s2)?;
            let j = positive("jerk-m-s3", m.jerk_m_s3)?;
            let mv = JerkLimitedMove::new(m.axis, m.distance_mm * 1e-3, v, a, j);
            check_samples(&m.common, &mv, None)?;
            let deviation = run_move(&m.common, &mv)?;
            // After the run, so that a refused move gives one error line only.
            super::console::status(format_args!(
                "move {}: {:.3} mm, peak velocity {:.4} m/s, peak set acceleration {:.3} m/s², {:.4} s",
                m.axis,
                m.distance_mm,
                mv.peak_velocity_m_s,
                mv.peak_accel_m_s2,
                mv.motion_s()
            ));
            super::console::status(format_args!("{deviation}"));
            Ok(())
        }
    }
}

/// Simulates the move (and, with a compensation, the same move without it); returns the
/// console line of the TCP's deviation from the nominal path.
fn run_move(common: &Common, mv: &JerkLimitedMove) -> anyhow::Result<String> {
    let (machine, pose, table) = common.load()?;
    let Some(i) = machine.axes().iter().position(|a| a.axis == mv.axis) else {
        bail!("{}: the machine has no axis {}", machine.source(), mv.axis);
    };
    let [lo, hi] = machine.axes()[i].stroke_m;
    let end = pose[i] + mv.distance_m;
    if end < lo || end > hi {
        bail!(
            "--distance-mm: the move ends at {:.1} mm, outside the {} stroke [{:.1}, {:.1}] mm",
            end * 1e3,
            mv.axis,
            lo * 1e3,
            hi * 1e3
        );
    }
    // Re-assembled every 10 mm of travel (eij::sim::move_segments).
    let rate = positive("rate-hz", common.rate_hz)?;
    let segments = eij::sim::move_segments(&machine, &pose, i, mv, rate)?;
    let cond = conditions(common, &machine, &pose);
    let comp = compensate(mv, table.as_ref(), &pose, &machine);
    let sp: &dyn SetPoint = match &comp {
        Some(c) => c,
        None => mv,
    };
    let spinner = super::console::Progress::spinner("simulate: the move");
    let run = eij::sim::simulate_segments(&segments, sp)?;
    drop(spinner);
    let cl = &segments[0].closed_loop;
    let correction = comp.as_ref().map(|c| corrections(c, cl, &run));
    let mut data = MoveData::from_run(cl, &run, mv.axis, cond.source.clone())?.planned(mv);
    let (with, without) = if let Some(c) = &correction {
        data = data.nominal(cl, &run, c)?;
        // The same move without the table: what the compensation is measured against.
        let spinner = super::console::Progress::spinner("simulate: the move without compensation");
        let plain = eij::sim::simulate_segments(&segments, mv)?;
        drop(spinner);
        data.uncompensated_um = MoveData::from_run(cl, &plain, mv.axis, String::new())?
            .nominal(cl, &plain, &[])?
            .compensated_um;
        (
            peaks_um(&data.compensated_um),
            peaks_um(&data.uncompensated_um),
        )
    } else {
        // The plot keeps the structural deviation ext − int; the console states TCP − set.
        let path = data.clone().nominal(cl, &run, &[])?.compensated_um;
        (Vec::new(), peaks_um(&path))
    };
    let kind = PlotKind::Move(Box::new(data));
    write_output_files(common, cl, run, kind, cond, correction)?;
    Ok(path_deviation_line(&with, &without))
}

/// The largest |value| of each axis's series.
fn peaks_um(series: &[(Axis, Vec<f64>)]) -> Vec<(Axis, f64)> {
    series
        .iter()
        .map(|(b, d)| (*b, d.iter().fold(0.0, |m: f64, x| m.max(x.abs()))))
        .collect()
}

/// The console line of the TCP's peak deviation from the nominal path per other axis, with
/// the compensation's reduction factor when it has one.
fn path_deviation_line(with: &[(Axis, f64)], without: &[(Axis, f64)]) -> String {
    let parts: Vec<String> = without
        .iter()
        .map(|(b, w)| match with.iter().find(|(a, _)| a == b) {
            Some((_, c)) => format!("{b} {w:.3} → {c:.3} µm ({:.0}×)", w / c),
            None => format!("{b} {w:.3} µm"),
        })
        .collect();
    let how = if with.is_empty() {
        "without compensation"
    } else {
        "without → with compensation"
    };
    format!(
        "TCP deviation from the nominal path (peak |TCP − set|), {how}: {}",
        parts.join(", ")
    )
}

fn run_setpoint(
    common: &Common,
    sp: &dyn SetPoint,
    plane: Plane,
    radius_mm: f64,
) -> anyhow::Result<()> {
    let (machine, pose, table) = common.load()?;
    let (a, b) = plane.axes();
    for ax in [a, b] {
        if machine.axis(ax).is_none() {
            bail!(
                "{}: the machine has no axis {ax}, cannot run a circle in plane {plane}",
                machine.source()
            );
        }
    }
    let cl = ClosedLoop::new(&machine, &pose)?;
    let cond = conditions(common, &machine, &pose);
    let comp = compensate(sp, table.as_ref(), &pose, &machine);
    let rate = positive("rate-hz", common.rate_hz)?;
    if common.plot.is_none() {
        return stream_csv(common, &cl, sp, comp.as_ref(), rate);
    }
    let spinner = super::console::Progress::spinner("simulate: the circle");
    let run = match &comp {
        Some(c) => simulate(&cl, c, rate)?,
        None => simulate(&cl, sp, rate)?,
    };
    drop(spinner);
    let correction = comp.as_ref().map(|c| corrections(c, &cl, &run));
    write_output_files(
        common,
        &cl,
        run,
        PlotKind::Circle { radius_mm },
        cond,
        correction,
    )
}

fn conditions(common: &Common, machine: &Machine, pose: &[f64]) -> Conditions {
    Conditions {
        source: format!("simulated ({})", common.out.display()),
        machine: Some(format!(
            "{} ({})",
            machine.name(),
            common.machine.machine.display()
        )),
        position_mm: Some(pose.iter().map(|p| p * 1e3).collect()),
    }
}

/// The CSV options of `common` (the noise checked).
fn csv_options(
    common: &Common,
    correction: Option<Vec<f64>>,
) -> anyhow::Result<output::CsvOptions> {
    if !(common.noise_um.is_finite() && common.noise_um >= 0.0) {
        bail!("--noise-um: {} must be ≥ 0", common.noise_um);
    }
    Ok(output::CsvOptions {
        required_only: common.required_only,
        decimals: common.decimals,
        noise_um: common.noise_um,
        seed: common.seed,
        correction,
    })
}

/// Simulates and writes the CSV block by block into the output's temporary file (memory
/// independent of the run's length), renamed into place when the run is complete.
fn stream_csv(
    common: &Common,
    cl: &ClosedLoop,
    sp: &dyn SetPoint,
    comp: Option<&Compensated>,
    rate: f64,
) -> anyhow::Result<()> {
    let opts = csv_options(common, None)?;
    let mut out = eij::io::StreamedOutput::create(&common.out, &common.inputs())?;
    let mut csv = output::CsvStream::new(cl, &opts, comp.is_some(), out.writer())?;
    let setpoint: &dyn SetPoint = match comp {
        Some(c) => c,
        None => sp,
    };
    // A write that fails (a full disk) names the output.
    let cannot_write = || format!("{}: cannot write", common.out.display());
    let duration_s = setpoint.duration_s();
    let bar = super::console::Progress::bar((duration_s * 1e3) as u64, "simulate", "ms");
    eij::sim::simulate_blocks(cl, setpoint, rate, |block| -> anyhow::Result<()> {
        if let Some(t) = block.t_s.last() {
            bar.set((t * 1e3) as u64);
        }
        let correction = comp.map(|c| corrections(c, cl, block));
        csv.write(block, correction.as_deref())
            .with_context(cannot_write)?;
        Ok(())
    })?;
    drop(bar);
    csv.finish().with_context(cannot_write)?;
    out.commit()?;
    super::console::wrote(&[&common.out]);
    Ok(())
}

/// Writes the CSV (and the figure) of a finished run.
fn write_output_files(
    common: &Common,
    cl: &ClosedLoop,
    run: eij::sim::Run,
    kind: PlotKind,
    cond: Conditions,
    correction: Option<Vec<f64>>,
) -> anyhow::Result<()> {
    let opts = csv_options(common, correction)?;
    let bytes = output::to_csv(cl, &run, &opts);
    let plot = match (&common.plot, kind) {
        (None, _) => None,
        (Some(path), PlotKind::Circle { radius_mm }) => {
            let series = output::to_series(cl, &run, cond.source.clone())?;
            let eval = EvalOptions {
                plane: None,
                radius_mm: Some(radius_mm),
            };
            Some((path, CircleView::new(&series, &eval)?.magnified_svg(&cond)?))
        }
        (Some(path), PlotKind::Move(data)) => Some((path, move_svg(&data, &cond)?)),
    };
    let mut files: Vec<(&std::path::Path, &[u8])> = vec![(&common.out, &bytes)];
    if let Some((path, svg)) = &plot {
        files.push((path, svg.as_bytes()));
    }
    write_outputs(&files, &common.inputs())
}
