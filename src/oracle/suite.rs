//! The built-in vector suite: [`DEFAULT_COUNT`] generated cases for a seed, then the
//! watertight groups ([`super::watertight`]).

use super::generate::generate_with;
use super::profile::Judging;
use super::vectors::{Case, ShapeKind};
use super::watertight::watertight_cases;

/// The number of generated cases of the default suite (the watertight groups come on top).
pub const DEFAULT_COUNT: usize = 4000;

/// The default suite for `seed`: every case `rtoracle check` runs when no vector file is given.
/// The same seed always gives the same cases, bit for bit, with stable ids.
pub fn default_suite(seed: u64) -> Vec<Case> {
    default_suite_with(seed, Judging::COURSE)
}

/// The default suite for `seed` classified under `judging` (the same inputs and ids as
/// [`default_suite`]).
pub fn default_suite_with(seed: u64, judging: Judging) -> Vec<Case> {
    suite_with(seed, DEFAULT_COUNT, &ShapeKind::ALL, judging)
}

/// `count` generated cases of `shapes` for `seed` under `judging`, then the watertight groups
/// whose shapes are all among `shapes`.
pub fn suite_with(seed: u64, count: usize, shapes: &[ShapeKind], judging: Judging) -> Vec<Case> {
    let mut cases = generate_with(seed, count, shapes, judging);
    let groups = watertight_cases(seed, judging);
    let left_out: std::collections::HashSet<&str> = groups
        .iter()
        .filter(|c| !shapes.contains(&c.shape.kind()))
        .filter_map(|c| c.expect.watertight.as_ref().map(|w| w.group.as_str()))
        .collect();
    let kept: Vec<Case> = groups
        .iter()
        .filter(|c| {
            c.expect
                .watertight
                .as_ref()
                .is_none_or(|w| !left_out.contains(w.group.as_str()))
        })
        .cloned()
        .collect();
    cases.extend(kept);
    cases
}

/// Every tag of `docs/oracle.md` ("Tags") that the generators draw; the default suite holds each.
pub const ORACLE_TAGS: [&str; 13] = [
    "tangent",
    "near-tangent",
    "edge",
    "corner",
    "parallel",
    "degenerate",
    "grazing",
    "interval-boundary",
    "inside",
    "behind",
    "negative-radius",
    "scale",
    "nonfinite",
];

#[cfg(test)]
mod tests {
    use super::*;
    use crate::oracle::vectors::Class;
    use std::collections::BTreeMap;

    #[test]
    fn default_suite_meets_the_issue_figures_and_is_stable() {
        let suite = default_suite(0);
        assert!(suite.len() >= 3000);
        let mut by: BTreeMap<(String, Class), usize> = BTreeMap::new();
        for c in &suite {
            *by.entry((c.shape.kind().to_string(), c.expect.class))
                .or_default() += 1;
        }
        eprintln!("{by:?}");
        for tag in ORACLE_TAGS {
            assert!(
                suite.iter().any(|c| c.expect.tags.iter().any(|t| t == tag)),
                "no case tagged {tag}"
            );
        }
        let definite_sq = suite
            .iter()
            .filter(|c| c.expect.class.is_definite() && c.shape.kind() != ShapeKind::Triangle)
            .count();
        assert!(
            definite_sq >= 1000,
            "{definite_sq} definite sphere and quad cases"
        );
        let loose = suite
            .iter()
            .filter(|c| !c.expect.class.is_definite())
            .count();
        assert!(
            loose * 100 <= 35 * suite.len(),
            "{loose} of {} ambiguous or any",
            suite.len()
        );
        let mut ids: Vec<&str> = suite.iter().map(|c| c.id.as_str()).collect();
        ids.sort();
        ids.dedup();
        assert_eq!(ids.len(), suite.len(), "ids are unique");
        // Same seed, same cases; another seed, other cases.
        assert_eq!(default_suite(0)[..50], suite[..50]);
        assert_ne!(default_suite(1)[..50], suite[..50]);
        // The watertight groups, after the generated cases.
        assert!(
            suite[DEFAULT_COUNT..]
                .iter()
                .all(|c| c.expect.watertight.is_some())
        );
        assert!(suite.len() > DEFAULT_COUNT + 100);
        // A group with a triangle is left out when triangles are.
        let no_triangles = suite_with(0, 10, &[ShapeKind::Quad], Judging::COURSE);
        assert!(
            no_triangles
                .iter()
                .all(|c| c.shape.kind() == ShapeKind::Quad)
        );
        assert!(no_triangles.iter().any(|c| c.expect.watertight.is_some()));
    }
}
