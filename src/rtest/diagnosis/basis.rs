//! The regressors of the circle diagnosis: every named term as the deviation it causes at the
//! nominal angle θ of the circle (formulas in docs/diagnosis.md).
//!
//! In-plane terms are vectors g(θ) = (g_a, g_b) in µm per unit of the term's value; the fit
//! projects them on the radial unit u = (cos θ, sin θ) and the tangential unit
//! t = (−sin θ, cos θ). Out-of-plane terms are scalars along the plane's normal k.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// What the regressors need to know about the circle besides θ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Circle {
    /// Set radius r, mm.
    pub radius_mm: f64,
    /// Signed angular speed ω, rad/s (positive ccw).
    pub omega_rad_s: f64,
    /// Decay time of a reversal spike, s.
    pub spike_decay_s: f64,
    /// Pitch of the cyclic error, mm (`None`: no cyclic terms).
    pub cyclic_pitch_mm: Option<f64>,
    /// The nominal angle at the middle of the samples, rad (θ is continuous, not wrapped).
    pub theta_mid_rad: f64,
}

impl Circle {
    /// +1 ccw, −1 cw.
    pub(crate) fn sense(&self) -> f64 {
        self.omega_rad_s.signum()
    }

    /// The sign of the nominal velocity of in-plane axis `axis` (0 = a, 1 = b) at θ:
    /// v_a = −rω sin θ, v_b = rω cos θ.
    pub(crate) fn velocity_sign(&self, axis: usize, theta: f64) -> f64 {
        let v = if axis == 0 { -theta.sin() } else { theta.cos() };
        sign(self.sense() * v)
    }
}

/// −1, 0 or +1 (0 at exactly 0, unlike `f64::signum`).
fn sign(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// An angle wrapped to (−π, π].
pub(crate) fn wrap(angle: f64) -> f64 {
    let w = angle.rem_euclid(TAU);
    if w > PI {
        w - TAU
    } else {
        w
    }
}

/// A reversal point of an in-plane axis: where it stops and turns, at the extremes of the
/// circle. `axis` 0 = a (θ = 0: side `+`, θ = π: side `−`), 1 = b (θ = π/2: `+`, 3π/2: `−`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Crossing {
    /// In-plane axis index: 0 = a, 1 = b.
    pub axis: usize,
    /// True at the axis' positive extreme.
    pub positive: bool,
}

impl Crossing {
    /// The four reversal points in the order a+, a−, b+, b−.
    pub(crate) const ALL: [Crossing; 4] = [
        Crossing {
            axis: 0,
            positive: true,
        },
        Crossing {
            axis: 0,
            positive: false,
        },
        Crossing {
            axis: 1,
            positive: true,
        },
        Crossing {
            axis: 1,
            positive: false,
        },
    ];

    /// The nominal angle θ_c of the reversal.
    pub(crate) fn angle(self) -> f64 {
        let base = if self.axis == 0 { 0.0 } else { FRAC_PI_2 };
        if self.positive {
            base
        } else {
            base + PI
        }
    }

    /// The outward unit n_c at the reversal (along the reversing axis).
    pub(crate) fn outward(self) -> [f64; 2] {
        let s = if self.positive { 1.0 } else { -1.0 };
        if self.axis == 0 {
            [s, 0.0]
        } else {
            [0.0, s]
        }
    }

    /// Signed angle travelled since the reversal, in the sense of motion, within (−π, π].
    fn since(self, circle: &Circle, theta: f64) -> f64 {
        circle.sense() * wrap(theta - self.angle())
    }
}

/// One column of the in-plane design: a unit value of it displaces the path by
/// [`InPlane::vector`] µm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum InPlane {
    /// A constant shift along a (µm).
    CentreA,
    /// A constant shift along b (µm).
    CentreB,
    /// A radius error: δ·u (µm).
    Radius,
    /// A rotation of the path about the centre, µm/m (µrad): ρ·r·(−sin θ, cos θ).
    Rotation,
    /// A path speed off the nominal angle's, µm/m (ppm of the feed): the tangential ramp
    /// ε·r·(θ − θ_mid)·(−sin θ, cos θ). It takes up what the straight line θ(t) leaves (a
    /// first harmonic of the phase biases its slope) and, in external − internal, a clock
    /// that runs at another rate.
    FeedDeviation,
    /// Axis a travelling m/2 further, b m/2 less over the radius (µm): ½(cos θ, −sin θ).
    ScaleMismatch,
    /// The angle between the axes 90° − α, α in µm/m (µrad): (α r/2)(sin θ, cos θ), the
    /// rotation-free (symmetric) part of the shear; the 45° ellipse.
    Squareness,
    /// Axis a bowed in b: e_b = k (a²/r² − ½) = (k/2) cos 2θ (µm, ends minus middle).
    StraightnessA,
    /// Axis b bowed in a: e_a = k (b²/r² − ½) = −(k/2) cos 2θ (µm).
    StraightnessB,
    /// Lost motion at a reversal: ±½ along the outward normal within a quarter revolution
    /// either side, − before, + after the reversal in time (µm, step height).
    Backlash(Crossing),
    /// A spike along the outward normal after the reversal, decaying as e^{−Δt/τ} until the
    /// axis reverses again half a revolution later (µm, height at the reversal).
    Spike(Crossing),
    /// A sideways shift of the axis (index 0 = a, 1 = b) across its motion, flipping with its
    /// direction: ½ sgn(v_axis) along the other in-plane axis (µm, shift between directions).
    LateralPlay(usize),
    /// Cyclic error along axis (0 = a, 1 = b): harmonic h of its position x with the pitch P,
    /// cos(2πh x/P) (false) or −sin(2πh x/P) (true), so that values (c, s) are the error
    /// A cos(2πh x/P + φ) with A = √(c² + s²), φ = atan2(s, c) (µm).
    Cyclic(usize, usize, bool),
}

impl InPlane {
    /// The displacement (a, b), µm, of a unit value of the column at nominal angle θ.
    pub(crate) fn vector(&self, circle: &Circle, theta: f64) -> [f64; 2] {
        let (s, c) = theta.sin_cos();
        let r_m = circle.radius_mm * 1e-3;
        match *self {
            InPlane::CentreA => [1.0, 0.0],
            InPlane::CentreB => [0.0, 1.0],
            InPlane::Radius => [c, s],
            InPlane::Rotation => [-r_m * s, r_m * c],
            InPlane::FeedDeviation => {
                let arc = r_m * (theta - circle.theta_mid_rad);
                [-arc * s, arc * c]
            }
            InPlane::ScaleMismatch => [0.5 * c, -0.5 * s],
            InPlane::Squareness => [0.5 * r_m * s, 0.5 * r_m * c],
            InPlane::StraightnessA => [0.0, 0.5 * (2.0 * theta).cos()],
            InPlane::StraightnessB => [-0.5 * (2.0 * theta).cos(), 0.0],
            InPlane::Backlash(x) => {
                let since = x.since(circle, theta);
                if since.abs() < FRAC_PI_2 {
                    let n = x.outward();
                    let h = 0.5 * sign(since);
                    [h * n[0], h * n[1]]
                } else {
                    [0.0, 0.0]
                }
            }
            InPlane::Spike(x) => {
                let since = x.since(circle, theta);
                if (0.0..PI).contains(&since) {
                    let dt = since / circle.omega_rad_s.abs();
                    let h = (-dt / circle.spike_decay_s).exp();
                    let n = x.outward();
                    [h * n[0], h * n[1]]
                } else {
                    [0.0, 0.0]
                }
            }
            InPlane::LateralPlay(axis) => {
                let h = 0.5 * circle.velocity_sign(axis, theta);
                if axis == 0 {
                    [0.0, h]
                } else {
                    [h, 0.0]
                }
            }
            InPlane::Cyclic(axis, harmonic, sine) => {
                let pitch = circle.cyclic_pitch_mm.unwrap_or(f64::INFINITY);
                let position = circle.radius_mm * if axis == 0 { c } else { s };
                let arg = TAU * harmonic as f64 * position / pitch;
                let v = if sine { -arg.sin() } else { arg.cos() };
                if axis == 0 {
                    [v, 0.0]
                } else {
                    [0.0, v]
                }
            }
        }
    }
}

/// One column of the out-of-plane design: a unit value moves the path by
/// [`Normal::value`] µm along the plane's normal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Normal {
    /// A constant offset (µm).
    Offset,
    /// A tilt of the path's plane, µm/m: r cos θ (false) or r sin θ (true).
    Tilt(bool),
    /// A saddle (µm): cos 2θ (false) or sin 2θ (true).
    Saddle(bool),
    /// A step of the normal when the axis (0 = a, 1 = b) reverses: ½ sgn(v_axis) (µm).
    Play(usize),
}

impl Normal {
    /// The normal displacement, µm, of a unit value of the column at θ.
    pub(crate) fn value(&self, circle: &Circle, theta: f64) -> f64 {
        let r_m = circle.radius_mm * 1e-3;
        match *self {
            Normal::Offset => 1.0,
            Normal::Tilt(false) => r_m * theta.cos(),
            Normal::Tilt(true) => r_m * theta.sin(),
            Normal::Saddle(false) => (2.0 * theta).cos(),
            Normal::Saddle(true) => (2.0 * theta).sin(),
            Normal::Play(axis) => 0.5 * circle.velocity_sign(axis, theta),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn circle(omega: f64) -> Circle {
        Circle {
            radius_mm: 2.0,
            omega_rad_s: omega,
            spike_decay_s: 0.01,
            cyclic_pitch_mm: Some(1.0),
            theta_mid_rad: 0.0,
        }
    }

    /// Lost motion: an axis lags by β/2 in its direction of motion, e_a = −(β/2) sgn(v_a);
    /// the two a-crossing columns with equal values are exactly that, in both senses.
    #[test]
    fn backlash_pair_is_lost_motion() {
        for omega in [10.0, -10.0] {
            let c = circle(omega);
            for k in 0..360 {
                let theta = (k as f64 + 0.5).to_radians();
                let sum: f64 = [Crossing::ALL[0], Crossing::ALL[1]]
                    .iter()
                    .map(|x| InPlane::Backlash(*x).vector(&c, theta)[0])
                    .sum();
                assert_eq!(sum, -0.5 * c.velocity_sign(0, theta), "θ {k}°, ω {omega}");
            }
        }
    }

    /// A lag τ_a of axis a on a = r cos ωt gives a ≈ r cos ωt + rωτ_a sin ωt; with τ_b = 0 the
    /// rotation-free part is the squareness column at α = ωτ_a, the rest a rotation by −α/2.
    #[test]
    fn servo_lag_is_apparent_squareness_plus_rotation() {
        let c = circle(30.0);
        let tau = 1e-3;
        let alpha_urad = c.omega_rad_s * tau * 1e6;
        for k in 0..36 {
            let theta = (k as f64 * 10.0).to_radians();
            let r_um = c.radius_mm * 1e3;
            let lag = [r_um * c.omega_rad_s * tau * theta.sin(), 0.0];
            let sq = InPlane::Squareness.vector(&c, theta);
            let rot = InPlane::Rotation.vector(&c, theta);
            for i in 0..2 {
                let model = alpha_urad * sq[i] - 0.5 * alpha_urad * rot[i];
                assert!(
                    (model - lag[i]).abs() < 1e-9 * r_um,
                    "θ {k}: {model} {}",
                    lag[i]
                );
            }
        }
    }
}
