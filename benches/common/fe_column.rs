//! The solid column of the FE benchmark (`benches/fe.rs`) and `examples/fe_column.rs`: hexahedral
//! elements, 0.6 × 0.5 × 3.0 m, 12 × 10 × `nz` elements (nz = 150: 64 779 DOFs), held by two RBE3
//! patches (foot and top), reduced with 30 fixed-interface modes.

use eij::fe::{Attachment, FeModel, Hex8Block, ReductionSettings};

/// The column with `nz` elements along its height.
pub fn column(nz: usize) -> FeModel {
    FeModel::hex8_block(&Hex8Block {
        origin_m: [0.0, 0.0, 0.0],
        size_m: [0.6, 0.5, 3.0],
        divisions: [12, 10, nz],
        youngs_modulus_pa: 1.2e11,
        poisson_ratio: 0.27,
        density_kg_m3: 7200.0,
    })
    .expect("the column meshes")
}

/// Foot and top centre.
pub fn attachments() -> [Attachment; 2] {
    [
        Attachment::fixed("foot", [0.3, 0.25, 0.0]),
        Attachment::fixed("top", [0.3, 0.25, 3.0]),
    ]
}

/// 30 fixed-interface modes, RBE3 radius 0.08 m.
pub fn settings() -> ReductionSettings {
    ReductionSettings {
        modes: 30,
        attach_radius_m: Some(0.08),
        ..Default::default()
    }
}
