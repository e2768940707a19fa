//! Compensation from a calibrated model: `eij compensation`, `eij simulate … --compensation`
//! and `eij evaluate-move`, on the demo machine identified from the bundled measurements.

use eij::axes::{Axis, Direction, Eij, Plane};
use eij::compensation::CompensationTable;
use eij::machine::Machine;
use eij::predict::{simulated_eij, CircleTest, SimSettings};
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::OnceLock;

mod common;

use common::{one_line_error, run, Scratch};

/// The identified demo machine and its compensation table, made once for all tests.
fn identified() -> &'static (Scratch, String, String) {
    static CELL: OnceLock<(Scratch, String, String)> = OnceLock::new();
    CELL.get_or_init(|| {
        let s = Scratch::new("compensation");
        let (machine, report) = (s.s("id.toml"), s.s("id.json"));
        // --report too: the default one would replace out/demo-vmc-identify-report.json.
        let r = run(&[
            "identify",
            "--quiet",
            "--no-design",
            "--out",
            &machine,
            "--report",
            &report,
        ]);
        assert!(r.ok, "{}", r.stderr);
        let table = s.s("table.csv");
        let r = run(&["compensation", "--machine", &machine, "--out", &table]);
        assert!(r.ok, "{}", r.stderr);
        (s, machine, table)
    })
}

/// A CSV as columns by name.
fn columns(path: &str) -> BTreeMap<String, Vec<f64>> {
    let mut rdr = csv::Reader::from_path(path).unwrap();
    let names: Vec<String> = rdr.headers().unwrap().iter().map(String::from).collect();
    let mut cols: BTreeMap<String, Vec<f64>> = names.iter().map(|n| (n.clone(), vec![])).collect();
    for rec in rdr.records() {
        for (n, v) in names.iter().zip(rec.unwrap().iter()) {
            cols.get_mut(n).unwrap().push(v.parse().unwrap());
        }
    }
    cols
}

/// The paper's 20 mm Z move (30 000 mm/min, 10 m/s², 250 m/s³) at `pos`, with extra options.
fn z_move(out: &str, pos: &str, extra: &[&str]) -> BTreeMap<String, Vec<f64>> {
    let r = z_move_run(out, pos, extra);
    assert!(r.ok, "{}", r.stderr);
    columns(out)
}

/// The Z move of [`z_move`], its console output.
fn z_move_run(out: &str, pos: &str, extra: &[&str]) -> common::Run {
    let (_, machine, _) = identified();
    let mut args = vec![
        "simulate",
        "move",
        "--machine",
        machine,
        "--position-mm",
        pos,
        "--axis",
        "z",
        "--distance-mm",
        "20",
        "--feed-mm-min",
        "30000",
        "--accel-m-s2",
        "10",
        "--jerk-m-s3",
        "250",
        "--rate-hz",
        "2000",
        "--out",
        out,
    ];
    args.extend_from_slice(extra);
    run(&args)
}

/// Largest |TCP − nominal path| of direction `a` over the move, µm.
fn worst_um(c: &BTreeMap<String, Vec<f64>>, a: &str) -> f64 {
    c[&format!("{a}_ext_mm")]
        .iter()
        .zip(&c[&format!("{a}_set_mm")])
        .map(|(e, s)| (e - s).abs() * 1e3)
        .fold(0.0, f64::max)
}

#[test]
fn the_table_reproduces_the_models_eij_on_its_grid() {
    // Independent of the table's own fit: simulate the EIJ at grid points afresh (the mean of
    // the two planes that accelerate J) and compare with k_IJ(s_K) there; the difference may
    // not exceed the worst residual the table states.
    let (_, machine, table) = identified();
    let m = Machine::from_file(Path::new(machine)).unwrap();
    let t = CompensationTable::read(Path::new(table), &m).unwrap();
    assert_eq!(t.coefficients.len(), 9);
    let points = [
        [-300.0, -250.0, -100.0],
        [150.0, 0.0, 200.0],
        [300.0, 250.0, 300.0],
    ];
    for p in points {
        let pos: Vec<f64> = p.iter().map(|v| v * 1e-3).collect();
        let tests: Vec<CircleTest> = Plane::ALL
            .iter()
            .map(|&pl| CircleTest::new(pl, Direction::Ccw, 2.0, 5.0).at(pos.clone()))
            .collect();
        let sims = simulated_eij(std::slice::from_ref(&m), &tests, &SimSettings::default())
            .unwrap()
            .remove(0);
        for c in &t.coefficients {
            let vals: Vec<f64> = sims
                .iter()
                .filter_map(|s| s.get(&c.parameter))
                .copied()
                .collect();
            assert_eq!(vals.len(), 2, "{}", c.parameter);
            let model = 0.5 * (vals[0] + vals[1]);
            let d = (c.at(p) - model).abs();
            assert!(
                d <= c.worst_residual_um_s2_per_m + 1e-5,
                "{} at {p:?}: table {:.5}, model {model:.5}, worst residual {}",
                c.parameter,
                c.at(p),
                c.worst_residual_um_s2_per_m
            );
        }
    }
    // The table's cross-talk of the Z move: EXZ and EYZ are large and nearly constant.
    let exz = t.get(Eij::new(Axis::X, Axis::Z)).unwrap();
    assert!(exz.offset_um_s2_per_m < -0.3 && exz.worst_residual_um_s2_per_m < 0.01);
}

#[test]
fn compensation_reduces_the_z_moves_cross_talk_tenfold_anywhere() {
    let (s, _, table) = identified();
    for pos in ["0,0,0", "150,-100,100"] {
        let plain = z_move(&s.s("plain.csv"), pos, &[]);
        let comp = z_move(&s.s("comp.csv"), pos, &["--compensation", table]);
        // The nominal path is the same; the correction is its own column.
        assert_eq!(plain["z_set_mm"], comp["z_set_mm"]);
        assert_eq!(plain["x_set_mm"], comp["x_set_mm"]);
        assert!(comp.contains_key("x_comp_mm") && !plain.contains_key("x_comp_mm"));
        for a in ["x", "y"] {
            let (before, after) = (worst_um(&plain, a), worst_um(&comp, a));
            assert!(
                before > 3.0,
                "{pos}: {a} cross-talk {before} µm without compensation"
            );
            assert!(
                after * 10.0 < before,
                "{pos}: {a} cross-talk {before:.3} µm → {after:.3} µm with compensation"
            );
        }
    }
}

#[test]
fn the_correction_column_is_minus_k_times_the_set_acceleration() {
    // Hand check at the sample of peak deceleration: comp_x = −k_XZ·a_z (+ −k_XX·a_x = 0).
    let (s, machine, table) = identified();
    let c = z_move(&s.s("hand.csv"), "0,0,0", &["--compensation", table]);
    let m = Machine::from_file(Path::new(machine)).unwrap();
    let t = CompensationTable::read(Path::new(table), &m).unwrap();
    let a = &c["z_acc_set_m_s2"];
    let k = (0..a.len()).min_by(|&i, &j| a[i].total_cmp(&a[j])).unwrap();
    assert!(a[k] < -5.0);
    let pos = [0.0, 0.0, c["z_set_mm"][k]];
    let kxz = t.get(Eij::new(Axis::X, Axis::Z)).unwrap().at(pos);
    let want_mm = -kxz * 1e-6 * a[k] * 1e3;
    assert!(
        (c["x_comp_mm"][k] - want_mm).abs() < 1e-9,
        "{} vs {want_mm}",
        c["x_comp_mm"][k]
    );
}

#[test]
fn move_eij_agree_with_circle_eij() {
    // The move's acceleration is no single 8 Hz line (ramps of 40 ms, 0–30 Hz), but the
    // structure's response is flat below its first modes, so both give the same EIJ within a
    // few per cent (measured 1–2 %); the issue asks 25 % with the sign right.
    let (s, machine, _) = identified();
    let path = s.s("eval.csv");
    z_move(&path, "0,0,0", &[]);
    let r = run(&["evaluate-move", &path, "--axis", "z", "--json"]);
    assert!(r.ok, "{}", r.stderr);
    let v: serde_json::Value = serde_json::from_str(&r.stdout).unwrap();
    assert_eq!(v["axis"], "z");
    let m = Machine::from_file(Path::new(machine)).unwrap();
    let tests = [Plane::Yz, Plane::Zx].map(|p| CircleTest::new(p, Direction::Ccw, 2.0, 5.0));
    let sims = simulated_eij(&[m], &tests, &SimSettings::default())
        .unwrap()
        .remove(0);
    for dev in Axis::ALL {
        let e = Eij::new(dev, Axis::Z);
        let circle = 0.5 * (sims[0][&e] + sims[1][&e]);
        let mv = v["eij_um_s2_per_m"][e.name()].as_f64().unwrap();
        let se = v["std_err_um_s2_per_m"][e.name()].as_f64().unwrap();
        assert!(se > 0.0 && se < 0.05, "{e}: std err {se}");
        assert!(
            mv.signum() == circle.signum() && ((mv - circle) / circle).abs() < 0.05,
            "{e}: move {mv:.4}, circles {circle:.4}"
        );
    }
}

#[test]
fn bad_tables_and_moves_are_refused_in_one_line() {
    let (s, machine, table) = identified();
    let good = std::fs::read_to_string(table).unwrap();
    let bad = |name: &str, text: String, needles: &[&str]| {
        let p = s.s(name);
        std::fs::write(&p, text).unwrap();
        let out_csv = s.s("never.csv");
        let out = common::eij(&[
            "simulate",
            "move",
            "--machine",
            machine,
            "--axis",
            "z",
            "--distance-mm",
            "5",
            "--feed-mm-min",
            "6000",
            "--accel-m-s2",
            "2",
            "--jerk-m-s3",
            "100",
            "--rate-hz",
            "1000",
            "--compensation",
            &p,
            "--out",
            &out_csv,
        ]);
        one_line_error(&out, needles);
        assert!(!Path::new(&out_csv).exists(), "{name}: output written");
    };
    bad(
        "unknown.csv",
        good.replace("EXY,", "EQY,"),
        &["unknown.csv", "line", "unknown parameter 'EQY'"],
    );
    bad(
        "units.csv",
        good.replace("offset_um_s2_per_m", "offset_nm_s2_per_m"),
        &["units.csv", "header", "unknown column 'offset_nm_s2_per_m'"],
    );
    let header = good.lines().next().unwrap();
    bad(
        "nan.csv",
        format!("{header}\nEXY,none,NaN,0,0.1\n"),
        &["nan.csv", "line 2", "not finite"],
    );
    bad(
        "axis.csv",
        good.replace("EXX,z,", "EXX,w,"),
        &["axis.csv", "line 2", "adaptation_axis"],
    );
    let twice = format!("{good}{}", good.lines().nth(1).unwrap());
    bad("twice.csv", twice, &["twice.csv", "given twice"]);
    bad(
        "huge.csv",
        good.replace("EXY,none,-0.", "EXY,none,-1000000."),
        &["huge.csv", "implausible"],
    );
    // An axis the machine lacks: the single-axis slide has no Z.
    let p = s.s("noz.csv");
    std::fs::write(
        &p,
        "parameter,adaptation_axis,offset_um_s2_per_m,slope_um_s2_per_m_per_mm\nEZX,none,0.1,0\n",
    )
    .unwrap();
    let out = common::eij(&[
        "simulate",
        "move",
        "--machine",
        "machines/reference/single-axis.toml",
        "--axis",
        "x",
        "--distance-mm",
        "5",
        "--feed-mm-min",
        "6000",
        "--accel-m-s2",
        "2",
        "--jerk-m-s3",
        "100",
        "--compensation",
        &p,
        "--out",
        &s.s("never.csv"),
    ]);
    one_line_error(&out, &["noz.csv", "line 2", "has no axis z"]);
    // A move file without the moved axis's set point, and a file that is no move.
    let p = s.s("noset.csv");
    std::fs::write(&p, format!("{}\n0,0,0,0,0,0,0\n", common::HEADER)).unwrap();
    one_line_error(
        &common::eij(&["evaluate-move", &p, "--axis", "z"]),
        &["noset.csv", "z_acc_set_m_s2"],
    );
}

#[test]
fn the_report_shows_the_compensated_move_and_move_against_circle_eij() {
    let (s, _, table) = identified();
    let (plain, comp) = (s.s("rep-plain.csv"), s.s("rep-comp.csv"));
    z_move(&plain, "0,0,0", &[]);
    z_move(&comp, "0,0,0", &["--compensation", table]);
    let out = s.s("report");
    let r = run(&[
        "report",
        "--measured",
        "measurements/demo-vmc/pos-a",
        "--move",
        &plain,
        "--move",
        &comp,
        "--out",
        &out,
    ]);
    assert!(r.ok, "{}", r.stderr);
    let html = std::fs::read_to_string(Path::new(&out).join("report.html")).unwrap();
    assert!(html.contains("EIJ from the moves and from the circles"));
    // Both moves give EXZ near the circles' mean, in the table's rows.
    assert_eq!(html.matches("<td>EXZ</td>").count(), 2, "{html}");
    // The move figures, inline in the page.
    let svgs: Vec<&str> = html
        .match_indices("<figure id=\"move-")
        .map(|(i, _)| &html[i..i + html[i..].find("</figure>").unwrap()])
        .collect();
    assert_eq!(svgs.len(), 2);
    let with = svgs
        .iter()
        .filter(|t| t.contains("with compensation"))
        .count();
    assert_eq!(with, 1, "one move figure shows the compensated deviation");
    // The compensated move's figure finds its plain run on the page and draws that run's
    // TCP − nominal path as "without compensation" (what the table reduces), as
    // `simulate move --compensation --plot` does; not the structural ext − int.
    let comp_svg = svgs
        .iter()
        .find(|t| t.contains("with compensation"))
        .unwrap();
    assert!(
        comp_svg.contains("dx without compensation (TCP − nominal path)")
            && comp_svg.contains("dx with compensation (TCP − nominal path)"),
        "{comp_svg}"
    );
    // The table gives the compensated move's EIJ against the nominal path beside ext − int:
    // the plain move's EIJ minus the table's k at the move (hand, from the table file), up to
    // the servo lag on the correction (3 % of E, as evaluate-move --nominal is checked).
    assert!(html.contains("<th>with compensation (TCP − nominal path)</th>"));
    let (machine, table) = (&identified().1, &identified().2);
    let m = Machine::from_file(Path::new(machine)).unwrap();
    let t = CompensationTable::read(Path::new(table), &m).unwrap();
    let cells = |file: &str, eij: &str| -> Vec<String> {
        let row = html
            .lines()
            .find(|l| l.starts_with(&format!("<tr><td>{file}</td><td>{eij}</td>")))
            .unwrap_or_else(|| panic!("no row {file} {eij}"));
        row.trim_start_matches("<tr><td>")
            .trim_end_matches("</td></tr>")
            .split("</td><td>")
            .map(String::from)
            .collect()
    };
    for i in [Axis::X, Axis::Y] {
        let e = Eij::new(i, Axis::Z);
        let name = e.name();
        let p = cells(&plain, &name);
        let c = cells(&comp, &name);
        assert_eq!((p[4].as_str(), p[5].as_str()), ("–", "–"), "{p:?}");
        let e_plain: f64 = p[2].parse().unwrap();
        let left: f64 = c[4].parse().unwrap();
        let k = t.get(e).unwrap().at([0.0, 0.0, 10.0]);
        assert!(
            (left - (e_plain - k)).abs() < 0.03 * e_plain.abs(),
            "{name}: with compensation {left}, E − k = {e_plain} − {k}"
        );
        // ext − int of the compensated move: the structure, which the table leaves but for
        // what the correction's own small motions of X and Y excite (1 % on EYZ).
        let e_comp: f64 = c[2].parse().unwrap();
        assert!(
            (e_comp - e_plain).abs() < 0.02 * e_plain.abs(),
            "{c:?} {p:?}"
        );
    }
    // The compensated move alone: no plain run to pair with, so the structural deviation
    // stands for the move without the table, and says so.
    let out = s.s("report-comp-alone");
    let r = run(&["report", "--move", &comp, "--out", &out]);
    assert!(r.ok, "{}", r.stderr);
    let html = std::fs::read_to_string(Path::new(&out).join("report.html")).unwrap();
    assert!(html.contains("dx ≈ without compensation (x_ext − x_int)"));
    assert!(html.contains("dx with compensation (TCP − nominal path)"));
    assert!(!html.contains("dx without compensation (TCP − nominal path)"));
}

/// The numbers of `text` (a header line or a console line) in order, as written.
fn numbers(text: &str) -> Vec<f64> {
    text.split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-'))
        .filter_map(|w| w.parse().ok())
        .collect()
}

#[test]
fn the_move_plots_header_states_the_planned_profile_the_console_prints() {
    // Issue 29 item 3: with a compensation, the set acceleration fed to the model holds the
    // correction's second difference; the header's peaks came from those samples (8.475 m/s²,
    // jerk ≈ 7936 m/s³). They must be the planned move's: what the console prints, and the
    // requested jerk.
    let (s, _, table) = identified();
    let (csv, svg) = (s.s("head.csv"), s.s("head.svg"));
    let r = z_move_run(&csv, "0,0,0", &["--compensation", table, "--plot", &svg]);
    assert!(r.ok, "{}", r.stderr);
    let console = r
        .stderr
        .lines()
        .find(|l| l.contains("peak set acceleration"))
        .unwrap_or_else(|| panic!("no move line in {}", r.stderr));
    // "move z: 20.000 mm, peak velocity 0.2924 m/s, peak set acceleration 8.550 m/s², 0.1368 s"
    let c = numbers(console.split("move z:").nth(1).unwrap());
    let (v, a) = (c[1], c[2]);
    // Independent: the paper's 20 mm at 250 m/s³ never reaches 10 m/s², a = (D·j²/2)^(1/3).
    assert!(
        (a - (0.02f64 * 250.0 * 250.0 / 2.0).cbrt()).abs() < 5e-4,
        "{console}"
    );
    let text = std::fs::read_to_string(&svg).unwrap();
    let header = text
        .split('>')
        .find(|t| t.contains("peak set velocity"))
        .unwrap_or_else(|| panic!("no header line in {svg}"));
    let h = numbers(header.split('<').next().unwrap());
    // distance, velocity, feed, acceleration, jerk
    assert_eq!(h.len(), 5, "{header}");
    assert!(
        !header.contains('≈'),
        "planned values, not estimates: {header}"
    );
    assert!((h[0] - 20.0).abs() < 1e-9, "{header}");
    assert!((h[1] - v).abs() < 1e-4, "velocity {header} vs {console}");
    assert!(
        (h[2] - v * 60_000.0).abs() < 6.0,
        "feed {header} vs {console}"
    );
    assert!(
        (h[3] - a).abs() < 1e-3,
        "acceleration {header} vs {console}"
    );
    assert_eq!(h[4], 250.0, "{header}");
    // The set acceleration drawn is the nominal one: the CSV's column (nominal too) never
    // exceeds the planned peak, the sampled values without spikes.
    let cols = columns(&csv);
    let peak = cols["z_acc_set_m_s2"]
        .iter()
        .fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(peak <= a + 1e-3 && peak > a - 0.3, "CSV peak {peak} vs {a}");
}

/// EXJ, EYJ, EZJ of the model from circles at the reference position (the mean of the two
/// planes that accelerate J, ccw, 2 mm, 5 m/s²): independent of any move.
fn circle_eij(j: Axis) -> BTreeMap<Eij, f64> {
    let (_, machine, _) = identified();
    let m = Machine::from_file(Path::new(machine)).unwrap();
    let planes: Vec<Plane> = Plane::ALL
        .into_iter()
        .filter(|p| {
            let (a, b) = p.axes();
            a == j || b == j
        })
        .collect();
    let tests: Vec<CircleTest> = planes
        .iter()
        .map(|&p| CircleTest::new(p, Direction::Ccw, 2.0, 5.0))
        .collect();
    let sims = simulated_eij(&[m], &tests, &SimSettings::default())
        .unwrap()
        .remove(0);
    Axis::ALL
        .into_iter()
        .map(|i| {
            let e = Eij::new(i, j);
            (e, 0.5 * (sims[0][&e] + sims[1][&e]))
        })
        .collect()
}

/// `eij evaluate-move FILE --axis z [--nominal] --json`, the EIJ by name.
fn move_eij(path: &str, nominal: bool) -> (BTreeMap<String, f64>, serde_json::Value) {
    let mut args = vec!["evaluate-move", path, "--axis", "z", "--json"];
    if nominal {
        args.push("--nominal");
    }
    let r = run(&args);
    assert!(r.ok, "{}", r.stderr);
    let v: serde_json::Value = serde_json::from_str(&r.stdout).unwrap();
    let eij = v["eij_um_s2_per_m"]
        .as_object()
        .unwrap()
        .iter()
        .map(|(k, x)| (k.clone(), x.as_f64().unwrap()))
        .collect();
    (eij, v)
}

#[test]
fn the_move_prints_the_tcps_path_deviation_with_and_without_the_table() {
    // Issue 29 item 2: eij itself shows what the compensation reduces, the TCP's deviation
    // from the nominal path. Independent truths: without the table the deviation is the
    // model's EIJ (from circles) × the planned peak acceleration (a = (D·j²/2)^(1/3), the jerk
    // limit keeps the move below 10 m/s²), to the few per cent by which move and circle EIJ
    // differ; the printed numbers are max |ext − set| of the written series; the compensated
    // run's is the smaller by the factor printed.
    let (s, _, table) = identified();
    let (plain, comp, svg) = (s.s("dev-plain.csv"), s.s("dev-comp.csv"), s.s("dev.svg"));
    let p = z_move_run(&plain, "0,0,0", &[]);
    let c = z_move_run(&comp, "0,0,0", &["--compensation", table, "--plot", &svg]);
    assert!(p.ok && c.ok, "{}{}", p.stderr, c.stderr);
    let (p_cols, c_cols) = (columns(&plain), columns(&comp));
    let line = |r: &common::Run| -> String {
        r.stderr
            .lines()
            .find(|l| l.contains("TCP deviation from the nominal path"))
            .unwrap_or_else(|| panic!("no deviation line in {}", r.stderr))
            .to_string()
    };
    let (pl, cl) = (line(&p), line(&c));
    let a_peak = (0.02f64 * 250.0 * 250.0 / 2.0).cbrt();
    let circles = circle_eij(Axis::Z);
    for axis in [Axis::X, Axis::Y] {
        let name = axis.name();
        let (w, m) = (worst_um(&p_cols, name), worst_um(&c_cols, name));
        let hand = circles[&Eij::new(axis, Axis::Z)].abs() * a_peak;
        assert!(
            ((w - hand) / hand).abs() < 0.05,
            "{name}: peak |TCP − set| {w:.3} µm, |E{}Z|·a = {hand:.3} µm",
            axis.letter()
        );
        assert!(m * 10.0 < w, "{name}: {w} → {m}");
        // The console says the same, plain and compensated.
        let part = |l: &str| -> Vec<f64> {
            let at = l
                .find(&format!(" {name} "))
                .unwrap_or_else(|| panic!("{l}"));
            numbers(&l[at + 2..]).into_iter().take(3).collect()
        };
        let (pn, cn) = (part(&pl), part(&cl));
        assert!((pn[0] - w).abs() < 6e-4, "{pl}: {w}");
        assert!(
            (cn[0] - w).abs() < 6e-4 && (cn[1] - m).abs() < 6e-4,
            "{cl}: {w} → {m}"
        );
        assert_eq!(cn[2], (w / m).round(), "{cl}");
    }
    let text = std::fs::read_to_string(&svg).unwrap();
    for needle in [
        "without compensation (TCP − nominal path)",
        "with compensation (TCP − nominal path)",
    ] {
        assert!(text.contains(needle), "{svg} lacks '{needle}'");
    }
}

#[test]
fn evaluate_move_nominal_measures_what_the_compensation_leaves() {
    // Issue 29 item 2: `--nominal` fits external − nominal path. By superposition the
    // compensated move's TCP deviates from the nominal path by (E − k)·a: its EIJ against the
    // nominal path are the plain move's EIJ minus the table's k at the move (hand computation
    // from the table file: offset + slope · s_K at the middle of the travel), up to the servo
    // lag on the correction. Without a compensation, nominal and internal reference differ
    // only by the other axes' servo lag: the same EIJ.
    let (s, machine, table) = identified();
    let (plain, comp) = (s.s("nom-plain.csv"), s.s("nom-comp.csv"));
    z_move(&plain, "0,0,0", &[]);
    z_move(&comp, "0,0,0", &["--compensation", table]);
    let (e_int, v_int) = move_eij(&plain, false);
    let (e_nom, v_nom) = move_eij(&plain, true);
    let (e_comp, _) = move_eij(&comp, true);
    assert_eq!(v_int["deviation"], "external − internal");
    assert_eq!(v_nom["deviation"], "external − nominal path");
    let m = Machine::from_file(Path::new(machine)).unwrap();
    let t = CompensationTable::read(Path::new(table), &m).unwrap();
    for i in [Axis::X, Axis::Y] {
        let e = Eij::new(i, Axis::Z);
        let name = e.name();
        assert!(
            (e_nom[&name] - e_int[&name]).abs() < 0.01 * e_int[&name].abs(),
            "{name}: nominal {} vs internal {}",
            e_nom[&name],
            e_int[&name]
        );
        let k = t.get(e).unwrap().at([0.0, 0.0, 10.0]);
        let hand = e_int[&name] - k;
        // Up to the servo lag on the correction: a few per cent of E (the compensated peak
        // deviation is 1–4 % of the uncompensated one).
        assert!(
            (e_comp[&name] - hand).abs() < 0.03 * e_int[&name].abs(),
            "{name}: compensated move {:.4} against the nominal path, E − k = {:.4} − {k:.4} = {hand:.4}",
            e_comp[&name],
            e_int[&name]
        );
        // What is left is a small part of what there was.
        assert!(e_comp[&name].abs() * 10.0 < e_int[&name].abs(), "{name}");
    }
    // Without the nominal path's columns `--nominal` is refused in one line.
    let p = s.s("noset-nominal.csv");
    std::fs::write(
        &p,
        format!("{},z_acc_set_m_s2\n0,0,0,0,0,0,0,0\n", common::HEADER),
    )
    .unwrap();
    one_line_error(
        &common::eij(&["evaluate-move", &p, "--axis", "z", "--nominal"]),
        &["noset-nominal.csv", "header", "x_set_mm", "nominal path"],
    );
}

/// The stroke widths of the move figure's data traces (polylines of 50 points or more: the
/// legend's and the grid's lines have two), in drawing order.
fn trace_widths(svg: &str) -> Vec<String> {
    let doc = roxmltree::Document::parse(svg).unwrap();
    doc.descendants()
        .filter(|n| n.has_tag_name("polyline"))
        .filter(|n| {
            n.attribute("points")
                .unwrap_or("")
                .split_whitespace()
                .count()
                >= 50
        })
        .map(|n| n.attribute("stroke-width").unwrap_or("").to_string())
        .collect()
}

#[test]
fn where_the_move_plots_traces_coincide_the_top_one_is_drawn_thin_over_the_others() {
    // Issue 29 item 3: after the move the set point, the scale reading and the deviations lie
    // on one another; drawn alike (all 2 px, in order) they showed as alternating dashes of
    // both colours. Each panel now draws its first curve (the set point, or the main trace)
    // last and 1 px wide over the others at 3 px: per panel some 3s, then one 1.
    let (s, _, table) = identified();
    for (extra, panels) in [
        (vec![], vec![2, 2, 2]),
        (vec!["--compensation", table.as_str()], vec![2, 2, 4]),
    ] {
        let (csv, svg) = (s.s("thin.csv"), s.s("thin.svg"));
        let mut args = extra.clone();
        args.extend(["--plot", svg.as_str()]);
        let r = z_move_run(&csv, "0,0,0", &args);
        assert!(r.ok, "{}", r.stderr);
        let widths = trace_widths(&std::fs::read_to_string(&svg).unwrap());
        let expected: Vec<String> = panels
            .iter()
            .flat_map(|&n| {
                std::iter::repeat_n("3", n - 1)
                    .chain(["1"])
                    .map(String::from)
            })
            .collect();
        assert_eq!(widths, expected, "{extra:?}");
    }
}
