//! `feedback.md`: what failed, in plain words, for the student, with the smallest failing case
//! ready to run and the heatmaps. Groups that are not visible only say that their result comes
//! later.

use std::fmt::Write;

use crate::grade::rubric::Visibility;
use crate::grade::{CheckResult, CheckStatus, GradeReport, smallest_failure};

fn fmt_points(x: f64) -> String {
    let s = format!("{x:.2}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

fn result_word(c: &CheckResult) -> &'static str {
    match c.status {
        CheckStatus::Passed => "passed",
        CheckStatus::Failed => "failed",
        CheckStatus::Error => "could not be checked",
        CheckStatus::Skipped => "not scored",
    }
}

/// `feedback.md` text.
pub fn render(report: &GradeReport) -> String {
    let mut md = String::new();
    let _ = writeln!(md, "# Feedback for {}\n", report.submission);
    let _ = writeln!(
        md,
        "**Score: {} / {}** ({} rubric)\n",
        fmt_points(report.score),
        fmt_points(report.max_score),
        report.rubric
    );
    md.push_str("| Check | Points | Result |\n|---|---:|---|\n");
    for c in &report.checks {
        if c.visibility == Visibility::Visible {
            let _ = writeln!(
                md,
                "| {} | {} / {} | {} |",
                c.name,
                fmt_points(c.score),
                fmt_points(c.max_score),
                result_word(c)
            );
        } else {
            let _ = writeln!(md, "| {} | hidden | shown later |", c.name);
        }
    }
    if let Some(fatal) = &report.code.fatal {
        let _ = writeln!(
            md,
            "\n## Your code could not be run\n\nNo intersection test could run, so the code checks score 0. \
             Python said:\n\n```\n{}\n```\n\nRun `python3 -c \"import RT_object\"` in your folder to see the same error.",
            fatal.trim_end()
        );
    }
    for c in &report.checks {
        if c.visibility != Visibility::Visible || c.status == CheckStatus::Passed {
            continue;
        }
        let _ = writeln!(
            md,
            "\n## {}: {} / {}\n",
            c.name,
            fmt_points(c.score),
            fmt_points(c.max_score)
        );
        if c.image.is_none() && report.code.fatal.is_some() {
            md.push_str("Not run: your code could not be imported (see above).\n");
            continue;
        }
        let _ = writeln!(md, "{}", c.message);
        if let Some(f) = smallest_failure(&c.failures) {
            let _ = writeln!(
                md,
                "\nTo run the smallest failing case, `{}`{}, yourself: save this as `repro.py` in \
                 your submission folder and run `python3 repro.py`.\n\n```python\n{}```",
                f.id,
                if f.tags.is_empty() {
                    String::new()
                } else {
                    format!(" ({})", f.tags.join(", "))
                },
                f.repro
            );
            if c.failures.len() > 1 {
                md.push_str("\nOther failing cases:\n\n");
                for g in c.failures.iter().filter(|g| g.id != f.id) {
                    let _ = writeln!(md, "- `{}`: {}", g.id, g.message);
                }
            }
        }
        if let Some(img) = &c.image {
            if img.heatmap.is_some() {
                let _ = writeln!(
                    md,
                    "\nIn the heatmap of {} below, red marks pixels brighter than the reference allows, blue darker ones, and green boxes outline the regions that fail.",
                    img.file
                );
            }
        }
    }
    let shown: Vec<&CheckResult> = report
        .checks
        .iter()
        .filter(|c| c.visibility == Visibility::Visible && c.status == CheckStatus::Passed)
        .collect();
    if !shown.is_empty() {
        md.push_str("\n## Passed\n\n");
        for c in shown {
            let _ = writeln!(md, "- {}: {}", c.name, c.message);
        }
    }
    let heatmaps: Vec<(&str, &str)> = report
        .checks
        .iter()
        .filter(|c| c.visibility == Visibility::Visible)
        .filter_map(|c| c.image.as_ref())
        .filter_map(|i| i.heatmap.as_deref().map(|h| (i.file.as_str(), h)))
        .collect();
    if !heatmaps.is_empty() {
        md.push_str("\n## Heatmaps\n\nYour images against the reference, as signed z-scores: white where they agree up to sampling noise, red where yours is brighter, blue where darker; green boxes outline the regions that fail.\n");
        for (file, h) in heatmaps {
            let _ = writeln!(md, "\n![{file} against the reference]({h})");
        }
    }
    md
}

#[cfg(test)]
mod tests {
    use crate::grade::run::fakes::{FakeCode, all_pass, counts};
    use crate::grade::{Rubric, grade, rubric::WEEK04_RUBRIC};

    #[test]
    fn hidden_groups_keep_their_details_out_of_the_feedback_but_not_out_of_results_json() {
        let text = WEEK04_RUBRIC.replacen(
            "points = 30\nvisibility = \"visible\"",
            "points = 30\nvisibility = \"hidden\"",
            1,
        );
        let rubric = Rubric::from_toml(&text, "hidden.toml").unwrap();
        let sub = tempfile::tempdir().unwrap();
        let out = tempfile::tempdir().unwrap();
        let code = FakeCode::new(counts(2, 1), counts(2, 1));
        let report = grade(sub.path(), &rubric, &code, &all_pass(), out.path()).unwrap();
        let md = super::render(&report);
        assert!(
            md.contains("| Sphere intersection | hidden | shown later |"),
            "{md}"
        );
        assert!(!md.contains("## Sphere intersection"), "{md}");
        assert!(
            md.contains("## Quad constructor and intersection: 15 / 30"),
            "{md}"
        );
        let gs = crate::grade::report::gradescope::value(&report);
        assert_eq!(gs["tests"][0]["visibility"], "hidden");
        assert_eq!(gs["tests"][1]["visibility"], "visible");
        assert_eq!(gs["score"], 15.0 + 15.0 + 40.0);
    }
}
