//! `feedback.md`: what failed, in plain words, for the student, with the smallest failing case
//! ready to run and the heatmaps. Groups that are not visible only say that their result comes
//! later.
//!
//! Everything the submission controls is escaped with [`crate::escape`]: its folder name with
//! [`markdown_inline`], exception messages and tracebacks in a [`markdown_block`] whose fence
//! nothing inside can close, so the only heading at the top level is the real score and no
//! link, image or HTML comes from the submission. Ambiguous vectors (reported, not scored) get
//! a section only when some of them differ from the exact answer.

use std::fmt::Write;

use crate::escape::{markdown_block, markdown_inline};
use crate::grade::result::smallest_case_sentence;
use crate::grade::rubric::Visibility;
use crate::grade::{CheckResult, CheckStatus, GradeReport, smallest_failure};

/// Points as short as they go: `15`, `7.5`, `33.33`.
pub(crate) fn fmt_points(x: f64) -> String {
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

/// Text the submission controls as a fenced block nothing inside can close.
pub(crate) fn fenced(s: &str) -> String {
    markdown_block(s, "text")
}

/// Whether an unscored check has something to say (some ambiguous vector differs).
pub(crate) fn worth_showing(c: &CheckResult) -> bool {
    c.status != CheckStatus::Skipped || !c.failures.is_empty()
}

/// A check's message and its smallest failing case as Markdown: the harness's own sentence as
/// text (with the submission's words taken out), then what the submission said in a fenced
/// block (`quote` writes it: [`fenced`] here, an entity-escaped quote for Gradescope). `repro`
/// adds the ready-to-run reproduction.
pub(crate) fn check_body(c: &CheckResult, repro: bool, quote: fn(&str) -> String) -> String {
    let mut md = String::new();
    let smallest = smallest_failure(&c.failures).or_else(|| {
        // Unscored (ambiguous) checks show their first case.
        (c.status == CheckStatus::Skipped)
            .then(|| c.failures.first())
            .flatten()
    });
    let sentence = smallest_failure(&c.failures).map(smallest_case_sentence);
    // The harness's own sentence (counts, the rubric's names, the comparison's words) is kept as
    // it reads; the vector's message it ends with is shown below in a block. A code check that
    // could not run quotes Python in its message: that one is escaped whole.
    let own = match &sentence {
        Some(s) => c.message.strip_suffix(s.as_str()).map(str::to_string),
        None if c.counts.is_some() && c.status == CheckStatus::Error => None,
        None => Some(c.message.clone()),
    };
    md.push_str(&own.unwrap_or_else(|| markdown_inline(&c.message)));
    md.push('\n');
    if let Some(f) = smallest {
        let _ = write!(
            md,
            "\n{}, `{}`{}, gave:\n\n{}",
            if c.status == CheckStatus::Skipped {
                "The first case that differs from the exact answer"
            } else {
                "The smallest failing case"
            },
            f.id.replace('`', "'"),
            if f.tags.is_empty() {
                String::new()
            } else {
                format!(" ({})", markdown_inline(&f.tags.join(", ")))
            },
            quote(&f.message)
        );
        if repro {
            let _ = write!(
                md,
                "\nTo run it yourself, save this as `repro.py` in your submission folder and run \
                 `python3 repro.py`:\n\n{}",
                markdown_block(&f.repro, "python")
            );
        }
        let others: Vec<_> = c.failures.iter().filter(|g| g.id != f.id).collect();
        if !others.is_empty() {
            md.push_str("\nOther failing cases:\n\n");
            for g in others {
                let _ = writeln!(
                    md,
                    "- `{}`: {}",
                    g.id.replace('`', "'"),
                    markdown_inline(&g.message)
                );
            }
        }
    }
    md
}

/// `feedback.md` text.
pub fn render(report: &GradeReport) -> String {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Feedback for {}: {} / {}\n",
        markdown_inline(&report.submission),
        fmt_points(report.score),
        fmt_points(report.max_score),
    );
    let _ = writeln!(md, "Graded with the {} rubric.\n", report.rubric);
    md.push_str("| Check | Points | Result |\n|---|---:|---|\n");
    for c in report.checks.iter().filter(|c| worth_showing(c)) {
        // The rubric's names are the instructor's; only a `|` would break the table.
        let name = c.name.replace('|', "\\|");
        if c.visibility != Visibility::Visible {
            let _ = writeln!(md, "| {name} | hidden | shown later |");
        } else if c.status == CheckStatus::Skipped {
            let _ = writeln!(md, "| {name} | not scored | see below |");
        } else {
            let _ = writeln!(
                md,
                "| {name} | {} / {} | {} |",
                fmt_points(c.score),
                fmt_points(c.max_score),
                result_word(c)
            );
        }
    }
    if let Some(fatal) = &report.code.fatal {
        let _ = write!(
            md,
            "\n## Your code could not be run\n\nNo intersection test could run, so the code checks score 0. \
             Python said:\n\n{}\nRun `python3 -c \"import RT_object\"` in your folder to see the same error.\n",
            markdown_block(fatal.trim_end(), "text")
        );
    }
    for c in &report.checks {
        if c.visibility != Visibility::Visible
            || c.status == CheckStatus::Passed
            || !worth_showing(c)
        {
            continue;
        }
        if c.status == CheckStatus::Skipped {
            let _ = writeln!(md, "\n## {}\n", c.name);
        } else {
            let _ = writeln!(
                md,
                "\n## {}: {} / {}\n",
                c.name,
                fmt_points(c.score),
                fmt_points(c.max_score)
            );
        }
        if c.image.is_none() && report.code.fatal.is_some() {
            md.push_str("Not run: your code could not be imported (see above).\n");
            continue;
        }
        md.push_str(&check_body(c, true, fenced));
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
            // The heatmap's name is the grader's own (`heatmap-<group>.png`).
            let _ = writeln!(
                md,
                "\n![{} against the reference]({})",
                file,
                h.replace([' ', '(', ')', '<', '>'], "_")
            );
        }
    }
    md
}

#[cfg(test)]
mod tests {
    use crate::grade::fakes::{FakeCode, all_pass, counts, fake_images};
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
        fake_images(sub.path());
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
