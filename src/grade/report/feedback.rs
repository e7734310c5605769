//! What the student's two reports (`feedback.md` and Gradescope's `results.json`) say alike about
//! one check, whatever their layout: the word for its result, where an exception was raised, the
//! body of a failing check and the short note on vectors where rounding decides.
//!
//! The promises, tested in `tests/integration/grade/feedback.rs`: ambiguous vectors are never called
//! failures (they "differ from the exact answer where rounding decides (not scored)", last and
//! short); a missing image is "missing" wherever it is named; an exception names the file and
//! line of the student's code it was raised in, and the same error is said once, not in every
//! section. Everything the submission controls goes through [`crate::escape`].

use std::fmt::Write;

use crate::candidate::judging::check::FailureKind;
use crate::escape::{Untrusted, markdown_block, markdown_inline};
use crate::grade::result::smallest_case_sentence;
use crate::grade::{
    checkers::FailureSummary, result::CheckResult, result::CheckStatus, result::smallest_failure,
};

use crate::grade::score::MISSING;

/// Whether `c` is an image check whose file is not in the submission.
pub(crate) fn is_missing_image(c: &CheckResult) -> bool {
    c.status == CheckStatus::Error
        && c.image.as_ref().is_some_and(|i| match &i.verdict {
            crate::grade::checkers::ImageVerdict::Unusable(why) => why.ends_with(MISSING),
            _ => false,
        })
}

/// Whether `c` is an image check judged on the grader's render of the submission's code.
fn is_rendered(c: &CheckResult) -> bool {
    c.image
        .as_ref()
        .is_some_and(|i| i.metrics.get("source").and_then(|s| s.as_str()) == Some("render"))
}

/// The word for a scored check's result: what became of it, never a vague "could not be
/// checked" (an image not uploaded is "missing" under a rubric that judges uploads; one the
/// grader could not render from the code is "not rendered", whatever was uploaded).
pub(crate) fn result_word(c: &CheckResult) -> &'static str {
    match c.status {
        CheckStatus::Passed => "passed",
        CheckStatus::Failed => "failed",
        CheckStatus::Error if is_rendered(c) => "not rendered",
        CheckStatus::Error if is_missing_image(c) => "missing",
        CheckStatus::Error if c.image.is_some() => "unusable",
        CheckStatus::Error => "not run",
        CheckStatus::Skipped => "not scored",
    }
}

/// Where the student's code raised an exception: the innermost frame of the traceback that is
/// not Python's own library, as Python printed it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct RaisedAt {
    /// The file's name (no folder: the sandbox's folder means nothing to the student).
    pub file: String,
    /// The line number.
    pub line: u64,
    /// The function, when Python named one.
    pub function: Option<String>,
    /// The line of code Python showed under the frame.
    pub code: Option<String>,
}

impl RaisedAt {
    /// `RT_object.py, line 42, in intersect`, escaped for a Markdown sentence.
    pub fn sentence(&self) -> String {
        let mut s = format!("{}, line {}", markdown_inline(&self.file), self.line);
        if let Some(f) = &self.function {
            let _ = write!(s, ", in {}", markdown_inline(f));
        }
        s
    }
}

/// The files rtoracle writes beside the submission's modules in the sandbox (the course
/// adapter and its drivers): a frame in one of them is never the student's.
const ADAPTER_FILES: [&str; 3] = [
    "course_adapter.py",
    "rtoracle_course_functions.py",
    "rtoracle_course_program.py",
];

/// Whether a traceback's file is Python's own (the standard library, an installed package, a
/// frozen module) or the grader's adapter, rather than one of the submission's.
fn is_library(path: &str) -> bool {
    path.starts_with('<')
        || path.contains("/site-packages/")
        || path.contains("/dist-packages/")
        || path.contains("/lib/python")
        || ADAPTER_FILES.contains(&path.rsplit('/').next().unwrap_or(path))
}

/// Where a traceback says the exception was raised in the submission's code: its last
/// `File "...", line N, in F` frame outside Python's library, and the code line under it.
pub(crate) fn raised_at_in(traceback: &str) -> Option<RaisedAt> {
    let lines: Vec<&str> = traceback.lines().collect();
    let mut found = None;
    for (i, line) in lines.iter().enumerate() {
        let Some(rest) = line.trim_start().strip_prefix("File \"") else {
            continue;
        };
        let Some((path, after)) = rest.split_once("\", line ") else {
            continue;
        };
        let (number, function) = match after.split_once(", in ") {
            Some((n, f)) => (n, Some(f.trim().to_string())),
            None => (after, None),
        };
        let Ok(line_number) = number.trim().parse::<u64>() else {
            continue;
        };
        if is_library(path) {
            continue;
        }
        // Python shows the line's code indented under the frame, then (3.11+) carets.
        let code = lines
            .get(i + 1)
            .filter(|next| next.starts_with("    ") && !next.trim_start().starts_with("File \""))
            .map(|next| next.trim().to_string())
            .filter(|c| !c.is_empty() && !c.chars().all(|ch| matches!(ch, '^' | '~')));
        let file = path.rsplit('/').next().unwrap_or(path).to_string();
        found = Some(RaisedAt {
            file,
            line: line_number,
            function,
            code,
        });
    }
    found
}

/// Where the exception of a failure that raised one was raised: the place the code sent with
/// it (the adapter's `file` and `line`, [`crate::candidate::process::protocol::CandidateError`]), else its
/// traceback's last frame of the submission ([`raised_at_in`]).
pub(crate) fn raised_at(f: &FailureSummary) -> Option<RaisedAt> {
    if f.kind != FailureKind::Error {
        return None;
    }
    let error = f.actual.get("error")?;
    let text = |key: &str| error.get(key).and_then(|v| v.as_str()).map(str::to_string);
    if let (Some(file), Some(line)) = (text("file"), error.get("line").and_then(|v| v.as_u64())) {
        return Some(RaisedAt {
            file: file.rsplit('/').next().unwrap_or_default().to_string(),
            line,
            function: text("function"),
            code: text("code"),
        });
    }
    raised_at_in(error.get("traceback")?.as_str()?)
}

/// The errors a report has already shown, so that a later section refers to them instead of
/// saying them again: each error's message and place, and the section that showed it.
#[derive(Default)]
pub(crate) struct Shown {
    errors: Vec<(Untrusted, Option<RaisedAt>, String)>,
}

impl Shown {
    /// The section that already showed the error of `f`, if one did.
    fn section_of(&self, f: &FailureSummary) -> Option<&str> {
        if f.kind != FailureKind::Error {
            return None;
        }
        let at = raised_at(f);
        self.errors
            .iter()
            .find(|(m, a, _)| *m == f.message && *a == at)
            .map(|(_, _, s)| s.as_str())
    }

    fn remember(&mut self, f: &FailureSummary, section: &str) {
        if f.kind == FailureKind::Error && self.section_of(f).is_none() {
            self.errors
                .push((f.message.clone(), raised_at(f), section.to_string()));
        }
    }
}

/// The place an exception was raised, as Markdown: a sentence and the line of code.
fn raised_at_markdown(at: &RaisedAt) -> String {
    let mut md = format!("\nPython raised it in {}", at.sentence());
    match &at.code {
        Some(code) => {
            md.push_str(":\n\n");
            md.push_str(&markdown_block(code, "python"));
        }
        None => md.push_str(".\n"),
    }
    md
}

/// The ready-to-run reproduction of `f`.
fn repro_markdown(f: &FailureSummary) -> String {
    format!(
        "\nTo run it yourself, save this as `repro.py` in your submission folder and run \
         `python3 repro.py`:\n\n{}",
        markdown_block(&f.repro, "python")
    )
}

/// A vector's id and tags for a sentence: `` `sphere-tangent-0003` (tangent) ``.
fn case_name(f: &FailureSummary) -> String {
    let mut s = format!("`{}`", f.id.replace('`', "'"));
    if !f.tags.is_empty() {
        let _ = write!(s, " ({})", markdown_inline(&f.tags.join(", ")));
    }
    s
}

/// A scored check's message and its smallest failing case as Markdown: the harness's own
/// sentence as text (with the submission's words taken out), then what the submission said in a
/// block (`quote` writes it: a fenced block in feedback.md, an entity-escaped quote on
/// Gradescope), where the code raised it, the ready-to-run reproduction, and the other failing
/// cases in one line each (or one sentence when they all failed the same way). An error an
/// earlier section showed is referred to, not repeated; `section` names this one for later ones.
pub(crate) fn check_body(
    c: &CheckResult,
    quote: fn(&Untrusted) -> String,
    shown: &mut Shown,
    section: &str,
) -> String {
    if let Some(f) = &c.function {
        return function_body(c, f, quote);
    }
    let mut md = String::new();
    let smallest = smallest_failure(&c.failures);
    let sentence = smallest.map(smallest_case_sentence);
    // The check's message, escaped as text (a render's exception, a copy finding and the
    // comparison's words can all carry the submission's text); the vector's message it ends
    // with is shown below in a block.
    let own = match &sentence {
        Some(s) => c
            .message
            .strip_suffix_of(s)
            .unwrap_or_else(|| c.message.clone()),
        None => c.message.clone(),
    };
    md.push_str(&own.markdown_inline());
    md.push('\n');
    let Some(f) = smallest else {
        return md;
    };
    match shown.section_of(f) {
        Some(earlier) => {
            let _ = writeln!(
                md,
                "\nThe smallest failing case, {}, raised the same error as in {} above.",
                case_name(f),
                markdown_inline(earlier)
            );
        }
        None => {
            let _ = write!(
                md,
                "\nThe smallest failing case, {}, gave:\n\n{}",
                case_name(f),
                quote(&f.message)
            );
            if let Some(at) = raised_at(f) {
                md.push_str(&raised_at_markdown(&at));
            }
        }
    }
    shown.remember(f, section);
    md.push_str(&repro_markdown(f));
    let others: Vec<&FailureSummary> = c.failures.iter().filter(|g| g.id != f.id).collect();
    if others.is_empty() {
    } else if others
        .iter()
        .all(|g| g.kind == f.kind && g.message == f.message)
    {
        let _ = match others.len() {
            1 => writeln!(md, "\nThe other case shown here failed the same way."),
            n => writeln!(md, "\nThe {n} other cases shown here failed the same way."),
        };
    } else {
        md.push_str("\nOther failing cases:\n\n");
        for g in others {
            let _ = writeln!(md, "- {}: {}", case_name(g), g.message.markdown_inline());
        }
    }
    md
}

/// How many of a group's ambiguous vectors differ from the exact answer, and how many there
/// are, from the group's scored check (the unscored one carries no counts).
fn ambiguous_counts(c: &CheckResult, checks: &[CheckResult]) -> Option<(usize, usize)> {
    checks
        .iter()
        .filter(|o| o.group == c.group)
        .find_map(|o| o.counts.as_ref())
        .map(|n| (n.ambiguous - n.ambiguous_passed, n.ambiguous))
}

/// A function check's message (the harness's words, escaped as text all the same) and the
/// function's smallest failing case: its input, what the submission answered or raised (in a
/// block `quote` writes: it is the submission's text), the reproduction, and the notes.
fn function_body(
    c: &CheckResult,
    f: &crate::weekly::run::FunctionResult,
    quote: fn(&Untrusted) -> String,
) -> String {
    let mut md = c.message.markdown_inline();
    md.push('\n');
    if let Some(failure) = &f.failure {
        let _ = write!(
            md,
            "\nThe smallest failing case of `{}`, `{}` ({}), gave:\n\n{}",
            f.id.replace('`', "'"),
            failure.case.replace('`', "'"),
            markdown_inline(&failure.input),
            quote(&Untrusted::from(failure.problem.as_str()))
        );
        md.push_str(&format!(
            "\nTo run it yourself, save this as `repro.py` in your submission folder and run \
             `python3 repro.py`:\n\n{}",
            markdown_block(&failure.repro, "python")
        ));
    }
    if let Some(stats) = &f.statistics {
        let fit = &stats.fit;
        let mut said = format!("\nThe statistical check judged {} samples", stats.samples);
        if fit.invariant_failures > 0 {
            let _ = write!(
                said,
                "; {} broke the course's invariant",
                fit.invariant_failures
            );
            if let Some((i, why)) = &fit.first_failure {
                let _ = write!(said, " (the first, sample {i}: {})", markdown_inline(why));
            }
        }
        if let Some(t) = &fit.test {
            let _ = write!(
                said,
                "; {} test: statistic {:.1}, p = {:.2e}, rejected below a false-alarm rate of {:.0e}",
                t.test, t.statistic, t.p_value, t.alpha
            );
        }
        md.push_str(&said);
        md.push_str(".\n");
    }
    for note in f.notes.iter().take(3) {
        let _ = writeln!(md, "\nNote: {}", markdown_inline(note));
    }
    md
}

/// The short note on a group's ambiguous vectors (an unscored check with some that differ):
/// how many differ from the exact answer where rounding decides, and the first of them with its
/// reproduction, which states the exact answer.
pub(crate) fn ambiguous_body(c: &CheckResult, checks: &[CheckResult]) -> String {
    let shape = c.tags.get(1).map_or("", String::as_str);
    let mut md = match ambiguous_counts(c, checks) {
        Some((differ, total)) => format!(
            "{differ} of {total} ambiguous {shape} vectors differ from the exact answer where \
             rounding decides (not scored).\n"
        ),
        None => "Some ambiguous vectors differ from the exact answer where rounding decides \
                 (not scored).\n"
            .to_string(),
    };
    md.push_str(
        "\nOn these a ray grazes an edge or a silhouette so closely that rounding decides the \
         answer: honest code may give either, so they do not count.\n",
    );
    if let Some(f) = c.failures.first() {
        let _ = write!(
            md,
            "\nFor example {}: {}\n",
            case_name(f),
            f.message.markdown_inline()
        );
        md.push_str(&repro_markdown(f));
    }
    md
}

/// Whether a check is one of the unscored notes on ambiguous vectors.
pub(crate) fn is_ambiguous_note(c: &CheckResult) -> bool {
    c.status == CheckStatus::Skipped
}

/// Whether a check has something to say: every scored check, and an unscored one when some
/// of its ambiguous vectors differ from the exact answer.
pub(crate) fn worth_showing(c: &CheckResult) -> bool {
    c.status != CheckStatus::Skipped || !c.failures.is_empty()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_place_is_the_last_frame_outside_python_s_library() {
        let tb = "Traceback (most recent call last):\n  \
                  File \"/tmp/rtoracle-sandbox-x/sub/RT_object.py\", line 42, in intersect\n    \
                  t = root\n        ^^^^\n  \
                  File \"/usr/lib/python3.11/json/decoder.py\", line 3, in decode\n    \
                  x = y\n\
                  NameError: name 'root' is not defined\n";
        let at = raised_at_in(tb).unwrap();
        assert_eq!(
            at,
            RaisedAt {
                file: "RT_object.py".into(),
                line: 42,
                function: Some("intersect".into()),
                code: Some("t = root".into()),
            }
        );
        assert_eq!(at.sentence(), "RT_object.py, line 42, in intersect");
        // Only Python's own frames, or none: no place.
        assert_eq!(
            raised_at_in("  File \"<frozen importlib._bootstrap>\", line 1, in f\n"),
            None
        );
        assert_eq!(raised_at_in("NameError: x\n"), None);
    }

    #[test]
    fn the_innermost_frame_of_the_submission_wins() {
        let tb = "  File \"/s/RT_object.py\", line 10, in intersect\n    return helper()\n  \
                  File \"/s/RT_utility.py\", line 7, in helper\n    return 1 / 0\n\
                  ZeroDivisionError: division by zero\n";
        let at = raised_at_in(tb).unwrap();
        assert_eq!((at.file.as_str(), at.line), ("RT_utility.py", 7));
        assert_eq!(at.code.as_deref(), Some("return 1 / 0"));
    }
}
