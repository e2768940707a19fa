//! EIJ maps over the workspace.

use eij::axes::{Axis, Direction, Eij, Plane};
use eij::map::{eij_map, read_csv, to_csv, AxisGrid, MapSpec};
use eij::predict::{simulated_eij, CircleTest, SimSettings};

mod common;

use common::demo;

fn spec() -> MapSpec {
    MapSpec {
        plane: Plane::Zx,
        direction: Direction::Ccw,
        radius_m: 0.002,
        accel_m_s2: 5.0,
    }
}

#[test]
fn a_map_point_equals_the_identification_simulation_at_that_position() {
    let m = demo();
    let grids = vec![
        AxisGrid::parse("x=-200:200:3").unwrap(),
        AxisGrid::parse("y=100:100:1").unwrap(),
    ];
    let points = eij_map(&m, &grids, &spec()).unwrap();
    assert_eq!(points.len(), 3);
    assert_eq!(points[2].position_m, vec![0.2, 0.1, 0.0]);
    let test = CircleTest::new(Plane::Zx, Direction::Ccw, 2.0, 5.0).at(vec![0.2, 0.1, 0.0]);
    let sim = simulated_eij(&[m], &[test], &SimSettings::default()).unwrap();
    for (e, v) in &sim[0][0] {
        assert!((points[2].eij[e] - v).abs() < 1e-12, "{e}");
    }
}

#[test]
fn table_pitch_cross_talk_grows_linearly_with_the_nest_offset() {
    // X moves the table (and the nest with it) over the saddle: the table's pitch under Z
    // acceleration is the same at every X, but the nest's lever arm about the pitch axis grows
    // with X, so EZX is linear in X and zero where the nest sits over the table's own centre.
    let m = demo();
    let points = eij_map(&m, &[AxisGrid::parse("x=-300:300:5").unwrap()], &spec()).unwrap();
    let ezx: Vec<f64> = points
        .iter()
        .map(|p| p.eij[&Eij::new(Axis::Z, Axis::X)])
        .collect();
    let slope = (ezx[4] - ezx[0]) / 600.0;
    assert!(slope.abs() > 1e-4, "EZX does not change with X: {ezx:?}");
    for (i, v) in ezx.iter().enumerate() {
        let linear = ezx[2] + slope * (i as f64 * 150.0 - 300.0);
        assert!(
            (v - linear).abs() < 0.02 * slope.abs() * 300.0,
            "EZX({i}) = {v}, linear {linear}"
        );
    }
    assert!(
        ezx[2].abs() < 0.01 * ezx[0].abs(),
        "EZX at X = 0: {}",
        ezx[2]
    );
}

#[test]
fn compensation_table_round_trips_and_bad_grids_are_refused() {
    let m = demo();
    let grids = vec![AxisGrid::parse("y=-250:250:3").unwrap()];
    let points = eij_map(&m, &grids, &spec()).unwrap();
    let dir = std::env::temp_dir().join(format!("eij-map-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("map.csv");
    std::fs::write(&file, to_csv(&m, &spec(), &points)).unwrap();
    let table = read_csv(&file).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(table.spec, spec());
    assert_eq!(table.machine.as_deref(), Some(m.name()));
    for (a, b) in points.iter().zip(&table.points) {
        for (e, v) in &a.eij {
            assert!((b.eij[e] - v).abs() < 1e-6);
        }
    }
    for bad in ["x=-400:0:3", "q=0:1:2", "x=1:0:3", "x=0:1", "x=0:1:0"] {
        let r = AxisGrid::parse(bad).and_then(|g| eij_map(&m, &[g], &spec()));
        assert!(r.is_err(), "{bad} accepted");
    }
    let svg = eij::report::map_svg("demo", &[Axis::X, Axis::Y, Axis::Z], &spec(), &points).unwrap();
    let doc = roxmltree::Document::parse(&svg).unwrap();
    let texts: Vec<&str> = doc.descendants().filter_map(|n| n.text()).collect();
    assert!(
        texts
            .iter()
            .any(|t| t.trim().starts_with("EIJ map of demo: zx ccw circles")),
        "{texts:?}"
    );
    assert!(texts.iter().any(|t| t.contains("EXZ / (µm·s²/m)")));
}
