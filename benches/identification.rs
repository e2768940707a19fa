//! The full demo identification (36 R-Test circles, 6 guideway factors), harmonic and time
//! domain, each with and without the ranking of candidate tests (experiment design, always
//! harmonic); and the flexible demo's (`machines/demo-vmc-flex.toml`, elastic column; 36
//! circles of `measurements/demo-vmc-flex/` pos-a and pos-b, 7 parameters with
//! `column.stiffness`), harmonic with and without the ranking. Each sample is a whole
//! identification after the measured files are read: expect a few seconds (harmonic) and about
//! a minute (time domain) for the ten samples.
//!
//! Run: `cargo bench --bench identification`

use criterion::{criterion_group, criterion_main, BatchSize, Criterion};
use eij::ident::measured::{load, MeasuredOptions};
use eij::ident::{identify, Parameter, Problem, Settings};
use eij::machine::Machine;
use eij::predict::{SimSettings, SolverKind};
use std::path::Path;

const HARMONIC: [(&str, SolverKind, bool); 2] = [
    ("harmonic", SolverKind::Harmonic, true),
    (
        "harmonic, without the ranking of candidate tests",
        SolverKind::Harmonic,
        false,
    ),
];

fn bench(c: &mut Criterion) {
    let time = [
        ("time domain", SolverKind::Time, true),
        (
            "time domain, without the ranking of candidate tests",
            SolverKind::Time,
            false,
        ),
    ];
    let all: Vec<_> = HARMONIC.into_iter().chain(time).collect();
    run(
        c,
        "demo identification (36 tests, 6 parameters)",
        "machines/demo-vmc.toml",
        &["measurements/demo-vmc"],
        &all,
    );
    run(
        c,
        "flexible demo identification (36 tests, 7 parameters)",
        "machines/demo-vmc-flex.toml",
        &[
            "measurements/demo-vmc-flex/pos-a",
            "measurements/demo-vmc-flex/pos-b",
        ],
        &HARMONIC,
    );
}

/// One group: the identification of `machine` from `measured` (default parameter set) with each
/// of `cases` (name, solver, ranking of candidate tests).
fn run(
    c: &mut Criterion,
    group: &str,
    machine: &str,
    measured: &[&str],
    cases: &[(&str, SolverKind, bool)],
) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let machine = Machine::from_file(&root.join(machine)).unwrap();
    let folders: Vec<_> = measured.iter().map(|m| root.join(m)).collect();
    let tests = load(&folders, &MeasuredOptions::default()).unwrap();
    let mut group = c.benchmark_group(group);
    group.sample_size(10);
    for &(name, solver, design) in cases {
        let settings = Settings {
            simulation: SimSettings {
                solver,
                ..SimSettings::default()
            },
            design,
            ..Settings::default()
        };
        // A fresh problem per run: a problem keeps its latest simulations.
        let fresh = || {
            Problem::new(
                machine.clone(),
                Parameter::default_set(&machine),
                tests.clone(),
                settings.clone(),
            )
            .unwrap()
        };
        group.bench_function(name, |b| {
            b.iter_batched(
                fresh,
                |problem| identify(&problem, None).unwrap(),
                BatchSize::PerIteration,
            )
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
