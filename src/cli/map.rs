//! `eij map`: EIJ over a grid of axis positions, as a compensation table.

use super::machine_args::write_outputs;
use anyhow::bail;
use eij::axes::{Direction, Plane};
use eij::machine::Machine;
use eij::map::{eij_map_with_progress, to_csv, AxisGrid, MapSpec};
use std::path::PathBuf;

/// Arguments of `eij map`.
#[derive(Debug, clap::Args)]
pub struct MapArgs {
    /// Machine description.
    #[arg(long, value_name = "FILE.toml")]
    machine: PathBuf,
    /// Plane of the circle: xy, yz or zx.
    #[arg(long)]
    plane: Plane,
    /// cw or ccw.
    #[arg(long, default_value = "ccw")]
    direction: Direction,
    /// Circle radius, mm.
    #[arg(long, default_value_t = 2.0, allow_hyphen_values = true)]
    radius_mm: f64,
    /// Set acceleration, m/s².
    #[arg(long, allow_hyphen_values = true)]
    accel_m_s2: f64,
    /// Grid of one axis, `<axis>=<min>:<max>:<count>` in mm (repeatable; other axes stay at their
    /// reference position).
    #[arg(
        long = "grid",
        value_name = "AXIS=MIN:MAX:N",
        required = true,
        allow_hyphen_values = true
    )]
    grids: Vec<String>,
    /// Output CSV (compensation table).
    #[arg(long, value_name = "FILE.csv")]
    out: PathBuf,
    /// Also draw the map as SVG.
    #[arg(long, value_name = "FILE.svg")]
    plot: Option<PathBuf>,
}

/// Runs `eij map`.
pub fn run(args: MapArgs) -> anyhow::Result<()> {
    if !(args.radius_mm.is_finite() && args.radius_mm > 0.0 && args.radius_mm <= 3.0) {
        bail!(
            "--radius-mm: {} must lie in (0, 3] mm (R-Test range)",
            args.radius_mm
        );
    }
    super::machine_args::accel_m_s2(args.accel_m_s2)?;
    let machine = Machine::from_file(&args.machine)?;
    let outputs: Vec<&std::path::Path> = std::iter::once(args.out.as_path())
        .chain(args.plot.as_deref())
        .collect();
    eij::io::check_outputs(&outputs, &[&args.machine])?;
    let grids = args
        .grids
        .iter()
        .map(|g| AxisGrid::parse(g))
        .collect::<Result<Vec<_>, _>>()
        .map_err(super::advice::map)?;
    let spec = MapSpec {
        plane: args.plane,
        direction: args.direction,
        radius_m: args.radius_mm * 1e-3,
        accel_m_s2: args.accel_m_s2,
    };
    let total: usize = grids.iter().map(|g| g.values_m.len()).product();
    let bar = super::console::Progress::bar(total as u64, "map", "grid points");
    let points = eij_map_with_progress(&machine, &grids, &spec, &|done, _| bar.set(done as u64))
        .map_err(super::advice::map)?;
    drop(bar);
    let axes: Vec<_> = machine.axes().iter().map(|a| a.axis).collect();
    let svg = match &args.plot {
        Some(_) => Some(eij::report::map_svg(machine.name(), &axes, &spec, &points)?),
        None => None,
    };
    let csv = to_csv(&machine, &spec, &points);
    let mut files: Vec<(&std::path::Path, &[u8])> = vec![(&args.out, csv.as_bytes())];
    if let (Some(path), Some(svg)) = (&args.plot, &svg) {
        files.push((path, svg.as_bytes()));
    }
    write_outputs(&files, &[&args.machine])
}
