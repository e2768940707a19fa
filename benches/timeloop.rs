//! The time loop against the plain C loop of `benches/fohloop.c` (the same
//! first-order-hold recurrence, hand-written, vectorised): the demo's closed loop (n = 63,
//! 15 outputs) on the zx circle at 5 m/s², 4 steady revolutions plus ramps, at 10 kHz.
//!
//! The bench writes the discretised matrices and the circle's inputs in fohloop's binary
//! format, compiles fohloop with `gcc -O3 -march=native` (when gcc and the file are there),
//! runs both on the same input in this one process's run — fohloop's median of 50 runs and
//! eij's median of 50 runs of the same recurrence ([`eij::sim::propagate::propagate_inputs`]) —
//! checks that the outputs agree, and prints both times and their ratio. Criterion then times
//! the block recurrence and the whole simulation that identify runs (set points included).
//!
//! Run: `cargo bench --bench timeloop`

use criterion::{criterion_group, criterion_main, Criterion};
use eij::axes::{Direction, Plane};
use eij::control::ClosedLoop;
use eij::machine::Machine;
use eij::sim::propagate::propagate_inputs;
use eij::sim::setpoint::Circle;
use eij::sim::{simulate_discrete, Discrete};
use nalgebra::DVector;
use std::hint::black_box;
use std::path::Path;
use std::process::Command;
use std::time::Instant;

const REPS: usize = 50;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// fohloop's input file: int32 n, nu, ny, N; Φ, Γ₀, Γ₁, C, D row-major; x0; U sample-major.
fn fohloop_input(cl: &ClosedLoop, disc: &Discrete, x0: &[f64], inputs: &[f64]) -> Vec<u8> {
    let (n, nu, ny) = (cl.a.nrows(), cl.b.ncols(), cl.c.nrows());
    let mut out = Vec::new();
    for v in [n, nu, ny, inputs.len() / nu] {
        out.extend_from_slice(&(v as i32).to_le_bytes());
    }
    for m in [&disc.phi, &disc.gamma0, &disc.gamma1, &cl.c, &cl.d] {
        for i in 0..m.nrows() {
            for j in 0..m.ncols() {
                out.extend_from_slice(&m[(i, j)].to_le_bytes());
            }
        }
    }
    for v in x0.iter().chain(inputs) {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out
}

/// Compiles and runs fohloop on `input`; its median and the outputs it wrote.
fn run_c(input: &[u8], dir: &Path) -> Option<(f64, Vec<f64>)> {
    let source = Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/fohloop.c");
    if !source.exists() {
        eprintln!("{} not found: no C comparison", source.display());
        return None;
    }
    let exe = dir.join("fohloop");
    let built = Command::new("gcc")
        .args(["-O3", "-march=native", "-DNP=64", "-DNYP=16"])
        .arg(&source)
        .arg("-o")
        .arg(&exe)
        .status()
        .ok()?;
    if !built.success() {
        eprintln!("gcc failed: no C comparison");
        return None;
    }
    let (bin, y) = (dir.join("in.bin"), dir.join("y.bin"));
    std::fs::write(&bin, input).ok()?;
    let out = Command::new(&exe)
        .arg(&bin)
        .arg(REPS.to_string())
        .arg(&y)
        .output()
        .ok()?;
    let text = String::from_utf8_lossy(&out.stdout);
    let median_s: f64 = text.split_whitespace().next()?.parse().ok()?;
    let bytes = std::fs::read(&y).ok()?;
    let values = bytes
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap_or([0; 8])))
        .collect();
    Some((median_s, values))
}

fn bench(c: &mut Criterion) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let machine = Machine::from_file(&root.join("machines/demo-vmc.toml")).unwrap();
    let cl = ClosedLoop::new(&machine, &machine.reference_pose()).unwrap();
    let disc = Discrete::new(&cl, 1e-4);
    let mut circle = Circle::new(Plane::Zx, 0.002, 5.0, Direction::Ccw);
    circle.steady_revolutions = 4;
    let run = simulate_discrete(&cl, &disc, &circle).unwrap();
    let nu = run.nu;
    let x0 = cl
        .equilibrium(&DVector::from_column_slice(&run.inputs[..nu]))
        .unwrap();
    let steps = run.len() - 1;
    let x0 = x0.as_slice().to_vec();

    let dir = std::env::temp_dir().join(format!("eij-timeloop-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let input = fohloop_input(&cl, &disc, &x0, &run.inputs);
    if let Some((c_s, c_y)) = run_c(&input, &dir) {
        let mut times = Vec::with_capacity(REPS);
        let mut y = Vec::new();
        for _ in 0..REPS {
            let t0 = Instant::now();
            y = propagate_inputs(&cl, &disc, &x0, black_box(&run.inputs));
            times.push(t0.elapsed().as_secs_f64());
        }
        let eij_s = median(times);
        let scale = c_y.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let diff = c_y
            .iter()
            .zip(&y)
            .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(
            diff <= 1e-9 * scale && c_y.len() == y.len(),
            "C and eij outputs differ by {diff:e} of {scale:e}"
        );
        eprintln!(
            "time loop, demo n = {}, {steps} steps, median of {REPS}: C (gcc -O3 -march=native) {:.2} ms, eij {:.2} ms, eij/C = {:.2} (outputs agree to {:.1e} relative)",
            cl.a.nrows(),
            c_s * 1e3,
            eij_s * 1e3,
            eij_s / c_s,
            diff / scale
        );
    }
    std::fs::remove_dir_all(&dir).ok();

    let mut group = c.benchmark_group("time loop");
    group.bench_function(
        format!("block recurrence over given inputs (demo, {steps} steps)"),
        |b| b.iter(|| propagate_inputs(&cl, &disc, &x0, black_box(&run.inputs))),
    );
    group.bench_function(
        format!("time-domain circle with set points (demo, {steps} steps)"),
        |b| b.iter(|| simulate_discrete(&cl, &disc, black_box(&circle)).unwrap()),
    );
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
