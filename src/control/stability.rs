//! A cheap and rigorous stability check for closed loops close to one already checked: a
//! Lyapunov certificate.
//!
//! For a stable closed loop, balanced to B = S⁻¹AS (the scaling of [`super::FrequencyForm`]),
//! the Lyapunov equation BᵀP + PB = −I has a symmetric positive definite solution P. Any other
//! state matrix A′ with P ≻ 0 and B′ᵀP + PB′ ≺ 0 (B′ = S⁻¹A′S) is stable as well: V = zᵀPz
//! decreases along every trajectory (Lyapunov's theorem). Checking that costs one matrix
//! product and one Cholesky factorisation (O(n³) with a small constant, about a tenth of the
//! non-symmetric eigenvalue problem), and it holds for the small changes of a finite-difference
//! Jacobian (a stiffness 1e-3 relative), where B′ᵀP + PB′ stays near −I. Far from the loop it
//! was made for the certificate fails, and the full eigenvalue check decides — so the verdict
//! is the same as that check's, only cheaper where the certificate applies.
//!
//! P comes from the eigen-decomposition B = VΛV⁻¹: with X = VᴴPV the equation reads
//! ΛᴴX + XΛ = −VᴴV, so X_ij = −(VᴴV)_ij / (λ̄_i + λ_j) and P = V⁻ᴴXV⁻¹. An inaccurate P (an
//! ill-conditioned V) does no harm: the certificate is accepted only when it proves stability
//! of the loop it was made from.

use faer::linalg::solvers::DenseSolveCore;
use faer::{c64, Mat, Side};
use nalgebra::DMatrix;
use std::sync::{Arc, Mutex};

/// Margin of the negative definiteness test, relative to ‖B′ᵀP + PB′‖_F (rounding of the
/// product is ~n·ε of it).
const MARGIN: f64 = 1e-9;

/// A Lyapunov certificate P for closed loops of one state dimension and balancing.
#[derive(Debug, Clone)]
pub struct Certificate {
    /// The balancing S of the loop it was made from (A → S⁻¹AS).
    scale: Vec<f64>,
    /// P, symmetric positive definite.
    p: Mat<f64>,
}

impl Certificate {
    /// The certificate of the stable state matrix `a`; `None` when `a` is not (strictly)
    /// stable or no certificate proves it (e.g. undamped modes on the imaginary axis).
    pub fn new(a: &DMatrix<f64>) -> Option<Certificate> {
        let n = a.nrows();
        let mut balanced = a.clone();
        let scale = nalgebra::linalg::balancing::balance_parlett_reinsch(&mut balanced);
        let b = Mat::<f64>::from_fn(n, n, |i, j| balanced[(i, j)]);
        let eig = b.eigen().ok()?;
        let v = eig.U().to_owned();
        let lambda: Vec<c64> = (0..n).map(|k| eig.S()[k]).collect();
        if lambda.iter().any(|l| l.re.is_nan() || l.re >= 0.0) {
            return None;
        }
        let w = v.adjoint() * &v;
        let x = Mat::<c64>::from_fn(n, n, |i, j| -w[(i, j)] / (lambda[i].conj() + lambda[j]));
        let v_inv = v.partial_piv_lu().inverse();
        let p_c = v_inv.adjoint() * &x * &v_inv;
        let p = Mat::<f64>::from_fn(n, n, |i, j| 0.5 * (p_c[(i, j)].re + p_c[(j, i)].re));
        if !p.norm_l2().is_finite() || p.llt(Side::Lower).is_err() {
            return None;
        }
        let cert = Certificate {
            scale: scale.iter().copied().collect(),
            p,
        };
        cert.certifies(a).then_some(cert)
    }

    /// Whether this certificate proves the state matrix `a` stable.
    pub fn certifies(&self, a: &DMatrix<f64>) -> bool {
        let n = self.scale.len();
        if a.nrows() != n || a.ncols() != n {
            return false;
        }
        let s = &self.scale;
        let b = Mat::<f64>::from_fn(n, n, |i, j| a[(i, j)] * s[j] / s[i]);
        let g = &self.p * &b;
        let mut m = Mat::<f64>::from_fn(n, n, |i, j| -(g[(i, j)] + g[(j, i)]));
        let norm = m.norm_l2();
        if !norm.is_finite() {
            return false;
        }
        for i in 0..n {
            m[(i, i)] -= MARGIN * norm;
        }
        m.llt(Side::Lower).is_ok()
    }
}

/// The certificate of the latest closed loop checked in full at one circle centre, shared by
/// the closed loops built there afterwards (in parallel; which certificate a loop meets never
/// changes its verdict, only what the check costs). The first loop at a centre is checked by
/// its eigenvalues alone: a certificate costs about twice that and pays only where more loops
/// follow (a Jacobian's, not a map's one loop per grid point).
///
/// A certificate pays only when it proves loops after the one it was made from. Where the
/// loops have lightly damped modes (an elastic body's, ζ ≈ 1 % at kHz), P is large along them
/// and a finite-difference step already breaks B′ᵀP + PB′ ≺ 0: each new certificate proves its
/// own loop and no other, and renewing it costs several eigenvalue checks per loop. So after
/// [`MAX_WASTED_RENEWALS`] certificates in a row that proved no further loop, this centre stops
/// making them and the eigenvalues decide (the same verdict; only the cost changes).
#[derive(Debug, Default)]
pub struct NearbyCertificate(Mutex<Slot>);

/// Certificates in a row that proved no loop but their own, after which a centre makes no more
/// (one: a certificate that proved nothing says the next will not either, and costs several
/// eigenvalue checks).
pub const MAX_WASTED_RENEWALS: u32 = 1;

/// What a [`NearbyCertificate`] holds.
#[derive(Debug, Default)]
struct Slot {
    /// Whether a loop was checked here before.
    visited: bool,
    /// The latest certificate made here.
    certificate: Option<Arc<Certificate>>,
    /// Loops the latest certificate proved besides its own.
    proved: u32,
    /// Certificates in a row that proved no loop besides their own.
    wasted: u32,
}

impl Slot {
    /// Whether certificates have stopped paying here.
    fn given_up(&self) -> bool {
        self.wasted >= MAX_WASTED_RENEWALS
    }
}

impl NearbyCertificate {
    /// Whether the stored certificate proves `a` stable.
    pub fn certifies(&self, a: &DMatrix<f64>) -> bool {
        let cert = self
            .0
            .lock()
            .ok()
            .filter(|s| !s.given_up())
            .and_then(|c| c.certificate.clone());
        let proved = cert.is_some_and(|c| c.certifies(a));
        if proved {
            if let Ok(mut slot) = self.0.lock() {
                slot.proved += 1;
                slot.wasted = 0;
            }
        }
        proved
    }

    /// For a loop the stored certificate does not prove: on the first visit nothing (false);
    /// afterwards makes `a`'s own certificate and stores it, true when one can be made (it
    /// proves `a` stable; else the eigenvalues must decide). Nothing (false) either once
    /// certificates stopped paying here (see the type's docs).
    pub fn renew(&self, a: &DMatrix<f64>) -> bool {
        let go = self.0.lock().map(|mut s| {
            if !std::mem::replace(&mut s.visited, true) {
                return false;
            }
            if s.certificate.is_some() && s.proved == 0 {
                s.wasted += 1;
            }
            s.proved = 0;
            !s.given_up()
        });
        if !go.unwrap_or(false) {
            return false;
        }
        let Some(c) = Certificate::new(a) else {
            return false;
        };
        if let Ok(mut slot) = self.0.lock() {
            slot.certificate = Some(Arc::new(c));
        }
        true
    }

    /// Whether this centre stopped making certificates (they proved no loop but their own).
    pub fn given_up(&self) -> bool {
        self.0.lock().is_ok_and(|s| s.given_up())
    }
}
