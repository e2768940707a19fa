//! The ANSYS route of docs/machine-file.md ("Getting the matrices out of an FE program"):
//! `*EXPORT,…,MMF` Matrix Market files and the `.mapping` file of `HBMAT`, written here by hand
//! in those programs' layouts for a beam of two Euler–Bernoulli elements whose K and M this
//! test builds from the textbook element matrices. ANSYS numbers its equations in its own
//! (reordered) sequence, so the files list the DOFs in a shuffled order given by the mapping
//! file. The import must give back exactly the hand-built matrices under that mapping, the
//! beam's mass properties, and the cantilever deflection P L³ / (3 E I) (exact for Hermite
//! elements under a tip load).

mod fe_common;

use eij::fe::{DofKind, FeModel};
use fe_common::{dense, static_solve};
use nalgebra::{DMatrix, DVector, Vector3};
use std::path::{Path, PathBuf};

/// Steel bar along x, 2 elements of 0.4 m.
const E: f64 = 2.1e11;
const G: f64 = 8.1e10;
const RHO: f64 = 7850.0;
const A: f64 = 4.0e-3;
const IY: f64 = 2.0e-6;
const IZ: f64 = 3.0e-6;
const J: f64 = 4.0e-6;
const LE: f64 = 0.4;
/// Node numbers as an FE program gives them (not 1, 2, 3).
const NODES: [u64; 3] = [101, 205, 307];

/// Global DOF index in node-major order: node `n` (0…2), `ux uy uz rx ry rz` (0…5).
fn g(n: usize, d: usize) -> usize {
    6 * n + d
}

/// The Hermite bending block of an element of length `a` in (w₁, θ₁, w₂, θ₂) with θ = dw/dx:
/// stiffness (times EI/a³) and consistent mass (times ρAa/420).
fn hermite(a: f64) -> ([[f64; 4]; 4], [[f64; 4]; 4]) {
    let k = [
        [12.0, 6.0 * a, -12.0, 6.0 * a],
        [6.0 * a, 4.0 * a * a, -6.0 * a, 2.0 * a * a],
        [-12.0, -6.0 * a, 12.0, -6.0 * a],
        [6.0 * a, 2.0 * a * a, -6.0 * a, 4.0 * a * a],
    ];
    let m = [
        [156.0, 22.0 * a, 54.0, -13.0 * a],
        [22.0 * a, 4.0 * a * a, 13.0 * a, -3.0 * a * a],
        [54.0, 13.0 * a, 156.0, -22.0 * a],
        [-13.0 * a, -3.0 * a * a, -22.0 * a, 4.0 * a * a],
    ];
    (k, m)
}

/// The 18 × 18 K and M of the two-element beam along x, node-major, assembled from the element
/// matrices of a 3D Euler–Bernoulli frame element (consistent mass, torsional inertia
/// ρ(I_y + I_z) per length, no rotary inertia of the sections).
fn beam_matrices() -> (DMatrix<f64>, DMatrix<f64>) {
    let (mut k, mut m) = (DMatrix::zeros(18, 18), DMatrix::zeros(18, 18));
    let a = LE;
    let (hk, hm) = hermite(a);
    for e in 0..2 {
        let ends = [e, e + 1];
        // Bending: (uy, rz) with rz = duy/dx, EI_z; (uz, ry) with ry = −duz/dx, EI_y (the
        // rotation's sign flips the couplings).
        for (w, t, sign, ei) in [(1, 5, 1.0, E * IZ), (2, 4, -1.0, E * IY)] {
            let dofs = [(ends[0], w), (ends[0], t), (ends[1], w), (ends[1], t)];
            let s = [1.0, sign, 1.0, sign];
            for i in 0..4 {
                for j in 0..4 {
                    let (r, c) = (g(dofs[i].0, dofs[i].1), g(dofs[j].0, dofs[j].1));
                    k[(r, c)] += ei / a.powi(3) * hk[i][j] * s[i] * s[j];
                    m[(r, c)] += RHO * A * a / 420.0 * hm[i][j] * s[i] * s[j];
                }
            }
        }
        // Axial (ux) and torsion (rx): linear elements.
        for (d, stiff, inertia) in [(0, E * A, RHO * A), (3, G * J, RHO * (IY + IZ))] {
            for (i, p) in ends.iter().enumerate() {
                for (j, q) in ends.iter().enumerate() {
                    let same = i == j;
                    k[(g(*p, d), g(*q, d))] += stiff / a * if same { 1.0 } else { -1.0 };
                    m[(g(*p, d), g(*q, d))] += inertia * a / 6.0 * if same { 2.0 } else { 1.0 };
                }
            }
        }
    }
    (k, m)
}

/// A value as ANSYS prints it: 16 significant digits, an upper-case exponent with its sign.
fn fortran(v: f64) -> String {
    let s = format!("{v:.15E}");
    let (mantissa, exponent) = s.split_once('E').unwrap();
    format!("{mantissa}E{:+03}", exponent.parse::<i32>().unwrap())
}

const LABELS: [&str; 6] = ["UX", "UY", "UZ", "ROTX", "ROTY", "ROTZ"];

/// ANSYS's equation order: a fixed shuffle of the 18 node-major DOFs (equation e holds DOF
/// `order[e]`).
fn order() -> Vec<usize> {
    (0..18).map(|e| (7 * e + 5) % 18).collect()
}

/// A matrix in the layout of `*EXPORT,…,MMF`: the Matrix Market banner, a block of `%` lines,
/// right-aligned size and entry fields, the lower triangle column by column, values with an
/// upper-case exponent.
fn mmf(a: &DMatrix<f64>, order: &[usize]) -> String {
    let n = order.len();
    let mut entries = Vec::new();
    for c in 0..n {
        for r in c..n {
            let v = a[(order[r], order[c])];
            if v != 0.0 {
                entries.push(format!("{:>8} {:>8}  {:>24}\n", r + 1, c + 1, fortran(v)));
            }
        }
    }
    let mut t = String::from("%%MatrixMarket matrix coordinate real symmetric\n");
    t += "%=================================================================================\n";
    t += "%\n% This ASCII file is in MatrixMarket format\n%\n";
    t += "%=================================================================================\n";
    t += &format!("{:>8} {:>8} {:>8}\n", n, n, entries.len());
    t + &entries.concat()
}

/// The `.mapping` file of `HBMAT,…,Mapping = YES`: `Matrix Eqn  Node  DOF`, then one line per
/// equation.
fn mapping(order: &[usize]) -> String {
    let mut t = String::from(" Matrix Eqn   Node   DOF\n");
    for (e, &d) in order.iter().enumerate() {
        t += &format!("{:>11} {:>6} {:>5}\n", e + 1, NODES[d / 6], LABELS[d % 6]);
    }
    t
}

fn folder(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("eij-ansys-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Writes the four files and returns their paths (M, K, mapping, nodes).
fn write_set(dir: &Path, k: &DMatrix<f64>, m: &DMatrix<f64>) -> [PathBuf; 4] {
    let order = order();
    let files = ["bar-M.mtx", "bar-K.mtx", "bar.mapping", "bar-nodes.csv"].map(|f| dir.join(f));
    std::fs::write(&files[0], mmf(m, &order)).unwrap();
    std::fs::write(&files[1], mmf(k, &order)).unwrap();
    std::fs::write(&files[2], mapping(&order)).unwrap();
    let mut nodes = String::from("node,x_m,y_m,z_m\n");
    for (i, id) in NODES.iter().enumerate() {
        nodes += &format!("{id},{},0.0,0.0\n", i as f64 * LE);
    }
    std::fs::write(&files[3], nodes).unwrap();
    files
}

fn read(f: &[PathBuf; 4]) -> Result<FeModel, String> {
    FeModel::from_files(&f[0], &f[1], &f[2], &f[3]).map_err(|e| e.to_string())
}

/// The node-major index of matrix row `r` of the imported model.
fn node_major(model: &FeModel, r: usize) -> usize {
    let (i, kind) = model.dofs[r];
    let n = NODES
        .iter()
        .position(|&id| id == model.nodes[i].id)
        .unwrap();
    g(n, kind.index())
}

#[test]
fn an_ansys_export_reads_as_the_hand_built_beam() {
    let (k, m) = beam_matrices();
    let dir = folder("beam");
    let f = write_set(&dir, &k, &m);
    let model = read(&f).unwrap();
    assert_eq!(model.n_dofs(), 18);
    // Row r of the file is equation r + 1: the mapping's node and label.
    let order = order();
    for (r, &d) in order.iter().enumerate() {
        assert_eq!(node_major(&model, r), d, "equation {}", r + 1);
        assert_eq!(model.dofs[r].1, DofKind::ALL[d % 6]);
    }
    // Every entry, both triangles, at 15 significant digits.
    let (kd, md) = (dense(&model.stiffness), dense(&model.mass));
    for r in 0..18 {
        for c in 0..18 {
            let (a, b) = (node_major(&model, r), node_major(&model, c));
            for (got, want, what) in [(kd[(r, c)], k[(a, b)], "K"), (md[(r, c)], m[(a, b)], "M")] {
                assert!(
                    (got - want).abs() <= 2e-15 * want.abs(),
                    "{what}({r}, {c}) = {got} vs {want}"
                );
            }
        }
    }

    // Mass properties against the bar: m = ρAL, COG at L/2; about it J_xx = ρ(I_y + I_z)L and
    // J_yy = J_zz = ρAL³/12 (the consistent mass holds a rigid rotation exactly).
    let l = 2.0 * LE;
    let props = model.mass_properties().unwrap();
    let mass = RHO * A * l;
    assert!(
        (props.mass_kg - mass).abs() <= 1e-12 * mass,
        "{}",
        props.mass_kg
    );
    assert!((props.cog_m - Vector3::new(LE, 0.0, 0.0)).norm() <= 1e-12);
    let j = props.inertia_kg_m2;
    let want = [
        RHO * (IY + IZ) * l,
        mass * l * l / 12.0,
        mass * l * l / 12.0,
    ];
    for (d, w) in want.iter().enumerate() {
        assert!(
            (j[(d, d)] - w).abs() <= 1e-10 * w,
            "J{d}{d} = {} vs {w}",
            j[(d, d)]
        );
    }

    // A cantilever held at node 101 with a tip load at node 307: P L³ / (3 E I) in both
    // bending planes, P L / (E A) axially, T L / (G J) in torsion — on the imported matrices,
    // in the file's equation order.
    let fixed: Vec<usize> = (0..18).filter(|&r| node_major(&model, r) < 6).collect();
    let row = |d: usize| (0..18).find(|&r| node_major(&model, r) == g(2, d)).unwrap();
    let cases = [
        (0, 1.0e4, l / (E * A)),
        (1, 1.0e3, l.powi(3) / (3.0 * E * IZ)),
        (2, 1.0e3, l.powi(3) / (3.0 * E * IY)),
        (3, 1.0e2, l / (G * J)),
    ];
    for (d, load, per_unit) in cases {
        let mut f = DVector::zeros(18);
        f[row(d)] = load;
        let u = static_solve(&kd, &f, &fixed);
        let want = load * per_unit;
        assert!(
            (u[row(d)] - want).abs() <= 1e-9 * want,
            "tip {} = {} vs {want}",
            LABELS[d],
            u[row(d)]
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_mapping_file_out_of_order_or_malformed_names_its_line() {
    let (k, m) = beam_matrices();
    let dir = folder("bad");
    let f = write_set(&dir, &k, &m);
    let good = std::fs::read_to_string(&f[2]).unwrap();
    let lines: Vec<&str> = good.lines().collect();
    for (tag, text, needles) in [
        (
            "skip",
            // Equation 3 left out: 4 follows 2.
            [&lines[..3], &lines[4..]].concat().join("\n"),
            vec!["bar.mapping: line 4", "equation `4` where 3 is next"],
        ),
        (
            "label",
            good.replacen(" ROTX\n", " TEMP\n", 1),
            vec!["bar.mapping: line", "dof `TEMP` is none of"],
        ),
        (
            "node",
            good.replacen("   205 ", "   999 ", 1),
            vec!["bar.mapping: line", "node 999 is not in the node file"],
        ),
        (
            "short",
            lines[..18].join("\n"),
            vec!["bar.mapping", "17 DOF rows, but the matrices are 18×18"],
        ),
    ] {
        std::fs::write(&f[2], text).unwrap();
        let e = read(&f).unwrap_err();
        assert!(!e.contains('\n'), "{tag}: {e}");
        for n in needles {
            assert!(e.contains(n), "{tag}: {n} not in: {e}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
