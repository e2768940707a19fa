//! Synthetic R-Test circle tests with known EIJ.
//!
//! The generator (independent of the evaluation code):
//! * set phase ψ(t): a dwell at rest, a raised-cosine ramp-in of the angular speed from 0 to
//!   ω₀ = √(a/r), a plateau of `steady_revs` revolutions at ω₀, the mirrored ramp-out, a dwell;
//!   sign +1 for ccw, −1 for cw (CONTRACT.md: a = r cos ωt, b = r sin ωt);
//! * internal path: the set circle with a servo lag proportional to speed (`lag_deg` at ω₀),
//!   axis radius errors (`radius_err_um`, a and b) and a centre offset (`centre_mm`);
//! * phase φ = atan2(b_int − b_c, a_int − a_c) about the true centre, set acceleration
//!   ä = −r ω(t)² (cos φ, sin φ) (tangential ramp terms are left out: the ramps are not
//!   evaluated), set position r (cos φ, sin φ);
//! * external = internal + (E·ä + G·x_set + offsets + Gaussian noise σ) / 1000 (µm → mm), with
//!   E the 3×2 EIJ of the plane (rows a, b, k; columns a, b) and G static geometric terms
//!   (µm per mm of set position);
//! * optional reading noise on the internal readings (`int_noise_um`);
//! * noise: xorshift64* + Box–Muller, deterministic from `seed`.
use std::collections::BTreeMap;
use std::f64::consts::PI;
use std::path::Path;

use eij::axes::{Eij, Plane};
use eij::rtest::CircleSeries;

/// One synthetic circle test.
#[derive(Debug, Clone)]
pub struct Synth {
    pub plane: Plane,
    pub ccw: bool,
    pub radius_mm: f64,
    pub accel_m_s2: f64,
    pub sample_hz: f64,
    pub dwell_s: f64,
    /// Revolutions covered by each ramp.
    pub ramp_revs: f64,
    /// Revolutions at constant speed.
    pub steady_revs: f64,
    pub lag_deg: f64,
    pub radius_err_um: [f64; 2],
    pub centre_mm: [f64; 3],
    pub ext_offset_um: [f64; 3],
    /// EIJ, µm·s²/m: rows deviation a, b, k; columns accelerated a, b.
    pub e: [[f64; 2]; 3],
    /// Static geometric terms, µm/mm: rows deviation a, b, k; columns set position a, b.
    pub g_um_per_mm: [[f64; 2]; 3],
    pub noise_um: f64,
    /// Reading noise of the internal measuring systems, µm (the external reading stays
    /// internal position + deviation: d = ext − int then carries this noise too).
    pub int_noise_um: f64,
    pub seed: u64,
}

impl Synth {
    /// The default test of the brief: r = 2 mm, 1 kHz, 2° lag, +3/−2 µm radius errors,
    /// centre and offsets, σ = 1.4 µm, EIJ of a few µm·s²/m.
    pub fn new(plane: Plane, ccw: bool, accel_m_s2: f64) -> Self {
        Synth {
            plane,
            ccw,
            radius_mm: 2.0,
            accel_m_s2,
            sample_hz: 1000.0,
            dwell_s: 0.05,
            ramp_revs: 1.0,
            steady_revs: 5.5,
            lag_deg: 2.0,
            radius_err_um: [3.0, -2.0],
            centre_mm: [0.012, -0.021, 0.007],
            ext_offset_um: [1.5, -0.7, 0.3],
            e: [[2.5, -0.8], [0.6, 1.7], [-1.55, 0.9]],
            g_um_per_mm: [[0.0; 2]; 3],
            noise_um: 1.4,
            int_noise_um: 0.0,
            seed: 0x9E37_79B9_7F4A_7C15,
        }
    }

    /// Noise-free with a circular internal path (no axis radius errors).
    pub fn exact(mut self) -> Self {
        self.noise_um = 0.0;
        self.radius_err_um = [0.0, 0.0];
        self
    }

    /// The true EIJ by name.
    pub fn truth(&self) -> BTreeMap<Eij, f64> {
        let (a, b) = self.plane.axes();
        let mut m = BTreeMap::new();
        for (i, dev) in [a, b, self.plane.normal()].into_iter().enumerate() {
            for (j, acc) in [a, b].into_iter().enumerate() {
                m.insert(Eij::new(dev, acc), self.e[i][j]);
            }
        }
        m
    }

    /// The true geometric terms, keyed like EIJ.
    pub fn truth_geometric(&self) -> BTreeMap<Eij, f64> {
        let (a, b) = self.plane.axes();
        let mut m = BTreeMap::new();
        for (i, dev) in [a, b, self.plane.normal()].into_iter().enumerate() {
            for (j, acc) in [a, b].into_iter().enumerate() {
                m.insert(Eij::new(dev, acc), self.g_um_per_mm[i][j]);
            }
        }
        m
    }

    pub fn omega0(&self) -> f64 {
        (self.accel_m_s2 / (self.radius_mm * 1e-3)).sqrt()
    }

    /// Columns t, int[x,y,z], ext[x,y,z].
    pub fn columns(&self) -> (Vec<f64>, [Vec<f64>; 3], [Vec<f64>; 3]) {
        let w0 = self.omega0();
        let t_rev = 2.0 * PI / w0;
        let t_ramp = 2.0 * self.ramp_revs * t_rev;
        let t_plateau = self.steady_revs * t_rev;
        let total = 2.0 * self.dwell_s + 2.0 * t_ramp + t_plateau;
        let n = (total * self.sample_hz).floor() as usize + 1;
        let sign = if self.ccw { 1.0 } else { -1.0 };
        let (a, b) = self.plane.axes();
        let k = self.plane.normal();
        let idx = [a.index(), b.index(), k.index()];
        let mut rng = Rng::new(self.seed);
        let mut t_s = Vec::with_capacity(n);
        let mut int: [Vec<f64>; 3] = Default::default();
        let mut ext: [Vec<f64>; 3] = Default::default();
        let r = self.radius_mm;
        for s in 0..n {
            let t = s as f64 / self.sample_hz;
            let (psi, w) = phase(t - self.dwell_s, w0, t_ramp, t_plateau);
            let lag = self.lag_deg.to_radians() * w / w0;
            let psi_int = sign * psi - sign * lag;
            let c = [
                self.centre_mm[idx[0]],
                self.centre_mm[idx[1]],
                self.centre_mm[idx[2]],
            ];
            let pi = [
                c[0] + (r + self.radius_err_um[0] * 1e-3) * psi_int.cos(),
                c[1] + (r + self.radius_err_um[1] * 1e-3) * psi_int.sin(),
                c[2],
            ];
            let phi = (pi[1] - c[1]).atan2(pi[0] - c[0]);
            let acc = [-r * 1e-3 * w * w * phi.cos(), -r * 1e-3 * w * w * phi.sin()];
            let set = [r * phi.cos(), r * phi.sin()];
            let mut pe = [0.0; 3];
            for i in 0..3 {
                let d_um = self.e[i][0] * acc[0]
                    + self.e[i][1] * acc[1]
                    + self.g_um_per_mm[i][0] * set[0]
                    + self.g_um_per_mm[i][1] * set[1]
                    + self.ext_offset_um[idx[i]]
                    + self.noise_um * rng.gauss();
                pe[i] = pi[i] + d_um * 1e-3;
            }
            t_s.push(t);
            for i in 0..3 {
                let reading_noise = if self.int_noise_um > 0.0 {
                    self.int_noise_um * 1e-3 * rng.gauss()
                } else {
                    0.0
                };
                int[idx[i]].push(pi[i] + reading_noise);
                ext[idx[i]].push(pe[i]);
            }
        }
        (t_s, int, ext)
    }

    pub fn series(&self) -> CircleSeries {
        let (t, int, ext) = self.columns();
        CircleSeries::new(format!("synthetic {:?}", self.plane), t, int, ext)
            .expect("synthetic series is valid")
    }

    /// Writes the CONTRACT.md CSV (columns deliberately not in the documented order, plus an
    /// ignored extra column).
    pub fn write_csv(&self, path: &Path) {
        let (t, int, ext) = self.columns();
        let mut s =
            String::from("x_ext_mm,t_s,comment,x_int_mm,y_int_mm,z_int_mm,y_ext_mm,z_ext_mm\n");
        for i in 0..t.len() {
            s.push_str(&format!(
                "{},{},ok,{},{},{},{},{}\n",
                ext[0][i], t[i], int[0][i], int[1][i], int[2][i], ext[1][i], ext[2][i]
            ));
        }
        std::fs::write(path, s).expect("write synthetic csv");
    }
}

/// Phase ψ and angular speed ω at time t after the dwell (raised-cosine ramps).
fn phase(t: f64, w0: f64, t_ramp: f64, t_plateau: f64) -> (f64, f64) {
    if t <= 0.0 {
        return (0.0, 0.0);
    }
    let ramp_phase = 0.5 * w0 * t_ramp;
    if t < t_ramp {
        let x = PI * t / t_ramp;
        return (
            0.5 * w0 * (t - t_ramp / PI * x.sin()),
            0.5 * w0 * (1.0 - x.cos()),
        );
    }
    let t = t - t_ramp;
    if t < t_plateau {
        return (ramp_phase + w0 * t, w0);
    }
    let t = t - t_plateau;
    let base = ramp_phase + w0 * t_plateau;
    if t < t_ramp {
        let x = PI * t / t_ramp;
        return (
            base + 0.5 * w0 * (t + t_ramp / PI * x.sin()),
            0.5 * w0 * (1.0 + x.cos()),
        );
    }
    (base + ramp_phase, 0.0)
}

/// xorshift64* with Box–Muller.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Rng(seed.max(1))
    }

    pub fn next_u64(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        x.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// Uniform in (0, 1].
    fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 1.0) / (1u64 << 53) as f64
    }

    pub fn gauss(&mut self) -> f64 {
        let (u1, u2) = (self.uniform(), self.uniform());
        (-2.0 * u1.ln()).sqrt() * (2.0 * PI * u2).cos()
    }
}

/// CSV text in the documented column order from columns t, int[x,y,z], ext[x,y,z].
pub fn csv_text(t: &[f64], int: &[Vec<f64>; 3], ext: &[Vec<f64>; 3]) -> String {
    let mut s = String::from("t_s,x_int_mm,y_int_mm,z_int_mm,x_ext_mm,y_ext_mm,z_ext_mm\n");
    for i in 0..t.len() {
        s.push_str(&format!(
            "{},{},{},{},{},{},{}\n",
            t[i], int[0][i], int[1][i], int[2][i], ext[0][i], ext[1][i], ext[2][i]
        ));
    }
    s
}
