//! EIJ maps over the workspace: the position-dependent model evaluated on a grid of axis
//! positions (harmonic steady state, the same simulation and evaluation as the
//! identification: [`crate::predict`]), as a compensation table position → EIJ.

use crate::axes::{Axis, Direction, Eij, EijMap, Plane};
use crate::machine::Machine;
use crate::predict::{simulated_eij, CircleTest, PredictError, SimSettings};
use std::collections::BTreeMap;

/// Errors of a map.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MapError {
    /// A grid that does not fit the machine.
    #[error("grid {spec}: {message}")]
    Grid {
        /// The grid specification given.
        spec: String,
        /// What is wrong.
        message: String,
    },
    /// A plane that the machine cannot run a circle in.
    #[error("plane {plane}: {message}")]
    Plane {
        /// The plane given.
        plane: Plane,
        /// What is wrong.
        message: String,
    },
    /// A grid point the model cannot be evaluated at (boxed: the error is large).
    #[error(transparent)]
    Predict(Box<PredictError>),
    /// A map table that cannot be read.
    #[error("{at}: {message}")]
    Table {
        /// File and line.
        at: String,
        /// What is wrong.
        message: String,
    },
}

impl From<PredictError> for MapError {
    fn from(e: PredictError) -> Self {
        MapError::Predict(Box::new(e))
    }
}

/// Most grid points of one map (all grids multiplied): bounds time and memory; a compensation
/// table of 21 × 21 × 21 positions has 9 261.
pub(crate) const MAX_POINTS: usize = 100_000;

/// Grid values of one axis: `min:max:count` in mm (count ≥ 1; count 1 takes `min`).
#[derive(Debug, Clone, PartialEq)]
pub struct AxisGrid {
    /// The axis.
    pub axis: Axis,
    /// Positions, m.
    pub values_m: Vec<f64>,
}

impl AxisGrid {
    /// Parses `x=-250:250:5` (mm).
    pub fn parse(spec: &str) -> Result<AxisGrid, MapError> {
        let bad = |m: &str| MapError::Grid {
            spec: spec.to_string(),
            message: m.to_string(),
        };
        let (axis, range) = spec
            .split_once('=')
            .ok_or_else(|| bad("expected <axis>=<min>:<max>:<count>, e.g. x=-250:250:5 (mm)"))?;
        let axis: Axis = axis.trim().parse().map_err(|m: String| bad(&m))?;
        let parts: Vec<&str> = range.split(':').collect();
        if parts.len() != 3 {
            return Err(bad("expected <min>:<max>:<count>"));
        }
        let lo: f64 = parts[0]
            .trim()
            .parse()
            .map_err(|_| bad("min is not a number"))?;
        let hi: f64 = parts[1]
            .trim()
            .parse()
            .map_err(|_| bad("max is not a number"))?;
        let n: usize = parts[2]
            .trim()
            .parse()
            .map_err(|_| bad("count is not a whole number"))?;
        if !(lo.is_finite() && hi.is_finite()) || n == 0 || (n > 1 && hi <= lo) {
            return Err(bad("need finite min < max and count ≥ 1"));
        }
        if n > MAX_POINTS {
            return Err(bad(&format!("count {n} exceeds {MAX_POINTS} points")));
        }
        let values_m = (0..n)
            .map(|i| if n == 1 { lo } else { lo + (hi - lo) * i as f64 / (n - 1) as f64 } * 1e-3)
            .collect();
        Ok(AxisGrid { axis, values_m })
    }
}

/// The circle evaluated at every grid point.
#[derive(Debug, Clone, PartialEq)]
pub struct MapSpec {
    /// Plane.
    pub plane: Plane,
    /// Direction.
    pub direction: Direction,
    /// Radius, m.
    pub radius_m: f64,
    /// Set acceleration, m/s².
    pub accel_m_s2: f64,
}

/// One grid point of a map.
#[derive(Debug, Clone, PartialEq)]
pub struct MapPoint {
    /// Axis positions in machine axis order, m.
    pub position_m: Vec<f64>,
    /// The six EIJ of the plane, µm·s²/m.
    pub eij: EijMap,
}

/// EIJ over the grid (axes without a grid stay at their reference position), in parallel;
/// points in row-major order of the grids as given.
pub fn eij_map(
    machine: &Machine,
    grids: &[AxisGrid],
    spec: &MapSpec,
) -> Result<Vec<MapPoint>, MapError> {
    eij_map_with_progress(machine, grids, spec, &|_, _| {})
}

/// Grid points simulated between two calls of a map's progress callback.
const PROGRESS_CHUNK: usize = 64;

/// As [`eij_map`], calling `progress(done, total)` with the grid points simulated so far (for
/// a progress bar; every [`PROGRESS_CHUNK`] points).
pub fn eij_map_with_progress(
    machine: &Machine,
    grids: &[AxisGrid],
    spec: &MapSpec,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Vec<MapPoint>, MapError> {
    let (a, b) = spec.plane.axes();
    for ax in [a, b] {
        if machine.axis(ax).is_none() {
            return Err(MapError::Plane {
                plane: spec.plane,
                message: format!("the machine {} has no axis {ax}", machine.name()),
            });
        }
    }
    let mut index = Vec::new();
    for g in grids {
        let i = machine
            .axes()
            .iter()
            .position(|a| a.axis == g.axis)
            .ok_or_else(|| MapError::Grid {
                spec: g.axis.to_string(),
                message: format!("the machine {} has no axis {}", machine.name(), g.axis),
            })?;
        if index.contains(&i) {
            return Err(MapError::Grid {
                spec: g.axis.to_string(),
                message: "axis given twice".into(),
            });
        }
        let [lo, hi] = machine.axes()[i].stroke_m;
        if g.values_m.iter().any(|v| *v < lo || *v > hi) {
            return Err(MapError::Grid {
                spec: g.axis.to_string(),
                message: format!("outside the stroke [{}, {}] mm", lo * 1e3, hi * 1e3),
            });
        }
        index.push(i);
    }
    let points = grids
        .iter()
        .try_fold(1usize, |n, g| n.checked_mul(g.values_m.len()))
        .unwrap_or(usize::MAX);
    if points > MAX_POINTS {
        return Err(MapError::Grid {
            spec: grids
                .iter()
                .map(|g| g.axis.to_string())
                .collect::<Vec<_>>()
                .join(", "),
            message: format!("{points} grid points, at most {MAX_POINTS}"),
        });
    }
    let mut positions = vec![machine.reference_pose().to_vec()];
    for (g, &i) in grids.iter().zip(&index) {
        positions = positions
            .into_iter()
            .flat_map(|p| {
                g.values_m.iter().map(move |v| {
                    let mut q = p.clone();
                    q[i] = *v;
                    q
                })
            })
            .collect();
    }
    // The same simulation and evaluation as the identification, one test per grid point.
    let tests: Vec<CircleTest> = positions
        .iter()
        .map(|p| {
            CircleTest::new(
                spec.plane,
                spec.direction,
                spec.radius_m * 1e3,
                spec.accel_m_s2,
            )
            .at(p.clone())
        })
        .collect();
    let mut sims = Vec::with_capacity(tests.len());
    for chunk in tests.chunks(PROGRESS_CHUNK) {
        sims.extend(
            simulated_eij(
                std::slice::from_ref(machine),
                chunk,
                &SimSettings::default(),
            )?
            .remove(0),
        );
        progress(sims.len(), tests.len());
    }
    Ok(positions
        .into_iter()
        .zip(sims)
        .map(|(position_m, eij)| MapPoint { position_m, eij })
        .collect())
}

/// The compensation table as CSV: `x_mm,y_mm,z_mm,plane,direction,radius_mm,accel_m_s2`, then
/// one `<EIJ>_um_s2_per_m` column per parameter of the plane, then `machine` (its name, so
/// that a figure of the table says which machine it maps).
pub fn to_csv(machine: &Machine, spec: &MapSpec, points: &[MapPoint]) -> String {
    let params = spec.plane.parameters();
    let mut out = String::from("x_mm,y_mm,z_mm,plane,direction,radius_mm,accel_m_s2");
    for p in &params {
        out.push_str(&format!(",{p}_um_s2_per_m"));
    }
    out.push_str(",machine\n");
    let name = csv_field(machine.name());
    for pt in points {
        let mut xyz = [0.0; 3];
        for (a, v) in machine.axes().iter().zip(&pt.position_m) {
            xyz[a.axis.index()] = v * 1e3;
        }
        out.push_str(&format!(
            "{:.3},{:.3},{:.3},{},{},{},{}",
            xyz[0],
            xyz[1],
            xyz[2],
            spec.plane,
            spec.direction,
            spec.radius_m * 1e3,
            spec.accel_m_s2
        ));
        for p in &params {
            out.push_str(&format!(",{:.6}", pt.eij[p]));
        }
        out.push(',');
        out.push_str(&name);
        out.push('\n');
    }
    out
}

/// A CSV field: quoted (quotes doubled) where it holds a separator, a quote or a line break.
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// A compensation table read back ([`read_csv`]).
#[derive(Debug, Clone, PartialEq)]
pub struct MapTable {
    /// The conditions of its circles.
    pub spec: MapSpec,
    /// Its grid points, positions in x, y, z order.
    pub points: Vec<MapPoint>,
    /// The machine it maps (`None` for tables written before the `machine` column).
    pub machine: Option<String>,
}

/// Reads a compensation table written by [`to_csv`] (with or without its `machine` column).
pub fn read_csv(path: &std::path::Path) -> Result<MapTable, MapError> {
    let name = path.display().to_string();
    let bad = |line: usize, m: String| MapError::Table {
        at: format!("{name}:{line}"),
        message: m,
    };
    let text = crate::io::read_input_text(path, crate::io::read::MAX_TEXT_BYTES).map_err(|e| {
        MapError::Table {
            at: name.clone(),
            message: format!("cannot read: {e}"),
        }
    })?;
    let mut reader = csv::ReaderBuilder::new().from_reader(text.as_bytes());
    let header: Vec<String> = reader
        .headers()
        .map_err(|e| bad(1, crate::io::delimited::csv_message(&e)))?
        .iter()
        .map(str::to_string)
        .collect();
    let fixed = [
        "x_mm",
        "y_mm",
        "z_mm",
        "plane",
        "direction",
        "radius_mm",
        "accel_m_s2",
    ];
    let with_machine = header.last().is_some_and(|h| h == "machine");
    let eij_end = header.len() - usize::from(with_machine);
    if eij_end != fixed.len() + 6 || header[..fixed.len()] != fixed {
        return Err(bad(
            1,
            format!(
                "not an eij map table (expected {},<six EIJ>_um_s2_per_m[,machine])",
                fixed.join(",")
            ),
        ));
    }
    let params: Vec<Eij> = header[fixed.len()..eij_end]
        .iter()
        .map(|h| h.strip_suffix("_um_s2_per_m").unwrap_or(h).parse::<Eij>())
        .collect::<Result<_, _>>()
        .map_err(|m| bad(1, m))?;
    if let Some((k, p)) = params
        .iter()
        .enumerate()
        .find(|(k, p)| params[..*k].contains(p))
    {
        return Err(bad(
            1,
            format!("column {}: {p} given twice", header[fixed.len() + k]),
        ));
    }
    let mut spec: Option<MapSpec> = None;
    let mut machine = None;
    let mut points: Vec<MapPoint> = Vec::new();
    // Grid positions as read, with their line: a point given twice would silently weigh twice.
    let mut seen: BTreeMap<[u64; 3], usize> = BTreeMap::new();
    for (i, rec) in reader.records().enumerate() {
        let line = i + 2;
        if points.len() >= MAX_POINTS {
            return Err(bad(line, format!("more than {MAX_POINTS} points")));
        }
        let rec = rec.map_err(|e| {
            let at = e.position().map_or(line, |p| p.line() as usize);
            bad(at, crate::io::delimited::csv_message(&e))
        })?;
        let num = |k: usize| -> Result<f64, MapError> {
            rec.get(k)
                .and_then(|v| v.trim().parse::<f64>().ok())
                .filter(|v| v.is_finite())
                .ok_or_else(|| bad(line, format!("column {}: not a finite number", header[k])))
        };
        let plane: Plane = rec.get(3).unwrap_or("").parse().map_err(|m| bad(line, m))?;
        let direction: Direction = rec.get(4).unwrap_or("").parse().map_err(|m| bad(line, m))?;
        let this = MapSpec {
            plane,
            direction,
            radius_m: num(5)? * 1e-3,
            accel_m_s2: num(6)?,
        };
        if spec.as_ref().is_some_and(|s| *s != this) {
            return Err(bad(line, "conditions differ from the first row".into()));
        }
        spec = Some(this);
        if with_machine {
            machine = rec.get(eij_end).map(str::to_string);
        }
        let mut eij = BTreeMap::new();
        for (k, p) in params.iter().enumerate() {
            eij.insert(*p, num(fixed.len() + k)?);
        }
        let position_mm = [num(0)?, num(1)?, num(2)?];
        if let Some(first) = seen.insert(position_mm.map(f64::to_bits), line) {
            return Err(bad(
                line,
                format!(
                    "position {} mm given twice (first on line {first})",
                    crate::text::nums(&position_mm)
                ),
            ));
        }
        points.push(MapPoint {
            position_m: position_mm.iter().map(|v| v * 1e-3).collect(),
            eij,
        });
    }
    let spec = spec.ok_or_else(|| bad(2, "no rows".into()))?;
    Ok(MapTable {
        spec,
        points,
        machine,
    })
}
