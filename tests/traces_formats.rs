//! Controller traces and R-Test files as real exports can differ from the documented layout
//! (docs/measurement-files.md, "What was checked against what"): read alike where the meaning
//! is plain, refused in one line where it is not.
//!
//! - English TNCscope exports name the actual position `s actual` (German `s ist`);
//! - blocks closed by a line holding only `%` (the shop folder's traces have them);
//! - `%COUNT=`: a slower channel packed into the first rows of its column is timed by its
//!   cycle time; a count that matches nothing is refused;
//! - Windows tools write Latin-1 (`µm` as byte B5) or UTF-16 with a byte-order mark;
//! - a Sinumerik trace above 64 MiB is refused before it is parsed.

mod common;

use common::shop;
use common::{one_line_error, root, Scratch};
use eij::axes::Eij;
use eij::measured::inputs::expand_tests;
use eij::measured::suite::{evaluate_tests, SuiteOptions};
use std::collections::BTreeMap;

/// The first test (xy cw 2 m/s²) of a shop folder's `files`: its `rtest.toml` with a
/// `[[test]]` entry naming `internal` and `probe.csv` in place of the pairing, the trace
/// `trace` and the R-Test file.
fn single(files: &[(String, Vec<u8>)], trace: &str, internal: &str) -> (String, Vec<u8>, Vec<u8>) {
    let get = |name: &str| files.iter().find(|(n, _)| n == name).unwrap().1.clone();
    let toml = String::from_utf8(get("rtest.toml")).unwrap();
    let toml = toml[..toml.find("[[pairing]]").unwrap()].to_string()
        + &format!("[[test]]\ninternal = \"{internal}\"\nexternal = \"probe.csv\"\n");
    (toml, get(trace), get(&shop::rtest_name(0)))
}

/// The first test of the TNCscope shop folder: `rtest.toml`, trace, R-Test file.
fn first_test() -> (String, String, Vec<u8>) {
    let files = shop::files(&root().join("measurements/demo-vmc/pos-a"));
    let (toml, trace, probe) = single(&files, "cnc/TRACE_01.sco", "cnc.sco");
    (toml, String::from_utf8(trace).unwrap(), probe)
}

fn eij_of(dir: &std::path::Path) -> Result<BTreeMap<Eij, f64>, String> {
    let tests = expand_tests(&[dir.to_path_buf()]).map_err(|e| e.to_string())?;
    let s = evaluate_tests(&tests, &SuiteOptions::default()).map_err(|e| e.to_string())?;
    assert_eq!(s.tests.len(), 1);
    Ok(s.tests[0].result.eij.value_map().into_iter().collect())
}

/// UTF-16 little-endian with its byte-order mark.
fn utf16(text: &str) -> Vec<u8> {
    let mut b = vec![0xFF, 0xFE];
    for u in text.encode_utf16() {
        b.extend(u.to_le_bytes());
    }
    b
}

/// The same test written as other tools write it gives the same EIJ, exactly.
#[test]
fn a_test_written_differently_reads_alike() {
    let d = Scratch::new("trace-formats");
    let (toml, trace, probe) = first_test();
    let probe_text = String::from_utf8(probe.clone()).unwrap();
    let latin1: Vec<u8> = probe_text.chars().map(|c| c as u32 as u8).collect();
    assert!(latin1.contains(&0xB5) && std::str::from_utf8(&latin1).is_err());
    let variants: Vec<(&str, Vec<u8>, Vec<u8>)> = vec![
        ("asis", trace.clone().into_bytes(), probe.clone()),
        (
            "english",
            trace.replace("s ist", "s actual").into_bytes(),
            probe.clone(),
        ),
        ("latin1", trace.clone().into_bytes(), latin1),
        ("utf16", utf16(&trace), utf16(&probe_text)),
        (
            "comma",
            {
                let data = trace.find("%[DATA]").unwrap();
                (trace[..data].to_string() + &trace[data..].replace('.', ",")).into_bytes()
            },
            probe.clone(),
        ),
        (
            "noclose",
            trace
                .lines()
                .filter(|l| *l != "%")
                .map(|l| format!("{l}\r\n"))
                .collect::<String>()
                .into_bytes(),
            probe.clone(),
        ),
    ];
    let mut first: Option<BTreeMap<Eij, f64>> = None;
    for (folder, t, p) in variants {
        d.write(&format!("{folder}/rtest.toml"), &toml);
        d.write(&format!("{folder}/cnc.sco"), t);
        d.write(&format!("{folder}/probe.csv"), p);
        let e = eij_of(&d.path(folder)).unwrap_or_else(|e| panic!("{folder}: {e}"));
        match &first {
            None => first = Some(e),
            Some(f) => assert!(f == &e, "{folder}: {e:?} vs {f:?}"),
        }
    }
}

/// A Sinumerik trace declared ISO-8859-1, with a Latin-1 byte in its caption (as Operate
/// writes them), and one in UTF-16 with a byte-order mark give the EIJ of the same trace in
/// UTF-8.
#[test]
fn a_latin1_sinumerik_trace_reads_alike() {
    let d = Scratch::new("trace-latin1");
    let files = shop::sinumerik_files(&root().join("measurements/demo-vmc/pos-a"));
    let (toml, xml, probe) = single(&files, "cnc/TRACE_01.xml", "cnc.xml");
    let xml = String::from_utf8(xml).unwrap();
    let latin1 = xml
        .replace("encoding=\"UTF-8\"", "encoding=\"ISO-8859-1\"")
        .replace("<traceData>", "<traceCaption>Kreis 2 mm, Vorschub 3 m/min, Ma\u{df}e in mm</traceCaption>\n  <traceData>")
        .chars()
        .map(|c| u8::try_from(u32::from(c)).unwrap())
        .collect::<Vec<u8>>();
    assert!(std::str::from_utf8(&latin1).is_err());
    let mut eij = Vec::new();
    let wide = utf16(&xml.replace("encoding=\"UTF-8\"", "encoding=\"UTF-16\""));
    for (folder, bytes) in [
        ("utf8", xml.into_bytes()),
        ("latin1", latin1),
        ("utf16", wide),
    ] {
        d.write(&format!("{folder}/rtest.toml"), &toml);
        d.write(&format!("{folder}/cnc.xml"), bytes);
        d.write(&format!("{folder}/probe.csv"), &probe);
        eij.push(eij_of(&d.path(folder)).unwrap_or_else(|e| panic!("{folder}: {e}")));
    }
    assert!(eij[0] == eij[1] && eij[0] == eij[2]);
}

/// A slower channel packed into the first rows of its column (`%COUNT=` rows at twice the row
/// interval, the rest of the column empty): its k-th value is its sample at 2k ms; the faster
/// channels meet it there. A `%COUNT=` that matches neither the samples nor a packed channel
/// is refused naming its line.
#[test]
fn count_tells_a_packed_slower_channel() {
    let d = Scratch::new("trace-count");
    let rows = 400;
    let pos = |t: f64| {
        let w = 2.0 * std::f64::consts::PI * 2.0;
        [
            150.0 + 2.0 * (w * t).cos(),
            -100.0 + 2.0 * (w * t).sin(),
            0.5 * t,
        ]
    };
    let mut head = String::from("%TNCscopeNT data file\n%[GLOBAL]\n%SAMPLING=1000\n%\n");
    for (n, (axis, count, cycle)) in [("X", rows, 1000), ("Y", rows, 1000), ("Z", rows / 2, 2000)]
        .into_iter()
        .enumerate()
    {
        head.push_str(&format!(
            "%[CURVE{}]\n%NAME=s ist/{axis}\n%CHANNELTYPE=s ist\n%AXISTYPE={axis}\n%DIMENSION=mm\n%COUNT={count}\n%CYCLETIME={cycle}\n%COLUMN={}\n%\n",
            n + 1,
            n + 1
        ));
    }
    head.push_str("%[DATA]\n");
    let mut body = String::new();
    for i in 0..rows {
        let t = i as f64 * 1e-3;
        let p = pos(t);
        let z = if i < rows / 2 {
            shop::sci(pos(2.0 * t)[2])
        } else {
            String::new()
        };
        body.push_str(&format!(
            "{}; {}; {}; {z};\n",
            shop::sci(t * 1e6),
            shop::sci(p[0]),
            shop::sci(p[1])
        ));
    }
    let toml = "radius_mm = 2.0\nposition_mm = [150.0, -100.0, 0.0]\ninternal_coordinates = \"absolute\"\n\n[[test]]\ninternal = \"cnc.sco\"\nexternal = \"probe.csv\"\n";
    d.write("packed/rtest.toml", toml);
    d.write("packed/cnc.sco", format!("{head}{body}"));
    d.write(
        "packed/probe.csv",
        "t_s,x_ext_mm,y_ext_mm,z_ext_mm\n0,2,0,0\n",
    );
    let tests = expand_tests(&[d.path("packed")]).unwrap();
    let r = tests[0]
        .read_internal()
        .unwrap()
        .expect("a two-system test");
    // The base is Z's 200 samples at 0, 2, 4, … ms; X and Y taken there as written (machine
    // coordinates: the reader gives the file's numbers).
    assert_eq!(r.t_s.len(), rows / 2);
    for (k, t) in r.t_s.iter().enumerate() {
        let want = 2.0 * k as f64 * 1e-3;
        assert!((t - want).abs() < 1e-12, "{k}: {t} s");
        let p = pos(want);
        let held = |v: f64| shop::sci(v).parse::<f64>().unwrap();
        assert_eq!(r.mm[0][k], held(p[0]), "x at {k}");
        assert_eq!(r.mm[2][k], held(p[2]), "z at {k}");
    }
    // A count that fits nothing: 150 where Z holds 200 samples.
    let wrong = format!("{head}{body}").replacen("%COUNT=200", "%COUNT=150", 1);
    d.write("wrong/rtest.toml", toml);
    d.write("wrong/cnc.sco", &wrong);
    d.write(
        "wrong/probe.csv",
        "t_s,x_ext_mm,y_ext_mm,z_ext_mm\n0,2,0,0\n",
    );
    let line = wrong.lines().position(|l| l == "%COUNT=150").unwrap() + 1;
    let needle = format!(
        "wrong/cnc.sco:{line}: %COUNT=150 of channel 's ist/Z', but its column holds 200 sample(s)"
    );
    let tests = expand_tests(&[d.path("wrong")]).unwrap();
    let e = tests[0].read_internal().unwrap_err().to_string();
    assert!(e.contains(&needle), "{e}");
    one_line_error(&common::eij(&["evaluate", &d.s("wrong")]), &[&needle]);
}

/// A Sinumerik trace one byte above 64 MiB: one line saying the limit, before it is parsed.
#[test]
fn a_sinumerik_trace_above_the_limit_is_refused() {
    let d = Scratch::new("trace-big");
    let head = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<trace>\n<!-- ";
    let mut xml = head.as_bytes().to_vec();
    xml.resize((64 << 20) + 1, b' ');
    d.write("big/trace.xml", &xml);
    d.write(
        "big/rtest.toml",
        "radius_mm = 2.0\n[[test]]\ninternal = \"trace.xml\"\nexternal = \"probe.csv\"\n",
    );
    d.write("big/probe.csv", "t_s,x_ext_mm,y_ext_mm,z_ext_mm\n0,2,0,0\n");
    drop(xml);
    let needle = "big/trace.xml: a Sinumerik trace of 64.0 MiB: eij reads traces of up to 64 MiB";
    let tests = expand_tests(&[d.path("big")]).unwrap();
    let e = tests[0].read_internal().unwrap_err().to_string();
    assert!(e.contains(needle), "{e}");
    one_line_error(&common::eij(&["evaluate", &d.s("big")]), &[needle]);
}
