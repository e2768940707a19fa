//! Generated R-Test circles with the imperfections of real ones, from a machine model with
//! known factors (the truth).
//!
//! The model's steady circle comes from the harmonic solution of its closed loop (phasors
//! H(jω)U, [`eij::sim::harmonic`]), sampled at about 1 kHz over five revolutions; then, on the
//! external (R-Test) readings only:
//! * static geometry: d += G·x (G µm per mm of the position on the circle, rows a, b, k, columns
//!   a, b), per plane and circle centre, the same for cw and ccw (an ellipse, a squareness, a
//!   tilt of the plane);
//! * a reversal term: d += sgn(ω)·G_rev·x (friction/backlash-like, flips with the direction);
//! * a centre offset (µm);
//! * a clock lag δ of the probe logger: the external reading stamped t is the position at t − δ
//!   (exact: the external phasors rotated by e^{−jωδ});
//! * Gaussian noise σ (ChaCha8, seeded).
//!
//! The series is then evaluated by the evaluation every measured file goes through
//! ([`eij::rtest::evaluate`]), so the test cases are what `eij identify` would read.

use eij::axes::{Direction, Plane};
use eij::control::ClosedLoop;
use eij::ident::TestCase;
use eij::machine::Machine;
use eij::predict::CircleTest;
use eij::rtest::{evaluate, CircleSeries, EvalOptions};
use eij::sim::harmonic;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};

/// The imperfections of one group of tests (one plane at one circle centre).
#[derive(Debug, Clone, Copy, Default)]
pub struct Imperfections {
    /// Static geometry, µm/mm: rows deviation a, b, k; columns position a, b.
    pub g_um_per_mm: [[f64; 2]; 3],
    /// Reversal geometry (sign of ccw), µm/mm.
    pub reversal_um_per_mm: [[f64; 2]; 3],
    /// Centre offset of the external path, µm (a, b, k).
    pub offset_um: [f64; 3],
    /// Probe-logger lag, s.
    pub lag_s: f64,
    /// Noise σ on each external coordinate, µm.
    pub noise_um: f64,
}

/// One test to generate.
#[derive(Debug, Clone)]
pub struct Planned {
    pub plane: Plane,
    pub direction: Direction,
    pub accel_m_s2: f64,
    pub position_mm: [f64; 3],
}

/// The demo's grid: planes × directions × accelerations at each circle centre.
pub fn grid(positions_mm: &[[f64; 3]], planes: &[Plane], accels: &[f64]) -> Vec<Planned> {
    let mut v = Vec::new();
    for p in positions_mm {
        for &plane in planes {
            for direction in Direction::ALL {
                for &accel_m_s2 in accels {
                    v.push(Planned {
                        plane,
                        direction,
                        accel_m_s2,
                        position_mm: *p,
                    });
                }
            }
        }
    }
    v
}

/// The series of one planned test on `truth` with `imp`, r = 2 mm.
// The sample index runs over the internal and external series of three axes at once.
#[allow(clippy::needless_range_loop)]
pub fn series(truth: &Machine, t: &Planned, imp: &Imperfections, seed: u64) -> CircleSeries {
    let radius_m = 2e-3;
    let pose: Vec<f64> = t.position_mm.iter().map(|v| v * 1e-3).collect();
    let pose = eij::machine::Pose::new(truth, &pose).unwrap();
    let cl = ClosedLoop::new(truth, &pose).unwrap();
    let ph = harmonic::circle_phasors(&cl, t.plane, radius_m, t.accel_m_s2, t.direction).unwrap();
    let freq = ph.omega.abs() / std::f64::consts::TAU;
    let per_rev = (1000.0 / freq).round() as usize;
    let run = harmonic::steady_circle(&ph, per_rev, 5);
    let clean = eij::sim::output::to_series(&cl, &run, "clean".into()).unwrap();
    // The lagged external reading: every output phasor rotated by e^{−jωδ}.
    let mut lagged = ph.clone();
    let rot = harmonic::phase_factor(-ph.omega * imp.lag_s);
    for y in lagged.outputs.iter_mut() {
        *y *= rot;
    }
    let late = eij::sim::output::to_series(
        &cl,
        &harmonic::steady_circle(&lagged, per_rev, 5),
        "late".into(),
    )
    .unwrap();
    let (a, b) = t.plane.axes();
    let axes = [a, b, t.plane.normal()];
    let sign = t.direction.sign();
    let noise = Normal::new(0.0, imp.noise_um.max(1e-12) * 1e-3).unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let int_mm = eij::axes::Axis::ALL.map(|ax| clean.int_mm(ax).to_vec());
    let mut ext_mm = eij::axes::Axis::ALL.map(|ax| late.ext_mm(ax).to_vec());
    for i in 0..clean.len() {
        let x = [clean.int_mm(a)[i], clean.int_mm(b)[i]];
        for (row, ax) in axes.iter().enumerate() {
            let g = imp.g_um_per_mm[row];
            let rev = imp.reversal_um_per_mm[row];
            let d_um = g[0] * x[0]
                + g[1] * x[1]
                + sign * (rev[0] * x[0] + rev[1] * x[1])
                + imp.offset_um[row];
            ext_mm[ax.index()][i] += d_um * 1e-3
                + if imp.noise_um > 0.0 {
                    noise.sample(&mut rng)
                } else {
                    0.0
                };
        }
    }
    let label = format!(
        "generated {} {} {} m/s² @ {:?} mm",
        t.plane,
        t.direction.name(),
        t.accel_m_s2,
        t.position_mm
    );
    CircleSeries::new(label, clean.t_s().to_vec(), int_mm, ext_mm).unwrap()
}

/// Generated and evaluated test cases: `imp(plane, position index)` gives the imperfections
/// of each group; seeds follow the order of `planned`.
pub fn tests(
    truth: &Machine,
    planned: &[Planned],
    imp: impl Fn(Plane, [f64; 3]) -> Imperfections,
    seed: u64,
) -> Vec<TestCase> {
    planned
        .iter()
        .enumerate()
        .map(|(k, t)| {
            let s = series(truth, t, &imp(t.plane, t.position_mm), seed + k as u64);
            let opts = EvalOptions {
                plane: Some(t.plane),
                radius_mm: Some(2.0),
            };
            let r = evaluate(&s, &opts).unwrap();
            TestCase {
                source: s.source().to_string(),
                circle: CircleTest {
                    plane: r.plane,
                    direction: r.direction,
                    radius_mm: r.radius_mm,
                    accel_m_s2: r.accel_m_s2,
                    position_m: Some(t.position_mm.iter().map(|v| v * 1e-3).collect()),
                },
                measured: r.eij,
                clock: Some("generated".into()),
            }
        })
        .collect()
}

/// Writes `tests` as EIJ tables (docs/eij-table.md) below `dir`: one folder `pos-<k>` per
/// circle centre, each with its `rtest.toml` (radius 2 mm, the centre) and `table.csv`.
/// Returns the folders in order of first appearance.
pub fn write_tables(dir: &std::path::Path, tests: &[TestCase]) -> Vec<std::path::PathBuf> {
    let mut centres: Vec<Vec<f64>> = Vec::new();
    let mut tables: Vec<String> = Vec::new();
    for t in tests {
        let pos = t.circle.position_m.clone().unwrap_or_default();
        let k = match centres.iter().position(|c| *c == pos) {
            Some(k) => k,
            None => {
                centres.push(pos);
                tables.push(
                    "plane,direction,accel_m_s2,parameter,value_um_s2_per_m,std_err_um_s2_per_m\n"
                        .into(),
                );
                centres.len() - 1
            }
        };
        for (eij, e) in &t.measured {
            let (v, se) = (e.value, e.std_err);
            tables[k].push_str(&format!(
                "{},{},{},{eij},{v:.6},{se:.6}\n",
                t.circle.plane,
                t.circle.direction.name(),
                t.circle.accel_m_s2
            ));
        }
    }
    centres
        .iter()
        .zip(&tables)
        .enumerate()
        .map(|(k, (c, table))| {
            let folder = dir.join(format!("pos-{k}"));
            std::fs::create_dir_all(&folder).unwrap();
            let mm: Vec<String> = c.iter().map(|v| format!("{:.3}", v * 1e3)).collect();
            std::fs::write(
                folder.join("rtest.toml"),
                format!(
                    "# generated by an eij test (tests/common/imperfect.rs)\nradius_mm = 2.0\nposition_mm = [{}]\n",
                    mm.join(", ")
                ),
            )
            .unwrap();
            std::fs::write(folder.join("table.csv"), table).unwrap();
            folder
        })
        .collect()
}
