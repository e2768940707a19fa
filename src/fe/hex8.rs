//! A rectangular block of 8-node hexahedral solid elements (trilinear, 2×2×2 Gauss points,
//! consistent mass): the solid models of the tests, benchmarks and examples (a column as an FE
//! program would mesh it, 3 DOF per node).

use super::{mtx, DofKind, FeError, FeModel, Node};
use nalgebra::{SMatrix, Vector3};

/// A block from `origin` to `origin + size_m`, `divisions` elements along x, y, z, of one
/// isotropic material. Nodes are numbered 1, 2, … with x running fastest, then y, then z.
#[derive(Debug, Clone, PartialEq)]
pub struct Hex8Block {
    /// Lowest corner, m.
    pub origin_m: [f64; 3],
    /// Edge lengths, m.
    pub size_m: [f64; 3],
    /// Elements along x, y, z.
    pub divisions: [usize; 3],
    /// Young's modulus, Pa.
    pub youngs_modulus_pa: f64,
    /// Poisson's ratio.
    pub poisson_ratio: f64,
    /// Density, kg/m³.
    pub density_kg_m3: f64,
}

type M24 = SMatrix<f64, 24, 24>;

/// Element stiffness and mass of an a × b × c brick, DOFs (ux uy uz) per corner, corners in the
/// order (0,0,0), (1,0,0), (0,1,0), (1,1,0), (0,0,1), … (x fastest).
fn brick(h: [f64; 3], e: f64, nu: f64, rho: f64) -> (M24, M24) {
    let lam = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let mu = e / (2.0 * (1.0 + nu));
    let mut d = SMatrix::<f64, 6, 6>::zeros();
    for i in 0..3 {
        for j in 0..3 {
            d[(i, j)] = lam;
        }
        d[(i, i)] = lam + 2.0 * mu;
        d[(i + 3, i + 3)] = mu;
    }
    let g = 1.0 / 3f64.sqrt();
    let det = h[0] * h[1] * h[2] / 8.0;
    let mut k = M24::zeros();
    let mut m = M24::zeros();
    for gp in 0..8 {
        let xi = [
            if gp & 1 == 0 { -g } else { g },
            if gp & 2 == 0 { -g } else { g },
            if gp & 4 == 0 { -g } else { g },
        ];
        let mut b = SMatrix::<f64, 6, 24>::zeros();
        let mut n = [0.0; 8];
        for (c, nc) in n.iter_mut().enumerate() {
            let s = [
                if c & 1 == 0 { -1.0 } else { 1.0 },
                if c & 2 == 0 { -1.0 } else { 1.0 },
                if c & 4 == 0 { -1.0 } else { 1.0 },
            ];
            let f = |a: usize| 1.0 + s[a] * xi[a];
            *nc = f(0) * f(1) * f(2) / 8.0;
            // dN/dx_a = (2/h_a) dN/dξ_a.
            let dn = [
                s[0] * f(1) * f(2) / 8.0 * 2.0 / h[0],
                s[1] * f(0) * f(2) / 8.0 * 2.0 / h[1],
                s[2] * f(0) * f(1) / 8.0 * 2.0 / h[2],
            ];
            let col = 3 * c;
            b[(0, col)] = dn[0];
            b[(1, col + 1)] = dn[1];
            b[(2, col + 2)] = dn[2];
            b[(3, col)] = dn[1];
            b[(3, col + 1)] = dn[0];
            b[(4, col + 1)] = dn[2];
            b[(4, col + 2)] = dn[1];
            b[(5, col)] = dn[2];
            b[(5, col + 2)] = dn[0];
        }
        k += det * b.transpose() * d * b;
        for p in 0..8 {
            for q in 0..8 {
                for a in 0..3 {
                    m[(3 * p + a, 3 * q + a)] += det * rho * n[p] * n[q];
                }
            }
        }
    }
    (k, m)
}

impl Hex8Block {
    /// Number of nodes along x, y, z.
    pub(crate) fn node_counts(&self) -> [usize; 3] {
        self.divisions.map(|d| d + 1)
    }

    /// Number of DOFs (3 per node).
    pub fn n_dofs(&self) -> usize {
        3 * self.node_counts().iter().product::<usize>()
    }
}

impl FeModel {
    /// Meshes a block of hexahedral solid elements (see [`Hex8Block`]).
    pub fn hex8_block(block: &Hex8Block) -> Result<FeModel, FeError> {
        let bad = |m: String| Err(FeError::file("hex8 block", m));
        if block.divisions.contains(&0) || block.size_m.iter().any(|s| !(*s > 0.0)) {
            return bad("divisions and sizes must be positive".into());
        }
        let material = block.youngs_modulus_pa > 0.0
            && block.density_kg_m3 > 0.0
            && block.poisson_ratio > -1.0
            && block.poisson_ratio < 0.5;
        if !material {
            return bad("E, density > 0 and −1 < ν < 0.5 needed".into());
        }
        let [nx, ny, nz] = block.node_counts();
        if block.n_dofs() > u32::MAX as usize {
            return bad("too many nodes".into());
        }
        let h: [f64; 3] = std::array::from_fn(|a| block.size_m[a] / block.divisions[a] as f64);
        let (ke, me) = brick(
            h,
            block.youngs_modulus_pa,
            block.poisson_ratio,
            block.density_kg_m3,
        );
        let node = |i: usize, j: usize, k: usize| i + nx * (j + ny * k);
        let [ex, ey, ez] = block.divisions;
        let per = ex * ey * ez * 300;
        let (mut tk, mut tm) = (Vec::with_capacity(per), Vec::with_capacity(per));
        for k in 0..ez {
            for j in 0..ey {
                for i in 0..ex {
                    let corners: [usize; 8] = std::array::from_fn(|c| {
                        node(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1))
                    });
                    for p in 0..24 {
                        for q in 0..24 {
                            let (r, c) = (3 * corners[p / 3] + p % 3, 3 * corners[q / 3] + q % 3);
                            if r >= c {
                                tk.push((r as u32, c as u32, ke[(p, q)]));
                                tm.push((r as u32, c as u32, me[(p, q)]));
                            }
                        }
                    }
                }
            }
        }
        let o = Vector3::from(block.origin_m);
        let mut nodes = Vec::with_capacity(nx * ny * nz);
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    nodes.push(Node {
                        id: node(i, j, k) as u64 + 1,
                        position: o + Vector3::new(
                            i as f64 * h[0],
                            j as f64 * h[1],
                            k as f64 * h[2],
                        ),
                    });
                }
            }
        }
        let dofs: Vec<(u64, DofKind)> = nodes
            .iter()
            .flat_map(|p| [DofKind::Ux, DofKind::Uy, DofKind::Uz].map(|d| (p.id, d)))
            .collect();
        let n = dofs.len();
        FeModel::new(
            "hex8 block",
            mtx::from_lower_triplets(n, tm),
            mtx::from_lower_triplets(n, tk),
            nodes,
            &dofs,
        )
    }
}
