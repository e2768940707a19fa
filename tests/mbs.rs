//! Multi-body assembly and modal analysis against hand calculations and physical identities.

use eij::machine::Machine;
use eij::mbs::{modal, MbsError, Model};

mod common;

use common::machine as load;

fn frequencies(machine: &Machine, pose: &[f64]) -> Vec<f64> {
    let model = Model::assemble(machine, pose).unwrap();
    modal::modes(&model)
        .unwrap()
        .iter()
        .map(|m| m.frequency_hz)
        .collect()
}

fn assert_rel(got: f64, want: f64, tol: f64) {
    assert!(
        ((got - want) / want).abs() < tol,
        "got {got}, want {want} (relative tolerance {tol})"
    );
}

/// Independent eigen-solution of the 6×6 problem (and the closed forms in the file header).
const FOUR_SUPPORTS_HZ: [f64; 6] = [
    0.450_157_958,
    227.820_440,
    318.309_886,
    389.848_574,
    427.057_823,
    555.926_761,
];

#[test]
fn single_body_on_four_supports_matches_hand_calculation() {
    let f = frequencies(&load("reference/four-joints.toml"), &[]);
    assert_eq!(f.len(), 6);
    for (got, want) in f.iter().zip(FOUR_SUPPORTS_HZ) {
        assert_rel(*got, want, 1e-6);
    }
    // Closed forms: z translation √(4k/m), x translation √(4·1e3/m).
    assert_rel(
        f[2],
        (4.0 * 5e8 / 500.0_f64).sqrt() / std::f64::consts::TAU,
        1e-9,
    );
    assert_rel(
        f[0],
        (4.0 * 1e3 / 500.0_f64).sqrt() / std::f64::consts::TAU,
        1e-6,
    );
}

#[test]
fn single_axis_slide_on_carriages_and_screw_matches_hand_calculation() {
    let machine = load("reference/single-axis.toml");
    let f = frequencies(&machine, &[0.0]);
    assert_eq!(f.len(), 7);
    assert_eq!(f[0], 0.0, "the drive's own rigid-body mode");
    // Axial mode of slide and rotor on the screw spring, by hand.
    let (e, d, l1) = (2.1e11, 0.03, 0.5);
    let k_shaft = e * std::f64::consts::PI * d * d / 4.0 / l1;
    let k_ax = 1.0 / (1.0 / k_shaft + 1.0 / 1e9 + 1.0 / 1e9);
    let m_r = 0.004 * (std::f64::consts::TAU / 0.02_f64).powi(2);
    let axial = (k_ax * (1.0 / 500.0 + 1.0 / m_r)).sqrt() / std::f64::consts::TAU;
    let mut want: Vec<f64> = FOUR_SUPPORTS_HZ[1..].to_vec();
    want.push(axial);
    want.sort_by(f64::total_cmp);
    for (got, want) in f[1..].iter().zip(&want) {
        assert_rel(*got, *want, 1e-6);
    }
}

#[test]
fn screw_stiffness_follows_the_nut_position() {
    // The axial mode frequency moves with the nut-to-bearing distance l₁ (E·A/l₁).
    let machine = load("reference/single-axis.toml");
    for s in [-0.2, 0.1, 0.2] {
        let model = Model::assemble(&machine, &[s]).unwrap();
        let axial = modal::modes(&model)
            .unwrap()
            .into_iter()
            .find(|m| m.frequency_hz > 0.0 && m.dominant_dof == "x.motor")
            .unwrap();
        let l1 = 0.5 + s; // tool side: the slide moves +s along x
        let k_shaft = 2.1e11 * std::f64::consts::PI * 0.03 * 0.03 / 4.0 / l1;
        let k_ax = 1.0 / (1.0 / k_shaft + 2.0 / 1e9);
        let m_r = 0.004 * (std::f64::consts::TAU / 0.02_f64).powi(2);
        let want = (k_ax * (1.0 / 500.0 + 1.0 / m_r)).sqrt() / std::f64::consts::TAU;
        assert_rel(axial.frequency_hz, want, 1e-6);
    }
}

#[test]
fn matrices_are_symmetric_and_stiffness_is_positive_semidefinite() {
    let machine = load("demo-vmc.toml");
    for pose in [[0.0, 0.0, 0.0], [0.3, -0.25, 0.3], [-0.3, 0.25, -0.1]] {
        let m = Model::assemble(&machine, &pose).unwrap();
        for mat in [&m.mass, &m.damping, &m.stiffness] {
            let asym = (mat - mat.transpose()).abs().max();
            assert!(asym <= 1e-12 * mat.abs().max(), "asymmetry {asym}");
        }
        let eig = m.stiffness.clone().symmetric_eigenvalues();
        let max = eig.max();
        assert!(
            eig.min() > -1e-12 * max,
            "K has a negative eigenvalue {}",
            eig.min()
        );
        // Exactly one zero-energy motion per drive: slide, everything it carries and rotor.
        for i in 0..machine.axes.len() {
            let v = m.drive_mode(&machine, i);
            let kv = &m.stiffness * &v;
            assert!(
                kv.norm() < 1e-9 * max * v.norm(),
                "drive mode {i} strains the structure"
            );
        }
        assert_eq!(
            modal::modes(&m)
                .unwrap()
                .iter()
                .filter(|m| m.frequency_hz == 0.0)
                .count(),
            3
        );
        modal::check_support(&m, &machine).unwrap();
    }
}

#[test]
fn frequencies_do_not_change_when_the_whole_machine_is_shifted() {
    let machine = load("demo-vmc.toml");
    let mut raw = machine.to_raw();
    let d = [0.7, -1.3, 2.1];
    let shift = |p: &mut [f64; 3]| (0..3).for_each(|i| p[i] += d[i]);
    shift(&mut raw.tcp.point_m);
    shift(&mut raw.workpiece.point_m);
    for b in &mut raw.bodies {
        if let Some(c) = b.cog_m.as_mut() {
            shift(c);
        }
    }
    for j in &mut raw.joints {
        shift(&mut j.point_m);
    }
    for a in &mut raw.axes {
        a.guideway
            .rails
            .iter_mut()
            .for_each(|r| r.carriages_m.iter_mut().for_each(shift));
        shift(&mut a.drive.nut_m);
        shift(&mut a.drive.bearing_m);
        shift(&mut a.drive.scale_m);
    }
    let shifted = Machine::from_raw(
        raw,
        &eij::machine::catalogue::Catalogue::bundled().unwrap(),
        "shifted",
    )
    .unwrap();
    let pose = [0.1, -0.1, 0.2];
    let a = frequencies(&machine, &pose);
    let b = frequencies(&shifted, &pose);
    for (x, y) in a.iter().zip(&b) {
        if *x == 0.0 {
            assert_eq!(*y, 0.0);
        } else {
            assert_rel(*y, *x, 1e-9);
        }
    }
}

#[test]
fn pitch_frequency_changes_towards_the_end_of_the_stroke() {
    // The X carriages ride with the table, so moving X to the end of its stroke carries the
    // table's 450 kg 0.3 m sideways over the saddle and its Y carriages: the saddle's pitch
    // (rotation b) mode, coupled to the table through the X carriages at new contact points,
    // must shift markedly.
    let machine = load("demo-vmc.toml");
    let pitch = |x: f64| -> f64 {
        let model = Model::assemble(&machine, &[x, 0.0, 0.0]).unwrap();
        modal::modes(&model)
            .unwrap()
            .into_iter()
            .filter(|m| m.dominant_dof == "saddle.b")
            .map(|m| m.frequency_hz)
            .fold(0.0, f64::max)
    };
    let mid = pitch(0.0);
    let end = pitch(0.3);
    assert!(mid > 0.0 && end > 0.0);
    assert!(
        (end - mid) / mid > 0.05 || (mid - end) / mid > 0.05,
        "pitch {mid} Hz -> {end} Hz"
    );
}

#[test]
fn unsupported_structure_is_reported_with_the_free_dof() {
    // Remove one rail of the X axis: the remaining carriages stand on one line along x
    // (y = −0.2, z = −0.16), so the table can roll about that line freely. Per unit roll angle
    // its COG (0, 0, −0.07) moves 0.2 in z (kinetic energy ∝ 450·0.2² = 18) against the
    // rotation's I_xx = 12: the motion is dominated by table.z.
    let machine = load("demo-vmc.toml");
    let mut raw = machine.to_raw();
    raw.axes[0].guideway.rails.truncate(1);
    let bad = Machine::from_raw(
        raw,
        &eij::machine::catalogue::Catalogue::bundled().unwrap(),
        "one-rail.toml",
    )
    .unwrap();
    let model = Model::assemble(&bad, &[0.0; 3]).unwrap();
    match modal::check_support(&model, &bad) {
        Err(MbsError::Unsupported { count, dof, .. }) => {
            assert_eq!(count, 1);
            assert_eq!(dof, "table.z");
        }
        other => panic!("expected Unsupported, got {other:?}"),
    }
}

#[test]
fn pose_outside_the_stroke_is_refused() {
    let machine = load("demo-vmc.toml");
    let err = Model::assemble(&machine, &[0.0, 0.0, 0.31]).unwrap_err();
    assert!(
        err.to_string()
            .contains("axis z position 0.31 m is outside the stroke"),
        "{err}"
    );
}
