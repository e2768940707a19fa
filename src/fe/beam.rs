//! A straight 3D Timoshenko beam (`[body.beam]`): axial, torsion and bending in two planes with
//! shear deformation and rotary inertia, consistent mass, 6 DOF per node.
//!
//! Bending uses the interdependent interpolation element (cubic deflection, quadratic section
//! rotation, constant shear strain; Friedman & Kosmatka 1993), which is exact for a statically
//! loaded Timoshenko beam: with ξ = x/L and Φ = 12EI/(κGA L²),
//! deflection N_v = [(2ξ³−3ξ²−Φξ+1+Φ), L(ξ³−(2+Φ/2)ξ²+(1+Φ/2)ξ), −(2ξ³−3ξ²−Φξ), L(ξ³−(1−Φ/2)ξ²−(Φ/2)ξ)]/(1+Φ),
//! rotation N_ψ = [6(ξ²−ξ)/L, 3ξ²−(4+Φ)ξ+1+Φ, −6(ξ²−ξ)/L, 3ξ²−(2−Φ)ξ]/(1+Φ);
//! K = ∫ EI N_ψ'ᵀN_ψ' + κGA (N_v'−N_ψ)ᵀ(N_v'−N_ψ) dx and M = ∫ ρA N_vᵀN_v + ρI N_ψᵀN_ψ dx, integrated
//! exactly by 4-point Gauss quadrature. Axial and torsion: linear elements with consistent mass
//! (torsional inertia ρ(I_y + I_z) per length).

use super::{mtx, DofKind, FeError, FeModel, Node};
use nalgebra::{Matrix3, SMatrix, Vector3};

/// A straight beam of constant section, in machine coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct Beam {
    /// Start point, m.
    pub from_m: [f64; 3],
    /// End point, m.
    pub to_m: [f64; 3],
    /// Number of elements (nodes = elements + 1, numbered 1, 2, … from the start).
    pub elements: usize,
    /// The section's local y direction (made orthogonal to the axis).
    pub y_axis: [f64; 3],
    /// Section area, m².
    pub area_m2: f64,
    /// Second moment of area about local y, m⁴ (bending in the local x–z plane).
    pub iy_m4: f64,
    /// Second moment of area about local z, m⁴ (bending in the local x–y plane).
    pub iz_m4: f64,
    /// Torsion constant, m⁴.
    pub torsion_m4: f64,
    /// Shear area / area (κ).
    pub shear_factor: f64,
    /// Young's modulus E, Pa.
    pub youngs_modulus_pa: f64,
    /// Shear modulus G, Pa.
    pub shear_modulus_pa: f64,
    /// Density, kg/m³.
    pub density_kg_m3: f64,
}

type M4 = SMatrix<f64, 4, 4>;
type M12 = SMatrix<f64, 12, 12>;

/// Gauss–Legendre points and weights on [0, 1], 4 points (exact to degree 7).
const GAUSS4: [(f64, f64); 4] = [
    (0.069_431_844_202_973_7, 0.173_927_422_568_726_9),
    (0.330_009_478_207_571_9, 0.326_072_577_431_273_1),
    (0.669_990_521_792_428_1, 0.326_072_577_431_273_1),
    (0.930_568_155_797_026_3, 0.173_927_422_568_726_9),
];

/// Stiffness and mass of bending in one plane for (v₁, ψ₁, v₂, ψ₂), ψ = the section rotation
/// that equals dv/dx without shear (module doc).
fn bending(l: f64, ei: f64, kga: f64, rho_a: f64, rho_i: f64) -> (M4, M4) {
    let phi = 12.0 * ei / (kga * l * l);
    let d = 1.0 + phi;
    let mut k = M4::zeros();
    let mut m = M4::zeros();
    for (xi, w) in GAUSS4 {
        let (x2, x3) = (xi * xi, xi * xi * xi);
        let nv = nalgebra::Vector4::new(
            (2.0 * x3 - 3.0 * x2 - phi * xi + 1.0 + phi) / d,
            l * (x3 - (2.0 + phi / 2.0) * x2 + (1.0 + phi / 2.0) * xi) / d,
            -(2.0 * x3 - 3.0 * x2 - phi * xi) / d,
            l * (x3 - (1.0 - phi / 2.0) * x2 - (phi / 2.0) * xi) / d,
        );
        // d/dx = (1/L) d/dξ.
        let dnv = nalgebra::Vector4::new(
            (6.0 * x2 - 6.0 * xi - phi) / (d * l),
            (3.0 * x2 - (4.0 + phi) * xi + 1.0 + phi / 2.0) / d,
            -(6.0 * x2 - 6.0 * xi - phi) / (d * l),
            (3.0 * x2 - (2.0 - phi) * xi - phi / 2.0) / d,
        );
        let npsi = nalgebra::Vector4::new(
            6.0 * (x2 - xi) / (d * l),
            (3.0 * x2 - (4.0 + phi) * xi + 1.0 + phi) / d,
            -6.0 * (x2 - xi) / (d * l),
            (3.0 * x2 - (2.0 - phi) * xi) / d,
        );
        let dnpsi = nalgebra::Vector4::new(
            6.0 * (2.0 * xi - 1.0) / (d * l * l),
            (6.0 * xi - 4.0 - phi) / (d * l),
            -6.0 * (2.0 * xi - 1.0) / (d * l * l),
            (6.0 * xi - 2.0 + phi) / (d * l),
        );
        let gamma = dnv - npsi;
        let wl = w * l;
        k += wl * (ei * dnpsi * dnpsi.transpose() + kga * gamma * gamma.transpose());
        m += wl * (rho_a * nv * nv.transpose() + rho_i * npsi * npsi.transpose());
    }
    (k, m)
}

impl Beam {
    fn check(&self) -> Result<(Vector3<f64>, Matrix3<f64>), FeError> {
        let err = |m: String| FeError::file("beam", m);
        let positive = [
            ("area_m2", self.area_m2),
            ("iy_m4", self.iy_m4),
            ("iz_m4", self.iz_m4),
            ("torsion_m4", self.torsion_m4),
            ("shear_factor", self.shear_factor),
            ("youngs_modulus_pa", self.youngs_modulus_pa),
            ("shear_modulus_pa", self.shear_modulus_pa),
            ("density_kg_m3", self.density_kg_m3),
        ];
        for (key, v) in positive {
            if !(v > 0.0 && v.is_finite()) {
                return Err(err(format!("{key} = {v}: must be a positive number")));
            }
        }
        if self.elements == 0 || self.elements > 100_000 {
            return Err(err(format!(
                "elements = {}: must be 1 … 100000",
                self.elements
            )));
        }
        let (a, b, y) = (
            Vector3::from(self.from_m),
            Vector3::from(self.to_m),
            Vector3::from(self.y_axis),
        );
        if a.iter()
            .chain(b.iter())
            .chain(y.iter())
            .any(|v| !v.is_finite())
        {
            return Err(err("from_m, to_m and y_axis must be finite".into()));
        }
        let axis = b - a;
        let length = axis.norm();
        if length == 0.0 {
            return Err(err("from_m and to_m are the same point".into()));
        }
        let ex = axis / length;
        let ey = y - ex * y.dot(&ex);
        if ey.norm() <= 1e-6 * y.norm().max(f64::MIN_POSITIVE) || y.norm() == 0.0 {
            return Err(err("y_axis is parallel to the beam (or zero)".into()));
        }
        let ey = ey.normalize();
        let ez = ex.cross(&ey);
        // Rows: the local axes in machine coordinates (local = Λ · machine).
        Ok((
            axis,
            Matrix3::from_rows(&[ex.transpose(), ey.transpose(), ez.transpose()]),
        ))
    }

    /// Element stiffness and mass in local coordinates, DOFs (u v w θx θy θz) per node.
    fn element(&self, l: f64) -> (M12, M12) {
        let (e, g, rho) = (
            self.youngs_modulus_pa,
            self.shear_modulus_pa,
            self.density_kg_m3,
        );
        let (a, kga) = (self.area_m2, self.shear_factor * self.area_m2 * g);
        let mut k = M12::zeros();
        let mut m = M12::zeros();
        let mut put = |idx: [usize; 2], kk: [[f64; 2]; 2], mm: [[f64; 2]; 2]| {
            for i in 0..2 {
                for j in 0..2 {
                    k[(idx[i], idx[j])] += kk[i][j];
                    m[(idx[i], idx[j])] += mm[i][j];
                }
            }
        };
        let bar = |s: f64, mass: f64| {
            (
                [[s, -s], [-s, s]],
                [[mass / 3.0, mass / 6.0], [mass / 6.0, mass / 3.0]],
            )
        };
        let (ka, ma) = bar(e * a / l, rho * a * l);
        put([0, 6], ka, ma);
        let (kt, mt) = bar(g * self.torsion_m4 / l, rho * (self.iy_m4 + self.iz_m4) * l);
        put([3, 9], kt, mt);
        // x–y plane: v with θz = +dv/dx; x–z plane: w with θy = −dw/dx (sign s).
        for (idx, i, s) in [
            ([1, 5, 7, 11], self.iz_m4, 1.0),
            ([2, 4, 8, 10], self.iy_m4, -1.0),
        ] {
            let (kb, mb) = bending(l, e * i, kga, rho * a, rho * i);
            let sign = [1.0, s, 1.0, s];
            for p in 0..4 {
                for q in 0..4 {
                    k[(idx[p], idx[q])] += sign[p] * sign[q] * kb[(p, q)];
                    m[(idx[p], idx[q])] += sign[p] * sign[q] * mb[(p, q)];
                }
            }
        }
        (k, m)
    }
}

impl FeModel {
    /// Builds the FE model of a beam: `elements` equal Timoshenko elements from `from_m` to
    /// `to_m`, nodes numbered 1 … elements + 1, six DOFs each (`ux uy uz rx ry rz` in machine
    /// axes).
    pub fn beam(beam: &Beam) -> Result<FeModel, FeError> {
        let (axis, lambda) = beam.check()?;
        let ne = beam.elements;
        let l = axis.norm() / ne as f64;
        let (kl, ml) = beam.element(l);
        let mut t = M12::zeros();
        for b in 0..4 {
            t.fixed_view_mut::<3, 3>(3 * b, 3 * b).copy_from(&lambda);
        }
        let kg = t.transpose() * kl * t;
        let mg = t.transpose() * ml * t;
        let n = 6 * (ne + 1);
        let mut tk = Vec::with_capacity(ne * 78);
        let mut tm = Vec::with_capacity(ne * 78);
        for el in 0..ne {
            for i in 0..12 {
                for j in 0..=i {
                    let (r, c) = ((6 * el + i) as u32, (6 * el + j) as u32);
                    tk.push((r, c, kg[(i, j)]));
                    tm.push((r, c, mg[(i, j)]));
                }
            }
        }
        let from = Vector3::from(beam.from_m);
        let nodes: Vec<Node> = (0..=ne)
            .map(|i| Node {
                id: i as u64 + 1,
                position: from + axis * (i as f64 / ne as f64),
            })
            .collect();
        let dofs: Vec<(u64, DofKind)> = nodes
            .iter()
            .flat_map(|p| DofKind::ALL.map(|k| (p.id, k)))
            .collect();
        FeModel::new(
            "beam",
            mtx::from_lower_triplets(n, tm),
            mtx::from_lower_triplets(n, tk),
            nodes,
            &dofs,
        )
    }
}
