//! Static (acceleration-independent) terms of the measured tests, fitted jointly with the
//! model's EIJ.
//!
//! Why: every real R-Test circle carries static geometry — an elliptic or out-of-square path,
//! a tilted plane — that does not scale with the acceleration. On a steady circle the set
//! position is x_set = −ä/ω², so a static term G (µm per mm of set position, as in
//! [`crate::rtest::evaluate_pooled`]) enters one test's evaluation exactly like an EIJ:
//!
//! Ê_ij = E_ij − G_ij·r/a     (r in mm, a = rω² the set acceleration),
//!
//! and a single test cannot tell them apart (1–2 µm of ellipticity shifts EIJ by 0.5 µm·s²/m at
//! 5 m/s² on r = 2 mm). Tests at several accelerations of one plane at one circle-centre
//! position can: E does not depend on a, the static term goes with 1/a.
//!
//! How: the identification's residuals become
//!
//! r = W·(E_sim(θ) − Ê) + A·g,
//!
//! with one column of A per static term g (per plane × circle-centre position ×
//! measured EIJ, entries −r/a/σ in the rows of that group's tests). The terms are linear
//! nuisance parameters, so they are eliminated exactly (variable projection, Golub & Pereyra
//! 1973): for given θ the best g is −A⁺·W(E_sim − Ê), and what is left is the projection
//! P = I − A·A⁺ of the weighted errors onto the complement of A's columns. The optimiser sees
//! only P·r and P·J (A does not depend on θ, so the projected Jacobian is exact); the
//! covariance of θ from P·J is the marginal one, the static terms' uncertainty included, with
//! m − n − q degrees of freedom. This is the second stage of a pooled evaluation: the per-test
//! EIJ are sufficient statistics of the per-test regression [ä_a, ä_b, 1] (the static term is
//! collinear with ä inside one test), so fitting G on them is the same as fitting it on the
//! samples, with E taken from the model instead of free per group.
//!
//! Which terms: a shared term per group and EIJ where the group holds two or more
//! accelerations (≥ 5 % apart), else none (said in a note: there static geometry is part of
//! the EIJ, as in a single test). A geometric ellipse or squareness is the same for cw and ccw;
//! a reversal term (friction, backlash) flips sign with the direction. A reversal term
//! G_rev·sgn(ω)·r/a per group and EIJ is added where the data need it
//! ([`StaticTerms::Auto`]: after the fit, when adding it lowers χ² by more than
//! [`super::settings::CHI2_SIGMAS`] standard deviations of its χ² distribution; the fit is
//! then repeated) and where each direction has two or more accelerations.
//!
//! A residual clock offset between scales and R-Test (δ·v, an antisymmetric in-plane
//! cross-talk ∝ sgn(ω)/√a) is the evaluation's business ([`crate::rtest::clock_fit`]).

use crate::axes::{Direction, Eij, Plane};
use nalgebra::{DMatrix, DVector};

/// Accelerations closer than this ratio count as one.
const SAME_ACCEL_RATIO: f64 = 1.05;

/// Which static terms are fitted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum StaticTerms {
    /// Shared terms where separable; reversal terms where the data need them (default).
    Auto,
    /// Shared terms where separable, never reversal terms.
    Shared,
    /// Shared and reversal terms wherever separable.
    PerDirection,
    /// None: every test's EIJ taken as they are (static geometry would bias them).
    None,
}

/// The rows of the residual vector: test index, EIJ and the σ it is weighted with.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Row {
    /// Index of the test.
    pub test: usize,
    /// The EIJ.
    pub eij: Eij,
    /// σ of the weighting (floored), µm·s²/m.
    pub sigma: f64,
    /// r/a of the test, mm·s²/m.
    pub r_over_a: f64,
    /// Direction of the test.
    pub direction: Direction,
}

/// The tests of one plane at one circle-centre position.
#[derive(Debug, Clone, PartialEq)]
pub struct StaticGroup {
    /// Plane.
    pub plane: Plane,
    /// Circle centre, m (machine axis order).
    pub position_m: Vec<f64>,
    /// Indices of its tests.
    pub tests: Vec<usize>,
    /// Whether shared static terms are fitted.
    pub shared: bool,
    /// Whether reversal terms are fitted.
    pub reversal: bool,
    /// Whether reversal terms could be fitted (each direction at two or more accelerations).
    pub reversal_possible: bool,
    /// Why terms are not fitted, where they are not.
    pub note: Option<super::Note>,
}

impl StaticGroup {
    /// `zx @ 150,-100,0 mm`.
    pub fn label(&self) -> String {
        format!(
            "{} @ {} mm",
            self.plane,
            self.position_m
                .iter()
                .map(|v| format!("{:.0}", v * 1e3))
                .collect::<Vec<_>>()
                .join(",")
        )
    }
}

/// One column of A: a static term.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StaticColumn {
    /// Its group.
    pub group: usize,
    /// The EIJ it shifts.
    pub eij: Eij,
    /// A reversal term (flips sign with the direction) rather than a shared one.
    pub reversal: bool,
    /// A clock offset (index into [`Statics::clocks`]) rather than a geometric term; `group`
    /// and `eij` then mean nothing.
    pub clock: Option<usize>,
}

/// The static terms of a problem and the projection that eliminates them.
#[derive(Debug, Clone, PartialEq)]
pub struct Statics {
    /// The groups.
    pub groups: Vec<StaticGroup>,
    /// The terms, in the order of A's columns.
    pub columns: Vec<StaticColumn>,
    /// The clocks (tests sharing one time offset between scales and R-Test, e.g. one folder)
    /// with a fitted offset.
    pub clocks: Vec<String>,
    /// A, m × q (weighted like the residuals).
    a: DMatrix<f64>,
    /// Orthonormal basis of A's column space, m × rank.
    basis: DMatrix<f64>,
    /// A⁺, q × m.
    pinv: DMatrix<f64>,
}

fn distinct(values: impl Iterator<Item = f64>) -> usize {
    let mut v: Vec<f64> = values.collect();
    v.sort_by(f64::total_cmp);
    let mut count = 0;
    let mut last: Option<f64> = None;
    for x in v {
        if last.is_none_or(|l| x.is_nan() || x > SAME_ACCEL_RATIO * l) {
            count += 1;
            last = Some(x);
        }
    }
    count
}

impl Statics {
    /// The groups of `tests` (plane, circle centre, acceleration and direction per test) and
    /// their static terms under `mode`; `reversal` forces reversal terms for the groups named
    /// (indices), as [`StaticTerms::Auto`] does after its test.
    pub fn new(
        tests: &[(Plane, Vec<f64>, f64, Direction)],
        rows: &[Row],
        mode: StaticTerms,
        reversal: &[usize],
    ) -> Statics {
        Self::assemble(tests, rows, mode, reversal).decomposed()
    }

    /// As [`Statics::new`] without the decomposition of A (projections are the identity until
    /// [`Statics::decomposed`]): for comparing A before paying for its SVD.
    pub(crate) fn assemble(
        tests: &[(Plane, Vec<f64>, f64, Direction)],
        rows: &[Row],
        mode: StaticTerms,
        reversal: &[usize],
    ) -> Statics {
        let mut groups: Vec<StaticGroup> = Vec::new();
        for (i, (plane, pos, _, _)) in tests.iter().enumerate() {
            match groups
                .iter_mut()
                .find(|g| g.plane == *plane && &g.position_m == pos)
            {
                Some(g) => g.tests.push(i),
                None => groups.push(StaticGroup {
                    plane: *plane,
                    position_m: pos.clone(),
                    tests: vec![i],
                    shared: false,
                    reversal: false,
                    reversal_possible: false,
                    note: None,
                }),
            }
        }
        for (k, g) in groups.iter_mut().enumerate() {
            let accels = |d: Option<Direction>| {
                distinct(
                    g.tests
                        .iter()
                        .filter(|&&t| d.is_none_or(|d| tests[t].3 == d))
                        .map(|&t| tests[t].2),
                )
            };
            let all = accels(None);
            g.reversal_possible =
                accels(Some(Direction::Cw)) >= 2 && accels(Some(Direction::Ccw)) >= 2;
            if mode == StaticTerms::None {
                continue;
            }
            if all < 2 {
                g.note = Some(super::Note::StaticsNotSeparable { group: g.label() });
                continue;
            }
            g.shared = true;
            g.reversal =
                g.reversal_possible && (mode == StaticTerms::PerDirection || reversal.contains(&k));
        }
        let mut columns = Vec::new();
        for (k, g) in groups.iter().enumerate() {
            let mut eijs: Vec<Eij> = rows
                .iter()
                .filter(|r| g.tests.contains(&r.test))
                .map(|r| r.eij)
                .collect();
            eijs.sort();
            eijs.dedup();
            for reversal in [false, true] {
                if (!reversal && g.shared) || (reversal && g.reversal) {
                    columns.extend(eijs.iter().map(|&eij| StaticColumn {
                        group: k,
                        eij,
                        reversal,
                        clock: None,
                    }));
                }
            }
        }
        let group_of: Vec<usize> = (0..tests.len())
            .map(|t| {
                groups
                    .iter()
                    .position(|g| g.tests.contains(&t))
                    .unwrap_or(0)
            })
            .collect();
        let a = DMatrix::from_fn(rows.len(), columns.len(), |i, c| {
            let (row, col) = (&rows[i], &columns[c]);
            if group_of[row.test] != col.group || row.eij != col.eij {
                return 0.0;
            }
            let sign = if col.reversal {
                row.direction.sign()
            } else {
                1.0
            };
            -sign * row.r_over_a / row.sigma
        });
        Statics {
            groups,
            columns,
            clocks: Vec::new(),
            basis: DMatrix::zeros(a.nrows(), 0),
            pinv: DMatrix::zeros(a.ncols(), a.nrows()),
            a,
        }
    }

    /// The projection onto the complement of A's columns computed (SVD of A).
    pub(crate) fn decomposed(mut self) -> Statics {
        let (basis, pinv) = decompose(&self.a);
        self.basis = basis;
        self.pinv = pinv;
        self
    }

    /// Adds a clock-offset term per clock whose tests hold both directions (`clock_of[test]`
    /// names each test's clock; see the module docs): external readings late by δ (ms) read
    /// x(t − δ) ≈ x − δ·v and shift the cross-talk of plane (a, b) by Ê_ab −= 10³·δ/ω,
    /// Ê_ba += 10³·δ/ω (ω signed, rad/s; [`crate::rtest::clock_fit`];
    /// `tests/rtest_clock_sign.rs`), so the column's entries are ∓10³/(ωσ) in those rows and
    /// the fitted δ is positive for late external readings (`external_late_ms`). The
    /// path's speed is taken as the set speed (ρ = r): a servo radius error of 1 % scales δ by
    /// 1 %.
    /// A velocity-proportional structural deviation (damping) has the same shape, but the model
    /// predicts it, so only a true offset is left for δ.
    pub fn with_clocks(self, clock_of: &[String], rows: &[Row], planes: &[Plane]) -> Statics {
        self.add_clocks(clock_of, rows, planes).decomposed()
    }

    /// As [`Statics::with_clocks`] without the decomposition (see [`Statics::assemble`]).
    pub(crate) fn add_clocks(
        mut self,
        clock_of: &[String],
        rows: &[Row],
        planes: &[Plane],
    ) -> Statics {
        let mut names: Vec<String> = clock_of.to_vec();
        names.sort();
        names.dedup();
        for name in names {
            let tests: Vec<usize> = (0..clock_of.len())
                .filter(|&t| clock_of[t] == name)
                .collect();
            let dirs = |d: Direction| {
                rows.iter()
                    .any(|r| tests.contains(&r.test) && r.direction == d)
            };
            if !(dirs(Direction::Cw) && dirs(Direction::Ccw)) {
                continue;
            }
            let k = self.clocks.len();
            self.clocks.push(name);
            self.columns.push(StaticColumn {
                group: 0,
                eij: rows
                    .first()
                    .map(|r| r.eij)
                    .unwrap_or(Eij::new(crate::axes::Axis::X, crate::axes::Axis::X)),
                reversal: false,
                clock: Some(k),
            });
            let col = DVector::from_iterator(
                rows.len(),
                rows.iter().map(|r| {
                    if !tests.contains(&r.test) {
                        return 0.0;
                    }
                    let (a, b) = planes[r.test].axes();
                    let s = if r.eij == Eij::new(a, b) {
                        1.0
                    } else if r.eij == Eij::new(b, a) {
                        -1.0
                    } else {
                        return 0.0;
                    };
                    // 1/ω = sgn·√(r/a), r in m.
                    let inv_omega = r.direction.sign() * (r.r_over_a * 1e-3).sqrt();
                    // The residual is model − measurement: the measured shift enters with −.
                    -s * 1e3 * inv_omega / r.sigma
                }),
            );
            self.a = self.a.clone().insert_column(self.a.ncols(), 0.0);
            let last = self.a.ncols() - 1;
            self.a.set_column(last, &col);
        }
        self
    }

    /// Number of static terms q.
    pub fn len(&self) -> usize {
        self.columns.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.columns.is_empty()
    }

    /// Rank of A (the degrees of freedom the static terms take).
    pub fn rank(&self) -> usize {
        self.basis.ncols()
    }

    /// P·v: `v` without its part in A's column space.
    pub(crate) fn project(&self, v: &DVector<f64>) -> DVector<f64> {
        if self.basis.ncols() == 0 {
            return v.clone();
        }
        v - &self.basis * (self.basis.transpose() * v)
    }

    /// P·J, column by column.
    pub(crate) fn project_matrix(&self, j: &DMatrix<f64>) -> DMatrix<f64> {
        if self.basis.ncols() == 0 {
            return j.clone();
        }
        j - &self.basis * (self.basis.transpose() * j)
    }

    /// χ² that the reversal terms of group `g` would remove from the projected residuals
    /// `r_p` (which are already orthogonal to A), and their number k.
    pub(crate) fn reversal_gain(&self, g: usize, rows: &[Row], r_p: &DVector<f64>) -> (f64, usize) {
        let group = &self.groups[g];
        let mut eijs: Vec<Eij> = rows
            .iter()
            .filter(|r| group.tests.contains(&r.test))
            .map(|r| r.eij)
            .collect();
        eijs.sort();
        eijs.dedup();
        let b = DMatrix::from_fn(rows.len(), eijs.len(), |i, c| {
            let row = &rows[i];
            if !group.tests.contains(&row.test) || row.eij != eijs[c] {
                return 0.0;
            }
            -row.direction.sign() * row.r_over_a / row.sigma
        });
        let (basis, _) = decompose(&self.project_matrix(&b));
        let k = basis.ncols();
        ((basis.transpose() * r_p).norm_squared(), k)
    }

    /// The static terms' estimates g = −A⁺·r_raw and their standard errors
    /// √diag(s²·A⁺A⁺ᵀ + A⁺J·cov_θ·JᵀA⁺ᵀ), from the raw (unprojected) weighted errors, the
    /// Jacobian of the free parameters and their covariance (θ units).
    pub fn estimates(
        &self,
        r_raw: &DVector<f64>,
        j: &DMatrix<f64>,
        cov_theta: &DMatrix<f64>,
        s2: f64,
    ) -> Vec<(f64, f64)> {
        if self.is_empty() {
            return Vec::new();
        }
        let g = -(&self.pinv * r_raw);
        let pj = &self.pinv * j;
        let cov = &self.pinv * self.pinv.transpose() * s2 + &pj * cov_theta * pj.transpose();
        (0..self.len())
            .map(|c| (g[c], cov[(c, c)].max(0.0).sqrt()))
            .collect()
    }

    /// A (weighted), m × q.
    pub fn matrix(&self) -> &DMatrix<f64> {
        &self.a
    }
}

/// Orthonormal basis of the column space of `a` and its pseudo-inverse, by SVD (singular
/// values below 1e-10 of the largest count as zero).
fn decompose(a: &DMatrix<f64>) -> (DMatrix<f64>, DMatrix<f64>) {
    let (m, q) = a.shape();
    if q == 0 || m == 0 {
        return (DMatrix::zeros(m, 0), DMatrix::zeros(q, m));
    }
    let Some(svd) = a.clone().try_svd(true, true, f64::EPSILON, 10_000) else {
        return (DMatrix::zeros(m, 0), DMatrix::zeros(q, m));
    };
    let (Some(u), Some(v_t)) = (svd.u.as_ref(), svd.v_t.as_ref()) else {
        return (DMatrix::zeros(m, 0), DMatrix::zeros(q, m));
    };
    let sv = &svd.singular_values;
    let largest = sv.max();
    let keep: Vec<usize> = (0..sv.len()).filter(|&k| sv[k] > 1e-10 * largest).collect();
    let basis = DMatrix::from_fn(m, keep.len(), |i, c| u[(i, keep[c])]);
    let mut pinv = DMatrix::zeros(q, m);
    for &k in &keep {
        pinv += v_t.row(k).transpose() * u.column(k).transpose() / sv[k];
    }
    (basis, pinv)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::axes::Axis;

    fn rows_of(tests: &[(Plane, Vec<f64>, f64, Direction)]) -> Vec<Row> {
        let eij = Eij::new(Axis::X, Axis::Z);
        tests
            .iter()
            .enumerate()
            .map(|(i, t)| Row {
                test: i,
                eij,
                sigma: 0.1,
                r_over_a: 2.0 / t.2,
                direction: t.3,
            })
            .collect()
    }

    #[test]
    fn a_static_term_is_recovered_and_projected_out() {
        // Ê = E − G·r/a with E = −1.5, G = 0.8 µm/mm at a = 2, 5, 8 m/s², cw and ccw.
        let pos = vec![0.0, 0.0, 0.0];
        let tests: Vec<_> = [2.0, 5.0, 8.0]
            .iter()
            .flat_map(|&a| Direction::ALL.map(|d| (Plane::Zx, pos.clone(), a, d)))
            .collect();
        let rows = rows_of(&tests);
        let s = Statics::new(&tests, &rows, StaticTerms::Auto, &[]);
        assert_eq!(s.len(), 1);
        assert!(s.groups[0].shared && !s.groups[0].reversal && s.groups[0].reversal_possible);
        // The model predicts E exactly: the raw weighted errors are (E − Ê)/σ = G·r/a/σ.
        let r_raw = DVector::from_iterator(rows.len(), rows.iter().map(|r| 0.8 * r.r_over_a / 0.1));
        assert!(s.project(&r_raw).norm() < 1e-12);
        let j = DMatrix::from_element(rows.len(), 1, 1.0);
        let est = s.estimates(&r_raw, &j, &DMatrix::zeros(1, 1), 1.0);
        assert!((est[0].0 - 0.8).abs() < 1e-12, "{est:?}");
        // σ(G) alone: 1/‖A‖ = σ/√Σ(r/a)².
        let want = 0.1 / rows.iter().map(|r| r.r_over_a.powi(2)).sum::<f64>().sqrt();
        assert!((est[0].1 - want).abs() < 1e-12);
        // A constant E error is not absorbed (it does not go with 1/a).
        let e = DVector::from_element(rows.len(), 1.0);
        assert!(s.project(&e).norm() > 0.3 * e.norm());
    }

    #[test]
    fn one_acceleration_or_one_direction_limits_the_terms() {
        let pos = vec![0.0, 0.0, 0.0];
        let one: Vec<_> = Direction::ALL
            .map(|d| (Plane::Xy, pos.clone(), 5.0, d))
            .to_vec();
        let s = Statics::new(&one, &rows_of(&one), StaticTerms::PerDirection, &[]);
        assert!(s.is_empty());
        assert_eq!(
            s.groups[0].note,
            Some(super::super::Note::StaticsNotSeparable {
                group: s.groups[0].label()
            })
        );
        let ccw: Vec<_> = [2.0, 8.0]
            .map(|a| (Plane::Xy, pos.clone(), a, Direction::Ccw))
            .to_vec();
        let s = Statics::new(&ccw, &rows_of(&ccw), StaticTerms::PerDirection, &[]);
        assert_eq!(
            s.len(),
            1,
            "shared only: one direction cannot carry a reversal term"
        );
    }

    #[test]
    fn a_reversal_term_is_seen_by_its_gain() {
        let pos = vec![0.0, 0.0, 0.0];
        let tests: Vec<_> = [2.0, 5.0, 8.0]
            .iter()
            .flat_map(|&a| Direction::ALL.map(|d| (Plane::Zx, pos.clone(), a, d)))
            .collect();
        let rows = rows_of(&tests);
        let s = Statics::new(&tests, &rows, StaticTerms::Auto, &[]);
        // A reversal of 0.5 µm/mm: sgn(ω)·G_rev·r/a.
        let r_raw = DVector::from_iterator(
            rows.len(),
            rows.iter()
                .map(|r| r.direction.sign() * 0.5 * r.r_over_a / 0.1),
        );
        let r_p = s.project(&r_raw);
        let (gain, k) = s.reversal_gain(0, &rows, &r_p);
        assert_eq!(k, 1);
        assert!((gain - r_p.norm_squared()).abs() < 1e-9 * gain && gain > 1.0);
        let with = Statics::new(&tests, &rows, StaticTerms::Auto, &[0]);
        assert_eq!(with.len(), 2);
        assert!(with.project(&r_raw).norm() < 1e-12);
    }
}
