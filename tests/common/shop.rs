//! The shop-style demo folder `measurements/demo-vmc-shop` (GENERATED): the 18 tests of
//! `measurements/demo-vmc/pos-a` rewritten the way a shop records them — the control's
//! TNCscope traces of the axes in `cnc/` (the text export as the control writes it: a
//! `%TNCscopeNT data file` header, one `%[CURVEn]` block per `s ist` channel, time in µs,
//! numbers like `1.520000000e+002;`, positions in absolute machine coordinates), one file per
//! test numbered in recording order; the R-Test logger's files in `rtest/`, named by the time
//! of day of each test, with a metadata line and a units row, `;` separated, decimal commas,
//! time in ms and positions in µm, on a clock 12.5 ms ahead of the trace's — and one
//! `rtest.toml` with one `[[pairing]]`.
//!
//! Nothing is resampled: the trace holds the internal readings and the R-Test files the
//! external readings of the same rows, so the folder evaluates to the EIJ of pos-a up to the
//! clock offset eij estimates (truth: internal − external clock = −12.5 ms exactly).
//!
//! [`sinumerik_files`] writes the same tests with Sinumerik Operate trace XML in place of the
//! TNCscope exports (for a test, not bundled).

use std::path::Path;

use eij::axes::Axis;
use eij::rtest::CircleSeries;

/// The circle centre of pos-a, mm (its `rtest.toml`).
pub const CENTRE: [f64; 3] = [150.0, -100.0, 0.0];
/// The R-Test logger's clock minus the trace's, s.
pub const LOGGER_AHEAD_S: f64 = 0.0125;

/// A number as TNCscope writes it: `3.000000000e+003` (ten significant digits, a signed
/// three-digit exponent).
pub fn sci(v: f64) -> String {
    let s = format!("{v:.9e}");
    let (m, e) = s.split_once('e').expect("{:e} has an exponent");
    let e: i32 = e.parse().expect("an integer exponent");
    format!("{m}e{}{:03}", if e < 0 { '-' } else { '+' }, e.abs())
}

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
     # The R-Test files' column names; their units come from the units row under the header.\n\
     # (The traces need no entry: eij takes their s ist channels, time and units as written.)\n\
     [external_columns]\n\
     t_s = \"Zeit\"\n\
     x_ext_mm = \"X\"\n\
     y_ext_mm = \"Y\"\n\
     z_ext_mm = \"Z\"\n\
     \n\
     # Trace k and R-Test file k are one test: no stem is shared, so they pair in recording\n\
     # order (the traces numbered, the R-Test files named by the time of day).\n\
     [[pairing]]\n\
     internal = \"cnc/*.sco\"\n\
     external = \"rtest/*.csv\"\n"
        .to_string()
}

/// The clock time of test `k` (0-based; two minutes apart from 10:15:00): `(h, m, s)`.
fn start(k: usize) -> (usize, usize, usize) {
    let s = 10 * 3600 + 15 * 60 + 120 * k;
    (s / 3600, s / 60 % 60, s % 60)
}

/// A TNCscope text export of the internal readings `int` (machine coordinates, mm) at
/// `t_s`, as the control writes it; `(h, m, s)` the time of day it was recorded.
pub fn sco(t_s: &[f64], int: &[Vec<f64>; 3], (h, m, s): (usize, usize, usize)) -> String {
    let mut out = format!(
        "%TNCscopeNT data file\n%[GLOBAL]\n%VERSION=3.0\n%SAMPLING=1000\n%CHANNELS=3\n\
         %DATE=2026-03-02 {h:02}:{m:02}:{s:02}\n%\n"
    );
    for axis in Axis::ALL {
        out.push_str(&format!(
            "%[CURVE{n}]\n%NAME=s ist/{l}\n%CHANNELTYPE=s ist\n%AXISTYPE={l}\n%DIMENSION=mm\n\
             %COUNT={count}\n%CYCLETIME=1000\n%COLUMN={n}\n%\n",
            n = axis.index() + 1,
            l = axis.letter(),
            count = t_s.len()
        ));
    }
    out.push_str("%[DATA]\n");
    for (i, t) in t_s.iter().enumerate() {
        out.push_str(&sci((t * 1e6).round()));
        out.push(';');
        for v in int {
            out.push(' ');
            out.push_str(&sci(v[i]));
            out.push(';');
        }
        out.push('\n');
    }
    out
}

/// A Sinumerik Operate trace (XML) of the internal readings `int` (machine coordinates, mm)
/// at `t_s`: signals `Position actual value X1` … `Z1 (64 bit)`, time in s.
pub fn sinumerik_xml(t_s: &[f64], int: &[Vec<f64>; 3]) -> String {
    let mut out = String::from(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<trace version=\"1.0\">\n  <traceData>\n    <dataFrame name=\"frame1\">\n",
    );
    for axis in Axis::ALL {
        out.push_str(&format!(
            "      <dataSignal name=\"/Nck/MachineAxis/measPos1[u1,{}]\" description=\"Position actual value {}1 (64 bit)\" />\n",
            axis.index() + 1,
            axis.letter()
        ));
    }
    for (i, t) in t_s.iter().enumerate() {
        out.push_str(&format!(
            "      <rec time=\"{t}\" f1=\"{:.6}\" f2=\"{:.6}\" f3=\"{:.6}\" />\n",
            int[0][i], int[1][i], int[2][i]
        ));
    }
    out.push_str("    </dataFrame>\n  </traceData>\n</trace>\n");
    out
}

/// The R-Test logger's file of test `k` (0-based): a metadata line, the header `Zeit;X;Y;Z`,
/// a units row, rows of time (ms, on the logger's clock) and positions (µm) with decimal
/// commas.
pub fn rtest_csv(k: usize, t_s: &[f64], ext: &[Vec<f64>; 3]) -> String {
    let (h, m, s) = start(k);
    let mut out = format!(
        "R-Test logger export;test {:02};2026-03-02 {h:02}:{m:02}:{s:02}\nZeit;X;Y;Z\n[ms];[µm];[µm];[µm]\n",
        k + 1
    );
    let comma = |v: f64, decimals: usize| format!("{v:.decimals$}").replace('.', ",");
    for (i, t) in t_s.iter().enumerate() {
        out.push_str(&format!(
            "{};{};{};{}\n",
            comma((t + LOGGER_AHEAD_S) * 1e3, 3),
            comma(ext[0][i] * 1e3, 2),
            comma(ext[1][i] * 1e3, 2),
            comma(ext[2][i] * 1e3, 2)
        ));
    }
    out
}

/// The R-Test file name of test `k` (0-based).
pub fn rtest_name(k: usize) -> String {
    let (h, m, s) = start(k);
    format!("rtest/RT_2026-03-02_{h:02}-{m:02}-{s:02}.csv")
}

/// One test: time (s), internal readings in machine coordinates and external readings (mm).
type Test = (Vec<f64>, [Vec<f64>; 3], [Vec<f64>; 3]);

/// Every test of pos-a in recording order: time, internal readings in machine coordinates
/// (the circle centre added), external readings.
fn tests(pos_a: &Path) -> Vec<Test> {
    recording_order()
        .iter()
        .map(|name| {
            let s = CircleSeries::read_csv(pos_a.join(format!("{name}.csv"))).expect("demo file");
            let int =
                Axis::ALL.map(|a| s.int_mm(a).iter().map(|v| v + CENTRE[a.index()]).collect());
            let ext = Axis::ALL.map(|a| s.ext_mm(a).to_vec());
            (s.t_s().to_vec(), int, ext)
        })
        .collect()
}

/// Every file of the folder (path inside it, bytes), from the pos-a folder `pos_a`.
pub fn files(pos_a: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out = vec![("rtest.toml".to_string(), conditions().into_bytes())];
    for (k, (t, int, ext)) in tests(pos_a).iter().enumerate() {
        out.push((
            format!("cnc/TRACE_{:02}.sco", k + 1),
            sco(t, int, start(k)).into_bytes(),
        ));
        out.push((rtest_name(k), rtest_csv(k, t, ext).into_bytes()));
    }
    out
}

/// The folder with Sinumerik Operate traces (`cnc/TRACE_kk.xml`) in place of the TNCscope
/// exports, and an `rtest.toml` that maps their signals (not bundled; see the module docs).
pub fn sinumerik_files(pos_a: &Path) -> Vec<(String, Vec<u8>)> {
    let toml = conditions().replace("cnc/*.sco", "cnc/*.xml").replace(
        "[external_columns]",
        "[internal_columns]\n\
         x_int_mm = { name = \"Position actual value X1\", unit = \"mm\" }\n\
         y_int_mm = { name = \"Position actual value Y1\", unit = \"mm\" }\n\
         z_int_mm = { name = \"Position actual value Z1\", unit = \"mm\" }\n\n\
         [external_columns]",
    );
    let mut out = vec![("rtest.toml".to_string(), toml.into_bytes())];
    for (k, (t, int, ext)) in tests(pos_a).iter().enumerate() {
        out.push((
            format!("cnc/TRACE_{:02}.xml", k + 1),
            sinumerik_xml(t, int).into_bytes(),
        ));
        out.push((rtest_name(k), rtest_csv(k, t, ext).into_bytes()));
    }
    out
}
