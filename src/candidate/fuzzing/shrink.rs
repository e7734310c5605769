//! Shrinking a failing case to a small one that still fails the same way.
//!
//! Each number (shape, origin, direction, interval ends) is replaced, one at a time, by simpler
//! values: `0`, `+-1`, an integer, then dyadic fractions with fewer bits. A replacement is kept
//! when [`oracle_expect_with`] still calls the case definite and the candidate still fails with the
//! same kind of failure. Candidates for one number are tried as one batch, so a shrink costs
//! a few dozen round trips.

use crate::candidate::fuzzing::generate::oracle_expect_with;
#[cfg(doc)]
use crate::candidate::judging::check::FailureKind;
use crate::oracle::profile::Judging;
use crate::oracle::vectors::{Case, RaySpec, ShapeSpec};

/// How simple a number is: fewer fractional bits first, then smaller magnitude. The camera's
/// interval ends (`1e-6`, `f64::MAX`) count as the simplest.
fn complexity(x: f64) -> (u32, u64) {
    if x == 1e-6 || x == f64::MAX || x == 0.0 {
        return (0, 0);
    }
    let mut bits = 0;
    let mut y = x;
    while y.fract() != 0.0 && bits < 64 {
        y *= 2.0;
        bits += 1;
    }
    (bits, x.abs().min(1e18) as u64 + 1)
}

/// Simpler values to try for `x`, simplest first.
fn simpler(x: f64) -> Vec<f64> {
    let mut out = vec![0.0, x.signum(), x.trunc(), x.round()];
    if x.abs() >= 2.0 {
        out.push((x / 2.0).trunc());
        out.push(x.trunc() - x.signum());
    }
    for bits in 1..=12 {
        let s = (1u64 << bits) as f64;
        out.push((x * s).round() / s);
    }
    let cx = complexity(x);
    let mut kept: Vec<f64> = Vec::new();
    for y in out {
        if y.is_finite() && y != x && complexity(y) < cx && !kept.contains(&y) {
            kept.push(y);
        }
    }
    kept
}

/// All numbers of a case, in a fixed order.
fn numbers(case: &Case) -> Vec<f64> {
    let mut v = case.shape.numbers();
    v.extend(case.ray.origin);
    v.extend(case.ray.direction);
    v.extend(case.interval);
    v
}

/// The case with its numbers replaced, re-classified; `None` when no longer definite.
fn with_numbers(case: &Case, v: &[f64], judging: Judging) -> Option<Case> {
    let a3 = |i: usize| [v[i], v[i + 1], v[i + 2]];
    let (shape, k) = match case.shape {
        ShapeSpec::Sphere { .. } => (
            ShapeSpec::Sphere {
                center: a3(0),
                radius: v[3],
            },
            4,
        ),
        ShapeSpec::Quad { .. } => (
            ShapeSpec::Quad {
                q: a3(0),
                u: a3(3),
                v: a3(6),
            },
            9,
        ),
        ShapeSpec::Triangle { .. } => (
            ShapeSpec::Triangle {
                a: a3(0),
                b: a3(3),
                c: a3(6),
            },
            9,
        ),
    };
    let ray = RaySpec {
        origin: a3(k),
        direction: a3(k + 3),
    };
    let interval = [v[k + 6], v[k + 7]];
    let expect = oracle_expect_with(&shape, &ray, interval, judging)?;
    Some(Case {
        id: format!("{}-shrunk", case.id.trim_end_matches("-shrunk")),
        shape,
        ray,
        interval,
        expect,
    })
}

/// Shrinks `case`, which fails with `kind`. `fails` runs a batch of cases and says, for each,
/// how it fails (`None` when it passes), in any classification of failures `K` (the report's
/// [`FailureKind`], or the fuzzer's finer one). At most `budget` cases are tried.
pub fn shrink<K: PartialEq>(
    case: &Case,
    kind: K,
    fails: &mut dyn FnMut(&[Case]) -> Vec<Option<K>>,
    budget: usize,
) -> Case {
    shrink_with(case, kind, fails, budget, Judging::COURSE)
}

/// [`shrink`], keeping only cases that are definite under `judging`.
pub fn shrink_with<K: PartialEq>(
    case: &Case,
    kind: K,
    fails: &mut dyn FnMut(&[Case]) -> Vec<Option<K>>,
    budget: usize,
    judging: Judging,
) -> Case {
    let mut best = case.clone();
    let mut tried = 0usize;
    // First the camera's interval, then each number in turn, until nothing changes.
    let mut changed = true;
    while changed && tried < budget {
        changed = false;
        let n = numbers(&best).len();
        for field in 0..n {
            let v = numbers(&best);
            let mut options: Vec<Case> = Vec::new();
            if field == n - 2 {
                let mut w = v.clone();
                w[n - 2] = 1e-6;
                w[n - 1] = f64::MAX;
                if w != v {
                    options.extend(with_numbers(&best, &w, judging));
                }
            }
            for y in simpler(v[field]) {
                let mut w = v.clone();
                w[field] = y;
                options.extend(with_numbers(&best, &w, judging));
            }
            if options.is_empty() {
                continue;
            }
            tried += options.len();
            let verdicts = fails(&options);
            if let Some(pos) = verdicts.iter().position(|k| k.as_ref() == Some(&kind)) {
                best = options.swap_remove(pos);
                changed = true;
            }
            if tried >= budget {
                break;
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::candidate::judging::check::FailureKind;
    use crate::oracle::vectors::Class;

    #[test]
    fn simpler_values_are_simpler() {
        assert_eq!(simpler(3.0), vec![0.0, 1.0, 2.0]);
        assert!(simpler(0.0).is_empty());
        let s = simpler(2.375);
        assert_eq!(&s[..3], &[0.0, 1.0, 2.0]);
        assert!(s.contains(&2.5));
        assert!(!s.contains(&2.375));
        assert!(simpler(1e-6).is_empty());
    }

    #[test]
    fn a_failure_that_depends_on_the_radius_shrinks_to_small_numbers() {
        // "Candidate" that fails every hit on a sphere of radius > 1: the minimal case keeps
        // a radius just above 1 and simple coordinates.
        let case = crate::candidate::fuzzing::generate::random_cases(
            3,
            0,
            200,
            &[crate::oracle::vectors::ShapeKind::Sphere],
        )
        .into_iter()
        .find(|c| {
            c.expect.class == Class::Hit
                && matches!(c.shape, ShapeSpec::Sphere { radius, .. } if radius > 2.0)
                && c.ray.origin.iter().any(|x| x.fract() != 0.0)
        })
        .expect("a hit on a big sphere");
        let mut fails = |cases: &[Case]| {
            cases
                .iter()
                .map(|c| match c.shape {
                    ShapeSpec::Sphere { radius, .. }
                        if radius > 1.0 && c.expect.class == Class::Hit =>
                    {
                        Some(FailureKind::Mismatch)
                    }
                    _ => None,
                })
                .collect()
        };
        let small = shrink(&case, FailureKind::Mismatch, &mut fails, 5000);
        let ShapeSpec::Sphere { radius, .. } = small.shape else {
            unreachable!()
        };
        assert_eq!(small.expect.class, Class::Hit);
        assert!(radius > 1.0 && radius <= 2.0, "radius {radius}");
        let all = numbers(&small);
        assert!(
            all.iter().all(|&x| complexity(x).0 <= 1),
            "only integers and halves remain: {all:?}"
        );
    }
}
