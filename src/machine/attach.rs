//! Where things attach to the bodies, and turning a body elastic: the sites an elastic body's
//! reduction must provide attachments for, and the checks that a reduced model fits its body.

use super::body::{BodyKind, ElasticBody, Site};
use super::{Machine, MachineError};
use nalgebra::Vector3;

/// One site on one body at the reference position.
#[derive(Debug, Clone, PartialEq)]
pub struct BodySite {
    /// Body index in [`Machine::bodies`].
    pub body: usize,
    /// What attaches.
    pub site: Site,
    /// The point of the body where it attaches at the reference position (every axis at its
    /// `reference_m`), m.
    pub point_m: Vector3<f64>,
    /// How the point travels over the body with the axes: per axis index, its displacement
    /// over the body per metre of axis position (empty: fixed to the body).
    pub travel: Vec<(usize, Vector3<f64>)>,
}

impl BodySite {
    /// The point of the body where it attaches with the axes at `pose_m` (machine axis order).
    pub fn point_at(&self, pose_m: &[f64], machine: &Machine) -> Vector3<f64> {
        self.travel.iter().fold(self.point_m, |p, (ai, dir)| {
            p + dir * (pose_m[*ai] - machine.axes()[*ai].reference_m)
        })
    }
}

/// Relative tolerance of the rigid block of a reduced mass matrix against blockdiag(m·I, J).
const RIGID_BLOCK_TOLERANCE: f64 = 1e-6;

impl Machine {
    /// Every site on every body (fixed bodies too), in assembly order: per axis its carriages,
    /// nut and scale (moving body first, then the carrier, where the point travels with the
    /// axis), the joints (both bodies), the TCP and the workpiece nest (which travels over the
    /// workpiece body with every axis that moves the tool relative to it).
    pub fn sites(&self) -> Vec<BodySite> {
        let mut out = Vec::new();
        let fixed = |body, site, point_m: &Vector3<f64>| BodySite {
            body,
            site,
            point_m: *point_m,
            travel: Vec::new(),
        };
        for (ai, a) in self.axes.iter().enumerate() {
            let along = vec![(ai, a.direction() * a.side.sign())];
            let both = |out: &mut Vec<BodySite>, site, p: &Vector3<f64>| {
                out.push(fixed(a.moving, site, p));
                out.push(BodySite {
                    travel: along.clone(),
                    ..fixed(a.carrier, site, p)
                });
            };
            let carriages = a.guideway.rails.iter().flat_map(|r| &r.carriages_m);
            for (index, p) in carriages.enumerate() {
                both(
                    &mut out,
                    Site::Carriage {
                        axis: a.axis,
                        index,
                    },
                    p,
                );
            }
            both(&mut out, Site::Nut(a.axis), &a.drive.nut_m);
            both(&mut out, Site::Scale(a.axis), &a.drive.scale_m);
        }
        for (ji, j) in self.joints.iter().enumerate() {
            out.push(fixed(j.body, Site::Joint(ji), &j.point_m));
            out.push(fixed(j.other, Site::Joint(ji), &j.point_m));
        }
        out.push(fixed(self.tcp.body, Site::Tcp, &self.tcp.point_m));
        let (tool, wp) = (self.tcp.body, self.workpiece.body);
        let travel = (0..self.axes.len())
            .filter_map(|ai| {
                let a = &self.axes[ai];
                let sign = match (self.is_carried_by(tool, ai), self.is_carried_by(wp, ai)) {
                    (true, false) => 1.0,
                    (false, true) => -1.0,
                    _ => 0.0,
                };
                (sign != 0.0).then(|| (ai, a.direction() * (a.side.sign() * sign)))
            })
            .collect();
        out.push(BodySite {
            travel,
            ..fixed(wp, Site::Workpiece, &self.tcp.point_m)
        });
        out
    }

    /// Makes body `name` elastic with the reduced model of `elastic`. Its mass, centre of
    /// gravity and inertia become the model's (the rigid block of its mass matrix must be
    /// blockdiag(m·I, J), the coordinates being at the centre of gravity), and the model must
    /// attach every site on the body.
    pub fn with_elastic_body(
        mut self,
        name: &str,
        elastic: ElasticBody,
    ) -> Result<Machine, MachineError> {
        let err =
            |k: &str, m: String| MachineError::new(&self.source, format!("body[{name}]{k}"), m);
        let b = self
            .bodies
            .iter()
            .position(|b| b.name == name)
            .ok_or_else(|| err("", "no such body".into()))?;
        if self.bodies[b].is_fixed() {
            return Err(err(".fixed", "a fixed body cannot be elastic".into()));
        }
        let model = elastic.model().clone();
        let m = model.mass();
        let mass_kg = m[(0, 0)];
        let inertia = m.fixed_view::<3, 3>(3, 3).into_owned();
        let mut rigid = nalgebra::Matrix6::zeros();
        for d in 0..3 {
            rigid[(d, d)] = mass_kg;
        }
        rigid.fixed_view_mut::<3, 3>(3, 3).copy_from(&inertia);
        let off = (m.fixed_view::<6, 6>(0, 0) - rigid).abs().max();
        if mass_kg <= 0.0 || off > RIGID_BLOCK_TOLERANCE * mass_kg.max(inertia.abs().max()) {
            return Err(err(
                "",
                format!(
                    "the reduced mass matrix's rigid block is not blockdiag(m·I, J) at the centre of gravity (off by {off:.3e})"
                ),
            ));
        }
        let w = m.nrows();
        for s in self.sites().iter().filter(|s| s.body == b) {
            match model.point_motion(s.site, &s.point_m) {
                Some(t) if t.shape() == (6, w) => {}
                Some(t) => {
                    return Err(err(
                        "",
                        format!("the motion of {} is {:?}, not 6 × {w}", s.site, t.shape()),
                    ))
                }
                None => return Err(err("", format!("no attachment for {}", s.site))),
            }
        }
        let body = &mut self.bodies[b];
        body.mass_kg = mass_kg;
        body.cog_m = model.cog_m();
        body.inertia_kg_m2 = inertia;
        body.kind = BodyKind::Elastic(elastic);
        Ok(self)
    }

    /// Sets the factor on the elastic stiffness of body `body` (finite and > 0; the body must
    /// be elastic).
    pub(crate) fn set_body_stiffness(
        &mut self,
        body: usize,
        value: f64,
    ) -> Result<(), MachineError> {
        let source = self.source.clone();
        let b = self
            .bodies
            .get_mut(body)
            .ok_or_else(|| MachineError::new(&source, format!("body[{body}]"), "no such body"))?;
        let key = format!("body[{}].stiffness_factor", b.name);
        let BodyKind::Elastic(e) = &mut b.kind else {
            return Err(MachineError::new(&source, key, "the body is not elastic"));
        };
        if !(value.is_finite() && value > 0.0) {
            return Err(MachineError::new(
                &source,
                key,
                format!("{value} must be > 0"),
            ));
        }
        e.set_stiffness_factor(value);
        Ok(())
    }
}
