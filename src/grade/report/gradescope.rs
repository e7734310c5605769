//! `results.json` in Gradescope's autograder format: `score` (the sum of the tests'),
//! `execution_time` (seconds, a number), `output`, and `tests[]` with `name`, `number`,
//! `score`, `max_score`, `status` (`passed` / `failed`), `output`, `visibility` and `tags`.
//!
//! Every `output` is Markdown, and says so (`"output_format": "md"`, at the top and in each
//! test): the same words as `feedback.md` (`super::feedback`), escaped only where Markdown
//! would otherwise change them. The tests come in rubric order, the notes on ambiguous vectors
//! (not scored) last.

use serde_json::{Value, json};

use super::feedback::{Shown, ambiguous_body, check_body, is_ambiguous_note, worth_showing};
use crate::escape::Untrusted;
use crate::grade::{result::CheckResult, result::CheckStatus, result::GradeReport};

/// Text the submission controls, for Gradescope's Markdown: each line escaped with
/// [`markdown_inline`] (so `<`, `>` and `&` are entities and nothing is a link, a heading or
/// HTML, even if Gradescope lets raw HTML through), as a quote with hard line breaks, leading
/// spaces kept as `&nbsp;`.
pub(crate) fn quoted(s: &Untrusted) -> String {
    let mut out = String::new();
    for line in s.trim_end().lines() {
        let text = line.markdown_inline();
        let body = text.trim_start_matches(' ');
        let indent = text.len() - body.len();
        out.push_str("> ");
        out.push_str(&"&nbsp;".repeat(indent));
        out.push_str(body);
        out.push_str("  \n");
    }
    out.push('\n');
    out
}

/// One test's output (Markdown): the message, the smallest failing case and its reproduction
/// (an error an earlier test showed is referred to); for a note on ambiguous vectors, the short
/// note. The heatmaps are not on Gradescope, so nothing points to them, and the diagnosis of an
/// image is said once (it is in the message).
fn test_output(check: &CheckResult, report: &GradeReport, shown: &mut Shown) -> String {
    let body = if is_ambiguous_note(check) {
        ambiguous_body(check, &report.checks)
    } else {
        check_body(check, quoted, shown, &check.name)
    };
    body.replace(" (outlined in the heatmap)", "")
        .trim_end()
        .to_string()
}

/// The Gradescope value.
pub fn value(report: &GradeReport) -> Value {
    let mut shown = Shown::default();
    let ordered = report
        .checks
        .iter()
        .filter(|c| !is_ambiguous_note(c))
        .chain(report.checks.iter().filter(|c| is_ambiguous_note(c)));
    let tests: Vec<Value> = ordered
        .filter(|c| worth_showing(c))
        .enumerate()
        .map(|(i, c)| {
            json!({
                "name": c.name,
                "number": format!("{}", i + 1),
                "score": c.score,
                "max_score": c.max_score,
                "status": if matches!(c.status, CheckStatus::Passed | CheckStatus::Skipped) { "passed" } else { "failed" },
                "output": test_output(c, report, &mut shown),
                "output_format": "md",
                "visibility": c.visibility.name(),
                "tags": c.tags,
            })
        })
        .collect();
    let score: f64 = crate::grade::result::round2(report.checks.iter().map(|c| c.score).sum());
    let mut output = format!(
        "Graded by rtoracle {} with the {} rubric: {} / {}.",
        report.reproducibility.tool_version, report.rubric, score, report.max_score
    );
    if let Some(fatal) = &report.code.fatal {
        output.push_str(&format!(
            "\n\nYour code could not be run. Python said:\n\n{}",
            quoted(fatal)
        ));
    }
    json!({
        "score": score,
        "execution_time": report.execution_time,
        "output": output,
        "output_format": "md",
        "visibility": "visible",
        "stdout_visibility": "hidden",
        "tests": tests,
    })
}

/// `results.json` text.
pub fn render(report: &GradeReport) -> String {
    serde_json::to_string_pretty(&value(report)).expect("a value always serialises") + "\n"
}
