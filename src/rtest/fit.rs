//! Least-squares fits of the structural deviation (paper section 2.2–2.3): the joint linear
//! fit (primary result), the paper's plane fit (cross-talk) and ellipse fit (in-talk).

use std::collections::BTreeMap;

use nalgebra::{DMatrix, Matrix2, Vector2};

use super::lstsq::{lstsq, Lstsq};
use super::normalise::Normalised;
use crate::axes::{Axis, Eij, EijEstimates, EijMap};

/// Result of the joint fit of one circle test.
#[derive(Debug, Clone, PartialEq)]
pub struct JointFit {
    /// The six EIJ of the plane with their standard errors, µm·s²/m.
    pub eij: EijEstimates,
    /// Constant deviations c_i, µm.
    pub offsets_um: BTreeMap<Axis, f64>,
    /// Residual RMS over the three components, µm.
    pub rms_residual_um: f64,
}

/// Joint linear least squares per plane (DESIGN.md "Evaluation"; paper section 2.2):
/// d_i = E_ia ä_a + E_ib ä_b + c_i for i = a, b, k. One QR of [ä_a, ä_b, 1] serves all three
/// components; each component's standard errors use its own residual variance
/// s² = rᵀr/(n − 3), cov = s² (XᵀX)⁻¹.
pub(crate) fn joint(norm: &Normalised) -> Option<JointFit> {
    let n = norm.samples();
    let fit = joint_lstsq(norm)?;
    let (a, b) = norm.plane.axes();
    let components = [a, b, norm.plane.normal()];
    let mut eij = EijEstimates::new();
    let mut offsets_um = BTreeMap::new();
    for (col, &dev) in components.iter().enumerate() {
        for (row, acc) in [a, b].into_iter().enumerate() {
            let value = fit.coef[(row, col)];
            eij.insert(Eij::new(dev, acc), value, fit.std_err(row, col));
        }
        offsets_um.insert(dev, fit.coef[(2, col)]);
    }
    let rms_residual_um = (fit.rss.iter().sum::<f64>() / (3 * n) as f64).sqrt();
    Some(JointFit {
        eij,
        offsets_um,
        rms_residual_um,
    })
}

/// The least-squares problem of [`joint`]: [ä_a, ä_b, 1] against [d_a, d_b, d_k] (rows of
/// the coefficients: E_·a, E_·b, offset; columns: components a, b, k).
pub(crate) fn joint_lstsq(norm: &Normalised) -> Option<Lstsq> {
    let n = norm.samples();
    let [acc_a, acc_b] = &norm.acc_m_s2;
    let x = DMatrix::from_fn(n, 3, |i, j| match j {
        0 => acc_a[i],
        1 => acc_b[i],
        _ => 1.0,
    });
    let y = DMatrix::from_fn(n, 3, |i, j| norm.dev_um[j][i]);
    lstsq(x, y)
}

/// The paper's route to cross-talk: a least-squares plane d_k = p_a a_set + p_b b_set + c
/// through the out-of-plane deviation over the set position, then E_ka = −p_a/ω²,
/// E_kb = −p_b/ω² because ä = −ω² x_set on a steady circle.
///
/// With φ and ω shared, [ä_a, ä_b] = −ω² [a_set, b_set] holds sample by sample, so this is the
/// joint fit's normal row in a rescaled regressor: the two agree to rounding (theory: exactly).
/// It is kept as the paper's route and as a check of the sign and scale of ä.
pub(crate) fn plane_route(norm: &Normalised) -> Option<EijEstimates> {
    let n = norm.samples();
    let [sa, sb] = &norm.set_mm;
    let x = DMatrix::from_fn(n, 3, |i, j| match j {
        0 => sa[i] * 1e-3,
        1 => sb[i] * 1e-3,
        _ => 1.0,
    });
    let y = DMatrix::from_fn(n, 1, |i, _| norm.dev_um[2][i]);
    let fit = lstsq(x, y)?;
    let w2 = norm.omega_rad_s * norm.omega_rad_s;
    let (a, b) = norm.plane.axes();
    let k = norm.plane.normal();
    let mut eij = EijEstimates::new();
    for (row, acc) in [a, b].into_iter().enumerate() {
        let (value, se) = (-fit.coef[(row, 0)] / w2, fit.std_err(row, 0) / w2);
        eij.insert(Eij::new(k, acc), value, se);
    }
    Some(eij)
}

/// An ellipse x ᵀQ' x = 1 about its centre, in coordinates centred on the internal path's
/// centre and scaled by the radius r.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ellipse {
    /// Centre, in units of r.
    pub centre: [f64; 2],
    /// Normalised quadratic form Q' (symmetric positive definite).
    pub q: Matrix2<f64>,
}

impl Ellipse {
    /// Half-widths of the ellipse along a and b, in units of r: √((Q'⁻¹)_aa), √((Q'⁻¹)_bb).
    /// For the image (I − ε)·u of the unit circle, Q'⁻¹ = (I − ε)(I − ε)ᵀ, so the half-width
    /// along a is √((1 − ε_aa)² + ε_ab²).
    pub(crate) fn half_widths(&self) -> Option<[f64; 2]> {
        let s = self.q.try_inverse()?;
        Some([s[(0, 0)].sqrt(), s[(1, 1)].sqrt()])
    }
}

/// Least-squares general conic A u² + B uv + C v² + D u + E v = 1 through the points
/// (u, v) = ((a − a_c)/r, (b − b_c)/r). Centring and scaling make the columns O(1); on raw
/// µm-on-mm coordinates this system is ill-conditioned and is deliberately not offered.
/// `None` unless the conic is a real ellipse.
pub(crate) fn fit_ellipse(
    a: &[f64],
    b: &[f64],
    centre_mm: [f64; 2],
    radius_mm: f64,
) -> Option<Ellipse> {
    let n = a.len();
    let u = |i: usize| (a[i] - centre_mm[0]) / radius_mm;
    let v = |i: usize| (b[i] - centre_mm[1]) / radius_mm;
    let x = DMatrix::from_fn(n, 5, |i, j| match j {
        0 => u(i) * u(i),
        1 => u(i) * v(i),
        2 => v(i) * v(i),
        3 => u(i),
        _ => v(i),
    });
    let fit = lstsq(x, DMatrix::from_element(n, 1, 1.0))?;
    let c = &fit.coef;
    let q = Matrix2::new(c[0], 0.5 * c[1], 0.5 * c[1], c[2]);
    let l = Vector2::new(c[3], c[4]);
    let x0 = -0.5 * q.try_inverse()? * l;
    let kappa = 1.0 + (x0.transpose() * q * x0)[0];
    let q = q / kappa;
    let positive = q[(0, 0)] > 0.0 && q.determinant() > 0.0 && kappa > 0.0;
    positive.then_some(Ellipse {
        centre: [x0[0], x0[1]],
        q,
    })
}

/// The paper's route to in-talk: ellipses through the internal and the external path; the
/// difference ext − int of the half-widths along a and b, divided by −r ω², gives E_aa, E_bb.
///
/// Derivation: on a steady circle ä = −ω² x_set, so in units of r the external path is
/// x_ext = x_int − ε x_set (+ offset) with ε = 10⁻⁶ ω² E (E in µm·s²/m). For a circular internal
/// path the external one is the ellipse (I − ε)·u, whose half-width along a is
/// √((1 − ε_aa)² + ε_ab²) = 1 − ε_aa + ε_ab²/2 + O(ε³). The route is therefore exact to first
/// order in ε; the leading difference from the joint fit is E_ab·ε_ab/2 (µm·s²/m), i.e. of
/// relative order ε = E·rω²/r, and an elliptic internal path (half-widths 1 + g) adds terms of
/// order g·E.
#[derive(Debug, Clone, PartialEq)]
pub struct EllipseRoute {
    /// E_aa, E_bb by this route, µm·s²/m.
    pub eij: EijMap,
    /// Half-widths (a, b) of the internal path, mm.
    pub half_width_int_mm: [f64; 2],
    /// Half-widths (a, b) of the external path, mm.
    pub half_width_ext_mm: [f64; 2],
    /// The same route applied to the joint fit's noise-free model of the external path
    /// (internal readings + in-plane E·ä), see [`predict_ellipse_route`]; empty until filled.
    pub predicted_from_joint: EijMap,
}

/// Fits both ellipses over the steady revolutions and converts them to in-talk.
pub(crate) fn ellipse_route(
    norm: &Normalised,
    int_mm: [&[f64]; 2],
    ext_mm: [&[f64]; 2],
) -> Option<EllipseRoute> {
    let r = norm.radius_mm;
    let int = fit_ellipse(int_mm[0], int_mm[1], norm.centre_mm, r)?.half_widths()?;
    let ext = fit_ellipse(ext_mm[0], ext_mm[1], norm.centre_mm, r)?.half_widths()?;
    let accel = norm.accel_m_s2();
    let (a, b) = norm.plane.axes();
    let mut eij = BTreeMap::new();
    for (i, ax) in [a, b].into_iter().enumerate() {
        let diff_um = (ext[i] - int[i]) * r * 1e3;
        eij.insert(Eij::new(ax, ax), -diff_um / accel);
    }
    Some(EllipseRoute {
        eij,
        half_width_int_mm: int.map(|w| w * r),
        half_width_ext_mm: ext.map(|w| w * r),
        predicted_from_joint: BTreeMap::new(),
    })
}

/// What the ellipse route would return if the external path were exactly the joint fit's
/// model: x_ext = x_int + (E_p ä)/1000 mm with the in-plane 2×2 block E_p of `eij`. The route's
/// own nonlinearity (second order in ε, the internal path's ellipticity) is then the same for
/// both, so the measured route differs from this prediction by noise only.
pub(crate) fn predict_ellipse_route(
    norm: &Normalised,
    int_mm: [&[f64]; 2],
    eij: &EijEstimates,
) -> Option<EijMap> {
    let (a, b) = norm.plane.axes();
    let e = |i: Axis, j: Axis| eij.value(&Eij::new(i, j));
    let (eaa, eab, eba, ebb) = (e(a, a)?, e(a, b)?, e(b, a)?, e(b, b)?);
    let [acc_a, acc_b] = &norm.acc_m_s2;
    let model = |k: usize, ea: f64, eb: f64| -> Vec<f64> {
        int_mm[k]
            .iter()
            .zip(acc_a.iter().zip(acc_b))
            .map(|(x, (aa, ab))| x + (ea * aa + eb * ab) * 1e-3)
            .collect()
    };
    let (pa, pb) = (model(0, eaa, eab), model(1, eba, ebb));
    Some(ellipse_route(norm, int_mm, [&pa, &pb])?.eij)
}
