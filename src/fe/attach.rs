//! Points attached to an elastic body, by the rules of docs/fe.md.
//!
//! Every attachment goes through *stations*: a station is a 6-DOF motion (translation u and
//! rotation θ at its reference point r) that is a linear function W u_FE of the FE displacements:
//! - a 6-DOF node (beam, shell): the node's own six DOFs, r = the node; a point p on it moves
//!   with u + θ × (p − r) (the nearest node; a tie goes to the lower node number);
//! - an RBE3 patch of 3-DOF nodes (solid): the least-squares rigid motion of the nodes within
//!   `attach_radius_m`, equal weights, r = their centroid: u = mean uᵢ,
//!   θ = A⁻¹ Σ dᵢ × uᵢ with dᵢ = xᵢ − r and A = Σ (|dᵢ|² I − dᵢdᵢᵀ).
//!
//! A travelling point (a carriage on a rail, a nut, the scale's read position) has a row of
//! stations along its line, ordered by their coordinate along the travel; at a position between
//! two it blends their motions linearly (each carried to the point through its lever arm), so the
//! attachment is continuous in the axis position.

use super::{FeError, FeModel};
use nalgebra::{Matrix3, Vector3};
use std::collections::HashMap;

/// How a point is attached.
#[derive(Debug, Clone, PartialEq)]
pub enum AttachmentKind {
    /// A point fixed on the body, m.
    Fixed {
        /// The point, machine coordinates at the reference position, m.
        point_m: [f64; 3],
    },
    /// A point travelling on the line from `start_m` to `end_m`; position s (m) along it.
    Travel {
        /// The point at s = 0, m.
        start_m: [f64; 3],
        /// The point at the end of the travel, m.
        end_m: [f64; 3],
    },
}

/// A named point attached to an elastic body.
#[derive(Debug, Clone, PartialEq)]
pub struct Attachment {
    /// Name, e.g. `z.carriage[0]`.
    pub name: String,
    /// Where and how.
    pub kind: AttachmentKind,
}

impl Attachment {
    /// A fixed point.
    pub fn fixed(name: &str, point_m: [f64; 3]) -> Attachment {
        Attachment {
            name: name.into(),
            kind: AttachmentKind::Fixed { point_m },
        }
    }
    /// A point travelling from `start_m` to `end_m`.
    pub fn travel(name: &str, start_m: [f64; 3], end_m: [f64; 3]) -> Attachment {
        Attachment {
            name: name.into(),
            kind: AttachmentKind::Travel { start_m, end_m },
        }
    }
    /// The point at position `s` m (a fixed point ignores `s`).
    pub fn point_at(&self, s: f64) -> Vector3<f64> {
        match &self.kind {
            AttachmentKind::Fixed { point_m } => Vector3::from(*point_m),
            AttachmentKind::Travel { start_m, end_m } => {
                let (a, b) = (Vector3::from(*start_m), Vector3::from(*end_m));
                a + (b - a).normalize() * s
            }
        }
    }
}

/// One station: its reference point, its nodes and how their DOFs make its 6-DOF motion.
#[derive(Debug, Clone, PartialEq)]
pub struct Station {
    /// Reference point r, m.
    pub reference_m: Vector3<f64>,
    /// Node indices (into [`FeModel::nodes`]).
    pub nodes: Vec<usize>,
    /// The weight of each node (1 for a 6-DOF node, 1/N in an RBE3 patch).
    pub weights: Vec<f64>,
    /// W: (station row 0 … 5, matrix row, value).
    pub(crate) w: Vec<(usize, usize, f64)>,
}

/// An attachment resolved to stations: one for a fixed point, a row sorted by coordinate along
/// the travel for a travelling one.
#[derive(Debug, Clone)]
pub(crate) struct Resolved {
    /// (coordinate along the travel m, station index).
    pub stations: Vec<(f64, usize)>,
}

pub(crate) struct Layout {
    pub stations: Vec<Station>,
    pub resolved: Vec<Resolved>,
}

struct Builder<'a> {
    model: &'a FeModel,
    radius: Option<f64>,
    extent: f64,
    stations: Vec<Station>,
    index: HashMap<Vec<usize>, usize>,
}

impl Builder<'_> {
    fn add(&mut self, s: Station) -> usize {
        let key = s.nodes.clone();
        *self.index.entry(key).or_insert_with(|| {
            self.stations.push(s);
            self.stations.len() - 1
        })
    }

    /// Nearest node carrying translations; a tie goes to the lower node number.
    fn nearest(&self, p: &Vector3<f64>) -> (usize, f64) {
        let m = self.model;
        let mut best = (usize::MAX, f64::INFINITY);
        for (i, node) in m.nodes.iter().enumerate() {
            if m.node_dofs[i][0].is_none() {
                continue;
            }
            let d = (node.position - p).norm();
            if d < best.1 || (d == best.1 && best.0 != usize::MAX && node.id < m.nodes[best.0].id) {
                best = (i, d);
            }
        }
        best
    }

    fn node_station(&self, i: usize) -> Station {
        let d = self.model.node_dofs[i];
        Station {
            reference_m: self.model.nodes[i].position,
            nodes: vec![i],
            weights: vec![1.0],
            w: (0..6)
                .map(|k| (k, d[k].expect("a 6-DOF node"), 1.0))
                .collect(),
        }
    }

    fn patch(&self, p: &Vector3<f64>, what: &str) -> Result<Station, String> {
        let radius = self.radius.ok_or_else(|| {
            format!("{what}: the body has solid (3-DOF) nodes there: attach_radius_m is needed")
        })?;
        let m = self.model;
        let mut nodes: Vec<usize> = (0..m.nodes.len())
            .filter(|&i| m.node_dofs[i][0].is_some() && (m.nodes[i].position - p).norm() <= radius)
            .collect();
        nodes.sort_by_key(|&i| m.nodes[i].id);
        let n = nodes.len() as f64;
        let centroid = nodes
            .iter()
            .map(|&i| m.nodes[i].position)
            .sum::<Vector3<f64>>()
            / n.max(1.0);
        let mut a = Matrix3::zeros();
        for &i in &nodes {
            let d = m.nodes[i].position - centroid;
            a += Matrix3::identity() * d.norm_squared() - d * d.transpose();
        }
        let eig = a.symmetric_eigenvalues();
        if nodes.len() < 3 || !(eig.min() > 1e-9 * eig.max()) {
            let (near, dist) = self.nearest(p);
            return Err(format!(
                "{what}: fewer than 3 non-collinear nodes within attach_radius_m = {radius} m of ({:.6}, {:.6}, {:.6}) \
                 ({} found; nearest node {} at {dist:.6} m)",
                p.x,
                p.y,
                p.z,
                nodes.len(),
                m.nodes.get(near).map(|p| p.id).unwrap_or(0)
            ));
        }
        let a_inv = a
            .try_inverse()
            .ok_or_else(|| format!("{what}: singular RBE3 patch"))?;
        let mut w = Vec::with_capacity(nodes.len() * 12);
        for &i in &nodes {
            let d = m.nodes[i].position - centroid;
            let rot = a_inv * d.cross_matrix();
            let dofs = m.node_dofs[i];
            for c in 0..3 {
                let row = dofs[c].expect("translations present");
                w.push((c, row, 1.0 / n));
                for r in 0..3 {
                    if rot[(r, c)] != 0.0 {
                        w.push((3 + r, row, rot[(r, c)]));
                    }
                }
            }
        }
        Ok(Station {
            reference_m: centroid,
            weights: vec![1.0 / n; nodes.len()],
            nodes,
            w,
        })
    }

    /// The station of a point by the rule of docs/fe.md.
    fn at_point(&mut self, p: &Vector3<f64>, what: &str) -> Result<usize, String> {
        let (near, dist) = self.nearest(p);
        if near == usize::MAX {
            return Err(format!("{what}: the body has no nodes"));
        }
        if dist > self.extent {
            return Err(format!(
                "{what}: ({:.6}, {:.6}, {:.6}) is {dist:.6} m from the nearest node, beyond the body's extent {:.6} m",
                p.x, p.y, p.z, self.extent
            ));
        }
        let station = if self.model.has_rotations(near) {
            self.node_station(near)
        } else {
            self.patch(p, what)?
        };
        Ok(self.add(station))
    }

    fn travel(
        &mut self,
        a: &Vector3<f64>,
        b: &Vector3<f64>,
        what: &str,
    ) -> Result<Resolved, String> {
        let length = (b - a).norm();
        if !(length > 0.0) {
            return Err(format!(
                "{what}: the travel's start and end are the same point"
            ));
        }
        let u = (b - a) / length;
        let m = self.model;
        let line = |x: &Vector3<f64>| {
            let s = (x - a).dot(&u);
            (s, (x - a - u * s).norm())
        };
        let (mid, _) = self.nearest(&(0.5 * (a + b)));
        if mid == usize::MAX {
            return Err(format!("{what}: the body has no nodes"));
        }
        let with_rotations = m.has_rotations(mid);
        let candidates: Vec<(f64, f64, usize)> = (0..m.nodes.len())
            .filter(|&i| m.node_dofs[i][0].is_some() && m.has_rotations(i) == with_rotations)
            .map(|i| {
                let (s, d) = line(&m.nodes[i].position);
                (s, d, i)
            })
            .collect();
        let dmin = candidates.iter().fold(f64::INFINITY, |x, c| x.min(c.1));
        let tol = 1e-6 * self.extent;
        let band = if with_rotations {
            dmin + self.radius.unwrap_or(0.0).max(tol)
        } else {
            self.radius.ok_or_else(|| {
                format!("{what}: the body has solid (3-DOF) nodes there: attach_radius_m is needed")
            })?
        };
        let mut near: Vec<(f64, f64, usize)> =
            candidates.into_iter().filter(|c| c.1 <= band).collect();
        if near.is_empty() {
            return Err(format!(
                "{what}: no node within {band:.6} m of the travel line (nearest at {dmin:.6} m)"
            ));
        }
        // One station per coordinate along the travel (nodes in one layer share it).
        near.sort_by(|x, y| {
            x.0.total_cmp(&y.0)
                .then(x.1.total_cmp(&y.1))
                .then(m.nodes[x.2].id.cmp(&m.nodes[y.2].id))
        });
        let mut layers: Vec<(f64, usize)> = Vec::new();
        for &(s, _, i) in &near {
            if layers.last().is_none_or(|l| s - l.0 > tol) {
                layers.push((s, i));
            }
        }
        // Keep the layers within the travel and the nearest one beyond each end.
        let first = layers.iter().rposition(|l| l.0 <= tol).unwrap_or(0);
        let last = layers
            .iter()
            .position(|l| l.0 >= length - tol)
            .unwrap_or(layers.len() - 1);
        let mut stations = Vec::new();
        for &(s, i) in &layers[first..=last] {
            let station = if with_rotations {
                self.node_station(i)
            } else {
                self.patch(&(a + u * s), &format!("{what} at {s:.6} m"))?
            };
            stations.push((s, self.add(station)));
        }
        stations.dedup_by_key(|s| s.1);
        Ok(Resolved { stations })
    }
}

/// Resolves every attachment to stations. `radius`: `attach_radius_m` (needed on solids).
pub(crate) fn layout(
    model: &FeModel,
    attachments: &[Attachment],
    radius: Option<f64>,
) -> Result<Layout, FeError> {
    let mut b = Builder {
        model,
        radius,
        extent: model.extent_m(),
        stations: Vec::new(),
        index: HashMap::new(),
    };
    let err = |m: String| FeError::file(&model.source, m);
    let mut resolved = Vec::with_capacity(attachments.len());
    for att in attachments {
        let what = format!("attachment {}", att.name);
        let r = match &att.kind {
            AttachmentKind::Fixed { point_m } => {
                let p = Vector3::from(*point_m);
                if p.iter().any(|v| !v.is_finite()) {
                    return Err(err(format!("{what}: the point is not finite")));
                }
                Resolved {
                    stations: vec![(0.0, b.at_point(&p, &what).map_err(err)?)],
                }
            }
            AttachmentKind::Travel { start_m, end_m } => {
                let (s, e) = (Vector3::from(*start_m), Vector3::from(*end_m));
                if s.iter().chain(e.iter()).any(|v| !v.is_finite()) {
                    return Err(err(format!("{what}: the travel line is not finite")));
                }
                b.travel(&s, &e, &what).map_err(err)?
            }
        };
        resolved.push(r);
    }
    Ok(Layout {
        stations: b.stations,
        resolved,
    })
}

impl Resolved {
    /// The stations and blend weights at coordinate `s`: one station, or two with (1 − t, t).
    pub(crate) fn blend(&self, s: f64) -> [(usize, f64); 2] {
        let st = &self.stations;
        let k = st.partition_point(|x| x.0 <= s);
        if k == 0 {
            return [(st[0].1, 1.0), (st[0].1, 0.0)];
        }
        if k == st.len() {
            let l = st[st.len() - 1].1;
            return [(l, 1.0), (l, 0.0)];
        }
        let (c0, c1) = (st[k - 1].0, st[k].0);
        let t = (s - c0) / (c1 - c0);
        [(st[k - 1].1, 1.0 - t), (st[k].1, t)]
    }
}
