//! Controller traces written by hand from the published formats (docs/measurement-files.md,
//! "Controller traces"): TNCscope text exports and Sinumerik Operate trace XML, and the demo's
//! contract CSV files split into the internal and external recordings of two systems.
#![allow(dead_code)]

use super::root;

pub use super::shop::sci;

/// The value a cell written by [`sci`] holds.
pub fn held(v: f64) -> f64 {
    sci(v).parse().unwrap()
}

/// One `%[CURVEn]` block.
#[derive(Clone)]
pub struct Curve {
    /// `%NAME=`, e.g. `s ist/X`.
    pub name: &'static str,
    /// `%CHANNELTYPE=`.
    pub channel_type: &'static str,
    /// `%AXISTYPE=`.
    pub axis: &'static str,
    /// `%DIMENSION=`.
    pub dimension: &'static str,
    /// `%CYCLETIME=`, µs.
    pub cycle_us: u32,
    /// `%COLUMN=` (1-based after the time).
    pub column: usize,
}

/// A curve `"{channel_type}/{axis}"`.
pub fn curve(
    channel_type: &'static str,
    axis: &'static str,
    dimension: &'static str,
    column: usize,
) -> Curve {
    let name: &'static str = Box::leak(format!("{channel_type}/{axis}").into_boxed_str());
    Curve {
        name,
        channel_type,
        axis,
        dimension,
        cycle_us: 1000,
        column,
    }
}

/// The header of a TNCscope export (up to and including `%[DATA]`).
pub fn sco_header(sampling_us: u32, curves: &[Curve]) -> String {
    let mut s = String::from("%TNCscopeNT data file\n%[GLOBAL]\n%VERSION=3.0\n");
    s.push_str(&format!(
        "%SAMPLING={sampling_us}\n%CHANNELS={}\n",
        curves.len()
    ));
    s.push_str("%DATE=2026-11-28 14:02:11\n");
    for (i, c) in curves.iter().enumerate() {
        s.push_str(&format!(
            "%[CURVE{}]\n%NAME={}\n%CHANNELTYPE={}\n%AXISTYPE={}\n%DIMENSION={}\n%CYCLETIME={}\n%COLUMN={}\n",
            i + 1,
            c.name,
            c.channel_type,
            c.axis,
            c.dimension,
            c.cycle_us,
            c.column
        ));
    }
    s.push_str("%[DATA]\n");
    s
}

/// One data row `time_us; v1; v2; …;` (`None`: an empty cell).
pub fn sco_row(t_us: f64, values: &[Option<f64>]) -> String {
    let mut s = sci(t_us);
    s.push(';');
    for v in values {
        s.push(' ');
        if let Some(v) = v {
            s.push_str(&sci(*v));
        }
        s.push(';');
    }
    s.push('\n');
    s
}

/// The number of header lines [`sco_header`] writes: the first data row is this plus one.
pub fn sco_header_lines(curves: usize) -> u64 {
    6 + 7 * curves as u64 + 1
}

/// One `dataSignal`.
pub struct Signal {
    pub name: &'static str,
    pub description: &'static str,
}

/// A Sinumerik Operate trace with one `dataFrame`: `recs` are (time s, [(signal number
/// 1-based, value text)]).
pub fn sinumerik(signals: &[Signal], recs: &[(f64, Vec<(usize, String)>)]) -> String {
    let mut s = String::from(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<trace version=\"1.0\">\n  <traceCaption>circle xy</traceCaption>\n  <traceData>\n    <dataFrame name=\"frame1\">\n",
    );
    for sig in signals {
        s.push_str(&format!(
            "      <dataSignal name=\"{}\" description=\"{}\" />\n",
            sig.name, sig.description
        ));
    }
    for (t, values) in recs {
        s.push_str(&format!("      <rec time=\"{t}\""));
        for (k, v) in values {
            s.push_str(&format!(" f{k}=\"{v}\""));
        }
        s.push_str(" />\n");
    }
    s.push_str("    </dataFrame>\n  </traceData>\n</trace>\n");
    s
}

/// The lines [`sinumerik`] writes before the first `rec`.
pub fn sinumerik_header_lines(signals: usize) -> u64 {
    5 + signals as u64
}

/// A contract CSV of the demo data: time and the internal and external columns.
pub struct DemoTest {
    pub t_s: Vec<f64>,
    pub int: [Vec<f64>; 3],
    pub ext: [Vec<f64>; 3],
}

/// Reads `measurements/demo-vmc/<name>` (contract layout).
pub fn demo_test(name: &str) -> DemoTest {
    let text = std::fs::read_to_string(root().join("measurements/demo-vmc").join(name)).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "t_s,x_int_mm,y_int_mm,z_int_mm,x_ext_mm,y_ext_mm,z_ext_mm"
    );
    let mut d = DemoTest {
        t_s: Vec::new(),
        int: Default::default(),
        ext: Default::default(),
    };
    for l in lines {
        let v: Vec<f64> = l.split(',').map(|c| c.parse().unwrap()).collect();
        d.t_s.push(v[0]);
        for k in 0..3 {
            d.int[k].push(v[1 + k]);
            d.ext[k].push(v[4 + k]);
        }
    }
    d
}

impl DemoTest {
    /// The external recording as a CSV file of its own.
    pub fn external_csv(&self) -> String {
        let mut s = String::from("t_s,x_ext_mm,y_ext_mm,z_ext_mm\n");
        for i in 0..self.t_s.len() {
            s.push_str(&format!(
                "{},{},{},{}\n",
                self.t_s[i], self.ext[0][i], self.ext[1][i], self.ext[2][i]
            ));
        }
        s
    }
}
