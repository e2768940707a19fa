//! Set-point generators: circles (paper eq. 3–4) with smooth ramps, and jerk-limited moves.
//!
//! A set point gives, for every machine axis, position (m, relative to the start/centre),
//! velocity (m/s) and acceleration (m/s²) at time t, laid out as the closed loop's inputs
//! `(x_set, v_set, a_set)` per axis.

use crate::axes::{Axis, Direction, Plane};

/// Anything that feeds the closed loop's inputs over time.
pub trait SetPoint {
    /// Total duration, s.
    fn duration_s(&self) -> f64;
    /// Fills `out[3·i .. 3·i+3]` = (position, velocity, acceleration) of machine axis `axes[i]`.
    fn eval(&self, t: f64, axes: &[Axis], out: &mut [f64]);
}

/// Smootherstep s(τ) = 6τ⁵ − 15τ⁴ + 10τ³ on [0, 1]: its first and second derivatives vanish at
/// both ends, so the angular acceleration and the set jerk stay continuous.
fn smootherstep(tau: f64) -> (f64, f64) {
    let t = tau.clamp(0.0, 1.0);
    let s = t * t * t * (10.0 + t * (-15.0 + 6.0 * t));
    let ds = 30.0 * t * t * (1.0 - t) * (1.0 - t);
    (s, ds)
}

/// ∫₀^τ s(x) dx = τ⁶ − 3τ⁵ + 2.5τ⁴.
fn smootherstep_integral(tau: f64) -> f64 {
    let t = tau.clamp(0.0, 1.0);
    t * t * t * t * (2.5 + t * (-3.0 + t))
}

/// A circle a = r·cos θ, b = r·sin θ in plane (a, b) (paper eq. 3–4), θ̇ = ω = ±√(a_set/r) in the
/// steady part, with a smooth ramp of the angular speed in and out. It starts at rest at
/// (a, b) = (r, 0) relative to the circle centre and ends at rest on the circle.
#[derive(Debug, Clone, PartialEq)]
pub struct Circle {
    /// Plane.
    pub plane: Plane,
    /// Radius, m.
    pub radius_m: f64,
    /// Steady set acceleration r·ω², m/s².
    pub accel_m_s2: f64,
    /// Sense of rotation.
    pub direction: Direction,
    /// Whole steady revolutions.
    pub steady_revolutions: u32,
    /// Duration of each ramp, in steady revolution periods.
    pub ramp_periods: f64,
    /// Rest after the ramp-out, s.
    pub settle_s: f64,
}

impl Circle {
    /// A circle with the defaults used by `eij simulate circle`: 5 steady revolutions, ramps of
    /// two periods, 50 ms rest at the end.
    pub fn new(plane: Plane, radius_m: f64, accel_m_s2: f64, direction: Direction) -> Self {
        Circle {
            plane,
            radius_m,
            accel_m_s2,
            direction,
            steady_revolutions: 5,
            ramp_periods: 2.0,
            settle_s: 0.05,
        }
    }

    /// Signed steady angular speed ω, rad/s.
    pub fn omega(&self) -> f64 {
        self.direction.sign() * (self.accel_m_s2 / self.radius_m).sqrt()
    }

    /// Steady frequency, Hz.
    pub fn frequency_hz(&self) -> f64 {
        self.omega().abs() / std::f64::consts::TAU
    }

    fn period_s(&self) -> f64 {
        std::f64::consts::TAU / self.omega().abs()
    }

    fn ramp_s(&self) -> f64 {
        self.ramp_periods * self.period_s()
    }

    /// Angle, angular speed and angular acceleration at t.
    pub fn angle(&self, t: f64) -> (f64, f64, f64) {
        let w = self.omega();
        let tr = self.ramp_s();
        let ts = self.steady_revolutions as f64 * self.period_s();
        if t <= tr {
            let tau = t / tr;
            let (s, ds) = smootherstep(tau);
            (w * tr * smootherstep_integral(tau), w * s, w * ds / tr)
        } else if t <= tr + ts {
            let theta0 = w * tr * 0.5;
            (theta0 + w * (t - tr), w, 0.0)
        } else {
            let tau = ((t - tr - ts) / tr).min(1.0);
            let (s, ds) = smootherstep(tau);
            let theta1 = w * tr * 0.5 + w * ts;
            (
                theta1 + w * tr * (tau - smootherstep_integral(tau)),
                w * (1.0 - s),
                -w * ds / tr,
            )
        }
    }
}

impl SetPoint for Circle {
    fn duration_s(&self) -> f64 {
        2.0 * self.ramp_s() + self.steady_revolutions as f64 * self.period_s() + self.settle_s
    }

    fn eval(&self, t: f64, axes: &[Axis], out: &mut [f64]) {
        out.fill(0.0);
        let (th, w, dw) = self.angle(t);
        let r = self.radius_m;
        let (c, s) = (th.cos(), th.sin());
        let (a, b) = self.plane.axes();
        for (i, ax) in axes.iter().enumerate() {
            let v = if *ax == a {
                [r * c, -r * s * w, -r * c * w * w - r * s * dw]
            } else if *ax == b {
                [r * s, r * c * w, -r * s * w * w + r * c * dw]
            } else {
                continue;
            };
            out[3 * i..3 * i + 3].copy_from_slice(&v);
        }
    }
}

/// A jerk-limited point-to-point move of one axis (seven phases: jerk +, constant acceleration,
/// jerk −, cruise, jerk −, constant deceleration, jerk +). Where the distance is too short for a
/// limit, the profile degrades: the peak velocity drops first, then the peak acceleration
/// (down to a_peak = (D·j²/2)^(1/3), see [`JerkLimitedMove::new`]).
#[derive(Debug, Clone, PartialEq)]
pub struct JerkLimitedMove {
    /// The moving axis.
    pub axis: Axis,
    /// Signed distance, m.
    pub distance_m: f64,
    /// Peak velocity actually reached, m/s.
    pub peak_velocity_m_s: f64,
    /// Peak acceleration actually reached, m/s².
    pub peak_accel_m_s2: f64,
    /// Jerk, m/s³.
    pub jerk_m_s3: f64,
    /// Duration of a jerk phase, s.
    pub t_jerk_s: f64,
    /// Duration of a constant-acceleration phase, s.
    pub t_accel_s: f64,
    /// Duration of the cruise, s.
    pub t_cruise_s: f64,
    /// Rest before the move, s.
    pub lead_s: f64,
    /// Rest after the move, s.
    pub settle_s: f64,
}

impl JerkLimitedMove {
    /// Plans the move from the limits (all > 0). With v the peak velocity, the distance needed
    /// to accelerate from rest to v and back is v·(v/a + a/j) when v ≥ a²/j (acceleration limit
    /// reached) and 2·v·√(v/j) otherwise. If the velocity limit cannot be reached,
    /// v solves v²/a + v·a/j = D (then a is reached) or v = (D²·j/4)^(1/3) with
    /// a_peak = √(v·j) (then it is not: the paper's 20 mm move at 250 m/s³ peaks at 8.55 m/s²).
    pub fn new(axis: Axis, distance_m: f64, v_max: f64, a_max: f64, j_max: f64) -> Self {
        let d = distance_m.abs();
        let ramp_distance = |v: f64| {
            if v >= a_max * a_max / j_max {
                v * (v / a_max + a_max / j_max)
            } else {
                2.0 * v * (v / j_max).sqrt()
            }
        };
        let v_peak = if ramp_distance(v_max) <= d {
            v_max
        } else {
            let with_a = 0.5
                * a_max
                * (-a_max / j_max + (a_max * a_max / (j_max * j_max) + 4.0 * d / a_max).sqrt());
            if with_a >= a_max * a_max / j_max {
                with_a
            } else {
                (d * d * j_max / 4.0).cbrt()
            }
        };
        let a_peak = a_max.min((v_peak * j_max).sqrt());
        let t_jerk = a_peak / j_max;
        let t_accel = if a_peak < a_max {
            0.0
        } else {
            (v_peak / a_peak - t_jerk).max(0.0)
        };
        let t_cruise = if v_peak > 0.0 {
            ((d - ramp_distance(v_peak)) / v_peak).max(0.0)
        } else {
            0.0
        };
        JerkLimitedMove {
            axis,
            distance_m,
            peak_velocity_m_s: v_peak,
            peak_accel_m_s2: a_peak,
            jerk_m_s3: j_max,
            t_jerk_s: t_jerk,
            t_accel_s: t_accel,
            t_cruise_s: t_cruise,
            lead_s: 0.02,
            settle_s: 0.1,
        }
    }

    fn phases(&self) -> [(f64, f64); 7] {
        let j = self.jerk_m_s3;
        [
            (self.t_jerk_s, j),
            (self.t_accel_s, 0.0),
            (self.t_jerk_s, -j),
            (self.t_cruise_s, 0.0),
            (self.t_jerk_s, -j),
            (self.t_accel_s, 0.0),
            (self.t_jerk_s, j),
        ]
    }

    /// Position, velocity, acceleration along the move at time t (exact piecewise cubic).
    pub fn state(&self, t: f64) -> (f64, f64, f64) {
        let sign = self.distance_m.signum();
        let mut tau = t - self.lead_s;
        if tau <= 0.0 {
            return (0.0, 0.0, 0.0);
        }
        let (mut p, mut v, mut a) = (0.0, 0.0, 0.0);
        for (dt, j) in self.phases() {
            let h = tau.min(dt);
            p += v * h + a * h * h / 2.0 + j * h * h * h / 6.0;
            v += a * h + j * h * h / 2.0;
            a += j * h;
            tau -= dt;
            if tau <= 0.0 {
                return (sign * p, sign * v, sign * a);
            }
        }
        (self.distance_m, 0.0, 0.0)
    }

    /// The time at which the set position has covered `fraction` (0…1) of the distance
    /// (the profile is monotonic; bisection to 1e-12 s).
    pub fn time_at_fraction(&self, fraction: f64) -> f64 {
        let target = fraction.clamp(0.0, 1.0) * self.distance_m;
        let (mut lo, mut hi) = (self.lead_s, self.lead_s + self.motion_s());
        while hi - lo > 1e-12 {
            let mid = 0.5 * (lo + hi);
            let (p, _, _) = self.state(mid);
            if (p - target) * self.distance_m.signum() < 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        hi
    }

    /// Duration of the motion itself (without the rests), s.
    pub fn motion_s(&self) -> f64 {
        self.phases().iter().map(|(dt, _)| dt).sum()
    }
}

impl SetPoint for JerkLimitedMove {
    fn duration_s(&self) -> f64 {
        self.lead_s + self.motion_s() + self.settle_s
    }

    fn eval(&self, t: f64, axes: &[Axis], out: &mut [f64]) {
        out.fill(0.0);
        if let Some(i) = axes.iter().position(|a| *a == self.axis) {
            let (p, v, a) = self.state(t);
            out[3 * i..3 * i + 3].copy_from_slice(&[p, v, a]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_move_peaks_at_8_55_m_s2() {
        let m = JerkLimitedMove::new(Axis::Z, 0.02, 0.5, 10.0, 250.0);
        // Neither limit is reached: v = (D²·j/4)^(1/3), a_peak = √(v·j) = (D·j²/2)^(1/3).
        let v = (0.02f64 * 0.02 * 250.0 / 4.0).cbrt();
        assert!((m.peak_velocity_m_s - v).abs() < 1e-12);
        assert!((m.peak_accel_m_s2 - (v * 250.0).sqrt()).abs() < 1e-12);
        assert!((m.peak_accel_m_s2 - (0.02f64 * 250.0 * 250.0 / 2.0).cbrt()).abs() < 1e-12);
        assert!((m.peak_accel_m_s2 - 8.55).abs() < 0.005);
        assert_eq!(m.t_accel_s, 0.0);
        let (p, v_end, a_end) = m.state(m.lead_s + m.motion_s());
        assert!((p - 0.02).abs() < 1e-12 && v_end.abs() < 1e-12 && a_end.abs() < 1e-9);
    }

    #[test]
    fn long_move_reaches_all_limits_and_the_distance() {
        let m = JerkLimitedMove::new(Axis::X, -0.3, 0.5, 10.0, 250.0);
        assert_eq!(m.peak_velocity_m_s, 0.5);
        assert_eq!(m.peak_accel_m_s2, 10.0);
        assert!(m.t_cruise_s > 0.0 && m.t_accel_s > 0.0);
        let (p, v, _) = m.state(m.lead_s + m.motion_s());
        assert!((p + 0.3).abs() < 1e-12 && v.abs() < 1e-12);
        // Cruise velocity in the middle.
        let (_, v_mid, a_mid) = m.state(m.lead_s + m.motion_s() / 2.0);
        assert!((v_mid + 0.5).abs() < 1e-12 && a_mid.abs() < 1e-12);
    }

    #[test]
    fn medium_move_reaches_acceleration_but_not_velocity() {
        // a²/j = 0.4 m/s; D = 0.04 m: v solves v²/10 + 0.04·v = 0.04 → v = 0.4633
        let m = JerkLimitedMove::new(Axis::Y, 0.04, 0.5, 10.0, 250.0);
        assert_eq!(m.peak_accel_m_s2, 10.0);
        assert!((m.peak_velocity_m_s - 0.4633249580710799).abs() < 1e-12);
        assert_eq!(m.t_cruise_s, 0.0);
        let (p, _, _) = m.state(m.duration_s());
        assert!((p - 0.04).abs() < 1e-12);
    }

    #[test]
    fn circle_set_points_are_consistent_derivatives() {
        let c = Circle::new(Plane::Zx, 0.002, 5.0, Direction::Ccw);
        assert!((c.frequency_hz() - 7.957747154594767).abs() < 1e-12);
        let axes = [Axis::X, Axis::Y, Axis::Z];
        let mut u0 = [0.0; 9];
        let mut u1 = [0.0; 9];
        let mut um = [0.0; 9];
        let h = 1e-6;
        // Ramp-in, steady and ramp-out: finite differences of position/velocity match.
        for t in [0.05, 0.2, 0.5, 0.95, c.duration_s() - 0.2] {
            c.eval(t - h, &axes, &mut u0);
            c.eval(t + h, &axes, &mut u1);
            c.eval(t, &axes, &mut um);
            for i in [0, 2] {
                let dp = (u1[3 * i] - u0[3 * i]) / (2.0 * h);
                let dv = (u1[3 * i + 1] - u0[3 * i + 1]) / (2.0 * h);
                assert!((dp - um[3 * i + 1]).abs() < 1e-7, "velocity at t={t}");
                assert!((dv - um[3 * i + 2]).abs() < 1e-5, "acceleration at t={t}");
            }
        }
        // Steady part: |a| = r·ω² = 5 m/s², z = r·cos, x = r·sin, ccw.
        c.eval(0.6, &axes, &mut um);
        let acc = (um[2].powi(2) + um[8].powi(2)).sqrt();
        assert!((acc - 5.0).abs() < 1e-12);
        // Starts and ends at rest.
        c.eval(0.0, &axes, &mut um);
        assert_eq!(um, [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.002, 0.0, 0.0]);
        c.eval(c.duration_s(), &axes, &mut um);
        assert!(um[1].abs() < 1e-15 && um[7].abs() < 1e-15 && um[2].abs() < 1e-12);
    }
}
