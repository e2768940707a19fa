//! How well a fitted model reproduces each plane × circle centre, and each EIJ in it.
//!
//! The z values are the fit's own residuals r = P·(E_sim − E_meas)/σ: the static terms
//! (geometry, clock offsets; [`super::statics`]) fitted with the EIJ are removed, exactly as in
//! the χ² of the fit. So the groups add up to the χ² test: Σ over groups of values·rms z² is
//! Σr² = s²·dof. (Raw differences without the static terms would show a group's geometry as a
//! model error while the χ² test, rightly, passes.)

use super::{IdentResult, Problem};
use crate::axes::{Eij, Plane};

/// One EIJ within a group.
#[derive(Debug, Clone, PartialEq)]
pub struct EijFit {
    /// The EIJ.
    pub eij: Eij,
    /// Values (tests measuring it in the group).
    pub values: usize,
    /// RMS of z over them.
    pub rms_z: f64,
}

/// The tests of one plane at one circle centre.
#[derive(Debug, Clone, PartialEq)]
pub struct GroupFit {
    /// Plane.
    pub plane: Plane,
    /// Circle centre, mm (machine axis order).
    pub position_mm: Vec<f64>,
    /// The circle centre with axis names, e.g. `X -150 / Y 100 / Z 250 mm`.
    pub position_label: String,
    /// Tests in the group.
    pub tests: usize,
    /// Values (tests × EIJ).
    pub values: usize,
    /// RMS of z over its values.
    pub rms_z: f64,
    /// Largest |z| and the test and EIJ it belongs to (`xy cw 8 EYY`).
    pub max_abs_z: (f64, String),
    /// Per EIJ, in the order first measured.
    pub eijs: Vec<EijFit>,
}

impl GroupFit {
    /// `zx @ 150,-100,0 mm` (the label of the static terms' groups).
    pub fn label(&self) -> String {
        let p: Vec<String> = self.position_mm.iter().map(|v| format!("{v:.0}")).collect();
        format!("{} @ {} mm", self.plane, p.join(","))
    }

    /// The EIJ with the largest RMS z.
    pub fn worst_eij(&self) -> Option<&EijFit> {
        self.eijs.iter().max_by(|a, b| a.rms_z.total_cmp(&b.rms_z))
    }
}

/// The set acceleration as written in labels: `5`, `2.5`.
pub(crate) fn short_accel(accel_m_s2: f64) -> String {
    let s = format!("{accel_m_s2:.2}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// The fit of `result` (of `problem`) per plane and circle centre, in the order the tests
/// first name them.
pub fn group_fits(problem: &Problem, result: &IdentResult) -> Vec<GroupFit> {
    let r = result
        .statics
        .project(&problem.errors_of(&result.simulated_final));
    let axes = problem.machine().axes();
    let mut groups: Vec<GroupFit> = Vec::new();
    let mut sums: Vec<(f64, Vec<f64>)> = Vec::new();
    let mut tests_seen: Vec<Vec<usize>> = Vec::new();
    for (k, row) in problem.rows().iter().enumerate() {
        let t = &problem.tests()[row.test];
        let position_mm: Vec<f64> = problem
            .position_m(row.test)
            .iter()
            .map(|v| v * 1e3)
            .collect();
        let plane = t.circle.plane;
        let g = match groups
            .iter()
            .position(|g| g.plane == plane && g.position_mm == position_mm)
        {
            Some(g) => g,
            None => {
                let label: Vec<String> = axes
                    .iter()
                    .zip(&position_mm)
                    .map(|(a, v)| format!("{} {v:.0}", a.axis.letter()))
                    .collect();
                groups.push(GroupFit {
                    plane,
                    position_label: format!("{} mm", label.join(" / ")),
                    position_mm,
                    tests: 0,
                    values: 0,
                    rms_z: 0.0,
                    max_abs_z: (0.0, String::new()),
                    eijs: Vec::new(),
                });
                sums.push((0.0, Vec::new()));
                tests_seen.push(Vec::new());
                groups.len() - 1
            }
        };
        let z = r[k];
        let group = &mut groups[g];
        if !tests_seen[g].contains(&row.test) {
            tests_seen[g].push(row.test);
            group.tests += 1;
        }
        group.values += 1;
        sums[g].0 += z * z;
        if z.abs() > group.max_abs_z.0 || group.max_abs_z.1.is_empty() {
            group.max_abs_z = (
                z.abs(),
                format!(
                    "{} {} {} {}",
                    plane,
                    t.circle.direction,
                    short_accel(t.circle.accel_m_s2),
                    row.eij
                ),
            );
        }
        match group.eijs.iter().position(|e| e.eij == row.eij) {
            Some(e) => {
                group.eijs[e].values += 1;
                sums[g].1[e] += z * z;
            }
            None => {
                group.eijs.push(EijFit {
                    eij: row.eij,
                    values: 1,
                    rms_z: 0.0,
                });
                sums[g].1.push(z * z);
            }
        }
    }
    for (group, (sum, per_eij)) in groups.iter_mut().zip(&sums) {
        group.rms_z = (sum / group.values.max(1) as f64).sqrt();
        for (e, s) in group.eijs.iter_mut().zip(per_eij) {
            e.rms_z = (s / e.values.max(1) as f64).sqrt();
        }
    }
    groups
}
