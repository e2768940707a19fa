//! The prediction on small random machines (`tests/common/random_machine.rs`): the harmonic
//! steady state and the time-domain simulation, through the same evaluation, give the same EIJ
//! (1 % or 0.01 µm·s²/m, the identification's confirmation threshold).

mod common;

use common::random_machine::{slide, toml};
use eij::machine::Machine;
use eij::predict::{simulated_eij, CircleTest, SimSettings, SolverKind};
use eij::{Direction, Plane};
use proptest::prelude::*;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(16))]

    #[test]
    fn harmonic_equals_time_domain(
        tool in slide(),
        table in slide(),
        accel_m_s2 in 1.0..10.0f64,
        ccw in any::<bool>(),
    ) {
        let machine = Machine::from_toml_str(&toml(&tool, &table), "random.toml").unwrap();
        let direction = if ccw { Direction::Ccw } else { Direction::Cw };
        let tests = [CircleTest::new(Plane::Xy, direction, 2.0, accel_m_s2)];
        let run = |solver| {
            let settings = SimSettings { solver, ..SimSettings::default() };
            simulated_eij(std::slice::from_ref(&machine), &tests, &settings)
        };
        let (harmonic, time) = match (run(SolverKind::Harmonic), run(SolverKind::Time)) {
            (Ok(h), Ok(t)) => (h[0][0].clone(), t[0][0].clone()),
            // A random controller/structure pair may be unstable: no steady state to compare.
            (h, t) => {
                let why = format!("{:?} {:?}", h.err(), t.err());
                prop_assume!(false, "not simulable: {}", why);
                unreachable!()
            }
        };
        prop_assert_eq!(harmonic.len(), 6);
        for (e, t) in &time {
            let h = harmonic[e];
            prop_assert!(
                (h - t).abs() <= (0.01 * t.abs()).max(0.01),
                "{}: harmonic {}, time domain {}", e, h, t
            );
        }
        // The offset nut tilts the slides: the in-talk is not trivially zero.
        prop_assert!(harmonic.values().any(|v| v.abs() > 1e-3));
    }
}
