//! Plausibility checks of a circle test (run by [`super::normalise::normalise`]): units of
//! length (µm or m in mm columns) and of time (ms or µs in a seconds column), dead or
//! unconnected probe channels, and the R-Test's measuring range.

use super::error::{Location, RtestError};
use super::series::{CircleSeries, EXT_COLUMNS, INT_COLUMNS};
use crate::axes::{Axis, Plane};
use std::f64::consts::TAU;

/// R-Test measuring range: |external − internal| must stay within this, mm.
pub const PROBE_RANGE_MM: f64 = 3.0;
/// Largest radius (mm) accepted for an R-Test circle before suspecting µm in mm columns.
const MAX_PLAUSIBLE_RADIUS_MM: f64 = 50.0;

/// Catches µm values written into mm columns: an external amplitude ≈ 1000× the internal one
/// (or the reverse), or a circle far too large for an R-Test (or ≈ 1000× the set radius).
pub(super) fn check_units(
    series: &CircleSeries,
    plane: Plane,
    amp_int: &[f64; 3],
    amp_ext: &[f64; 3],
    set_radius_mm: Option<f64>,
) -> Result<(), RtestError> {
    let whole = || Location::source(series.source());
    let thousandfold = |ratio: f64| (300.0..3000.0).contains(&ratio);
    let (a, b) = plane.axes();
    for ax in [a, b] {
        let (i, e) = (amp_int[ax.index()], amp_ext[ax.index()]);
        if thousandfold(e / i) {
            return Err(RtestError::LooksLikeMicrometres {
                at: whole(),
                column: EXT_COLUMNS[ax.index()].into(),
                detail: format!(
                    "amplitude ±{e:.4} is {:.0}× that of {}",
                    e / i,
                    INT_COLUMNS[ax.index()]
                ),
            });
        }
        if e > 0.0 && thousandfold(i / e) {
            return Err(RtestError::LooksLikeMicrometres {
                at: whole(),
                column: INT_COLUMNS[ax.index()].into(),
                detail: format!(
                    "amplitude ±{i:.4} is {:.0}× that of {}",
                    i / e,
                    EXT_COLUMNS[ax.index()]
                ),
            });
        }
    }
    let r0 = 0.5 * (amp_int[a.index()] + amp_int[b.index()]);
    let column = INT_COLUMNS[a.index()].to_string();
    if r0 > MAX_PLAUSIBLE_RADIUS_MM {
        let detail = format!(
            "circle radius {} is implausible for an R-Test circle",
            crate::text::num(if r0 < 1e6 {
                (r0 * 10.0).round() / 10.0
            } else {
                r0
            })
        );
        // Only where the values read as µm make a plausible circle is µm the likely slip.
        if r0 * 1e-3 > MAX_PLAUSIBLE_RADIUS_MM {
            return Err(RtestError::Implausible {
                at: whole(),
                column,
                detail: format!(
                    "{detail} (at most {MAX_PLAUSIBLE_RADIUS_MM} mm, and too large for µm as well)"
                ),
            });
        }
        return Err(RtestError::LooksLikeMicrometres {
            at: whole(),
            column,
            detail,
        });
    }
    if let Some(set) = set_radius_mm {
        if thousandfold(r0 / set) {
            return Err(RtestError::LooksLikeMicrometres {
                at: whole(),
                column,
                detail: format!("circle radius {r0:.1} is {:.0}× the set radius", r0 / set),
            });
        }
    }
    Ok(())
}

/// Plausible set accelerations of an R-Test circle, m/s² (outside: wrong units of time).
pub const PLAUSIBLE_ACCEL_M_S2: (f64, f64) = (0.01, 1000.0);
/// Plausible circle frequencies, Hz.
const PLAUSIBLE_FREQ_HZ: (f64, f64) = (0.01, 500.0);

/// A set acceleration r·ω² or a frequency far outside what circle tests use means the time
/// column is in other units than read: the error names the column and the unit that would
/// make the test plausible.
pub(super) fn check_time_scale(
    series: &CircleSeries,
    radius_mm: f64,
    omega: f64,
) -> Result<(), RtestError> {
    let plausible = |w: f64| {
        let (accel, freq) = (radius_mm * 1e-3 * w * w, w.abs() / TAU);
        (PLAUSIBLE_ACCEL_M_S2.0..=PLAUSIBLE_ACCEL_M_S2.1).contains(&accel)
            && (PLAUSIBLE_FREQ_HZ.0..=PLAUSIBLE_FREQ_HZ.1).contains(&freq)
    };
    if plausible(omega) {
        return Ok(());
    }
    let (accel, freq) = (radius_mm * 1e-3 * omega * omega, omega.abs() / TAU);
    // Times read f× too large (f = 1000: ms read as s) give ω f× too small.
    let hint = [
        (1e3, "1000× too large (ms read as s?)"),
        (1e6, "10⁶× too large (µs read as s?)"),
        (1e-3, "1000× too small (s read as ms?)"),
        (1e-6, "10⁶× too small (s read as µs?)"),
    ]
    .into_iter()
    .find(|(f, _)| plausible(omega * f))
    .map_or(String::new(), |(f, what)| {
        let w = omega * f;
        format!(
            "; the times look {what}: then {:.3} m/s² at {:.3} Hz. State the unit in rtest.toml [columns], e.g. t_s = {{ unit = \"ms\" }}",
            radius_mm * 1e-3 * w * w,
            w.abs() / TAU
        )
    });
    Err(RtestError::Implausible {
        at: Location::source(series.source()),
        column: series.column_label("t_s"),
        detail: format!(
            "set acceleration {accel:.3e} m/s² at {freq:.4} Hz is implausible for a circle test \
             (expected {}–{} m/s², {}–{} Hz){hint}",
            PLAUSIBLE_ACCEL_M_S2.0,
            PLAUSIBLE_ACCEL_M_S2.1,
            PLAUSIBLE_FREQ_HZ.0,
            PLAUSIBLE_FREQ_HZ.1
        ),
    })
}

/// The external readings must follow the circle: an in-plane external column that moves less
/// than half as much as its internal one, or (in a file) an external column that is constant
/// over the whole file, is a dead or unconnected probe channel, not a deviation.
pub(super) fn check_external(
    series: &CircleSeries,
    plane: Plane,
    amp_int: &[f64; 3],
    amp_ext: &[f64; 3],
) -> Result<(), RtestError> {
    let (a, b) = plane.axes();
    for ax in [a, b] {
        let (i, e) = (amp_int[ax.index()], amp_ext[ax.index()]);
        if e < 0.5 * i {
            return Err(RtestError::Implausible {
                at: Location::source(series.source()),
                column: series.column_label(EXT_COLUMNS[ax.index()]),
                detail: format!(
                    "moves ±{e:.4} mm while {} moves ±{i:.4} mm: the R-Test does not follow the \
                     circle (dead or unconnected probe channel?)",
                    series.column_label(INT_COLUMNS[ax.index()])
                ),
            });
        }
    }
    // Noise-free series built in memory (simulations, synthetic tests) may hold an exactly
    // constant normal component; a file from a real probe never does.
    for ax in Axis::ALL.into_iter().filter(|_| series.is_from_file()) {
        if amp_ext[ax.index()] == 0.0 {
            return Err(RtestError::Implausible {
                at: Location::source(series.source()),
                column: series.column_label(EXT_COLUMNS[ax.index()]),
                detail: format!(
                    "constant ({}) over the whole file: a real probe reading is never constant \
                     (dead or unconnected probe channel?)",
                    series.ext_mm(ax)[0]
                ),
            });
        }
    }
    Ok(())
}

/// |external − internal| must stay within the R-Test range on every row and axis. The error
/// names the first row out of range; it suggests µm when most rows are out of range but all
/// would be in range with the external column read as µm.
pub(super) fn check_probe_range(series: &CircleSeries) -> Result<(), RtestError> {
    for ax in Axis::ALL {
        let (int, ext) = (series.int_mm(ax), series.ext_mm(ax));
        let out_of_range = |(&i, &e): (&f64, &f64)| (e - i).abs() > PROBE_RANGE_MM;
        if let Some(row) = int.iter().zip(ext).position(out_of_range) {
            let outside = int.iter().zip(ext).filter(|p| out_of_range(*p)).count();
            let as_um_in_range = int
                .iter()
                .zip(ext)
                .all(|(&i, &e)| (e * 1e-3 - i).abs() <= PROBE_RANGE_MM);
            return Err(RtestError::ProbeRange {
                at: series.at_row(row),
                axis: ax,
                deviation_mm: ext[row] - int[row],
                range_mm: PROBE_RANGE_MM,
                looks_like_um: as_um_in_range && 2 * outside > int.len(),
            });
        }
    }
    Ok(())
}
