//! A body with elastic coordinates in the assembly, checked against calculations written here.
//!
//! The reduced model is made by hand: the demo's spindle head keeps its six rigid coordinates at
//! its centre of gravity and gains one elastic coordinate η (modal mass 1, stiffness ω²) that
//! moves the nut by α and the TCP by β along z and nothing else. Accelerating the head along z,
//! the screw force F = m·a is the only force on it along z (the carriages take none along their
//! rails), so η̈ + 2ζωη̇ + ω²η = α·F and the TCP moves by β·η more than on the rigid head:
//! EZZ grows by α·β·m/(ω² − Ω²) at the circle frequency Ω, and nothing else changes.

use eij::axes::{Axis, Direction, Eij, Plane};
use eij::ident::Parameter;
use eij::machine::catalogue::Catalogue;
use eij::machine::{ElasticBody, ElasticModel, Machine, Site};
use eij::mbs::{modal, Model};
use eij::predict::CircleTest;
use nalgebra::{DMatrix, Vector3};
use std::sync::Arc;

mod common;

use common::{assert_motion_free, demo, one_eij, whole_machine_motion};

/// Nut and TCP motion per unit η along z, m.
const ALPHA: f64 = 0.05;
const BETA: f64 = 0.04;
const ZETA: f64 = 0.02;

#[derive(Debug)]
struct HandMadeHead {
    cog: Vector3<f64>,
    mass: DMatrix<f64>,
    stiffness: DMatrix<f64>,
}

impl HandMadeHead {
    /// The demo's head (500 kg, inertia diag(40, 35, 20) kg·m² at [0.03, 0.22, 0.5] m, as its
    /// machine file gives) with one elastic mode at `f_hz`.
    fn new(f_hz: f64) -> HandMadeHead {
        let mut mass = DMatrix::zeros(7, 7);
        for (d, m) in [500.0, 500.0, 500.0, 40.0, 35.0, 20.0, 1.0]
            .iter()
            .enumerate()
        {
            mass[(d, d)] = *m;
        }
        let mut stiffness = DMatrix::zeros(7, 7);
        stiffness[(6, 6)] = (std::f64::consts::TAU * f_hz).powi(2);
        HandMadeHead {
            cog: Vector3::new(0.03, 0.22, 0.5),
            mass,
            stiffness,
        }
    }
}

impl ElasticModel for HandMadeHead {
    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
    fn cog_m(&self) -> Vector3<f64> {
        self.cog
    }
    fn mass(&self) -> &DMatrix<f64> {
        &self.mass
    }
    fn stiffness(&self) -> &DMatrix<f64> {
        &self.stiffness
    }
    fn point_motion(&self, site: Site, p: &Vector3<f64>) -> Option<DMatrix<f64>> {
        // u = u_c + θ × (p − c): the columns of θ are the cross products with the unit
        // rotations, θ × r = −r × θ.
        let r = p - self.cog;
        let mut t = DMatrix::zeros(6, 7);
        for d in 0..3 {
            t[(d, d)] = 1.0;
            t[(3 + d, 3 + d)] = 1.0;
            let mut unit = Vector3::zeros();
            unit[d] = 1.0;
            let moved = unit.cross(&r);
            for k in 0..3 {
                t[(k, 3 + d)] = moved[k];
            }
        }
        match site {
            Site::Nut(Axis::Z) => t[(2, 6)] = ALPHA,
            Site::Tcp => t[(2, 6)] = BETA,
            _ => {}
        }
        Some(t)
    }
}

/// The demo machine with ideal set-point tracking: no set-point smoothing and no current-loop
/// lag, so that the head accelerates as set (with the feed-forwards at 1) and F = m·a holds with
/// the set acceleration.
fn tracking_demo() -> Machine {
    let mut raw = demo().to_raw();
    for a in &mut raw.axes {
        a.control.setpoint_filter_s = 0.0;
        a.control.current_lag_s = 0.0;
    }
    Machine::from_raw(raw, &Catalogue::bundled().unwrap(), "demo, ideal tracking").unwrap()
}

fn elastic_demo(f_hz: f64, stiffness_factor: f64) -> Machine {
    let body = ElasticBody::new(Arc::new(HandMadeHead::new(f_hz)), ZETA, stiffness_factor).unwrap();
    tracking_demo().with_elastic_body("head", body).unwrap()
}

fn zx_eij(machine: &Machine) -> std::collections::BTreeMap<Eij, f64> {
    one_eij(
        machine,
        CircleTest::new(Plane::Zx, Direction::Ccw, 2.0, 5.0),
    )
}

/// α·β·m/(ω² − Ω²), µm·s²/m: the TCP's extra lag per set acceleration of Z.
fn hand_ezz(f_hz: f64) -> f64 {
    let test = CircleTest::new(Plane::Zx, Direction::Ccw, 2.0, 5.0);
    let omega = std::f64::consts::TAU * f_hz;
    let big_omega = std::f64::consts::TAU * test.freq_hz();
    ALPHA * BETA * 500.0 / (omega * omega - big_omega * big_omega) * 1e6
}

/// Quasi-static TCP deviation along z per set acceleration of Z, m/(m/s²): the slide and rotor
/// accelerate rigidly by a, their inertia loads the structure with f = −M·r·a, the scales hold
/// every axis at its set point, [K B; Sᵀ 0]·[q; τ] = [f; 0], and the deviation is tcp·q.
fn quasi_static_ezz(machine: &Machine) -> f64 {
    let model = Model::assemble(machine, &[0.0, 0.0, 0.0]).unwrap();
    let (n, na) = (model.n_dof(), machine.axes().len());
    let z = machine
        .axes()
        .iter()
        .position(|a| a.axis == Axis::Z)
        .unwrap();
    let mut r = nalgebra::DVector::zeros(n);
    for b in 0..machine.bodies().len() {
        if let (Some(i), true) = (model.body_dofs[b], machine.is_carried_by(b, z)) {
            r[i + 2] = 1.0;
        }
    }
    r[model.axes[z].rotor_dof] = 1.0 / machine.axes()[z].drive.transmission_m_per_rad();
    let mut kkt = DMatrix::zeros(n + na, n + na);
    kkt.view_mut((0, 0), (n, n)).copy_from(&model.stiffness);
    let mut rhs = nalgebra::DVector::zeros(n + na);
    rhs.rows_mut(0, n).copy_from(&-(&model.mass * &r));
    for (i, ports) in model.axes.iter().enumerate() {
        kkt[(ports.rotor_dof, n + i)] = -1.0;
        for k in 0..n {
            kkt[(n + i, k)] = ports.scale[k];
        }
    }
    let x = kkt.lu().solve(&rhs).unwrap();
    (&model.tcp * x.rows(0, n))[2]
}

#[test]
fn in_statics_the_elastic_head_lags_by_exactly_alpha_beta_m_over_omega_squared() {
    let rigid = quasi_static_ezz(&demo());
    for f_hz in [150.0, 400.0] {
        let omega2 = (std::f64::consts::TAU * f_hz).powi(2);
        let want = ALPHA * BETA * 500.0 / omega2;
        let body = ElasticBody::new(Arc::new(HandMadeHead::new(f_hz)), ZETA, 1.0).unwrap();
        let elastic = demo().with_elastic_body("head", body).unwrap();
        let got = quasi_static_ezz(&elastic) - rigid;
        assert!(
            (got - want).abs() < 1e-9 * want,
            "{f_hz} Hz: {got} m/(m/s²) against {want}"
        );
    }
}

/// In the closed loop at the circle frequency: the lag follows α·β·m/(ω² − Ω²) to within the
/// change of the drive's tracking the extra compliance in the drive line brings (it scales the
/// rigid part of the EIJ by a few tenths of a percent).
#[test]
fn an_elastic_head_adds_the_hand_calculated_lag_to_ezz_and_nothing_else() {
    let rigid = zx_eij(&tracking_demo());
    for f_hz in [150.0, 400.0] {
        let elastic = zx_eij(&elastic_demo(f_hz, 1.0));
        let want = hand_ezz(f_hz);
        let zz = Eij::new(Axis::Z, Axis::Z);
        let got = elastic[&zz] - rigid[&zz];
        assert!(
            (got - want).abs() < 0.01 * want,
            "{f_hz} Hz: EZZ grew by {got}, by hand {want}"
        );
        for (k, v) in &rigid {
            if *k != zz {
                assert!(
                    (elastic[k] - v).abs() < 0.01 * want,
                    "{k}: {} against {v} on the rigid head",
                    elastic[k]
                );
            }
        }
    }
}

#[test]
fn the_stiffness_factor_scales_the_mode_as_youngs_modulus_does() {
    // Factor c: ω² → c·ω², so the added lag follows α·β·m/(c·ω² − Ω²).
    let rigid = zx_eij(&tracking_demo())[&Eij::new(Axis::Z, Axis::Z)];
    let mut machine = elastic_demo(150.0, 1.0);
    let p = Parameter::parse("head.stiffness", &machine).unwrap();
    assert_eq!(p.get(&machine), 1.0);
    p.set(&mut machine, 4.0).unwrap();
    let got = zx_eij(&machine)[&Eij::new(Axis::Z, Axis::Z)] - rigid;
    let want = hand_ezz(300.0);
    assert!((got - want).abs() < 0.01 * want, "{got} against {want}");
    assert!(Parameter::parse("head.stiffness", &demo()).is_err());
}

#[test]
fn a_very_stiff_elastic_coordinate_gives_the_rigid_body() {
    let rigid = zx_eij(&tracking_demo());
    let stiff = zx_eij(&elastic_demo(150.0, 1e4));
    for (k, v) in &rigid {
        assert!(
            (stiff[k] - v).abs() < 1e-3 * v.abs().max(0.1),
            "{k}: {} against {v}",
            stiff[k]
        );
    }
}

#[test]
fn coordinates_are_named_and_a_rigid_motion_of_the_whole_machine_stays_free() {
    // Without its feet the machine floats: a rigid motion of everything together (elastic
    // coordinates at zero) meets no spring, moves no scale and shows no deviation, at the
    // reference and far from it.
    let mut raw = demo().to_raw();
    raw.joints.clear();
    let floating = Machine::from_raw(raw, &Catalogue::bundled().unwrap(), "no feet").unwrap();
    let body = ElasticBody::new(Arc::new(HandMadeHead::new(150.0)), ZETA, 1.0).unwrap();
    let machine = floating.with_elastic_body("head", body).unwrap();
    let head = machine
        .bodies()
        .iter()
        .position(|b| b.name == "head")
        .unwrap();
    for pose in [[0.0, 0.0, 0.0], [0.2, -0.15, 0.1]] {
        let model = Model::assemble(&machine, &pose).unwrap();
        let i = model.body_dofs[head].unwrap();
        assert_eq!(model.dofs[i + 6], "head.mode1");
        assert_eq!(model.dofs[i + 7], "x.motor");
        let (tr, rot) = (
            Vector3::new(1e-6, -3e-6, 2e-6),
            Vector3::new(1e-6, -2e-6, 0.5e-6),
        );
        let v = whole_machine_motion(&machine, &model, &pose, tr, rot, Vector3::zeros());
        assert_motion_free(&model, &v, 1e-18);
    }
    // With its feet, the structure is supported (only the drives move freely).
    let with_feet = elastic_demo(150.0, 1.0);
    let model = Model::assemble(&with_feet, &[0.1, 0.1, 0.1]).unwrap();
    modal::check_support(&model, &with_feet).unwrap();
}

#[test]
fn a_reduced_model_that_does_not_fit_its_body_is_refused() {
    // Stiffness on a rigid coordinate: a rigid motion would meet a spring.
    let mut head = HandMadeHead::new(150.0);
    head.stiffness[(2, 2)] = 1e6;
    let e = ElasticBody::new(Arc::new(head), ZETA, 1.0).unwrap_err();
    assert!(e.to_string().contains("rigid motion"), "{e}");
    // A mass matrix whose rigid block is not at the centre of gravity.
    let mut head = HandMadeHead::new(150.0);
    head.mass[(0, 4)] = 10.0;
    head.mass[(4, 0)] = 10.0;
    let body = ElasticBody::new(Arc::new(head), ZETA, 1.0).unwrap();
    let e = demo().with_elastic_body("head", body).unwrap_err();
    assert!(e.to_string().contains("body[head]"), "{e}");
    // Damping ratio outside [0, 1), a fixed body, an unknown body.
    assert!(ElasticBody::new(Arc::new(HandMadeHead::new(150.0)), 1.5, 1.0).is_err());
    let body = || ElasticBody::new(Arc::new(HandMadeHead::new(150.0)), ZETA, 1.0).unwrap();
    assert!(demo().with_elastic_body("floor", body()).is_err());
    assert!(demo().with_elastic_body("nobody", body()).is_err());
}
