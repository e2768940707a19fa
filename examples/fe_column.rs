//! Reduces a hexahedral solid column as the FE benchmark does and prints wall times and the
//! peak memory (VmHWM): `cargo run --release --example fe_column -- [DIVISIONS_Z] [--write DIR]`.
//! With `--write DIR` the column's M, K (Matrix Market), DOF map and nodes are written there for
//! `benches/fe_scipy.py`. 150 divisions along z give 64 779 DOFs; 470 give 202 059.

use eij::fe::{free_free_frequencies_hz, reduce, FeModel};
use std::time::Instant;

#[path = "../benches/common/fe_column.rs"]
mod fe_column;

fn peak_mib() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines().find(|l| l.starts_with("VmHWM:")).and_then(|l| {
                l.split_whitespace()
                    .nth(1)
                    .and_then(|v| v.parse::<f64>().ok())
            })
        })
        .map(|kib| kib / 1024.0)
        .unwrap_or(f64::NAN)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let nz: usize = args.first().and_then(|a| a.parse().ok()).unwrap_or(150);
    let write = args
        .iter()
        .position(|a| a == "--write")
        .and_then(|i| args.get(i + 1));
    let t = Instant::now();
    let model = fe_column::column(nz);
    println!(
        "mesh: {} DOFs in {:.2} s, peak {:.0} MiB",
        model.n_dofs(),
        t.elapsed().as_secs_f64(),
        peak_mib()
    );
    if let Some(dir) = write {
        let dir = std::path::Path::new(dir);
        std::fs::create_dir_all(dir)?;
        model.write_files(
            [
                &dir.join("column-M.mtx"),
                &dir.join("column-K.mtx"),
                &dir.join("column-dofs.csv"),
                &dir.join("column-nodes.csv"),
            ],
            "eij examples/fe_column: hex8 column 0.6 x 0.5 x 3.0 m, E 1.2e11 Pa, nu 0.27, 7200 kg/m3",
        )?;
        let t = Instant::now();
        let back = FeModel::from_files(
            &dir.join("column-M.mtx"),
            &dir.join("column-K.mtx"),
            &dir.join("column-dofs.csv"),
            &dir.join("column-nodes.csv"),
        )?;
        println!(
            "read back from Matrix Market in {:.2} s, peak {:.0} MiB",
            t.elapsed().as_secs_f64(),
            peak_mib()
        );
        drop(back);
    }
    let body = reduce(&model, &fe_column::attachments(), &fe_column::settings())?;
    let f = body.frequencies_hz(1.0);
    println!(
        "reduce: {} interface DOFs, 30 fixed-interface modes, {:.2} s (nnz(L) {:.1} M), peak {:.0} MiB; first free-free {:.2} {:.2} {:.2} Hz",
        body.interface_dofs(),
        body.reduction_s,
        body.factor_nnz as f64 / 1e6,
        peak_mib(),
        f[0],
        f[1],
        f[2]
    );
    let t = Instant::now();
    let full = free_free_frequencies_hz(&model, 30, 0.1 * f[0])?;
    println!(
        "full free-free, 30 elastic modes: {:.2} s, peak {:.0} MiB; first {:.2} {:.2} {:.2} Hz, 30th {:.2} Hz",
        t.elapsed().as_secs_f64(),
        peak_mib(),
        full[0],
        full[1],
        full[2],
        full[29]
    );
    Ok(())
}
