//! One source of one test: design, fit, terms with values and standard errors, their
//! contributions to G, the ranking and the residual.

use super::basis::Circle;
use super::decompose::{
    circular_deviation, normal_design, normal_model, range, rms, solve_in_plane, solve_normal,
    InPlaneDesign, Solved,
};
use super::terms::{self, Combine, Family, Spec};
use super::{CrossingValue, Curves, DiagnosisOptions, Figure, Note, Source, SourceDiagnosis, Term};
use crate::axes::Plane;

/// A source's deviation over the steady revolutions, µm.
#[derive(Debug, Clone, Default)]
pub(super) struct Deviation {
    /// Radial.
    pub radial_um: Vec<f64>,
    /// Tangential (ccw positive).
    pub tangential_um: Vec<f64>,
    /// Along the plane's normal.
    pub normal_um: Vec<f64>,
}

impl Deviation {
    /// Empty, room for `n` samples.
    pub(super) fn with_capacity(n: usize) -> Self {
        Deviation {
            radial_um: Vec::with_capacity(n),
            tangential_um: Vec::with_capacity(n),
            normal_um: Vec::with_capacity(n),
        }
    }
}

/// The families dropped, last first, until the in-plane design has a unique solution.
const DROP_ORDER: [Family; 5] = [
    Family::Cyclic,
    Family::Spike,
    Family::Straightness,
    Family::LateralPlay,
    Family::Core,
];

/// Decomposes one source; `None` when even the core terms have no unique solution.
pub(super) fn fit_source(
    source: Source,
    plane: Plane,
    circle: &Circle,
    theta: &[f64],
    dev: &Deviation,
    opts: &DiagnosisOptions,
) -> Option<SourceDiagnosis> {
    let mut notes = Vec::new();
    let (mut in_specs, design, solved) = DROP_ORDER.iter().find_map(|&keep| {
        let (cols, specs) = terms::in_plane(plane, opts, keep);
        let design = InPlaneDesign::new(&cols, circle, theta);
        let solved = solve_in_plane(&design, &dev.radial_um, &dev.tangential_um)?;
        Some((specs, design, solved))
    })?;
    let (full_cols, full_specs) = terms::in_plane(plane, opts, Family::Cyclic);
    if full_cols.len() > design.radial.ncols() {
        let kept: Vec<&str> = in_specs.iter().map(|s| s.name.as_str()).collect();
        let dropped: Vec<&str> = full_specs
            .iter()
            .map(|s| s.name.as_str())
            .filter(|n| !kept.contains(n))
            .collect();
        notes.push(Note::LeftOut {
            terms: dropped.into_iter().map(str::to_string).collect(),
        });
    }
    let (n_cols, n_specs) = terms::normal(plane);
    let n_design = normal_design(&n_cols, circle, theta);
    let n_solved = solve_normal(&n_design, &dev.normal_um)?;

    let r = circle.radius_mm;
    let all: Vec<usize> = (0..design.radial.ncols()).collect();
    let [mr, mt] = design.model(&solved.coef, &all);
    let res_r: Vec<f64> = dev.radial_um.iter().zip(&mr).map(|(d, m)| d - m).collect();
    let res_t: Vec<f64> = dev
        .tangential_um
        .iter()
        .zip(&mt)
        .map(|(d, m)| d - m)
        .collect();
    let n_all: Vec<usize> = (0..n_design.ncols()).collect();
    let mn = normal_model(&n_design, &n_solved.coef, &n_all);
    let res_n: Vec<f64> = dev.normal_um.iter().zip(&mn).map(|(d, m)| d - m).collect();

    let mut in_plane: Vec<Term> = in_specs
        .drain(..)
        .filter(|spec| {
            source == Source::Structure || !terms::REFERENCE.contains(&spec.name.as_str())
        })
        .map(|spec| {
            let [er, et] = design.model(&solved.coef, &spec.columns);
            let g = circular_deviation(r, theta, [&er, &et]);
            term(&spec, &solved, g, Figure::CircularDeviation, plane)
        })
        .collect();
    let mut out_of_plane: Vec<Term> = n_specs
        .iter()
        .map(|spec| {
            let pv = range(&normal_model(&n_design, &n_solved.coef, &spec.columns));
            term(spec, &n_solved, pv, Figure::OutOfPlane, plane)
        })
        .collect();
    let by_contribution = |x: &Term, y: &Term| y.contribution_um.total_cmp(&x.contribution_um);
    in_plane.sort_by(by_contribution);
    out_of_plane.sort_by(by_contribution);
    in_plane.extend(out_of_plane);
    if let Some(sq) = in_plane.iter_mut().find(|t| t.name == "squareness") {
        sq.notes.push(Note::SquarenessWithServo);
    }
    let zeros = vec![0.0; theta.len()];
    Some(SourceDiagnosis {
        source,
        terms: in_plane,
        residual_um: rms(&res_r),
        residual_tangential_um: rms(&res_t),
        residual_normal_um: rms(&res_n),
        residual_contribution_um: circular_deviation(r, theta, [&res_r, &zeros]),
        circular_deviation_um: circular_deviation(r, theta, [&dev.radial_um, &dev.tangential_um]),
        circular_deviation_terms_um: circular_deviation(r, theta, [&mr, &mt]),
        notes,
        curves: Curves {
            theta: theta.to_vec(),
            radial_um: dev.radial_um.clone(),
            radial_model_um: mr,
        },
    })
}

/// A term's value, standard error, phase and crossings from the solved coefficients.
fn term(spec: &Spec, solved: &Solved, contribution_um: f64, figure: Figure, plane: Plane) -> Term {
    let c = &solved.coef;
    let cols = &spec.columns;
    let mut phase_deg = None;
    let mut crossings = Vec::new();
    let (value, std_err) = match spec.combine {
        Combine::One => (c[cols[0]], solved.std_err_of(&cols[..1], &[1.0])),
        Combine::Mean(pair) => {
            let (a, b) = plane.axes();
            for (x, &col) in pair.iter().zip(cols) {
                let axis = if x.axis == 0 { a } else { b };
                crossings.push(CrossingValue {
                    side: format!("{axis}{}", if x.positive { '+' } else { '-' }),
                    at_deg: x.angle().to_degrees(),
                    value: c[col],
                    std_err: solved.std_err_of(&[col], &[1.0]),
                });
            }
            (
                0.5 * (c[cols[0]] + c[cols[1]]),
                solved.std_err_of(cols, &[0.5, 0.5]),
            )
        }
        Combine::Amplitude => {
            let (x, y) = (c[cols[0]], c[cols[1]]);
            let amp = x.hypot(y);
            phase_deg = Some(y.atan2(x).to_degrees());
            // Delta method: the gradient of √(x² + y²) is (x, y)/amp; at amp = 0 the mean of
            // the two variances.
            let se = if amp > 0.0 {
                solved.std_err_of(cols, &[x / amp, y / amp])
            } else {
                (0.5 * (solved.cov[(cols[0], cols[0])] + solved.cov[(cols[1], cols[1])])).sqrt()
            };
            (amp, se)
        }
    };
    Term {
        name: spec.name.clone(),
        value,
        unit: spec.unit,
        std_err,
        axis: spec.axis,
        phase_deg,
        contribution_um,
        figure,
        crossings,
        notes: Vec::new(),
        limit: None,
        verdict: None,
    }
}
