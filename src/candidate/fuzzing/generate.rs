//! Random cases for fuzzing and for the fixtures' tests: small integers and dyadic fractions,
//! aimed so that about half hit, with negative radii, rays from inside, primitives behind the
//! origin, finite intervals and rays exactly parallel to a quad.
//!
//! Classification goes through one function, [`oracle_expect`]: the exact oracle's class
//! ([`crate::oracle::classify::classify()`]), keeping only the definite cases (a candidate is judged on
//! nothing floating point cannot settle).

use rand_core::Rng;
use rand_pcg::Pcg64;

use crate::oracle::generate::{self as og, Stream};
use crate::oracle::profile::Judging;
use crate::oracle::vectors::{Case, Expect, RaySpec, ShapeKind, ShapeSpec};

/// The exact oracle's expected answer for a case when it is definite, `None` when it is not
/// (degenerate, non-finite, or within the error band of a decision boundary), under the course
/// profile in `f64`.
pub fn oracle_expect(shape: &ShapeSpec, ray: &RaySpec, interval: [f64; 2]) -> Option<Expect> {
    oracle_expect_with(shape, ray, interval, Judging::COURSE)
}

/// [`oracle_expect`] under `judging`.
pub fn oracle_expect_with(
    shape: &ShapeSpec,
    ray: &RaySpec,
    interval: [f64; 2],
    judging: Judging,
) -> Option<Expect> {
    let expect = crate::oracle::classify::classify_with(shape, ray, interval, judging);
    expect.class.is_definite().then_some(expect)
}

/// The precision regimes of the vector suite each shape's fuzzing draws from (the oracle's
/// generator categories), besides `tiny`.
fn regimes(kind: ShapeKind) -> &'static [&'static str] {
    match kind {
        ShapeKind::Sphere => &[
            "far",
            "scale",
            "unnormalised",
            "tangent",
            "near-tangent",
            "interval-boundary",
            "inside",
            "behind",
            "negative-radius",
            "tiny",
        ],
        ShapeKind::Quad => &[
            "scale",
            "unnormalised",
            "grazing",
            "edge",
            "corner",
            "skewed",
            "skinny",
            "parallel",
            "interval-boundary",
            "tiny",
        ],
        ShapeKind::Triangle => &[
            "scale",
            "unnormalised",
            "grazing",
            "edge",
            "corner",
            "interval-boundary",
            "tiny",
        ],
    }
}

/// A primitive `2^-40 .. 2^-10` the size of its distance from the origin, aimed at (a sphere:
/// offset up to 1.3 radii; a plane: coordinates in `[-0.4, 1.4]`).
fn tiny(r: &mut Stream, kind: ShapeKind) -> og::Raw {
    let s = r.log_scale(-20.0, 20.0);
    let size = s * r.log_scale(-40.0, -10.0);
    let origin = og::scale(r.unit(), s * r.uniform(0.0, 4.0));
    let target = og::add(origin, og::scale(r.unit(), s));
    let shape = match kind {
        ShapeKind::Sphere => ShapeSpec::Sphere {
            center: target,
            radius: size,
        },
        ShapeKind::Quad => ShapeSpec::Quad {
            q: target,
            u: og::scale(r.unit(), size),
            v: og::scale(r.unit(), size),
        },
        ShapeKind::Triangle => ShapeSpec::Triangle {
            a: target,
            b: og::add(target, og::scale(r.unit(), size)),
            c: og::add(target, og::scale(r.unit(), size)),
        },
    };
    let aim = match shape {
        ShapeSpec::Sphere { center, radius } => {
            og::add(center, og::scale(r.unit(), radius * r.uniform(0.0, 1.3)))
        }
        ShapeSpec::Quad { q, u, v } | ShapeSpec::Triangle { a: q, b: u, c: v } => {
            let (u, v) = if kind == ShapeKind::Triangle {
                (og::sub(u, q), og::sub(v, q))
            } else {
                (u, v)
            };
            let (a, b) = (r.uniform(-0.4, 1.4), r.uniform(-0.4, 1.4));
            og::add(q, og::add(og::scale(u, a), og::scale(v, b)))
        }
    };
    let dir = og::sub(aim, origin);
    let len = r.log_scale(-10.0, 10.0) / og::dot(dir, dir).sqrt();
    let mut raw = og::raw_parts(shape, origin, og::scale(dir, len), og::CAMERA);
    raw.tags = vec!["tiny"];
    raw
}

/// A seeded stream of random inputs.
pub struct CaseGen {
    rng: Pcg64,
}

impl CaseGen {
    /// The generator for `seed` (and a `stream`, so rounds of a fuzz run differ).
    pub fn new(seed: u64, stream: u64) -> Self {
        CaseGen {
            rng: Pcg64::new(
                0xcafe_f00d_d15e_a5e5_u128 ^ ((seed as u128) << 64),
                stream as u128,
            ),
        }
    }

    fn below(&mut self, n: u64) -> u64 {
        self.rng.next_u64() % n
    }

    fn int(&mut self, lo: i64, hi: i64) -> i64 {
        lo + self.below((hi - lo + 1) as u64) as i64
    }

    fn chance(&mut self, percent: u64) -> bool {
        self.below(100) < percent
    }

    /// A dyadic number in `[lo, hi]` with `bits` fractional bits.
    fn dyadic(&mut self, lo: f64, hi: f64, bits: u32) -> f64 {
        let s = (1u64 << bits) as f64;
        self.int((lo * s).ceil() as i64, (hi * s).floor() as i64) as f64 / s
    }

    fn vec(&mut self, lo: f64, hi: f64, bits: u32) -> [f64; 3] {
        [
            self.dyadic(lo, hi, bits),
            self.dyadic(lo, hi, bits),
            self.dyadic(lo, hi, bits),
        ]
    }

    fn nonzero_int_vec(&mut self, m: i64) -> [f64; 3] {
        loop {
            let v = [
                self.int(-m, m) as f64,
                self.int(-m, m) as f64,
                self.int(-m, m) as f64,
            ];
            if v != [0.0; 3] {
                return v;
            }
        }
    }

    fn interval(&mut self) -> [f64; 2] {
        match self.below(10) {
            0 => [self.dyadic(0.0, 4.0, 2), f64::MAX],
            1 => {
                let a = self.dyadic(0.0, 4.0, 2);
                [a, a + self.dyadic(0.25, 8.0, 2)]
            }
            _ => [1e-6, f64::MAX],
        }
    }

    /// Scales a direction by a random power of two or small integer (never normalised).
    fn scale_dir(&mut self, d: [f64; 3]) -> [f64; 3] {
        let k = [0.25, 0.5, 1.0, 1.0, 2.0, 3.0][self.below(6) as usize];
        d.map(|x| x * k)
    }

    /// Random inputs for a `kind` primitive, with the generator's tags.
    pub fn inputs(&mut self, kind: ShapeKind) -> (ShapeSpec, RaySpec, [f64; 2], Vec<String>) {
        let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
        let add = |a: [f64; 3], b: [f64; 3]| [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
        let mul = |a: [f64; 3], k: f64| a.map(|x| x * k);
        let mut tags = Vec::new();
        let interval = self.interval();
        match kind {
            ShapeKind::Sphere => {
                let center = self.vec(-8.0, 8.0, 2);
                let r = self.dyadic(0.5, 6.0, 2);
                let radius = if self.chance(20) { -r } else { r };
                let (origin, direction) = match self.below(6) {
                    0 => {
                        tags.push("inside".to_string());
                        let o = add(center, self.vec(-r / 2.0, r / 2.0, 3));
                        (o, self.nonzero_int_vec(3))
                    }
                    k => {
                        let o = self.vec(-20.0, 20.0, 1);
                        let target = add(center, self.vec(-1.2 * r, 1.2 * r, 2));
                        let mut d = sub(target, o);
                        if k == 1 {
                            tags.push("behind".to_string());
                            d = mul(d, -1.0);
                        }
                        (o, d)
                    }
                };
                let direction = self.scale_dir(direction);
                (
                    ShapeSpec::Sphere { center, radius },
                    RaySpec { origin, direction },
                    interval,
                    tags,
                )
            }
            ShapeKind::Quad => {
                let q = self.vec(-8.0, 8.0, 1);
                let (u, v) = loop {
                    let (u, v) = if self.chance(30) {
                        let a = self.int(1, 4) as f64;
                        let b = self.int(1, 4) as f64;
                        ([a, 0.0, 0.0], [0.0, b, 0.0])
                    } else {
                        (self.nonzero_int_vec(4), self.nonzero_int_vec(4))
                    };
                    let n = glam::DVec3::from(u).cross(glam::DVec3::from(v));
                    if n != glam::DVec3::ZERO {
                        break (u, v);
                    }
                };
                let n = glam::DVec3::from(u).cross(glam::DVec3::from(v)).to_array();
                let (origin, direction) = if self.chance(12) {
                    tags.push("parallel".to_string());
                    let a = self.int(-2, 2) as f64;
                    let b = if a == 0.0 {
                        1.0
                    } else {
                        self.int(-2, 2) as f64
                    };
                    let d = add(mul(u, a), mul(v, b));
                    let off = [-2.0, -1.0, 1.0, 2.0][self.below(4) as usize];
                    // Off the plane by `off` normals, above a point of the quad.
                    let o = add(q, mul(n, off));
                    let o = add(o, add(mul(u, self.dyadic(0.0, 1.0, 2)), mul(v, 0.5)));
                    (o, d)
                } else {
                    let a = self.dyadic(-0.25, 1.25, 3);
                    let b = self.dyadic(-0.25, 1.25, 3);
                    let p = add(q, add(mul(u, a), mul(v, b)));
                    let o = self.vec(-20.0, 20.0, 1);
                    let mut d = sub(p, o);
                    if self.chance(15) {
                        tags.push("behind".to_string());
                        d = mul(d, -1.0);
                    }
                    (o, d)
                };
                let direction = self.scale_dir(direction);
                (
                    ShapeSpec::Quad { q, u, v },
                    RaySpec { origin, direction },
                    interval,
                    tags,
                )
            }
            ShapeKind::Triangle => {
                let a = self.vec(-8.0, 8.0, 1);
                let b = add(a, self.nonzero_int_vec(5));
                let c = add(a, self.nonzero_int_vec(5));
                let w1 = self.dyadic(-0.3, 1.0, 3);
                let w2 = self.dyadic(-0.3, 1.0, 3);
                let p = add(a, add(mul(sub(b, a), w1), mul(sub(c, a), w2)));
                let o = self.vec(-20.0, 20.0, 1);
                let direction = self.scale_dir(sub(p, o));
                (
                    ShapeSpec::Triangle { a, b, c },
                    RaySpec {
                        origin: o,
                        direction,
                    },
                    interval,
                    tags,
                )
            }
        }
    }
}

/// `n` definite random cases of the given kinds (round-robin), deterministic for `seed` and
/// `stream`, classified under `judging`; ids are `fuzz-<kind>-<stream>-<n>`. Half the attempts
/// are the small dyadic cases of [`random_cases`] (logic bugs), half draw from every precision
/// regime the vector suite covers: far spheres (distance over radius up to `1e8`), scenes scaled
/// by `2^-60 .. 2^60` and translated, tiny primitives (`2^-40 .. 2^-10` of their distance),
/// tangent and near-tangent ulp ladders, grazing rays, edges and corners, unnormalised
/// directions (length `1e-3 .. 1e3`) and interval boundaries. Only definite cases are kept.
pub fn random_cases_with(
    seed: u64,
    stream: u64,
    n: usize,
    kinds: &[ShapeKind],
    judging: Judging,
) -> Vec<Case> {
    let mut g = CaseGen::new(seed, stream);
    let mut r = Stream::new(seed, &format!("fuzz-regimes-{stream}"));
    let mut cases = Vec::with_capacity(n);
    let mut attempts = 0usize;
    while cases.len() < n && attempts < 20 * n + 100 {
        let kind = kinds[attempts % kinds.len()];
        let i = attempts / kinds.len();
        attempts += 1;
        let (shape, ray, interval, gen_tags) = if i % 2 == 0 {
            g.inputs(kind)
        } else {
            let list = regimes(kind);
            let cat = list[r.int(0, list.len() as i64 - 1) as usize];
            let raw = if cat == "tiny" {
                tiny(&mut r, kind)
            } else {
                og::raw_case(kind, cat, &mut r, i / 2)
            };
            let tags = raw.tags.iter().map(|t| t.to_string()).collect();
            (raw.shape, raw.ray, raw.interval, tags)
        };
        let tag_refs: Vec<&str> = gen_tags.iter().map(String::as_str).collect();
        let expect = crate::oracle::classify::classify_tagged_with(
            &shape, &ray, interval, &tag_refs, judging,
        );
        if expect.class.is_definite() {
            cases.push(Case {
                id: format!("fuzz-{}-{stream}-{:05}", kind.name(), cases.len()),
                shape,
                ray,
                interval,
                expect,
            });
        }
    }
    cases
}

/// `n` definite random cases of the given kinds (round-robin), deterministic for `seed` and
/// `stream`; ids are `fuzz-<kind>-<stream>-<n>`. Small integers and dyadic fractions only,
/// classified under the course profile (the fixtures' tests use these; fuzzing uses
/// [`random_cases_with`]).
pub fn random_cases(seed: u64, stream: u64, n: usize, kinds: &[ShapeKind]) -> Vec<Case> {
    let mut g = CaseGen::new(seed, stream);
    let mut cases = Vec::with_capacity(n);
    let mut attempts = 0usize;
    while cases.len() < n && attempts < 20 * n + 100 {
        let kind = kinds[attempts % kinds.len()];
        attempts += 1;
        let (shape, ray, interval, gen_tags) = g.inputs(kind);
        if let Some(mut expect) = oracle_expect(&shape, &ray, interval) {
            for t in gen_tags {
                if !expect.tags.contains(&t) {
                    expect.tags.push(t);
                }
            }
            cases.push(Case {
                id: format!("fuzz-{}-{stream}-{:05}", kind.name(), cases.len()),
                shape,
                ray,
                interval,
                expect,
            });
        }
    }
    cases
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::oracle::vectors::Class;

    #[test]
    fn cases_are_deterministic_mixed_and_mostly_definite() {
        let kinds = ShapeKind::ALL;
        let a = random_cases(7, 0, 600, &kinds);
        assert_eq!(a, random_cases(7, 0, 600, &kinds));
        assert_eq!(a.len(), 600);
        let hits = a.iter().filter(|c| c.expect.class == Class::Hit).count();
        assert!((150..450).contains(&hits), "{hits} hits of 600");
        for tag in ["negative-radius", "inside", "behind", "parallel"] {
            assert!(
                a.iter().any(|c| c.expect.tags.iter().any(|t| t == tag)),
                "{tag}"
            );
        }
        // A parallel ray off the plane is a definite miss.
        assert!(
            a.iter()
                .filter(|c| c.expect.tags.iter().any(|t| t == "parallel"))
                .all(|c| c.expect.class == Class::Miss)
        );
    }

    fn fuzz_failures(v: &crate::oracle::mistakes::Variant, cases: &[Case]) -> Vec<String> {
        cases
            .iter()
            .filter(|c| c.shape.kind() == v.shape)
            .filter_map(|c| {
                crate::oracle::mistakes::judge(&c.expect, &(v.run)(&c.shape, &c.ray, c.interval))
                    .err()
                    .map(|e| format!("{}: {e}", c.id))
            })
            .collect()
    }

    #[test]
    fn fuzzing_under_robust_finds_rtiow_out_and_the_reference_passes_it() {
        use crate::oracle::mistakes::{honest, rtiow};
        // Seeded: the same 2000 sphere cases every run.
        let robust = random_cases_with(3, 0, 2000, &[ShapeKind::Sphere], Judging::ROBUST);
        assert_eq!(robust.len(), 2000);
        let sphere = rtiow().remove(0);
        let f = fuzz_failures(&sphere, &robust);
        assert!(
            !f.is_empty(),
            "2000 robust cases never catch RTIOW's sphere"
        );
        // Fair: under the course profile the same code passes.
        let course = random_cases_with(3, 0, 2000, &[ShapeKind::Sphere], Judging::COURSE);
        assert_eq!(fuzz_failures(&sphere, &course), Vec::<String>::new());
        // The reference passes every robust fuzzed case of every shape.
        let all = random_cases_with(4, 1, 3000, &ShapeKind::ALL, Judging::ROBUST);
        for v in honest().iter().filter(|v| v.name.ends_with("-reference")) {
            let f = fuzz_failures(v, &all);
            assert!(f.is_empty(), "{}: {:?}", v.name, &f[..f.len().min(3)]);
        }
        // The regimes are reached: far, scaled and tiny cases are among the definite ones.
        for tag in ["far", "scale", "tiny", "unnormalised", "edge", "grazing"] {
            assert!(
                all.iter().any(|c| c.expect.tags.iter().any(|t| t == tag)),
                "no fuzzed case tagged {tag}"
            );
        }
    }

    #[test]
    fn boundary_cases_are_not_definite() {
        // Tangent: the ray grazes the unit sphere at x = 1.
        let s = ShapeSpec::Sphere {
            center: [0.0; 3],
            radius: 1.0,
        };
        let tangent = RaySpec {
            origin: [1.0, 0.0, 5.0],
            direction: [0.0, 0.0, -1.0],
        };
        assert!(oracle_expect(&s, &tangent, [1e-6, f64::MAX]).is_none());
        // Hit exactly at t_max = 4.
        let down = RaySpec {
            origin: [0.0, 0.0, 5.0],
            direction: [0.0, 0.0, -1.0],
        };
        assert!(oracle_expect(&s, &down, [1e-6, 4.0]).is_none());
        let e = oracle_expect(&s, &down, [1e-6, 4.5]).unwrap();
        assert_eq!((e.class, e.t), (Class::Hit, Some(4.0)));
        // A ray exactly parallel to a quad: in its plane degenerate, off it a miss.
        let q = ShapeSpec::Quad {
            q: [0.0; 3],
            u: [1.0, 0.0, 0.0],
            v: [0.0, 1.0, 0.0],
        };
        let along = |z: f64| RaySpec {
            origin: [-1.0, 0.5, z],
            direction: [1.0, 0.0, 0.0],
        };
        assert!(oracle_expect(&q, &along(0.0), [1e-6, f64::MAX]).is_none());
        let e = oracle_expect(&q, &along(0.5), [1e-6, f64::MAX]).unwrap();
        assert_eq!(
            (e.class, e.tags),
            (Class::Miss, vec!["parallel".to_string()])
        );
        // Quad edge.
        let q = ShapeSpec::Quad {
            q: [0.0; 3],
            u: [1.0, 0.0, 0.0],
            v: [0.0, 1.0, 0.0],
        };
        let edge = RaySpec {
            origin: [1.0, 0.5, 1.0],
            direction: [0.0, 0.0, -1.0],
        };
        assert!(oracle_expect(&q, &edge, [1e-6, f64::MAX]).is_none());
    }
}
