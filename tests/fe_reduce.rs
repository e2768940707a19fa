//! Craig–Bampton reduction of a small solid (hexahedral column) against the full FE model solved
//! densely here: free-free frequencies, static deflection under loads through the attachments
//! (with an RBE3 written in this test from its formula), rigid-body motion, mass properties, the
//! stiffness factor, and continuity of a travelling attachment.

mod fe_common;
use eij::fe::{reduce, Attachment, FeModel, Hex8Block, ReductionSettings, CUTOFF_MARGIN};
use fe_common::{dense, generalized_eigenvalues, hz};
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

fn block(e: f64) -> Hex8Block {
    Hex8Block {
        origin_m: [0.0, 0.0, 0.0],
        size_m: [0.3, 0.2, 1.2],
        divisions: [3, 2, 10],
        youngs_modulus_pa: e,
        poisson_ratio: 0.28,
        density_kg_m3: 7200.0,
    }
}

const RADIUS: f64 = 0.11;

fn attachments() -> Vec<Attachment> {
    vec![
        Attachment::fixed("foot", [0.1, 0.1, 0.0]),
        Attachment::fixed("top", [0.1, 0.1, 1.2]),
        Attachment::travel("rail", [0.3, 0.0, 0.2], [0.3, 0.0, 1.0]),
    ]
}

fn settings(cutoff_hz: Option<f64>) -> ReductionSettings {
    ReductionSettings {
        modes: 20,
        cutoff_hz,
        attach_radius_m: Some(RADIUS),
        interface_modes: None,
        full_reference: true,
    }
}

/// Solves K u = f with held u = 0 (Lagrange multipliers, `held`: 6 × n).
fn held_solve(k: &DMatrix<f64>, held: &DMatrix<f64>, f: &DVector<f64>) -> DVector<f64> {
    let n = k.nrows();
    let mut kkt = DMatrix::zeros(n + 6, n + 6);
    kkt.view_mut((0, 0), (n, n)).copy_from(k);
    kkt.view_mut((0, n), (n, 6)).copy_from(&held.transpose());
    kkt.view_mut((n, 0), (6, n)).copy_from(held);
    let mut rhs = DVector::zeros(n + 6);
    rhs.rows_mut(0, n).copy_from(f);
    kkt.lu().solve(&rhs).unwrap().rows(0, n).into_owned()
}

/// The test column reduced with 20 modes, without the full-model reference.
fn reduced(model: &FeModel) -> eij::fe::ReducedBody {
    let quick = ReductionSettings {
        full_reference: false,
        ..settings(None)
    };
    reduce(model, &attachments(), &quick).unwrap()
}

/// RBE3 by its definition: the least-squares rigid motion (u at the centroid, θ) of the nodes
/// within the radius, then carried to `p`: 6 × n.
fn rbe3(model: &FeModel, centre: Vector3<f64>, p: Vector3<f64>) -> DMatrix<f64> {
    let nodes: Vec<usize> = (0..model.nodes.len())
        .filter(|&i| (model.nodes[i].position - centre).norm() <= RADIUS)
        .collect();
    // Unknowns (u, θ) at p minimise Σ |u + θ × (xᵢ − p) − uᵢ|²: normal equations AᵀA z = Aᵀ U.
    let rows = 3 * nodes.len();
    let mut a = DMatrix::zeros(rows, 6);
    let mut sel = DMatrix::zeros(rows, model.n_dofs());
    for (k, &i) in nodes.iter().enumerate() {
        let d = model.nodes[i].position - p;
        let dofs = model.node_dofs(i);
        for c in 0..3 {
            a[(3 * k + c, c)] = 1.0;
            sel[(3 * k + c, dofs[c].unwrap())] = 1.0;
        }
        // θ × d = −skew(d) θ.
        a.view_mut((3 * k, 3), (3, 3))
            .copy_from(&(-d.cross_matrix()));
    }
    let ata = a.transpose() * &a;
    ata.try_inverse().unwrap() * a.transpose() * sel
}

#[test]
fn reduced_free_free_frequencies_match_the_full_model_below_half_the_cutoff() {
    let model = FeModel::hex8_block(&block(2.1e11)).unwrap();
    let cutoff = 5000.0;
    let body = reduce(&model, &attachments(), &settings(Some(cutoff))).unwrap();
    let full = generalized_eigenvalues(&dense(&model.stiffness), &dense(&model.mass));
    let full_hz: Vec<f64> = full.iter().map(|l| hz(*l)).collect();
    // Six rigid-body modes at ~0, then the elastic ones.
    assert!(full_hz[5] < 1e-4 * full_hz[6], "{:?}", &full_hz[..8]);
    let reduced = body.frequencies_hz(1.0);
    let elastic = &full_hz[6..];
    let mut compared = 0;
    for (r, f) in reduced.iter().zip(elastic) {
        // Rayleigh–Ritz: never below the full model.
        assert!(*r >= f * (1.0 - 1e-9), "{r} below {f}");
        if *f < 0.5 * cutoff {
            assert!((r - f) / f <= 1e-3, "{r} vs {f}");
            compared += 1;
        }
    }
    assert!(compared >= 6, "only {compared} modes below half the cutoff");
    // Fixed-interface modes are kept up to CUTOFF_MARGIN × the cutoff, no further.
    let fixed: Vec<f64> = body
        .fixed_interface_eigenvalues
        .iter()
        .map(|l| hz(*l))
        .collect();
    assert!(
        fixed.iter().all(|f| *f <= CUTOFF_MARGIN * cutoff) && fixed.len() >= 10,
        "{fixed:?}"
    );
    // The sparse full-model reference (Lanczos) equals the dense one.
    let sparse = body.full_free_frequencies_hz.as_ref().unwrap();
    assert_eq!(sparse.len(), reduced.len());
    for (s, f) in sparse.iter().zip(elastic) {
        assert!((s - f).abs() <= 1e-8 * f, "{s} vs {f}");
    }
    let summary = body.summary("column", &[0.0, 0.0, 0.3], 1.0);
    assert_eq!(summary.interface_dofs, body.interface_dofs());
    assert_eq!(
        summary.free_frequencies_hz.len(),
        summary.full_free_frequencies_hz.len()
    );
}

#[test]
fn static_deflection_under_attachment_loads_equals_the_full_model() {
    let model = FeModel::hex8_block(&block(2.1e11)).unwrap();
    let body = reduce(&model, &attachments(), &settings(None)).unwrap();
    let k = dense(&model.stiffness);
    let foot = rbe3(
        &model,
        Vector3::new(0.1, 0.1, 0.0),
        Vector3::new(0.1, 0.1, 0.0),
    );
    // A rail point on a node layer (z = 0.48): its stations' patch is centred on the line there.
    let s = 0.28;
    let rail_p = Vector3::new(0.3, 0.0, 0.2 + s);
    let rail = rbe3(&model, rail_p, rail_p);
    let top = rbe3(
        &model,
        Vector3::new(0.1, 0.1, 1.2),
        Vector3::new(0.1, 0.1, 1.2),
    );
    let load = DVector::from_row_slice(&[3.0e4, -2.0e4, 1.0e4, 800.0, -500.0, 300.0]);
    for (name, w_load, index, at) in [("top", &top, 1usize, 0.0), ("rail", &rail, 2, s)] {
        // Full: K u = W_loadᵀ f with W_foot u = 0; reduced: the same in body coordinates.
        let full = w_load * held_solve(&k, &foot, &(w_load.transpose() * &load));
        let gl = DMatrix::from_iterator(
            6,
            body.width(),
            body.point_motion(index, at).iter().copied(),
        );
        let gf = DMatrix::from_iterator(6, body.width(), body.point_motion(0, 0.0).iter().copied());
        let reduced = &gl * held_solve(&body.stiffness_matrix(1.0), &gf, &(gl.transpose() * &load));
        let err = (&reduced - &full).norm() / full.norm();
        assert!(err <= 1e-9, "{name}: {reduced} vs {full}: {err:.2e}");
    }
}

#[test]
fn rigid_motion_mass_properties_and_stiffness_factor() {
    let b = block(2.1e11);
    let model = FeModel::hex8_block(&b).unwrap();
    let body = reduced(&model);
    let [lx, ly, lz] = b.size_m;
    let mass = 7200.0 * lx * ly * lz;
    assert!((body.mass.mass_kg - mass).abs() < 1e-9 * mass);
    assert!((body.mass.cog_m - Vector3::new(0.15, 0.1, 0.6)).norm() < 1e-12);
    let box_j = Matrix3::from_diagonal(&Vector3::new(
        ly * ly + lz * lz,
        lx * lx + lz * lz,
        lx * lx + ly * ly,
    )) * (mass / 12.0);
    assert!((body.mass.inertia_kg_m2 - box_j).norm() < 1e-9 * box_j.norm());
    // Rigid part of every attachment's motion: [I, −skew(p − cog); 0, I], elastic force none.
    for (i, s) in [(0, 0.0), (1, 0.0), (2, 0.0), (2, 0.41), (2, 0.8)] {
        let g = body.point_motion(i, s);
        let p = attachments()[i].point_at(s);
        let d = p - body.mass.cog_m;
        let mut rigid = DMatrix::<f64>::identity(6, 6);
        rigid
            .view_mut((0, 3), (3, 3))
            .copy_from(&(-d.cross_matrix()));
        assert!((g.columns(0, 6) - &rigid).amax() < 1e-9, "{i} at {s}");
    }
    let m = body.mass_matrix();
    let k = body.stiffness_matrix(1.0);
    assert!(k.columns(0, 6).amax() == 0.0 && k.rows(0, 6).amax() == 0.0);
    assert!(
        (m.view((6, 6), (body.elastic_modes(), body.elastic_modes()))
            - DMatrix::identity(body.elastic_modes(), body.elastic_modes()))
        .amax()
            == 0.0
    );
    // Stiffness factor 2 without a new reduction = the reduction of a body with E × 2.
    let stiffer = reduce(
        &FeModel::hex8_block(&block(4.2e11)).unwrap(),
        &attachments(),
        &settings(None),
    )
    .unwrap();
    for (a, b) in body
        .frequencies_hz(2.0)
        .iter()
        .zip(stiffer.frequencies_hz(1.0))
    {
        assert!((a - b).abs() <= 1e-9 * b, "{a} vs {b}");
    }
}

#[test]
fn travelling_attachment_is_continuous_across_stations() {
    let model = FeModel::hex8_block(&block(2.1e11)).unwrap();
    let body = reduced(&model);
    let scale = body.point_motion(2, 0.4).amax();
    // Layers at z = 0.12 k: s = z − 0.2 crosses stations at 0.04, 0.16, 0.28, …
    for z in [0.24, 0.36, 0.48, 0.6, 0.72, 0.84, 0.96] {
        let s = z - 0.2;
        for eps in [1e-6, 1e-9] {
            let jump = (body.point_motion(2, s + eps) - body.point_motion(2, s - eps)).amax();
            assert!(
                jump <= 1e3 * eps * scale,
                "jump {jump:.3e} at s = {s} (ε = {eps})"
            );
        }
    }
    // Between two stations the motion is the linear blend of theirs (carried to the point).
    let a = body.point_motion(2, 0.30);
    let b = body.point_motion(2, 0.35);
    let mid = body.point_motion(2, 0.325);
    // (rotations carry no lever arm, so they blend exactly linearly in s)
    assert!((mid.rows(3, 3) - (a.rows(3, 3) + b.rows(3, 3)) * 0.5).amax() < 1e-9 * scale);
    let nodes = body.attachment_nodes(2, 0.30);
    assert!((nodes.weights.iter().sum::<f64>() - 1.0).abs() < 1e-12);
}

#[test]
fn carriage_on_a_beam_deflects_like_the_beam_formula_and_moves_continuously() {
    let (e, g, kappa) = (2.1e11, 8.1e10, 0.5);
    let beam = fe_common::contract_beam(12, e, g);
    let model = FeModel::beam(&beam).unwrap();
    // A carriage 0.2 m off the beam axis (along x) travels along it; the foot node is held.
    let atts = [
        Attachment::fixed("foot", [0.0, 0.6, -0.1]),
        Attachment::travel("carriage", [0.2, 0.6, -0.1], [0.2, 0.6, 1.1]),
    ];
    let body = reduce(
        &model,
        &atts,
        &ReductionSettings {
            modes: 8,
            ..Default::default()
        },
    )
    .unwrap();
    let w = body.width();
    let foot = DMatrix::from_iterator(6, w, body.point_motion(0, 0.0).iter().copied());
    let p = 1.0e4;
    let force = DVector::from_row_slice(&[0.0, p, 0.0, 0.0, 0.0, 0.0]);
    // On a node (s = 0.7 m: 0.7 m from the foot) the deflection along y is bending about local y
    // (machine y is the section's local z) plus shear plus the twist from the 0.2 m lever.
    let a = 0.7;
    let g_p = DMatrix::from_iterator(6, w, body.point_motion(1, a).iter().copied());
    let u = &g_p
        * held_solve(
            &body.stiffness_matrix(1.0),
            &foot,
            &(g_p.transpose() * &force),
        );
    let expected = p * a.powi(3) / (3.0 * e * beam.iy_m4)
        + p * a / (kappa * g * beam.area_m2)
        + 0.04 * p * a / (g * beam.torsion_m4);
    assert!(
        (u[1] - expected).abs() <= 1e-9 * expected,
        "{} vs {expected}",
        u[1]
    );
    // Stations are the beam's nodes (0.1 m apart): no step across any of them.
    let scale = body.point_motion(1, 0.55).amax();
    for k in 1..12 {
        let s = 0.1 * k as f64;
        let jump = (body.point_motion(1, s + 1e-9) - body.point_motion(1, s - 1e-9)).amax();
        assert!(jump <= 1e-6 * scale, "step {jump:.2e} at s = {s}");
    }
    let at = body.attachment_nodes(1, 0.25);
    assert_eq!(at.nodes, vec![3, 4]);
    assert!((at.weights[0] - 0.5).abs() < 1e-12 && (at.weights[1] - 0.5).abs() < 1e-12);
}

#[test]
fn reduced_interface_keeps_the_low_modes() {
    // The rail's 9 stations and the two points: 66 interface DOFs, reduced to 6 + 12.
    let model = FeModel::hex8_block(&block(2.1e11)).unwrap();
    let full = generalized_eigenvalues(&dense(&model.stiffness), &dense(&model.mass));
    let cutoff = 5000.0;
    let settings = ReductionSettings {
        interface_modes: Some(12),
        full_reference: false,
        ..settings(Some(cutoff))
    };
    let body = reduce(&model, &attachments(), &settings).unwrap();
    assert_eq!(
        (body.interface_dofs(), body.interface_coordinates()),
        (66, 18)
    );
    let mut compared = 0;
    for (r, l) in body.frequencies_hz(1.0).iter().zip(&full[6..]) {
        let f = hz(*l);
        assert!(*r >= f * (1.0 - 1e-9), "{r} below {f}");
        if f < 0.5 * cutoff {
            assert!((r - f) / f <= 1e-3, "{r} vs {f}");
            compared += 1;
        }
    }
    assert!(compared >= 6);
    // Rigid-body motion is still exact at every station.
    let g = body.point_motion(2, 0.5);
    let d = attachments()[2].point_at(0.5) - body.mass.cog_m;
    let mut rigid = DMatrix::<f64>::identity(6, 6);
    rigid
        .view_mut((0, 3), (3, 3))
        .copy_from(&(-d.cross_matrix()));
    assert!((g.columns(0, 6) - &rigid).amax() < 1e-9);
}
