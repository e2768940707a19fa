//! Drives under cascaded P-PI control; the closed loop in state space.
//!
//! Per axis (DESIGN.md "Drives and control"):
//!
//! ```text
//! x_c, v_c, a_c = x_set, v_set, a_set, or their first-order smoothing (set-point filter T_f)
//! v_cmd = Kv·(x_c − x_fb) + k_vff·v_c                          position loop P, m/s
//! e_ω   = ρ·v_cmd − φ̇,  ρ = σ·2π/h                              speed error at the motor, rad/s
//! T_set = Kp·(e_ω + ζ/Tn) + k_aff·J_eq·ρ·a_c,  ζ̇ = e_ω           velocity loop PI + torque feed-forward
//! Tc·Ṫ  = T_set − T   (Tc = 0: T = T_set)                        current loop
//! M q̈ + D q̇ + K q = b_rotor·T                                    structure (mbs)
//! ```
//!
//! x_fb is the linear-scale reading (or the motor encoder); J_eq = J_rotor + m_moved·(h/2π)².
//! With the state x = (q, q̇, ζ, T_lagged, x_filtered) the closed loop at an axis position is LTI:
//! ẋ = A x + B u, y = C x + D u, with inputs u = (x_set, v_set, a_set) per axis and the outputs
//! named in [`ClosedLoop::outputs`].

use crate::axes::Axis;
use crate::machine::raw::Feedback;
use crate::machine::{Machine, Pose};
use crate::mbs::{modal, MbsError, Model};
use nalgebra::{Complex, DMatrix, DVector};
use std::sync::atomic::{AtomicBool, Ordering};

pub(crate) mod frequency;
pub mod stability;
pub use frequency::FrequencyForm;
pub use stability::NearbyCertificate;

/// What the closed loops at one pose share when they differ only in stiffness factors (see
/// [`ClosedLoop::new_near`]; shared between threads).
///
/// The support: the structure's rigid-body modes are the null space of K = Σ fᵢ·Kᵢ, a sum of
/// positive semi-definite element stiffnesses Kᵢ with factors fᵢ > 0, which is ∩ null(Kᵢ)
/// whatever the factors' values; so once one loop's structure is supported, every other's is.
/// The stability: the certificate of the latest loop checked in full ([`NearbyCertificate`]).
#[derive(Debug, Default)]
pub struct PoseChecks {
    /// Whether a loop's structure was found supported here.
    supported: AtomicBool,
    /// The stability certificate shared by the loops here.
    pub stability: NearbyCertificate,
}

/// Errors building the closed loop.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ControlError {
    /// Assembly or support check failed.
    #[error(transparent)]
    Mbs(#[from] MbsError),
    /// Axis positions that are no pose of the machine.
    #[error(transparent)]
    Pose(#[from] crate::machine::PoseError),
    /// The closed loop has an eigenvalue with non-negative real part.
    #[error("{machine}: closed loop unstable at axis {axis} (eigenvalue {re:.3} ± {im:.3}i 1/s, {freq_hz:.1} Hz): {hint}")]
    Unstable {
        /// Machine source.
        machine: String,
        /// The axis whose drive dominates the unstable mode.
        axis: Axis,
        /// Real part, 1/s.
        re: f64,
        /// Imaginary part, 1/s.
        im: f64,
        /// |λ|/(2π).
        freq_hz: f64,
        /// What to change: the current-loop lag where it is long against the unstable mode,
        /// else the gains.
        hint: String,
    },
    /// The eigen-solver failed.
    #[error("{machine}: closed-loop eigenvalues could not be computed")]
    Eigen {
        /// Machine source.
        machine: String,
    },
}

/// Input channel kinds per axis, in order.
pub(crate) const INPUTS_PER_AXIS: usize = 3;

/// The closed loop at one axis position.
#[derive(Debug, Clone)]
pub struct ClosedLoop {
    /// State matrix.
    pub a: DMatrix<f64>,
    /// Input matrix.
    pub b: DMatrix<f64>,
    /// Output matrix.
    pub c: DMatrix<f64>,
    /// Feed-through matrix.
    pub d: DMatrix<f64>,
    /// State names: `q:<dof>`, `v:<dof>`, `<axis>.pi_integral`, `<axis>.torque`,
    /// `<axis>.setpoint_filter`.
    pub states: Vec<String>,
    /// Input names: `<axis>_pos_set_m`, `<axis>_vel_set_m_s`, `<axis>_acc_set_m_s2` per axis.
    pub inputs: Vec<String>,
    /// Output names: `<axis>_int_m` (linear scale) per axis, `x_tcp_m`, `y_tcp_m`, `z_tcp_m`
    /// (TCP relative to the workpiece), then per axis `<axis>_acc_act_m_s2` (second derivative
    /// of the scale reading), `<axis>_following_error_m` (commanded minus fed-back position),
    /// `<axis>_torque_nm`.
    pub outputs: Vec<String>,
    /// The machine axes, in input order.
    pub axes: Vec<Axis>,
    /// The structural model it was built from.
    pub model: Model,
}

impl ClosedLoop {
    /// Assembles the structure at `pose`, checks its support, closes the loops and checks
    /// stability.
    pub fn new(machine: &Machine, pose: &Pose) -> Result<ClosedLoop, ControlError> {
        let model = Model::assemble(machine, pose)?;
        modal::check_support(&model, machine)?;
        let cl = ClosedLoop::from_model(machine, model);
        cl.check_stability(machine)?;
        Ok(cl)
    }

    /// As [`ClosedLoop::new`] for one of several loops at one pose with other stiffness
    /// factors (an identification's parameter sets), with what `checks` knows from the loops
    /// before: the support is checked by the first loop only (see [`PoseChecks`]), and the
    /// stability check first tries the Lyapunov certificate of a loop checked in full (see
    /// [`stability`]): for the loops of a finite-difference Jacobian a tenth of the eigenvalue
    /// problem's cost, with the same verdict.
    pub fn new_near(
        machine: &Machine,
        pose: &Pose,
        checks: &PoseChecks,
    ) -> Result<ClosedLoop, ControlError> {
        let model = Model::assemble(machine, pose)?;
        if !checks.supported.load(Ordering::Relaxed) {
            modal::check_support(&model, machine)?;
            checks.supported.store(true, Ordering::Relaxed);
        }
        let cl = ClosedLoop::from_model(machine, model);
        let near = &checks.stability;
        // The loop's own certificate, when one is made, proves it stable as well (the
        // eigenvalue check then decides only where no certificate proves anything).
        if !near.certifies(&cl.a) && !near.renew(&cl.a) {
            cl.check_stability(machine)?;
        }
        Ok(cl)
    }

    /// Closes the loops around an assembled model without any check.
    pub fn from_model(machine: &Machine, model: Model) -> ClosedLoop {
        let n = model.n_dof();
        let na = machine.axes().len();
        let lagged: Vec<usize> = (0..na)
            .filter(|&i| machine.axes()[i].control.current_lag_s > 0.0)
            .collect();
        let filtered: Vec<usize> = (0..na)
            .filter(|&i| machine.axes()[i].control.setpoint_filter_s > 0.0)
            .collect();
        let nx = 2 * n + na + lagged.len() + filtered.len();
        let nu = INPUTS_PER_AXIS * na;
        let (iq, iv, iz, it) = (0, n, 2 * n, 2 * n + na);
        let i_f = it + lagged.len();

        // Commanded position, velocity and acceleration seen by the controller, as rows over
        // (x, u): the set points themselves, or their first-order smoothing p_f with
        // ṗ_f = (x_set − p_f)/T_f, v_c = ṗ_f, a_c = (v_set − ṗ_f)/T_f.
        let mut cpx = DMatrix::zeros(na, nx);
        let mut cpu = DMatrix::zeros(na, nu);
        let mut cvx = DMatrix::zeros(na, nx);
        let mut cvu = DMatrix::zeros(na, nu);
        let mut cax = DMatrix::zeros(na, nx);
        let mut cau = DMatrix::zeros(na, nu);
        for i in 0..na {
            let (up, uv, ua) = (3 * i, 3 * i + 1, 3 * i + 2);
            match filtered.iter().position(|&f| f == i) {
                None => {
                    cpu[(i, up)] = 1.0;
                    cvu[(i, uv)] = 1.0;
                    cau[(i, ua)] = 1.0;
                }
                Some(k) => {
                    let tf = machine.axes()[i].control.setpoint_filter_s;
                    cpx[(i, i_f + k)] = 1.0;
                    cvx[(i, i_f + k)] = -1.0 / tf;
                    cvu[(i, up)] = 1.0 / tf;
                    cax[(i, i_f + k)] = 1.0 / (tf * tf);
                    cau[(i, up)] = -1.0 / (tf * tf);
                    cau[(i, uv)] = 1.0 / tf;
                }
            }
        }

        // Torque command T_set = gx·x + gu·u per axis (rows).
        let mut gx = DMatrix::zeros(na, nx);
        let mut gu = DMatrix::zeros(na, nu);
        // Speed error e_ω = ex·x + eu·u per axis (rows): the PI integrator's derivative.
        let mut ex = DMatrix::zeros(na, nx);
        let mut eu = DMatrix::zeros(na, nu);
        // Following error x_cmd − x_fb.
        let mut fx = cpx.clone();
        let fu = cpu.clone();
        for (i, a) in machine.axes().iter().enumerate() {
            let p = &model.axes[i];
            let c = &a.control;
            let fb = match c.feedback {
                Feedback::Scale => &p.scale,
                Feedback::Encoder => &p.encoder,
            };
            let rho = p.rad_per_m;
            {
                let mut f = fx.view_mut((i, iq), (1, n));
                f -= fb.transpose();
            }
            // e_ω = ρ·(Kv·(x_cmd − x_fb) + k_vff·v_cmd) − φ̇
            let row = fx.row(i) * (rho * c.kv_per_s) + cvx.row(i) * (rho * c.velocity_feedforward);
            ex.row_mut(i).copy_from(&row);
            ex[(i, iv + p.rotor_dof)] -= 1.0;
            let row = fu.row(i) * (rho * c.kv_per_s) + cvu.row(i) * (rho * c.velocity_feedforward);
            eu.row_mut(i).copy_from(&row);
            // T_set = Kp·e_ω + Kp/Tn·ζ + k_aff·J_eq·ρ·a_cmd
            let ff = c.acceleration_feedforward * p.inertia_eq_kg_m2 * rho;
            let row = ex.row(i) * c.kp_nm_s_per_rad + cax.row(i) * ff;
            gx.row_mut(i).copy_from(&row);
            gx[(i, iz + i)] += c.kp_nm_s_per_rad / c.tn_s;
            let row = eu.row(i) * c.kp_nm_s_per_rad + cau.row(i) * ff;
            gu.row_mut(i).copy_from(&row);
        }
        // Applied torque T = tx·x + tu·u (the lag state, or T_set itself).
        let mut tx = gx.clone();
        let mut tu = gu.clone();
        for (k, &i) in lagged.iter().enumerate() {
            tx.row_mut(i).fill(0.0);
            tx[(i, it + k)] = 1.0;
            tu.row_mut(i).fill(0.0);
        }
        // b_rotor: generalised force of each motor torque.
        let mut bt = DMatrix::zeros(n, na);
        for (i, p) in model.axes.iter().enumerate() {
            bt[(p.rotor_dof, i)] = 1.0;
        }
        let chol = model
            .mass
            .clone()
            .cholesky()
            .expect("mass matrix validated positive definite");
        let minv_k = chol.solve(&model.stiffness);
        let minv_d = chol.solve(&model.damping);
        let minv_bt = chol.solve(&bt);

        // q̈ = −M⁻¹K q − M⁻¹D q̇ + M⁻¹b T  → rows of acceleration in terms of x and u.
        let mut accx = DMatrix::zeros(n, nx);
        accx.view_mut((0, iq), (n, n)).copy_from(&(-&minv_k));
        accx.view_mut((0, iv), (n, n)).copy_from(&(-&minv_d));
        accx += &minv_bt * &tx;
        let accu = &minv_bt * &tu;

        let mut a_mat = DMatrix::zeros(nx, nx);
        let mut b_mat = DMatrix::zeros(nx, nu);
        a_mat.view_mut((iq, iv), (n, n)).fill_with_identity();
        a_mat.view_mut((iv, 0), (n, nx)).copy_from(&accx);
        b_mat.view_mut((iv, 0), (n, nu)).copy_from(&accu);
        a_mat.view_mut((iz, 0), (na, nx)).copy_from(&ex);
        b_mat.view_mut((iz, 0), (na, nu)).copy_from(&eu);
        for (k, &i) in lagged.iter().enumerate() {
            let tc = machine.axes()[i].control.current_lag_s;
            let row = gx.row(i) / tc;
            a_mat.row_mut(it + k).copy_from(&row);
            a_mat[(it + k, it + k)] -= 1.0 / tc;
            let row = gu.row(i) / tc;
            b_mat.row_mut(it + k).copy_from(&row);
        }
        for (k, &i) in filtered.iter().enumerate() {
            a_mat.row_mut(i_f + k).copy_from(&cvx.row(i));
            b_mat.row_mut(i_f + k).copy_from(&cvu.row(i));
        }

        // Outputs.
        let ny = 4 * na + 3;
        let mut c_mat = DMatrix::zeros(ny, nx);
        let mut d_mat = DMatrix::zeros(ny, nu);
        let mut outputs = Vec::with_capacity(ny);
        for (i, a) in machine.axes().iter().enumerate() {
            c_mat
                .view_mut((i, iq), (1, n))
                .copy_from(&model.axes[i].scale.transpose());
            outputs.push(format!("{}_int_m", a.axis));
        }
        for (k, ax) in Axis::ALL.iter().enumerate() {
            c_mat
                .view_mut((na + k, iq), (1, n))
                .copy_from(&model.tcp.row(k));
            outputs.push(format!("{ax}_tcp_m"));
        }
        let base = na + 3;
        for (i, a) in machine.axes().iter().enumerate() {
            let s = model.axes[i].scale.transpose();
            c_mat.row_mut(base + 3 * i).copy_from(&(&s * &accx));
            d_mat.row_mut(base + 3 * i).copy_from(&(&s * &accu));
            outputs.push(format!("{}_acc_act_m_s2", a.axis));
            c_mat.row_mut(base + 3 * i + 1).copy_from(&fx.row(i));
            d_mat.row_mut(base + 3 * i + 1).copy_from(&fu.row(i));
            outputs.push(format!("{}_following_error_m", a.axis));
            c_mat.row_mut(base + 3 * i + 2).copy_from(&tx.row(i));
            d_mat.row_mut(base + 3 * i + 2).copy_from(&tu.row(i));
            outputs.push(format!("{}_torque_nm", a.axis));
        }

        let mut states = Vec::with_capacity(nx);
        states.extend(model.dofs.iter().map(|d| format!("q:{d}")));
        states.extend(model.dofs.iter().map(|d| format!("v:{d}")));
        states.extend(
            machine
                .axes()
                .iter()
                .map(|a| format!("{}.pi_integral", a.axis)),
        );
        states.extend(
            lagged
                .iter()
                .map(|&i| format!("{}.torque", machine.axes()[i].axis)),
        );
        states.extend(
            filtered
                .iter()
                .map(|&i| format!("{}.setpoint_filter", machine.axes()[i].axis)),
        );
        let mut inputs = Vec::with_capacity(nu);
        for a in machine.axes() {
            inputs.push(format!("{}_pos_set_m", a.axis));
            inputs.push(format!("{}_vel_set_m_s", a.axis));
            inputs.push(format!("{}_acc_set_m_s2", a.axis));
        }
        ClosedLoop {
            a: a_mat,
            b: b_mat,
            c: c_mat,
            d: d_mat,
            states,
            inputs,
            outputs,
            axes: machine.axes().iter().map(|a| a.axis).collect(),
            model,
        }
    }

    /// Index of a named output.
    pub fn output(&self, name: &str) -> Option<usize> {
        self.outputs.iter().position(|o| o == name)
    }

    /// Index of a named input.
    pub fn input(&self, name: &str) -> Option<usize> {
        self.inputs.iter().position(|o| o == name)
    }

    /// Closed-loop eigenvalues (faer's non-symmetric eigen-solver).
    pub fn eigenvalues(&self) -> Option<Vec<Complex<f64>>> {
        let n = self.a.nrows();
        let a = faer::Mat::<f64>::from_fn(n, n, |i, j| self.a[(i, j)]);
        let ev = a.eigenvalues().ok()?;
        Some(ev.iter().map(|c| Complex::new(c.re, c.im)).collect())
    }

    /// Fails with the responsible axis when any eigenvalue has a positive real part.
    ///
    /// Undamped structural modes that the drives do not touch stay on the imaginary axis
    /// (Re λ = 0 up to round-off, |Re λ| ≤ 1e-9·|λ|); they are marginally stable and accepted.
    pub(crate) fn check_stability(&self, machine: &Machine) -> Result<(), ControlError> {
        let n = self.a.nrows();
        let unstable = |re: f64, im: f64| re > 1e-9 * (re * re + im * im).sqrt();
        // Eigenvalues alone decide; eigenvectors are computed only to name the axis.
        let values = self.eigenvalues().ok_or_else(|| ControlError::Eigen {
            machine: machine.source().to_string(),
        })?;
        if !values.iter().any(|l| unstable(l.re, l.im)) {
            return Ok(());
        }
        let a = faer::Mat::<f64>::from_fn(n, n, |i, j| self.a[(i, j)]);
        let eig = a.eigen().map_err(|_| ControlError::Eigen {
            machine: machine.source().to_string(),
        })?;
        let s = eig.S();
        let u = eig.U();
        let mut worst: Option<usize> = None;
        for k in 0..n {
            let re = s[k].re;
            if unstable(re, s[k].im) && worst.is_none_or(|w| re > s[w].re) {
                worst = Some(k);
            }
        }
        let Some(k) = worst else { return Ok(()) };
        // Attribute the mode to the axis whose rotor speed and PI state it moves most.
        let nd = self.model.n_dof();
        let axis = (0..self.axes.len())
            .map(|i| {
                let p = &self.model.axes[i];
                let rotor = u[(nd + p.rotor_dof, k)];
                let w = (rotor.re * rotor.re + rotor.im * rotor.im) * p.inertia_eq_kg_m2;
                (i, w)
            })
            .max_by(|x, y| x.1.total_cmp(&y.1))
            .map_or(self.axes[0], |(i, _)| self.axes[i]);
        let (re, im) = (s[k].re, s[k].im.abs());
        let omega = (re * re + im * im).sqrt();
        let lag = machine.axis(axis).map_or(0.0, |a| a.control.current_lag_s);
        // A first-order lag costs ωτ rad of phase at the mode: beyond ~0.3 rad it, not the
        // gains, is what the loop cannot take.
        let hint = if lag * omega > 0.3 {
            format!(
                "the current-loop lag current_lag_s = {} s is long for this loop (ωτ = {:.2} at the unstable mode): shorten it, or lower kp_nm_s_per_rad",
                crate::text::num(lag),
                lag * omega
            )
        } else {
            "lower kv_per_s or kp_nm_s_per_rad, or raise tn_s".to_string()
        };
        Err(ControlError::Unstable {
            machine: machine.source().to_string(),
            axis,
            re,
            im,
            freq_hz: omega / std::f64::consts::TAU,
            hint,
        })
    }

    /// Frequency response H(jω) = C (jωI − A)⁻¹ B + D (ny × nu, complex): the columns of
    /// [`ClosedLoop::response`] for unit inputs.
    pub fn frequency_response(&self, omega: f64) -> Option<DMatrix<Complex<f64>>> {
        let nu = self.b.ncols();
        let units: Vec<Vec<Complex<f64>>> = (0..nu)
            .map(|k| {
                let mut u = vec![Complex::new(0.0, 0.0); nu];
                u[k] = Complex::new(1.0, 0.0);
                u
            })
            .collect();
        let y = self.responses(omega, &units)?;
        Some(DMatrix::from_fn(self.c.nrows(), nu, |o, k| y[k][o]))
    }

    /// Output phasors Y = H(jω) U = C (jωI − A)⁻¹ B U + D U of input phasors `u` (closed-loop
    /// input order): the steady state of sinusoidal set points at ω. `None` if jωI − A is
    /// singular (a pole on the imaginary axis at ω).
    pub fn response(&self, omega: f64, u: &[Complex<f64>]) -> Option<Vec<Complex<f64>>> {
        Some(
            self.responses(omega, std::slice::from_ref(&u.to_vec()))?
                .remove(0),
        )
    }

    /// [`ClosedLoop::response`] for several input vectors with one reduction of A
    /// ([`FrequencyForm`]: the one implementation of H(jω), used by the harmonic simulation).
    fn responses(
        &self,
        omega: f64,
        inputs: &[Vec<Complex<f64>>],
    ) -> Option<Vec<Vec<Complex<f64>>>> {
        let form = self.frequency_form();
        inputs.iter().map(|u| form.response(omega, u)).collect()
    }

    /// The closed loop reduced for frequency responses at many frequencies.
    pub fn frequency_form(&self) -> FrequencyForm {
        FrequencyForm::new(self)
    }

    /// The state of rest in equilibrium at constant set input `u` (zero velocity and
    /// acceleration set points): A x + B u = 0.
    pub fn equilibrium(&self, u: &DVector<f64>) -> Option<DVector<f64>> {
        let rhs = -(&self.b * u);
        self.a.clone().lu().solve(&rhs)
    }
}
