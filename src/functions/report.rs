//! A week's function checks in words, for `rtoracle check` (the JSON form is [`WeekReport`]'s
//! serde).
//!
//! Everything the candidate controls (error messages, answers quoted in a problem) is escaped
//! for the terminal ([`crate::escape::terminal_line`], [`crate::escape::terminal_text`]).

use super::run::{FunctionResult, Status, WeekReport};
use super::samplers::Standing;
use crate::escape::{terminal_line, terminal_text};

fn status_word(s: Status) -> &'static str {
    match s {
        Status::Passed => "PASS",
        Status::Failed => "FAIL",
        Status::NotRun => "NOT RUN",
    }
}

fn standing_word(s: Standing) -> &'static str {
    match s {
        Standing::Mistake | Standing::Course => "mistake",
        Standing::Physical => "physical alternative",
        Standing::Alternative => "the course's other version",
        Standing::Departure => "departure that keeps the course's behaviour",
    }
}

fn counts(f: &FunctionResult) -> String {
    let c = f.counts;
    let mut s = format!("{}/{}", c.passed, c.passed + c.failed);
    if c.not_scored > 0 {
        s.push_str(&format!(", {} not scored", c.not_scored));
    }
    if c.not_run > 0 {
        s.push_str(&format!(", {} not run", c.not_run));
    }
    s
}

/// The report as text: one line per function (this week's first, then the earlier weeks'),
/// then up to `show` failures with their smallest case and a Python reproduction.
pub fn to_text(report: &WeekReport, show: usize) -> String {
    let mut out = String::new();
    out.push_str(&format!(
        "functions of {} (seed {}; each statistical test at a false-alarm rate of {:.0e}):\n",
        report.week, report.options.seed, report.options.alpha
    ));
    let ordered: Vec<&FunctionResult> = report
        .of_the_week()
        .chain(report.functions.iter().filter(|f| f.week != report.week))
        .collect();
    let width = ordered.iter().map(|f| f.id.len()).max().unwrap_or(0);
    for f in &ordered {
        let mut line = format!(
            "  {} {:<width$}  {:<7}  {}",
            f.week,
            f.id,
            status_word(f.status),
            counts(f)
        );
        if f.given {
            line.push_str("  (given by the course)");
        }
        if let Some(m) = f.mistakes.first() {
            line.push_str(&format!("  {}: {}", standing_word(m.standing), m.name));
            for other in &f.mistakes[1..] {
                line.push_str(&format!(" or {}", other.name));
            }
        }
        out.push_str(&line);
        out.push('\n');
    }
    let failed: Vec<&&FunctionResult> = ordered
        .iter()
        .filter(|f| f.status == Status::Failed)
        .collect();
    for f in failed.iter().take(show) {
        out.push_str(&format!("\n{} ({}) fails:\n", f.id, f.function));
        if let Some(c) = &f.failure {
            out.push_str(&format!(
                "  smallest failing case {}: {}\n",
                c.case,
                terminal_line(&c.input)
            ));
            out.push_str(&format!("  {}\n", terminal_line(&c.problem)));
        }
        for m in &f.mistakes {
            out.push_str(&format!(
                "  {} {}: {}\n",
                standing_word(m.standing),
                m.name,
                m.says
            ));
        }
        if let Some(c) = &f.failure {
            out.push_str("  reproduce it in Python, in the submission folder:\n");
            for l in terminal_text(&c.repro).lines() {
                out.push_str(&format!("    {l}\n"));
            }
        }
        out.push_str(&format!("  (compared: {})\n", f.tolerance));
    }
    if failed.len() > show {
        out.push_str(&format!(
            "\n... and {} more failing functions (--show N)\n",
            failed.len() - show
        ));
    }
    for f in ordered.iter().filter(|f| !f.notes.is_empty()) {
        for n in &f.notes {
            out.push_str(&format!("note: {}: {}\n", f.id, n));
        }
    }
    let this_week: Vec<&FunctionResult> = report.of_the_week().collect();
    let passed = this_week
        .iter()
        .filter(|f| f.status == Status::Passed)
        .count();
    out.push_str(&format!(
        "{}: {passed} of {} functions of the week pass; {} of {} in all\n",
        report.week,
        this_week.len(),
        report
            .functions
            .iter()
            .filter(|f| f.status == Status::Passed)
            .count(),
        report.functions.len()
    ));
    out
}
