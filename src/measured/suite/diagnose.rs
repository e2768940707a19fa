//! The diagnosis of a suite's tests (`eij evaluate --diagnose`, `eij report`): each test
//! diagnosed by source ([`crate::rtest::diagnosis`]) with its folder's `[diagnosis]` settings,
//! the tests of one plane and circle centre separated together (squareness from servo
//! mismatch, geometry from EIJ), and every test judged against its folder's `[tolerances]`.

use rayon::prelude::*;
use serde_json::{json, Value};

use super::{EvaluatedTest, Suite};
use crate::measured::conditions::DiagnosisSettings;
use crate::measured::MeasuredError;
use crate::rtest::diagnosis::tolerance::{judge, Verdict};
use crate::rtest::diagnosis::{diagnose_series, separate, CircleDiagnosis, GroupSeparation};
use crate::rtest::EvalOptions;

/// The diagnosis of every test of a suite.
#[derive(Debug, Clone, PartialEq)]
pub struct SuiteDiagnosis {
    /// Per test, in the suite's order.
    pub tests: Vec<CircleDiagnosis>,
    /// What the tests of each plane and circle centre told together.
    pub groups: Vec<GroupSeparation>,
    /// Per test, its verdict where its folder gives tolerances.
    pub verdicts: Vec<Option<Verdict>>,
}

impl SuiteDiagnosis {
    /// `pass` when every judged test passes, `fail` when one fails, `None` when no test has
    /// tolerances.
    pub fn verdict(&self) -> Option<&'static str> {
        let mut judged = self.verdicts.iter().flatten().peekable();
        judged.peek()?;
        Some(if judged.all(Verdict::passed) {
            "pass"
        } else {
            "fail"
        })
    }

    /// The tests that failed their tolerances (indices).
    pub fn failed(&self) -> Vec<usize> {
        (0..self.verdicts.len())
            .filter(|&i| self.verdicts[i].as_ref().is_some_and(|v| !v.passed()))
            .collect()
    }

    /// Test `i`'s `"diagnosis"` object (docs/commands.md), and its `"verdict"` where judged.
    pub fn test_json(&self, i: usize) -> (Value, Option<Value>) {
        let verdict = self.verdicts[i].as_ref().map(|v| json!(v));
        (self.tests[i].to_json(), verdict)
    }

    /// Adds `"diagnosis"` (and `"verdict"`) to every test of an evaluate document and, at the
    /// top, `"diagnosis_groups"` and the overall `"verdict"` where tests were judged.
    pub fn add_to_json(&self, doc: &mut serde_json::Map<String, Value>) {
        if let Some(Value::Array(tests)) = doc.get_mut("tests") {
            for (i, t) in tests.iter_mut().enumerate() {
                let (d, v) = self.test_json(i);
                if let Value::Object(o) = t {
                    o.insert("diagnosis".into(), d);
                    if let Some(v) = v {
                        o.insert("verdict".into(), v["verdict"].clone());
                        o.insert("tolerance_checks".into(), v["checks"].clone());
                        if v.get("unchecked").is_some() {
                            o.insert("unchecked_tolerances".into(), v["unchecked"].clone());
                        }
                    }
                }
            }
        }
        doc.insert("diagnosis_groups".into(), json!(self.groups));
        if let Some(v) = self.verdict() {
            doc.insert("verdict".into(), json!(v));
        }
    }
}

/// Diagnoses, separates and judges the suite's tests; `settings` (the command line's) over
/// each test's `[diagnosis]`.
pub fn diagnose(
    suite: &Suite,
    settings: DiagnosisSettings,
) -> Result<SuiteDiagnosis, MeasuredError> {
    let mut tests: Vec<CircleDiagnosis> = suite
        .tests
        .par_iter()
        .map(|t| diagnose_test(t, settings))
        .collect::<Vec<_>>()
        .into_iter()
        .collect::<Result<_, _>>()?;
    let groups = separate(&mut tests);
    let verdicts = tests
        .iter_mut()
        .zip(&suite.tests)
        .map(|(d, t)| (!t.input.tolerances.is_empty()).then(|| judge(d, &t.input.tolerances)))
        .collect();
    Ok(SuiteDiagnosis {
        tests,
        groups,
        verdicts,
    })
}

fn diagnose_test(
    t: &EvaluatedTest,
    settings: DiagnosisSettings,
) -> Result<CircleDiagnosis, MeasuredError> {
    let eval = EvalOptions {
        plane: Some(t.result.plane),
        radius_mm: Some(t.result.radius_mm),
    };
    let opts = settings.over(t.input.diagnosis).options();
    let mut d = diagnose_series(&t.series, &eval, &opts)?;
    d.name = t.input.name();
    d.position_mm = t.input.test.position_mm.as_deref().map(|p| {
        let mut xyz = [0.0; 3];
        for (dst, src) in xyz.iter_mut().zip(p) {
            *dst = *src;
        }
        xyz
    });
    Ok(d)
}
