//! Speed of the FE side (issue 27): Craig–Bampton reduction of a hexahedral solid column with 30
//! fixed-interface modes, and the full model's 30 lowest elastic free-free modes by shift-invert
//! Lanczos — the task `benches/fe_scipy.py` gives scipy's `eigsh` on the same matrices.
//!
//! `cargo bench --bench fe` (65 000 DOFs; `EIJ_BENCH_FE_NZ=40` for a 17 000-DOF column).
//! Figures and the scipy comparison: docs/fe.md.

use criterion::{criterion_group, criterion_main, Criterion};
use eij::fe::{free_free_frequencies_hz, reduce};
use std::hint::black_box;
use std::time::Duration;

#[path = "common/fe_column.rs"]
mod fe_column;
use fe_column::{attachments, column, settings};

fn bench(c: &mut Criterion) {
    let nz = std::env::var("EIJ_BENCH_FE_NZ")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(150);
    let model = column(nz);
    let (attachments, settings) = (attachments(), settings());
    let first_hz = reduce(&model, &attachments, &settings)
        .expect("reduces")
        .frequencies_hz(1.0)[0];
    let mut group = c.benchmark_group(format!("fe_column_{}_dofs", model.n_dofs()));
    group.sample_size(10);
    group.warm_up_time(Duration::from_millis(1));
    group.measurement_time(Duration::from_secs(1));
    group.bench_function("reduce_30_modes", |b| {
        b.iter(|| {
            black_box(
                reduce(&model, &attachments, &settings)
                    .unwrap()
                    .eigenvalues
                    .len(),
            )
        })
    });
    group.bench_function("full_free_free_30_modes", |b| {
        b.iter(|| black_box(free_free_frequencies_hz(&model, 30, 0.1 * first_hz).unwrap()[0]))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
