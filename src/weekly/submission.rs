//! Checking one submission of a week: the intersection vectors and the week's function checks,
//! in one session ([`check_week`]), with the week-4 vectors judged fairly on later weeks' code.
//!
//! From week 7 on, the course's `Sphere.intersect` calls `get_uv`, whose `math.acos` raises
//! `ValueError` when rounding puts `|n.y|` above 1 (a hit at a pole). The course's own code does
//! that, so on week-7 to week-10 code a sphere vector whose only fault is that error is not
//! scored ([`excuse_pole_crashes`]); the report counts them.

use serde::Serialize;

use super::run::{FunctionOptions, WeekReport, run_week};
use super::runner::SessionRunner;
use super::score::{WeekScore, score};
use super::week::Week;
use crate::candidate::judging::report::CheckReport;
use crate::candidate::judging::report::build_report;
use crate::candidate::process::command::CandidateCommand;
use crate::candidate::process::error::HarnessError;
use crate::candidate::process::options::RunOptions;
use crate::candidate::process::outcome::Outcome;
use crate::candidate::process::session::Session;
use crate::candidate::run_info;
use crate::oracle::vectors::{Case, Class, ShapeKind};

/// The tag given to a sphere vector not scored because the course's `get_uv` raised on it.
pub const POLE_CRASH_TAG: &str = "course-get-uv-raises";

/// A week's submission, checked.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WeekCheck {
    /// The week it was checked as.
    pub week: Week,
    /// How the week was found (`--week`, or the marks in the folder).
    pub week_from: String,
    /// The intersection vectors' report.
    pub intersections: CheckReport,
    /// Sphere vectors not scored because `get_uv`'s `acos` raised on them (weeks 7 to 10).
    pub pole_crashes_excused: usize,
    /// The function checks.
    pub functions: WeekReport,
    /// The function checks scored by the week's groups.
    pub score: WeekScore,
}

impl WeekCheck {
    /// Whether the intersections and every function passed.
    pub fn passed(&self) -> bool {
        self.intersections.passed() && self.functions.passed()
    }

    /// The one JSON document of `rtoracle check --json` for this check.
    pub fn document(&self) -> super::report::CheckDocument<'_> {
        super::report::CheckDocument {
            schema: super::report::CHECK_SCHEMA,
            version: super::report::CHECK_VERSION,
            week: self.week.number(),
            week_from: self.week_from.clone(),
            verdict: if self.passed() { "pass" } else { "fail" },
            intersections: &self.intersections,
            pole_crashes_excused: self.pole_crashes_excused,
            functions: Some(&self.functions),
            score: Some(&self.score),
        }
    }

    /// The report as one JSON object.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("a report always serialises")
    }

    /// The report as text: the intersections', then the functions' (`show` failures each).
    pub fn to_text(&self, show: usize) -> String {
        let mut out = format!("checked as {} ({})\n\n", self.week, self.week_from);
        out.push_str(self.intersections.to_text(show).trim_end());
        out.push('\n');
        if self.pole_crashes_excused > 0 {
            out.push_str(&format!(
                "not scored: {} sphere vectors on which get_uv's acos raised ValueError at a pole (the course's own code does)\n",
                self.pole_crashes_excused
            ));
        }
        out.push('\n');
        out.push_str(&super::report::to_text(&self.functions, show));
        out.push_str(&format!(
            "\nscore of {}'s functions: {:.1} / {:.0}\n",
            self.week, self.score.score, self.score.max
        ));
        for g in &self.score.groups {
            let mut line = format!(
                "  {:<22} {:>5.1} / {:<3.0} {}",
                g.id, g.score, g.max, g.name
            );
            if !g.mistakes.is_empty() {
                line.push_str(&format!(" (mistake: {})", g.mistakes.join(" or ")));
            }
            out.push_str(&line);
            out.push('\n');
        }
        if !self.score.regressions.is_empty() {
            out.push_str(&format!(
                "  no points, but failing (given by the skeleton or an earlier week's): {}\n",
                self.score.regressions.join(", ")
            ));
        }
        out.push_str(&format!(
            "\nverdict: {} (intersections {}, functions {})\n",
            if self.passed() { "PASS" } else { "FAIL" },
            if self.intersections.passed() {
                "pass"
            } else {
                "fail"
            },
            if self.functions.passed() {
                "pass"
            } else {
                "fail"
            }
        ));
        out
    }
}

/// `cases` with the sphere vectors that a week-7-or-later `get_uv` raised `ValueError` on
/// (`math domain error`, the course's own behaviour at a pole) made not scored, and how many.
/// Before week 7, or for other errors, nothing changes.
pub fn excuse_pole_crashes(week: Week, cases: &[Case], outcomes: &[Outcome]) -> (Vec<Case>, usize) {
    let mut out = cases.to_vec();
    if week.number() < 7 {
        return (out, 0);
    }
    let mut excused = 0;
    for (case, outcome) in out.iter_mut().zip(outcomes) {
        if case.shape.kind() != ShapeKind::Sphere || !case.expect.class.is_definite() {
            continue;
        }
        let Outcome::Answered { answer, .. } = outcome else {
            continue;
        };
        let Some(e) = &answer.error else { continue };
        if e.kind == "ValueError" && e.message.contains("math domain error") {
            case.expect.class = Class::Any;
            case.expect.tags.push(POLE_CRASH_TAG.to_string());
            excused += 1;
        }
    }
    (out, excused)
}

/// Starts `command`, runs `cases` and the function checks of `week` in the same session, and
/// returns both reports (the candidate's processes are gone when it returns).
pub fn check_week(
    command: CandidateCommand,
    cases: &[Case],
    run: RunOptions,
    week: Week,
    week_from: String,
    options: FunctionOptions,
) -> Result<WeekCheck, HarnessError> {
    let mut session = Session::start(command, run)?;
    let outcomes = session.run(cases)?;
    let (cases, pole_crashes_excused) = excuse_pole_crashes(week, cases, &outcomes);
    let functions = run_week(&mut SessionRunner::new(&mut session), week, options);
    let intersections = build_report(&cases, &outcomes, run_info(&session));
    Ok(WeekCheck {
        week,
        week_from,
        intersections,
        pole_crashes_excused,
        score: score(&functions),
        functions,
    })
}
