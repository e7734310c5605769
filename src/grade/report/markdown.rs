//! `feedback.md`: what failed, in plain words, for the student, with the smallest failing case
//! ready to run and the heatmaps. Groups that are not visible only say that their result comes
//! later.
//!
//! The page: the score and a table of the scored checks; a section per check that lost points
//! (what `super::feedback` says of it); what passed; the heatmaps; last, short, the vectors
//! where rounding decides and the code differs from the exact answer (not scored, never called
//! failures).
//!
//! Everything the submission controls is escaped with [`crate::escape`]: its folder name with
//! `markdown_inline`, exception messages and tracebacks in a `markdown_block` whose fence
//! nothing inside can close, so the only heading at the top level is the real score and no
//! link, image or HTML comes from the submission.

use std::fmt::Write;

use super::feedback::{
    Shown, ambiguous_body, check_body, is_ambiguous_note, result_word, worth_showing,
};
use crate::escape::Untrusted;
use crate::grade::rubric::Visibility;
use crate::grade::{result::CheckResult, result::CheckStatus, result::GradeReport};

/// Points as short as they go: `15`, `7.5`, `33.33`.
pub(crate) fn fmt_points(x: f64) -> String {
    let s = format!("{x:.2}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// Text the submission controls as a fenced block nothing inside can close.
pub(crate) fn fenced(s: &Untrusted) -> String {
    s.markdown_block("text")
}

/// The score and the table of scored checks.
fn write_table(md: &mut String, report: &GradeReport) {
    let _ = writeln!(
        md,
        "# Feedback for {}: {} / {}\n",
        report.submission.markdown_inline(),
        fmt_points(report.score),
        fmt_points(report.max_score),
    );
    let _ = writeln!(md, "Graded with the {} rubric.\n", report.rubric);
    md.push_str("| Check | Points | Result |\n|---|---:|---|\n");
    for c in report.checks.iter().filter(|c| !is_ambiguous_note(c)) {
        // The rubric's names are the instructor's; only a `|` would break the table.
        let name = c.name.replace('|', "\\|");
        if c.visibility != Visibility::Visible {
            let _ = writeln!(md, "| {name} | hidden | shown later |");
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
}

/// A section per visible check that lost points.
fn write_lost(md: &mut String, report: &GradeReport, shown: &mut Shown) {
    for c in &report.checks {
        if c.visibility != Visibility::Visible
            || c.status == CheckStatus::Passed
            || is_ambiguous_note(c)
        {
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
        md.push_str(&check_body(c, fenced, shown, &c.name));
        if let Some(img) = &c.image {
            if img.heatmap.is_some() {
                let _ = writeln!(
                    md,
                    "\nIn the heatmap of {} below (one map per colour channel: red, green, blue), orange marks pixels higher than the reference allows, purple lower ones, and green boxes outline the regions that fail.",
                    img.file
                );
            }
        }
    }
}

/// What passed, then the heatmaps of the visible images.
fn write_passed_and_heatmaps(md: &mut String, report: &GradeReport) {
    let visible = || {
        report
            .checks
            .iter()
            .filter(|c| c.visibility == Visibility::Visible)
    };
    let passed: Vec<&CheckResult> = visible()
        .filter(|c| c.status == CheckStatus::Passed)
        .collect();
    if !passed.is_empty() {
        md.push_str("\n## Passed\n\n");
        for c in passed {
            let _ = writeln!(md, "- {}: {}", c.name, c.message.markdown_inline());
        }
    }
    let heatmaps: Vec<(&str, &str)> = visible()
        .filter_map(|c| c.image.as_ref())
        .filter_map(|i| i.heatmap.as_deref().map(|h| (i.file.as_str(), h)))
        .collect();
    if heatmaps.is_empty() {
        return;
    }
    md.push_str("\n## Heatmaps\n\nYour images against the reference, as signed z-scores, one map per colour channel (red, green, blue): white where they agree up to sampling noise, orange where yours is higher, purple where lower");
    let image_lost = visible().any(|c| c.image.is_some() && c.status == CheckStatus::Failed);
    md.push_str(if image_lost {
        "; green boxes outline the regions that fail.\n"
    } else {
        ".\n"
    });
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

/// Last and short: the visible groups whose ambiguous vectors differ from the exact answer.
fn write_ambiguous(md: &mut String, report: &GradeReport) {
    let notes: Vec<&CheckResult> = report
        .checks
        .iter()
        .filter(|c| c.visibility == Visibility::Visible && is_ambiguous_note(c))
        .filter(|c| worth_showing(c))
        .collect();
    if notes.is_empty() {
        return;
    }
    md.push_str("\n## Where rounding decides (not scored)\n");
    for c in notes {
        let group = report
            .checks
            .iter()
            .find(|o| o.group == c.group && !is_ambiguous_note(o))
            .map_or(c.name.as_str(), |o| o.name.as_str());
        let _ = write!(md, "\n### {group}\n\n{}", ambiguous_body(c, &report.checks));
    }
}

/// `feedback.md` text.
pub fn render(report: &GradeReport) -> String {
    let mut md = String::new();
    write_table(&mut md, report);
    if let Some(fatal) = &report.code.fatal {
        let _ = write!(
            md,
            "\n## Your code could not be run\n\nNo intersection test could run, so the code checks score 0. \
             Python said:\n\n{}\nRun `python3 -c \"import RT_object\"` in your folder to see the same error.\n",
            fatal.trim_end().markdown_block("text")
        );
    }
    let mut shown = Shown::default();
    write_lost(&mut md, report, &mut shown);
    write_passed_and_heatmaps(&mut md, report);
    write_ambiguous(&mut md, report);
    md
}

#[cfg(test)]
mod tests {
    use crate::grade::checkers::fakes::{FakeCode, all_pass, counts, fake_images};
    use crate::grade::{rubric::Rubric, rubric::WEEK04_RUBRIC, run::grade};

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
