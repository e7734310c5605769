//! A week's function checks in words, for `rtoracle check`, and the one JSON document
//! `rtoracle check --json` prints for any week ([`CheckDocument`]).
//!
//! Everything the candidate controls (error messages, answers quoted in a problem) is escaped
//! for the terminal ([`crate::escape::terminal_line`], [`crate::escape::terminal_text`]).

use serde::Serialize;

use super::run::{FunctionResult, Status, WeekReport};
use super::samplers::Standing;
use super::score::WeekScore;
use crate::candidate::judging::report::CheckReport;
use crate::escape::{terminal_line, terminal_text};

/// What `rtoracle check --json` prints says it is: [`CheckDocument::schema`].
pub const CHECK_SCHEMA: &str = "rtoracle-check";

/// The version of [`CheckDocument`]'s layout: 2 since the document has one shape for every
/// week (version 1, unversioned, was the intersections' report at the top for week 4 and this
/// document without `schema`, `version` and `verdict` for later weeks; `docs/commands.md`
/// says how to read both).
pub const CHECK_VERSION: u32 = 2;

/// The one JSON document of `rtoracle check --json`, whatever the week: the intersections'
/// report, and the week's function checks and their score (`null` for week 4 and for an
/// adapter, which have none). Its JSON Schema is `docs/schemas/check.schema.json`.
#[derive(Clone, Debug, Serialize)]
pub struct CheckDocument<'a> {
    /// [`CHECK_SCHEMA`].
    pub schema: &'static str,
    /// [`CHECK_VERSION`].
    pub version: u32,
    /// The week checked as: 4 (the intersection vectors only) to 10.
    pub week: u8,
    /// How the week was found (`--week 6`, the marks in the folder's files), or why it is 4.
    pub week_from: String,
    /// `pass` or `fail`: the exit code's verdict (0 or 1).
    pub verdict: &'static str,
    /// The intersection vectors' report.
    pub intersections: &'a CheckReport,
    /// Sphere vectors not scored because the course's own `get_uv` raised on them (weeks 7 to
    /// 10; 0 otherwise).
    pub pole_crashes_excused: usize,
    /// The week's function checks (`null` for week 4).
    pub functions: Option<&'a WeekReport>,
    /// The function checks scored by the week's groups (`null` for week 4).
    pub score: Option<&'a WeekScore>,
}

impl<'a> CheckDocument<'a> {
    /// The document of a week-4 check (or an adapter's): intersections only; `week_from` says
    /// why it is week 4.
    pub fn intersections(report: &'a CheckReport, week_from: impl Into<String>) -> Self {
        CheckDocument {
            schema: CHECK_SCHEMA,
            version: CHECK_VERSION,
            week: 4,
            week_from: week_from.into(),
            verdict: if report.passed() { "pass" } else { "fail" },
            intersections: report,
            pole_crashes_excused: 0,
            functions: None,
            score: None,
        }
    }

    /// The document as pretty JSON.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("a check document always serialises")
    }
}

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
