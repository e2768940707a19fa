//! The full demo identification (36 R-Test circles, 6 guideway factors), harmonic and time
//! domain, each with and without the ranking of candidate tests (experiment design, always
//! harmonic). Each sample is a whole identification after the measured files are read: expect
//! a few seconds (harmonic) and about a minute (time domain) for the ten samples.
//!
//! Run: `cargo bench --bench identification`

use criterion::{criterion_group, criterion_main, BatchSize, Criterion};
use eij::ident::measured::{load, MeasuredOptions};
use eij::ident::{identify, Parameter, Problem, Settings};
use eij::machine::Machine;
use eij::predict::{SimSettings, SolverKind};
use std::path::Path;

fn bench(c: &mut Criterion) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let machine = Machine::from_file(&root.join("machines/demo-vmc.toml")).unwrap();
    let tests = load(
        &[root.join("measurements/demo-vmc")],
        &MeasuredOptions::default(),
    )
    .unwrap();
    let mut group = c.benchmark_group("demo identification (36 tests, 6 parameters)");
    group.sample_size(10);
    for (name, solver, design) in [
        ("harmonic", SolverKind::Harmonic, true),
        (
            "harmonic, without the ranking of candidate tests",
            SolverKind::Harmonic,
            false,
        ),
        ("time domain", SolverKind::Time, true),
        (
            "time domain, without the ranking of candidate tests",
            SolverKind::Time,
            false,
        ),
    ] {
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
