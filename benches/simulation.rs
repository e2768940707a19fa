//! Benchmarks of the modelling chain on the demo machine: assembly, modal analysis, closed loop,
//! discretisation and a circle simulation (3 steady revolutions at 10 kHz output).
//!
//! Run: `cargo bench --bench simulation`

use criterion::{criterion_group, criterion_main, Criterion};
use eij::axes::{Direction, Plane};
use eij::control::ClosedLoop;
use eij::machine::Machine;
use eij::mbs::{modal, Model};
use eij::sim::setpoint::Circle;
use eij::sim::{simulate_discrete, Discrete};
use std::hint::black_box;
use std::path::Path;

fn demo() -> Machine {
    Machine::from_file(&Path::new(env!("CARGO_MANIFEST_DIR")).join("machines/demo-vmc.toml"))
        .unwrap()
}

fn bench(c: &mut Criterion) {
    let machine = demo();
    let pose = machine.reference_pose();
    c.bench_function("assemble M, D, K (demo, 27 DOF)", |b| {
        b.iter(|| Model::assemble(black_box(&machine), black_box(&pose)).unwrap())
    });
    let model = Model::assemble(&machine, &pose).unwrap();
    c.bench_function("modal analysis (demo)", |b| {
        b.iter(|| modal::modes(black_box(&model)).unwrap())
    });
    c.bench_function(
        "closed loop with support and stability checks (demo)",
        |b| b.iter(|| ClosedLoop::new(black_box(&machine), black_box(&pose)).unwrap()),
    );
    let cl = ClosedLoop::new(&machine, &pose).unwrap();
    c.bench_function("discretise, first-order hold, 10 kHz (demo)", |b| {
        b.iter(|| Discrete::new(black_box(&cl), 1e-4))
    });
    let disc = Discrete::new(&cl, 1e-4);
    let mut circle = Circle::new(Plane::Zx, 0.002, 5.0, Direction::Ccw);
    circle.steady_revolutions = 3;
    c.bench_function(
        "circle zx 5 m/s², 3 revolutions + ramps, 10 kHz (demo)",
        |b| {
            b.iter(|| {
                simulate_discrete(black_box(&cl), black_box(&disc), black_box(&circle)).unwrap()
            })
        },
    );
}

criterion_group!(benches, bench);
criterion_main!(benches);
