//! The check report as text for a person ([`CheckReport::to_text`]): who was checked, a table
//! of counts per shape, the verdict and what explains it, the first failures with how to
//! reproduce each, and the end of the candidate's stderr.
//!
//! What the text promises about text from the candidate: each message, traceback, name and
//! stderr line is written through [`crate::escape::terminal_line`] or
//! [`crate::escape::terminal_text`], so nothing a candidate prints can move the cursor, colour
//! the terminal or fake a line of the report. When every failure is the same error (a
//! submission that cannot be imported), the text says it once.

use std::collections::HashMap;
use std::fmt::Write as _;

use crate::candidate::judging::check::FailureKind;
use crate::candidate::judging::report::{CheckReport, Counts, Failure};
use crate::escape::{terminal_line, terminal_text};

impl CheckReport {
    /// A summary table and the first `max_failures` failures, each with its request and
    /// expected answer (or its Python reproduction for the course adapter). Every text from
    /// the candidate is escaped for the terminal.
    pub fn to_text(&self, max_failures: usize) -> String {
        let mut s = String::new();
        self.write_header(&mut s);
        self.write_table(&mut s);
        self.write_verdict(&mut s);
        let rest = self.write_diagnosed(&mut s);
        rest.write_failures(&mut s, max_failures);
        self.write_stderr_tail(&mut s);
        s
    }

    /// Who was checked, by what, and why it could not run, if so.
    fn write_header(&self, s: &mut String) {
        let _ = writeln!(s, "candidate: {}", terminal_line(&self.candidate));
        if let Some(j) = &self.judged_by {
            let _ = writeln!(s, "judged by: {j}");
        }
        if let Some(e) = &self.import_error {
            let _ = writeln!(
                s,
                "the submission could not be imported: {}",
                terminal_line(&e.to_string())
            );
            if !e.traceback.is_empty() {
                for line in terminal_text(e.traceback.trim_end()).lines() {
                    let _ = writeln!(s, "    {line}");
                }
            }
        }
        for note in &self.notes {
            let _ = writeln!(s, "note: {}", terminal_line(note));
        }
        if let Some(f) = &self.start_failure {
            let _ = writeln!(
                s,
                "the candidate could not be started: {}",
                terminal_line(f)
            );
        }
    }

    /// The counts, one row per shape and one for all.
    fn write_table(&self, s: &mut String) {
        let _ = writeln!(
            s,
            "\n{:<10} {:>7} {:>7} {:>7} {:>7} {:>8} {:>7} {:>10} {:>11} {:>5}",
            "shape",
            "total",
            "passed",
            "failed",
            "errors",
            "timeouts",
            "not_run",
            "ambiguous",
            "amb_passed",
            "any"
        );
        let row = |s: &mut String, name: &str, c: &Counts| {
            let _ = writeln!(
                s,
                "{:<10} {:>7} {:>7} {:>7} {:>7} {:>8} {:>7} {:>10} {:>11} {:>5}",
                name,
                c.total,
                c.passed,
                c.failed,
                c.errors,
                c.timeouts,
                c.not_run,
                c.ambiguous,
                c.ambiguous_passed,
                c.any
            );
        };
        for (kind, c) in &self.by_shape {
            row(s, kind.name(), c);
        }
        row(s, "all", &self.counts);
        let _ = writeln!(
            s,
            "(total: the definite vectors, which are judged; the ambiguous and any ones are run and not counted in it)"
        );
    }

    /// The verdict, and what explains it: required shapes not run, the triangles' winding,
    /// the diagnosis, restarts, the sandbox's note, the vectors not run.
    fn write_verdict(&self, s: &mut String) {
        let _ = writeln!(
            s,
            "\nverdict: {} ({} of {} definite vectors passed{})",
            if self.passed() { "PASS" } else { "FAIL" },
            self.counts.passed,
            self.counts.total,
            if self.counts.not_run > 0 {
                format!(", {} not run", self.counts.not_run)
            } else {
                String::new()
            }
        );
        let c = &self.counts;
        if c.unscored_timeouts + c.unscored_crashes > 0 {
            let _ = writeln!(
                s,
                "hangs and crashes: {} time-outs and {} crashes on vectors that are not scored \
                 (ambiguous or any): a candidate must answer every vector, whatever it answers",
                c.unscored_timeouts, c.unscored_crashes
            );
        }
        if c.watertight > 0 {
            let _ = writeln!(
                s,
                "watertight groups: {}",
                crate::candidate::judging::watertight::groups_summary(
                    c.watertight,
                    c.watertight_cracked
                )
            );
        }
        if c.left_unrun() > 0 {
            let _ = writeln!(
                s,
                "left unrun: {} definite vectors (why: below); only the vectors of a shape the \
                 candidate does not implement may be left out",
                c.left_unrun()
            );
        }
        for k in self.required_not_run() {
            let _ = writeln!(
                s,
                "required: {k}s (--require {k}), but {} {k} vectors were not run (why: below)",
                self.by_shape[&k].not_run
            );
        }
        if let Some(w) = self.triangle_winding {
            let _ = writeln!(
                s,
                "triangles: your triangles face {}; either winding is accepted (front_face is judged by yours)",
                w.formula()
            );
        }
        for d in &self.diagnosis {
            let _ = writeln!(s, "diagnosis: {}", d.sentence());
        }
        if self.restarts > 0 {
            let _ = writeln!(s, "the candidate was restarted {} times", self.restarts);
        }
        if let Some(note) = self.sandbox.as_ref().and_then(|f| f.note.as_ref()) {
            let _ = writeln!(s, "sandbox: {}", terminal_line(note));
        }
        // Vectors not run: one line per shape and reason.
        for n in &self.not_run_summary {
            let _ = writeln!(
                s,
                "not run: {} {} vectors: {}",
                n.count,
                n.shape,
                terminal_line(&n.reason)
            );
        }
    }

    /// For each shape whose failures a diagnosis explains all of: the fix, and one of its
    /// failures with how to reproduce it (the others would only say the same). Returns the
    /// report with those failures taken out, for [`CheckReport::write_failures`] to show the
    /// rest.
    fn write_diagnosed(&self, s: &mut String) -> CheckReport {
        let mut rest = self.clone();
        for d in self.diagnosis.iter().filter(|d| d.explained == d.of) {
            let Some(first) = self.failures.iter().find(|f| f.shape == d.shape) else {
                continue;
            };
            s.push('\n');
            if let Some(fix) = crate::candidate::judging::diagnose::fix(&d.mistake_id) {
                let _ = writeln!(s, "fix for the {} failures: {fix}", d.shape);
            }
            let _ = writeln!(
                s,
                "one of the {} {} failures, all explained by the diagnosis:",
                d.of, d.shape
            );
            write_failure(s, first);
            rest.failures.retain(|f| f.shape != d.shape);
        }
        rest
    }

    /// The first `max_failures` failures, or one cause said once when all share it. Failures
    /// alike ([`alike`]) are shown once, with the ids of the others.
    fn write_failures(&self, s: &mut String, max_failures: usize) {
        let shown = &self.failures;
        let groups = alike(shown);
        if shown.is_empty() {
        } else if shown.len() > 1 && groups.len() == 1 {
            // One cause for all (an import error): said once, with one example.
            let f = &shown[0];
            let _ = writeln!(
                s,
                "\nall {} failures are the same: [{}] {}",
                shown.len(),
                f.kind.name(),
                terminal_line(&f.message)
            );
            if max_failures > 0 && self.import_error.is_none() {
                let _ = writeln!(s, "for example {} ({}):", terminal_line(&f.id), f.shape);
                write_case(s, f);
            }
        } else {
            let kinds = if groups.len() < shown.len() {
                format!(" ({} different)", groups.len())
            } else {
                String::new()
            };
            let _ = writeln!(
                s,
                "\nfirst {} of {} failures{kinds}:",
                groups.len().min(max_failures),
                shown.len()
            );
            for group in groups.iter().take(max_failures) {
                write_failure(s, group[0]);
                write_others(s, &group[1..]);
            }
        }
    }

    /// The last 20 lines of the candidate's stderr.
    fn write_stderr_tail(&self, s: &mut String) {
        let tail = self.stderr_tail.trim_end();
        if !tail.is_empty() {
            let _ = writeln!(s, "\nend of the candidate's stderr:");
            for line in tail
                .lines()
                .rev()
                .take(20)
                .collect::<Vec<_>>()
                .into_iter()
                .rev()
            {
                let _ = writeln!(s, "    {}", terminal_line(line));
            }
        }
    }
}

/// The failures in groups alike: the same kind and the same message once the failure's own id
/// is taken out of it (a protocol error quotes the line, which carries the id), in the order
/// of their first failure.
fn alike(failures: &[Failure]) -> Vec<Vec<&Failure>> {
    let mut index: HashMap<(FailureKind, String), usize> = HashMap::new();
    let mut groups: Vec<Vec<&Failure>> = Vec::new();
    for f in failures {
        let key = (f.kind, f.message.replace(f.id.as_str(), "\u{0}"));
        match index.get(&key) {
            Some(&g) => groups[g].push(f),
            None => {
                index.insert(key, groups.len());
                groups.push(vec![f]);
            }
        }
    }
    groups
}

/// Most ids of failures alike named after the one shown.
const OTHERS_NAMED: usize = 5;

/// The other failures of a group: how many, and the first ids.
fn write_others(s: &mut String, others: &[&Failure]) {
    if others.is_empty() {
        return;
    }
    let mut ids: Vec<String> = others
        .iter()
        .take(OTHERS_NAMED)
        .map(|f| terminal_line(&f.id))
        .collect();
    if others.len() > OTHERS_NAMED {
        ids.push("...".into());
    }
    let _ = writeln!(
        s,
        "  and {} more failing the same way: {}",
        others.len(),
        ids.join(", ")
    );
}

fn write_failure(s: &mut String, f: &Failure) {
    let _ = writeln!(
        s,
        "\n[{}] {} ({}): {}",
        f.kind.name(),
        terminal_line(&f.id),
        f.shape,
        terminal_line(&f.message)
    );
    write_case(s, f);
}

/// A failure's tags and how to reproduce it.
fn write_case(s: &mut String, f: &Failure) {
    if !f.tags.is_empty() {
        let _ = writeln!(s, "  tags: {}", terminal_line(&f.tags.join(", ")));
    }
    if f.repro.is_empty() {
        let _ = writeln!(s, "  request: {}", terminal_line(&f.request));
        let _ = writeln!(s, "  expected: {}", f.expected_text);
    } else {
        // Unindented, so that it can be pasted into a file as it is.
        let _ = writeln!(
            s,
            "  reproduce: save these lines as repro.py in the submission folder and run `python3 repro.py`:\n"
        );
        for line in f.repro.lines() {
            let _ = writeln!(s, "{}", terminal_line(line));
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::candidate::judging::report::{RunInfo, build_report};
    use crate::candidate::process::outcome::Outcome;
    use crate::candidate::process::protocol::Answer;

    #[test]
    fn one_error_on_every_case_is_said_once_and_candidate_text_is_escaped() {
        let cases = crate::candidate::test_cases::basic_cases();
        let error = Answer::error("SyntaxError", "bad\x1b[31m input");
        let outcomes: Vec<Outcome> = cases
            .iter()
            .map(|_| Outcome::Answered {
                answer: error.clone(),
                junk: vec![],
            })
            .collect();
        let info = RunInfo {
            candidate: "evil\nverdict: PASS".into(),
            course_api: true,
            ..RunInfo::default()
        };
        let text = build_report(&cases, &outcomes, info).to_text(10);
        assert_eq!(text.matches("raised SyntaxError").count(), 1, "{text}");
        assert_eq!(text.matches("reproduce").count(), 1, "{text}");
        assert!(text.contains(&format!("all {} failures are the same", cases.len())));
        assert!(
            !text.contains('\x1b') && text.contains("\\x1b[31m"),
            "{text}"
        );
        assert!(!text.contains("\nverdict: PASS"), "{text}");
    }

    /// The same error on many vectors (a protocol error quoting each line, which differs only
    /// by its id) filled the report with the same paragraph: it is shown once, with the ids of
    /// the others; different failures each still show.
    #[test]
    fn failures_alike_are_shown_once_with_the_others_ids() {
        let cases = crate::candidate::test_cases::basic_cases();
        let bad = |c: &crate::oracle::vectors::Case| Outcome::Protocol {
            message: format!(
                "a malformed answer (not valid JSON): the line was {:?}",
                format!("{{\"id\":\"{}\",\"hit\":nan}}", c.id)
            ),
            junk: vec![],
        };
        let mut outcomes: Vec<Outcome> = cases.iter().map(bad).collect();
        outcomes[4] = Outcome::Timeout { junk: vec![] };
        let text = build_report(&cases, &outcomes, RunInfo::default()).to_text(10);
        assert!(
            text.contains("first 2 of 5 failures (2 different):"),
            "{text}"
        );
        assert_eq!(text.matches("[protocol]").count(), 1, "{text}");
        assert!(
            text.contains(
                "  and 3 more failing the same way: sphere-basic-0001, quad-basic-0000, quad-basic-0001"
            ),
            "{text}"
        );
        assert!(text.contains("[timeout] triangle-basic-0000"), "{text}");
        // Alike all: said once.
        outcomes[4] = bad(&cases[4]);
        let text = build_report(&cases, &outcomes, RunInfo::default()).to_text(10);
        assert!(
            text.contains("all 5 failures are the same: [protocol]"),
            "{text}"
        );
    }
}
