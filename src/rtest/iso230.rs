//! ISO 230-4 figures of a circular path (ISO 230-4:2005, section 3): circular deviation G,
//! radial deviation F and the bi-directional circular deviation G(b) of a cw/ccw pair, for the
//! internal path (the axes' own readings, ISO 230-4 Annex E "feedback signal") and the external
//! one (the R-Test's TCP relative to the nest), over the steady revolutions.
//!
//! Centres are least-squares circle centres. The fit is the algebraic (Kåsa) one of
//! [`super::normalise::circle_centre`]; on circles whose deviations are small against the
//! radius it equals the geometric least-squares centre to second order (for 10 µm on 2 mm, to
//! 0.05 µm), far below what G resolves.

use super::normalise::circle_centre;

/// The ISO 230-4 figures of one path.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PathFigures {
    /// Circular deviation G: the radial range (largest minus smallest radius) about the
    /// least-squares centre, µm.
    pub circular_deviation_um: f64,
    /// Radial deviation F, largest: the largest radius about the least-squares centre minus the
    /// nominal radius, µm.
    pub radial_deviation_max_um: f64,
    /// Radial deviation F, smallest (negative inside the nominal circle), µm.
    pub radial_deviation_min_um: f64,
    /// Mean radius about the least-squares centre minus the nominal radius, µm.
    pub mean_radius_deviation_um: f64,
    /// The least-squares centre (a, b) in the plane, mm.
    pub centre_mm: [f64; 2],
}

/// The figures of both paths of a test.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CircleFigures {
    /// The nominal (set) radius the radial deviations refer to, mm.
    pub nominal_radius_mm: f64,
    /// The internal path (axis readings).
    pub internal: PathFigures,
    /// The external path (R-Test).
    pub external: PathFigures,
}

/// Radii (mm) of the points about `centre`.
fn radii<'a>(a: &'a [f64], b: &'a [f64], centre: [f64; 2]) -> impl Iterator<Item = f64> + 'a {
    a.iter()
        .zip(b)
        .map(move |(x, y)| (x - centre[0]).hypot(y - centre[1]))
}

/// The figures of one path (in-plane coordinates a, b in mm) against the nominal radius;
/// `None` when no centre can be fitted (fewer than four points, or all on a line).
pub fn path_figures(a: &[f64], b: &[f64], nominal_radius_mm: f64) -> Option<PathFigures> {
    if a.len() < 4 {
        return None;
    }
    let centre = circle_centre(a, b)?;
    let (mut lo, mut hi, mut sum) = (f64::INFINITY, f64::NEG_INFINITY, 0.0);
    for r in radii(a, b, centre) {
        lo = lo.min(r);
        hi = hi.max(r);
        sum += r;
    }
    let mean = sum / a.len() as f64;
    Some(PathFigures {
        circular_deviation_um: (hi - lo) * 1e3,
        radial_deviation_max_um: (hi - nominal_radius_mm) * 1e3,
        radial_deviation_min_um: (lo - nominal_radius_mm) * 1e3,
        mean_radius_deviation_um: (mean - nominal_radius_mm) * 1e3,
        centre_mm: centre,
    })
}

/// Bi-directional circular deviation G(b), µm: the radial range of the two paths of a cw/ccw
/// pair superimposed, about the least-squares centre of both together (ISO 230-4, 3.4).
pub fn bidirectional_deviation(paths: [(&[f64], &[f64]); 2]) -> Option<f64> {
    let a: Vec<f64> = paths[0].0.iter().chain(paths[1].0).copied().collect();
    let b: Vec<f64> = paths[0].1.iter().chain(paths[1].1).copied().collect();
    if a.len() < 4 {
        return None;
    }
    let centre = circle_centre(&a, &b)?;
    let (lo, hi) = radii(&a, &b, centre).fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), r| {
        (l.min(r), h.max(r))
    });
    Some((hi - lo) * 1e3)
}
