//! The physics behind the predicted EIJ, against calculations written here: the R-Test nest
//! under the tool (a rigid motion of the whole machine never shows as EIJ) and the quasi-static
//! deflection under the inertial load of the accelerated slides.

use eij::axes::{Direction, Eij, Plane};
use eij::machine::catalogue::Catalogue;
use eij::machine::{Machine, Pose};
use eij::mbs::Model;
use eij::predict::{simulated_eij, CircleTest, SimSettings};
use nalgebra::{DMatrix, DVector};
use std::collections::BTreeMap;

mod common;

use common::demo;

/// Circle centres away from the reference position (and the reference itself), m.
const POSITIONS: [[f64; 3]; 4] = [
    [0.0, 0.0, 0.0],
    [0.15, -0.1, 0.0],
    [-0.25, 0.2, 0.25],
    [0.28, 0.22, -0.08],
];

/// The demo machine with its levelling feet `factor` times stiffer.
fn with_stiffer_feet(factor: f64) -> Machine {
    let mut raw = demo().to_raw();
    for j in &mut raw.joints {
        for k in &mut j.stiffness_n_per_m {
            *k *= factor;
        }
    }
    Machine::from_raw(raw, &Catalogue::bundled().unwrap(), "demo, stiffer feet").unwrap()
}

fn tests_everywhere(accel: f64) -> Vec<CircleTest> {
    let mut tests = Vec::new();
    for p in POSITIONS {
        for plane in Plane::ALL {
            tests.push(CircleTest::new(plane, Direction::Ccw, 2.0, accel).at(p.to_vec()));
        }
    }
    tests
}

#[test]
fn stiffer_feet_change_no_eij_anywhere_in_the_workspace() {
    // The feet carry the whole machine: stiffening them changes how it rocks as one body, which
    // the R-Test (nest under the tool) cannot see. On slow circles nothing changes, at the
    // reference or far from it, in any plane.
    let tests = tests_everywhere(0.5);
    let settings = SimSettings::default();
    let eij = simulated_eij(&[demo(), with_stiffer_feet(100.0)], &tests, &settings).unwrap();
    let mut largest: f64 = 0.0;
    for (t, (soft, stiff)) in tests.iter().zip(eij[0].iter().zip(&eij[1])) {
        for e in t.plane.parameters() {
            largest = largest.max(soft[&e].abs());
            let d = (soft[&e] - stiff[&e]).abs();
            assert!(
                d < 1e-3,
                "{}: {e} {:.5} with the demo's feet, {:.5} with 100× stiffer ones",
                t.label(),
                soft[&e],
                stiff[&e]
            );
        }
    }
    assert!(
        largest > 0.3,
        "the test must see real EIJ: largest {largest}"
    );
}

#[test]
fn on_fast_circles_the_feet_act_only_through_the_machine_inertia() {
    // What remains at 8 Hz is dynamic: the bed and everything on it accelerate on the feet, and
    // that inertia loads the slides. It grows as ω² (∝ a on circles of one radius), about 5×
    // from 1 to 5 m/s², and stays below 1 % of the largest EIJ.
    let machines = [demo(), with_stiffer_feet(100.0)];
    let settings = SimSettings::default();
    let change = |accel: f64| -> (f64, f64) {
        let tests = tests_everywhere(accel);
        let eij = simulated_eij(&machines, &tests, &settings).unwrap();
        let (mut d, mut largest): (f64, f64) = (0.0, 0.0);
        for (t, (soft, stiff)) in tests.iter().zip(eij[0].iter().zip(&eij[1])) {
            for e in t.plane.parameters() {
                d = d.max((soft[&e] - stiff[&e]).abs());
                largest = largest.max(soft[&e].abs());
            }
        }
        (d, largest)
    };
    let (slow, _) = change(1.0);
    let (fast, largest) = change(5.0);
    let growth = fast / slow;
    assert!(
        (4.5..6.5).contains(&growth),
        "the feet's share grows {growth}× from 1 to 5 m/s² ({slow} → {fast})"
    );
    assert!(
        fast < 0.01 * largest,
        "the feet's share at 8 Hz: {fast} of {largest}"
    );
}

/// Quasi-static EIJ, µm·s²/m, by a calculation of its own: the slides carried by axis J
/// accelerate rigidly by a (bodies by σ·e·a, the rotor by σ·a/h); their inertia loads the
/// structure with f = −M·r·a; every axis holds its scale at the set point (integral action) with
/// whatever motor torque that takes; the deflection q solves [K B; Sᵀ 0]·[q; τ] = [f; 0].
/// The deviation is TCP − nest − scale reading: tcp·q (the scales read zero).
fn quasi_static_eij(machine: &Machine, pose: &[f64]) -> BTreeMap<Eij, f64> {
    let model = Model::assemble(machine, &Pose::new(machine, pose).unwrap()).unwrap();
    let n = model.n_dof();
    let na = machine.axes().len();
    // Rigid motion of each axis per metre of axis travel.
    let mut out = BTreeMap::new();
    for (j, axis) in machine.axes().iter().enumerate() {
        let sigma = axis.side.sign();
        let mut r = DVector::zeros(n);
        for b in 0..machine.bodies().len() {
            if let (Some(dof), true) = (model.body_dofs[b], machine.is_carried_by(b, j)) {
                for d in 0..3 {
                    r[dof + d] = sigma * axis.direction()[d];
                }
            }
        }
        r[model.axes[j].rotor_dof] = sigma / axis.drive.transmission_m_per_rad();
        let f = -(&model.mass * &r);
        let mut kkt = DMatrix::zeros(n + na, n + na);
        kkt.view_mut((0, 0), (n, n)).copy_from(&model.stiffness);
        let mut rhs = DVector::zeros(n + na);
        rhs.rows_mut(0, n).copy_from(&f);
        for (i, ports) in model.axes.iter().enumerate() {
            kkt[(ports.rotor_dof, n + i)] = -1.0;
            for k in 0..n {
                kkt[(n + i, k)] = ports.scale[k];
            }
        }
        let x = kkt.lu().solve(&rhs).expect("the scales pin every drive");
        let q = x.rows(0, n);
        let dev = &model.tcp * q;
        for (i, a) in machine.axes().iter().enumerate() {
            out.insert(Eij::new(a.axis, axis.axis), dev[i] * 1e6);
        }
    }
    out
}

#[test]
fn slow_circles_give_the_quasi_static_deflection_and_8_hz_circles_stay_within_2_percent() {
    let machine = demo();
    for p in [POSITIONS[0], POSITIONS[1], POSITIONS[2]] {
        let qs = quasi_static_eij(&machine, &p);
        let largest = qs.values().fold(0.0_f64, |m, v| m.max(v.abs()));
        assert!(largest > 0.3, "largest quasi-static EIJ {largest}");
        for (accel, tol) in [(0.2, 0.005), (5.0, 0.02)] {
            let tests: Vec<CircleTest> = Plane::ALL
                .iter()
                .map(|&plane| CircleTest::new(plane, Direction::Ccw, 2.0, accel).at(p.to_vec()))
                .collect();
            let sim = simulated_eij(
                std::slice::from_ref(&machine),
                &tests,
                &SimSettings::default(),
            )
            .unwrap();
            for (t, eij) in tests.iter().zip(&sim[0]) {
                for e in t.plane.parameters() {
                    let (got, want) = (eij[&e], qs[&e]);
                    assert!(
                        (got - want).abs() <= tol * want.abs().max(0.1 * largest),
                        "{} ({:.2} Hz): {e} simulated {got:.5}, quasi-static {want:.5}",
                        t.label(),
                        t.freq_hz()
                    );
                }
            }
        }
    }
}
