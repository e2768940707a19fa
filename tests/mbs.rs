//! Multi-body assembly and modal analysis against hand calculations and physical identities.

use eij::machine::catalogue::Catalogue;
use eij::machine::Machine;
use eij::mbs::{modal, MbsError, Model};

mod common;

use common::machine as load;
use common::whole_machine_motion;

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

/// The single-axis slide's x, y, roll a and rotor φ by hand (z, b, c do not couple with them:
/// the nut lies on the line through the COG and the rails are symmetric about it). Carriages at
/// (±0.3, ±0.25, 0), COG at z = 0.2: a carriage moves by u_y = y + 0.2·a laterally and
/// u_z = z ± 0.25·a normally; the screw spring strains by δ = x − (φ + a)·h/(2π) (right-hand
/// thread: the nut turning with the slide's roll moves along the screw). Returns ω² of
/// K v = ω² M v, ascending, rigid drive mode first.
fn slide_hand_omega2(k_ax: f64) -> Vec<f64> {
    let (kc, h) = (5e8, 0.02 / std::f64::consts::TAU);
    // DOF order x, y, a, φ.
    let mut k = nalgebra::Matrix4::<f64>::zeros();
    k[(1, 1)] = 4.0 * kc;
    k[(1, 2)] = 4.0 * kc * 0.2;
    k[(2, 1)] = 4.0 * kc * 0.2;
    k[(2, 2)] = 4.0 * kc * 0.04 + 4.0 * kc * 0.0625;
    let g = nalgebra::Vector4::new(1.0, 0.0, -h, -h);
    k += g * g.transpose() * k_ax;
    let m_inv_sqrt = nalgebra::Vector4::new(500.0, 500.0, 20.0, 0.004).map(|m: f64| 1.0 / m.sqrt());
    let a = nalgebra::Matrix4::from_diagonal(&m_inv_sqrt)
        * k
        * nalgebra::Matrix4::from_diagonal(&m_inv_sqrt);
    let mut w2: Vec<f64> = a.symmetric_eigenvalues().iter().copied().collect();
    w2.sort_by(f64::total_cmp);
    w2
}

fn hz(omega2: f64) -> f64 {
    omega2.max(0.0).sqrt() / std::f64::consts::TAU
}

/// Total axial stiffness of the single-axis screw with the nut at l₁ from the bearing.
fn single_axis_k_ax(l1: f64) -> f64 {
    let k_shaft = 2.1e11 * std::f64::consts::PI * 0.03 * 0.03 / 4.0 / l1;
    1.0 / (1.0 / k_shaft + 1.0 / 1e9 + 1.0 / 1e9)
}

#[test]
fn single_axis_slide_on_carriages_and_screw_matches_hand_calculation() {
    let machine = load("reference/single-axis.toml");
    let f = frequencies(&machine, &[0.0]);
    assert_eq!(f.len(), 7);
    assert_eq!(f[0], 0.0, "the drive's own rigid-body mode");
    let hand = slide_hand_omega2(single_axis_k_ax(0.5));
    assert!(
        hand[0].abs() < 1e-6 * hand[3],
        "hand drive mode {}",
        hand[0]
    );
    // z, b, c from four-joints.toml (318, 390, 427 Hz); x, y, a and the rotor from the 4-DOF
    // hand model.
    let mut want: Vec<f64> = FOUR_SUPPORTS_HZ[2..5].to_vec();
    want.extend(hand[1..].iter().map(|w| hz(*w)));
    want.sort_by(f64::total_cmp);
    for (got, want) in f[1..].iter().zip(&want) {
        assert_rel(*got, *want, 1e-6);
    }
    // Without the thread torque the axial mode would be √(k_ax(1/m + 1/m_r)): the torque
    // couples it with the roll and moves it by about 1e-5 — more than the tolerance above.
    let m_r = 0.004 * (std::f64::consts::TAU / 0.02_f64).powi(2);
    let no_torque = hz(single_axis_k_ax(0.5) * (1.0 / 500.0 + 1.0 / m_r));
    let axial = f
        .iter()
        .copied()
        .min_by(|a, b| (a - no_torque).abs().total_cmp(&(b - no_torque).abs()))
        .unwrap();
    assert!(
        ((axial - no_torque) / no_torque).abs() > 5e-6,
        "{axial} vs {no_torque}"
    );
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
        let hand = slide_hand_omega2(single_axis_k_ax(l1));
        let want = hand[1..]
            .iter()
            .map(|w| hz(*w))
            .min_by(|a, b| {
                (a - axial.frequency_hz)
                    .abs()
                    .total_cmp(&(b - axial.frequency_hz).abs())
            })
            .unwrap();
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
        for i in 0..machine.axes().len() {
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
    if let Some(p) = raw.workpiece.point_m.as_mut() {
        shift(p);
    }
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

#[test]
fn screw_force_on_the_nut_comes_with_the_thread_torque() {
    // Turn the rotor of the single-axis slide by φ₀ with everything else held: the screw spring
    // pushes the nut with F = k_ax·φ₀·h/(2π) along +x, and the right-hand thread adds the torque
    // −F·h/(2π) about x on the slide (its reaction is on the ground). The nut lies on the line
    // through the COG, so the slide sees no other moment. Hand numbers from the machine file.
    let machine = load("reference/single-axis.toml");
    let model = Model::assemble(&machine, &[0.0]).unwrap();
    let h = 0.02 / std::f64::consts::TAU;
    let k_shaft = 2.1e11 * std::f64::consts::PI * 0.03 * 0.03 / 4.0 / 0.5;
    let k_ax = 1.0 / (1.0 / k_shaft + 2.0 / 1e9);
    let phi0 = 1e-3;
    let mut q = nalgebra::DVector::zeros(model.n_dof());
    q[model.axes[0].rotor_dof] = phi0;
    let f = -(&model.stiffness * &q);
    let force = k_ax * phi0 * h;
    assert_rel(f[0], force, 1e-12);
    assert!(f[1].abs() < 1e-9 * force && f[2].abs() < 1e-9 * force);
    assert_rel(f[3], -force * h, 1e-12);
    assert!(f[4].abs() < 1e-9 * force && f[5].abs() < 1e-9 * force);
    // On the rotor: the screw's reaction −F·h/(2π).
    assert_rel(f[model.axes[0].rotor_dof], -force * h, 1e-12);
}

#[test]
fn a_rigid_motion_of_the_whole_machine_is_neither_deviation_nor_scale_reading() {
    // The nest is set up under the tool at every circle centre, so rocking the whole machine on
    // its feet moves TCP and nest together: no deviation, no scale reading, no screw strain, at
    // the reference and far from it.
    let machine = load("demo-vmc.toml");
    let mut raw = machine.to_raw();
    raw.joints.clear();
    let on_no_feet =
        Machine::from_raw(raw, &Catalogue::bundled().unwrap(), "demo without feet").unwrap();
    for pose in [
        [0.0, 0.0, 0.0],
        [0.15, -0.1, 0.0],
        [-0.3, 0.25, -0.1],
        [0.3, 0.25, 0.3],
    ] {
        let model = Model::assemble(&machine, &pose).unwrap();
        let floating = Model::assemble(&on_no_feet, &pose).unwrap();
        for (tr, rot) in [
            ([1e-6, -2e-6, 3e-6], [0.0, 0.0, 0.0]),
            ([0.0, 0.0, 0.0], [1e-6, 0.0, 0.0]),
            ([0.0, 0.0, 0.0], [0.0, 1e-6, 0.0]),
            ([0.0, 0.0, 0.0], [0.0, 0.0, 1e-6]),
        ] {
            let v = whole_machine_motion(
                &machine,
                &model,
                &pose,
                tr.into(),
                rot.into(),
                nalgebra::Vector3::new(0.4, -0.7, -0.9),
            );
            let tcp = &model.tcp * &v;
            assert!(
                tcp.norm() < 1e-18,
                "pose {pose:?}: TCP − nest moves by {tcp}"
            );
            for (a, p) in model.axes.iter().enumerate() {
                let s = p.scale.dot(&v);
                assert!(s.abs() < 1e-18, "pose {pose:?}: scale {a} reads {s}");
            }
            // Only the feet strain: without them the same motion strains nothing.
            let k_free = &floating.stiffness * &v;
            assert!(
                k_free.amax() < 1e-9 * floating.stiffness.amax() * 1e-6,
                "pose {pose:?}: a rigid motion strains the machine: {}",
                k_free.amax()
            );
        }
    }
}

#[test]
fn kinetic_energy_holds_the_rotor_spinning_with_its_carrier() {
    // ½ vᵀ M v against the kinetic energy written out: every free body ½(m |u̇|² + ωᵀ J ω) at
    // its centre of gravity, every rotor ½ J_rotor (φ̇ + e·ω_carrier)², φ being measured
    // against the stator on the carrier (the X motor sits on the saddle, Y and Z on the bed).
    let machine = load("demo-vmc.toml");
    let model = Model::assemble(&machine, &[0.1, -0.2, 0.05]).unwrap();
    let n = model.n_dof();
    let v = nalgebra::DVector::from_fn(n, |i, _| ((i * 7 + 3) % 11) as f64 / 11.0 - 0.4);
    let mut energy = 0.0;
    for (b, body) in machine.bodies().iter().enumerate() {
        if let Some(i) = model.body_dofs[b] {
            let u = v.fixed_rows::<3>(i);
            let w = v.fixed_rows::<3>(i + 3);
            energy += 0.5
                * (body.mass_kg * u.norm_squared() + (w.transpose() * body.inertia_kg_m2 * w)[0]);
        }
    }
    for (ai, a) in machine.axes().iter().enumerate() {
        let carrier_spin = model.body_dofs[a.carrier]
            .map_or(0.0, |i| a.direction().dot(&v.fixed_rows::<3>(i + 3)));
        let spin = v[model.axes[ai].rotor_dof] + carrier_spin;
        energy += 0.5 * a.drive.rotor_inertia_kg_m2 * spin * spin;
    }
    let got = 0.5 * v.dot(&(&model.mass * &v));
    assert_rel(got, energy, 1e-13);
}
