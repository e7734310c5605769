//! `report.json`: the native, complete report (the [`GradeReport`] serialised, keys in name
//! order), headed by what it is and the version of its layout. Its JSON Schema is
//! `docs/schemas/report.schema.json`.

use crate::grade::result::GradeReport;

/// What `report.json` says it is (its `schema`).
pub const REPORT_SCHEMA: &str = "rtoracle-grade-report";

/// The version of `report.json`'s layout (its `version`): 2 since `schema` names the document
/// and `version` counts its layouts, as in `rtoracle check --json` and `batch.json`. Version 1
/// had `"schema": 1` and `"tool": "rtoracle"` instead; the rest of its keys are version 2's
/// (`docs/grading.md` says how to read both).
pub const REPORT_VERSION: u32 = 2;

/// The report as pretty JSON with a trailing newline.
pub fn render(report: &GradeReport) -> String {
    let mut value = serde_json::to_value(report).expect("a report always serialises");
    if let Some(o) = value.as_object_mut() {
        o.insert("schema".into(), REPORT_SCHEMA.into());
        o.insert("version".into(), REPORT_VERSION.into());
    }
    serde_json::to_string_pretty(&value).expect("a value always serialises") + "\n"
}
