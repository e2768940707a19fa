//! The shop-style demo folder `measurements/demo-vmc-shop` (GENERATED): the 18 tests of
//! `measurements/demo-vmc/pos-a` rewritten the way a shop records them — the control's traces
//! of the axes in machine coordinates in `cnc/`, one file per test numbered in recording order,
//! the R-Test logger's files in `rtest/`, named by the time of day of each test, with a
//! metadata line, `;` separated, decimal commas, time in ms and positions in µm, on a clock
//! 12.5 ms ahead of the trace's — and one `rtest.toml` with one `[[pairing]]`.
//!
//! Nothing is resampled: the trace holds the internal readings and the R-Test files the
//! external readings of the same rows, so the folder evaluates to the EIJ of pos-a up to the
//! clock offset eij estimates (truth: internal − external clock = −12.5 ms exactly).

use std::path::Path;

use eij::axes::Axis;
use eij::rtest::CircleSeries;

/// The circle centre of pos-a, mm (its `rtest.toml`).
pub const CENTRE: [f64; 3] = [150.0, -100.0, 0.0];
/// The R-Test logger's clock minus the trace's, s.
pub const LOGGER_AHEAD_S: f64 = 0.0125;

/// The tests in recording order: xy, yz, zx; cw, ccw; 2, 5, 8 m/s².
pub fn recording_order() -> Vec<String> {
    let mut v = Vec::new();
    for plane in ["xy", "yz", "zx"] {
        for dir in ["cw", "ccw"] {
            for a in [2, 5, 8] {
                v.push(format!("{plane}_{dir}_{a}"));
            }
        }
    }
    v
}

/// The `rtest.toml` of the folder.
pub fn conditions() -> String {
    "# GENERATED, not measured: measurements/demo-vmc/pos-a rewritten as a shop records it\n\
     # (cargo run --release --example shop_folder -- measurements/demo-vmc-shop; README.md).\n\
     machine = \"demo-vmc\"\n\
     instrument = \"R-Test (generated)\"\n\
     radius_mm = 2.0\n\
     position_mm = [150.0, -100.0, 0.0]\n\
     # The traces hold machine positions: the circle centre is subtracted.\n\
     internal_coordinates = \"absolute\"\n\
     \n\
     [internal_columns]\n\
     t_s = { name = \"time_us\", unit = \"us\" }\n\
     x_int_mm = \"X_act\"\n\
     y_int_mm = \"Y_act\"\n\
     z_int_mm = \"Z_act\"\n\
     \n\
     [external_columns]\n\
     t_s = { name = \"Zeit\", unit = \"ms\" }\n\
     x_ext_mm = { name = \"X\", unit = \"um\" }\n\
     y_ext_mm = { name = \"Y\", unit = \"um\" }\n\
     z_ext_mm = { name = \"Z\", unit = \"um\" }\n\
     \n\
     # Trace k and R-Test file k are one test: no stem is shared, so they pair in recording\n\
     # order (the traces numbered, the R-Test files named by the time of day).\n\
     [[pairing]]\n\
     internal = \"cnc/*.csv\"\n\
     external = \"rtest/*.csv\"\n"
        .to_string()
}

/// Every file of the folder (path inside it, bytes), from the pos-a folder `pos_a`.
pub fn files(pos_a: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out = vec![("rtest.toml".to_string(), conditions().into_bytes())];
    for (k, name) in recording_order().iter().enumerate() {
        let s = CircleSeries::read_csv(pos_a.join(format!("{name}.csv"))).expect("demo file");
        let mut trace = String::from("time_us,X_act,Y_act,Z_act\n");
        // Each test two minutes after the one before, from 10:15:00.
        let start = 10 * 3600 + 15 * 60 + 120 * k;
        let mut probe = format!(
            "R-Test logger export;test {:02};2026-03-02 {:02}:{:02}:{:02}\nZeit;X;Y;Z\n",
            k + 1,
            start / 3600,
            start / 60 % 60,
            start % 60
        );
        for i in 0..s.len() {
            let t = s.t_s()[i];
            let int = Axis::ALL.map(|a| s.int_mm(a)[i] + CENTRE[a.index()]);
            trace.push_str(&format!(
                "{:.0},{:.5},{:.5},{:.5}\n",
                t * 1e6,
                int[0],
                int[1],
                int[2]
            ));
            let ext = Axis::ALL.map(|a| format!("{:.2}", s.ext_mm(a)[i] * 1e3).replace('.', ","));
            probe.push_str(&format!(
                "{};{};{};{}\n",
                format!("{:.3}", (t + LOGGER_AHEAD_S) * 1e3).replace('.', ","),
                ext[0],
                ext[1],
                ext[2]
            ));
        }
        out.push((format!("cnc/TRACE_{:02}.csv", k + 1), trace.into_bytes()));
        out.push((
            format!(
                "rtest/RT_2026-03-02_{:02}-{:02}-{:02}.csv",
                start / 3600,
                start / 60 % 60,
                start % 60
            ),
            probe.into_bytes(),
        ));
    }
    out
}
