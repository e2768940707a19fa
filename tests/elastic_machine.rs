//! A machine with an elastic body from `[body.beam]` (`machines/reference/column-mill-beam.toml`:
//! the moving-column mill with its column a Timoshenko beam), against calculations written
//! here: the beam's mass properties, the rigid limit, a rigid motion of the whole machine, EIJ
//! continuous as the Z carriages travel over the column's nodes, and the column's stiffness
//! identified from EIJ it produced.

use eij::axes::{Axis, Direction, Eij, EijEstimates, Plane};
use eij::ident::{identify, Parameter, Problem, Settings, TestCase};
use eij::machine::catalogue::Catalogue;
use eij::machine::elastic::FeBody;
use eij::machine::{Machine, Pose};
use eij::mbs::Model;
use eij::predict::{simulated_eij, CircleTest, EijMap};
use nalgebra::Vector3;

mod common;

use common::{assert_motion_free, machine as load, one_eij, whole_machine_motion};

const BEAM: &str = "reference/column-mill-beam.toml";

fn column(machine: &Machine) -> usize {
    machine
        .bodies()
        .iter()
        .position(|b| b.name == "column")
        .unwrap()
}

fn eij_at(machine: &Machine, plane: Plane, pose: [f64; 3]) -> EijMap {
    one_eij(
        machine,
        CircleTest::new(plane, Direction::Ccw, 2.0, 5.0).at(pose.to_vec()),
    )
}

#[test]
fn the_column_has_the_mass_properties_of_a_uniform_beam() {
    // ρ = 7200 kg/m³, A = 0.08 m², I_y = I_z = 2.167e-3 m⁴, L = 1.55 m along z at x = 0,
    // y = 0.55 m: m = ρAL, COG at mid-length, J_xx = J_yy = m L²/12 + ρ I L (the sections'
    // rotary inertia), J_zz = ρ (I_y + I_z) L.
    let machine = load(BEAM);
    let c = &machine.bodies()[column(&machine)];
    let (rho, a, i, l) = (7200.0, 0.08, 2.167e-3, 1.55);
    let m = rho * a * l;
    assert!((c.mass_kg - m).abs() < 1e-9 * m, "{} kg", c.mass_kg);
    let cog = Vector3::new(0.0, 0.55, -0.45 + l / 2.0);
    assert!((c.cog_m - cog).norm() < 1e-9, "{}", c.cog_m);
    let bending = m * l * l / 12.0 + rho * i * l;
    let torsion = rho * 2.0 * i * l;
    let want = nalgebra::Matrix3::from_diagonal(&Vector3::new(bending, bending, torsion));
    assert!(
        (c.inertia_kg_m2 - want).abs().max() < 1e-9 * bending,
        "{}",
        c.inertia_kg_m2
    );
    assert!(c.elastic().is_some_and(|e| e.modes() > 6));
}

#[test]
fn the_column_is_reduced_once_per_run() {
    // Reading the machine again (and a parameter set with another stiffness factor) reuses the
    // reduction: the factor scales the reduced stiffness without a new reduction.
    let reduction = |m: &Machine| {
        m.bodies()[column(m)]
            .elastic()
            .and_then(|e| e.model().as_any().downcast_ref::<FeBody>())
            .map(|f| f.reduction().clone())
            .unwrap()
    };
    let (a, b) = (load(BEAM), load(BEAM));
    assert!(std::sync::Arc::ptr_eq(&reduction(&a), &reduction(&b)));
    let mut c = a.clone();
    Parameter::parse("column.stiffness", &c)
        .unwrap()
        .set(&mut c, 0.5)
        .unwrap();
    assert!(std::sync::Arc::ptr_eq(&reduction(&a), &reduction(&c)));
    let k = |m: &Machine| {
        Model::assemble(m, &Pose::new(m, &[0.0; 3]).unwrap())
            .unwrap()
            .stiffness
    };
    assert!((k(&a) - k(&c)).abs().max() > 0.0);
}

/// The same machine with the column rigid, with the mass properties its beam has.
fn rigid_column(elastic: &Machine) -> Machine {
    let c = &elastic.bodies()[column(elastic)];
    let mut raw = elastic.to_raw();
    let rb = raw.bodies.iter_mut().find(|b| b.name == "column").unwrap();
    rb.beam = None;
    rb.mass_kg = Some(c.mass_kg);
    rb.cog_m = Some(c.cog_m.into());
    rb.inertia_kg_m2 = Some(std::array::from_fn(|r| {
        std::array::from_fn(|k| c.inertia_kg_m2[(r, k)])
    }));
    Machine::from_raw(raw, &Catalogue::bundled().unwrap(), "rigid column").unwrap()
}

#[test]
fn a_column_ten_thousand_times_stiffer_gives_the_rigid_column_eij() {
    let elastic = load(BEAM);
    let rigid = rigid_column(&elastic);
    let mut stiff = elastic.clone();
    Parameter::parse("column.stiffness", &stiff)
        .unwrap()
        .set(&mut stiff, 1e4)
        .unwrap();
    for plane in Plane::ALL {
        let pose = [0.1, -0.1, 0.2];
        let (r, s, e) = (
            eij_at(&rigid, plane, pose),
            eij_at(&stiff, plane, pose),
            eij_at(&elastic, plane, pose),
        );
        let scale = r.values().fold(0.0f64, |m, v| m.max(v.abs()));
        let mut softened = 0.0f64;
        for (k, v) in &r {
            assert!(
                (s[k] - v).abs() < 1e-3 * scale,
                "{plane} {k}: {} with the stiff column, {v} with the rigid one",
                s[k]
            );
            softened = softened.max((e[k] - v).abs());
        }
        // The column as built does bend: its EIJ differ from the rigid column's.
        assert!(softened > 1e-2 * scale, "{plane}: {softened} of {scale}");
    }
}

#[test]
fn a_rigid_motion_of_the_whole_floating_machine_is_no_deviation() {
    let mut raw = load(BEAM).to_raw();
    raw.joints.clear();
    let floating = Machine::from_raw(raw, &Catalogue::bundled().unwrap(), "no feet").unwrap();
    for pose in [[0.0, 0.0, 0.0], [0.25, -0.15, 0.27]] {
        let model = Model::assemble(&floating, &Pose::new(&floating, &pose).unwrap()).unwrap();
        let v = whole_machine_motion(
            &floating,
            &model,
            &pose,
            Vector3::new(2e-6, -1e-6, 3e-6),
            Vector3::new(1e-6, 2e-6, -1.5e-6),
            Vector3::new(0.3, 0.2, -0.4),
        );
        assert_motion_free(&model, &v, 1e-17);
    }
}

#[test]
fn eij_stay_continuous_as_the_carriages_pass_the_column_nodes() {
    // Nodes every 1.55/8 m from z = −0.45 m; the lower Z carriages (z = 0.25 m + Z) pass the
    // node at z = 0.325 m at Z = 75 mm, the scale's read position (0.45 m + Z) the node at
    // 0.51875 m at Z = 68.75 mm. A jump would stay as the step shrinks; continuity makes the
    // difference shrink with it.
    let machine = load(BEAM);
    for z_cross in [0.075, 0.06875] {
        let span = |eps: f64| {
            let lo = eij_at(&machine, Plane::Yz, [0.0, 0.0, z_cross - eps]);
            let hi = eij_at(&machine, Plane::Yz, [0.0, 0.0, z_cross + eps]);
            lo.keys()
                .map(|k| (hi[k] - lo[k]).abs())
                .fold(0.0f64, f64::max)
        };
        let (wide, narrow) = (span(1e-3), span(1e-6));
        assert!(wide > 0.0, "EIJ do not depend on Z at all");
        assert!(
            narrow < 1e-2 * wide + 1e-9,
            "Z = {z_cross} m: {narrow} over ±1 µm against {wide} over ±1 mm"
        );
    }
    // And between nodes they follow the axis position smoothly over the whole stroke: no step
    // larger than a few times the typical one.
    let ezz: Vec<f64> = (0..20)
        .map(|i| eij_at(&machine, Plane::Yz, [0.0, 0.0, -0.09 + 0.019 * i as f64]))
        .map(|e| e[&Eij::new(Axis::Z, Axis::Z)])
        .collect();
    let steps: Vec<f64> = ezz.windows(2).map(|w| (w[1] - w[0]).abs()).collect();
    let mut sorted = steps.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2];
    assert!(steps.iter().all(|s| *s <= 5.0 * median + 1e-9), "{steps:?}");
}

#[test]
fn the_column_stiffness_is_identified_from_the_eij_it_produced() {
    let machine = load(BEAM);
    let names = ["column.stiffness", "z.guideway_normal"];
    let params: Vec<Parameter> = names
        .iter()
        .map(|n| Parameter::parse(n, &machine).unwrap())
        .collect();
    let truth_values = [0.6, 0.8];
    let mut truth = machine.clone();
    for (p, v) in params.iter().zip(truth_values) {
        p.set(&mut truth, v).unwrap();
    }
    let settings = Settings::default();
    let mut tests: Vec<TestCase> = [Plane::Yz, Plane::Zx]
        .into_iter()
        .flat_map(|plane| {
            [[0.0, -0.15, 0.25], [0.0, 0.15, -0.05]].map(|pose| TestCase {
                source: format!("synthetic {plane}"),
                circle: CircleTest::new(plane, Direction::Ccw, 2.0, 5.0).at(pose.to_vec()),
                measured: Default::default(),
                clock: None,
            })
        })
        .collect();
    let circles: Vec<CircleTest> = tests.iter().map(|t| t.circle.clone()).collect();
    let sims = simulated_eij(std::slice::from_ref(&truth), &circles, &settings.simulation)
        .unwrap()
        .remove(0);
    for (t, sim) in tests.iter_mut().zip(sims) {
        t.measured = EijEstimates::with_std_err(sim, 0.02);
    }
    let problem = Problem::new(machine, params, tests, settings).unwrap();
    let result = identify(&problem, None).unwrap();
    for (q, want) in result.parameters.iter().zip(truth_values) {
        assert!(
            ((q.value - want) / want).abs() < 1e-3,
            "{} = {} (truth {want})",
            q.name,
            q.value
        );
    }
    // The identified machine keeps its beam, with the identified factor written back.
    let raw = result.machine.to_raw();
    let beam = raw.bodies.iter().find_map(|b| b.beam.as_ref()).unwrap();
    assert!((beam.stiffness_factor - 0.6).abs() < 1e-3 * 0.6);
}

#[test]
fn an_elastic_body_the_file_gets_wrong_is_one_error_naming_the_key() {
    let text = std::fs::read_to_string(common::root().join("machines").join(BEAM)).unwrap();
    let with = |from: &str, to: &str| {
        assert!(text.contains(from), "{from}");
        let file = common::root().join("machines/reference/variant.toml");
        Machine::from_toml_str(&text.replacen(from, to, 1), &file.display().to_string())
            .unwrap_err()
            .to_string()
    };
    let beam = "\n[body.beam]\n";
    for (from, to, needles) in [
        (
            beam,
            "\nmass_kg = 700.0\n[body.beam]\n",
            &["body[column].mass_kg", "1 %"][..],
        ),
        (
            beam,
            "\ncog_m = [0.0, 0.55, 0.6]\n[body.beam]\n",
            &["body[column].cog_m", "extent"][..],
        ),
        (beam, "\nfixed = true\n[body.beam]\n", &["body[column].beam", "fixed"][..]),
        (
            "modes = 12",
            "modes = 12\ncutoff_hz = 500.0",
            &["body[column].beam.modes", "not both"][..],
        ),
        (
            "damping_ratio = 0.02",
            "damping_ratio = 1.5",
            &["body[column].beam", "damping ratio"][..],
        ),
        (
            "elements = 8",
            "elements = 8\nstiffness_factor = -1.0",
            &["body[column].beam.stiffness_factor"][..],
        ),
        (
            beam,
            "\n[body.fe]\nmass_matrix = \"missing-M.mtx\"\nstiffness_matrix = \"missing-K.mtx\"\ndofs = \"d.csv\"\nnodes = \"n.csv\"\n\n[body.beam]\n",
            &["body[column]", "not both"][..],
        ),
    ] {
        let e = with(from, to);
        assert!(!e.contains('\n'), "{e}");
        for n in needles {
            assert!(e.contains(n), "{n} not in: {e}");
        }
    }
    // A [body.fe] whose files are missing names the file, relative to the machine file.
    let fe = text.replace(
        &text[text.find("\n[body.beam]").unwrap() + 1..text.find("damping_ratio = 0.02").unwrap()],
        "[body.fe]\nmass_matrix = \"fe/missing-M.mtx\"\nstiffness_matrix = \"fe/missing-K.mtx\"\ndofs = \"fe/d.csv\"\nnodes = \"fe/n.csv\"\n",
    );
    let file = common::root().join("machines/reference/variant.toml");
    let e = Machine::from_toml_str(&fe, &file.display().to_string())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("body[column].fe") && e.contains("machines/reference/fe/missing-M.mtx"),
        "{e}"
    );
}
