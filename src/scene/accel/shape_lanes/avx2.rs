//! The two queries of a [`ShapeSet`] (the closest hit, the course's occlusion test) for four
//! rays at once, on x86-64 with AVX2 ([`ShapeSet::closest_lanes`], and
//! [`ShapeSet::shadowed_lanes`] for shadow rays to a point light): the renderer's lanes of
//! paths ask them. The whole file is x86-64 only (its parent declares it so, once).
//!
//! It promises, lane by lane, the scalar set's answers, so [`Scene::closest`]'s and
//! [`Scene::count_hits`]'s, bit for bit; where a lane's sphere arithmetic over- or underflows, it
//! says so and the scalar path decides. Each object's test is the scalar test's operations, in
//! its order, in one AVX2 vector (IEEE operations round alike in a vector lane; nothing is
//! fused); where the scalar code branches, both sides are computed and the lane's is selected.
//! Objects are taken in the scene's order, so ties go as the scene's loop sends them (a quad's
//! closed test replaces an earlier object at the same `t`, a sphere's open one does not).
//!
//! Work is skipped only where its answer is known without it, as the scalar set skips it (a
//! sphere behind the ray, beside it, or left by a ray starting on its surface: `sure_miss` in
//! `scene::accel::shape_set`), and, for shadow rays, the light's own sphere, which a ray aimed at its
//! centre from far enough surely hits (`aimed_ball_lanes`, with the exact arithmetic that
//! proves it); the occlusion test tests that sphere first and stops once every lane has met two
//! objects, as the scalar count stops at its limit.
//!
//! The per-object tests are `#[inline(always)]` unsafe functions without a target feature of
//! their own, so that they are compiled inside the two queries, which are compiled for AVX2:
//! as separate functions (one call per object and ray packet, the vectors passed through
//! memory) they took week 8's benchmark from 1.01x the C loop's speed to 0.72x. They use no
//! closures: a closure does not take on the target features of the function it is inlined
//! into, and ones the compiler left out of line called each intrinsic as a function (week 5's
//! goldens rendered five times slower).
//!
//! [`Scene::closest`]: crate::scene::Scene::closest
//! [`Scene::count_hits`]: crate::scene::Scene::count_hits

use std::arch::x86_64::*;

use glam::DVec3;

use super::{LANES, RayLanes};
use crate::geometry::{Interval, PARALLEL_EPSILON, Quad};
use crate::scene::accel::shape_set::{
    Ball, LEAVING_MIN, LEAVING_SLOPE, Member, PREFILTER_MARGIN, PREFILTER_RANGE, ShapeSet,
};

/// Three coordinates, one vector each.
type Vec3Lanes = [__m256d; 3];

/// `u . v` lane by lane, in glam's order `(x x' + y y') + z z'`.
///
/// # Safety
///
/// The processor must have AVX2.
#[inline(always)]
unsafe fn dot(u: Vec3Lanes, v: Vec3Lanes) -> __m256d {
    // SAFETY: AVX2 is there (this function's contract).
    unsafe {
        _mm256_add_pd(
            _mm256_add_pd(_mm256_mul_pd(u[0], v[0]), _mm256_mul_pd(u[1], v[1])),
            _mm256_mul_pd(u[2], v[2]),
        )
    }
}

/// Where `x` is neither infinite nor NaN, lane by lane.
///
/// # Safety
///
/// The processor must have AVX2.
#[inline(always)]
unsafe fn finite(x: __m256d) -> __m256d {
    // SAFETY: AVX2 is there (this function's contract).
    unsafe {
        let magnitude = _mm256_andnot_pd(_mm256_set1_pd(-0.0), x);
        _mm256_cmp_pd::<_CMP_LT_OQ>(magnitude, _mm256_set1_pd(f64::INFINITY))
    }
}

/// `x` in every lane.
///
/// # Safety
///
/// The processor must have AVX2.
#[inline(always)]
pub(crate) unsafe fn splat(x: f64) -> __m256d {
    // SAFETY: AVX2 is there (this function's contract).
    unsafe { _mm256_set1_pd(x) }
}

/// `v`'s coordinates, each in every lane.
///
/// # Safety
///
/// The processor must have AVX2.
#[inline(always)]
unsafe fn splat3(v: DVec3) -> Vec3Lanes {
    // SAFETY: AVX2 is there (this function's contract).
    unsafe { [splat(v.x), splat(v.y), splat(v.z)] }
}

/// `a x b` lane by lane, glam's terms in glam's order:
/// `(a.y b.z - b.y a.z, a.z b.x - b.z a.x, a.x b.y - b.x a.y)`.
///
/// # Safety
///
/// The processor must have AVX2.
#[inline(always)]
unsafe fn cross(a: Vec3Lanes, b: Vec3Lanes) -> Vec3Lanes {
    // SAFETY: AVX2 is there (this function's contract).
    unsafe {
        [
            _mm256_sub_pd(_mm256_mul_pd(a[1], b[2]), _mm256_mul_pd(b[1], a[2])),
            _mm256_sub_pd(_mm256_mul_pd(a[2], b[0]), _mm256_mul_pd(b[2], a[0])),
            _mm256_sub_pd(_mm256_mul_pd(a[0], b[1]), _mm256_mul_pd(b[0], a[1])),
        ]
    }
}

/// Where `lo < x < hi` (`OPEN`) or `lo <= x <= hi`, lane by lane (false for NaN).
///
/// # Safety
///
/// The processor must have AVX2.
#[inline(always)]
pub(crate) unsafe fn between<const OPEN: bool>(lo: __m256d, x: __m256d, hi: __m256d) -> __m256d {
    // SAFETY: AVX2 is there (this function's contract).
    unsafe {
        if OPEN {
            _mm256_and_pd(
                _mm256_cmp_pd::<_CMP_LT_OQ>(lo, x),
                _mm256_cmp_pd::<_CMP_LT_OQ>(x, hi),
            )
        } else {
            _mm256_and_pd(
                _mm256_cmp_pd::<_CMP_LE_OQ>(lo, x),
                _mm256_cmp_pd::<_CMP_LE_OQ>(x, hi),
            )
        }
    }
}

/// The rays' origins, directions and active lanes, loaded, with what every object's test reads
/// of a ray alone: `a = d . d` (glam's order, `(x x + y y) + z z`), the pre-filter's margin
/// `a PREFILTER_MARGIN`, where `a` is sane for `roots_of` (`a.is_normal() && a < 1e300`, which
/// for a sum of squares is `MIN_POSITIVE <= a < 1e300`: false for 0, subnormals, infinity and
/// NaN alike) and where it lies in the pre-filter's range.
#[derive(Clone, Copy)]
struct Loaded {
    origin: Vec3Lanes,
    direction: Vec3Lanes,
    active: __m256d,
    a: __m256d,
    a_margin: __m256d,
    a_sane: __m256d,
    a_in_range: __m256d,
}

impl Loaded {
    /// `rays`, loaded.
    ///
    /// # Safety
    ///
    /// The processor must have AVX2.
    #[inline(always)]
    unsafe fn new(rays: &RayLanes) -> Self {
        // SAFETY: AVX2 is there (this function's contract); each load reads a whole `[_; 4]`.
        unsafe {
            let direction = [lanes_of(&rays.dx), lanes_of(&rays.dy), lanes_of(&rays.dz)];
            let a = dot(direction, direction);
            Self {
                origin: [lanes_of(&rays.ox), lanes_of(&rays.oy), lanes_of(&rays.oz)],
                direction,
                active: mask(&rays.active),
                a,
                a_margin: _mm256_mul_pd(a, splat(PREFILTER_MARGIN)),
                a_sane: _mm256_and_pd(
                    _mm256_cmp_pd::<_CMP_GE_OQ>(a, splat(f64::MIN_POSITIVE)),
                    _mm256_cmp_pd::<_CMP_LT_OQ>(a, splat(1e300)),
                ),
                a_in_range: _mm256_and_pd(
                    _mm256_cmp_pd::<_CMP_GE_OQ>(a, splat(PREFILTER_RANGE.start)),
                    _mm256_cmp_pd::<_CMP_LT_OQ>(a, splat(PREFILTER_RANGE.end)),
                ),
            }
        }
    }
}

impl RayLanes {
    /// Each lane's `d.y / |d|`, the `y` of its direction's unit vector, with the scalar
    /// `direction.y / direction.length()`'s operations (`|d| = sqrt((x x + y y) + z z)`, each
    /// rounded once), so bit for bit its value. A lane never set holds NaN (`0 / 0`).
    ///
    /// # Safety
    ///
    /// The processor must have AVX2 ([`has_lanes`]).
    #[target_feature(enable = "avx2")]
    #[inline]
    pub(crate) unsafe fn unit_y(&self) -> [f64; LANES] {
        let mut y = [0.0; LANES];
        // SAFETY: AVX2 is there (this function's contract); the loads and the store read and
        // write whole `[f64; 4]` arrays.
        unsafe {
            let d = [lanes_of(&self.dx), lanes_of(&self.dy), lanes_of(&self.dz)];
            let length = _mm256_sqrt_pd(dot(d, d));
            _mm256_storeu_pd(y.as_mut_ptr(), _mm256_div_pd(d[1], length));
        }
        y
    }
}

/// The four values of `x`, one per lane, read one at a time.
///
/// A [`RayLanes`] is written one `f64` at a time, just before its query; a vector load of
/// those values waits for the four stores to reach the cache (a processor forwards a store
/// to a load it contains, not several small stores to one wide load: a store-forwarding
/// stall, at the start of every query). Read singly (volatile, so that the compiler does not
/// merge them back into one wide load), each value comes straight from its store, and
/// shuffles put them together: week 8 renders about 7% faster so.
///
/// # Safety
///
/// The processor must have AVX2.
#[inline(always)]
unsafe fn lanes_of(x: &[f64; LANES]) -> __m256d {
    // SAFETY: AVX2 is there (this function's contract); each read is of an element of `x`,
    // a valid, aligned `f64`.
    unsafe {
        let [a, b, c, d] = [&x[0], &x[1], &x[2], &x[3]].map(|x| std::ptr::read_volatile(x));
        _mm256_set_pd(d, c, b, a)
    }
}

/// A lane mask of all ones or all zeros per lane, loaded as [`lanes_of`] loads (the same
/// bits).
///
/// # Safety
///
/// The processor must have AVX2.
#[inline(always)]
unsafe fn mask(x: &[u64; LANES]) -> __m256d {
    // SAFETY: AVX2 is there (this function's contract); each read is of an element of `x`,
    // a valid, aligned `u64`.
    unsafe {
        let [a, b, c, d] = [&x[0], &x[1], &x[2], &x[3]].map(|x| std::ptr::read_volatile(x));
        _mm256_castsi256_pd(_mm256_set_epi64x(d as i64, c as i64, b as i64, a as i64))
    }
}

/// One sphere (centre `center` lane by lane, squared radius `r2`) against every lane: where each
/// lane's ray has a root in `(min, max[k])` (the lane's root in `t`, the others unchanged), and
/// the lanes whose intermediates over- or underflow.
///
/// Lane by lane these are the scalar set's `root` operations, in its order: the same `f`, `b'`,
/// `c`, early outs (`sure_miss`), then [`roots_lanes`]. A ball every lane surely misses costs
/// no division. The tests compare it with the scene's loop
/// (`lanes_answer_as_the_scene_loop_does`).
///
/// # Safety
///
/// The processor must have AVX2 (the caller checked [`has_lanes`]).
#[inline(always)]
unsafe fn ball_lanes(
    center: Vec3Lanes,
    r2: f64,
    loaded: &Loaded,
    min: f64,
    max: &[f64; LANES],
    t: &mut [f64; LANES],
) -> (u32, u32) {
    // SAFETY: for every intrinsic below, AVX2 is there (this function's contract).
    unsafe {
        let [o, d] = [loaded.origin, loaded.direction];
        let f = [
            _mm256_sub_pd(o[0], center[0]),
            _mm256_sub_pd(o[1], center[1]),
            _mm256_sub_pd(o[2], center[2]),
        ];
        let r2v = splat(r2);
        let half_b = dot(f, d);
        let ff = dot(f, f);
        let c = _mm256_sub_pd(ff, r2v);
        let zero = _mm256_setzero_pd();
        let solvable = if r2 < 1e300 {
            _mm256_and_pd(_mm256_and_pd(loaded.a_sane, finite(c)), finite(half_b))
        } else {
            zero
        };
        let receding = _mm256_cmp_pd::<_CMP_GT_OQ>(half_b, zero);
        let behind = if min >= 0.0 {
            _mm256_and_pd(receding, _mm256_cmp_pd::<_CMP_GT_OQ>(c, zero))
        } else {
            zero
        };
        let scale = _mm256_add_pd(ff, r2v);
        let in_range = _mm256_and_pd(
            _mm256_cmp_pd::<_CMP_GE_OQ>(scale, splat(PREFILTER_RANGE.start)),
            _mm256_cmp_pd::<_CMP_LT_OQ>(scale, splat(PREFILTER_RANGE.end)),
        );
        let both_in_range = _mm256_and_pd(loaded.a_in_range, in_range);
        let leaving = if min >= LEAVING_MIN {
            // `c >= -(LEAVING_SLOPE b')`, as `sure_miss` computes it.
            let bound = _mm256_xor_pd(_mm256_mul_pd(splat(LEAVING_SLOPE), half_b), splat(-0.0));
            _mm256_and_pd(
                _mm256_and_pd(receding, both_in_range),
                _mm256_cmp_pd::<_CMP_GE_OQ>(c, bound),
            )
        } else {
            zero
        };
        let a = loaded.a;
        let naive = _mm256_sub_pd(_mm256_mul_pd(half_b, half_b), _mm256_mul_pd(a, c));
        let margin = _mm256_mul_pd(loaded.a_margin, scale);
        let margin = _mm256_xor_pd(margin, splat(-0.0));
        let aside = _mm256_and_pd(both_in_range, _mm256_cmp_pd::<_CMP_LT_OQ>(naive, margin));
        let sure = _mm256_and_pd(solvable, _mm256_or_pd(_mm256_or_pd(behind, leaving), aside));
        let open = _mm256_andnot_pd(sure, loaded.active);
        let unsolved = _mm256_andnot_pd(solvable, loaded.active);
        if _mm256_movemask_pd(open) == 0 {
            return (0, _mm256_movemask_pd(unsolved) as u32);
        }
        let parts = Parts {
            f,
            a,
            half_b,
            r2: r2v,
            c,
        };
        let (found, overflow) = roots_lanes(&parts, d, open, min, max, t);
        (found, _mm256_movemask_pd(unsolved) as u32 | overflow)
    }
}

/// [`ball_lanes`] for a ball centred exactly on the point every lane's ray is aimed at (each
/// direction computed as `center - origin`, as a shadow ray to a point light): where a lane's
/// answer is sure without arithmetic, it is given so (a hit), and the other lanes are solved
/// by [`ball_lanes`].
///
/// With `d = center - o`, the parts are exact: `f = o - center = -d` bit for bit (a difference
/// changes sign exactly with its operands), so `b' = f . d = -a` and `f . f = a` (the same
/// products and sums, signs flipped), `b' / a = -1`, `perp = f - d (-1) = 0` and
/// `disc = a r^2`. Then `q = a + sqrt(a r^2)` and the roots are `t0 = (a - r^2) / q` and
/// `t1 = q / a >= 1`. Where `a` lies in `PREFILTER_RANGE` and `a >= 2 r^2`, every part is
/// finite and sane for `roots_of`, `a - r^2 >= a / 2` and `q <= 2 a` (so `1/4 <= t0 <= 1`, each
/// bound surviving rounding, which is monotone); so `t0`, the near root, lies in
/// `(min, max)` whenever `min < 1/4` and `max > 1`: a hit. (The course's point light at distance
/// above 1 and more than 1.42 radii from its centre: its own sphere, counted by the occlusion
/// test, costs no division.)
///
/// # Safety
///
/// The processor must have AVX2 (the caller checked [`has_lanes`]).
#[inline(always)]
unsafe fn aimed_ball_lanes(
    ball: &Ball,
    loaded: &Loaded,
    min: f64,
    max: &[f64; LANES],
    t: &mut [f64; LANES],
) -> (u32, u32) {
    // SAFETY: for every intrinsic below, AVX2 is there (this function's contract); the load
    // reads a whole `[f64; 4]`.
    unsafe {
        let sure = if min < 0.25 {
            _mm256_and_pd(
                _mm256_and_pd(loaded.active, loaded.a_in_range),
                _mm256_and_pd(
                    _mm256_cmp_pd::<_CMP_GE_OQ>(loaded.a, splat(2.0 * ball.r2)),
                    _mm256_cmp_pd::<_CMP_GT_OQ>(_mm256_loadu_pd(max.as_ptr()), splat(1.0)),
                ),
            )
        } else {
            _mm256_setzero_pd()
        };
        let sure_hits = _mm256_movemask_pd(sure) as u32;
        let rest = Loaded {
            active: _mm256_andnot_pd(sure, loaded.active),
            ..*loaded
        };
        if _mm256_movemask_pd(rest.active) == 0 {
            return (sure_hits, 0);
        }
        let (found, bad) = ball_lanes(splat3(ball.center), ball.r2, &rest, min, max, t);
        (found | sure_hits, bad)
    }
}

/// One sphere's parts for the lanes' rays: `f = o - center`, `a = d . d`, `b' = f . d`,
/// `r^2` and `c = f . f - r^2`.
struct Parts {
    f: Vec3Lanes,
    a: __m256d,
    half_b: __m256d,
    r2: __m256d,
    c: __m256d,
}

/// `roots_of` then `pick_root` against `(min, max[k])`, for the `open` lanes: where a lane
/// finds a root, it is stored in `t`. Returns the lanes that found one, and those whose
/// discriminant over- or underflowed.
///
/// # Safety
///
/// The processor must have AVX2.
#[inline(always)]
unsafe fn roots_lanes(
    parts: &Parts,
    d: Vec3Lanes,
    open: __m256d,
    min: f64,
    max: &[f64; LANES],
    t: &mut [f64; LANES],
) -> (u32, u32) {
    // SAFETY: for every intrinsic below, AVX2 is there (this function's contract); the load and
    // the store read and write whole `[f64; 4]` arrays.
    unsafe {
        let &Parts {
            f,
            a,
            half_b,
            r2,
            c,
        } = parts;
        let sign = _mm256_set1_pd(-0.0);
        let zero = _mm256_setzero_pd();
        let s = _mm256_div_pd(half_b, a);
        let p = [
            _mm256_sub_pd(f[0], _mm256_mul_pd(d[0], s)),
            _mm256_sub_pd(f[1], _mm256_mul_pd(d[1], s)),
            _mm256_sub_pd(f[2], _mm256_mul_pd(d[2], s)),
        ];
        let disc = _mm256_mul_pd(a, _mm256_sub_pd(r2, dot(p, p)));
        let disc_finite = finite(disc);
        let overflow = _mm256_andnot_pd(disc_finite, open);
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
        let (lo, hi) = (splat(min), _mm256_loadu_pd(max.as_ptr()));
        let (near_in, far_in) = (between::<true>(lo, near, hi), between::<true>(lo, far, hi));
        let found = _mm256_and_pd(
            _mm256_and_pd(open, disc_finite),
            _mm256_and_pd(
                _mm256_cmp_pd::<_CMP_GE_OQ>(disc, zero),
                _mm256_or_pd(near_in, far_in),
            ),
        );
        let chosen = _mm256_blendv_pd(far, near, near_in);
        let kept = _mm256_blendv_pd(_mm256_loadu_pd(t.as_ptr()), chosen, found);
        _mm256_storeu_pd(t.as_mut_ptr(), kept);
        (
            _mm256_movemask_pd(found) as u32,
            _mm256_movemask_pd(overflow) as u32,
        )
    }
}

/// One quad against every lane: where each lane's ray hits it within `[min, max[k]]` (closed,
/// the course's `contains`; the lane's `t` stored in `t`).
///
/// Lane by lane these are [`Quad::solve_from`]'s operations, in its order: `denom = n . d`,
/// `t = (D - n . o) / denom`, refused when `|denom| < 1e-8` or NaN, `t` not finite or outside
/// the interval; then `planar = o + d t - Q` and `alpha = w . (planar x v)`,
/// `beta = w . (u x planar)` (glam's cross product, term by term), both in `[0, 1]`. A quad
/// whose plane no lane meets within its interval costs no more than the division.
///
/// # Safety
///
/// The processor must have AVX2 (the caller checked [`has_lanes`]).
#[inline(always)]
unsafe fn quad_lanes(
    quad: &Quad,
    loaded: &Loaded,
    min: f64,
    max: &[f64; LANES],
    t: &mut [f64; LANES],
) -> u32 {
    // SAFETY: for every intrinsic below, AVX2 is there (this function's contract); the load and
    // the store read and write whole `[f64; 4]` arrays.
    unsafe {
        let [o, d] = [loaded.origin, loaded.direction];
        let n = splat3(quad.normal);
        let denom = dot(n, d);
        let offset = _mm256_sub_pd(splat(quad.d), dot(n, o));
        let at = _mm256_div_pd(offset, denom);
        let magnitude = _mm256_andnot_pd(splat(-0.0), denom);
        let plane = _mm256_and_pd(
            _mm256_and_pd(
                loaded.active,
                _mm256_cmp_pd::<_CMP_GE_OQ>(magnitude, splat(PARALLEL_EPSILON)),
            ),
            _mm256_and_pd(
                finite(at),
                between::<false>(splat(min), at, _mm256_loadu_pd(max.as_ptr())),
            ),
        );
        if _mm256_movemask_pd(plane) == 0 {
            return 0;
        }
        // `ray.at(t) - q`.
        let q = splat3(quad.q);
        let p = [
            _mm256_sub_pd(_mm256_add_pd(o[0], _mm256_mul_pd(d[0], at)), q[0]),
            _mm256_sub_pd(_mm256_add_pd(o[1], _mm256_mul_pd(d[1], at)), q[1]),
            _mm256_sub_pd(_mm256_add_pd(o[2], _mm256_mul_pd(d[2], at)), q[2]),
        ];
        let (u, v, w) = (splat3(quad.u), splat3(quad.v), splat3(quad.w));
        let alpha = dot(w, cross(p, v));
        let beta = dot(w, cross(u, p));
        let (zero, one) = (_mm256_setzero_pd(), splat(1.0));
        let found = _mm256_and_pd(
            plane,
            _mm256_and_pd(
                between::<false>(zero, alpha, one),
                between::<false>(zero, beta, one),
            ),
        );
        let kept = _mm256_blendv_pd(_mm256_loadu_pd(t.as_ptr()), at, found);
        _mm256_storeu_pd(t.as_mut_ptr(), kept);
        _mm256_movemask_pd(found) as u32
    }
}

/// Member `member` against every lane: the lanes that found a root in the interval (stored in
/// `t`) and those that must be decided by the scalar path.
///
/// # Safety
///
/// The processor must have AVX2.
#[inline(always)]
unsafe fn member_lanes(
    member: &Member,
    rays: &RayLanes,
    loaded: &Loaded,
    min: f64,
    max: &[f64; LANES],
    t: &mut [f64; LANES],
) -> (u32, u32) {
    // SAFETY: AVX2 is there (this function's contract); the load reads a whole `[f64; 4]`.
    unsafe {
        match member {
            Member::Ball(Ball { center, r2 }) => {
                ball_lanes(splat3(*center), *r2, loaded, min, max, t)
            }
            Member::Moving { ball, travel } => {
                // `center + travel * time`, lane by lane.
                let time = lanes_of(&rays.time);
                let (c, travel) = (splat3(ball.center), splat3(*travel));
                let center = [
                    _mm256_add_pd(c[0], _mm256_mul_pd(travel[0], time)),
                    _mm256_add_pd(c[1], _mm256_mul_pd(travel[1], time)),
                    _mm256_add_pd(c[2], _mm256_mul_pd(travel[2], time)),
                ];
                ball_lanes(center, ball.r2, loaded, min, max, t)
            }
            Member::Quad(quad) => (quad_lanes(quad, loaded, min, max, t), 0),
        }
    }
}

impl ShapeSet {
    /// [`ShapeSet::closest`] for each active lane of `rays` at once: lane `k`'s closest hit in
    /// `interval`, or `Err(())` where the lane's ray must be decided by the scalar path (over-
    /// or underflow). Inactive lanes answer `Ok(None)`.
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
        // SAFETY: AVX2 is there (this function's contract).
        let loaded = unsafe { Loaded::new(rays) };
        for (me, member) in self.members.iter().enumerate() {
            let max = closest;
            // SAFETY: AVX2 is there (this function's contract).
            let (hit, bad) =
                unsafe { member_lanes(member, rays, &loaded, interval.min, &max, &mut closest) };
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

    /// The course's occlusion test ([`ShapeSet::count_hits`] on `[min, max[k]]`, limit 2, more
    /// than one hit) for each active lane of `rays` at once: `Ok(occluded)`, or `Err(())` where
    /// the lane's ray must be decided by the scalar path. Inactive lanes answer `Ok(false)`.
    ///
    /// # Safety
    ///
    /// The processor must have AVX2 ([`has_lanes`]).
    #[cfg(test)]
    #[target_feature(enable = "avx2")]
    #[inline]
    pub(crate) unsafe fn occluded_lanes(
        &self,
        rays: &RayLanes,
        min: f64,
        max: &[f64; LANES],
    ) -> [Result<bool, ()>; LANES] {
        // SAFETY: AVX2 is there (this function's contract).
        unsafe {
            let loaded = Loaded::new(rays);
            self.count_lanes(rays, &loaded, min, max, 0)
        }
    }

    /// The course's occlusion test of shadow rays to one point, for each active lane of `rays`
    /// at once: every active lane's direction is `point - origin` (computed so), its ray is
    /// tested on `(min, |direction|)` (`occluded`'s interval, the length computed as
    /// `DVec3::length` does, in one vector), and `aimed` is [`ShapeSet::centred_at`]`(point)`.
    /// The answers are the course's occlusion test's on those intervals (as `occluded_lanes`,
    /// the general query the tests ask, answers it); the spheres centred at
    /// `point` (a point light's own) are decided without their roots where they can be
    /// (`aimed_ball_lanes`).
    ///
    /// # Safety
    ///
    /// The processor must have AVX2 ([`has_lanes`]).
    #[target_feature(enable = "avx2")]
    #[inline]
    pub(crate) unsafe fn shadowed_lanes(
        &self,
        rays: &RayLanes,
        min: f64,
        aimed: u64,
    ) -> [Result<bool, ()>; LANES] {
        let mut reach = [0.0; LANES];
        // SAFETY: AVX2 is there (this function's contract); the store writes a whole array.
        unsafe {
            let loaded = Loaded::new(rays);
            // `|d| = sqrt((x x + y y) + z z)`, glam's `length`, from the loaded `a`.
            _mm256_storeu_pd(reach.as_mut_ptr(), _mm256_sqrt_pd(loaded.a));
            self.count_lanes(rays, &loaded, min, &reach, aimed)
        }
    }

    /// The occlusion count of the loaded `rays` on `(min, max[k])`, the members `aimed` marks
    /// tested by `aimed_ball_lanes` (see [`ShapeSet::shadowed_lanes`]).
    ///
    /// Whether a ray meets more than one object does not depend on the order the objects are
    /// tested in (each object's test is on the same interval, whatever the others answer), so
    /// the aimed spheres go first (a light's own, a sure hit where `aimed_ball_lanes` can say
    /// so), then the others in the scene's order, and the test stops once every active lane
    /// has met two objects, as the scalar `count_hits` stops at its limit. A lane that has met
    /// two is decided even where a later object over- or underflows: that object cannot undo
    /// the two hits.
    ///
    /// # Safety
    ///
    /// The processor must have AVX2 ([`has_lanes`]).
    #[inline(always)]
    unsafe fn count_lanes(
        &self,
        rays: &RayLanes,
        loaded: &Loaded,
        min: f64,
        max: &[f64; LANES],
        aimed: u64,
    ) -> [Result<bool, ()>; LANES] {
        // SAFETY: AVX2 is there (this function's contract).
        let active = unsafe { _mm256_movemask_pd(loaded.active) } as u32;
        let (mut once, mut twice, mut unsolved) = (0u32, 0u32, 0u32);
        let mut t = [0.0; LANES];
        let aimed = if self.members.len() < 64 {
            aimed & ((1 << self.members.len()) - 1)
        } else {
            aimed
        };
        let mut rest = aimed;
        while rest != 0 {
            let me = rest.trailing_zeros() as usize;
            rest &= rest - 1;
            // SAFETY: AVX2 is there (this function's contract).
            let (hit, bad) = unsafe {
                match &self.members[me] {
                    Member::Ball(ball) => aimed_ball_lanes(ball, loaded, min, max, &mut t),
                    member => member_lanes(member, rays, loaded, min, max, &mut t),
                }
            };
            twice |= once & hit;
            once |= hit;
            unsolved |= bad;
        }
        for (me, member) in self.members.iter().enumerate() {
            if twice & active == active {
                break;
            }
            if me < 64 && aimed & (1 << me) != 0 {
                continue;
            }
            // SAFETY: AVX2 is there (this function's contract).
            let (hit, bad) = unsafe { member_lanes(member, rays, loaded, min, max, &mut t) };
            twice |= once & hit;
            once |= hit;
            unsolved |= bad;
        }
        let mut answers = [Ok(false); LANES];
        for (k, answer) in answers.iter_mut().enumerate() {
            *answer = if twice & (1 << k) != 0 {
                Ok(true)
            } else if unsolved & (1 << k) != 0 {
                Err(())
            } else {
                Ok(false)
            };
        }
        answers
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Ray;
    use crate::render::PixelSampler;
    use crate::scene::accel::shape_set::tests::{intervals, random_ray, random_scene};
    use crate::scene::{Object, Scene};

    /// On 300 random scenes of spheres, then 300 of spheres, moving spheres and quads, 250
    /// packets of four rays each (some lanes idle), under the camera's interval, a shadow ray's
    /// and the book's: each lane's closest object and `t` bits are the scene loop's, and its
    /// occlusion (on its own reach) is the scene's count above one.
    #[test]
    fn lanes_answer_as_the_scene_loop_does() {
        if super::super::skipped_without_lanes("there are no lanes to check") {
            return;
        }
        let mut s = PixelSampler::new(29, 7);
        let mut compared = 0;
        for scene_number in 0..600 {
            let scene = random_scene(&mut s, 1 + scene_number % 12, scene_number >= 300);
            let set = ShapeSet::new(&scene).expect("spheres and quads only");
            for _ in 0..250 {
                let mut rays = RayLanes::default();
                let mut packet: [Option<(Ray, [Interval; 3])>; LANES] = [None; LANES];
                for (k, lane) in packet.iter_mut().enumerate() {
                    let ray = random_ray(&mut s, &scene);
                    let asked = intervals(&mut s, &ray);
                    if s.next_f64() < 0.85 {
                        rays.set(k, ray.origin, ray.direction, ray.time);
                        *lane = Some((ray, asked));
                    }
                }
                for which in 0..3 {
                    let interval = |k: usize| packet[k].map(|(_, i)| i[which]);
                    let shared = interval(0).unwrap_or(Interval::CAMERA);
                    // SAFETY: the processor has AVX2 (checked above).
                    let closest = unsafe { set.closest_lanes(&rays, shared) };
                    let reach = [0, 1, 2, 3].map(|k| interval(k).map_or(0.0, |i| i.max));
                    // SAFETY: as above.
                    let dark = unsafe { set.occluded_lanes(&rays, shared.min, &reach) };
                    for (k, lane) in packet.iter().enumerate() {
                        let Some((ray, _)) = lane else {
                            assert_eq!(closest[k], Ok(None));
                            assert_eq!(dark[k], Ok(false));
                            continue;
                        };
                        let slow = scene.closest(ray, shared);
                        assert_eq!(
                            closest[k].map(|a| a.map(|(t, k)| (t.to_bits(), k))),
                            Ok(slow.map(|(t, k)| (t.to_bits(), k))),
                            "{ray:?} {shared:?}"
                        );
                        let own = Interval::new(shared.min, reach[k]);
                        assert_eq!(dark[k], Ok(scene.count_hits(ray, own, 2) > 1), "{ray:?}");
                        compared += 1;
                    }
                }
            }
        }
        assert!(compared > 600 * 250 * 3 * 3, "{compared}");
    }

    /// Lane 1's answers for `ray` alone: its closest hit in `interval`, and its occlusion on the
    /// same interval.
    fn lane_one(set: &ShapeSet, ray: &Ray, interval: Interval) -> (Option<(f64, usize)>, bool) {
        let mut rays = RayLanes::default();
        rays.set(1, ray.origin, ray.direction, ray.time);
        // SAFETY: the callers checked that the processor has AVX2.
        let (closest, dark) = unsafe {
            (
                set.closest_lanes(&rays, interval),
                set.occluded_lanes(&rays, interval.min, &[interval.max; LANES]),
            )
        };
        (closest[1].unwrap(), dark[1].unwrap())
    }

    /// Rays that meet a quad at exactly either end of the interval (a quad's test is closed
    /// there, a sphere's open), a quad and a sphere at the same `t` (the later quad takes it),
    /// and rays nearly parallel to a quad's plane (`0 < |n . d| < 1e-8` is refused even where
    /// the point it would give lies on the quad): each answer worked out by hand, and the scene
    /// loop's.
    #[test]
    fn quads_at_the_ends_of_the_interval_and_nearly_parallel_rays() {
        if super::super::skipped_without_lanes("there are no lanes to check") {
            return;
        }
        let c = DVec3::new;
        let object = |shape| crate::scene::SceneObject { shape, material: 0 };
        let wall = |x: f64| {
            Object::Quad(Quad::new(
                c(x, -1.0, -1.0),
                c(0.0, 2.0, 0.0),
                c(0.0, 0.0, 2.0),
            ))
        };
        let ball = Object::Sphere(crate::geometry::Sphere::new(c(5.0, 0.0, 0.0), 1.0));
        // Walls at x = 1 and x = 3, a ball whose near side is at x = 4, and a wall at x = 4.
        let scene = Scene {
            objects: vec![
                object(wall(1.0)),
                object(wall(3.0)),
                object(ball),
                object(wall(4.0)),
            ],
            materials: vec![],
        };
        let set = ShapeSet::new(&scene).unwrap();
        let along_x = |x: f64| Ray::new(c(x, 0.0, 0.0), DVec3::X);
        for (ray, interval, closest, dark) in [
            // The wall at t = min is hit (closed), so both walls occlude.
            (along_x(0.0), Interval::new(1.0, 3.0), Some((1.0, 0)), true),
            // The wall at t = max is hit (closed).
            (along_x(0.0), Interval::new(1.5, 3.0), Some((3.0, 1)), false),
            // At t = max = 4 the ball is not hit (open) and the wall behind it in the list is.
            (along_x(0.0), Interval::new(3.5, 4.0), Some((4.0, 3)), false),
            // Between the ball's roots (4 and 6), nothing.
            (along_x(0.0), Interval::new(4.5, 5.9), None, false),
            // The ball and the wall behind it in the list, both at t = 0.5: the wall takes it.
            (along_x(3.5), Interval::CAMERA, Some((0.5, 3)), true),
        ] {
            assert_eq!(
                lane_one(&set, &ray, interval),
                (closest, dark),
                "{ray:?} {interval:?}"
            );
            let count = scene.count_hits(&ray, interval, 2);
            assert_eq!((scene.closest(&ray, interval), count > 1), (closest, dark));
        }
        // A floor at z = 5, 1e10 long in x: a ray rising 1e-9 per unit of x would meet it at
        // x = 5e9, on it, but `|n . d| = 1e-9` counts as parallel; one rising 1e-7 meets it.
        let floor = Quad::new(c(-1.0, -1.0, 5.0), c(1e10, 0.0, 0.0), c(0.0, 2.0, 0.0));
        let scene = Scene {
            objects: vec![object(Object::Quad(floor)), object(Object::Quad(floor))],
            materials: vec![],
        };
        let set = ShapeSet::new(&scene).unwrap();
        let flat = Ray::new(DVec3::ZERO, c(1.0, 0.0, 1e-9));
        assert_eq!(lane_one(&set, &flat, Interval::CAMERA), (None, false));
        assert_eq!(scene.closest(&flat, Interval::CAMERA), None);
        let rising = Ray::new(DVec3::ZERO, c(1.0, 0.0, 1e-7));
        let (hit, dark) = lane_one(&set, &rising, Interval::CAMERA);
        let (t, k) = hit.expect("the rising ray meets the floor");
        assert!(
            (t / 5e7 - 1.0).abs() < 1e-12 && k == 1 && dark,
            "{hit:?} {dark}"
        );
        assert_eq!(scene.closest(&rising, Interval::CAMERA), hit);
    }

    /// Rays whose `a = d . d` lies at the edges of what `roots_of` accepts (a normal number below
    /// 1e300) are handed back exactly where the scalar set hands them back, and answered as it
    /// answers the rest: a sphere of radius 1 seen from 2 away along `-z`, the direction scaled
    /// so that `a` is 0, subnormal (1e-320), about `f64::MIN_POSITIVE`, 1e-300, 1e298, about
    /// 1e300, 1.21e300 (finite, refused) and infinite. The subnormal and the 1.21e300 lanes have
    /// finite roots, so a lane that took them would answer where the scalar set does not.
    #[test]
    fn rays_at_the_edges_of_a_sane_length_are_handed_back_as_the_scalar_set_does() {
        if super::super::skipped_without_lanes("there are no lanes to check") {
            return;
        }
        let scene = Scene {
            objects: vec![crate::scene::SceneObject {
                shape: Object::Sphere(crate::geometry::Sphere::new(DVec3::ZERO, 1.0)),
                material: 0,
            }],
            materials: vec![],
        };
        let set = ShapeSet::new(&scene).unwrap();
        let scales = [
            0.0,
            1e-160,
            f64::MIN_POSITIVE.sqrt(),
            f64::MIN_POSITIVE.sqrt() * (1.0 + f64::EPSILON),
            1e-150,
            1e149,
            1e150,
            1e150 * (1.0 + f64::EPSILON),
            1.1e150,
            1e155,
        ];
        let mut handed_back = 0;
        for packet in scales.chunks(LANES) {
            let mut rays = RayLanes::default();
            let mut plain = Vec::new();
            for (k, &scale) in packet.iter().enumerate() {
                let ray = Ray::new(DVec3::new(0.0, 0.0, 2.0), DVec3::new(0.0, 0.0, -scale));
                rays.set(k, ray.origin, ray.direction, 0.0);
                plain.push(ray);
            }
            // SAFETY: the processor has AVX2 (checked above).
            let answers = unsafe { set.closest_lanes(&rays, Interval::CAMERA) };
            for (k, ray) in plain.iter().enumerate() {
                let scalar = set.closest(ray, Interval::CAMERA).ok_or(());
                let bits = |a: Result<Option<(f64, usize)>, ()>| {
                    a.map(|a| a.map(|(t, i)| (t.to_bits(), i)))
                };
                assert_eq!(
                    bits(answers[k]),
                    bits(scalar),
                    "direction scale {:e}",
                    ray.direction.z
                );
                handed_back += usize::from(scalar.is_err());
            }
        }
        // 0, the subnormal, below MIN_POSITIVE, 1.21e300 and infinity at least.
        assert!(handed_back >= 4, "{handed_back}");
    }

    /// `unit_y` is the scalar `d.y / d.length()` bit for bit, for random directions of scales
    /// 2^-600 to 2^600 and for the edges: a zero direction (NaN), a subnormal one, lengths whose
    /// square under- or overflows (a `y` of 0 over an infinite length), infinite components.
    #[test]
    fn unit_y_is_the_scalar_unit_vectors_y_bit_for_bit() {
        if super::super::skipped_without_lanes("there are no lanes to check") {
            return;
        }
        let mut s = PixelSampler::new(11, 4);
        let mut directions = vec![
            DVec3::ZERO,
            DVec3::new(0.0, 5e-324, 0.0),
            DVec3::new(1e-170, -3e-170, 2e-170),
            DVec3::new(1e160, 2e160, -1e160),
            DVec3::new(0.0, f64::INFINITY, 0.0),
            DVec3::new(f64::INFINITY, 1.0, 0.0),
            DVec3::new(0.0, -1.0, 0.0),
            DVec3::new(3.0, 4.0, 12.0),
        ];
        for _ in 0..4000 {
            let scale = (s.uniform(-600.0, 600.0)).exp2();
            directions.push(
                DVec3::new(
                    s.uniform(-1.0, 1.0),
                    s.uniform(-1.0, 1.0),
                    s.uniform(-1.0, 1.0),
                ) * scale,
            );
        }
        for packet in directions.chunks(LANES) {
            let mut rays = RayLanes::default();
            for (k, d) in packet.iter().enumerate() {
                rays.set(k, DVec3::ZERO, *d, 0.0);
            }
            // SAFETY: the processor has AVX2 (checked above).
            let y = unsafe { rays.unit_y() };
            for (k, d) in packet.iter().enumerate() {
                let scalar = d.y / d.length();
                assert!(
                    y[k].to_bits() == scalar.to_bits() || (y[k].is_nan() && scalar.is_nan()),
                    "{d}: {} against {scalar}",
                    y[k]
                );
            }
        }
        // Closed forms: (3, 4, 12) has length 13 exactly, so y = 4 / 13 rounded once.
        let mut rays = RayLanes::default();
        rays.set(0, DVec3::ZERO, DVec3::new(3.0, 4.0, 12.0), 0.0);
        rays.set(1, DVec3::ZERO, DVec3::new(0.0, -1e-170, 0.0), 0.0);
        // SAFETY: the processor has AVX2 (checked above).
        let y = unsafe { rays.unit_y() };
        assert_eq!(y[0], 4.0 / 13.0);
        // (1e-170)^2 underflows to 0: -1e-170 / 0 is -infinity, as the scalar code computes it.
        assert_eq!(y[1], f64::NEG_INFINITY);
    }

    /// A lane whose sphere arithmetic overflows is handed back (`Err`), alone: the other lanes
    /// are answered.
    #[test]
    fn an_overflowing_lane_is_handed_back_alone() {
        if super::super::skipped_without_lanes("there are no lanes to check") {
            return;
        }
        let mut s = PixelSampler::new(3, 1);
        let scene = random_scene(&mut s, 6, true);
        let set = ShapeSet::new(&scene).unwrap();
        let mut rays = RayLanes::default();
        let plain = Ray::new(DVec3::new(0.0, 0.0, 9.0), -DVec3::Z);
        rays.set(0, plain.origin, plain.direction, 0.0);
        rays.set(
            2,
            DVec3::new(-1e300, 0.0, 0.0),
            DVec3::new(1e300, 0.0, 0.0),
            0.0,
        );
        // SAFETY: the processor has AVX2 (checked above).
        let answers = unsafe { set.closest_lanes(&rays, Interval::CAMERA) };
        assert_eq!(
            answers[0].map(|a| a.map(|(t, k)| (t.to_bits(), k))),
            Ok(scene
                .closest(&plain, Interval::CAMERA)
                .map(|(t, k)| (t.to_bits(), k)))
        );
        assert_eq!((answers[1], answers[3]), (Ok(None), Ok(None)));
        assert_eq!(answers[2], Err(()));
    }

    /// The occlusion test stops at two objects: a lane that has met two is answered (dark)
    /// even when an object whose arithmetic overflows comes after them, as the scene loop
    /// answers it; a lane that met fewer is handed back for that object. Whatever the order of
    /// the three, and with the two hit objects aimed at or not.
    #[test]
    fn a_lane_that_met_two_objects_is_dark_whatever_overflows_after() {
        if super::super::skipped_without_lanes("there are no lanes to check") {
            return;
        }
        let ball = |center: DVec3, r: f64| crate::scene::SceneObject {
            shape: Object::Sphere(crate::geometry::Sphere::new(center, r)),
            material: 0,
        };
        // `r^2 = 1e302`: beyond what the set solves (its lanes are handed back).
        let huge = ball(DVec3::new(0.0, 0.0, -1e160), 1e151);
        let near = ball(DVec3::new(0.0, 0.0, 2.0), 1.0);
        let light = ball(DVec3::new(0.0, 0.0, -6.0), 0.25);
        let target = DVec3::new(0.0, 0.0, -6.0);
        for order in [[0, 1, 2], [2, 1, 0], [1, 0, 2], [0, 2, 1]] {
            let objects = [huge, near, light];
            let scene = Scene {
                objects: order.map(|k| objects[k]).to_vec(),
                ..Scene::default()
            };
            let set = ShapeSet::new(&scene).unwrap();
            let mut rays = RayLanes::default();
            // Lane 0 passes through the near sphere to the light; lane 1 reaches the light
            // past it; lane 3 is idle.
            let from = [DVec3::new(0.0, 0.0, 6.0), DVec3::new(3.0, 0.0, 6.0)];
            for (k, p) in from.iter().enumerate() {
                rays.set(k, *p, target - *p, 0.0);
            }
            rays.set(
                2,
                DVec3::new(0.0, 0.5, 6.0),
                target - DVec3::new(0.0, 0.5, 6.0),
                0.0,
            );
            for aimed in [0, set.centred_at(target)] {
                // SAFETY: the processor has AVX2 (checked above).
                let dark = unsafe { set.shadowed_lanes(&rays, 1e-6, aimed) };
                assert_eq!(dark[0], Ok(true), "{order:?} {aimed}");
                assert_eq!(dark[2], Ok(true), "{order:?} {aimed}");
                assert_eq!(dark[1], Err(()), "{order:?} {aimed}");
                assert_eq!(dark[3], Ok(false), "{order:?} {aimed}");
                for p in [from[0], DVec3::new(0.0, 0.5, 6.0)] {
                    let reach = Interval::new(1e-6, (target - p).length());
                    assert!(scene.count_hits(&Ray::new(p, target - p), reach, 2) > 1);
                }
            }
        }
    }

    /// Shadow rays to a point light (a small sphere's centre, or a point no sphere is centred
    /// on) from points on the scene's objects and in space, at distances from 0.01 to 30 (so
    /// inside the light's sphere, within 1 of its centre, across `a = 2 r^2` and far), radii
    /// from 1e-3 to 2, scales of the whole scene from 2^-40 to 2^40: `shadowed_lanes` answers
    /// the scene loop's `count_hits(ray, (1e-6, |c - p|), 2) > 1` lane by lane, and lanes both
    /// inside and outside the aimed sphere's sure case occur.
    #[test]
    fn shadow_rays_to_a_light_answer_as_the_scene_loop_does() {
        if super::super::skipped_without_lanes("there are no lanes to check") {
            return;
        }
        let mut s = PixelSampler::new(53, 4);
        let (mut sure, mut solved) = (0, 0);
        for scene_number in 0..400 {
            let scale = 2f64.powi((s.next_f64() * 81.0) as i32 - 40);
            let mut scene = random_scene(&mut s, 1 + scene_number % 8, scene_number >= 200);
            let light = DVec3::new(
                s.uniform(-2.0, 2.0),
                s.uniform(-2.0, 2.0),
                s.uniform(-2.0, 2.0),
            );
            let radius = 10f64.powf(s.uniform(-3.0, 0.3));
            if scene_number % 5 != 4 {
                // The light's own sphere, anywhere in the list.
                let at = (s.next_f64() * (scene.objects.len() + 1) as f64) as usize;
                scene.objects.insert(
                    at,
                    crate::scene::SceneObject {
                        shape: Object::Sphere(crate::geometry::Sphere::new(light, radius)),
                        material: 0,
                    },
                );
            }
            for object in &mut scene.objects {
                object.shape = scaled(object.shape, scale);
            }
            let light = light * scale;
            let set = ShapeSet::new(&scene).expect("spheres and quads only");
            let aimed = set.centred_at(light);
            assert_eq!(aimed != 0, scene_number % 5 != 4);
            for _ in 0..100 {
                let mut rays = RayLanes::default();
                let mut points = [None; LANES];
                for (k, point) in points.iter_mut().enumerate() {
                    let p = if s.next_f64() < 0.5 {
                        random_ray(&mut s, &scene).origin
                    } else {
                        light + s.unit_vector() * (10f64.powf(s.uniform(-2.0, 1.5)) * scale)
                    };
                    if s.next_f64() < 0.9 && p != light {
                        rays.set(k, p, light - p, 0.0);
                        *point = Some(p);
                    }
                }
                // SAFETY: the processor has AVX2 (checked above).
                let dark = unsafe { set.shadowed_lanes(&rays, 1e-6, aimed) };
                // The aimed sphere's shortcut finds, lane by lane, what its roots find.
                let reach = points.map(|p| p.map_or(0.0, |p| (light - p).length()));
                for (me, member) in set.members.iter().enumerate() {
                    let Member::Ball(ball) = member else {
                        continue;
                    };
                    if me >= 64 || aimed & (1 << me) == 0 {
                        continue;
                    }
                    // At the shadow rays' `min`, and at one above the shortcut's bound.
                    for min in [1e-6, 0.5] {
                        let (mut t, mut u) = ([0.0; LANES], [0.0; LANES]);
                        // SAFETY: as above.
                        let (quick, full) = unsafe {
                            let loaded = Loaded::new(&rays);
                            let center = splat3(ball.center);
                            (
                                aimed_ball_lanes(ball, &loaded, min, &reach, &mut t),
                                ball_lanes(center, ball.r2, &loaded, min, &reach, &mut u),
                            )
                        };
                        assert_eq!(quick, full, "{min} {points:?} {light}");
                    }
                }
                for (k, point) in points.iter().enumerate() {
                    let Some(p) = *point else {
                        assert_eq!(dark[k], Ok(false));
                        continue;
                    };
                    let to_light = light - p;
                    let ray = Ray::new(p, to_light);
                    let reach = Interval::new(1e-6, to_light.length());
                    assert_eq!(
                        dark[k],
                        Ok(scene.count_hits(&ray, reach, 2) > 1),
                        "{p} {light}"
                    );
                    let a = to_light.dot(to_light);
                    if aimed != 0
                        && PREFILTER_RANGE.contains(&a)
                        && a >= 2.0 * (radius * scale).powi(2)
                        && reach.max > 1.0
                    {
                        sure += 1;
                    } else {
                        solved += 1;
                    }
                }
            }
        }
        assert!(
            sure > 20_000 && solved > 20_000,
            "{sure} sure, {solved} solved"
        );
    }

    /// `shape` with every length multiplied by `k` (a power of two: exactly).
    fn scaled(shape: Object, k: f64) -> Object {
        use crate::geometry::{MovingSphere, Sphere};
        let ball = |b: Sphere| Sphere::new(b.center * k, b.radius * k);
        match shape {
            Object::Sphere(b) => Object::Sphere(ball(b)),
            Object::MovingSphere(m) => {
                Object::MovingSphere(MovingSphere::new(ball(m.sphere), m.end * k))
            }
            Object::Quad(q) => Object::Quad(Quad::new(q.q * k, q.u * k, q.v * k)),
            Object::Triangle(t) => Object::Triangle(t),
        }
    }
}
