//! The spheres of a scene made only of static spheres ([`SphereSet`]): their centres and
//! squared radii side by side, tested in one tight loop with two exact early outs, for the
//! closest hit and the course's occlusion count; and, on x86-64 with AVX2, the same two queries
//! for four rays at once ([`SphereSet::closest_lanes`], [`SphereSet::occluded_lanes`]), which
//! the renderer's lanes of paths use.
//!
//! It promises the answers of [`Scene::closest`] and [`Scene::count_hits`], bit for bit, one ray
//! at a time and lane by lane (where a lane over- or underflows, it says so). Each
//! sphere's roots are [`Sphere::roots`]'s (the same `f`, `b'`, `c` and [`roots_of`]), chosen as
//! the scene's loop chooses them. A ray for which some sphere's intermediates over- or
//! underflow, which only the scalar path's rescaling handles, is handed back (`None`). What it
//! skips, it skips only where the roots would lie outside the interval ([`sure_miss`]).
//!
//! The course's scenes from week 6 on are made of a handful of spheres; the general loop over
//! [`Object`]s pays for every shape's match and a record twice the size of a sphere's, and
//! computes a division for every sphere (the robust roots start with `b' / a`).

use glam::DVec3;

use super::{Object, Scene};
use crate::geometry::{Interval, Ray, pick_root, roots_of};

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
const PREFILTER_MARGIN: f64 = 1e-12;

/// Where the pre-filter trusts `a` and `|f|^2 + r^2`.
const PREFILTER_RANGE: std::ops::Range<f64> = 1e-100..1e100;

/// Whether a sphere whose roots [`roots_of`] would find from these parts (it checked them:
/// no over- or underflow) certainly has none inside `interval`.
///
/// - *Behind*: `b' > 0` and `c > 0` (outside the sphere, moving away) with `interval.min >= 0`.
///   Then `q = -(b' + sqrt(disc)) < 0`, so both roots, `c / q` and `q / a`, are negative or
///   `-0`: neither lies above a `min` of 0 or more. The signs are those of the very `b'` and `c`
///   the roots are computed from, so this is exact.
/// - *Aside*: the naive discriminant below the margin ([`PREFILTER_MARGIN`]).
#[inline(always)]
fn sure_miss(a: f64, half_b: f64, ff: f64, r2: f64, c: f64, interval: Interval) -> bool {
    if interval.min >= 0.0 && half_b > 0.0 && c > 0.0 {
        return true;
    }
    let scale = ff + r2;
    PREFILTER_RANGE.contains(&a)
        && PREFILTER_RANGE.contains(&scale)
        && half_b * half_b - a * c < -(a * PREFILTER_MARGIN * scale)
}

/// One sphere: its centre and squared radius.
#[derive(Clone, Copy, Debug)]
struct Ball {
    center: DVec3,
    r2: f64,
}

/// The spheres of a scene of static spheres only.
#[derive(Clone, Debug)]
pub(crate) struct SphereSet {
    balls: Vec<Ball>,
}

/// What one sphere does to a ray: no root in the interval, a root `t`, or over- or underflow.
enum Roots {
    Outside,
    At(f64),
    Unsolved,
}

impl SphereSet {
    /// The set of `scene`'s objects, or `None` when one of them is not a static sphere.
    pub(super) fn new(scene: &Scene) -> Option<Self> {
        let balls = scene
            .objects
            .iter()
            .map(|o| match o.shape {
                Object::Sphere(s) => Some(Ball {
                    center: s.center,
                    r2: s.radius * s.radius,
                }),
                _ => None,
            })
            .collect::<Option<Vec<_>>>()?;
        (!balls.is_empty()).then_some(Self { balls })
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

    /// [`Scene::closest`]'s answer, inside `Some`; `None` when the scalar path must decide.
    #[inline(always)]
    pub(super) fn closest(&self, ray: &Ray, interval: Interval) -> Option<Option<(f64, usize)>> {
        let (o, d) = (ray.origin, ray.direction);
        let a = d.dot(d);
        let mut best = None;
        let mut closest = interval.max;
        for (index, ball) in self.balls.iter().enumerate() {
            match Self::root(ball, o, d, a, Interval::new(interval.min, closest)) {
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
    pub(super) fn count_hits(&self, ray: &Ray, interval: Interval, limit: usize) -> Option<usize> {
        let (o, d) = (ray.origin, ray.direction);
        let a = d.dot(d);
        let mut count = 0;
        for ball in &self.balls {
            match Self::root(ball, o, d, a, interval) {
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

/// How many rays [`SphereSet::closest_lanes`] and [`SphereSet::occluded_lanes`] take at once:
/// four `f64` lanes, one AVX2 vector.
pub(crate) const LANES: usize = 4;

/// Up to [`LANES`] rays side by side (origins, directions, and `a = d . d`), for the lanes
/// queries. A lane that is not `active` is ignored.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct RayLanes {
    ox: [f64; LANES],
    oy: [f64; LANES],
    oz: [f64; LANES],
    dx: [f64; LANES],
    dy: [f64; LANES],
    dz: [f64; LANES],
    a: [f64; LANES],
    /// `a * PREFILTER_MARGIN`, the pre-filter's margin before the sphere's scale.
    a_margin: [f64; LANES],
    /// All ones where `a.is_normal() && a < 1e300` (`roots_of`'s check of `a`).
    a_sane: [u64; LANES],
    /// All ones where `a` lies in the pre-filter's range.
    a_in_range: [u64; LANES],
    active: [u64; LANES],
}

impl RayLanes {
    /// Puts the ray from `origin` along `direction` in lane `k`.
    #[inline(always)]
    pub(crate) fn set(&mut self, k: usize, origin: DVec3, direction: DVec3) {
        (self.ox[k], self.oy[k], self.oz[k]) = (origin.x, origin.y, origin.z);
        (self.dx[k], self.dy[k], self.dz[k]) = (direction.x, direction.y, direction.z);
        let a = direction.dot(direction);
        self.a[k] = a;
        self.a_margin[k] = a * PREFILTER_MARGIN;
        self.a_sane[k] = if a.is_normal() && a < 1e300 {
            u64::MAX
        } else {
            0
        };
        self.a_in_range[k] = if PREFILTER_RANGE.contains(&a) {
            u64::MAX
        } else {
            0
        };
        self.active[k] = u64::MAX;
    }
}

/// One ball against every lane: where each lane's ray has a root in `(min, max[k])` (the lane's
/// root in `t`, the others unchanged), and the lanes whose intermediates over- or underflow.
///
/// Lane by lane these are [`SphereSet::root`]'s operations, in its order, in one AVX2 vector:
/// the same `f`, `b'`, `c`, early outs ([`sure_miss`]), [`roots_of`] and [`pick_root`], so each
/// lane decides as the scalar loop does, bit for bit (IEEE operations round alike in a vector
/// lane; nothing is fused). Where the scalar code branches, both sides are computed and the
/// lane's is selected. A ball every lane surely misses costs no division. The tests compare it
/// with the scalar loop (`lanes_answer_as_the_scalar_loop_does`).
///
/// # Safety
///
/// The processor must have AVX2 (the caller checked [`has_lanes`]).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn ball_lanes(
    ball: &Ball,
    rays: &RayLanes,
    min: f64,
    max: &[f64; LANES],
    t: &mut [f64; LANES],
) -> (u32, u32) {
    use std::arch::x86_64::*;
    // SAFETY (every intrinsic below): AVX2 is there (this function's contract); the loads and
    // the store read and write whole `[f64; 4]` arrays.
    unsafe {
        let load = |x: &[f64; LANES]| _mm256_loadu_pd(x.as_ptr());
        let splat = |x: f64| _mm256_set1_pd(x);
        let sign = splat(-0.0);
        let (dx, dy, dz, a) = (
            load(&rays.dx),
            load(&rays.dy),
            load(&rays.dz),
            load(&rays.a),
        );
        let mask = |x: &[u64; LANES]| _mm256_castsi256_pd(_mm256_loadu_si256(x.as_ptr().cast()));
        let active = mask(&rays.active);
        let fx = _mm256_sub_pd(load(&rays.ox), splat(ball.center.x));
        let fy = _mm256_sub_pd(load(&rays.oy), splat(ball.center.y));
        let fz = _mm256_sub_pd(load(&rays.oz), splat(ball.center.z));
        let r2 = splat(ball.r2);
        let dot = |ux, uy, uz, vx, vy, vz| {
            _mm256_add_pd(
                _mm256_add_pd(_mm256_mul_pd(ux, vx), _mm256_mul_pd(uy, vy)),
                _mm256_mul_pd(uz, vz),
            )
        };
        let half_b = dot(fx, fy, fz, dx, dy, dz);
        let ff = dot(fx, fy, fz, fx, fy, fz);
        let c = _mm256_sub_pd(ff, r2);
        let finite =
            |x| _mm256_cmp_pd::<_CMP_LT_OQ>(_mm256_andnot_pd(sign, x), splat(f64::INFINITY));
        let zero = _mm256_setzero_pd();
        let solvable = if ball.r2 < 1e300 {
            _mm256_and_pd(_mm256_and_pd(mask(&rays.a_sane), finite(c)), finite(half_b))
        } else {
            zero
        };
        let behind = if min >= 0.0 {
            _mm256_and_pd(
                _mm256_cmp_pd::<_CMP_GT_OQ>(half_b, zero),
                _mm256_cmp_pd::<_CMP_GT_OQ>(c, zero),
            )
        } else {
            zero
        };
        let scale = _mm256_add_pd(ff, r2);
        let in_range = |x| {
            _mm256_and_pd(
                _mm256_cmp_pd::<_CMP_GE_OQ>(x, splat(PREFILTER_RANGE.start)),
                _mm256_cmp_pd::<_CMP_LT_OQ>(x, splat(PREFILTER_RANGE.end)),
            )
        };
        let naive = _mm256_sub_pd(_mm256_mul_pd(half_b, half_b), _mm256_mul_pd(a, c));
        let margin = _mm256_xor_pd(_mm256_mul_pd(load(&rays.a_margin), scale), sign);
        let aside = _mm256_and_pd(
            _mm256_and_pd(mask(&rays.a_in_range), in_range(scale)),
            _mm256_cmp_pd::<_CMP_LT_OQ>(naive, margin),
        );
        let sure = _mm256_and_pd(solvable, _mm256_or_pd(behind, aside));
        let open = _mm256_andnot_pd(sure, active);
        let mut unsolved = _mm256_andnot_pd(solvable, active);
        if _mm256_movemask_pd(open) == 0 {
            return (0, _mm256_movemask_pd(unsolved) as u32);
        }
        // `roots_of`, lane by lane.
        let s = _mm256_div_pd(half_b, a);
        let px = _mm256_sub_pd(fx, _mm256_mul_pd(dx, s));
        let py = _mm256_sub_pd(fy, _mm256_mul_pd(dy, s));
        let pz = _mm256_sub_pd(fz, _mm256_mul_pd(dz, s));
        let disc = _mm256_mul_pd(a, _mm256_sub_pd(r2, dot(px, py, pz, px, py, pz)));
        let disc_finite = finite(disc);
        unsolved = _mm256_or_pd(unsolved, _mm256_andnot_pd(disc_finite, open));
        let root = _mm256_sqrt_pd(disc);
        // `sqrt(disc).copysign(half_b)`, then negated.
        let signed = _mm256_or_pd(_mm256_andnot_pd(sign, root), _mm256_and_pd(sign, half_b));
        let q = _mm256_xor_pd(_mm256_add_pd(half_b, signed), sign);
        let t0 = _mm256_div_pd(c, q);
        let t1 = _mm256_div_pd(q, a);
        // `-b' / a`: a negated quotient rounds to the same magnitude, so this is `-(b' / a)`.
        let double = _mm256_xor_pd(s, sign);
        let ordered = _mm256_cmp_pd::<_CMP_LE_OQ>(t0, t1);
        let near = _mm256_blendv_pd(t1, t0, ordered);
        let far = _mm256_blendv_pd(t0, t1, ordered);
        let tangent = _mm256_cmp_pd::<_CMP_EQ_OQ>(q, zero);
        let near = _mm256_blendv_pd(near, double, tangent);
        let far = _mm256_blendv_pd(far, double, tangent);
        // `pick_root` against `(min, max[k])`.
        let (lo, hi) = (splat(min), load(max));
        let surrounds = |x| {
            _mm256_and_pd(
                _mm256_cmp_pd::<_CMP_LT_OQ>(lo, x),
                _mm256_cmp_pd::<_CMP_LT_OQ>(x, hi),
            )
        };
        let (near_in, far_in) = (surrounds(near), surrounds(far));
        let found = _mm256_and_pd(
            _mm256_and_pd(open, disc_finite),
            _mm256_and_pd(
                _mm256_cmp_pd::<_CMP_GE_OQ>(disc, zero),
                _mm256_or_pd(near_in, far_in),
            ),
        );
        let chosen = _mm256_blendv_pd(far, near, near_in);
        let kept = _mm256_blendv_pd(load(t), chosen, found);
        _mm256_storeu_pd(t.as_mut_ptr(), kept);
        (
            _mm256_movemask_pd(found) as u32,
            _mm256_movemask_pd(unsolved) as u32,
        )
    }
}

/// Whether this processor runs the lanes queries ([`SphereSet::closest_lanes`],
/// [`SphereSet::occluded_lanes`]): an x86-64 with AVX2. Elsewhere the renderer traces one ray at
/// a time, to the same film.
#[inline]
pub(crate) fn has_lanes() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

#[cfg(target_arch = "x86_64")]
impl SphereSet {
    /// [`SphereSet::closest`] for each active lane of `rays` at once (an AVX2 vector of four
    /// rays where the caller is compiled for it): lane `k`'s closest hit in `interval`, or
    /// `Err(())` where the lane's ray must be decided by the scalar path (over- or underflow).
    /// Inactive lanes answer `Ok(None)`.
    ///
    /// # Safety
    ///
    /// The processor must have AVX2 ([`has_lanes`]).
    #[target_feature(enable = "avx2")]
    #[inline]
    pub(crate) unsafe fn closest_lanes(
        &self,
        rays: &RayLanes,
        interval: Interval,
    ) -> [Result<Option<(f64, usize)>, ()>; LANES] {
        let mut closest = [interval.max; LANES];
        let mut index = [usize::MAX; LANES];
        let mut unsolved = 0;
        for (me, ball) in self.balls.iter().enumerate() {
            let max = closest;
            // SAFETY: AVX2 is there (this function's contract).
            let (hit, bad) = unsafe { ball_lanes(ball, rays, interval.min, &max, &mut closest) };
            for (k, index) in index.iter_mut().enumerate() {
                if hit & (1 << k) != 0 {
                    *index = me;
                }
            }
            unsolved |= bad;
        }
        let mut answers = [Ok(None); LANES];
        for (k, answer) in answers.iter_mut().enumerate() {
            if unsolved & (1 << k) != 0 {
                *answer = Err(());
            } else if index[k] != usize::MAX {
                *answer = Ok(Some((closest[k], index[k])));
            }
        }
        answers
    }

    /// The course's occlusion test ([`SphereSet::count_hits`] on `(min, max[k])`, limit 2, more
    /// than one hit) for each active lane of `rays` at once: `Ok(occluded)`, or `Err(())` where
    /// the lane's ray must be decided by the scalar path. Inactive lanes answer `Ok(false)`.
    ///
    /// # Safety
    ///
    /// The processor must have AVX2 ([`has_lanes`]).
    #[target_feature(enable = "avx2")]
    #[inline]
    pub(crate) unsafe fn occluded_lanes(
        &self,
        rays: &RayLanes,
        min: f64,
        max: &[f64; LANES],
    ) -> [Result<bool, ()>; LANES] {
        let mut count = [0u32; LANES];
        let mut unsolved = 0;
        let mut t = [0.0; LANES];
        for ball in &self.balls {
            // SAFETY: AVX2 is there (this function's contract).
            let (hit, bad) = unsafe { ball_lanes(ball, rays, min, max, &mut t) };
            for (k, count) in count.iter_mut().enumerate() {
                *count += (hit >> k) & 1;
            }
            unsolved |= bad;
        }
        let mut answers = [Ok(false); LANES];
        for (k, answer) in answers.iter_mut().enumerate() {
            *answer = if unsolved & (1 << k) != 0 {
                Err(())
            } else {
                Ok(count[k] > 1)
            };
        }
        answers
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Sphere;
    use crate::render::PixelSampler;
    use crate::scene::SceneObject;

    /// A scene of `n` random spheres (some hollow, some tiny, some huge, some overlapping).
    fn random_scene(s: &mut PixelSampler, n: usize) -> Scene {
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
                SceneObject {
                    shape: Object::Sphere(Sphere::new(c, r)),
                    material: 0,
                }
            })
            .collect();
        Scene {
            objects,
            materials: vec![],
        }
    }

    /// A ray started on a sphere's surface (as a bounce is), or aimed at a silhouette within
    /// 1e-9 of its radius (where the naive and robust discriminants are nearly zero and the
    /// pre-filter's margin is what keeps it right), or from anywhere; of any length from 1e-3
    /// to 1e3.
    fn random_ray(s: &mut PixelSampler, scene: &Scene) -> Ray {
        let k = (s.next_f64() * scene.objects.len() as f64) as usize;
        let Object::Sphere(sphere) = scene.objects[k].shape else {
            unreachable!("spheres only")
        };
        let length = 10f64.powf(s.uniform(-3.0, 3.0));
        match (s.next_f64() * 3.0) as u32 {
            0 => {
                let origin = sphere.center + sphere.radius.abs() * s.unit_vector();
                Ray::new(origin, s.unit_vector() * length)
            }
            1 => {
                let origin = 4.0 * s.unit_vector();
                let to = sphere.center - origin;
                let side = to.cross(s.unit_vector()).normalize() * sphere.radius.abs();
                let graze = 1.0 + 1e-9 * s.uniform(-1.0, 1.0);
                Ray::new(origin, (to + side * graze) * length)
            }
            _ => Ray::new(3.0 * s.unit_vector(), s.unit_vector() * length),
        }
    }

    /// On 300 random scenes of 1 to 12 spheres, 2000 rays each, under the camera's interval, a
    /// shadow ray's and the book's: the same closest object and `t` bits as the scene's loop,
    /// and the same capped count as its count.
    #[test]
    fn answers_as_the_scene_loop_does() {
        let mut s = PixelSampler::new(11, 5);
        let mut compared = 0;
        for scene_number in 0..300 {
            let scene = random_scene(&mut s, 1 + scene_number % 12);
            let set = SphereSet::new(&scene).expect("spheres only");
            for _ in 0..2000 {
                let ray = random_ray(&mut s, &scene);
                let reach = ray.direction.length() * s.uniform(0.1, 3.0);
                for interval in [
                    Interval::CAMERA,
                    Interval::new(1e-6, reach),
                    Interval::new(0.001, f64::INFINITY),
                ] {
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
        assert_eq!(compared, 300 * 2000 * 3);
    }

    /// A ray whose intermediates overflow is handed back to the scalar path; a plain ray is
    /// answered; a scene with anything but static spheres, or with nothing, has no set.
    #[test]
    fn hands_back_what_only_the_scalar_path_solves() {
        let scene = Scene {
            objects: vec![SceneObject {
                shape: Object::Sphere(Sphere::new(DVec3::ZERO, 1.0)),
                material: 0,
            }],
            materials: vec![],
        };
        let set = SphereSet::new(&scene).unwrap();
        let huge = Ray::new(DVec3::new(-1e300, 0.0, 0.0), DVec3::new(1e300, 0.0, 0.0));
        assert!(set.closest(&huge, Interval::CAMERA).is_none());
        assert!(set.count_hits(&huge, Interval::CAMERA, 2).is_none());
        let plain = Ray::new(DVec3::new(-3.0, 0.0, 0.0), DVec3::X);
        assert_eq!(set.closest(&plain, Interval::CAMERA), Some(Some((2.0, 0))));
        assert_eq!(set.count_hits(&plain, Interval::CAMERA, 2), Some(1));
        let mut mixed = scene.clone();
        mixed.objects.push(SceneObject {
            shape: Object::Quad(crate::geometry::Quad::new(DVec3::ZERO, DVec3::X, DVec3::Y)),
            material: 0,
        });
        assert!(SphereSet::new(&mixed).is_none());
        assert!(SphereSet::new(&Scene::default()).is_none());
    }
}
