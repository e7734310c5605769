//! The scoring rule against answers that ignore the ray, the honest and buggy transcriptions
//! of the course's code, and the other rules it was chosen from.

use std::collections::BTreeMap;

use super::*;
use crate::candidate::judging::check::{decide_winding, judge_wound};
use crate::candidate::process::protocol::Answer;
use crate::oracle::generate::{add, scale};
use crate::oracle::mistakes::{self, Variant};
use crate::oracle::suite::default_suite;
use crate::oracle::vectors::ShapeKind;

/// Deterministic pseudo-random numbers (splitmix64) for the coin-toss strategies.
struct Coin(u64);

impl Coin {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A way of answering every vector without intersecting anything.
type Strategy = Box<dyn Fn(&Case, &mut Coin) -> Answer>;

/// The vectors a group scores: the definite ones of `shape`.
fn group(suite: &[Case], shape: ShapeKind) -> Vec<Case> {
    suite
        .iter()
        .filter(|c| c.shape.kind() == shape && c.expect.class.is_definite())
        .cloned()
        .collect()
}

/// The hit answer every hit vector of `cases` shares most often: the best a constant hit can do.
fn most_common_hit(cases: &[Case]) -> Answer {
    let mut seen: BTreeMap<(u64, [i64; 3], bool), usize> = BTreeMap::new();
    for c in cases.iter().filter(|c| c.expect.class == Class::Hit) {
        let n = c.expect.normal.unwrap_or_default();
        let key = (
            c.expect.t.unwrap_or_default().to_bits(),
            n.map(|x| (x * 1e6).round() as i64),
            c.expect.front_face.unwrap_or(true),
        );
        *seen.entry(key).or_default() += 1;
    }
    let ((t, n, ff), _) = seen.into_iter().max_by_key(|(_, k)| *k).expect("hits");
    Answer::hit(f64::from_bits(t), [0.0; 3], n.map(|x| x as f64 / 1e6), ff)
}

fn strategy(
    name: impl Into<String>,
    f: impl Fn(&Case, &mut Coin) -> Answer + 'static,
) -> (String, Strategy) {
    (name.into(), Box::new(f))
}

/// The constant and random strategies, by name, for the vectors `cases`.
fn strategies(cases: &[Case]) -> Vec<(String, Strategy)> {
    let mut out = vec![
        strategy("always a miss", |_, _| Answer::miss()),
        strategy("always an error", |_, _| {
            Answer::error("ZeroDivisionError", "float division by zero")
        }),
        strategy("the ray's own origin (t = 0)", |c, _| {
            Answer::hit(0.0, c.ray.origin, scale(c.ray.direction, -1.0), true)
        }),
        strategy("the point one direction ahead (t = 1)", |c, _| {
            let p = add(c.ray.origin, c.ray.direction);
            Answer::hit(1.0, p, scale(c.ray.direction, -1.0), true)
        }),
    ];
    for (t, n, ff) in [
        (1.0, [0.0, 0.0, 1.0], true),
        (1.0, [0.0, 1.0, 0.0], false),
        (0.5, [0.0, 0.0, -1.0], true),
        (10.0, [1.0, 0.0, 0.0], true),
    ] {
        out.push(strategy(
            format!("always a hit at t = {t}, normal {n:?}, front_face {ff}"),
            move |_, _| Answer::hit(t, [0.0; 3], n, ff),
        ));
    }
    let best = most_common_hit(cases);
    for ff in [true, false] {
        let mut a = best.clone();
        a.front_face = Some(ff);
        out.push(strategy(
            format!(
                "always the suite's most common hit (t = {}, front_face {ff})",
                a.t.unwrap_or_default()
            ),
            move |_, _| a.clone(),
        ));
    }
    for p in [0.1, 0.5, 0.9] {
        out.push(strategy(
            format!("a coin toss, a hit with probability {p} at a random t"),
            move |_, coin| {
                if coin.next() < p {
                    let t = 20.0 * coin.next();
                    let n = [coin.next() - 0.5, coin.next() - 0.5, coin.next() - 0.5];
                    Answer::hit(t, [0.0; 3], n, coin.next() < 0.5)
                } else {
                    Answer::miss()
                }
            },
        ));
    }
    out
}

/// A transcription's answer as the course adapter would send it.
fn answer_of(v: &mistakes::Answer, c: &Case) -> Answer {
    match v {
        Err(e) => Answer::error(*e, "raised"),
        Ok(None) => Answer::miss(),
        Ok(Some(h)) => {
            let p = add(c.ray.origin, scale(c.ray.direction, h.t));
            Answer::hit(h.t, p, h.normal, h.front_face)
        }
    }
}

/// What the checker counts for `answers` to `cases` (as `CourseCodeChecker` does): each vector
/// judged, triangles by the winding the answers show, and marked for the rule.
fn tally(cases: &[Case], answers: Vec<Answer>) -> (ClassTally, Vec<Mark>) {
    let outcomes: Vec<Outcome> = answers
        .into_iter()
        .map(|answer| Outcome::Answered {
            answer,
            junk: vec![],
        })
        .collect();
    let winding = decide_winding(cases, &outcomes);
    let mut t = ClassTally::default();
    let mut marks = Vec::new();
    for (c, o) in cases.iter().zip(&outcomes) {
        let m = mark(c, o, &judge_wound(c, o, winding), winding);
        t.record(expects_hit(c), m);
        marks.push(m);
    }
    (t, marks)
}

fn run_strategy(cases: &[Case], s: &Strategy) -> (ClassTally, Vec<Mark>) {
    let mut coin = Coin(7);
    tally(cases, cases.iter().map(|c| s(c, &mut coin)).collect())
}

fn run_variant(cases: &[Case], v: &Variant) -> (ClassTally, Vec<Mark>) {
    let answers = cases
        .iter()
        .map(|c| answer_of(&(v.run)(&c.shape, &c.ray, c.interval), c))
        .collect();
    tally(cases, answers)
}

/// The variant `v` with a second mistake on top of its own: `front_face` reversed for spheres
/// and quads; for triangles, whose winding is the submission's choice (reversing every
/// `front_face` is the other winding, not a mistake), the normal not of unit length.
fn with_a_second_mistake(cases: &[Case], v: &Variant) -> (ClassTally, Vec<Mark>) {
    let answers = cases
        .iter()
        .map(|c| {
            let mut a = answer_of(&(v.run)(&c.shape, &c.ray, c.interval), c);
            if v.shape == ShapeKind::Triangle {
                a.normal = a.normal.map(|n| scale(n, 2.0));
            } else {
                a.front_face = a.front_face.map(|f| !f);
            }
            a
        })
        .collect();
    tally(cases, answers)
}

fn fraction((t, _): &(ClassTally, Vec<Mark>)) -> f64 {
    credit(*t, false).fraction
}

const SHAPES: [ShapeKind; 3] = [ShapeKind::Sphere, ShapeKind::Quad, ShapeKind::Triangle];

fn catalogue(shape: ShapeKind) -> Vec<Variant> {
    let mut list = mistakes::buggy();
    list.extend(mistakes::buggy_extra());
    list.retain(|v| v.shape == shape);
    list
}

#[test]
fn no_constant_or_random_answer_earns_more_than_2_percent_of_any_group() {
    for seed in [0, 1] {
        let suite = default_suite(seed);
        for shape in SHAPES {
            let cases = group(&suite, shape);
            for (name, s) in strategies(&cases) {
                let f = fraction(&run_strategy(&cases, &s));
                assert!(f <= 0.02, "seed {seed} {shape}: {name} earns {f:.4}");
            }
            for v in mistakes::honest().iter().filter(|v| v.shape == shape) {
                let r = run_variant(&cases, v);
                assert_eq!(fraction(&r), 1.0, "seed {seed}: {} {:?}", v.name, r.0);
            }
        }
    }
}

#[test]
fn two_mistakes_cost_more_than_one_and_an_edge_case_less_than_a_wrong_formula() {
    let suite = default_suite(0);
    let reversed_ff = |shape| format!("{shape}-front-face-reversed");
    for shape in SHAPES {
        let cases = group(&suite, shape);
        let mut edge = Vec::new();
        let mut formula = Vec::new();
        let mut neither = Vec::new();
        for v in catalogue(shape) {
            let single = run_variant(&cases, &v);
            let f1 = fraction(&single);
            assert!(f1 < 1.0, "{} loses nothing", v.name);
            // One mistake costs less than the same mistake plus another.
            if v.name != reversed_ff(shape) {
                let f2 = fraction(&with_a_second_mistake(&cases, &v));
                assert!(
                    f2 < f1 || f1 == 0.0,
                    "{}: {f1:.3} alone, {f2:.3} with a second mistake",
                    v.name
                );
            }
            // Which vectors it gets wrong decides which kind of mistake it is: confined to one
            // edge case (every vector it fails carries one tag), or a wrong formula (it fails
            // a quarter or more of the plain vectors, the ones with no edge-case tag).
            let failed: Vec<&Case> = cases
                .iter()
                .zip(&single.1)
                .filter(|(_, m)| **m != Mark::Right)
                .map(|(c, _)| c)
                .collect();
            let plain: Vec<(&Case, &Mark)> = cases
                .iter()
                .zip(&single.1)
                .filter(|(c, _)| c.expect.tags.is_empty())
                .collect();
            let plain_failed = plain.iter().filter(|(_, m)| **m != Mark::Right).count();
            let one_tag = failed[0].expect.tags.iter().find(|tag| {
                failed
                    .iter()
                    .all(|c| c.expect.tags.iter().any(|t| t == *tag))
            });
            if let Some(tag) = one_tag {
                edge.push((v.name, tag.clone(), f1));
            } else if plain_failed * 4 >= plain.len() {
                formula.push((v.name, f1));
            } else {
                neither.push((v.name, plain_failed, plain.len()));
            }
        }
        eprintln!(
            "{shape}: edge cases {edge:?}\n{shape}: wrong formulas {formula:?}\n{shape}: neither (plain failed of plain) {neither:?}"
        );
        // The triangle catalogue has no wrong formula by this measure: its third-edge mistake
        // fails 6 of the 36 plain triangle vectors (a sixth), the others fail tagged ones only.
        assert!(!edge.is_empty(), "{shape}");
        assert!(
            !formula.is_empty() || shape == ShapeKind::Triangle,
            "{shape}"
        );
        for (e, tag, fe) in &edge {
            for (w, fw) in &formula {
                assert!(
                    fe > fw,
                    "{e} (only {tag} vectors) earns {fe:.3}, no more than {w} ({fw:.3})"
                );
            }
        }
    }
}

/// The candidate rules on one group's vectors, from each vector's class, tags and mark.
struct Rules<'a> {
    cases: &'a [Case],
    /// The most vectors any listed constant strategy passes, and its per-tag score.
    best_constant: (usize, f64),
}

impl Rules<'_> {
    fn passes(marks: &[Mark]) -> usize {
        marks.iter().filter(|m| **m == Mark::Right).count()
    }

    /// The mean pass rate over the strata (class, tag), a vector with no tag in `plain`.
    fn per_tag(&self, marks: &[Mark]) -> f64 {
        let mut strata: BTreeMap<(bool, String), (usize, usize)> = BTreeMap::new();
        for (c, m) in self.cases.iter().zip(marks) {
            let tags = if c.expect.tags.is_empty() {
                vec!["plain".to_string()]
            } else {
                c.expect.tags.clone()
            };
            for tag in tags {
                let e = strata.entry((expects_hit(c), tag)).or_default();
                e.0 += 1;
                e.1 += (*m == Mark::Right) as usize;
            }
        }
        strata
            .values()
            .map(|(n, k)| *k as f64 / *n as f64)
            .sum::<f64>()
            / strata.len() as f64
    }

    /// proportional, above the best constant, Youden's J, product, per tag, the chosen rule.
    fn all(&self, (t, marks): &(ClassTally, Vec<Mark>)) -> [f64; 6] {
        let n = self.cases.len();
        let p = Self::passes(marks);
        let (c, tag_c) = self.best_constant;
        let h = t.hits_right as f64 / t.hits.max(1) as f64;
        let m = t.misses_right as f64 / t.misses.max(1) as f64;
        let clamp = |x: f64| x.clamp(0.0, 1.0);
        [
            p as f64 / n as f64,
            clamp((p as f64 - c as f64) / (n - c) as f64),
            clamp(h + m - 1.0),
            h * m,
            clamp((self.per_tag(marks) - tag_c) / (1.0 - tag_c)),
            credit(*t, false).fraction,
        ]
    }
}

/// Prints the table `docs/grading.md` quotes ("How a code group is scored"):
/// `cargo test --lib grade::rubric::credit::tests::measure -- --nocapture`.
#[test]
fn measure_the_candidate_rules_on_the_catalogued_mistakes() {
    let suite = default_suite(0);
    for shape in SHAPES {
        let cases = group(&suite, shape);
        let runs: Vec<(String, (ClassTally, Vec<Mark>))> = strategies(&cases)
            .iter()
            .map(|(name, s)| (name.clone(), run_strategy(&cases, s)))
            .collect();
        let mut rules = Rules {
            cases: &cases,
            best_constant: (0, 0.0),
        };
        let best = runs
            .iter()
            .map(|(_, r)| Rules::passes(&r.1))
            .max()
            .unwrap_or(0);
        let best_tag = runs
            .iter()
            .map(|(_, r)| rules.per_tag(&r.1))
            .fold(0.0, f64::max);
        rules.best_constant = (best, best_tag);
        let (hits, misses) = (runs[0].1.0.hits, runs[0].1.0.misses);
        eprintln!(
            "\n{shape}: {} vectors, {hits} hit, {misses} miss\n{:<58} {:>6} {:>6} {:>6} {:>6} {:>6} {:>6}",
            cases.len(),
            "",
            "prop",
            "above",
            "youden",
            "prod",
            "pertag",
            "chosen"
        );
        let mut rows = runs;
        for v in mistakes::honest()
            .iter()
            .filter(|v| v.shape == shape)
            .take(1)
        {
            rows.push((format!("honest {}", v.name), run_variant(&cases, v)));
        }
        for v in catalogue(shape) {
            rows.push((format!("mistake {}", v.name), run_variant(&cases, &v)));
        }
        for (name, r) in &rows {
            let f = rules.all(r);
            eprintln!(
                "{name:<58} {:>6.3} {:>6.3} {:>6.3} {:>6.3} {:>6.3} {:>6.3}",
                f[0], f[1], f[2], f[3], f[4], f[5]
            );
        }
    }
}
