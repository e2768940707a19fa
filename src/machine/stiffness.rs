//! The stiffness set of a machine as a table, for other tools (an FE, Simscape or Modelica
//! model, a supplier discussion): one row per axis, element and direction with the value the
//! machine file gives (catalogue or explicit), the reduction factor on it and the stiffness the
//! model uses, N/µm (`eij stiffness`, `eij identify --stiffness-out`; docs/stiffness-table.md).
//!
//! Rows of each axis, in the machine's axis order:
//!
//! * `guideway normal`, `guideway lateral`: per carriage, shared by the axis's `count` carriages.
//!   The file value is the catalogue's linearised one (normal: mean of the radial and the
//!   reverse-radial stiffness, [`super::catalogue::CarriageData::normal_n_per_m`]) or the
//!   machine file's own; the factor is `reduction_normal` / `reduction_lateral`.
//! * `screw axial`: the shaft, E·A/l₁ (fixed-free) or E·A·L/(l₁·(L − l₁)) (fixed-fixed), with l₁
//!   the nut-to-bearing distance at the axis's **reference position** (the shaft stiffness
//!   follows the nut; [`StiffnessRow::screw`] holds l₁ and the range over the stroke).
//! * `nut axial`, `bearing axial`: as the machine file gives them.
//!
//! The value is file value × factor. The drive's one factor scales the whole chain, and scaling
//! each element by it gives the model's series stiffness r/(1/k_screw + 1/k_nut + 1/k_bearing)
//! ([`super::Drive::axial_stiffness_n_per_m`]). The standard error of a value is the file value
//! × the standard error of its factor, filled in from an identification
//! ([`StiffnessTable::set_factor_std_err`]).

use super::raw::Support;
use super::{Drive, LinearAxis, Machine};
use crate::axes::Axis;
use serde::{Deserialize, Serialize};
use std::fmt;

/// N/m per N/µm.
const N_PER_M_PER_N_PER_UM: f64 = 1e6;

/// The compliant element of an axis a row describes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Element {
    /// A guideway carriage (per carriage).
    Guideway,
    /// The screw shaft between the fixed bearing and the nut.
    Screw,
    /// The ball nut.
    Nut,
    /// The screw's support bearing(s).
    Bearing,
}

impl Element {
    /// Name in the table (`guideway`, `screw`, `nut`, `bearing`).
    pub fn name(self) -> &'static str {
        match self {
            Element::Guideway => "guideway",
            Element::Screw => "screw",
            Element::Nut => "nut",
            Element::Bearing => "bearing",
        }
    }
}

impl fmt::Display for Element {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The direction a row's stiffness acts in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum StiffnessDirection {
    /// Across the rail, along the carriage's normal (radial load) direction.
    Normal,
    /// Across the rail, along axis × normal.
    Lateral,
    /// Along the axis (the drive chain).
    Axial,
}

impl StiffnessDirection {
    /// Name in the table (`normal`, `lateral`, `axial`).
    pub fn name(self) -> &'static str {
        match self {
            StiffnessDirection::Normal => "normal",
            StiffnessDirection::Lateral => "lateral",
            StiffnessDirection::Axial => "axial",
        }
    }
}

impl fmt::Display for StiffnessDirection {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Which reduction factor of an axis scales a row.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FactorKind {
    /// `guideway.reduction_normal`.
    GuidewayNormal,
    /// `guideway.reduction_lateral`.
    GuidewayLateral,
    /// `drive.reduction`: screw, nut and bearing together.
    Drive,
}

/// Where a screw row's shaft value holds, and how it changes over the stroke.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ScrewPosition {
    /// Axis position of the row's value (the reference position), mm.
    pub axis_position_mm: f64,
    /// Nut-to-bearing distance l₁ there, mm.
    pub nut_bearing_mm: f64,
    /// Smallest and largest value (file × factor) over the stroke, N/µm.
    pub stroke_range_n_per_um: [f64; 2],
}

impl ScrewPosition {
    /// Where the screw value of `axis` holds, in words: `x: nut 550 mm from the fixed bearing at
    /// x = 0.0 mm, 152.1 … 517.2 N/µm over the stroke`.
    pub fn describe(&self, axis: Axis) -> String {
        format!(
            "{axis}: nut {:.0} mm from the fixed bearing at {axis} = {:.1} mm, {:.1} … {:.1} N/µm over the stroke",
            self.nut_bearing_mm,
            self.axis_position_mm,
            self.stroke_range_n_per_um[0],
            self.stroke_range_n_per_um[1]
        )
    }
}

/// One row of the table; in JSON (the identification report's `stiffness`) with the CSV's
/// column names as keys and `screw` on screw rows.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StiffnessRow {
    /// The axis.
    pub axis: Axis,
    /// The element.
    pub element: Element,
    /// The direction.
    pub direction: StiffnessDirection,
    /// How many such elements the axis has (carriages; 1 for the drive chain's elements).
    pub count: usize,
    /// The machine file's value (catalogue or explicit), N/µm per element.
    pub file_n_per_um: f64,
    /// The reduction factor on it.
    pub factor: f64,
    /// The stiffness the model uses, file × factor, N/µm per element.
    pub value_n_per_um: f64,
    /// Standard error of the value, file × standard error of the factor, N/µm; `None` when the
    /// factor was not identified or the tests do not determine it.
    #[serde(default)]
    pub std_err_n_per_um: Option<f64>,
    /// The identified parameter that set the factor (`x.guideway_normal`), if any.
    #[serde(default)]
    pub parameter: Option<String>,
    /// Screw rows: where the shaft value holds.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub screw: Option<ScrewPosition>,
}

impl StiffnessRow {
    /// The reduction factor that scales this row.
    pub(crate) fn factor_kind(&self) -> FactorKind {
        match (self.element, self.direction) {
            (Element::Guideway, StiffnessDirection::Lateral) => FactorKind::GuidewayLateral,
            (Element::Guideway, _) => FactorKind::GuidewayNormal,
            _ => FactorKind::Drive,
        }
    }
}

/// An elastic body's row: the factor on its whole FE stiffness (E and G alike) and the first
/// elastic frequency it gives. In the CSV: `axis` = the body's name, `element` = `body`,
/// `direction` = `all`, `count` = 1, no N/µm values.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BodyRow {
    /// The body's name.
    pub body: String,
    /// Its `stiffness_factor`.
    pub factor: f64,
    /// Its first elastic free-free frequency with the factor (the reduced body alone), Hz.
    pub first_frequency_hz: f64,
    /// Elastic coordinates kept.
    pub modes: usize,
    /// Standard error of the factor, where identified.
    #[serde(default)]
    pub factor_std_err: Option<f64>,
    /// The identified parameter that set the factor (`column.stiffness`), if any.
    #[serde(default)]
    pub parameter: Option<String>,
}

/// The stiffness set of a machine.
#[derive(Debug, Clone, PartialEq)]
pub struct StiffnessTable {
    /// Whether the table carries an identification's standard errors (then the CSV has the
    /// `std_err_n_per_um` and `parameter` columns).
    pub identified: bool,
    /// Rows, per axis in the machine's order: guideway normal, guideway lateral, screw, nut,
    /// bearing.
    pub rows: Vec<StiffnessRow>,
    /// One row per elastic body, in the machine's body order.
    pub bodies: Vec<BodyRow>,
}

/// The columns a table of a machine with elastic bodies adds (`factor_std_err` on identified
/// tables only).
pub(crate) const BODY_COLUMNS: [&str; 2] = ["first_frequency_hz", "factor_std_err"];

/// The columns every stiffness table has (docs/stiffness-table.md).
pub const COLUMNS: [&str; 7] = [
    "axis",
    "element",
    "direction",
    "count",
    "file_n_per_um",
    "factor",
    "value_n_per_um",
];

/// The columns an identified table adds.
pub(crate) const IDENTIFIED_COLUMNS: [&str; 2] = ["std_err_n_per_um", "parameter"];

/// Shaft stiffness with the nut at l₁ from the fixed bearing, N/m (without the factor).
fn shaft_n_per_m(d: &Drive, l1: f64) -> f64 {
    let ea = d.screw_modulus_pa * d.screw_area_m2;
    match (d.support, d.screw_length_m) {
        (Support::FixedFixed, Some(l)) => ea * l / (l1 * (l - l1)),
        _ => ea / l1,
    }
}

/// The screw shaft of an axis: its value at the reference position, N/m, and where it holds.
fn screw_at_reference(a: &LinearAxis) -> (f64, ScrewPosition) {
    let e = a.direction();
    let d = &a.drive;
    // Signed nut-to-bearing distance at the reference position and at axis position s
    // (the moving body shifts by σ·(s − s_ref) along e; machine::check_nut_travel keeps the
    // nut on one side of the bearing over the whole stroke).
    let l_ref = e.dot(&(d.nut_m - d.bearing_m));
    let l_at = |s: f64| (l_ref + a.side.sign() * (s - a.reference_m)).abs();
    let [lo, hi] = a.stroke_m;
    let mut candidates = vec![l_at(lo), l_at(hi)];
    if let (Support::FixedFixed, Some(total)) = (d.support, d.screw_length_m) {
        // E·A·L/(l₁(L − l₁)) is smallest at mid-span.
        let (l_lo, l_hi) = (l_at(lo).min(l_at(hi)), l_at(lo).max(l_at(hi)));
        if l_lo < total / 2.0 && total / 2.0 < l_hi {
            candidates.push(total / 2.0);
        }
    }
    let values = candidates
        .iter()
        .map(|&l| shaft_n_per_m(d, l) * d.reduction / N_PER_M_PER_N_PER_UM);
    let range = values.fold([f64::INFINITY, f64::NEG_INFINITY], |[mn, mx], v| {
        [mn.min(v), mx.max(v)]
    });
    let l1 = l_ref.abs();
    (
        shaft_n_per_m(d, l1),
        ScrewPosition {
            axis_position_mm: a.reference_m * 1e3,
            nut_bearing_mm: l1 * 1e3,
            stroke_range_n_per_um: range,
        },
    )
}

impl StiffnessTable {
    /// The stiffness set of `machine` with the factors of its file and no standard errors.
    pub fn of(machine: &Machine) -> StiffnessTable {
        let mut rows = Vec::with_capacity(5 * machine.axes.len());
        for a in &machine.axes {
            let row = |element, direction, count, file_n_per_m: f64, factor: f64| {
                let file_n_per_um = file_n_per_m / N_PER_M_PER_N_PER_UM;
                StiffnessRow {
                    axis: a.axis,
                    element,
                    direction,
                    count,
                    file_n_per_um,
                    factor,
                    value_n_per_um: file_n_per_um * factor,
                    std_err_n_per_um: None,
                    parameter: None,
                    screw: None,
                }
            };
            let g = &a.guideway;
            let carriages = g.rails.iter().map(|r| r.carriages_m.len()).sum();
            rows.push(row(
                Element::Guideway,
                StiffnessDirection::Normal,
                carriages,
                g.normal_n_per_m,
                g.reduction_normal,
            ));
            rows.push(row(
                Element::Guideway,
                StiffnessDirection::Lateral,
                carriages,
                g.lateral_n_per_m,
                g.reduction_lateral,
            ));
            let d = &a.drive;
            let (shaft, position) = screw_at_reference(a);
            let mut screw = row(
                Element::Screw,
                StiffnessDirection::Axial,
                1,
                shaft,
                d.reduction,
            );
            screw.screw = Some(position);
            rows.push(screw);
            rows.push(row(
                Element::Nut,
                StiffnessDirection::Axial,
                1,
                d.nut_stiffness_n_per_m,
                d.reduction,
            ));
            rows.push(row(
                Element::Bearing,
                StiffnessDirection::Axial,
                1,
                d.bearing_stiffness_n_per_m,
                d.reduction,
            ));
        }
        let bodies = machine
            .bodies
            .iter()
            .filter_map(|b| {
                let e = b.elastic()?;
                Some(BodyRow {
                    body: b.name.clone(),
                    factor: e.stiffness_factor(),
                    first_frequency_hz: e.frequencies_hz().first().copied().unwrap_or(f64::NAN),
                    modes: e.modes(),
                    factor_std_err: None,
                    parameter: None,
                })
            })
            .collect();
        StiffnessTable {
            identified: false,
            rows,
            bodies,
        }
    }

    /// Marks the table as identified and gives the row of elastic body `body` the parameter
    /// that set its factor and the factor's standard error.
    pub(crate) fn set_body_std_err(&mut self, body: &str, parameter: &str, std_err: Option<f64>) {
        self.identified = true;
        for r in self.bodies.iter_mut().filter(|r| r.body == body) {
            r.factor_std_err = std_err;
            r.parameter = Some(parameter.to_string());
        }
    }

    /// Marks the table as identified and gives every row of `axis` scaled by `kind` the
    /// parameter that set the factor and the standard error of its value (file × `std_err`,
    /// the factor's standard error; `None` when the tests do not determine it).
    pub fn set_factor_std_err(
        &mut self,
        axis: Axis,
        kind: FactorKind,
        parameter: &str,
        std_err: Option<f64>,
    ) {
        self.identified = true;
        for r in &mut self.rows {
            if r.axis == axis && r.factor_kind() == kind {
                r.std_err_n_per_um = std_err.map(|s| r.file_n_per_um * s);
                r.parameter = Some(parameter.to_string());
            }
        }
    }

    /// The table as CSV (docs/commands.md columns; an identified table adds `std_err_n_per_um` and
    /// `parameter`, empty where a factor was not identified). Numbers are written in full
    /// (shortest round-trip form), so two tables of the same stiffness set are equal as text.
    pub fn to_csv(&self) -> Vec<u8> {
        let mut w = csv::Writer::from_writer(Vec::new());
        let mut header: Vec<&str> = COLUMNS.to_vec();
        if self.identified {
            header.extend(IDENTIFIED_COLUMNS);
        }
        let with_bodies = !self.bodies.is_empty();
        if with_bodies {
            header.push(BODY_COLUMNS[0]);
            if self.identified {
                header.push(BODY_COLUMNS[1]);
            }
        }
        // Writing into a Vec cannot fail.
        let _ = w.write_record(&header);
        for r in &self.rows {
            let mut record = vec![
                r.axis.name().to_string(),
                r.element.name().to_string(),
                r.direction.name().to_string(),
                r.count.to_string(),
                r.file_n_per_um.to_string(),
                r.factor.to_string(),
                r.value_n_per_um.to_string(),
            ];
            if self.identified {
                record.push(r.std_err_n_per_um.map_or(String::new(), |s| s.to_string()));
                record.push(r.parameter.clone().unwrap_or_default());
            }
            if with_bodies {
                record.push(String::new());
                if self.identified {
                    let factor = r.std_err_n_per_um.map(|s| s / r.file_n_per_um);
                    record.push(factor.map_or(String::new(), |s| s.to_string()));
                }
            }
            let _ = w.write_record(&record);
        }
        for b in &self.bodies {
            let mut record = vec![
                b.body.clone(),
                "body".into(),
                "all".into(),
                "1".into(),
                String::new(),
                b.factor.to_string(),
                String::new(),
            ];
            if self.identified {
                record.push(String::new());
                record.push(b.parameter.clone().unwrap_or_default());
            }
            record.push(b.first_frequency_hz.to_string());
            if self.identified {
                record.push(b.factor_std_err.map_or(String::new(), |s| s.to_string()));
            }
            let _ = w.write_record(&record);
        }
        w.into_inner().unwrap_or_default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn machine(name: &str) -> Machine {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("machines")
            .join(name);
        Machine::from_file(&path).unwrap()
    }

    #[test]
    fn series_of_the_scaled_drive_elements_is_the_models_axial_stiffness() {
        let mut m = machine("demo-vmc.toml");
        for a in &mut m.axes {
            a.drive.reduction = 0.7;
        }
        let t = StiffnessTable::of(&m);
        for a in &m.axes {
            let value = |e: Element| {
                t.rows
                    .iter()
                    .find(|r| r.axis == a.axis && r.element == e)
                    .unwrap()
                    .value_n_per_um
            };
            let series = 1.0
                / (1.0 / value(Element::Screw)
                    + 1.0 / value(Element::Nut)
                    + 1.0 / value(Element::Bearing));
            let l1 = (a.drive.nut_m - a.drive.bearing_m)
                .dot(&a.direction())
                .abs();
            let model = a.drive.axial_stiffness_n_per_m(l1) / 1e6;
            assert!(
                (series / model - 1.0).abs() < 1e-12,
                "{}: {series} vs {model}",
                a.axis
            );
        }
    }

    #[test]
    fn fixed_fixed_shaft_is_softest_at_mid_span() {
        // E·A·L/(l(L − l)) over a stroke that crosses mid-span: the range's minimum is 4·E·A/L.
        let text = std::fs::read_to_string(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("machines/demo-vmc.toml"),
        )
        .unwrap()
        .replace(
            "bearing_m = [-0.55, 0.0, -0.18]",
            "bearing_m = [-0.55, 0.0, -0.18]\nscrew_length_m = 1.2",
        )
        .replacen("support = \"fixed-free\"", "support = \"fixed-fixed\"", 1);
        let m = Machine::from_toml_str(&text, "ff.toml").unwrap();
        let t = StiffnessTable::of(&m);
        let screw = t.rows.iter().find(|r| r.element == Element::Screw).unwrap();
        let d = &m.axes[0].drive;
        let ea = d.screw_modulus_pa * d.screw_area_m2;
        // Nut 0.55 m from the bearing at x = 0; the stroke ±0.3 m takes it through 0.6 m.
        let at = |l: f64| ea * 1.2 / (l * (1.2 - l)) / 1e6;
        assert!((screw.file_n_per_um / at(0.55) - 1.0).abs() < 1e-12);
        let pos = screw.screw.unwrap();
        assert!((pos.nut_bearing_mm - 550.0).abs() < 1e-9);
        assert!((pos.stroke_range_n_per_um[0] / at(0.6) - 1.0).abs() < 1e-12);
        assert!((pos.stroke_range_n_per_um[1] / at(0.25) - 1.0).abs() < 1e-12);
    }
}
