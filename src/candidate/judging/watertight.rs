//! Judging the watertight groups of a run ([`crate::oracle::watertight`]): a group of class
//! `hit` holds when the candidate hit at least one of its members at the member's exact `t`,
//! and cracks when every member was answered and none was so hit (an open edge). A group with
//! a member not answered (a time-out, a death, a protocol error, a shape not implemented) or
//! answered with an error (the code raised) is not judged: the member's own failure, if any,
//! is reported by the vector's verdict.

use crate::candidate::process::outcome::Outcome;
use crate::oracle::vectors::{Case, Class};

/// What a group came to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GroupResult {
    /// At least one member was hit at its exact `t`.
    Held,
    /// Every member was answered without an error, none hit: the ray went through a crack.
    Cracked,
    /// Not judged: a member was not answered, or the group is `ambiguous`.
    Unjudged,
}

/// One watertight group of a run.
#[derive(Clone, Debug)]
pub struct Group {
    /// The group's id.
    pub id: String,
    /// The indices of its members in the run's cases, in order.
    pub members: Vec<usize>,
    /// What it came to.
    pub result: GroupResult,
}

/// Whether `outcome` hits `case` where the exact answer does (`t` within the case's
/// tolerance, or `1e-9 max(|t|, 1)`).
fn hit_right(case: &Case, outcome: &Outcome) -> bool {
    let (Outcome::Answered { answer, .. }, Some(te)) = (outcome, case.expect.t) else {
        return false;
    };
    let tol = case.expect.t_tol.unwrap_or(1e-9 * te.abs().max(1.0));
    answer.error.is_none()
        && answer.hit == Some(true)
        && answer.t.is_some_and(|t| (t - te).abs() <= tol)
}

/// The watertight groups of `cases` (in the order of their first member) and what each came to.
pub fn judge_groups(cases: &[Case], outcomes: &[Outcome]) -> Vec<Group> {
    let mut groups: Vec<Group> = Vec::new();
    let mut index = std::collections::HashMap::<&str, usize>::new();
    let mut classes = Vec::new();
    for (i, case) in cases.iter().enumerate() {
        let Some(w) = &case.expect.watertight else {
            continue;
        };
        match index.get(w.group.as_str()) {
            Some(&g) => groups[g].members.push(i),
            None => {
                index.insert(&w.group, groups.len());
                classes.push(w.class);
                groups.push(Group {
                    id: w.group.clone(),
                    members: vec![i],
                    result: GroupResult::Unjudged,
                });
            }
        }
    }
    for (group, class) in groups.iter_mut().zip(classes) {
        let held = group
            .members
            .iter()
            .any(|&i| hit_right(&cases[i], &outcomes[i]));
        let all_answered = group.members.iter().all(
            |&i| matches!(&outcomes[i], Outcome::Answered { answer, .. } if answer.error.is_none()),
        );
        group.result = match (class, held, all_answered) {
            (Class::Hit, true, _) => GroupResult::Held,
            (Class::Hit, false, true) => GroupResult::Cracked,
            _ => GroupResult::Unjudged,
        };
    }
    groups
}

/// The watertight groups of a run in words, as `check` and `grade` both say them:
/// `16 judged, 16 cracked (a ray through an edge or vertex that shapes share hit none of them)`.
pub fn groups_summary(judged: usize, cracked: usize) -> String {
    format!(
        "{judged} judged, {cracked} cracked (a ray through an edge or vertex that shapes share \
         hit none of them)"
    )
}

/// The failure message of a cracked group.
pub fn crack_message(group: &Group, cases: &[Case]) -> String {
    let ids: Vec<&str> = group
        .members
        .iter()
        .map(|&i| cases[i].id.as_str())
        .collect();
    let at = if cases[group.members[0]]
        .expect
        .tags
        .iter()
        .any(|t| t == "corner")
    {
        "a vertex"
    } else {
        "an edge"
    };
    format!(
        "watertight group {}: the ray through {at} its shapes share hit none of them ({}); \
         expected a hit on at least one: an edge test `> 0` or `< 1` where `>= 0` or `<= 1` \
         is meant leaves a crack between shapes that share an edge",
        group.id,
        ids.join(", ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::candidate::process::protocol::Answer;
    use crate::oracle::profile::Judging;
    use crate::oracle::watertight::watertight_cases;

    fn answered(answer: Answer) -> Outcome {
        Outcome::Answered {
            answer,
            junk: vec![],
        }
    }

    #[test]
    fn a_group_holds_with_one_right_hit_and_cracks_with_none() {
        let cases = watertight_cases(0, Judging::COURSE);
        let misses: Vec<Outcome> = cases.iter().map(|_| answered(Answer::miss())).collect();
        let groups = judge_groups(&cases, &misses);
        assert!(!groups.is_empty());
        for g in &groups {
            let class = cases[g.members[0]]
                .expect
                .watertight
                .as_ref()
                .unwrap()
                .class;
            let want = if class == Class::Hit {
                GroupResult::Cracked
            } else {
                GroupResult::Unjudged
            };
            assert_eq!(g.result, want, "{}", g.id);
        }
        // One member hit right holds its group; a hit at a wrong t does not.
        let g = groups
            .iter()
            .find(|g| g.result == GroupResult::Cracked)
            .unwrap();
        let m = *g
            .members
            .iter()
            .find(|&&i| cases[i].expect.t.is_some())
            .unwrap();
        let e = &cases[m].expect;
        let mut outcomes = misses.clone();
        let hit = |t| {
            answered(Answer::hit(
                t,
                e.point.unwrap(),
                e.normal.unwrap(),
                e.front_face.unwrap(),
            ))
        };
        outcomes[m] = hit(e.t.unwrap());
        let again = judge_groups(&cases, &outcomes);
        assert_eq!(
            again.iter().find(|x| x.id == g.id).unwrap().result,
            GroupResult::Held
        );
        outcomes[m] = hit(e.t.unwrap() * 2.0);
        let again = judge_groups(&cases, &outcomes);
        assert_eq!(
            again.iter().find(|x| x.id == g.id).unwrap().result,
            GroupResult::Cracked
        );
        // A member that timed out: not judged (the time-out fails on its own).
        outcomes[m] = Outcome::Timeout { junk: vec![] };
        let again = judge_groups(&cases, &outcomes);
        assert_eq!(
            again.iter().find(|x| x.id == g.id).unwrap().result,
            GroupResult::Unjudged
        );
        assert!(crack_message(g, &cases).contains(&g.id));
    }
}
