//! The stiffness table of an identified machine ([`crate::machine::stiffness`]) with the
//! standard errors of the identified factors: from the identification itself, or from the
//! `[provenance]` an identified machine file carries — so that `eij stiffness` of the exported
//! file gives exactly the table `eij identify --stiffness-out` wrote.

use std::fmt;

use super::{IdentError, IdentResult, Parameter, ParameterKind, Problem};
use crate::machine::stiffness::{FactorKind, StiffnessTable};
use crate::machine::Machine;

impl ParameterKind {
    /// The reduction factors of its axis a parameter of this kind sets.
    pub fn factors(self) -> &'static [FactorKind] {
        match self {
            ParameterKind::Guideway => &[FactorKind::GuidewayNormal, FactorKind::GuidewayLateral],
            ParameterKind::GuidewayNormal => &[FactorKind::GuidewayNormal],
            ParameterKind::GuidewayLateral => &[FactorKind::GuidewayLateral],
            ParameterKind::Screw => &[FactorKind::Drive],
            ParameterKind::BodyStiffness => &[],
        }
    }
}

/// The stiffness table of `machine` with, for every fitted parameter, its name and the standard
/// error of its factor (`None`: not determined by the tests) on the rows it scales.
pub(crate) fn table_with_std_err<'a>(
    machine: &Machine,
    fitted: impl IntoIterator<Item = (&'a Parameter, Option<f64>)>,
) -> StiffnessTable {
    let mut table = StiffnessTable::of(machine);
    table.identified = true;
    for (p, std_err) in fitted {
        if let Some(b) = p.body_index() {
            table.set_body_std_err(&machine.bodies()[b].name, &p.name, std_err);
        }
        let Some(axis) = p.axis_index().map(|i| machine.axes()[i].axis) else {
            continue;
        };
        for &kind in p.kind.factors() {
            table.set_factor_std_err(axis, kind, &p.name, std_err);
        }
    }
    table
}

/// The stiffness table of an identification's result: the identified machine with the standard
/// errors of the identified factors.
pub fn identified_table(problem: &Problem, result: &IdentResult) -> StiffnessTable {
    table_with_std_err(
        &result.machine,
        problem
            .parameters()
            .iter()
            .zip(&result.parameters)
            .map(|(p, r)| (p, r.std_err)),
    )
}

/// A recorded factor of a machine file's `[provenance]` that no longer holds: its standard
/// error is left out of the table. Rendered to text where it is shown, as [`super::Warning`].
#[derive(Debug, Clone, PartialEq)]
pub enum ProvenanceWarning {
    /// A recorded parameter that does not name a parameter of the machine.
    Unknown {
        /// The machine file.
        file: String,
        /// Why it names none.
        error: IdentError,
    },
    /// A recorded factor the file no longer has: it was edited after the identification.
    Edited {
        /// The machine file.
        file: String,
        /// The parameter.
        parameter: String,
        /// Its factor in the file now.
        now: f64,
        /// The factor identified, as recorded.
        identified: f64,
    },
}

impl fmt::Display for ProvenanceWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ProvenanceWarning::Unknown { file, error } => write!(
                f,
                "{file}: provenance: {error}; its standard error is left out"
            ),
            ProvenanceWarning::Edited {
                file,
                parameter,
                now,
                identified,
            } => write!(
                f,
                "{file}: {parameter} = {now} differs from the identified {identified} recorded in \
                 [provenance]: its standard error is left out"
            ),
        }
    }
}

/// The stiffness table of a machine file: with the standard errors its `[provenance]` records
/// when it is an identified file, and warnings for recorded factors that no longer hold (the
/// file was edited after the identification; their standard errors are left out).
pub fn machine_table(machine: &Machine) -> (StiffnessTable, Vec<ProvenanceWarning>) {
    let Some(provenance) = machine.to_raw().provenance else {
        return (StiffnessTable::of(machine), Vec::new());
    };
    let mut warnings = Vec::new();
    let mut fitted = Vec::new();
    for (name, recorded) in &provenance.parameters {
        let parameter = match Parameter::parse(name, machine) {
            Ok(p) => p,
            Err(error) => {
                warnings.push(ProvenanceWarning::Unknown {
                    file: machine.source().to_string(),
                    error,
                });
                continue;
            }
        };
        let now = parameter.get(machine);
        if recorded.identified != now {
            warnings.push(ProvenanceWarning::Edited {
                file: machine.source().to_string(),
                parameter: name.clone(),
                now,
                identified: recorded.identified,
            });
            continue;
        }
        fitted.push((parameter, recorded.std_err));
    }
    (
        table_with_std_err(machine, fitted.iter().map(|(p, s)| (p, *s))),
        warnings,
    )
}

/// An elastic body in the identification report: what the model keeps of it, its elastic
/// frequencies and its stiffness factor as identified (docs/identification-files.md).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ElasticBodyReport {
    /// The body's name.
    pub body: String,
    /// Elastic coordinates kept by the reduction.
    pub modes: usize,
    /// Elastic free-free frequencies of the reduced body with its identified factor, Hz,
    /// ascending (rigid modes left out).
    pub frequencies_hz: Vec<f64>,
    /// Its stiffness factor (identified, or as in the file).
    pub factor: f64,
    /// Standard error of the factor; null when not identified or not determined.
    #[serde(default)]
    pub std_err: Option<f64>,
    /// The factor ± 3 standard errors taken in 1/p and mapped back (high null: unbounded;
    /// [`super::verdict::factor_interval`]).
    #[serde(default)]
    pub interval_3sigma: Option<(f64, Option<f64>)>,
    /// The parameter that set it (`column.stiffness`), if identified.
    #[serde(default)]
    pub parameter: Option<String>,
}

/// The elastic bodies of an identification's result, in the machine's body order.
pub fn elastic_bodies(problem: &Problem, result: &IdentResult) -> Vec<ElasticBodyReport> {
    let table = identified_table(problem, result);
    table
        .bodies
        .iter()
        .map(|b| {
            let frequencies_hz = result
                .machine
                .bodies()
                .iter()
                .find(|x| x.name == b.body)
                .and_then(|x| x.elastic())
                .map(|e| e.frequencies_hz())
                .unwrap_or_default();
            ElasticBodyReport {
                body: b.body.clone(),
                modes: b.modes,
                frequencies_hz,
                factor: b.factor,
                std_err: b.factor_std_err,
                interval_3sigma: b.factor_std_err.and_then(|se| {
                    super::verdict::factor_interval(b.factor, se, super::settings::INTERVAL_SIGMAS)
                }),
                parameter: b.parameter.clone(),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::axes::Axis;
    use crate::machine::stiffness::Element;

    #[test]
    fn a_parameter_scales_its_rows_only() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("machines/demo-vmc.toml");
        let m = Machine::from_file(&path).unwrap();
        let screw = Parameter::parse("y.screw", &m).unwrap();
        let guide = Parameter::parse("z.guideway", &m).unwrap();
        let t = table_with_std_err(&m, [(&screw, Some(0.1)), (&guide, None)]);
        assert!(t.identified);
        for r in &t.rows {
            match (r.axis, r.element) {
                (Axis::Y, Element::Screw | Element::Nut | Element::Bearing) => {
                    assert_eq!(r.std_err_n_per_um, Some(0.1 * r.file_n_per_um));
                    assert_eq!(r.parameter.as_deref(), Some("y.screw"));
                }
                (Axis::Z, Element::Guideway) => {
                    assert_eq!(r.std_err_n_per_um, None);
                    assert_eq!(r.parameter.as_deref(), Some("z.guideway"));
                }
                _ => assert_eq!((&r.std_err_n_per_um, &r.parameter), (&None, &None)),
            }
        }
    }

    #[test]
    fn an_edited_factor_is_said_with_both_values() {
        let w = ProvenanceWarning::Edited {
            file: "machines/vmc-identified.toml".into(),
            parameter: "y.screw".into(),
            now: 0.5,
            identified: 0.8125,
        };
        assert_eq!(
            w.to_string(),
            "machines/vmc-identified.toml: y.screw = 0.5 differs from the identified 0.8125 \
             recorded in [provenance]: its standard error is left out"
        );
    }
}
