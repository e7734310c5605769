//! Watertight groups: two or three coplanar shapes that share an edge, and a ray through an
//! exact point of the shared edge or a shared vertex.
//!
//! One shape alone cannot tell an open edge (`alpha > 0` where `alpha >= 0` is meant) from a
//! closed one: a ray through the exact edge is, rightly, ambiguous, since rounding may put it on
//! either side. Where two shapes share the edge, an open edge is a real bug (the ray misses both
//! and a mesh shows cracks), so a group carries a rule of its own: *the ray hits at least one
//! of the group's shapes* ([`Watertight`], in each member's `expect.watertight`).
//!
//! The groups ([`watertight_cases`]): two coplanar quads sharing an edge (the second anchored so
//! the shared edge is its `beta = 0`, `alpha = 0` or `beta = 1`), a square split into two
//! triangles along its diagonal, and a quad whose edge two triangles share (meeting at a vertex
//! in its middle; the group holds the shapes through the ray's point: the quad and one triangle,
//! or all three at that vertex). Every member holds the point, so each is hit exactly and none
//! is a definite vector alone: the groups add no definite vector to a suite. Each lies in an axis plane (any axis, either orientation, any integer
//! offset), with power-of-two sides, and the ray runs along the plane's normal (either side,
//! a power-of-two length) through a dyadic point of the shared edge or through a shared vertex.
//! In such a group every quantity an honest intersector computes is a small dyadic number
//! (`u x v`, `n . n`, `w`, `t`, the hit point's coordinates in the plane, `alpha`, `beta`,
//! Möller–Trumbore's `det` and barycentrics), exact in `f64` and in `f32`; so closed-edge code
//! hits the edge exactly and open-edge code misses every member, under every profile and
//! precision. The rule is decided exactly: the members' expected answers come from
//! [`classify_tagged_with`] (exact arithmetic), and a group is `hit` only when at least one of
//! them is hit exactly (the generator checks it). Rays that lie in the plane (tangent to the
//! group) make groups of class `ambiguous`: reported, never scored.

use super::classify::classify_tagged_with;
use super::generate::{CAMERA, Stream, add, pow2, scale, sub};
use super::profile::Judging;
pub use super::vectors::Watertight;
use super::vectors::{Case, Class, RaySpec, ShapeSpec};

/// The kinds of group, with how many groups of each the suite holds (the last
/// [`TANGENT_GROUPS`] of each have a ray in the plane).
pub const GROUPS: [(&str, usize); 3] = [("quads", 18), ("triangles", 18), ("quad-triangles", 18)];

/// How many groups of each kind have a ray lying in their plane (class `ambiguous`).
pub const TANGENT_GROUPS: usize = 2;

/// A point in the plane's own coordinates `(x, y)`, the plane being `z = 0`.
type P2 = [f64; 2];

/// One shape of a group in plane coordinates.
#[derive(Clone, Copy)]
enum Flat {
    Quad { q: P2, u: P2, v: P2 },
    Triangle { a: P2, b: P2, c: P2 },
}

/// Where a group lies: plane coordinates `(x, y, z)` go to world axis `axes[i]` times
/// `signs[i]`, plus `offset`.
struct Frame {
    axes: [usize; 3],
    signs: [f64; 3],
    offset: [f64; 3],
}

impl Frame {
    fn random(r: &mut Stream) -> Frame {
        const PERMS: [[usize; 3]; 6] = [
            [0, 1, 2],
            [0, 2, 1],
            [1, 0, 2],
            [1, 2, 0],
            [2, 0, 1],
            [2, 1, 0],
        ];
        let axes = PERMS[r.int(0, 5) as usize];
        let signs = [0; 3].map(|_| if r.coin() { 1.0 } else { -1.0 });
        Frame {
            axes,
            signs,
            offset: r.ivec(-16, 16),
        }
    }

    /// A direction in plane coordinates, in the world.
    fn dir(&self, d: [f64; 3]) -> [f64; 3] {
        let mut w = [0.0; 3];
        for i in 0..3 {
            w[self.axes[i]] = self.signs[i] * d[i];
        }
        w
    }

    /// A point of the plane (`z = 0`) in the world.
    fn point(&self, p: P2) -> [f64; 3] {
        add(self.offset, self.dir([p[0], p[1], 0.0]))
    }

    fn shape(&self, f: Flat) -> ShapeSpec {
        let e = |d: P2| self.dir([d[0], d[1], 0.0]);
        match f {
            Flat::Quad { q, u, v } => ShapeSpec::Quad {
                q: self.point(q),
                u: e(u),
                v: e(v),
            },
            Flat::Triangle { a, b, c } => ShapeSpec::Triangle {
                a: self.point(a),
                b: self.point(b),
                c: self.point(c),
            },
        }
    }
}

/// `(a, b, c)` rotated `k` times (the same triangle, another first vertex).
fn rotated(a: P2, b: P2, c: P2, k: i64) -> Flat {
    let (a, b, c) = match k % 3 {
        0 => (a, b, c),
        1 => (b, c, a),
        _ => (c, a, b),
    };
    Flat::Triangle { a, b, c }
}

/// A random dyadic `k / 64` of `len` with `k` in `1..=63` (a point inside an edge).
fn inside(r: &mut Stream, len: f64) -> f64 {
    r.int(1, 63) as f64 * len / 64.0
}

/// The 2D cross product `a x b`.
fn cross2(a: P2, b: P2) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// Whether the closed shape `f` holds `p` (exact for the groups' small dyadic numbers).
fn holds(f: Flat, p: P2) -> bool {
    let (q, u, v, triangle) = match f {
        Flat::Quad { q, u, v } => (q, u, v, false),
        Flat::Triangle { a, b, c } => (
            a,
            [b[0] - a[0], b[1] - a[1]],
            [c[0] - a[0], c[1] - a[1]],
            true,
        ),
    };
    let d = [p[0] - q[0], p[1] - q[1]];
    let n = cross2(u, v);
    let (alpha, beta) = (cross2(d, v) / n, cross2(u, d) / n);
    let unit = |x: f64| (0.0..=1.0).contains(&x);
    unit(alpha) && unit(beta) && (!triangle || alpha + beta <= 1.0)
}

/// The shapes of a group of `kind` and the point the ray goes through, with the tag the point
/// earns (`edge` or `corner`).
fn layout(kind: &str, r: &mut Stream) -> (Vec<Flat>, P2, &'static str) {
    let (l, m, n) = (pow2(r.int(0, 3)), pow2(r.int(0, 3)), pow2(r.int(0, 3)));
    let vertex = r.int(0, 3) == 0;
    match kind {
        "quads" => {
            let a = Flat::Quad {
                q: [0.0, 0.0],
                u: [l, 0.0],
                v: [0.0, m],
            };
            let b = match r.int(0, 2) {
                0 => Flat::Quad {
                    q: [0.0, m],
                    u: [l, 0.0],
                    v: [0.0, n],
                },
                1 => Flat::Quad {
                    q: [0.0, m],
                    u: [0.0, n],
                    v: [l, 0.0],
                },
                _ => Flat::Quad {
                    q: [l, m + n],
                    u: [-l, 0.0],
                    v: [0.0, -n],
                },
            };
            let p = if vertex {
                [[0.0, m], [l, m]][r.int(0, 1) as usize]
            } else {
                [inside(r, l), m]
            };
            (vec![a, b], p, if vertex { "corner" } else { "edge" })
        }
        "triangles" => {
            // The square [0, l]^2 split along its diagonal from (l, 0) to (0, l).
            let (o, x, y, xy) = ([0.0, 0.0], [l, 0.0], [0.0, l], [l, l]);
            let t1 = rotated(o, x, y, r.int(0, 2));
            let t2 = rotated(xy, y, x, r.int(0, 2));
            let p = if vertex {
                [x, y][r.int(0, 1) as usize]
            } else {
                let s = inside(r, l);
                [l - s, s]
            };
            (vec![t1, t2], p, if vertex { "corner" } else { "edge" })
        }
        _ => {
            // The quad's edge y = m is shared by two triangles meeting at (l/2, m).
            let h = l / 2.0;
            let quad = Flat::Quad {
                q: [0.0, 0.0],
                u: [l, 0.0],
                v: [0.0, m],
            };
            let t1 = rotated([0.0, m], [h, m], [0.0, m + n], r.int(0, 2));
            let t2 = rotated([h, m], [l, m], [l, m + n], r.int(0, 2));
            let p = if vertex {
                [[h, m], [0.0, m], [l, m]][r.int(0, 2) as usize]
            } else {
                [inside(r, l), m]
            };
            let tag = if vertex || p[0] == h {
                "corner"
            } else {
                "edge"
            };
            // The shapes through the point: the quad and the triangle (or both) it touches.
            let shapes = [quad, t1, t2]
                .into_iter()
                .filter(|&f| holds(f, p))
                .collect();
            (shapes, p, tag)
        }
    }
}

/// The ray of group `i` of a kind through `p` (plane coordinates): along the normal from
/// either side, or, for the last [`TANGENT_GROUPS`], lying in the plane.
fn ray(frame: &Frame, p: P2, tangent: bool, r: &mut Stream) -> RaySpec {
    let d = if tangent {
        [r.int(-4, 4) as f64, r.int(1, 4) as f64, 0.0]
    } else {
        let side = if r.coin() { 1.0 } else { -1.0 };
        [0.0, 0.0, side * pow2(r.int(-2, 2))]
    };
    let t = pow2(r.int(0, 4));
    let p = frame.point(p);
    let d = frame.dir(d);
    RaySpec {
        origin: sub(p, scale(d, t)),
        direction: d,
    }
}

/// The watertight groups for `seed`, each member classified under `judging` (the same inputs,
/// ids and groups for every judging), ids like `watertight-quads-0003-b`.
pub fn watertight_cases(seed: u64, judging: Judging) -> Vec<Case> {
    let mut cases = Vec::new();
    for (kind, count) in GROUPS {
        let mut r = Stream::new(seed, &format!("watertight-{kind}"));
        for i in 0..count {
            let group = format!("watertight-{kind}-{i:04}");
            let tangent = i >= count - TANGENT_GROUPS;
            let frame = Frame::random(&mut r);
            let (flats, p, tag) = layout(kind, &mut r);
            let ray = ray(&frame, p, tangent, &mut r);
            let class = if tangent {
                Class::Ambiguous
            } else {
                Class::Hit
            };
            let first = cases.len();
            for (k, flat) in flats.into_iter().enumerate() {
                let shape = frame.shape(flat);
                let mut expect = classify_tagged_with(&shape, &ray, CAMERA, &[tag], judging);
                expect.watertight = Some(Watertight {
                    group: group.clone(),
                    class,
                });
                cases.push(Case {
                    id: format!("{group}-{}", (b'a' + k as u8) as char),
                    shape,
                    ray,
                    interval: CAMERA,
                    expect,
                });
            }
            // Decided exactly: the ray goes through the closed union, so at least one member
            // is hit exactly.
            assert!(
                tangent || cases[first..].iter().any(|c| c.expect.t.is_some()),
                "{group}: no member is hit exactly"
            );
        }
    }
    cases
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::oracle::mistakes::{self, VHit, Variant};
    use crate::oracle::profile::{Precision, Profile};
    use crate::oracle::vectors::ShapeKind;
    use std::collections::BTreeMap;

    const JUDGINGS: [Judging; 4] = [
        Judging::new(Profile::Course, Precision::F64),
        Judging::new(Profile::Robust, Precision::F64),
        Judging::new(Profile::Course, Precision::F32),
        Judging::new(Profile::Robust, Precision::F32),
    ];

    /// The groups of `cases` by id, in order.
    fn groups(cases: &[Case]) -> BTreeMap<String, Vec<&Case>> {
        let mut g: BTreeMap<String, Vec<&Case>> = BTreeMap::new();
        for c in cases {
            let w = c.expect.watertight.as_ref().expect("a member");
            g.entry(w.group.clone()).or_default().push(c);
        }
        g
    }

    /// Whether `run` (of the member's kind) hits `c` at its exact `t`.
    fn hits(run: &Variant, c: &Case) -> bool {
        match (run.run)(&c.shape, &c.ray, c.interval) {
            Ok(Some(VHit { t, .. })) => c.expect.t.is_some_and(|te| (t - te).abs() <= 1e-6 * te),
            _ => false,
        }
    }

    fn variant(all: &[Variant], name: &str) -> Variant {
        all.iter()
            .find(|v| v.name == name)
            .copied()
            .unwrap_or_else(|| panic!("no variant {name}"))
    }

    /// For every judging: the same groups, a rule decided exactly (a member hit exactly in
    /// each `hit` group, every member's point on the shared edge), and the members alone not
    /// definite where the edge is (the rule is the only way to find an open edge).
    #[test]
    fn groups_are_the_same_in_every_judging_and_their_rule_is_exact() {
        let base = watertight_cases(0, Judging::COURSE);
        let n_groups: usize = GROUPS.iter().map(|g| g.1).sum();
        assert_eq!(groups(&base).len(), n_groups);
        for judging in JUDGINGS {
            let cases = watertight_cases(0, judging);
            assert_eq!(cases.len(), base.len());
            for (c, b) in cases.iter().zip(&base) {
                assert_eq!((&c.id, &c.shape, &c.ray), (&b.id, &b.shape, &b.ray));
                assert_eq!(c.expect.watertight, b.expect.watertight);
                // The expected answer is exact: the same in every judging.
                assert_eq!((c.expect.t, c.expect.point), (b.expect.t, b.expect.point));
            }
            for (id, members) in groups(&cases) {
                let class = members[0].expect.watertight.as_ref().unwrap().class;
                let hit: Vec<_> = members.iter().filter(|c| c.expect.t.is_some()).collect();
                if class == Class::Hit {
                    assert!(!hit.is_empty(), "{id}");
                    // All hit at the same point: the one on the shared edge.
                    assert!(hit.iter().all(|c| c.expect.point == hit[0].expect.point));
                    assert!(hit.len() >= 2, "{id}: the point is shared");
                    assert_eq!(
                        hit.len(),
                        members.len(),
                        "{id}: every member holds the point"
                    );
                    // No member hit at the edge is a definite hit by itself.
                    assert!(
                        hit.iter().all(|c| c.expect.class != Class::Hit),
                        "{id} under {judging}"
                    );
                }
            }
        }
    }

    /// Closed-edge code (the course's quad, RTIOW's in f64 and f32, the reference's, course
    /// style and Möller–Trumbore triangles) hits at least one member of every `hit` group;
    /// open-edge code (`0 < alpha < 1`) hits none in any group.
    #[test]
    fn closed_edges_hold_every_group_and_open_edges_crack_every_one() {
        let honest = mistakes::honest();
        let rtiow: Vec<Variant> = mistakes::rtiow()
            .into_iter()
            .chain(mistakes::rtiow_f32())
            .collect();
        let closed = [
            (
                variant(&honest, "quad-course"),
                variant(&honest, "triangle-course-style"),
            ),
            (
                variant(&honest, "quad-reference"),
                variant(&honest, "triangle-reference"),
            ),
            (
                variant(&honest, "quad-normalised-direction"),
                variant(&honest, "triangle-moller-trumbore"),
            ),
            (
                variant(&rtiow, "quad-rtiow"),
                variant(&honest, "triangle-moller-trumbore"),
            ),
            (
                variant(&rtiow, "quad-rtiow-f32"),
                variant(&honest, "triangle-course-style"),
            ),
        ];
        let open = (
            variant(&honest, "quad-strict-edges"),
            variant(&honest, "triangle-course-style-strict"),
        );
        let pick = |pair: &(Variant, Variant), c: &Case| {
            if c.shape.kind() == ShapeKind::Quad {
                pair.0
            } else {
                pair.1
            }
        };
        let cases = watertight_cases(0, Judging::COURSE);
        let mut cracked = 0;
        for (id, members) in groups(&cases) {
            if members[0].expect.watertight.as_ref().unwrap().class != Class::Hit {
                continue;
            }
            for pair in &closed {
                assert!(
                    members.iter().any(|c| hits(&pick(pair, c), c)),
                    "{id}: {} / {} hit no member",
                    pair.0.name,
                    pair.1.name
                );
            }
            assert!(
                !members.iter().any(|c| hits(&pick(&open, c), c)),
                "{id}: open edges hit"
            );
            cracked += 1;
        }
        assert_eq!(
            cracked,
            GROUPS.iter().map(|g| g.1 - TANGENT_GROUPS).sum::<usize>()
        );
    }
}
