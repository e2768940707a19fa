//! The time loop in blocks of samples: within a block the set points are known beforehand, so
//! everything but the recurrence itself is a matrix product over the whole block (faer):
//!
//! ```text
//! X[:, k+1] = Γ₀ U[:, k] + Γ₁ U[:, k+1]        all k of the block at once
//! X[:, k+1] += Φ X[:, k]                        one matrix-vector product per step
//! Y = C X + D U                                 all k of the block at once
//! ```
//!
//! The serial part is one n × n product per step (the first-order-hold recurrence written
//! per step costs three products for the state and two for the outputs). Blocks are handed to
//! the caller as they are finished, so a long run can be written while it is simulated.

use super::setpoint::SetPoint;
use super::{Piece, Run, SimError};
use faer::linalg::matmul::matmul;
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::{Accum, Mat, MatMut, MatRef, Par};

/// Samples per block: large enough that the block products run at matrix-product speed, small
/// enough (a few MB for a few hundred states) to stay in cache and to stream.
pub const BLOCK_SAMPLES: usize = 2048;

/// One piece's matrices in faer's layout.
struct Matrices {
    phi: Mat<f64>,
    gamma0: Mat<f64>,
    gamma1: Mat<f64>,
    c: Mat<f64>,
    d: Mat<f64>,
}

fn faer_of(m: &nalgebra::DMatrix<f64>) -> Mat<f64> {
    Mat::from_fn(m.nrows(), m.ncols(), |i, j| m[(i, j)])
}

impl Matrices {
    fn of(cl: &super::ClosedLoop, disc: &super::Discrete) -> Matrices {
        Matrices {
            phi: faer_of(&disc.phi),
            gamma0: faer_of(&disc.gamma0),
            gamma1: faer_of(&disc.gamma1),
            c: faer_of(&cl.c),
            d: faer_of(&cl.d),
        }
    }
}

/// The discrete recurrence over the precomputed inputs `u` (nu × (K + 1), column k the input at
/// step k): states `x` (n × (K + 1), column 0 given, the others written) and outputs `y`
/// (ny × K) of the first K samples.
fn propagate(m: &Matrices, u: MatRef<'_, f64>, mut x: MatMut<'_, f64>, y: MatMut<'_, f64>) {
    let steps = y.ncols();
    let par = Par::Seq;
    {
        let mut next = x.rb_mut().subcols_mut(1, steps);
        matmul(
            next.rb_mut(),
            Accum::Replace,
            m.gamma0.as_ref(),
            u.subcols(0, steps),
            1.0,
            par,
        );
        matmul(
            next,
            Accum::Add,
            m.gamma1.as_ref(),
            u.subcols(1, steps),
            1.0,
            par,
        );
    }
    for k in 0..steps {
        let (done, mut rest) = x.rb_mut().split_at_col_mut(k + 1);
        matmul(
            rest.rb_mut().subcols_mut(0, 1),
            Accum::Add,
            m.phi.as_ref(),
            done.rb().subcols(k, 1),
            1.0,
            par,
        );
    }
    let mut y = y;
    matmul(
        y.rb_mut(),
        Accum::Replace,
        m.c.as_ref(),
        x.rb().subcols(0, steps),
        1.0,
        par,
    );
    matmul(y, Accum::Add, m.d.as_ref(), u.subcols(0, steps), 1.0, par);
}

/// The time loop over `pieces` (see [`super::run_piecewise`]), handing every finished block of
/// samples to `sink` in order.
pub(super) fn run_blocks<E: From<SimError>>(
    pieces: &[Piece],
    setpoint: &dyn SetPoint,
    mut sink: impl FnMut(&Run) -> Result<(), E>,
) -> Result<(), E> {
    let &(_, cl0, disc0, _) = pieces
        .first()
        .ok_or_else(|| SimError::Invalid("no segment to simulate".into()))?;
    let h = disc0.step_s;
    if pieces.iter().any(|p| p.2.step_s != h) {
        return Err(SimError::Invalid("segments with different step sizes".into()).into());
    }
    let steps = (setpoint.duration_s() / h).ceil();
    if !(steps.is_finite() && steps < super::MAX_SAMPLES as f64) {
        return Err(SimError::Invalid(format!(
            "{:.4} s at {} Hz would be {} samples, at most {} are simulated (a lower rate or fewer revolutions)",
            setpoint.duration_s(),
            crate::text::num(1.0 / h),
            crate::text::num(steps),
            super::MAX_SAMPLES
        ))
        .into());
    }
    let steps = steps as usize;
    let (nu, nx, ny) = (cl0.b.ncols(), cl0.a.nrows(), cl0.c.nrows());
    let matrices: Vec<Matrices> = pieces
        .iter()
        .map(|&(_, cl, disc, _)| Matrices::of(cl, disc))
        .collect();
    let mut u0 = nalgebra::DVector::zeros(nu);
    setpoint.eval(0.0, &cl0.axes, u0.as_mut_slice());
    let x0 = cl0.equilibrium(&u0).ok_or(SimError::NoEquilibrium)?;
    let block = BLOCK_SAMPLES.min(steps + 1);
    let mut u = Mat::<f64>::zeros(nu, block + 1);
    let mut x = Mat::<f64>::zeros(nx, block + 1);
    let mut y = Mat::<f64>::zeros(ny, block);
    for i in 0..nx {
        x[(i, 0)] = x0[i];
    }
    for i in 0..nu {
        u[(i, 0)] = u0[i];
    }
    let mut out = Run::with_capacity(nu, ny, block);
    let mut active = 0;
    let mut first = 0;
    while first <= steps {
        let t_first = first as f64 * h;
        while active + 1 < pieces.len() && pieces[active + 1].0 <= t_first {
            active += 1;
        }
        // The block ends at the sample limit, at the end of the run or where the next piece
        // takes over.
        let mut len = block.min(steps + 1 - first);
        if let Some(next) = pieces.get(active + 1) {
            let until = (first..first + len)
                .position(|k| next.0 <= k as f64 * h)
                .unwrap_or(len);
            len = until.max(1);
        }
        // Inputs of samples first + 1 ..= first + len (the last one for the last step only).
        for k in 1..=len {
            let t = (first + k) as f64 * h;
            setpoint.eval(t, &cl0.axes, u.col_as_slice_mut(k));
        }
        let (_, cl, _, nest_origin) = pieces[active];
        propagate(
            &matrices[active],
            u.as_ref().subcols(0, len + 1),
            x.as_mut().subcols_mut(0, len + 1),
            y.as_mut().subcols_mut(0, len),
        );
        out.t_s.clear();
        out.inputs.clear();
        out.outputs.clear();
        for k in 0..len {
            out.t_s.push((first + k) as f64 * h);
            out.inputs.extend_from_slice(u.col_as_slice(k));
            let start = out.outputs.len();
            out.outputs.extend_from_slice(y.col_as_slice(k));
            if let Some(origin) = nest_origin {
                let xk = nalgebra::DVector::from_fn(nx, |i, _| x[(i, k)]);
                let uk = nalgebra::DVector::from_fn(nu, |i, _| u[(i, k)]);
                let mut yk = nalgebra::DVector::from_column_slice(&out.outputs[start..]);
                super::follow_the_tool(cl, origin, &xk, &uk, &mut yk);
                out.outputs[start..].copy_from_slice(yk.as_slice());
            }
        }
        sink(&out)?;
        // The last state and input of this block start the next.
        for i in 0..nx {
            x[(i, 0)] = x[(i, len)];
        }
        for i in 0..nu {
            u[(i, 0)] = u[(i, len)];
        }
        first += len;
    }
    Ok(())
}

/// The recurrence alone over given inputs (sample-major, `inputs[k·nu + i]`, N samples) from
/// state `x0`: the outputs of every sample, sample-major — the same block products as every
/// simulation, without set points (for comparing the loop with other implementations).
pub fn propagate_inputs(
    cl: &super::ClosedLoop,
    disc: &super::Discrete,
    x0: &[f64],
    inputs: &[f64],
) -> Vec<f64> {
    let (nu, nx, ny) = (cl.b.ncols(), cl.a.nrows(), cl.c.nrows());
    let samples = inputs.len() / nu;
    let m = Matrices::of(cl, disc);
    let block = BLOCK_SAMPLES.min(samples);
    let mut x = Mat::<f64>::zeros(nx, block + 1);
    let mut y = Mat::<f64>::zeros(ny, block);
    for i in 0..nx {
        x[(i, 0)] = x0[i];
    }
    let mut out = Vec::with_capacity(samples * ny);
    let mut first = 0;
    while first < samples {
        let len = block.min(samples - first);
        // The inputs of the block and the one after it (repeated at the very end).
        let last = (first + len).min(samples - 1);
        let u = Mat::<f64>::from_fn(nu, len + 1, |i, k| inputs[(first + k).min(last) * nu + i]);
        propagate(
            &m,
            u.as_ref(),
            x.as_mut().subcols_mut(0, len + 1),
            y.as_mut().subcols_mut(0, len),
        );
        for k in 0..len {
            out.extend_from_slice(y.col_as_slice(k));
        }
        for i in 0..nx {
            x[(i, 0)] = x[(i, len)];
        }
        first += len;
    }
    out
}
