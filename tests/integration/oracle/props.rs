//! Properties and metamorphic relations of the oracle (`ORACLE.md`), as proptest tests with a
//! fixed seed and a committed regression file, plus pbrt-v4's re-intersection test and
//! Embree-style watertightness tests of the reference.

use proptest::prelude::*;
use proptest::test_runner::{Config, FileFailurePersistence, RngAlgorithm, RngSeed};

use rtoracle::geometry::{DVec3, Interval, Ray, Shape, Triangle};
use rtoracle::oracle::classify::analyse;
use rtoracle::oracle::exact::{Decision, ExactHit};
use rtoracle::oracle::generate::{Raw, Stream, pow2, random_plane, random_sphere, raw_case};
use rtoracle::oracle::vectors::{Class, RaySpec, ShapeKind, ShapeSpec};

fn config(cases: u32) -> Config {
    Config {
        cases,
        rng_algorithm: RngAlgorithm::ChaCha,
        rng_seed: RngSeed::Fixed(0x0ac1e),
        failure_persistence: Some(Box::new(FileFailurePersistence::Direct(
            "tests/proptest-regressions/oracle_props.txt",
        ))),
        ..Config::default()
    }
}

/// A generated case: a seed, a shape and a category of the generators.
fn case() -> impl Strategy<Value = Raw> {
    let cats = [
        (ShapeKind::Sphere, "random"),
        (ShapeKind::Sphere, "tangent"),
        (ShapeKind::Sphere, "near-tangent"),
        (ShapeKind::Sphere, "inside"),
        (ShapeKind::Sphere, "interval-boundary"),
        (ShapeKind::Sphere, "negative-radius"),
        (ShapeKind::Sphere, "far"),
        (ShapeKind::Quad, "random"),
        (ShapeKind::Quad, "edge"),
        (ShapeKind::Quad, "corner"),
        (ShapeKind::Quad, "grazing"),
        (ShapeKind::Quad, "interval-boundary"),
        (ShapeKind::Quad, "skewed"),
        (ShapeKind::Triangle, "random"),
        (ShapeKind::Triangle, "edge"),
        (ShapeKind::Triangle, "corner"),
    ];
    (any::<u64>(), 0..cats.len(), 0usize..64).prop_map(move |(seed, k, i)| {
        let (kind, cat) = cats[k];
        raw_case(kind, cat, &mut Stream::new(seed, "prop"), i)
    })
}

/// The exact decision and hit of a case.
fn exact(c: &Raw) -> (Option<Decision>, Option<ExactHit>) {
    let a = analyse(&c.shape, &c.ray, c.interval);
    (a.decision, a.hit)
}

fn map_points(c: &Raw, f: impl Fn([f64; 3]) -> [f64; 3], g: impl Fn([f64; 3]) -> [f64; 3]) -> Raw {
    let mut out = c.clone();
    out.shape = match c.shape {
        ShapeSpec::Sphere { center, radius } => ShapeSpec::Sphere {
            center: f(center),
            radius,
        },
        ShapeSpec::Quad { q, u, v } => ShapeSpec::Quad {
            q: f(q),
            u: g(u),
            v: g(v),
        },
        ShapeSpec::Triangle { a, b, c } => ShapeSpec::Triangle {
            a: f(a),
            b: f(b),
            c: f(c),
        },
    };
    out.ray = RaySpec {
        origin: f(c.ray.origin),
        direction: g(c.ray.direction),
    };
    out
}

/// Whether `|unit(n) . d|` is within a factor 2^31 of the course's 1e-8 threshold.
fn near_threshold(c: &Raw) -> bool {
    let ShapeSpec::Quad { u, v, .. } = c.shape else {
        return false;
    };
    let n = DVec3::from(u).cross(DVec3::from(v));
    let x = (n.normalize().dot(DVec3::from(c.ray.direction))).abs();
    !(x > 1e-8 * 2f64.powi(31) || x < 1e-8 * 2f64.powi(-31))
}

fn t_bits(h: Option<ExactHit>) -> Option<u64> {
    h.map(|h| h.t.to_bits())
}

proptest! {
    #![proptest_config(config(400))]

    /// The reference decides every definite case as the exact oracle does, with t in t_tol.
    #[test]
    fn reference_equals_exact_on_definite_cases(c in case()) {
        let e = rtoracle::oracle::classify::classify(&c.shape, &c.ray, c.interval);
        let hit = c.shape.object().intersect(&c.ray.ray(), Interval::new(c.interval[0], c.interval[1]));
        if e.class.is_definite() {
            prop_assert_eq!(hit.is_some(), e.class == Class::Hit);
            if let (Some(h), Some(t)) = (hit, e.t) {
                prop_assert!((h.t - t).abs() <= e.t_tol.unwrap());
                prop_assert_eq!(h.front_face, e.front_face.unwrap());
            }
        }
    }

    /// Permuting and reflecting the axes changes neither the decision nor t (bit for bit).
    #[test]
    fn axis_permutation_and_reflection_are_exact(c in case(), p in 0usize..6, flip in 0usize..3) {
        let perms = [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]];
        let pm = perms[p];
        let f = move |v: [f64; 3]| {
            let mut w = [v[pm[0]], v[pm[1]], v[pm[2]]];
            w[flip] = -w[flip];
            w
        };
        let d = map_points(&c, f, f);
        let (a, b) = (exact(&c), exact(&d));
        prop_assert_eq!(a.0, b.0);
        prop_assert_eq!(t_bits(a.1), t_bits(b.1));
    }

    /// Scaling every position and d by 2^k keeps the decision and t; d -> 2^k d alone (with the
    /// interval scaled by 2^-k) gives t -> 2^-k t exactly.
    #[test]
    fn power_of_two_scalings_are_exact(c in case(), k in -30i64..30) {
        // The course's parallel threshold on quads is absolute in d: leave it out.
        if let Some(sg) = rtoracle::oracle::exact::plane_signs(&c.shape, &c.ray, c.interval) {
            if sg.below_threshold || matches!(c.shape, ShapeSpec::Quad { .. }) && near_threshold(&c) {
                return Ok(());
            }
        }
        let s = pow2(k);
        let mut d = map_points(&c, |v| v.map(|x| x * s), |v| v.map(|x| x * s));
        if let ShapeSpec::Sphere { radius, .. } = &mut d.shape { *radius *= s; }
        let (a, b) = (exact(&c), exact(&d));
        prop_assert_eq!(a.0, b.0);
        prop_assert_eq!(t_bits(a.1), t_bits(b.1));
        let mut e = c.clone();
        e.ray.direction = c.ray.direction.map(|x| x * s);
        e.interval = c.interval.map(|x| if x == f64::MAX { x } else { x / s });
        let b = exact(&e);
        prop_assert_eq!(a.0, b.0);
        prop_assert_eq!(a.1.map(|h| (h.t / s).to_bits()), t_bits(b.1));
    }

    /// A negative radius gives the same t and flips front_face.
    #[test]
    fn negative_radius_flips_only_the_face(c in case()) {
        let ShapeSpec::Sphere { center, radius } = c.shape else { return Ok(()); };
        let mut d = c.clone();
        d.shape = ShapeSpec::Sphere { center, radius: -radius };
        let (a, b) = (exact(&c), exact(&d));
        prop_assert_eq!(a.0, b.0);
        prop_assert_eq!(t_bits(a.1), t_bits(b.1));
        if let (Some(x), Some(y)) = (a.1, b.1) {
            if x.front_face || y.front_face {
                prop_assert_ne!(x.front_face, y.front_face);
            }
        }
    }

    /// Quads: u <-> v swaps alpha and beta; re-anchoring at the opposite corner (Q + u + v, -u,
    /// -v) keeps the decision and t and maps alpha to 1 - alpha. Triangles: rotating the
    /// vertices keeps the decision and t.
    #[test]
    fn quad_and_triangle_relabellings_are_exact(c in case()) {
        let a = exact(&c);
        match c.shape {
            ShapeSpec::Quad { q, u, v } => {
                let mut d = c.clone();
                d.shape = ShapeSpec::Quad { q, u: v, v: u };
                let b = exact(&d);
                prop_assert_eq!(a.0, b.0);
                prop_assert_eq!(t_bits(a.1), t_bits(b.1));
                if let (Some(x), Some(y)) = (a.1, b.1) {
                    let (xa, xb) = x.uv.unwrap();
                    let (ya, yb) = y.uv.unwrap();
                    prop_assert_eq!((xa.to_bits(), xb.to_bits()), (yb.to_bits(), ya.to_bits()));
                }
                let far = [q[0] + u[0] + v[0], q[1] + u[1] + v[1], q[2] + u[2] + v[2]];
                let exact_sum = (0..3).all(|i| far[i] - u[i] - v[i] == q[i]);
                if exact_sum {
                    let mut e = c.clone();
                    e.shape = ShapeSpec::Quad { q: far, u: u.map(|x| -x), v: v.map(|x| -x) };
                    let b = exact(&e);
                    prop_assert_eq!(a.0, b.0);
                    prop_assert_eq!(t_bits(a.1), t_bits(b.1));
                }
            }
            ShapeSpec::Triangle { a: p, b: q, c: r } => {
                let mut d = c.clone();
                d.shape = ShapeSpec::Triangle { a: q, b: r, c: p };
                let b = exact(&d);
                prop_assert_eq!(a.0, b.0);
                prop_assert_eq!(t_bits(a.1), t_bits(b.1));
            }
            ShapeSpec::Sphere { .. } => {}
        }
    }

    /// Moving the origin along the ray by s d moves t by -s (approximately, for the
    /// reference on definite hits); reversing the ray of a plane hit keeps the hit point.
    #[test]
    fn moving_the_origin_along_the_ray_shifts_t(c in case(), s in 0.0f64..0.5) {
        let e = rtoracle::oracle::classify::classify(&c.shape, &c.ray, c.interval);
        let (Class::Hit, Some(t)) = (e.class, e.t) else { return Ok(()); };
        let shift = s * t;
        let mut d = c.clone();
        d.ray.origin = [0, 1, 2].map(|i| c.ray.origin[i] + shift * c.ray.direction[i]);
        d.interval = c.interval.map(|x| if x == f64::MAX { x } else { x - shift });
        let h = d.shape.object().hit_t(&d.ray.ray(), Interval::new(d.interval[0], d.interval[1]));
        let e2 = rtoracle::oracle::classify::classify(&d.shape, &d.ray, d.interval);
        if e2.class == Class::Hit {
            let h = h.expect("definite hit");
            prop_assert!((h - (t - shift)).abs() <= 1e-6 * t.abs() + e2.t_tol.unwrap(), "{} vs {}", h, t - shift);
        }
    }
}

/// A generic case: the `random` category of one of the three shapes, whose exact decisions are
/// not near a boundary (unlike the tangent, edge, corner and grazing categories, built to be).
fn generic_case() -> impl Strategy<Value = Raw> {
    let kinds = [ShapeKind::Sphere, ShapeKind::Quad, ShapeKind::Triangle];
    (any::<u64>(), 0..kinds.len(), 0usize..64).prop_map(move |(seed, k, i)| {
        raw_case(kinds[k], "random", &mut Stream::new(seed, "rigid"), i)
    })
}

/// The rotation matrix (rows) of the unit quaternion along `q` (any non-zero 4-vector).
fn rotation(q: [f64; 4]) -> [[f64; 3]; 3] {
    let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
    let [w, x, y, z] = q.map(|c| c / n);
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

fn apply(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    m.map(|row| row[0] * v[0] + row[1] * v[1] + row[2] * v[2])
}

/// The largest magnitude among a case's numbers: the scale of its rounding errors.
fn size_of(c: &Raw) -> f64 {
    c.shape
        .numbers()
        .iter()
        .chain(&c.ray.origin)
        .fold(0.0f64, |m, x| m.max(x.abs()))
}

proptest! {
    #![proptest_config(config(400))]

    /// Approximate relations: a rigid motion (a rotation, then a translation of up to four times
    /// the case's size) of a generic case keeps the exact decision, and moves the hit as it moves
    /// the case: the same t, the point carried along, the normal turned and the same face. The
    /// motion rounds every input by a few ulps of the case's size; a generic case is far from
    /// every boundary compared with that, so its decision cannot flip (a case that is ambiguous
    /// either way is skipped), and t, point and normal move by a few ulps over the angle.
    #[test]
    fn rotations_and_translations_move_the_hit_with_the_case(
        c in generic_case(),
        q in prop::array::uniform4(-1.0f64..1.0),
        shift in prop::array::uniform3(-4.0f64..4.0),
    ) {
        prop_assume!(q.iter().map(|x| x * x).sum::<f64>() > 1e-3);
        let m = rotation(q);
        let size = size_of(&c);
        let shift = shift.map(|x| x * size);
        let moved = map_points(
            &c,
            |p| {
                let r = apply(&m, p);
                [r[0] + shift[0], r[1] + shift[1], r[2] + shift[2]]
            },
            |v| apply(&m, v),
        );
        let before = rtoracle::oracle::classify::classify(&c.shape, &c.ray, c.interval);
        let after = rtoracle::oracle::classify::classify(&moved.shape, &moved.ray, moved.interval);
        let definite = |e: &rtoracle::oracle::vectors::Expect| matches!(e.class, Class::Hit | Class::Miss);
        if !(definite(&before) && definite(&after)) {
            return Ok(());
        }
        prop_assert_eq!(before.class, after.class, "{:?} moved to {:?}", c, moved);
        if before.class != Class::Hit {
            return Ok(());
        }
        let (t0, t1) = (before.t.unwrap(), after.t.unwrap());
        prop_assert!((t0 - t1).abs() <= 1e-9 * t0.abs().max(1e-300), "t {} vs {}", t0, t1);
        let p0 = apply(&m, before.point.unwrap());
        let p1 = after.point.unwrap();
        let reach = size + t0.abs() * DVec3::from(c.ray.direction).length();
        for i in 0..3 {
            prop_assert!((p0[i] + shift[i] - p1[i]).abs() <= 1e-9 * (reach + size), "point {:?} vs {:?}", p0, p1);
        }
        let (n0, n1) = (apply(&m, before.normal.unwrap()), after.normal.unwrap());
        prop_assert!((0..3).all(|i| (n0[i] - n1[i]).abs() <= 1e-9), "normal {:?} vs {:?}", n0, n1);
        prop_assert_eq!(before.front_face, after.front_face);
    }
}

proptest! {
    #![proptest_config(config(200))]

    /// Permuting a scene's objects does not change the closest t (ties aside).
    #[test]
    fn permuting_a_scenes_objects_keeps_the_closest_hit(seed in any::<u64>(), n in 2usize..7, rot in 1usize..6) {
        use rtoracle::scene::{Scene, SceneObject};
        let mut r = Stream::new(seed, "scene-perm");
        let base = random_sphere(&mut r, 20.0, Some((0.0, 0.8)));
        let ray = base.ray.ray();
        let mut objects = vec![base.shape];
        for k in 1..n {
            // More primitives around the same ray: random spheres and quads near its path.
            let t = r.uniform(0.5, 3.0) * k as f64;
            let p = ray.at(t).to_array();
            let s = r.uniform(0.1, 1.0) * (ray.direction.length() * t).max(1e-300);
            objects.push(if r.coin() {
                ShapeSpec::Sphere { center: p, radius: s }
            } else {
                let u = r.unit().map(|x| x * s);
                let v = r.unit().map(|x| x * s);
                ShapeSpec::Quad { q: [0, 1, 2].map(|i| p[i] - 0.5 * (u[i] + v[i])), u, v }
            });
        }
        let scene = |shapes: &[ShapeSpec]| Scene {
            objects: shapes.iter().map(|s| SceneObject { shape: s.object(), material: 0 }).collect(),
            materials: vec![],
        };
        let hits: Vec<f64> = objects
            .iter()
            .filter_map(|o| o.object().hit_t(&ray, Interval::CAMERA))
            .collect();
        let mut sorted = hits.clone();
        sorted.sort_by(f64::total_cmp);
        prop_assume!(sorted.windows(2).all(|w| w[0] != w[1]));
        let a = scene(&objects).closest(&ray, Interval::CAMERA).map(|h| h.0);
        let mut permuted = objects.clone();
        permuted.rotate_left(rot % n);
        permuted.reverse();
        let b = scene(&permuted).closest(&ray, Interval::CAMERA).map(|h| h.0);
        prop_assert_eq!(a.map(f64::to_bits), b.map(f64::to_bits));
        prop_assert_eq!(a, sorted.first().copied());
    }

    /// Reversing a ray that hits a quad or triangle definitely, from a point beyond the hit,
    /// meets the same point (approximately).
    #[test]
    fn reversing_the_ray_meets_the_same_point(c in case()) {
        if matches!(c.shape, ShapeSpec::Sphere { .. }) { return Ok(()); }
        let e = rtoracle::oracle::classify::classify(&c.shape, &c.ray, c.interval);
        let (Class::Hit, Some(p), Some(t)) = (e.class, e.point, e.t) else { return Ok(()); };
        let o2 = [0, 1, 2].map(|i| c.ray.origin[i] + 2.0 * t * c.ray.direction[i]);
        let back = RaySpec { origin: o2, direction: c.ray.direction.map(|x| -x) };
        let e2 = rtoracle::oracle::classify::classify(&c.shape, &back, [0.0, f64::MAX]);
        if e2.class == Class::Hit {
            let q = e2.point.unwrap();
            let size = c.shape.numbers().iter().chain(&c.ray.origin).fold(0.0f64, |m, x| m.max(x.abs()));
            let off = (0..3).map(|i| (p[i] - q[i]).abs()).fold(0.0, f64::max);
            prop_assert!(off <= 1e-9 * (size + t.abs() * 4.0), "{:?} vs {:?}", p, q);
        }
    }
}

/// pbrt-v4's re-intersection test: a ray spawned from a hit point, offset off the surface and
/// leaving it, never hits the same primitive again, at scales 1e-8 .. 1e8.
#[test]
fn spawned_rays_never_hit_their_own_primitive_again() {
    let mut r = Stream::new(7, "reintersect");
    let mut tried = 0;
    for i in 0..20_000 {
        let scale_k = r.int(-26, 26); // 2^-26 .. 2^26, about 1e-8 .. 1e8
        let mut c = if i % 2 == 0 {
            random_sphere(&mut r, 50.0, Some((0.0, 0.95)))
        } else {
            random_plane(&mut r, i % 4 == 1)
        };
        let s = pow2(scale_k);
        c = map_points(&c, |v| v.map(|x| x * s), |v| v.map(|x| x * s));
        if let ShapeSpec::Sphere { radius, .. } = &mut c.shape {
            *radius *= s;
        }
        let obj = c.shape.object();
        let Some(h) = obj.intersect(&c.ray.ray(), Interval::CAMERA) else {
            continue;
        };
        tried += 1;
        // Offset the point off the surface on the side the ray came from, by a bound on the
        // point's rounding error, and leave in a random direction of that hemisphere.
        let p = h.point;
        let err = (p.abs().max_element()
            + c.shape.numbers().iter().fold(0.0f64, |m, x| m.max(x.abs())))
            * 2f64.powi(-40);
        // Leave a sphere outward (a ray leaving into a sphere meets its far side, rightly).
        let n = match c.shape {
            ShapeSpec::Sphere { center, .. } => {
                let out = h.point - DVec3::from(center);
                if out.dot(h.normal) >= 0.0 {
                    h.normal
                } else {
                    -h.normal
                }
            }
            _ => h.normal,
        };
        let origin = p + n * err * 4.0;
        let mut d = DVec3::from(r.unit());
        if d.dot(n) < 0.0 {
            d = -d;
        }
        if d.dot(n) < 1e-3 {
            continue;
        }
        let again = obj.hit_t(&Ray::new(origin, d), Interval::new(0.0, f64::MAX));
        assert!(
            again.is_none(),
            "case {i}: {c:?} re-hit at {again:?} from {origin}"
        );
    }
    assert!(tried > 5_000, "only {tried} hits");
}

fn tri(a: DVec3, b: DVec3, c: DVec3) -> Triangle {
    Triangle::new(a, b, c)
}

/// A quad split into two triangles along its diagonal is hit where the ray crosses the
/// diagonal: at least one of the triangles is hit, for rays through exact diagonal points.
#[test]
fn rays_through_a_shared_diagonal_hit_a_triangle() {
    let mut r = Stream::new(11, "watertight");
    for i in 0..20_000 {
        let s = r.log_scale(-20.0, 20.0);
        let q = DVec3::from(r.unit()) * s * r.uniform(0.0, 1e3);
        let u = DVec3::from(r.unit()) * s;
        let v = DVec3::from(r.unit()) * s;
        let (t1, t2) = (tri(q, q + u, q + u + v), tri(q, q + u + v, q + v));
        let k = r.uniform(0.01, 0.99);
        let p = q + (u + v) * k;
        let d = DVec3::from(r.unit());
        let o = p - d * s * r.uniform(0.5, 4.0);
        let ray = Ray::new(o, d);
        let n = u.cross(v).normalize();
        if n.dot(d).abs() < 1e-3 {
            continue;
        }
        let all = Interval::new(0.0, f64::MAX);
        let hit = t1.hit_t(&ray, all).is_some() || t2.hit_t(&ray, all).is_some();
        assert!(
            hit,
            "case {i}: a ray through the diagonal at {p} slipped through"
        );
    }
}

/// An octahedron subdivided to a closed triangulated sphere at (148376, 1234, -223423): rays
/// from points inside it always hit a triangle.
#[test]
fn rays_from_inside_a_closed_triangulated_sphere_always_hit() {
    let c = DVec3::new(148376.0, 1234.0, -223423.0);
    let mut tris: Vec<[DVec3; 3]> = vec![];
    let (x, y, z) = (DVec3::X, DVec3::Y, DVec3::Z);
    for sx in [-1.0, 1.0] {
        for sy in [-1.0, 1.0] {
            for sz in [-1.0, 1.0] {
                tris.push([x * sx, y * sy, z * sz]);
            }
        }
    }
    for _ in 0..4 {
        let mut next = vec![];
        for [a, b, d] in tris {
            let (ab, bd, da) = (
                (a + b).normalize(),
                (b + d).normalize(),
                (d + a).normalize(),
            );
            next.extend([[a, ab, da], [ab, b, bd], [da, bd, d], [ab, bd, da]]);
        }
        tris = next;
    }
    let mesh: Vec<Triangle> = tris
        .iter()
        .map(|[a, b, d]| tri(c + *a * 3.0, c + *b * 3.0, c + *d * 3.0))
        .collect();
    let mut r = Stream::new(3, "closed");
    for i in 0..3_000 {
        let o = c + DVec3::from(r.unit()) * r.uniform(0.0, 2.0);
        let ray = Ray::new(o, DVec3::from(r.unit()));
        let hit = mesh
            .iter()
            .any(|t| t.hit_t(&ray, Interval::new(0.0, f64::MAX)).is_some());
        assert!(hit, "ray {i} from {o} escaped the closed mesh");
    }
}
