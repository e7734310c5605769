//! The objects of a small scene of spheres, moving spheres and quads ([`ShapeSet`]), side by
//! side: each sphere's centre and squared radius, each moving sphere's travel, each quad's
//! plane, tested in one tight loop (spheres with two exact early outs) for the closest hit and
//! the course's occlusion count. On x86-64 with AVX2, `scene::accel::shape_lanes` answers the same two
//! queries for four rays at once, which the renderer's lanes of paths use.
//!
//! It promises the answers of [`Scene::closest`] and [`Scene::count_hits`], bit for bit. Each
//! sphere's roots are [`Sphere::roots`]'s (the same `f`, `b'`, `c` and [`roots_of`]), chosen as
//! the scene's loop chooses them; a moving sphere is first moved to the ray's time as
//! [`MovingSphere::at`] moves it; a quad is [`Quad::hit_t`] itself. A ray for which some
//! sphere's intermediates over- or underflow, which only the scalar path's rescaling handles, is
//! handed back (`None`). What it skips, it skips only where the roots would lie outside the
//! interval ([`sure_miss`]).
//!
//! The course's scenes are made of a handful of spheres and quads; the general
//! loop over [`Object`]s pays for every shape's match and a record twice the size of a
//! sphere's, and computes a division for every sphere (the robust roots start with `b' / a`).
//!
//! [`Sphere::roots`]: crate::geometry::Sphere::roots
//! [`MovingSphere::at`]: crate::geometry::MovingSphere::at
//! [`Quad::hit_t`]: crate::geometry::Shape::hit_t

use glam::DVec3;

use crate::geometry::{Interval, Quad, Ray, Shape, pick_root, roots_of};
use crate::scene::{Object, Scene};

/// The pre-filter's margin, relative to `a (f . f + r2)`.
///
/// Before the robust roots (which cost a division, and a square root on a hit) the naive
/// discriminant `b'^2 - a c` is evaluated and the sphere is skipped when it is below
/// `-PREFILTER_MARGIN a (f . f + r2)`. Both discriminants estimate the same exact value
/// `a r^2 - (a |f|^2 - b'^2)`, the naive one within about `15 eps a (|f|^2 + r^2)` and the robust
/// one within about `20 eps a (|f|^2 + r^2)` (`eps = 2^-53`; each term is bounded by
/// `a (|f|^2 + r^2)` since `b'^2 <= a |f|^2`). So a naive value below `-1e-12 a (|f|^2 + r^2)`, some
/// 4500 `eps` away, means the robust discriminant is negative too: the sphere is missed either
/// way. Any NaN or infinity makes the comparison false; so does `a` or `|f|^2 + r^2` outside
/// `[1e-100, 1e100)`, where underflow could make the relative bounds wrong. (The renderer's
/// fixed-origin fast path uses the same margin and the same argument.)
pub(in crate::scene) const PREFILTER_MARGIN: f64 = 1e-12;

/// Where the pre-filter trusts `a` and `|f|^2 + r^2`.
pub(in crate::scene) const PREFILTER_RANGE: std::ops::Range<f64> = 1e-100..1e100;

/// The *leaving* early out's bound on `-c / b'` (see [`sure_miss`]).
pub(in crate::scene) const LEAVING_SLOPE: f64 = 1e-7;

/// The least `interval.min` for which the *leaving* early out holds: ten times
/// [`LEAVING_SLOPE`], well above the root it rules out.
pub(in crate::scene) const LEAVING_MIN: f64 = 1e-6;

/// Whether a sphere whose roots [`roots_of`] would find from these parts (it checked them:
/// no over- or underflow) certainly has none inside `interval`.
///
/// - *Behind*: `b' > 0` and `c > 0` (outside the sphere, moving away) with `interval.min >= 0`.
///   Then `q = -(b' + sqrt(disc)) < 0`, so both roots, `c / q` and `q / a`, are negative or
///   `-0`: neither lies above a `min` of 0 or more. The signs are those of the very `b'` and `c`
///   the roots are computed from, so this is exact.
/// - *Leaving*: `b' > 0` and `-LEAVING_SLOPE b' <= c <= 0` (a ray starting on the sphere, or
///   a rounding error inside it, and moving outwards: every ray scattered from a sphere's
///   outside, and every shadow ray from its lit side, meets its own sphere so), with
///   `interval.min >= LEAVING_MIN` and `a` and `f . f + r^2` in [`PREFILTER_RANGE`]. In that range
///   `disc = a (r^2 - |p|^2)` is finite (`|p| <= 2 |f|`), so `roots_of` computes both roots: with
///   `sqrt(disc) >= 0`, `|q| = b' + sqrt(disc) >= b'` after rounding, so `t1 = q / a < 0` and
///   `|t0| = |c| / |q| <= |c| / b' <= LEAVING_SLOPE` (rounding is monotone, and the bound
///   `LEAVING_SLOPE b'` is rounded once), well below `min`: no root lies in the interval. Exact
///   in the same sense as *behind*: it reasons on the very `b'` and `c` the roots come from.
/// - *Aside*: the naive discriminant below the margin ([`PREFILTER_MARGIN`]).
#[inline(always)]
fn sure_miss(a: f64, half_b: f64, ff: f64, r2: f64, c: f64, interval: Interval) -> bool {
    if interval.min >= 0.0 && half_b > 0.0 && c > 0.0 {
        return true;
    }
    let scale = ff + r2;
    let in_range = PREFILTER_RANGE.contains(&a) && PREFILTER_RANGE.contains(&scale);
    if in_range && interval.min >= LEAVING_MIN && half_b > 0.0 && c >= -(LEAVING_SLOPE * half_b) {
        return true;
    }
    in_range && half_b * half_b - a * c < -(a * PREFILTER_MARGIN * scale)
}

/// One sphere: its centre and squared radius.
#[derive(Clone, Copy, Debug)]
pub(in crate::scene) struct Ball {
    pub(in crate::scene) center: DVec3,
    pub(in crate::scene) r2: f64,
}

/// One object of the set, as the queries test it.
#[derive(Clone, Copy, Debug)]
pub(in crate::scene) enum Member {
    /// A static sphere.
    Ball(Ball),
    /// A moving sphere: the ball at time 0 and its `travel = end - center`, so that at time
    /// `s` its centre is `center + travel s` (the same bits as [`MovingSphere::at`]'s
    /// `center + (end - center) s`).
    ///
    /// [`MovingSphere::at`]: crate::geometry::MovingSphere::at
    Moving { ball: Ball, travel: DVec3 },
    /// A quad, tested by its own [`Quad::solve_from`].
    Quad(Quad),
}

/// The objects of a scene of spheres, moving spheres and quads, in the scene's order (which
/// decides ties).
#[derive(Clone, Debug)]
pub(crate) struct ShapeSet {
    pub(in crate::scene) members: Vec<Member>,
}

/// What one object does to a ray: no root in the interval, a root `t`, or over- or underflow.
enum Roots {
    Outside,
    At(f64),
    Unsolved,
}

impl ShapeSet {
    /// The set of `scene`'s objects, or `None` when one of them is not a sphere, a moving
    /// sphere or a quad, or there is none.
    pub(in crate::scene) fn new(scene: &Scene) -> Option<Self> {
        let ball = |s: crate::geometry::Sphere| Ball {
            center: s.center,
            r2: s.radius * s.radius,
        };
        let members = scene
            .objects
            .iter()
            .map(|o| match o.shape {
                Object::Sphere(s) => Some(Member::Ball(ball(s))),
                Object::MovingSphere(m) => Some(Member::Moving {
                    ball: ball(m.sphere),
                    travel: m.end - m.sphere.center,
                }),
                Object::Quad(q) => Some(Member::Quad(q)),
                Object::Triangle(_) => None,
            })
            .collect::<Option<Vec<_>>>()?;
        (!members.is_empty()).then_some(Self { members })
    }

    /// The static spheres (among the first 64 objects) centred exactly at `point`, bit `i`
    /// for object `i`: the lanes' occlusion test decides them for rays aimed at `point`
    /// without their roots (`ShapeSet::shadowed_lanes`).
    pub(crate) fn centred_at(&self, point: DVec3) -> u64 {
        let bits = |v: DVec3| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()];
        self.members
            .iter()
            .take(64)
            .enumerate()
            .filter(|(_, m)| matches!(m, Member::Ball(b) if bits(b.center) == bits(point)))
            .fold(0, |mask, (i, _)| mask | 1 << i)
    }

    /// Whether an object moves (its rays' times matter).
    #[cfg(test)]
    pub(in crate::scene) fn moves(&self) -> bool {
        self.members
            .iter()
            .any(|m| matches!(m, Member::Moving { .. }))
    }

    /// Ball `ball`'s root within `interval` along `o + t d` (`a = d . d`), as the scene's
    /// `Sphere::hit_t`.
    #[inline(always)]
    fn root(ball: &Ball, o: DVec3, d: DVec3, a: f64, interval: Interval) -> Roots {
        let f = o - ball.center;
        let (half_b, ff) = (f.dot(d), f.dot(f));
        let c = ff - ball.r2;
        // `roots_of`'s own check of its inputs, so that the early outs judge the parts it uses.
        let solvable =
            a.is_normal() && a < 1e300 && c.is_finite() && ball.r2 < 1e300 && half_b.is_finite();
        if solvable && sure_miss(a, half_b, ff, ball.r2, c, interval) {
            return Roots::Outside;
        }
        match roots_of(f, d, a, half_b, ball.r2, c) {
            Ok(roots) => match roots.and_then(|r| pick_root(r, interval)) {
                Some(t) => Roots::At(t),
                None => Roots::Outside,
            },
            Err(()) => Roots::Unsolved,
        }
    }

    /// Member `member`'s answer for `ray` (`a = d . d`) within `interval`, as the scene's
    /// `hit_t` of that object.
    #[inline(always)]
    fn member_root(member: &Member, ray: &Ray, a: f64, interval: Interval) -> Roots {
        let (o, d) = (ray.origin, ray.direction);
        match member {
            Member::Ball(ball) => Self::root(ball, o, d, a, interval),
            Member::Moving { ball, travel } => {
                let moved = Ball {
                    center: ball.center + *travel * ray.time,
                    r2: ball.r2,
                };
                Self::root(&moved, o, d, a, interval)
            }
            Member::Quad(quad) => match quad.hit_t(ray, interval) {
                Some(t) => Roots::At(t),
                None => Roots::Outside,
            },
        }
    }

    /// [`Scene::closest`]'s answer, inside `Some`; `None` when the scalar path must decide.
    #[inline(always)]
    pub(in crate::scene) fn closest(
        &self,
        ray: &Ray,
        interval: Interval,
    ) -> Option<Option<(f64, usize)>> {
        let a = ray.direction.dot(ray.direction);
        let mut best = None;
        let mut closest = interval.max;
        for (index, member) in self.members.iter().enumerate() {
            match Self::member_root(member, ray, a, Interval::new(interval.min, closest)) {
                Roots::Outside => {}
                Roots::At(t) => {
                    closest = t;
                    best = Some((t, index));
                }
                Roots::Unsolved => return None,
            }
        }
        Some(best)
    }

    /// [`Scene::count_hits`]'s answer; `None` when the scalar path must decide.
    #[inline(always)]
    pub(in crate::scene) fn count_hits(
        &self,
        ray: &Ray,
        interval: Interval,
        limit: usize,
    ) -> Option<usize> {
        let a = ray.direction.dot(ray.direction);
        let mut count = 0;
        for member in &self.members {
            match Self::member_root(member, ray, a, interval) {
                Roots::Outside => {}
                Roots::At(_) => {
                    count += 1;
                    if count >= limit {
                        break;
                    }
                }
                Roots::Unsolved => return None,
            }
        }
        Some(count)
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::geometry::{MovingSphere, Sphere};
    use crate::render::PixelSampler;
    use crate::scene::SceneObject;

    /// A random quad near the origin, of edges from 1e-2 to 6 long, some of them a floor, a
    /// wall or a light's square aligned with the axes (where rays along the axes meet edges and
    /// corners exactly).
    fn random_quad(s: &mut PixelSampler) -> Quad {
        let q = DVec3::new(
            s.uniform(-3.0, 3.0),
            s.uniform(-3.0, 3.0),
            s.uniform(-3.0, 3.0),
        );
        if s.next_f64() < 0.5 {
            let (a, b) = (s.uniform(0.5, 6.0).round(), s.uniform(0.5, 6.0).round());
            let q = q.round();
            return match (s.next_f64() * 3.0) as u32 {
                0 => Quad::new(q, DVec3::X * a, DVec3::Z * b),
                1 => Quad::new(q, DVec3::Y * a, DVec3::X * b),
                _ => Quad::new(q, DVec3::Z * a, DVec3::Y * b),
            };
        }
        let edge = |s: &mut PixelSampler| s.unit_vector() * 10f64.powf(s.uniform(-2.0, 0.8));
        Quad::new(q, edge(s), edge(s))
    }

    /// A scene of `n` random objects: spheres (some hollow, some tiny, some huge, some
    /// overlapping), and when `mixed`, moving spheres and quads too.
    pub(crate) fn random_scene(s: &mut PixelSampler, n: usize, mixed: bool) -> Scene {
        let objects = (0..n)
            .map(|_| {
                let c = DVec3::new(
                    s.uniform(-3.0, 3.0),
                    s.uniform(-3.0, 3.0),
                    s.uniform(-3.0, 3.0),
                );
                let r = match (s.next_f64() * 4.0) as u32 {
                    0 => s.uniform(-1.0, -0.01),
                    1 => s.uniform(1e-4, 1e-2),
                    2 => s.uniform(50.0, 200.0),
                    _ => s.uniform(0.1, 1.5),
                };
                let kind = if mixed { s.next_f64() } else { 0.0 };
                let shape = if kind < 0.4 {
                    Object::Sphere(Sphere::new(c, r))
                } else if kind < 0.6 {
                    let end = c + s.unit_vector() * s.uniform(0.0, 1.0);
                    Object::MovingSphere(MovingSphere::new(Sphere::new(c, r), end))
                } else {
                    Object::Quad(random_quad(s))
                };
                SceneObject { shape, material: 0 }
            })
            .collect();
        Scene {
            objects,
            materials: vec![],
        }
    }

    /// A point on object `k` of `scene` at time `time` (on a quad, often on its edge or corner),
    /// and a length for the sphere's silhouette rays (its radius; a quad's size).
    fn point_on(s: &mut PixelSampler, scene: &Scene, k: usize, time: f64) -> (DVec3, f64) {
        match scene.objects[k].shape {
            Object::Sphere(sphere) => (
                sphere.center + sphere.radius.abs() * s.unit_vector(),
                sphere.radius.abs(),
            ),
            Object::MovingSphere(m) => {
                let sphere = m.at(time);
                (
                    sphere.center + sphere.radius.abs() * s.unit_vector(),
                    sphere.radius.abs(),
                )
            }
            Object::Quad(quad) => {
                let corner = |s: &mut PixelSampler| match (s.next_f64() * 4.0) as u32 {
                    0 => 0.0,
                    1 => 1.0,
                    _ => s.next_f64(),
                };
                let (alpha, beta) = (corner(s), corner(s));
                (quad.q + quad.u * alpha + quad.v * beta, quad.u.length())
            }
            Object::Triangle(_) => unreachable!("no triangles here"),
        }
    }

    /// A ray started on an object (as a bounce is), or aimed at a sphere's silhouette within
    /// 1e-9 of its radius (where the naive and robust discriminants are nearly zero and the
    /// pre-filter's margin is what keeps it right) or at a point of a quad (its edges and
    /// corners), or along an axis, or from anywhere; of any length from 1e-3 to 1e3, at a time
    /// in `[0, 1]`.
    pub(crate) fn random_ray(s: &mut PixelSampler, scene: &Scene) -> Ray {
        let k = (s.next_f64() * scene.objects.len() as f64) as usize;
        let time = s.next_f64();
        let (point, size) = point_on(s, scene, k, time);
        let length = 10f64.powf(s.uniform(-3.0, 3.0));
        let direction = match (s.next_f64() * 5.0) as u32 {
            0 => return Ray::at_time(point, s.unit_vector() * length, time),
            1 => {
                let origin = 4.0 * s.unit_vector();
                let to = point - origin;
                let side = to.cross(s.unit_vector()).normalize() * size;
                let graze = 1.0 + 1e-9 * s.uniform(-1.0, 1.0);
                return Ray::at_time(origin, (to + side * graze) * length, time);
            }
            2 => {
                let origin = (4.0 * s.unit_vector()).round();
                if origin != point {
                    return Ray::at_time(origin, (point - origin) * length, time);
                }
                s.unit_vector()
            }
            3 => [
                DVec3::X,
                DVec3::Y,
                DVec3::Z,
                -DVec3::X,
                -DVec3::Y,
                -DVec3::Z,
            ][(s.next_f64() * 6.0) as usize],
            _ => s.unit_vector(),
        };
        Ray::at_time((3.0 * s.unit_vector()).round(), direction * length, time)
    }

    /// The intervals a render asks about for `ray`: the camera's, a shadow ray's and the book's.
    pub(crate) fn intervals(s: &mut PixelSampler, ray: &Ray) -> [Interval; 3] {
        let reach = ray.direction.length() * s.uniform(0.1, 3.0);
        [
            Interval::CAMERA,
            Interval::new(1e-6, reach),
            Interval::new(0.001, f64::INFINITY),
        ]
    }

    /// On 300 random scenes of 1 to 12 spheres, then 300 of spheres, moving spheres and quads,
    /// 1000 rays each under the camera's interval, a shadow ray's and the book's: the same
    /// closest object and `t` bits as the scene's loop, and the same capped count as its count.
    #[test]
    fn answers_as_the_scene_loop_does() {
        let mut s = PixelSampler::new(11, 5);
        let mut compared = 0;
        for scene_number in 0..600 {
            let scene = random_scene(&mut s, 1 + scene_number % 12, scene_number >= 300);
            let set = ShapeSet::new(&scene).expect("spheres and quads only");
            for _ in 0..1000 {
                let ray = random_ray(&mut s, &scene);
                for interval in intervals(&mut s, &ray) {
                    let fast = set.closest(&ray, interval).expect("no overflow here");
                    let slow = scene.closest(&ray, interval);
                    assert_eq!(
                        fast.map(|(t, k)| (t.to_bits(), k)),
                        slow.map(|(t, k)| (t.to_bits(), k)),
                        "{ray:?} {interval:?}"
                    );
                    for limit in [0, 1, 2, 5] {
                        let count = scene.count_hits(&ray, interval, limit);
                        assert_eq!(set.count_hits(&ray, interval, limit), Some(count));
                    }
                    compared += 1;
                }
            }
        }
        assert_eq!(compared, 600 * 1000 * 3);
    }

    /// A ray whose intermediates overflow is handed back to the scalar path; a plain ray is
    /// answered, by a sphere, a quad and a moving sphere at its time; a scene with a triangle,
    /// or with nothing, has no set.
    #[test]
    fn hands_back_what_only_the_scalar_path_solves() {
        let ball = SceneObject {
            shape: Object::Sphere(Sphere::new(DVec3::ZERO, 1.0)),
            material: 0,
        };
        let scene = Scene {
            objects: vec![ball],
            materials: vec![],
        };
        let set = ShapeSet::new(&scene).unwrap();
        let huge = Ray::new(DVec3::new(-1e300, 0.0, 0.0), DVec3::new(1e300, 0.0, 0.0));
        assert!(set.closest(&huge, Interval::CAMERA).is_none());
        assert!(set.count_hits(&huge, Interval::CAMERA, 2).is_none());
        let plain = Ray::new(DVec3::new(-3.0, 0.0, 0.0), DVec3::X);
        assert_eq!(set.closest(&plain, Interval::CAMERA), Some(Some((2.0, 0))));
        assert_eq!(set.count_hits(&plain, Interval::CAMERA, 2), Some(1));
        // A wall at x = -2.5 in front of the ball, and a ball moving from x = -10 to x = 10:
        // at time 0.25 it is centred at x = -5, so the ray from x = -3 meets nothing of it.
        let mut more = scene.clone();
        more.objects.push(SceneObject {
            shape: Object::Quad(Quad::new(
                DVec3::new(-2.5, -1.0, -1.0),
                DVec3::Y * 2.0,
                DVec3::Z * 2.0,
            )),
            material: 0,
        });
        more.objects.push(SceneObject {
            shape: Object::MovingSphere(MovingSphere::new(
                Sphere::new(DVec3::new(-10.0, 0.0, 0.0), 0.5),
                DVec3::new(10.0, 0.0, 0.0),
            )),
            material: 0,
        });
        let set = ShapeSet::new(&more).unwrap();
        assert!(set.moves());
        assert_eq!(set.closest(&plain, Interval::CAMERA), Some(Some((0.5, 1))));
        let at = |time| Ray::at_time(plain.origin, plain.direction, time);
        // At time 0.5 the moving ball is centred at 0, inside the first: its near root is 2.5.
        assert_eq!(set.count_hits(&at(0.5), Interval::CAMERA, 5), Some(3));
        assert_eq!(set.count_hits(&at(0.25), Interval::CAMERA, 5), Some(2));
        let mut triangle = scene.clone();
        triangle.objects.push(SceneObject {
            shape: Object::Triangle(crate::geometry::Triangle::new(
                DVec3::ZERO,
                DVec3::X,
                DVec3::Y,
            )),
            material: 0,
        });
        assert!(ShapeSet::new(&triangle).is_none());
        assert!(ShapeSet::new(&Scene::default()).is_none());
    }

    /// Rays leaving a sphere from its surface (a hit point, or a point put on it) or from just
    /// inside it (`|c|` from 1e-15 to 1e-5 of `r^2`, across the *leaving* bound), outwards, at
    /// radii and lengths from 1e-3 to 1e3: wherever `sure_miss` calls the sphere a miss under
    /// `(1e-6, MAX)` or `(0.001, inf)`, the robust roots have none there; and it calls most of
    /// the rays from the surface misses (those the *behind* test alone left to the roots too).
    #[test]
    fn a_ray_leaving_a_sphere_is_a_sure_miss_only_where_no_root_is_in_the_interval() {
        let mut s = PixelSampler::new(41, 2);
        let (mut leaving, mut asked) = (0, 0);
        for round in 0..200_000 {
            let radius = 10f64.powf(s.uniform(-3.0, 3.0));
            let center = DVec3::new(s.uniform(-5.0, 5.0), s.uniform(-5.0, 5.0), 0.0) * radius;
            let u = s.unit_vector();
            let origin = match round % 3 {
                // A hit point: the camera ray's `at(t)`, as the renderer computes it.
                0 => {
                    let from = center + u * radius * s.uniform(2.0, 10.0);
                    let ray = Ray::new(from, (center - from) * s.uniform(0.01, 100.0));
                    match Sphere::new(center, radius).hit_t(&ray, Interval::CAMERA) {
                        Some(t) => ray.at(t),
                        None => continue,
                    }
                }
                1 => center + u * radius,
                _ => center + u * (radius * (1.0 - 10f64.powf(s.uniform(-15.0, -5.0)))),
            };
            // Outwards: any direction on the normal's side.
            let mut d = s.unit_vector();
            if d.dot(origin - center) < 0.0 {
                d = -d;
            }
            let d = d * 10f64.powf(s.uniform(-3.0, 3.0));
            let f = origin - center;
            let (a, half_b, ff, r2) = (d.dot(d), f.dot(d), f.dot(f), radius * radius);
            let c = ff - r2;
            for interval in [Interval::CAMERA, Interval::new(0.001, f64::INFINITY)] {
                asked += 1;
                if !(half_b > 0.0 && c <= 0.0 && sure_miss(a, half_b, ff, r2, c, interval)) {
                    continue;
                }
                leaving += 1;
                let roots = roots_of(f, d, a, half_b, r2, c).expect("in range");
                assert_eq!(
                    roots.and_then(|r| pick_root(r, interval)),
                    None,
                    "{origin} {d}"
                );
            }
        }
        assert!(leaving * 4 > asked, "{leaving} of {asked}");
    }

    /// `centred_at` marks exactly the static spheres whose centre has the point's bits (not
    /// `-0` for `0`, not a moving sphere or a quad), among the first 64 objects.
    #[test]
    fn centred_at_marks_the_spheres_with_that_centre_bit_for_bit() {
        let c = DVec3::new(0.0, 1.0, -2.0);
        let ball = |center, r| SceneObject {
            shape: Object::Sphere(Sphere::new(center, r)),
            material: 0,
        };
        let mut objects = vec![
            ball(c, 0.1),
            ball(DVec3::new(-0.0, 1.0, -2.0), 0.1),
            ball(c + DVec3::X * 1e-15, 0.1),
            SceneObject {
                shape: Object::MovingSphere(MovingSphere::new(Sphere::new(c, 0.1), c)),
                material: 0,
            },
            ball(c, -0.5),
        ];
        objects.extend((0..70).map(|_| ball(DVec3::ZERO, 1.0)));
        objects.push(ball(c, 0.2));
        let set = ShapeSet::new(&Scene {
            objects,
            materials: vec![],
        })
        .unwrap();
        assert_eq!(set.centred_at(c), 0b10001);
        assert_eq!(set.centred_at(DVec3::ZERO), !0 << 5);
        assert_eq!(set.centred_at(DVec3::new(9.0, 9.0, 9.0)), 0);
    }
}
