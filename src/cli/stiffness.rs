//! `eij stiffness --machine FILE.toml [--out F.csv]`: the stiffness set of a machine file as a
//! table (docs/stiffness-table.md).

use super::machine_args::write_output;
use eij::ident::stiffness::machine_table;
use eij::machine::stiffness::StiffnessTable;
use eij::machine::Machine;
use std::path::PathBuf;

/// Arguments of `eij stiffness`.
#[derive(Debug, clap::Args)]
pub struct StiffnessArgs {
    /// Machine description (the catalogue model or an identified one).
    #[arg(long, value_name = "FILE.toml")]
    machine: PathBuf,
    /// The table as CSV (default: a readable table on standard output).
    #[arg(long, value_name = "F.csv")]
    out: Option<PathBuf>,
}

/// Runs `eij stiffness`.
pub fn run(args: StiffnessArgs) -> anyhow::Result<()> {
    let machine = Machine::from_file(&args.machine)?;
    if let Some(out) = &args.out {
        eij::io::check_outputs(&[out.as_path()], &[args.machine.as_path()])?;
    }
    let (table, warnings) = machine_table(&machine);
    for w in &warnings {
        errln!("warning: {w}");
    }
    match &args.out {
        Some(out) => write_output(out, &table.to_csv(), &[args.machine.as_path()]),
        None => {
            out!("{}", text(&machine, &table));
            Ok(())
        }
    }
}

/// The table for reading: aligned columns, and where each screw value holds.
pub fn text(machine: &Machine, table: &StiffnessTable) -> String {
    let mut s = format!(
        "Stiffness of {} (N/µm per element; value = file × factor)\n\n",
        machine.name()
    );
    s.push_str(&format!(
        "  {:<4} {:<9} {:<9} {:>5} {:>10} {:>8} {:>10}",
        "axis", "element", "direction", "count", "file", "factor", "value"
    ));
    if table.identified {
        s.push_str(&format!(" {:>10}  {}", "std err", "parameter"));
    }
    s.push('\n');
    for r in &table.rows {
        s.push_str(&format!(
            "  {:<4} {:<9} {:<9} {:>5} {:>10.1} {:>8.4} {:>10.1}",
            r.axis.name(),
            r.element.name(),
            r.direction.name(),
            r.count,
            r.file_n_per_um,
            r.factor,
            r.value_n_per_um
        ));
        if table.identified {
            let std_err = r.std_err_n_per_um.map_or("-".into(), |e| format!("{e:.1}"));
            s.push_str(&format!(
                " {std_err:>10}  {}",
                r.parameter.as_deref().unwrap_or("-")
            ));
        }
        s.push('\n');
    }
    for b in &table.bodies {
        let std_err = b
            .factor_std_err
            .map_or(String::new(), |e| format!(" ± {e:.4}"));
        let parameter = b
            .parameter
            .as_deref()
            .map_or(String::new(), |p| format!(" ({p})"));
        s.push_str(&format!(
            "  {:<14} body: factor {:.4}{std_err}{parameter} on its whole FE stiffness, first elastic frequency {:.1} Hz, {} elastic modes\n",
            b.body, b.factor, b.first_frequency_hz, b.modes
        ));
    }
    let screws: Vec<String> = table
        .rows
        .iter()
        .filter_map(|r| r.screw.map(|p| (r.axis, p)))
        .map(|(axis, p)| p.describe(axis))
        .collect();
    if !screws.is_empty() {
        s.push_str("\nScrew shafts at the reference position (E·A/l₁ follows the nut):\n  ");
        s.push_str(&screws.join("\n  "));
        s.push('\n');
    }
    let elastic: Vec<String> = machine
        .bodies()
        .iter()
        .filter_map(|b| b.elastic().map(|e| (b, e)))
        .map(|(b, e)| {
            format!(
                "{:<10} stiffness_factor {:.4} ({} elastic coordinates; `eij fe --body {}`)",
                b.name,
                e.stiffness_factor(),
                e.modes(),
                b.name
            )
        })
        .collect();
    if !elastic.is_empty() {
        s.push_str(
            "\nElastic bodies (the factor scales the body's whole FE stiffness, E and G alike; their rows are in the CSV as element `body`):\n  ",
        );
        s.push_str(&elastic.join("\n  "));
        s.push('\n');
    }
    s
}
