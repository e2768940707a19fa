//! The SVG figures: parsed as XML, series found by their colours, titles and axis labels
//! checked, and the magnified path checked numerically against the magnification.

mod common;

use common::synth::Synth;
use common::Scratch;
use eij::axes::{Axis, Plane};
use eij::control::ClosedLoop;
use eij::ident::report::IdentReport;
use eij::report::svg::{self, svg_color};
use eij::report::{identification_svg, move_svg, CircleView, Conditions, MoveData};
use eij::rtest::EvalOptions;
use eij::sim::output::{to_csv, CsvOptions};
use eij::sim::setpoint::JerkLimitedMove;
use eij::sim::simulate;
use serde_json::json;

/// A polyline: its stroke colour and points (pixels).
struct Polyline {
    stroke: String,
    points: Vec<(f64, f64)>,
}

struct Svg {
    polylines: Vec<Polyline>,
    texts: Vec<String>,
    /// Fill colours of the `<circle>` elements.
    circles: Vec<String>,
}

fn parse(svg: &str) -> Svg {
    let doc = roxmltree::Document::parse(svg).expect("the SVG parses as XML");
    assert_eq!(doc.root_element().tag_name().name(), "svg");
    let mut out = Svg {
        polylines: Vec::new(),
        texts: Vec::new(),
        circles: Vec::new(),
    };
    for n in doc.descendants().filter(|n| n.is_element()) {
        match n.tag_name().name() {
            "polyline" => {
                let nums: Vec<f64> = n
                    .attribute("points")
                    .unwrap()
                    .split(|c: char| c == ',' || c.is_whitespace())
                    .filter(|s| !s.is_empty())
                    .map(|s| s.parse().unwrap())
                    .collect();
                out.polylines.push(Polyline {
                    stroke: n.attribute("stroke").unwrap_or("").to_string(),
                    points: nums.chunks(2).map(|p| (p[0], p[1])).collect(),
                });
            }
            "text" => out.texts.push(n.text().unwrap_or("").trim().to_string()),
            "circle" => out
                .circles
                .push(n.attribute("fill").unwrap_or("").to_string()),
            _ => {}
        }
    }
    out
}

impl Svg {
    /// Polylines of a colour with more than `min_points` points (legend swatches have two).
    fn series(&self, color: plotters::style::RGBColor, min_points: usize) -> Vec<&Polyline> {
        let c = svg_color(color);
        self.polylines
            .iter()
            .filter(|p| p.stroke == c && p.points.len() > min_points)
            .collect()
    }

    fn has_text(&self, needle: &str) -> bool {
        self.texts.iter().any(|t| t.contains(needle))
    }

    fn assert_texts(&self, needles: &[&str]) {
        for n in needles {
            assert!(self.has_text(n), "no text with '{n}' in {:?}", self.texts);
        }
    }
}

fn extremes(p: &Polyline) -> (f64, f64, f64, f64) {
    p.points.iter().fold(
        (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ),
        |(x0, x1, y0, y1), (x, y)| (x0.min(*x), x1.max(*x), y0.min(*y), y1.max(*y)),
    )
}

/// Pure in-talk EZZ = −2.5 µm·s²/m at 5 m/s² in plane zx: the external path reaches
/// r + 12.5 µm along z and r along x; M = 20 (1-2-5 floor of 0.3·r / 12.5 µm = 48) draws it
/// at 2.25 mm along z, 2.0 mm along x.
#[test]
fn magnified_external_path_lands_where_the_magnification_predicts() {
    let mut s = Synth::new(Plane::Zx, true, 5.0).exact();
    s.e = [[-2.5, 0.0], [0.0, 0.0], [0.0, 0.0]];
    s.ext_offset_um = [0.0; 3];
    let opts = EvalOptions {
        plane: None,
        radius_mm: Some(2.0),
    };
    let view = CircleView::new(&s.series(), &opts).unwrap();
    assert_eq!(view.magnification, 20.0);
    let cond = Conditions {
        source: "synthetic.csv".into(),
        machine: Some("test machine".into()),
        position_mm: Some(vec![150.0, -100.0, 0.0]),
    };
    let doc = parse(&view.magnified_svg(&cond).unwrap());
    doc.assert_texts(&[
        "magnified ×20",
        "plane zx",
        "ccw",
        "radius r = 2 mm",
        "set acceleration 5 m/s²",
        "7.958 Hz",
        "source: synthetic.csv",
        "machine: test machine",
        "circle centre at axis positions [150.0, -100.0, 0.0] mm",
        "z − zc / mm (deviation ×20)",
        "x − xc / mm (deviation ×20)",
        "EZZ = -2.5000",
    ]);
    // Set circle, internal, external, two ellipses: one long polyline each.
    for c in [
        svg::SET,
        svg::INTERNAL,
        svg::EXTERNAL,
        svg::ELLIPSE_INT,
        svg::ELLIPSE_EXT,
    ] {
        assert_eq!(doc.series(c, 100).len(), 1, "series {}", svg_color(c));
    }
    let (sx0, sx1, sy0, sy1) = extremes(doc.series(svg::SET, 100)[0]);
    let (cx, cy) = ((sx0 + sx1) / 2.0, (sy0 + sy1) / 2.0);
    let px_per_mm = (sx1 - sx0) / 4.0;
    assert!(((sy1 - sy0) / 4.0 - px_per_mm).abs() < 1.5, "square plot");
    for (color, tol) in [(svg::EXTERNAL, 2.0), (svg::ELLIPSE_EXT, 2.0)] {
        let (x0, x1, y0, y1) = extremes(doc.series(color, 100)[0]);
        let mm = |px: f64| px / px_per_mm;
        for (got, want) in [
            (mm(x1 - cx), 2.25),
            (mm(cx - x0), 2.25),
            (mm(y1 - cy), 2.0),
            (mm(cy - y0), 2.0),
        ] {
            assert!(
                (got - want).abs() * px_per_mm < tol,
                "{}: {got} mm, expected {want} mm",
                svg_color(color)
            );
        }
    }
    // The internal path is the set circle: drawn on it.
    let (ix0, ix1, _, _) = extremes(doc.series(svg::INTERNAL, 100)[0]);
    assert!((ix1 - sx1).abs() < 1.5 && (ix0 - sx0).abs() < 1.5);
}

#[test]
fn out_of_plane_view_holds_the_deviation_and_the_fitted_plane() {
    let s = Synth::new(Plane::Xy, false, 4.0).exact();
    let view = CircleView::new(&s.series(), &EvalOptions::default()).unwrap();
    let doc = parse(&view.out_of_plane_svg(&Conditions::default()).unwrap());
    doc.assert_texts(&[
        "out-of-plane deviation dz",
        "plane xy",
        "cw",
        "set acceleration 4 m/s²",
        "phase φ / °",
        "dz / µm",
        "EZX = -1.5500",
        "EZY = 0.9000",
    ]);
    let plane = doc.series(svg::FIT, 100);
    assert_eq!(plane.len(), 1);
    assert_eq!(plane[0].points.len(), 361);
    let dots = doc
        .circles
        .iter()
        .filter(|f| **f == svg_color(svg::EXTERNAL))
        .count();
    assert!((200..=1502).contains(&dots), "{dots} measured points");
}

fn demo_move() -> (ClosedLoop, eij::sim::Run) {
    let machine = common::demo();
    let pose = machine.reference_pose();
    let cl = ClosedLoop::new(&machine, &pose).unwrap();
    let mv = JerkLimitedMove::new(Axis::Z, 0.01, 0.3, 8.0, 250.0);
    let run = simulate(&cl, &mv, 5000.0).unwrap();
    (cl, run)
}

#[test]
fn move_plot_from_csv_and_from_run_agree_and_show_three_panels() {
    let (cl, run) = demo_move();
    let scratch = Scratch::new("report-move");
    let dir = scratch.0.clone();
    let csv = dir.join("move.csv");
    std::fs::write(&csv, to_csv(&cl, &run, &CsvOptions::default())).unwrap();
    let from_csv = MoveData::read_csv(&csv).unwrap();
    let from_run = MoveData::from_run(&cl, &run, Axis::Z, "run".into()).unwrap();
    assert_eq!(from_csv.axis, Axis::Z);
    assert!((from_csv.distance_mm() - 10.0).abs() < 1e-6);
    assert!((from_csv.peak_accel_m_s2() - from_run.peak_accel_m_s2()).abs() < 1e-6);
    assert!(from_csv.peak_accel_m_s2() <= 8.0 + 1e-9 && from_csv.peak_accel_m_s2() > 4.0);
    assert_eq!(from_csv.cross_talk_um.len(), 2);
    for ((a, u), (b, v)) in from_csv.cross_talk_um.iter().zip(&from_run.cross_talk_um) {
        assert_eq!(a, b);
        let worst = u
            .iter()
            .zip(v)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max);
        assert!(
            worst < 1e-3,
            "cross-talk {a}: CSV and run differ by {worst} µm"
        );
    }
    let cond = Conditions {
        source: csv.display().to_string(),
        ..Default::default()
    };
    let doc = parse(&move_svg(&from_csv, &cond).unwrap());
    doc.assert_texts(&[
        "Positioning move of axis Z",
        "distance 10 mm",
        "peak set acceleration",
        "m/s²",
        "time t / s",
        "z / mm",
        "äz / (m/s²)",
        "deviation / µm",
        "dx = x_ext − x_int",
        "dy = y_ext − y_int",
    ]);
    // Panel 1: set + internal; panel 2: set + actual acceleration (black and blue twice);
    // panel 3: two cross-talk series.
    assert_eq!(doc.series(svg::SET, 100).len(), 2);
    assert_eq!(doc.series(svg::INTERNAL, 100).len(), 2);
    assert_eq!(doc.series(svg::EXTERNAL, 100).len(), 1);
    assert_eq!(doc.series(svg::SECOND, 100).len(), 1);
    let _ = std::fs::remove_dir_all(&dir);
}

fn ident_report() -> serde_json::Value {
    json!({
        "machine": "machines/demo-vmc.toml",
        "parameters": [
            {"name": "z.guideway_normal", "initial": 1.0, "identified": 0.4, "std_err": 0.02, "identifiable": true},
            {"name": "x.screw", "initial": 1.0, "identified": 0.8, "std_err": null, "identifiable": false}
        ],
        "correlation": [[1.0, -0.3], [-0.3, 1.0]],
        "cost_initial": 400.0,
        "cost_final": 2.5,
        "cost_history": [400.0, 30.0, 2.6, 2.5],
        "tests": [
            {"plane": "zx", "direction": "ccw", "accel_m_s2": 2.0,
             "measured": {"EZZ": -1.2, "EXX": -2.7},
             "measured_std_err": {"EZZ": 0.05, "EXX": 0.04},
             "simulated_initial": {"EZZ": -0.5, "EXX": -1.1},
             "simulated_final": {"EZZ": -1.19, "EXX": -2.72}},
            {"plane": "zx", "direction": "cw", "accel_m_s2": 4.0,
             "measured": {"EZZ": -1.25, "EXX": -2.65},
             "measured_std_err": {"EZZ": 0.05, "EXX": 0.04},
             "simulated_initial": {"EZZ": -0.5, "EXX": -1.1},
             "simulated_final": {"EZZ": -1.21, "EXX": -2.69}},
            {"plane": "xy", "direction": "ccw", "accel_m_s2": 6.0,
             "measured": {"EXX": -2.6},
             "measured_std_err": {"EXX": 0.03},
             "simulated_initial": {"EXX": -1.0},
             "simulated_final": {"EXX": -2.62}}
        ]
    })
}

#[test]
fn identification_figure_has_a_panel_per_parameter_and_the_cost() {
    let report = IdentReport::from_value(&ident_report()).unwrap();
    let doc = parse(&identification_svg(&report).unwrap());
    doc.assert_texts(&[
        "Identification",
        "3 tests",
        "cost 400 → 2.5 in 3 iterations",
        "machine: machines/demo-vmc.toml",
        "EXX / (µm·s²/m)",
        "EZZ / (µm·s²/m)",
        "cost over iterations (log scale)",
        "iteration",
        "zx ccw 2",
        "xy ccw 6",
        "measured ± 2 std err",
    ]);
    // Cost: one polyline through the four iterations.
    let cost: Vec<_> = doc
        .series(svg::INTERNAL, 1)
        .into_iter()
        .filter(|p| p.points.len() == 4)
        .collect();
    assert_eq!(cost.len(), 1);
    // Log scale: equal ratios give equal steps; 400 → 30 is further down than 30 → 2.6.
    let y: Vec<f64> = cost[0].points.iter().map(|p| p.1).collect();
    let ratio = ((y[1] - y[0]) / (y[2] - y[1]) - (400f64 / 30.0).ln() / (30f64 / 2.6).ln()).abs();
    assert!(ratio < 0.05, "log scale: steps {y:?}");
    // Error bars: one horizontal two-point polyline per measured value (5, one row per test),
    // and the legend's vertical one.
    let bars = |horizontal: bool| {
        doc.polylines
            .iter()
            .filter(|p| p.stroke == svg_color(svg::ERROR_BAR) && p.points.len() == 2)
            .filter(|p| {
                let (dx, dy) = (p.points[0].0 - p.points[1].0, p.points[0].1 - p.points[1].1);
                if horizontal {
                    dy.abs() < 0.5 && dx.abs() > 0.5
                } else {
                    dx.abs() < 0.5
                }
            })
            .count()
    };
    assert_eq!((bars(true), bars(false)), (5, 1));
    // Measured (black), initial (grey rings, no fill), final (green) markers.
    let fills = |c| doc.circles.iter().filter(|f| **f == svg_color(c)).count();
    assert_eq!(fills(svg::SET), 5 + 1);
    assert_eq!(fills(svg::FIT), 5 + 1);
}

#[test]
fn identification_figure_names_a_missing_key() {
    let mut r = ident_report();
    r["tests"][1]
        .as_object_mut()
        .unwrap()
        .remove("simulated_final");
    let msg = IdentReport::from_value(&r).unwrap_err().to_string();
    assert!(
        msg.contains("key `tests[1].simulated_final`: missing"),
        "{msg}"
    );

    let mut r = ident_report();
    r.as_object_mut().unwrap().remove("cost_final");
    let msg = IdentReport::from_value(&r).unwrap_err().to_string();
    assert!(msg.contains("key `cost_final`: missing"), "{msg}");

    let mut r = ident_report();
    r["tests"][0]["measured"]["EQQ"] = json!(1.0);
    let msg = IdentReport::from_value(&r).unwrap_err().to_string();
    assert!(msg.contains("tests[0].measured"), "{msg}");
    assert!(msg.contains("unknown parameter 'EQQ'"), "{msg}");
}
