//! Normalisation of a circle test (paper eq. 5–6): plane, centre, radius, phase, steady whole
//! revolutions, ω and the set accelerations, plus the plausibility checks on units and range.

use super::error::{Location, RtestError};
use super::lstsq::lstsq;
use super::series::{CircleSeries, INT_COLUMNS};
use super::EvalOptions;
use crate::axes::{Axis, Plane};
use nalgebra::DMatrix;
use std::f64::consts::{PI, TAU};

pub use super::checks::PROBE_RANGE_MM;
use super::checks::{check_external, check_probe_range, check_time_scale, check_units};
/// Relative band around the plateau angular speed that counts as steady.
pub(crate) const STEADY_TOLERANCE: f64 = 0.005;

/// The wider band of the first pass, whose phase is taken about the mid-range centre: a centre
/// off by δ makes the local speed ripple by ±δ/r (a file that starts at rest on the set radius
/// while the steady path runs on a smaller one puts the mid-range off by half the difference).
const COARSE_TOLERANCE: f64 = 0.03;
/// Fewest samples per revolution accepted.
pub const MIN_SAMPLES_PER_REVOLUTION: usize = 36;
/// Smallest in-plane half-amplitude (mm) that counts as motion.
const MIN_MOTION_MM: f64 = 1e-3;

/// A circle test reduced to its steady whole revolutions, in the plane's coordinates
/// (a, b in-plane as in eq. 3–4, k the normal).
#[derive(Debug, Clone, PartialEq)]
pub struct Normalised {
    /// The circle plane.
    pub plane: Plane,
    /// Radius r used for the set points, mm (the given set radius, else the mean internal one).
    pub radius_mm: f64,
    /// Mean internal radius about the fitted centre over the steady revolutions, mm.
    pub measured_radius_mm: f64,
    /// Centre (a, b) of the internal path, mm.
    pub centre_mm: [f64; 2],
    /// Angular speed ω, rad/s, from a straight-line fit of the unwrapped phase over time;
    /// positive is ccw.
    pub omega_rad_s: f64,
    /// First sample of the steady whole revolutions.
    pub first: usize,
    /// One past the last sample of the steady whole revolutions.
    pub end: usize,
    /// Number of whole revolutions in `first..end`.
    pub revolutions: usize,
    /// Set positions a_set = r cos φ, b_set = r sin φ (eq. 6), mm, over `first..end`.
    pub set_mm: [Vec<f64>; 2],
    /// Set accelerations ä_a = −r ω² cos φ, ä_b = −r ω² sin φ, m/s², over `first..end`.
    pub acc_m_s2: [Vec<f64>; 2],
    /// Structural deviation d = external − internal (section 2.2) along a, b, k, µm.
    pub dev_um: [Vec<f64>; 3],
}

impl Normalised {
    /// Set acceleration magnitude r ω², m/s².
    pub fn accel_m_s2(&self) -> f64 {
        self.radius_mm * 1e-3 * self.omega_rad_s * self.omega_rad_s
    }

    /// Revolutions per second |ω| / 2π.
    pub fn freq_hz(&self) -> f64 {
        self.omega_rad_s.abs() / TAU
    }

    /// Samples in the steady whole revolutions.
    pub fn samples(&self) -> usize {
        self.end - self.first
    }
}

/// Normalises `series`: infers (or takes) the plane and radius, checks units and probe range,
/// finds the steady whole revolutions and computes the phase φ_k = atan2(b − b_c, a − a_c) from
/// the internal readings (eq. 5), the set points and set accelerations (eq. 6).
///
/// The phase comes from the internal readings, never from time: a servo lag of 2° would
/// otherwise rotate the acceleration vector and leak in-talk into cross-talk.
pub fn normalise(series: &CircleSeries, opts: &EvalOptions) -> Result<Normalised, RtestError> {
    let whole = || Location::source(series.source());
    if let Some(r) = opts.radius_mm {
        if !(r.is_finite() && r > 0.0) {
            return Err(RtestError::BadValue {
                at: whole(),
                column: "radius_mm".into(),
                message: format!("set radius {r} must be a positive number of mm"),
            });
        }
    }
    let amp_int = Axis::ALL.map(|ax| half_amplitude(series.int_mm(ax)));
    let amp_ext = Axis::ALL.map(|ax| half_amplitude(series.ext_mm(ax)));
    let plane = match opts.plane {
        Some(p) => p,
        None => infer_plane(&amp_int, &whole)?,
    };
    let (a, b) = plane.axes();
    let k = plane.normal();
    for ax in [a, b] {
        if amp_int[ax.index()] < MIN_MOTION_MM {
            return Err(RtestError::NoMotion {
                at: whole(),
                detail: format!(
                    "{} moves ±{:.3e} mm in plane {plane}",
                    INT_COLUMNS[ax.index()],
                    amp_int[ax.index()]
                ),
            });
        }
    }
    check_units(series, plane, &amp_int, &amp_ext, opts.radius_mm)?;
    check_external(series, plane, &amp_int, &amp_ext)?;
    check_probe_range(series)?;

    let (ai, bi) = (series.int_mm(a), series.int_mm(b));
    let t = series.t_s();
    // The mid-range is centre enough to find the steady part; the least-squares centre of the
    // steady revolutions follows.
    // Two passes: the mid-range centre finds the steady part roughly, the least-squares centre
    // of that part gives the phase whose speed plateau decides the whole revolutions.
    let centre0 = [mid_range(ai), mid_range(bi)];
    let phase0 = unwrapped_phase(ai, bi, centre0);
    let (f0, e0, _) = steady_revolutions(t, &phase0, COARSE_TOLERANCE, &whole)?;
    let centre1 = circle_centre(&ai[f0..e0], &bi[f0..e0]).unwrap_or(centre0);
    let phase1 = unwrapped_phase(ai, bi, centre1);
    let (first, end, revolutions) = steady_revolutions(t, &phase1, STEADY_TOLERANCE, &whole)?;
    let spr = (end - first) / revolutions;
    if spr < MIN_SAMPLES_PER_REVOLUTION {
        return Err(RtestError::TooShort {
            at: whole(),
            detail: format!(
                "only {spr} samples per revolution, at least {MIN_SAMPLES_PER_REVOLUTION} needed"
            ),
        });
    }

    let (aw, bw) = (&ai[first..end], &bi[first..end]);
    let centre = circle_centre(aw, bw).ok_or_else(|| RtestError::Singular {
        at: whole(),
        detail: "cannot fit the centre of the steady revolutions".into(),
    })?;
    let phase = unwrapped_phase(aw, bw, centre);
    let n = phase.len();
    // cos φ and sin φ straight from the readings: (a − a_c)/ρ, (b − b_c)/ρ.
    let mut cos_sin = Vec::with_capacity(n);
    let mut radius_sum = 0.0;
    for (x, y) in aw.iter().zip(bw) {
        let (u, v) = (x - centre[0], y - centre[1]);
        let rho = (u * u + v * v).sqrt();
        radius_sum += rho;
        cos_sin.push((u / rho, v / rho));
    }
    let measured_radius_mm = radius_sum / n as f64;
    let radius_mm = match opts.radius_mm {
        Some(set) => {
            if (measured_radius_mm - set).abs() > 0.1 * set {
                return Err(RtestError::RadiusMismatch {
                    at: whole(),
                    measured_mm: measured_radius_mm,
                    set_mm: set,
                });
            }
            set
        }
        None => measured_radius_mm,
    };
    let omega_rad_s = slope(&t[first..end], &phase);
    check_time_scale(series, radius_mm, omega_rad_s)?;

    let r_m = radius_mm * 1e-3;
    let w2 = omega_rad_s * omega_rad_s;
    let mut set_mm = [Vec::with_capacity(n), Vec::with_capacity(n)];
    let mut acc_m_s2 = [Vec::with_capacity(n), Vec::with_capacity(n)];
    for &(c, s) in &cos_sin {
        set_mm[0].push(radius_mm * c);
        set_mm[1].push(radius_mm * s);
        acc_m_s2[0].push(-r_m * w2 * c);
        acc_m_s2[1].push(-r_m * w2 * s);
    }
    let dev_um = [a, b, k].map(|ax| {
        series.ext_mm(ax)[first..end]
            .iter()
            .zip(&series.int_mm(ax)[first..end])
            .map(|(e, i)| (e - i) * 1e3)
            .collect()
    });
    Ok(Normalised {
        plane,
        radius_mm,
        measured_radius_mm,
        centre_mm: centre,
        omega_rad_s,
        first,
        end,
        revolutions,
        set_mm,
        acc_m_s2,
        dev_um,
    })
}

fn min_max(v: &[f64]) -> (f64, f64) {
    v.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
            (lo.min(x), hi.max(x))
        })
}

fn half_amplitude(v: &[f64]) -> f64 {
    let (lo, hi) = min_max(v);
    (hi - lo) / 2.0
}

fn mid_range(v: &[f64]) -> f64 {
    let (lo, hi) = min_max(v);
    (hi + lo) / 2.0
}

/// The plane of the two axes with the largest internal amplitude; the third must be small.
fn infer_plane(amp: &[f64; 3], whole: &dyn Fn() -> Location) -> Result<Plane, RtestError> {
    let detail = || {
        format!(
            "half-amplitudes x {:.4} mm, y {:.4} mm, z {:.4} mm",
            amp[0], amp[1], amp[2]
        )
    };
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &j| amp[j].total_cmp(&amp[i]));
    let (second, third) = (amp[order[1]], amp[order[2]]);
    if second < MIN_MOTION_MM {
        return Err(RtestError::NoMotion {
            at: whole(),
            detail: detail(),
        });
    }
    if third > 0.2 * second {
        return Err(RtestError::AmbiguousPlane {
            at: whole(),
            detail: detail(),
        });
    }
    Ok(match order[2] {
        0 => Plane::Yz,
        1 => Plane::Zx,
        _ => Plane::Xy,
    })
}

/// Algebraic (Kåsa) circle fit a² + b² = 2 a_c a + 2 b_c b + c by QR least squares, on
/// mean-centred data for conditioning. Returns the centre (a_c, b_c).
pub fn circle_centre(a: &[f64], b: &[f64]) -> Option<[f64; 2]> {
    let n = a.len();
    let (ma, mb) = (mean(a), mean(b));
    let x = DMatrix::from_fn(n, 3, |i, j| match j {
        0 => a[i] - ma,
        1 => b[i] - mb,
        _ => 1.0,
    });
    let y = DMatrix::from_fn(n, 1, |i, _| {
        let (u, v) = (a[i] - ma, b[i] - mb);
        u * u + v * v
    });
    let fit = lstsq(x, y)?;
    Some([ma + 0.5 * fit.coef[(0, 0)], mb + 0.5 * fit.coef[(1, 0)]])
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

/// φ_k = atan2(b − b_c, a − a_c) (eq. 5), unwrapped to a continuous sequence.
pub(crate) fn unwrapped_phase(a: &[f64], b: &[f64], centre: [f64; 2]) -> Vec<f64> {
    let mut out = Vec::with_capacity(a.len());
    let mut prev_raw = 0.0;
    let mut acc = 0.0;
    for (i, (x, y)) in a.iter().zip(b).enumerate() {
        let raw = (y - centre[1]).atan2(x - centre[0]);
        if i == 0 {
            acc = raw;
        } else {
            let mut d = raw - prev_raw;
            if d > PI {
                d -= TAU;
            } else if d < -PI {
                d += TAU;
            }
            acc += d;
        }
        prev_raw = raw;
        out.push(acc);
    }
    out
}

/// Least-squares slope of y over t (straight line with intercept).
fn slope(t: &[f64], y: &[f64]) -> f64 {
    let (mt, my) = (mean(t), mean(y));
    let (mut sty, mut stt) = (0.0, 0.0);
    for (ti, yi) in t.iter().zip(y) {
        sty += (ti - mt) * (yi - my);
        stt += (ti - mt) * (ti - mt);
    }
    sty / stt
}

/// Finds the steady part and keeps only whole revolutions of it.
///
/// The local angular speed at sample k is half a revolution of phase divided by the time the
/// path takes for it: π / (t(u_k + π/2) − t(u_k − π/2)), with u the unwrapped phase in the
/// sense of rotation. The window is defined in phase, not in samples, so every ripple of the
/// speed that repeats every half revolution (an elliptic internal path: axes with different
/// gains or lags, ±ε at 2ω) cancels exactly, whatever the sampling, its jitter or its gaps.
/// The times at the window ends come from a straight line t(u) fitted through the samples
/// within ±1/16 revolution of each end, which averages timestamp jitter. The plateau speed is
/// first taken as the 90th percentile of the speeds above half the largest one (dwells and
/// slow ramp parts do not count) and refined as the median over the plateau; the plateau is
/// the longest run within `tolerance` of that speed. Of it the largest whole number of
/// revolutions is kept, centred, so that the ramp-in and ramp-out are trimmed alike. Returns
/// `(first, end, revolutions)`.
fn steady_revolutions(
    t: &[f64],
    phase: &[f64],
    tolerance: f64,
    whole: &dyn Fn() -> Location,
) -> Result<(usize, usize, usize), RtestError> {
    let n = phase.len();
    let total = phase[n - 1] - phase[0];
    let sign = if total >= 0.0 { 1.0 } else { -1.0 };
    let too_short = |what: String| RtestError::TooShort {
        at: whole(),
        detail: what,
    };
    if total.abs() < TAU {
        return Err(too_short(format!(
            "only {:.3} revolution(s) in all, at least one whole steady revolution needed",
            total.abs() / TAU
        )));
    }
    let u: Vec<f64> = phase.iter().map(|p| sign * p).collect();
    // The smoothing window is about 1/16 of a plateau revolution: guessed from the mean rate
    // over the whole file, and set from the plateau speed where that guess is more than twice
    // too wide (long dwells).
    let mut dt: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    let mid = dt.len() / 2;
    let dt_median = *dt.select_nth_unstable_by(mid, f64::total_cmp).1;
    let smoothing = |samples_per_rev: f64| ((samples_per_rev / 16.0) as usize).clamp(1, 64);
    let mut m = smoothing(n as f64 * TAU / total.abs());
    let (speed, reference) = loop {
        let speed = half_revolution_speed(t, &u, m);
        let top = speed
            .iter()
            .copied()
            .filter(|w| w.is_finite())
            .fold(f64::NEG_INFINITY, f64::max);
        // `top` is the largest finite speed (or −∞ where there is none): never NaN.
        if top <= 0.0 {
            return Err(too_short("no steady rotation found".into()));
        }
        let mut fast: Vec<f64> = speed.iter().copied().filter(|&w| w >= 0.5 * top).collect();
        let q = (fast.len() * 9) / 10;
        let reference = *fast.select_nth_unstable_by(q, f64::total_cmp).1;
        let m_plateau = smoothing(TAU / (reference * dt_median));
        if 2 * m_plateau >= m {
            break (speed, reference);
        }
        m = m_plateau;
    };
    let mut scratch = Vec::new();
    let (mut k0, mut k1) = longest_run(&speed, reference, tolerance);
    let step = stride(m);
    scratch.clear();
    scratch.extend_from_slice(&speed[k0..=k1]);
    let mid = scratch.len() / 2;
    let median = *scratch.select_nth_unstable_by(mid, f64::total_cmp).1;
    (k0, k1) = longest_run(&speed, median, tolerance);
    let (k0, k1) = (k0 * step, k1 * step);
    let span = u[k1] - u[k0];
    let revolutions = (span / TAU + 1e-9).floor();
    if revolutions < 1.0 {
        return Err(too_short(format!(
            "only {:.3} steady revolution(s), at least one whole steady revolution needed",
            span.max(0.0) / TAU
        )));
    }
    let slack = span - revolutions * TAU;
    let first = (k0..=k1)
        .find(|&k| u[k] - u[k0] >= 0.5 * slack)
        .unwrap_or(k0);
    // The window ends (exclusive) at the sample nearest to whole revolutions after `first`:
    // a strict `≥` would, on rounding, take one sample more now and then, so that EIJ jump by
    // ~1e-4 relative between neighbouring parameter values (a noisy cost for identification).
    let end = (first + 1..=k1)
        .find(|&k| u[k] - u[first] >= revolutions * TAU - 0.5 * (u[k] - u[k - 1]))
        .unwrap_or(k1 + 1);
    Ok((first, end, revolutions as usize))
}

/// Samples between two speed evaluations: half the smoothing window, about 1/32 revolution.
fn stride(m: usize) -> usize {
    m.div_ceil(2)
}

/// The local angular speed π / (t(u_k + π/2) − t(u_k − π/2)) of every [`stride`]-th sample k
/// (NaN where the
/// half revolution around it leaves the record), the window ends smoothed over ±`m` samples;
/// see [`steady_revolutions`].
fn half_revolution_speed(t: &[f64], u: &[f64], m: usize) -> Vec<f64> {
    let n = u.len();
    // The running maximum is monotone: the first sample reaching a phase is found by bisection
    // even where the phase wobbles at rest.
    let mut reach = Vec::with_capacity(n);
    let mut top = f64::NEG_INFINITY;
    for &v in u {
        top = top.max(v);
        reach.push(top);
    }
    // The first sample at or past `target`, walking from the previous answer (the targets of
    // successive samples move little).
    let first_reaching = |j: &mut usize, target: f64| -> Option<usize> {
        while *j > 0 && reach[*j - 1] >= target {
            *j -= 1;
        }
        while *j < n && reach[*j] < target {
            *j += 1;
        }
        (*j > 0 && *j < n).then_some(*j)
    };
    let (mut j_lo, mut j_hi) = (0, 0);
    (0..n)
        .step_by(stride(m))
        .map(|k| {
            let (lo, hi) = (u[k] - 0.25 * TAU, u[k] + 0.25 * TAU);
            match (first_reaching(&mut j_lo, lo), first_reaching(&mut j_hi, hi)) {
                (Some(a), Some(b)) => {
                    let dt = local_time(t, u, b, hi, m) - local_time(t, u, a, lo, m);
                    if dt > 0.0 {
                        PI / dt
                    } else {
                        f64::NAN
                    }
                }
                _ => f64::NAN,
            }
        })
        .collect()
}

/// The time at which the phase reaches `target`, from a straight line t(u) through the samples
/// `j − m ..= j + m` (j the first sample at or past the target); the straight line between
/// samples j − 1 and j where the phase barely moves over that window (rest).
fn local_time(t: &[f64], u: &[f64], j: usize, target: f64, m: usize) -> f64 {
    let lo = j.saturating_sub(m);
    let hi = (j + m).min(t.len() - 1);
    let k = (hi + 1 - lo) as f64;
    let (mu, mt) = (
        u[lo..=hi].iter().sum::<f64>() / k,
        t[lo..=hi].iter().sum::<f64>() / k,
    );
    let (mut suu, mut sut) = (0.0, 0.0);
    for i in lo..=hi {
        suu += (u[i] - mu) * (u[i] - mu);
        sut += (u[i] - mu) * (t[i] - mt);
    }
    let linear = || {
        let (u0, u1) = (u[j - 1], u[j]);
        let f = if u1 > u0 {
            (target - u0) / (u1 - u0)
        } else {
            1.0
        };
        t[j - 1] + f * (t[j] - t[j - 1])
    };
    if suu > 0.0 && sut > 0.0 {
        mt + sut / suu * (target - mu)
    } else {
        linear()
    }
}

/// Longest run of `speed` within `tolerance` (relative) of `reference`, as inclusive indices.
fn longest_run(speed: &[f64], reference: f64, tolerance: f64) -> (usize, usize) {
    let tol = tolerance * reference;
    let (mut best, mut start) = ((0, 0), None);
    let mut best_len = 0;
    for (k, s) in speed.iter().enumerate() {
        if (s - reference).abs() <= tol {
            let s0 = *start.get_or_insert(k);
            if k + 1 - s0 > best_len {
                best_len = k + 1 - s0;
                best = (s0, k);
            }
        } else {
            start = None;
        }
    }
    best
}
