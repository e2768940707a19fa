//! An FE model from the files an FE program exported: Matrix Market M and K, the DOF map
//! (`node,dof`, one line per matrix row in row order, or the mapping file ANSYS's `HBMAT` writes)
//! and the nodes (`node,x_m,y_m,z_m`).

use super::{mtx, DofKind, FeError, FeModel, Node};
use crate::io::read::read_input;
use std::path::Path;

/// Most bytes of a DOF map or node file.
const MAX_TABLE_BYTES: u64 = 256 << 20;

impl FeModel {
    /// Reads an exported FE model and checks it: sizes, the DOF map against the nodes, mass
    /// properties (rigid-body mass > 0) and that the stiffness leaves the six rigid-body motions
    /// free. Every error names the file, the line where there is one, and what is wrong.
    pub fn from_files(
        mass: &Path,
        stiffness: &Path,
        dofs: &Path,
        nodes: &Path,
    ) -> Result<FeModel, FeError> {
        let name = |p: &Path| p.display().to_string();
        let (m_name, k_name) = (name(mass), name(stiffness));
        let m = mtx::read_symmetric(mass, &m_name)?;
        let k = mtx::read_symmetric(stiffness, &k_name)?;
        if m.nrows() != k.nrows() {
            return Err(FeError::file(
                &m_name,
                format!(
                    "the mass matrix is {0}×{0}, the stiffness matrix {k_name} {1}×{1}",
                    m.nrows(),
                    k.nrows()
                ),
            ));
        }
        for c in 0..m.ncols() {
            for (r, v) in m.row_idx_of_col(c).zip(m.val_of_col(c)) {
                if r == c && *v < 0.0 {
                    return Err(FeError::file(
                        &m_name,
                        format!("diagonal entry ({0}, {0}) = {v} is negative: a mass matrix is positive semi-definite", r + 1),
                    ));
                }
            }
        }
        let node_list = read_nodes(nodes)?;
        let map = read_dofs(dofs, &node_list, k.nrows())?;
        let model = FeModel::new(&k_name, m, k, node_list, &map)?;
        model.mass_properties().map_err(|e| rename(e, &m_name))?;
        model.check_free()?;
        Ok(model)
    }
}

impl FeModel {
    /// Writes the model as an FE program would export it, in the layout
    /// [`FeModel::from_files`] reads: M and K as Matrix Market `coordinate real symmetric`
    /// (lower triangle, 17 digits, `comment` as `%` lines), the DOF map `node,dof` and the nodes
    /// `node,x_m,y_m,z_m`. The four files are written as one set (all or none,
    /// [`crate::io::write_set`]).
    pub fn write_files(
        &self,
        [mass, stiffness, dofs, nodes]: [&Path; 4],
        comment: &str,
    ) -> Result<(), crate::io::WriteError> {
        let matrix = |a: &super::SparseMatrix| {
            let mut out = Vec::new();
            mtx::write_symmetric(&mut out, a, comment).map(|()| out)
        };
        fn io(path: &Path) -> impl Fn(std::io::Error) -> crate::io::WriteError + '_ {
            move |cause| crate::io::WriteError::Io {
                path: path.to_path_buf(),
                cause,
            }
        }
        let m = matrix(&self.mass).map_err(io(mass))?;
        let k = matrix(&self.stiffness).map_err(io(stiffness))?;
        let mut map = String::from("node,dof\n");
        for (i, kind) in &self.dofs {
            map += &format!("{},{}\n", self.nodes[*i].id, kind.name());
        }
        let mut list = String::from("node,x_m,y_m,z_m\n");
        for p in &self.nodes {
            list += &format!(
                "{},{:?},{:?},{:?}\n",
                p.id, p.position.x, p.position.y, p.position.z
            );
        }
        crate::io::write_set(
            &[
                (mass, &m),
                (stiffness, &k),
                (dofs, map.as_bytes()),
                (nodes, list.as_bytes()),
            ],
            &[],
        )
    }
}

fn rename(e: FeError, file: &str) -> FeError {
    match e {
        FeError::File { message, .. } => FeError::file(file, message),
        other => other,
    }
}

type Table = csv::Reader<std::io::Cursor<Vec<u8>>>;

fn reader(path: &Path, header: &[&str]) -> Result<(String, Table), FeError> {
    let file = path.display().to_string();
    let bytes =
        read_input(path, MAX_TABLE_BYTES).map_err(|e| FeError::file(&file, e.to_string()))?;
    let rdr = table(&file, bytes, header)?;
    Ok((file, rdr))
}

/// A CSV table whose header must be `header` (any case).
fn table(file: &str, bytes: Vec<u8>, header: &[&str]) -> Result<Table, FeError> {
    let mut rdr = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .from_reader(std::io::Cursor::new(bytes));
    let got: Vec<String> = rdr
        .headers()
        .map_err(|e| FeError::line(file, 1, format!("not a CSV header: {e}")))?
        .iter()
        .map(|h| h.to_ascii_lowercase())
        .collect();
    if got.len() != header.len() || got.iter().zip(header).any(|(g, h)| g != h) {
        return Err(FeError::line(
            file,
            1,
            format!(
                "the header must be `{}`, found `{}`",
                header.join(","),
                got.join(",")
            ),
        ));
    }
    Ok(rdr)
}

/// The mapping file of ANSYS's `HBMAT` (`Mapping = YES`): a header line `Matrix Eqn  Node  DOF`,
/// then per matrix equation, in equation order, `equation node label` separated by blanks
/// (labels `UX UY UZ ROTX ROTY ROTZ`). Equations must count 1, 2, 3, … (the matrices' row order).
fn read_ansys_mapping(
    file: &str,
    bytes: &[u8],
    add: &mut impl FnMut(usize, &str, &str) -> Result<(), String>,
) -> Result<(), FeError> {
    let text =
        std::str::from_utf8(bytes).map_err(|_| FeError::file(file, "not text (invalid UTF-8)"))?;
    let mut header = false;
    let mut equation = 0usize;
    for (i, line) in text.lines().enumerate() {
        let line_no = i + 1;
        let l = line.trim();
        if l.is_empty() {
            continue;
        }
        if !header {
            header = true;
            continue;
        }
        let f: Vec<&str> = l.split_ascii_whitespace().collect();
        let [eqn, node, dof] = f.as_slice() else {
            return Err(FeError::line(
                file,
                line_no,
                format!("expected `equation node dof` (an ANSYS mapping file), found `{l}`"),
            ));
        };
        equation += 1;
        if eqn.parse::<usize>().ok() != Some(equation) {
            return Err(FeError::line(
                file,
                line_no,
                format!("equation `{eqn}` where {equation} is next: the mapping lists the matrix equations in order, one per line"),
            ));
        }
        add(line_no, node, dof).map_err(|m| FeError::line(file, line_no, m))?;
    }
    Ok(())
}

fn records(
    file: &str,
    rdr: &mut Table,
    mut each: impl FnMut(usize, &csv::StringRecord) -> Result<(), String>,
) -> Result<(), FeError> {
    for rec in rdr.records() {
        let rec = rec.map_err(|e| {
            let line = e.position().map(|p| p.line() as usize).unwrap_or(0);
            FeError::line(file, line, format!("not a CSV row: {e}"))
        })?;
        let line = rec.position().map(|p| p.line() as usize).unwrap_or(0);
        each(line, &rec).map_err(|m| FeError::line(file, line, m))?;
    }
    Ok(())
}

fn node_id(s: &str) -> Result<u64, String> {
    s.parse()
        .map_err(|_| format!("node `{s}` is not a whole number ≥ 0"))
}

fn read_nodes(path: &Path) -> Result<Vec<Node>, FeError> {
    let (file, mut rdr) = reader(path, &["node", "x_m", "y_m", "z_m"])?;
    let mut nodes = Vec::new();
    let mut seen = std::collections::HashMap::new();
    records(&file, &mut rdr, |line, rec| {
        let id = node_id(&rec[0])?;
        let mut x = [0.0; 3];
        for (k, v) in x.iter_mut().enumerate() {
            *v = rec[k + 1]
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| format!("coordinate `{}` is not a finite number", &rec[k + 1]))?;
        }
        if let Some(first) = seen.insert(id, line) {
            return Err(format!("node {id} given twice (first on line {first})"));
        }
        nodes.push(Node {
            id,
            position: x.into(),
        });
        Ok(())
    })?;
    if nodes.is_empty() {
        return Err(FeError::file(&file, "no nodes"));
    }
    Ok(nodes)
}

/// The header of the mapping file ANSYS's `HBMAT` writes (`Matrix Eqn  Node  DOF`).
const ANSYS_MAPPING: &str = "matrix eqn";

fn read_dofs(path: &Path, nodes: &[Node], n: usize) -> Result<Vec<(u64, DofKind)>, FeError> {
    let file = path.display().to_string();
    let bytes =
        read_input(path, MAX_TABLE_BYTES).map_err(|e| FeError::file(&file, e.to_string()))?;
    let known: std::collections::HashSet<u64> = nodes.iter().map(|p| p.id).collect();
    let mut seen = std::collections::HashMap::new();
    let mut map = Vec::with_capacity(n);
    let mut add = |line: usize, node: &str, dof: &str| {
        let id = node_id(node)?;
        if !known.contains(&id) {
            return Err(format!("node {id} is not in the node file"));
        }
        let kind = DofKind::parse(dof)
            .ok_or_else(|| format!("dof `{dof}` is none of ux uy uz rx ry rz"))?;
        if let Some(first) = seen.insert((id, kind), line) {
            return Err(format!(
                "node {id} {} given twice (first on line {first})",
                kind.name()
            ));
        }
        map.push((id, kind));
        Ok(())
    };
    let first = bytes
        .split(|&b| b == b'\n')
        .map(|l| String::from_utf8_lossy(l).trim().to_ascii_lowercase())
        .find(|l| !l.is_empty());
    if first.is_some_and(|l| l.starts_with(ANSYS_MAPPING)) {
        read_ansys_mapping(&file, &bytes, &mut add)?;
    } else {
        let mut rdr = table(&file, bytes, &["node", "dof"])?;
        records(&file, &mut rdr, |line, rec| add(line, &rec[0], &rec[1]))?;
    }
    if map.len() != n {
        return Err(FeError::file(
            &file,
            format!(
                "{} DOF rows, but the matrices are {n}×{n} (one row per matrix row, in row order)",
                map.len()
            ),
        ));
    }
    Ok(map)
}
