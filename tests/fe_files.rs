//! FE models from exported files: Matrix Market variants as FE programs write them, and every
//! bad input of issue 27 item 6 as one error line naming the file, the line and what is wrong.

mod fe_common;
use eij::fe::{mtx, reduce, Attachment, Beam, FeModel, ReductionSettings};
use fe_common::dense;
use std::path::{Path, PathBuf};

fn beam() -> Beam {
    fe_common::contract_beam(3, 1.2e11, 4.6e10)
}

/// A fresh folder for one test's files.
fn folder(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("eij-fe-files-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Lower-triangle entries (row ≥ column, 1-based) of a sparse symmetric matrix.
fn lower(a: &eij::fe::SparseMatrix) -> Vec<(usize, usize, f64)> {
    let mut out = Vec::new();
    for c in 0..a.ncols() {
        for (r, v) in a.row_idx_of_col(c).zip(a.val_of_col(c)) {
            if r >= c {
                out.push((r + 1, c + 1, *v));
            }
        }
    }
    out
}

struct Files {
    m: PathBuf,
    k: PathBuf,
    dofs: PathBuf,
    nodes: PathBuf,
}

/// The beam model written as an FE program would export it.
fn export(dir: &Path, model: &FeModel) -> Files {
    let f = Files {
        m: dir.join("M.mtx"),
        k: dir.join("K.mtx"),
        dofs: dir.join("dofs.csv"),
        nodes: dir.join("nodes.csv"),
    };
    for (path, a) in [(&f.m, &model.mass), (&f.k, &model.stiffness)] {
        let mut out = Vec::new();
        mtx::write_symmetric(&mut out, a, "exported by the test").unwrap();
        std::fs::write(path, out).unwrap();
    }
    let mut d = String::from("node,dof\n");
    for (i, kind) in &model.dofs {
        d += &format!("{},{}\n", model.nodes[*i].id, kind.name());
    }
    std::fs::write(&f.dofs, d).unwrap();
    let mut n = String::from("node,x_m,y_m,z_m\n");
    for p in &model.nodes {
        n += &format!(
            "{},{:.17e},{:.17e},{:.17e}\n",
            p.id, p.position.x, p.position.y, p.position.z
        );
    }
    std::fs::write(&f.nodes, n).unwrap();
    f
}

fn read(f: &Files) -> Result<FeModel, String> {
    FeModel::from_files(&f.m, &f.k, &f.dofs, &f.nodes).map_err(|e| e.to_string())
}

#[test]
fn exported_model_reads_back_and_reduces_like_the_beam() {
    let dir = folder("roundtrip");
    let model = FeModel::beam(&beam()).unwrap();
    let files = export(&dir, &model);
    let back = read(&files).unwrap();
    assert_eq!(dense(&back.stiffness), dense(&model.stiffness));
    assert_eq!(dense(&back.mass), dense(&model.mass));
    let atts = [
        Attachment::fixed("foot", [0.0, 0.6, -0.1]),
        Attachment::fixed("tcp", [0.0, 0.4, 1.1]),
    ];
    let settings = ReductionSettings {
        modes: 6,
        ..Default::default()
    };
    let a = reduce(&model, &atts, &settings).unwrap();
    let b = reduce(&back, &atts, &settings).unwrap();
    for (x, y) in a.frequencies_hz(1.0).iter().zip(b.frequencies_hz(1.0)) {
        assert!((x - y).abs() <= 1e-12 * y);
    }
    assert_eq!(b.attachment_nodes(1, 0.0).nodes, vec![4]);
}

/// The text of a small symmetric matrix in the different layouts exporters write.
#[test]
fn matrix_market_layouts_read_alike() {
    let model = FeModel::beam(&beam()).unwrap();
    let k = &model.stiffness;
    let n = k.nrows();
    let entries = lower(k);
    let reference = dense(k);
    let header = |kind: &str, count: usize| {
        format!("%%MatrixMarket matrix coordinate real {kind}\n% comment\n%\n{n} {n} {count}\n")
    };
    // Symmetric, upper triangle, reverse order, explicit zeros, blank lines, CRLF, odd spacing.
    let mut upper = header("symmetric", entries.len() + 1);
    for (r, c, v) in entries.iter().rev() {
        upper += &format!("  {c}\t{r}   {v:e}\r\n");
    }
    upper += &format!("{n} 1 0.0\n\n");
    // General: both triangles, columns interleaved.
    let mut general = String::new();
    let mut count = 0;
    for (r, c, v) in &entries {
        general += &format!("{r} {c} {v:.17e}\n");
        count += 1;
        if r != c {
            general += &format!("{c} {r} {v:.17e}\n");
            count += 1;
        }
    }
    let general = header("GENERAL", count) + &general;
    // Integer field of a diagonal matrix.
    let ints = format!("%%MatrixMarket matrix coordinate integer symmetric\n{n} {n} {n}\n")
        + &(1..=n)
            .map(|i| format!("{i} {i} {}\n", 10 * i))
            .collect::<String>();
    for (name, text) in [("upper", &upper), ("general", &general)] {
        let a = mtx::parse(text.as_bytes(), name).unwrap();
        let d = dense(&a);
        assert!(
            (&d - &reference).amax() <= 1e-15 * reference.amax(),
            "{name}"
        );
    }
    let a = dense(&mtx::parse(ints.as_bytes(), "ints").unwrap());
    assert_eq!(a[(n - 1, n - 1)], 10.0 * n as f64);
    assert_eq!(a[(0, 1)], 0.0);
}

/// Error of a Matrix Market text.
fn mtx_error(text: &str) -> String {
    mtx::parse(text.as_bytes(), "K.mtx")
        .unwrap_err()
        .to_string()
}

#[test]
fn bad_matrix_market_files_name_line_and_fault() {
    let h = "%%MatrixMarket matrix coordinate real symmetric\n";
    let cases: [(String, &str); 14] = [
        ("node,dof\n1,ux\n".into(), "K.mtx: line 1: not a Matrix Market file"),
        (String::new(), "K.mtx: empty file"),
        ("%%MatrixMarket matrix array real general\n2 2\n1\n0\n0\n1\n".into(), "line 1: only `matrix coordinate`"),
        ("%%MatrixMarket matrix coordinate complex general\n1 1 1\n1 1 1 0\n".into(), "line 1: only real matrices"),
        (format!("{h}3 4 1\n1 1 1.0\n"), "line 2: the matrix is 3×4, not square"),
        (format!("{h}% c\n2 2 2\n1 1 1.0\n0 1 2.0\n"), "line 5: row index 0: Matrix Market indices start at 1"),
        (format!("{h}2 2 2\n1 1 1.0\n3 1 2.0\n"), "line 4: row index 3 beyond the matrix size 2"),
        (format!("{h}2 2 2\n1 1 NaN\n2 2 1.0\n"), "line 3: value NaN is not finite"),
        (format!("{h}2 2 2\n1 1 1.0\n2 2 -inf\n"), "line 4: value -inf is not finite"),
        (format!("{h}2 2 2\n1 1 1.0\n2 2 x\n"), "line 4: value `x` is not a number"),
        (format!("{h}2 2 3\n1 1 1.0\n2 2 1.0\n"), "line 5: the file ends after 2 entries, the size line declares 3"),
        (format!("{h}2 2 1\n1 1 1.0\n2 2 1.0\n"), "line 4: more entries than the 1"),
        (format!("{h}2 2 3\n1 1 1.0\n2 1 0.5\n1 2 0.5\n"), "line 5: a symmetric file stores one triangle, but (2, 1) and (1, 2) are both given (lines 4 and 5)"),
        (
            "%%MatrixMarket matrix coordinate real general\n2 2 4\n1 1 1.0\n2 1 0.5\n1 2 0.7\n2 2 1.0\n".into(),
            "line 5: the matrix is not symmetric: (1, 2) = 0.7 but (2, 1) = 0.5 (line 4)",
        ),
    ];
    for (text, expected) in cases {
        let e = mtx_error(&text);
        assert!(e.contains(expected), "{e:?} lacks {expected:?}");
        assert!(e.starts_with("K.mtx: "), "{e}");
        assert_eq!(e.lines().count(), 1);
    }
    let e = mtx_error(&format!("{h}2 2 3\n1 1 1.0\n2 2 1.0\n2 2 1.0\n"));
    assert!(
        e.contains("line 5: entry (2, 2) given twice (lines 4 and 5)"),
        "{e}"
    );
    let e = mtx_error("%%MatrixMarket matrix coordinate real general\n2 2 2\n1 1 1.0\n1 2 0.5\n");
    assert!(
        e.contains("line 4: the matrix is not symmetric: entry (1, 2) = 0.5 has no partner (2, 1)"),
        "{e}"
    );
}

/// Rewrites one exported file and reads the model.
fn with(f: &Files, path: &Path, text: String) -> String {
    let old = std::fs::read(path).unwrap();
    std::fs::write(path, text).unwrap();
    let e = read(f).unwrap_err();
    std::fs::write(path, old).unwrap();
    e
}

#[test]
fn bad_model_files_name_file_and_fault() {
    let dir = folder("bad");
    let model = FeModel::beam(&beam()).unwrap();
    let f = export(&dir, &model);
    let n = model.n_dofs();
    let dofs = std::fs::read_to_string(&f.dofs).unwrap();
    let nodes = std::fs::read_to_string(&f.nodes).unwrap();
    let m_name = f.m.display().to_string();
    let k_name = f.k.display().to_string();
    let d_name = f.dofs.display().to_string();
    let n_name = f.nodes.display().to_string();

    let short: String = dofs.lines().take(n).map(|l| format!("{l}\n")).collect();
    let e = with(&f, &f.dofs, short);
    assert_eq!(e, format!("{d_name}: {} DOF rows, but the matrices are {n}×{n} (one row per matrix row, in row order)", n - 1));
    // (file, text replaced, replacement, the error after the file name)
    let cases = [
        (
            "d",
            "\n1,ux\n",
            "\n99,ux\n",
            "line 2: node 99 is not in the node file",
        ),
        (
            "d",
            "\n1,uy\n",
            "\n1,ux\n",
            "line 3: node 1 ux given twice (first on line 2)",
        ),
        ("d", "\n1,uy\n", "\n1,uq\n", "line 3: dof `uq` is none of"),
        (
            "d",
            "node,dof",
            "node,direction",
            "line 1: the header must be `node,dof`",
        ),
        (
            "n",
            "\n2,",
            "\n1,",
            "line 3: node 1 given twice (first on line 2)",
        ),
        ("n", "\n2,", "\n2,nan", "line 3: coordinate `nan"),
    ];
    for (which, from, to, expected) in cases {
        let (path, name, text) = if which == "d" {
            (&f.dofs, &d_name, &dofs)
        } else {
            (&f.nodes, &n_name, &nodes)
        };
        let e = with(&f, path, text.replacen(from, to, 1));
        let expected = format!("{name}: {expected}");
        assert!(e.starts_with(&expected), "{e:?} is not {expected:?}");
    }

    // Mass: a negative diagonal, and no mass at all (rigid-body mass 0).
    let mut m = lower(&model.mass);
    m[0].2 = -m[0].2;
    let text = |e: &[(usize, usize, f64)]| {
        format!(
            "%%MatrixMarket matrix coordinate real symmetric\n{n} {n} {}\n",
            e.len()
        ) + &e
            .iter()
            .map(|(r, c, v)| format!("{r} {c} {v:e}\n"))
            .collect::<String>()
    };
    let e = with(&f, &f.m, text(&m));
    assert!(
        e.starts_with(&format!("{m_name}: diagonal entry (1, 1) = -"))
            && e.contains("positive semi-definite"),
        "{e}"
    );
    let zero: Vec<(usize, usize, f64)> = (1..=n).map(|i| (i, i, 0.0)).collect();
    let e = with(&f, &f.m, text(&zero));
    assert!(
        e.starts_with(&format!("{m_name}: mass matrix: rigid-body mass 0")),
        "{e}"
    );
    // Stiffness with a spring to ground: fewer than 6 rigid-body modes.
    let mut k = lower(&model.stiffness);
    k[0].2 *= 1.5;
    let e = with(&f, &f.k, text(&k));
    assert!(
        e.starts_with(&format!(
            "{k_name}: stiffness matrix: a rigid-body translation x produces elastic forces"
        )),
        "{e}"
    );
    // Matrices of different sizes.
    let e = with(
        &f,
        &f.m,
        "%%MatrixMarket matrix coordinate real symmetric\n3 3 1\n1 1 1.0\n".into(),
    );
    assert!(
        e.starts_with(&format!("{m_name}: the mass matrix is 3×3")),
        "{e}"
    );
    let e = with(&f, &f.k, "not a matrix\n".into());
    assert!(
        e.starts_with(&format!("{k_name}: line 1: not a Matrix Market file")),
        "{e}"
    );
    let missing = Files {
        m: dir.join("none.mtx"),
        ..f
    };
    let e = read(&missing).unwrap_err();
    assert_eq!(
        e,
        format!("{}: file not found", dir.join("none.mtx").display())
    );
}

#[test]
fn attachments_that_cannot_be_made_are_errors() {
    let model = FeModel::beam(&beam()).unwrap();
    let settings = ReductionSettings::default();
    let far = [Attachment::fixed("tcp", [0.0, 60.0, 0.5])];
    let e = reduce(&model, &far, &settings).unwrap_err().to_string();
    assert!(
        e.starts_with("beam: attachment tcp: (0.000000, 60.000000, 0.500000) is 59.4"),
        "{e}"
    );
    assert!(e.contains("beyond the body's extent 1.2"), "{e}");
    let e = reduce(&model, &[], &settings).unwrap_err().to_string();
    assert_eq!(
        e,
        "beam: no attachments: a body needs at least one attached point"
    );
    // Two points on the same node share one station; a degenerate travel is an error.
    let twice = [
        Attachment::fixed("a", [0.0, 0.6, -0.1]),
        Attachment::fixed("b", [0.0, 0.5, -0.1]),
    ];
    assert_eq!(
        reduce(&model, &twice, &settings).unwrap().interface_dofs(),
        6
    );
    let line = [Attachment::travel("rail", [0.0, 0.6, 0.0], [0.0, 0.6, 0.0])];
    let e = reduce(&model, &line, &settings).unwrap_err().to_string();
    assert_eq!(
        e,
        "beam: attachment rail: the travel's start and end are the same point"
    );
}
