//! The Timoshenko beam that `[body.beam]` builds, against beam theory: cantilever tip
//! deflection with shear, first bending and torsion frequencies of a slender and a stocky beam
//! (Euler–Bernoulli, Timoshenko), and a two-element beam assembled by hand from the textbook
//! element matrices (Przemieniecki, shear-deformable beam).

mod fe_common;
use eij::fe::{lowest_modes, Beam, FeModel};
use fe_common::{dense, held_eigenvalues, hz, static_solve, sub};
use nalgebra::{DMatrix, DVector};
use std::f64::consts::PI;

const E: f64 = 2.1e11;
const G: f64 = 8.1e10;
const RHO: f64 = 7850.0;
const KAPPA: f64 = 5.0 / 6.0;

/// A beam along `to − from` with a b × h rectangle (b along local y).
fn beam(from: [f64; 3], to: [f64; 3], y_axis: [f64; 3], b: f64, h: f64, elements: usize) -> Beam {
    Beam {
        from_m: from,
        to_m: to,
        elements,
        y_axis,
        area_m2: b * h,
        iy_m4: b * h.powi(3) / 12.0,
        iz_m4: h * b.powi(3) / 12.0,
        torsion_m4: 0.8 * (b * h.powi(3) + h * b.powi(3)) / 12.0,
        shear_factor: KAPPA,
        youngs_modulus_pa: E,
        shear_modulus_pa: G,
        density_kg_m3: RHO,
    }
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn cantilever_tip_deflection_with_shear_in_both_planes() {
    // Along machine z, local y = machine x: a force along x bends about local z (I_z).
    let (b, h, l) = (0.12, 0.08, 0.9);
    let bm = beam(
        [0.0, 0.6, -0.1],
        [0.0, 0.6, -0.1 + l],
        [1.0, 0.0, 0.0],
        b,
        h,
        6,
    );
    let model = FeModel::beam(&bm).unwrap();
    let k = dense(&model.stiffness);
    let n = model.n_dofs();
    let tip = n - 6;
    for (dir, i) in [(0usize, bm.iz_m4), (1, bm.iy_m4)] {
        let p = 1.0e4;
        let mut f = DVector::zeros(n);
        f[tip + dir] = p;
        let u = static_solve(&k, &f, &(0..6).collect::<Vec<_>>());
        let expected = p * l.powi(3) / (3.0 * E * i) + p * l / (KAPPA * G * b * h);
        assert!(
            rel(u[tip + dir], expected) < 1e-9,
            "dir {dir}: {} vs {expected}",
            u[tip + dir]
        );
        // Tip rotation of a cantilever under a tip force: P L² / (2EI), about the axis ⟂ both.
        let rot = if dir == 0 { tip + 4 } else { tip + 3 };
        let sign = if dir == 0 { 1.0 } else { -1.0 };
        assert!(rel(sign * u[rot], p * l * l / (2.0 * E * i)) < 1e-9);
    }
    // Torsion: θ = T L / (G J).
    let mut f = DVector::zeros(n);
    f[tip + 5] = 500.0;
    let u = static_solve(&k, &f, &(0..6).collect::<Vec<_>>());
    assert!(rel(u[tip + 5], 500.0 * l / (G * bm.torsion_m4)) < 1e-9);
}

/// Nearest value of `list` to `x`, relative distance.
fn nearest(list: &[f64], x: f64) -> f64 {
    list.iter()
        .map(|v| rel(*v, x))
        .fold(f64::INFINITY, f64::min)
}

/// Lowest frequencies (Hz) of the beam held at `fixed` (dense solve).
fn frequencies(model: &FeModel, fixed: &[usize]) -> Vec<f64> {
    let keep: Vec<usize> = (0..model.n_dofs()).filter(|i| !fixed.contains(i)).collect();
    let k = sub(&dense(&model.stiffness), &keep);
    let m = sub(&dense(&model.mass), &keep);
    held_eigenvalues(&k, &m).into_iter().map(hz).collect()
}

#[test]
fn slender_cantilever_bending_and_torsion_frequencies() {
    let (b, h, l) = (0.05, 0.04, 2.5);
    // 80 elements: 480 free DOFs, enough for the sparse path to run Lanczos, not its dense fallback.
    let bm = beam([0.0, 0.0, 0.0], [l, 0.0, 0.0], [0.0, 1.0, 0.0], b, h, 80);
    let model = FeModel::beam(&bm).unwrap();
    let f = frequencies(&model, &(0..6).collect::<Vec<_>>());
    let beta = 1.875_104_068_711_96_f64;
    let a = b * h;
    for i in [bm.iy_m4, bm.iz_m4] {
        let eb = beta * beta * (E * i / (RHO * a * l.powi(4))).sqrt() / (2.0 * PI);
        assert!(nearest(&f, eb) < 5e-3, "bending {eb} Hz not in {f:?}");
    }
    let ip = bm.iy_m4 + bm.iz_m4;
    let torsion = PI / (2.0 * l) * (G * bm.torsion_m4 / (RHO * ip)).sqrt() / (2.0 * PI);
    assert!(
        nearest(&f, torsion) < 5e-3,
        "torsion {torsion} Hz not in {f:?}"
    );
    // The sparse Lanczos path finds the same lowest modes as the dense solve.
    let modes = lowest_modes(&model, &(0..6).collect::<Vec<_>>(), 0.0, 6).unwrap();
    for (x, y) in modes.frequencies_hz().iter().zip(&f) {
        assert!(rel(*x, *y) < 1e-9, "{x} vs {y}");
    }
}

/// First frequency of a simply supported Timoshenko beam, Hz: the smaller root ω² of
/// EI k⁴ − ρAω² − ρI(1 + E/κG) k²ω² + ρ²I ω⁴/(κG) = 0, k = π/L.
fn timoshenko_simply_supported(i: f64, a: f64, l: f64) -> f64 {
    let k = PI / l;
    let qa = RHO * RHO * i / (KAPPA * G);
    let qb = -(RHO * a + RHO * i * (1.0 + E / (KAPPA * G)) * k * k);
    let qc = E * i * k.powi(4);
    let w2 = (-qb - (qb * qb - 4.0 * qa * qc).sqrt()) / (2.0 * qa);
    w2.sqrt() / (2.0 * PI)
}

#[test]
fn stocky_simply_supported_beam_matches_timoshenko_not_euler_bernoulli() {
    let (b, h, l) = (0.25, 0.2, 1.0);
    let ne = 20;
    let bm = beam([0.0, 0.0, 0.0], [l, 0.0, 0.0], [0.0, 1.0, 0.0], b, h, ne);
    let model = FeModel::beam(&bm).unwrap();
    let last = 6 * ne;
    // Pinned at both ends in y and z, axial and torsion held at the start.
    let fixed = vec![0, 1, 2, 3, last + 1, last + 2];
    let f = frequencies(&model, &fixed);
    let a = b * h;
    for i in [bm.iy_m4, bm.iz_m4] {
        let timo = timoshenko_simply_supported(i, a, l);
        let eb = PI * PI / (l * l) * (E * i / (RHO * a)).sqrt() / (2.0 * PI);
        assert!(
            eb / timo > 1.04,
            "the beam must be stocky enough to tell the theories apart"
        );
        assert!(
            nearest(&f, timo) < 5e-3,
            "Timoshenko {timo} Hz not in {f:?}"
        );
        assert!(nearest(&f, eb) > 3e-2);
    }
}

/// Textbook shear-deformable element (Przemieniecki) for (v₁, θ₁, v₂, θ₂), θ = dv/dx.
fn textbook(l: f64, ei: f64, phi: f64, rho_a: f64, rho_i: f64) -> (DMatrix<f64>, DMatrix<f64>) {
    let c = ei / ((1.0 + phi) * l.powi(3));
    let k = DMatrix::from_row_slice(
        4,
        4,
        &[
            12.0,
            6.0 * l,
            -12.0,
            6.0 * l,
            6.0 * l,
            (4.0 + phi) * l * l,
            -6.0 * l,
            (2.0 - phi) * l * l,
            -12.0,
            -6.0 * l,
            12.0,
            -6.0 * l,
            6.0 * l,
            (2.0 - phi) * l * l,
            -6.0 * l,
            (4.0 + phi) * l * l,
        ],
    ) * c;
    let d = (1.0 + phi).powi(2);
    let (m11, m12) = (
        13.0 / 35.0 + 7.0 / 10.0 * phi + phi * phi / 3.0,
        (11.0 / 210.0 + 11.0 / 120.0 * phi + phi * phi / 24.0) * l,
    );
    let (m13, m14) = (
        9.0 / 70.0 + 3.0 / 10.0 * phi + phi * phi / 6.0,
        -(13.0 / 420.0 + 3.0 / 40.0 * phi + phi * phi / 24.0) * l,
    );
    let (m22, m24) = (
        (1.0 / 105.0 + phi / 60.0 + phi * phi / 120.0) * l * l,
        -(1.0 / 140.0 + phi / 60.0 + phi * phi / 120.0) * l * l,
    );
    let mt = DMatrix::from_row_slice(
        4,
        4,
        &[
            m11, m12, m13, m14, m12, m22, -m14, m24, m13, -m14, m11, -m12, m14, m24, -m12, m22,
        ],
    ) * (rho_a * l / d);
    let (r11, r12) = (6.0 / 5.0, (1.0 / 10.0 - phi / 2.0) * l);
    let (r22, r24) = (
        (2.0 / 15.0 + phi / 6.0 + phi * phi / 3.0) * l * l,
        (-1.0 / 30.0 - phi / 6.0 + phi * phi / 6.0) * l * l,
    );
    let mr = DMatrix::from_row_slice(
        4,
        4,
        &[
            r11, r12, -r11, r12, r12, r22, -r12, r24, -r11, -r12, r11, -r12, r12, r24, -r12, r22,
        ],
    ) * (rho_i / (l * d));
    (k, mt + mr)
}

#[test]
fn two_element_beam_equals_hand_assembly() {
    let (b, h, le) = (0.1, 0.06, 0.3);
    let bm = beam(
        [0.0, 0.0, 0.0],
        [2.0 * le, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        b,
        h,
        2,
    );
    let model = FeModel::beam(&bm).unwrap();
    let (a, asr) = (b * h, KAPPA * b * h);
    let mut k = DMatrix::<f64>::zeros(18, 18);
    let mut m = DMatrix::<f64>::zeros(18, 18);
    for e in 0..2 {
        let o = 6 * e;
        let mut put = |dofs: &[usize], ke: &DMatrix<f64>, me: &DMatrix<f64>| {
            for (p, &dp) in dofs.iter().enumerate() {
                for (q, &dq) in dofs.iter().enumerate() {
                    k[(o + dp, o + dq)] += ke[(p, q)];
                    m[(o + dp, o + dq)] += me[(p, q)];
                }
            }
        };
        let bar = |s: f64, mm: f64| {
            (
                DMatrix::from_row_slice(2, 2, &[s, -s, -s, s]),
                DMatrix::from_row_slice(2, 2, &[mm / 3.0, mm / 6.0, mm / 6.0, mm / 3.0]),
            )
        };
        let (ka, ma) = bar(E * a / le, RHO * a * le);
        put(&[0, 6], &ka, &ma);
        let (kt, mt) = bar(G * bm.torsion_m4 / le, RHO * (bm.iy_m4 + bm.iz_m4) * le);
        put(&[3, 9], &kt, &mt);
        // x–y plane (v, θz) with I_z.
        let phi = 12.0 * E * bm.iz_m4 / (G * asr * le * le);
        let (kb, mb) = textbook(le, E * bm.iz_m4, phi, RHO * a, RHO * bm.iz_m4);
        put(&[1, 5, 7, 11], &kb, &mb);
        // x–z plane (w, θy), θy = −dw/dx: flip the rotation signs.
        let phi = 12.0 * E * bm.iy_m4 / (G * asr * le * le);
        let (kb, mb) = textbook(le, E * bm.iy_m4, phi, RHO * a, RHO * bm.iy_m4);
        let s = DMatrix::from_diagonal(&DVector::from_row_slice(&[1.0, -1.0, 1.0, -1.0]));
        put(&[2, 4, 8, 10], &(&s * kb * &s), &(&s * mb * &s));
    }
    let (kf, mf) = (dense(&model.stiffness), dense(&model.mass));
    assert!(
        (&kf - &k).amax() <= 1e-12 * k.amax(),
        "K differs by {}",
        (&kf - &k).amax()
    );
    assert!(
        (&mf - &m).amax() <= 1e-12 * m.amax(),
        "M differs by {}",
        (&mf - &m).amax()
    );
}

#[test]
fn beam_mass_properties_are_those_of_the_bar() {
    let (b, h, l) = (0.2, 0.3, 1.2);
    let bm = beam([0.1, 0.6, -0.1], [0.1, 0.6, 1.1], [1.0, 0.0, 0.0], b, h, 8);
    let model = FeModel::beam(&bm).unwrap();
    let mp = model.mass_properties().unwrap();
    let mass = RHO * b * h * l;
    assert!(rel(mp.mass_kg, mass) < 1e-12);
    assert!((mp.cog_m - nalgebra::Vector3::new(0.1, 0.6, 0.5)).norm() < 1e-12);
    // Slender-rod inertia m L²/12 about x and y plus the section's own; about z (the axis) ρ Ip L.
    let ip = RHO * (bm.iy_m4 + bm.iz_m4) * l;
    assert!(rel(mp.inertia_kg_m2[(2, 2)], ip) < 1e-9);
    // About machine x (local y): m L²/12 + ρ I_y L (rotary inertia of the section).
    assert!(
        rel(
            mp.inertia_kg_m2[(0, 0)],
            mass * l * l / 12.0 + RHO * bm.iy_m4 * l
        ) < 1e-9
    );
    model.check_free().unwrap();
}
