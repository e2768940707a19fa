//! Benchmarks of the modelling chain on the demo machine: assembly, modal analysis, closed loop,
//! discretisation, one circle test's EIJ in the time domain and harmonically (sampled and in
//! closed form, against one complex LU), and scaling with the number of bodies (a synthetic
//! chain up to 32 bodies, ~400 states) and with the number of samples.
//!
//! Run: `cargo bench --bench simulation`

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use eij::axes::{Direction, Plane};
use eij::control::stability::Certificate;
use eij::control::{ClosedLoop, FrequencyForm};
use eij::machine::Machine;
use eij::mbs::{modal, Model};
use eij::predict::EijMap;
use eij::rtest::harmonic::joint_eij;
use eij::rtest::{evaluate_joint, EvalOptions};
use eij::sim::setpoint::Circle;
use eij::sim::{harmonic, output, simulate_discrete, Discrete};
use std::hint::black_box;
use std::path::Path;

fn demo() -> Machine {
    Machine::from_file(&Path::new(env!("CARGO_MANIFEST_DIR")).join("machines/demo-vmc.toml"))
        .unwrap()
}

/// The flexible demo (`machines/demo-vmc-flex.toml`) with its beam column in 16 elements and 20
/// fixed-interface modes kept (issue 27's speed check: the harmonic circle with an elastic
/// column of 20 modes against one complex LU of its closed loop).
fn elastic_demo() -> Machine {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("machines/demo-vmc-flex.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let text = text
        .replacen("elements = 5\n", "elements = 16\n", 1)
        .replacen("modes = 0 ", "modes = 20 ", 1);
    let m = Machine::from_toml_str(&text, &path.display().to_string()).unwrap();
    let column = m.bodies().iter().position(|b| b.name == "column").unwrap();
    let kept = m.fe_summary(column).unwrap().unwrap().modes;
    assert_eq!(kept, 20, "fixed-interface modes of the column");
    m
}

/// A synthetic machine: a chain of `n` bodies of 500 kg, each on four joints on the previous
/// one, with an X slide and a Y cross slide on it, each on guideways with a ball screw
/// (6·n + 14 DOF, 12·n + 34 closed-loop states).
fn chain(n: usize) -> Machine {
    let mut t = String::from(
        "name = \"chain\"\n[tcp]\nbody = \"cross\"\npoint_m = [0.0, 0.0, 0.3]\n[workpiece]\nbody = \"ground\"\npoint_m = [0.0, 0.0, 0.3]\n[[body]]\nname = \"ground\"\nfixed = true\n",
    );
    for i in 1..=n {
        t += &format!(
            "[[body]]\nname = \"b{i}\"\nmass_kg = 500.0\ncog_m = [0.0, 0.0, 0.0]\ninertia_kg_m2 = [[40.0, 0.0, 0.0], [0.0, 50.0, 0.0], [0.0, 0.0, 60.0]]\n"
        );
        let below = if i == 1 {
            "ground".to_string()
        } else {
            format!("b{}", i - 1)
        };
        for (k, (x, y)) in [(0.4, 0.3), (-0.4, 0.3), (0.4, -0.3), (-0.4, -0.3)]
            .iter()
            .enumerate()
        {
            t += &format!(
                "[[joint]]\nname = \"j{i}-{k}\"\nbody = \"b{i}\"\nother = \"{below}\"\npoint_m = [{x}, {y}, -0.1]\nstiffness_n_per_m = [2e8, 2e8, 5e8]\ndamping_n_s_per_m = [2e4, 2e4, 4e4]\n"
            );
        }
    }
    t += &format!(
        "[[body]]\nname = \"slide\"\nmass_kg = 300.0\ncog_m = [0.0, 0.0, 0.15]\ninertia_kg_m2 = [[10.0, 0.0, 0.0], [0.0, 15.0, 0.0], [0.0, 0.0, 20.0]]\n[[axis]]\nname = \"x\"\ncarrier = \"b{n}\"\nmoving = \"slide\"\nstroke_m = [-0.2, 0.2]\n[axis.guideway]\ncarriage = \"HIWIN HGH25CA ZA\"\ndamping_normal_n_s_per_m = 1.5e4\ndamping_lateral_n_s_per_m = 1.5e4\n[[axis.guideway.rail]]\nnormal = [0.0, 0.0, 1.0]\ncarriages_m = [[0.2, 0.2, 0.05], [-0.2, 0.2, 0.05]]\n[[axis.guideway.rail]]\nnormal = [0.0, 0.0, 1.0]\ncarriages_m = [[0.2, -0.2, 0.05], [-0.2, -0.2, 0.05]]\n[axis.drive]\nnut_m = [0.0, 0.0, 0.08]\nbearing_m = [-0.5, 0.0, 0.08]\nscale_m = [0.0, 0.25, 0.05]\nlead_m = 0.02\nscrew_diameter_m = 0.028\nsupport = \"fixed-free\"\nnut_stiffness_n_per_um = 900.0\nbearing_stiffness_n_per_um = 1000.0\ndamping_n_s_per_m = 5e3\nrotor_inertia_kg_m2 = 0.005\n[axis.control]\nkv_per_s = 50.0\nkp_nm_s_per_rad = 3.0\ntn_s = 0.01\ncurrent_lag_s = 0.0005\n"
    );
    t += "[[body]]\nname = \"cross\"\nmass_kg = 150.0\ncog_m = [0.0, 0.0, 0.25]\ninertia_kg_m2 = [[5.0, 0.0, 0.0], [0.0, 5.0, 0.0], [0.0, 0.0, 8.0]]\n[[axis]]\nname = \"y\"\ncarrier = \"slide\"\nmoving = \"cross\"\nstroke_m = [-0.2, 0.2]\n[axis.guideway]\ncarriage = \"HIWIN HGH25CA ZA\"\ndamping_normal_n_s_per_m = 1.5e4\ndamping_lateral_n_s_per_m = 1.5e4\n[[axis.guideway.rail]]\nnormal = [0.0, 0.0, 1.0]\ncarriages_m = [[0.15, 0.15, 0.2], [0.15, -0.15, 0.2]]\n[[axis.guideway.rail]]\nnormal = [0.0, 0.0, 1.0]\ncarriages_m = [[-0.15, 0.15, 0.2], [-0.15, -0.15, 0.2]]\n[axis.drive]\nnut_m = [0.0, 0.0, 0.22]\nbearing_m = [0.0, -0.5, 0.22]\nscale_m = [0.2, 0.0, 0.2]\nlead_m = 0.02\nscrew_diameter_m = 0.025\nsupport = \"fixed-free\"\nnut_stiffness_n_per_um = 800.0\nbearing_stiffness_n_per_um = 900.0\ndamping_n_s_per_m = 5e3\nrotor_inertia_kg_m2 = 0.004\n[axis.control]\nkv_per_s = 50.0\nkp_nm_s_per_rad = 2.5\ntn_s = 0.01\ncurrent_lag_s = 0.0005\n";
    Machine::from_toml_str(&t, "chain").unwrap()
}

fn bench(c: &mut Criterion) {
    let machine = demo();
    let pose = machine.reference_pose();
    c.bench_function("assemble M, D, K (demo, 27 DOF)", |b| {
        b.iter(|| Model::assemble(black_box(&machine), black_box(&pose)).unwrap())
    });
    let model = Model::assemble(&machine, &pose).unwrap();
    c.bench_function("modal analysis (demo)", |b| {
        b.iter(|| modal::modes(black_box(&model)).unwrap())
    });
    c.bench_function(
        "closed loop with support and stability checks (demo)",
        |b| b.iter(|| ClosedLoop::new(black_box(&machine), black_box(&pose)).unwrap()),
    );
    let cl = ClosedLoop::new(&machine, &pose).unwrap();
    c.bench_function("discretise, first-order hold, 10 kHz (demo)", |b| {
        b.iter(|| Discrete::new(black_box(&cl), 1e-4))
    });
    let disc = Discrete::new(&cl, 1e-4);
    let mut circle = Circle::new(Plane::Zx, 0.002, 5.0, Direction::Ccw);
    circle.steady_revolutions = 3;
    c.bench_function(
        "circle zx 5 m/s², 3 revolutions + ramps, 10 kHz (demo)",
        |b| {
            b.iter(|| {
                simulate_discrete(black_box(&cl), black_box(&disc), black_box(&circle)).unwrap()
            })
        },
    );
    let opts = EvalOptions {
        plane: Some(Plane::Zx),
        radius_mm: Some(2.0),
    };
    c.bench_function(
        "EIJ of one circle, time domain (simulate 10 kHz + evaluate)",
        |b| {
            b.iter(|| {
                let run = simulate_discrete(&cl, &disc, &circle).unwrap();
                let s = output::to_series(&cl, &run, "t".into()).unwrap();
                evaluate_joint(black_box(&s), &opts).unwrap().1
            })
        },
    );
    c.bench_function(
        "EIJ of one circle, harmonic sampled (phasors + 128 samples/rev + evaluate)",
        |b| {
            b.iter(|| {
                let ph =
                    harmonic::circle_phasors(&cl, Plane::Zx, 0.002, 5.0, Direction::Ccw).unwrap();
                let run = harmonic::steady_circle(&ph, 128, 4);
                let s = output::to_series(&cl, &run, "h".into()).unwrap();
                evaluate_joint(black_box(&s), &opts).unwrap().1
            })
        },
    );
    harmonic_circle(c, "demo", &cl);
    let elastic = elastic_demo();
    let cl_elastic = ClosedLoop::new(&elastic, &elastic.reference_pose()).unwrap();
    harmonic_circle(c, "demo, elastic column of 20 modes", &cl_elastic);

    let mut group = c.benchmark_group("bodies");
    for n in [1usize, 4, 16, 32] {
        let m = chain(n);
        let pose = m.reference_pose();
        let cl = ClosedLoop::new(&m, &pose).unwrap();
        let states = cl.a.nrows();
        group.bench_with_input(BenchmarkId::new("assemble", states), &m, |b, m| {
            b.iter(|| Model::assemble(m, &pose).unwrap())
        });
        group.bench_with_input(
            BenchmarkId::new("closed loop + checks", states),
            &m,
            |b, m| b.iter(|| ClosedLoop::new(m, &pose).unwrap()),
        );
        group.bench_with_input(
            BenchmarkId::new("frequency form (balance + Hessenberg)", states),
            &cl,
            |b, cl| b.iter(|| cl.frequency_form()),
        );
        let lu_input = shifted(&cl, 31.6);
        group.bench_with_input(
            BenchmarkId::new("complex LU of jωI − A", states),
            &lu_input,
            |b, lu_input| b.iter(|| lu_input.partial_piv_lu()),
        );
        let form = cl.frequency_form();
        group.bench_with_input(
            BenchmarkId::new("EIJ of one circle, harmonic closed form", states),
            &form,
            |b, form| b.iter(|| closed_form_eij(&cl, form, Plane::Xy)),
        );
        // One parameter set of an identification like the demo's: two circle centres (closed
        // loop with checks and its frequency form each) and 36 harmonic circles.
        group.bench_with_input(
            BenchmarkId::new("one parameter set: 2 closed loops + 36 circles", states),
            &m,
            |b, m| {
                b.iter(|| {
                    for _ in 0..2 {
                        let cl = ClosedLoop::new(m, &pose).unwrap();
                        let form = cl.frequency_form();
                        for _ in 0..18 {
                            black_box(closed_form_eij(&cl, &form, Plane::Xy));
                        }
                    }
                })
            },
        );
    }
    group.finish();

    let mut group = c.benchmark_group("samples");
    for rate in [1_000.0, 10_000.0, 100_000.0] {
        let disc = Discrete::new(&cl, 1.0 / rate);
        let n = (circle_duration(&circle) * rate) as usize;
        group.bench_with_input(
            BenchmarkId::new("time-domain circle", n),
            &disc,
            |b, disc| b.iter(|| simulate_discrete(&cl, disc, &circle).unwrap()),
        );
    }
    group.finish();
}

/// jωI − A as a faer matrix.
fn shifted(cl: &ClosedLoop, omega: f64) -> faer::Mat<faer::c64> {
    let n = cl.a.nrows();
    faer::Mat::from_fn(n, n, |i, k| {
        let d = if i == k { omega } else { 0.0 };
        faer::c64::new(-cl.a[(i, k)], d)
    })
}

/// The EIJ of a 2 mm, 2 m/s² circle on a reduced closed loop: phasors and closed-form
/// evaluation, as identify runs every test.
fn closed_form_eij(cl: &ClosedLoop, form: &FrequencyForm, plane: Plane) -> EijMap {
    let ph =
        harmonic::circle_phasors_in(form, &cl.axes, plane, 0.002, 2.0, Direction::Ccw).unwrap();
    let steady = harmonic::steady_harmonic(cl, plane, &ph);
    let window = harmonic::steady_window(ph.omega, 128, 4);
    joint_eij(&steady, 2.0, &window, "bench").unwrap()
}

/// One harmonic circle (phasors on the frequency form + closed-form evaluation) against one
/// complex LU of jωI − A, the closed loop's stability check and its frequency form.
fn harmonic_circle(c: &mut Criterion, name: &str, cl: &ClosedLoop) {
    let n = cl.a.nrows();
    let form = cl.frequency_form();
    let mut group = c.benchmark_group(format!("harmonic circle ({name}, {n} states)"));
    let m = shifted(cl, 31.6);
    group.bench_function("one complex LU of jωI − A (faer)", |b| {
        b.iter(|| black_box(&m).partial_piv_lu())
    });
    group.bench_function("EIJ of one circle, harmonic closed form", |b| {
        b.iter(|| closed_form_eij(cl, black_box(&form), Plane::Zx))
    });
    group.bench_function(
        "frequency form (balance + Hessenberg), once per closed loop",
        |b| b.iter(|| black_box(cl).frequency_form()),
    );
    group.bench_function(
        "closed-loop eigenvalues (stability), once per closed loop",
        |b| b.iter(|| black_box(cl).eigenvalues().unwrap()),
    );
    group.bench_function("eigenvalues of the Hessenberg form", |b| {
        b.iter(|| {
            black_box(&form)
                .hessenberg()
                .to_owned()
                .eigenvalues()
                .unwrap()
        })
    });
    if let Some(cert) = Certificate::new(&cl.a) {
        group.bench_function(
            "stability certificate: made (eigen-decomposition + P)",
            |b| b.iter(|| Certificate::new(black_box(&cl.a))),
        );
        group.bench_function("stability certificate: a loop checked against it", |b| {
            b.iter(|| black_box(&cert).certifies(black_box(&cl.a)))
        });
    }
    group.finish();
}

fn circle_duration(c: &Circle) -> f64 {
    use eij::sim::setpoint::SetPoint;
    c.duration_s()
}

criterion_group!(benches, bench);
criterion_main!(benches);
