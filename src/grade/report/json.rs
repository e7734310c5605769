//! `report.json`: the native, complete report (the [`GradeReport`] serialised).

use crate::grade::GradeReport;

/// Schema version of `report.json`.
pub const REPORT_SCHEMA: u32 = 1;

/// The report as pretty JSON with a trailing newline.
pub fn render(report: &GradeReport) -> String {
    let mut value = serde_json::to_value(report).expect("a report always serialises");
    if let Some(o) = value.as_object_mut() {
        o.insert("schema".into(), REPORT_SCHEMA.into());
        o.insert("tool".into(), "rtoracle".into());
    }
    serde_json::to_string_pretty(&value).expect("a value always serialises") + "\n"
}
