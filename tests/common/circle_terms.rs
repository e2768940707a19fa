//! Synthetic circle tests with known ballbar-style errors in the axes (internal path) and in
//! the structure (external − internal), written from the physical description of each error,
//! independently of the diagnosis' regressors:
//!
//! * axes: each in-plane axis follows its set point r·(cos ψ, sin ψ), ψ = ψ₀ + ωt, late by its
//!   own lag τ (servo), a(t) = r cos(ψ − ωτ_a), b(t) = r sin(ψ − ωτ_b) (exact, not linearised);
//! * on the lagged path (a, b) with velocity v = (ȧ, ḃ): radius δ·(a, b)/r, scale mismatch
//!   (m/2)·(a, −b)/r, squareness as a shear of axis b towards a, a += α·b (α µm/m),
//!   straightness k_a (a²/r² − ½) across axis a, lost motion −(β/2)·sgn(v) along each axis,
//!   a spike h·e^{−Δt/τ} outward after each reversal of an axis (Δt since its velocity last
//!   passed zero, from its phase), lateral play (λ/2)·sgn(v_a) across axis a, cyclic error A cos(2π a/P + φ) along
//!   each axis, the out-of-plane offset, tilt t·(a, b), saddle and play (s/2)·sgn(v);
//! * a rotation ρ of the path about the normal, ρ·(−b, a); a clock of the external readings
//!   running ε faster than the internal ones, which read the path at t + ε·(t − t_mid):
//!   ε·(t − t_mid)·v, t_mid the middle of the recording (meant for the structure);
//! * structure: the same errors added to external − internal, plus EIJ d = E·ä with ä the
//!   internal path's acceleration −ω²(a, b);
//! * Gaussian noise on the internal and the external readings (ChaCha8, seeded).
//!
//! The file is also the demo set's generator (`examples/diagnosis_demo.rs`).
#![allow(dead_code)]

use eij::axes::{Axis, Plane};
use eij::rtest::CircleSeries;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use std::f64::consts::{PI, TAU};

/// Errors of one source, in the units of the diagnosis' terms.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Errors {
    /// Centre offset (a, b), µm.
    pub centre_um: [f64; 2],
    /// Radius deviation, µm.
    pub radius_um: f64,
    /// Scale mismatch: a travels m/2 further, b m/2 less over the radius, µm.
    pub scale_mismatch_um: f64,
    /// Squareness: the angle between the axes is 90° − α, µm/m.
    pub squareness_um_per_m: f64,
    /// Lag of each in-plane axis behind its set point, ms (the internal path only).
    pub lag_ms: [f64; 2],
    /// Lost motion (backlash) of each in-plane axis, µm.
    pub backlash_um: [f64; 2],
    /// Reversal spike height of each in-plane axis, µm, and its decay time, ms.
    pub spike_um: [f64; 2],
    /// Decay time of the spikes, ms.
    pub spike_decay_ms: f64,
    /// Lateral play of each in-plane axis, µm.
    pub lateral_play_um: [f64; 2],
    /// Straightness (bow, ends minus middle) of each in-plane axis, µm.
    pub straightness_um: [f64; 2],
    /// Cyclic error: pitch, mm; amplitude per axis, µm; phase per axis, rad.
    pub cyclic: Option<(f64, [f64; 2], [f64; 2])>,
    /// EIJ, µm·s²/m: rows deviation a, b, k; columns accelerated a, b.
    pub eij: [[f64; 2]; 3],
    /// Out-of-plane offset, µm.
    pub normal_offset_um: f64,
    /// Out-of-plane tilt along a and b, µm/m.
    pub tilt_um_per_m: [f64; 2],
    /// Out-of-plane saddle: amplitude of cos 2θ and sin 2θ, µm.
    pub saddle_um: [f64; 2],
    /// Out-of-plane step when each in-plane axis reverses, µm.
    pub normal_play_um: [f64; 2],
    /// Rotation of the path about the normal, µm/m (µrad).
    pub rotation_um_per_m: f64,
    /// Rate of the clock against the internal one's, µm/m (ppm), about the recording's middle.
    pub clock_rate_um_per_m: f64,
}

/// One synthetic circle test.
#[derive(Debug, Clone, PartialEq)]
pub struct TermCircle {
    pub plane: Plane,
    pub ccw: bool,
    pub radius_mm: f64,
    pub accel_m_s2: f64,
    pub sample_hz: f64,
    /// Revolutions recorded, all at constant speed (the evaluation keeps the whole ones
    /// more than a quarter revolution from either end).
    pub revolutions: f64,
    /// Set angle at t = 0, rad.
    pub start_rad: f64,
    pub internal: Errors,
    pub structure: Errors,
    pub int_noise_um: f64,
    pub ext_noise_um: f64,
    pub seed: u64,
}

impl TermCircle {
    /// r = 2 mm, 2 kHz, 4.6 revolutions, noise 0.2 µm (axes) and 0.5 µm (R-Test), no errors.
    pub fn new(plane: Plane, ccw: bool, accel_m_s2: f64) -> Self {
        TermCircle {
            plane,
            ccw,
            radius_mm: 2.0,
            accel_m_s2,
            sample_hz: 2000.0,
            revolutions: 4.6,
            start_rad: 0.3,
            internal: Errors::default(),
            structure: Errors::default(),
            int_noise_um: 0.2,
            ext_noise_um: 0.5,
            seed: 1,
        }
    }

    /// Signed angular speed, rad/s.
    pub fn omega(&self) -> f64 {
        let w = (self.accel_m_s2 / (self.radius_mm * 1e-3)).sqrt();
        if self.ccw {
            w
        } else {
            -w
        }
    }

    /// Time, internal and external readings (x, y, z order), mm.
    pub fn columns(&self) -> (Vec<f64>, [Vec<f64>; 3], [Vec<f64>; 3]) {
        let w = self.omega();
        let r = self.radius_mm;
        let n = (self.revolutions * TAU / w.abs() * self.sample_hz) as usize;
        let t: Vec<f64> = (0..n).map(|i| i as f64 / self.sample_hz).collect();
        let lag = self.internal.lag_ms.map(|l| l * 1e-3);
        // The lagged internal path, its velocity and each axis' time since its last reversal
        // (a reverses where its phase passes kπ, b where its phase passes π/2 + kπ).
        let path: Vec<Point> = t
            .iter()
            .map(|&ti| {
                let (pa, pb) = (
                    self.start_rad + w * (ti - lag[0]),
                    self.start_rad + w * (ti - lag[1]),
                );
                let since = [pa, pb - 0.5 * PI].map(|p| (w.signum() * p).rem_euclid(PI) / w.abs());
                Point {
                    t: ti,
                    p: [r * pa.cos(), r * pb.sin()],
                    v: [-r * w * pa.sin(), r * w * pb.cos()],
                    since,
                }
            })
            .collect();
        let t_mid = 0.5 * t.last().copied().unwrap_or(0.0);
        let int_dev = deviations(&self.internal, &path, r, w, t_mid);
        let str_dev = deviations(&self.structure, &path, r, w, t_mid);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(self.seed);
        let noise = |sigma: f64| Normal::new(0.0, sigma.max(1e-15)).unwrap();
        let (n_int, n_ext) = (noise(self.int_noise_um), noise(self.ext_noise_um));
        let (a, b) = self.plane.axes();
        let k = self.plane.normal();
        let mut int_mm: [Vec<f64>; 3] = Default::default();
        let mut ext_mm: [Vec<f64>; 3] = Default::default();
        for i in 0..n {
            let nominal = [path[i].p[0], path[i].p[1], 0.0];
            for (j, ax) in [a, b, k].into_iter().enumerate() {
                let int = nominal[j] + (int_dev[i][j] + n_int.sample(&mut rng)) * 1e-3;
                let ext = int + (str_dev[i][j] + n_ext.sample(&mut rng)) * 1e-3;
                int_mm[ax.index()].push(int);
                ext_mm[ax.index()].push(ext);
            }
        }
        (t, int_mm, ext_mm)
    }

    /// The test as an in-memory series.
    pub fn series(&self) -> CircleSeries {
        let (t, int, ext) = self.columns();
        CircleSeries::new(self.label(), t, int, ext).unwrap()
    }

    /// `synthetic xy ccw 5 m/s²`.
    pub fn label(&self) -> String {
        format!(
            "synthetic {} {} {} m/s²",
            self.plane,
            if self.ccw { "ccw" } else { "cw" },
            self.accel_m_s2
        )
    }
}

fn sgn(x: f64) -> f64 {
    if x == 0.0 {
        0.0
    } else {
        x.signum()
    }
}

/// A point of the internal path.
struct Point {
    /// Time, s.
    t: f64,
    /// Position (a, b), mm.
    p: [f64; 2],
    /// Velocity, mm/s.
    v: [f64; 2],
    /// Time since each axis last reversed, s.
    since: [f64; 2],
}

/// The deviation (a, b, k), µm, of `e` along the path (`t_mid`: the clock's reference time).
fn deviations(e: &Errors, path: &[Point], r: f64, w: f64, t_mid: f64) -> Vec<[f64; 3]> {
    let mut out = Vec::with_capacity(path.len());
    for Point { t, p, v, since } in path {
        let (pa, pb) = (p[0] / r, p[1] / r);
        let mut d = [
            e.centre_um[0] + e.radius_um * pa + 0.5 * e.scale_mismatch_um * pa,
            e.centre_um[1] + e.radius_um * pb - 0.5 * e.scale_mismatch_um * pb,
            e.normal_offset_um,
        ];
        d[0] += e.squareness_um_per_m * p[1] * 1e-3;
        // Rotation ρ µrad of a point p mm: ρ·(−b, a)·10⁻³ µm; the clock: ε·10⁻⁶·(t − t_mid)·v mm.
        d[0] -= e.rotation_um_per_m * p[1] * 1e-3;
        d[1] += e.rotation_um_per_m * p[0] * 1e-3;
        for (ax, d_ax) in d.iter_mut().take(2).enumerate() {
            *d_ax += e.clock_rate_um_per_m * (t - t_mid) * v[ax] * 1e-3;
        }
        d[1] += e.straightness_um[0] * (pa * pa - 0.5);
        d[0] += e.straightness_um[1] * (pb * pb - 0.5);
        for ax in 0..2 {
            let other = 1 - ax;
            let s = sgn(v[ax]);
            d[ax] -= 0.5 * e.backlash_um[ax] * s;
            if e.spike_um[ax] != 0.0 {
                d[ax] -= s * e.spike_um[ax] * (-since[ax] / (e.spike_decay_ms * 1e-3)).exp();
            }
            d[other] += 0.5 * e.lateral_play_um[ax] * s;
            d[2] += 0.5 * e.normal_play_um[ax] * s;
            if let Some((pitch, amp, phase)) = e.cyclic {
                d[ax] += amp[ax] * (TAU * p[ax] / pitch + phase[ax]).cos();
            }
        }
        let acc = [-w * w * p[0] * 1e-3, -w * w * p[1] * 1e-3];
        for (row, d_row) in d.iter_mut().enumerate() {
            *d_row += e.eij[row][0] * acc[0] + e.eij[row][1] * acc[1];
        }
        let theta = p[1].atan2(p[0]);
        d[2] += (e.tilt_um_per_m[0] * p[0] + e.tilt_um_per_m[1] * p[1]) * 1e-3
            + e.saddle_um[0] * (2.0 * theta).cos()
            + e.saddle_um[1] * (2.0 * theta).sin();
        out.push(d);
    }
    out
}

/// The axis of in-plane index `i` (0 = a, 1 = b) of `plane`.
pub fn axis(plane: Plane, i: usize) -> Axis {
    let (a, b) = plane.axes();
    [a, b][i]
}
