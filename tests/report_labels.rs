//! Labels of the report's figures do not sit on their traces (issue 29 item 9: the polar
//! plots' ring labels were drawn on the rings at 75°, the "0" under the set circle and the
//! paths that follow it). Measured in the SVG the page holds: every text's box against every
//! drawn path and the set circle.

mod common;

use common::Scratch;

/// A text's box in SVG pixels: left, top, right, bottom, and the text.
type TextBox = (f64, f64, f64, f64, String);

/// The texts of an SVG with their boxes. plotters writes `x`, `y` (top, `dy="0.76em"`) or
/// the baseline, `font-size` and `text-anchor`; the width is estimated at 0.6 em a
/// character (sans-serif digits and letters are narrower on average).
fn texts(doc: &roxmltree::Document) -> Vec<TextBox> {
    doc.descendants()
        .filter(|n| n.has_tag_name("text"))
        .filter_map(|n| {
            let x: f64 = n.attribute("x")?.parse().ok()?;
            let y: f64 = n.attribute("y")?.parse().ok()?;
            let size: f64 = n
                .attribute("font-size")
                .and_then(|s| s.trim_end_matches("px").parse().ok())
                .unwrap_or(14.0);
            let text: String = n.children().filter_map(|c| c.text()).collect();
            let text = text.trim().to_string();
            let w = 0.6 * size * text.chars().count() as f64;
            let left = match n.attribute("text-anchor") {
                Some("middle") => x - w / 2.0,
                Some("end") => x - w,
                _ => x,
            };
            let top = if n.attribute("dy").is_some_and(|d| d.contains("0.76em")) {
                y
            } else {
                y - 0.8 * size
            };
            Some((left, top, left + w, top + size, text))
        })
        .collect()
}

/// The polylines of `stroke` colours, as point lists.
fn polylines(doc: &roxmltree::Document, strokes: &[&str]) -> Vec<Vec<(f64, f64)>> {
    doc.descendants()
        .filter(|n| n.has_tag_name("polyline"))
        .filter(|n| {
            n.attribute("stroke")
                .is_some_and(|s| strokes.iter().any(|c| s.eq_ignore_ascii_case(c)))
        })
        .map(|n| {
            n.attribute("points")
                .unwrap_or("")
                .split_whitespace()
                .filter_map(|p| {
                    let (x, y) = p.split_once(',')?;
                    Some((x.parse().ok()?, y.parse().ok()?))
                })
                .collect()
        })
        .collect()
}

/// Whether the segment a–b passes through the box (sampled every half pixel).
fn crosses(a: (f64, f64), b: (f64, f64), t: &TextBox) -> bool {
    let steps = ((b.0 - a.0).hypot(b.1 - a.1) * 2.0).ceil().max(1.0) as usize;
    (0..=steps).any(|k| {
        let s = k as f64 / steps as f64;
        let (x, y) = (a.0 + s * (b.0 - a.0), a.1 + s * (b.1 - a.1));
        x > t.0 && x < t.2 && y > t.1 && y < t.3
    })
}

#[test]
fn no_label_of_a_circle_plot_sits_on_a_path_or_the_set_circle() {
    let s = Scratch::new("report-labels");
    let out = s.s("report");
    let r = common::eij(&[
        "report",
        "--measured",
        "measurements/demo-vmc/pos-a",
        "--out",
        &out,
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let page = std::fs::read_to_string(s.path("report/report.html")).unwrap();
    let mut figures = 0;
    for (at, _) in page.match_indices("<figure") {
        let fig = &page[at..at + page[at..].find("</figure>").unwrap()];
        let tag = &fig[..fig.find('>').unwrap()];
        let Some(id) = tag.split("id=\"").nth(1).and_then(|r| r.split('"').next()) else {
            continue;
        };
        if !id.starts_with("circle-plot-") {
            continue;
        }
        let Some(start) = fig.find("<svg") else {
            continue;
        };
        let svg = &fig[start..fig.rfind("</svg>").unwrap() + "</svg>".len()];
        let doc = roxmltree::Document::parse(svg).unwrap();
        // Every text inside the figure (the circle plot's legend was cut at its right edge;
        // the boxes' 0.6 em a character is generous, 0.55 em is closer for these texts).
        let width: f64 = doc
            .root_element()
            .attribute("width")
            .unwrap()
            .parse()
            .unwrap();
        for t in texts(&doc) {
            let right = t.0 + (t.2 - t.0) * 0.55 / 0.6;
            assert!(
                right <= width,
                "{id}: '{}' ends at {right:.0} px of {width}",
                t.4
            );
        }
        if id.ends_with("-out-of-plane") {
            continue;
        }
        // cw and ccw paths, and the set circle (the bold dark ring).
        let lines = polylines(&doc, &["#0072B2", "#D55E00", "#3C3C3C"]);
        assert!(lines.len() >= 5, "paths and set circles in {id}");
        let boxes = texts(&doc);
        assert!(
            boxes.iter().any(|t| t.4.contains("µm")),
            "a scale is written"
        );
        for t in &boxes {
            for line in &lines {
                let hit = line.windows(2).any(|w| crosses(w[0], w[1], t));
                assert!(!hit, "{id}: label '{}' sits on a trace", t.4);
            }
        }
        figures += 1;
    }
    assert!(figures >= 6, "{figures} circle plots checked");
}
