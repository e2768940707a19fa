//! Properties of the assembled model on small random machines (`tests/common/random_machine.rs`):
//! the stiffness matrix is symmetric and positive semi-definite, and the rigid motion of each
//! drive (slide and rotor together) lies in its null space. (The damping matrix does not vanish
//! on it: viscous friction on the rotor resists the drive's motion.)

mod common;

use common::random_machine::{slide, toml};
use eij::machine::{Machine, Pose};
use eij::mbs::Model;
use proptest::prelude::*;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn stiffness_is_symmetric_positive_semidefinite_and_drives_are_free(
        tool in slide(),
        table in slide(),
        x in -0.2..0.2f64,
        y in -0.2..0.2f64,
    ) {
        let machine = Machine::from_toml_str(&toml(&tool, &table), "random.toml").unwrap();
        let model = Model::assemble(&machine, &Pose::new(&machine, &[x, y]).unwrap()).unwrap();
        let k = &model.stiffness;
        let scale = k.amax();
        prop_assert!((k - k.transpose()).amax() <= 1e-12 * scale);
        let eig = k.clone().symmetric_eigen();
        let min = eig.eigenvalues.min();
        prop_assert!(min >= -1e-9 * scale, "eigenvalue {min} of K (max |K| {scale})");
        for i in 0..machine.axes().len() {
            let v = model.drive_mode(&machine, i);
            let kv = (k * &v).amax();
            prop_assert!(kv <= 1e-9 * scale * v.amax(), "axis {i}: |K v| = {kv}");
        }
    }
}
