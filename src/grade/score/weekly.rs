//! Scoring a week's function checks by the rubric's functions groups: one check per function,
//! and one unscored check listing what failed among the functions that carry no points.
//!
//! A function earns its group's share (the group's points over its number of functions) when it
//! passes: every scored case right, or its statistical test passed. A failing function whose
//! answers fit an alternative the rubric accepts (`accept`) passes too, and its message says
//! which. One that fails, raises or is not run earns nothing; its check holds the function's
//! result (counts, its smallest failing case with a Python reproduction, the catalogued
//! mistakes its answers fit, a sampler's statistics), which the reports show.
//!
//! Every other function the week checks (the skeleton's, the earlier weeks') is run and judged
//! too: a failure among them is a regression, listed in the `functions.unscored` check (0
//! points), and shown in the feedback.
//!
//! What the messages promise: they are the harness's own words (function ids, counts, the
//! catalogue's names and sentences). What the submission said (an exception's text) is only in
//! the function result's `failure.problem`, which the reports quote as untrusted text.

use crate::grade::checkers::FunctionsOutcome;
use crate::grade::result::{CheckResult, CheckStatus};
use crate::grade::rubric::{Group, GroupKind, Rubric, Visibility};
use crate::weekly::{run::FunctionResult, run::Status};

/// The id of the unscored check that lists the failing functions that carry no points.
pub const UNSCORED_ID: &str = "functions.unscored";

/// Whether `f` passes under `rubric` (passed, or failed with answers fitting an accepted
/// alternative), and the alternative when that is why.
fn passes<'a>(f: &'a FunctionResult, rubric: &Rubric) -> (bool, Option<&'a str>) {
    match f.status {
        Status::Passed => (true, None),
        Status::Failed => match f.mistakes.iter().find(|m| rubric.accept.contains(&m.name)) {
            Some(m) => (true, Some(m.name.as_str())),
            None => (false, None),
        },
        Status::NotRun => (false, None),
    }
}

/// The counts of `f` in words: `12 of 12 cases right (2 not scored)`.
fn counts_sentence(f: &FunctionResult) -> String {
    if let Some(stats) = &f.statistics {
        return format!("{} samples judged", stats.samples);
    }
    let c = f.counts;
    let scored = c.passed + c.failed;
    let mut s = format!("{} of {scored} scored cases right", c.passed);
    if c.not_scored > 0 {
        s.push_str(&format!(", {} not scored", c.not_scored));
    }
    if c.not_run > 0 {
        s.push_str(&format!(", {} not run", c.not_run));
    }
    s
}

/// The message of one function's check (the harness's words only).
fn message(f: &FunctionResult, accepted: Option<&str>, passed: bool) -> String {
    let mut m = match (f.status, accepted) {
        (Status::Passed, _) => format!("{} passed: {}.", f.id, counts_sentence(f)),
        (Status::Failed, Some(alt)) => format!(
            "{} passed as the version the rubric accepts ({alt}): {}.",
            f.id,
            counts_sentence(f)
        ),
        (Status::Failed, None) => format!("{} failed: {}.", f.id, counts_sentence(f)),
        (Status::NotRun, _) => format!("{} was not run: {}.", f.id, counts_sentence(f)),
    };
    if !passed {
        let named: Vec<String> = f
            .mistakes
            .iter()
            .map(|k| format!("{} ({})", k.name, k.says))
            .collect();
        if !named.is_empty() {
            m.push_str(&format!(
                " Its answers fit the catalogued mistake {}.",
                named.join(", or ")
            ));
        }
        if f.status == Status::NotRun {
            if let Some(note) = f.notes.first() {
                m.push_str(&format!(" {}.", note.trim_end_matches('.')));
            }
        }
    }
    m
}

/// The checks of the rubric's functions groups from `outcome` (rubric order), then the unscored
/// check (when the week's report has functions outside every group).
pub fn function_checks(rubric: &Rubric, outcome: &FunctionsOutcome) -> Vec<CheckResult> {
    let groups: Vec<&Group> = rubric
        .groups
        .iter()
        .filter(|g| g.kind == GroupKind::Functions)
        .collect();
    let mut checks = Vec::new();
    for g in &groups {
        checks.extend(group_checks(g, rubric, outcome));
    }
    if let Some(report) = &outcome.report {
        let scored: Vec<&str> = groups
            .iter()
            .flat_map(|g| g.functions.iter().flatten().map(String::as_str))
            .collect();
        let unscored: Vec<&FunctionResult> = report
            .functions
            .iter()
            .filter(|f| !scored.contains(&f.id.as_str()))
            .collect();
        if !unscored.is_empty() {
            checks.push(unscored_check(&unscored, rubric));
        }
    }
    checks
}

/// One check per function of group `g`.
fn group_checks(g: &Group, rubric: &Rubric, outcome: &FunctionsOutcome) -> Vec<CheckResult> {
    let names = g.functions.as_deref().unwrap_or_default();
    let share = g.points / names.len().max(1) as f64;
    names
        .iter()
        .map(|id| {
            let result = outcome
                .report
                .as_ref()
                .and_then(|r| r.functions.iter().find(|f| f.id == *id));
            let (score, status, message) = match (result, &outcome.fatal) {
                (_, Some(fatal)) => (
                    0.0,
                    CheckStatus::Error,
                    format!("{id} could not be checked: no function could be run. {fatal}"),
                ),
                (None, None) => (
                    0.0,
                    CheckStatus::Error,
                    format!("{id} was not checked (the week's checks do not hold it)."),
                ),
                (Some(f), None) => {
                    let (ok, accepted) = passes(f, rubric);
                    let status = match (ok, f.status) {
                        (true, _) => CheckStatus::Passed,
                        (false, Status::NotRun) => CheckStatus::Error,
                        (false, _) => CheckStatus::Failed,
                    };
                    (
                        if ok { share } else { 0.0 },
                        status,
                        message(f, accepted, ok),
                    )
                }
            };
            CheckResult {
                id: format!("{}.{id}", g.id),
                group: g.id.clone(),
                name: result.map_or_else(|| id.clone(), |f| format!("{id}: {}", f.function)),
                score,
                max_score: share,
                status,
                message: message.into(),
                visibility: g.visibility,
                tags: vec!["functions".to_string(), id.clone()],
                counts: None,
                credit: None,
                failures: Vec::new(),
                image: None,
                function: result.filter(|f| f.status != Status::Passed).cloned(),
            }
        })
        .collect()
}

/// The check listing the failing functions among those that carry no points.
fn unscored_check(unscored: &[&FunctionResult], rubric: &Rubric) -> CheckResult {
    let failing: Vec<&&FunctionResult> = unscored
        .iter()
        .filter(|f| !passes(f, rubric).0 && f.status == Status::Failed)
        .collect();
    let names: Vec<String> = failing
        .iter()
        .map(|f| {
            let mistakes: Vec<&str> = f.mistakes.iter().map(|m| m.name.as_str()).collect();
            if mistakes.is_empty() {
                format!("{} ({})", f.id, f.week)
            } else {
                format!("{} ({}; fits {})", f.id, f.week, mistakes.join(" or "))
            }
        })
        .collect();
    let message = if failing.is_empty() {
        format!(
            "The {} functions that carry no points (the skeleton's and the earlier weeks') pass.",
            unscored.len()
        )
    } else {
        format!(
            "No points, but failing: {} (of the {} functions the skeleton or an earlier week gives). A regression here may cost points in the images.",
            names.join(", "),
            unscored.len()
        )
    };
    CheckResult {
        id: UNSCORED_ID.to_string(),
        group: UNSCORED_ID.to_string(),
        name: "Functions the skeleton or an earlier week gives (no points)".to_string(),
        score: 0.0,
        max_score: 0.0,
        status: if failing.is_empty() {
            CheckStatus::Passed
        } else {
            CheckStatus::Failed
        },
        message: message.into(),
        visibility: Visibility::Visible,
        tags: vec!["functions".to_string(), "unscored".to_string()],
        counts: None,
        credit: None,
        failures: Vec::new(),
        image: None,
        function: failing.first().map(|f| (**f).clone()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::weekly::run::{CaseCounts, NamedMistake};
    use crate::weekly::samplers::Standing;
    use crate::weekly::{run::FunctionOptions, run::WeekReport, week::Week};

    fn result(id: &str, week: u8, status: Status, mistake: Option<&str>) -> FunctionResult {
        FunctionResult {
            id: id.into(),
            function: format!("f_{id}()"),
            week: Week::new(week).unwrap(),
            given: false,
            tolerance: String::new(),
            status,
            counts: CaseCounts {
                passed: 3,
                failed: usize::from(status == Status::Failed),
                ..CaseCounts::default()
            },
            failure: None,
            mistakes: mistake
                .map(|m| NamedMistake {
                    name: m.into(),
                    says: "says".into(),
                    standing: Standing::Alternative,
                })
                .into_iter()
                .collect(),
            statistics: None,
            notes: vec!["not run: the code time budget ran out".into()],
            by_behaviour: 0,
            partners: &[],
        }
    }

    fn outcome(functions: Vec<FunctionResult>) -> FunctionsOutcome {
        FunctionsOutcome {
            report: Some(WeekReport {
                week: Week::new(5).unwrap(),
                options: FunctionOptions::default(),
                functions,
            }),
            ..FunctionsOutcome::default()
        }
    }

    /// Shares are equal within a group; a pass earns its share, a failure or a function not run
    /// earns nothing; an accepted alternative passes; an unscored failure is listed without
    /// points; an outcome that could not run scores every function 0 with the reason.
    #[test]
    fn functions_groups_score_by_equal_shares() {
        // The week-5 rubric with the function groups of this test (the built-in one scores only
        // the direct term).
        let builtin = crate::grade::rubric::weeks::builtin_rubric_toml("week05").unwrap();
        let lights = "[[group]]\nid = \"functions.lights\"";
        let at = builtin.find(lights).unwrap();
        let end = at + builtin[at..].find("\n\n").unwrap();
        let groups = "[[group]]\nid = \"functions.lights\"\nname = \"lights\"\nkind = \"functions\"\nfunctions = [\"occlusion\", \"direct-term\"]\npoints = 35\n\n[[group]]\nid = \"functions.lambertian\"\nname = \"lambertian\"\nkind = \"functions\"\nfunctions = [\"lambertian\", \"lambertian-lobe\"]\npoints = 28\n\n[[group]]\nid = \"functions.background\"\nname = \"background\"\nkind = \"functions\"\nfunctions = [\"background\"]\npoints = 7";
        let text = format!("{}{groups}{}", &builtin[..at], &builtin[end..]);
        let rubric = Rubric::from_toml(&text, "t").unwrap();
        let older = "older_direct_term_one_over_d";
        let all = vec![
            result("occlusion", 5, Status::Passed, None),
            result("direct-term", 5, Status::Failed, Some(older)),
            result("lambertian", 5, Status::NotRun, None),
            result("lambertian-lobe", 5, Status::Passed, None),
            result("background", 5, Status::Passed, None),
            result("extra", 5, Status::Failed, Some("shadows_missing")),
        ];
        let checks = function_checks(&rubric, &outcome(all.clone()));
        let score = |id: &str| checks.iter().find(|c| c.id == id).unwrap();
        assert_eq!(score("functions.lights.occlusion").score, 17.5);
        assert_eq!(score("functions.lights.direct-term").score, 0.0);
        assert!(
            score("functions.lights.direct-term")
                .message
                .contains(older)
        );
        assert_eq!(score("functions.lambertian.lambertian").score, 0.0);
        assert_eq!(
            score("functions.lambertian.lambertian").status,
            CheckStatus::Error
        );
        assert!(
            score("functions.lambertian.lambertian")
                .message
                .contains("budget")
        );
        assert_eq!(score("functions.lambertian.lambertian-lobe").score, 14.0);
        let unscored = score(UNSCORED_ID);
        assert_eq!((unscored.score, unscored.max_score), (0.0, 0.0));
        assert!(unscored.message.contains("extra") && unscored.message.contains("shadows_missing"));
        // With the earlier direct term accepted, it earns its share.
        let accepting = Rubric::from_toml(
            &text.replace("week = 5\n", &format!("week = 5\naccept = [\"{older}\"]\n")),
            "t",
        )
        .unwrap();
        let checks = function_checks(&accepting, &outcome(all));
        let dt = checks
            .iter()
            .find(|c| c.id == "functions.lights.direct-term")
            .unwrap();
        assert_eq!((dt.score, dt.status), (17.5, CheckStatus::Passed));
        // Nothing could run: every function scores 0, and says why.
        let fatal = FunctionsOutcome {
            fatal: Some("importing the submission failed".into()),
            ..FunctionsOutcome::default()
        };
        let checks = function_checks(&rubric, &fatal);
        assert_eq!(checks.len(), 5);
        assert!(
            checks
                .iter()
                .all(|c| c.score == 0.0 && c.message.contains("importing"))
        );
        // An unknown alternative, a function the week does not check, a week out of range:
        // refused with the rubric named.
        for bad in [
            text.replace("week = 5\n", "week = 5\naccept = [\"nope\"]\n"),
            text.replace("\"occlusion\", ", "\"occlusion\", \"refract\", "),
            text.replace("week = 5\n", "week = 11\n"),
        ] {
            let e = Rubric::from_toml(&bad, "bad.toml").unwrap_err().to_string();
            assert!(e.starts_with("bad.toml: "), "{e}");
        }
    }
}
