//! `results.json` in Gradescope's autograder format: `score` (the sum of the tests'),
//! `execution_time` (seconds, a number), `output`, and `tests[]` with `name`, `number`,
//! `score`, `max_score`, `status` (`passed` / `failed`), `output`, `visibility` and `tags`.

use serde_json::{Value, json};

use crate::grade::{CheckStatus, GradeReport};

/// One test's output text (Markdown): the message, then the first failure's reproduction.
fn test_output(check: &crate::grade::CheckResult) -> String {
    let mut out = check.message.clone();
    if let Some(f) = crate::grade::smallest_failure(&check.failures) {
        out.push_str(&format!(
            "\n\nSmallest failing case to run yourself:\n\n```python\n{}```",
            f.repro
        ));
    }
    if let Some(img) = &check.image {
        if let Some(d) = &img.diagnosis {
            if !out.contains(d.as_str()) {
                out.push_str(&format!("\n\n{d}"));
            }
        }
    }
    out
}

/// The Gradescope value.
pub fn value(report: &GradeReport) -> Value {
    let tests: Vec<Value> = report
        .checks
        .iter()
        .enumerate()
        .map(|(i, c)| {
            json!({
                "name": c.name,
                "number": format!("{}", i + 1),
                "score": c.score,
                "max_score": c.max_score,
                "status": if matches!(c.status, CheckStatus::Passed | CheckStatus::Skipped) { "passed" } else { "failed" },
                "output": test_output(c),
                "output_format": "md",
                "visibility": c.visibility.name(),
                "tags": c.tags,
            })
        })
        .collect();
    let score: f64 = crate::grade::round2(report.checks.iter().map(|c| c.score).sum());
    let mut output = format!(
        "Graded by rtoracle {} with the {} rubric: {} / {}.",
        report.reproducibility.tool_version, report.rubric, score, report.max_score
    );
    if let Some(fatal) = &report.code.fatal {
        output.push_str(&format!(
            "\n\nYour code could not be run:\n\n```\n{fatal}\n```"
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
