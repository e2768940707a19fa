//! The full demo identification (36 R-Test circles, 6 guideway factors), harmonic and time
//! domain. Each sample is a whole identification: expect about a minute (harmonic) and several
//! minutes (time domain) for the default ten samples.
//!
//! Run: `cargo bench --bench identification`

use criterion::{criterion_group, criterion_main, Criterion};
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
    for (name, solver) in [
        ("harmonic", SolverKind::Harmonic),
        ("time domain", SolverKind::Time),
    ] {
        let settings = Settings {
            simulation: SimSettings {
                solver,
                ..SimSettings::default()
            },
            ..Settings::default()
        };
        let problem = Problem::new(
            machine.clone(),
            Parameter::default_set(&machine),
            tests.clone(),
            settings,
        )
        .unwrap();
        group.bench_function(name, |b| b.iter(|| identify(&problem, None).unwrap()));
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
