//! Small random machines for property tests: a tool slide (X) and a workpiece table (Y), each on
//! two rails of two carriages on a fixed base and driven by a ball screw whose nut sits off the
//! centre of gravity (so that acceleration tilts the slide). Every dimension, mass and stiffness
//! is drawn from a physical range; the controller is the reference single-axis one.

use proptest::prelude::*;

/// What varies between the random machines.
#[derive(Debug, Clone)]
pub struct Slide {
    /// Mass, kg.
    pub mass_kg: f64,
    /// Height of the centre of gravity above the carriages, m.
    pub cog_z_m: f64,
    /// Half the carriage spacing along and across the rails, m.
    pub half_spacing_m: (f64, f64),
    /// Normal and lateral stiffness per carriage, N/µm.
    pub stiffness_n_per_um: (f64, f64),
    /// Height of the nut (drive force line) above the carriages, m.
    pub nut_z_m: f64,
}

/// Random slide parameters.
pub fn slide() -> impl Strategy<Value = Slide> {
    (
        100.0..800.0f64,
        0.05..0.3f64,
        (0.1..0.4f64, 0.1..0.3f64),
        (100.0..1500.0f64, 100.0..1500.0f64),
        0.0..0.2f64,
    )
        .prop_map(
            |(mass_kg, cog_z_m, half_spacing_m, stiffness_n_per_um, nut_z_m)| Slide {
                mass_kg,
                cog_z_m,
                half_spacing_m,
                stiffness_n_per_um,
                nut_z_m,
            },
        )
}

fn body(name: &str, s: &Slide) -> String {
    let (m, z) = (s.mass_kg, s.cog_z_m);
    // A block 0.6 × 0.5 × 0.3 m of that mass: positive definite, triangle inequality holds.
    let (a, b, c) = (0.6f64, 0.5f64, 0.3f64);
    let (ixx, iyy, izz) = (
        m * (b * b + c * c) / 12.0,
        m * (a * a + c * c) / 12.0,
        m * (a * a + b * b) / 12.0,
    );
    format!(
        "[[body]]\nname = \"{name}\"\nmass_kg = {m}\ncog_m = [0.0, 0.0, {z}]\ninertia_kg_m2 = [[{ixx}, 0.0, 0.0], [0.0, {iyy}, 0.0], [0.0, 0.0, {izz}]]\n\n"
    )
}

fn axis(name: &str, moving: &str, s: &Slide) -> String {
    let (hx, hy) = s.half_spacing_m;
    let (kn, kl) = s.stiffness_n_per_um;
    let (along, across) = if name == "x" { (hx, hy) } else { (hy, hx) };
    let point = |u: f64, v: f64| {
        if name == "x" {
            format!("[{u}, {v}, 0.0]")
        } else {
            format!("[{v}, {u}, 0.0]")
        }
    };
    let rail = |v: f64| {
        format!(
            "[[axis.guideway.rail]]\nnormal = [0.0, 0.0, 1.0]\ncarriages_m = [{}, {}]\n\n",
            point(along, v),
            point(-along, v)
        )
    };
    let nut = point(0.0, 0.0).replace(", 0.0]", &format!(", {}]", s.nut_z_m));
    let bearing = point(-0.6, 0.0).replace(", 0.0]", &format!(", {}]", s.nut_z_m));
    format!(
        "[[axis]]\nname = \"{name}\"\ncarrier = \"base\"\nmoving = \"{moving}\"\nstroke_m = [-0.2, 0.2]\n\n\
         [axis.guideway]\nstiffness_normal_n_per_um = {kn}\nstiffness_lateral_n_per_um = {kl}\n\
         damping_normal_n_s_per_m = 2.0e3\ndamping_lateral_n_s_per_m = 2.0e3\n\n{}{}\
         [axis.drive]\nnut_m = {nut}\nbearing_m = {bearing}\nscale_m = {nut}\nlead_m = 0.02\n\
         screw_diameter_m = 0.03\nsupport = \"fixed-free\"\nnut_stiffness_n_per_um = 1000.0\n\
         bearing_stiffness_n_per_um = 1000.0\nrotor_inertia_kg_m2 = 0.004\ndamping_n_s_per_m = 4.0e3\n\
         friction_nm_s_per_rad = 0.01\n\n\
         [axis.control]\nkv_per_s = 40.0\nkp_nm_s_per_rad = 2.0\ntn_s = 0.01\ncurrent_lag_s = 0.0004\n\n",
        rail(across),
        rail(-across)
    )
}

/// The machine file text: tool slide `x` (TCP on it) and workpiece table `y` (nest on it).
pub fn toml(tool: &Slide, table: &Slide) -> String {
    let tcp_z = tool.cog_z_m + 0.2;
    format!(
        "name = \"random-xy\"\n\n[tcp]\nbody = \"slide\"\npoint_m = [0.0, 0.0, {tcp_z}]\n\n\
         [workpiece]\nbody = \"table\"\npoint_m = [0.0, 0.0, {tcp_z}]\n\n\
         [[body]]\nname = \"base\"\nfixed = true\n\n{}{}{}{}",
        body("slide", tool),
        body("table", table),
        axis("x", "slide", tool),
        axis("y", "table", table)
    )
}
