//! Every quad of a packet in one AVX2 vector per coordinate ([`quads_hit_avx2`]), to the bits
//! of the portable [`quad_hit_lanes`](super::quad_hit_lanes); x86-64 only (its parent declares
//! it so, once).

use std::arch::x86_64::*;

use glam::DVec3;

use crate::geometry::{PARALLEL_EPSILON, Quad};
use crate::render::fast::packet::{Directions, Lanes, WIDTH};
use crate::scene::{lanes_between, lanes_splat};

/// [`quad_hit_lanes`] for every quad of `quads` that `candidates` holds (bit `me`, every quad
/// from the 64th), in order, in AVX2 vectors: the same operations in the same order lane by
/// lane (IEEE operations round alike in a vector lane; nothing is fused), so the same `closest`
/// and `index`, bit for bit. The compiler turns [`quad_hit_lanes`]'s four lanes into two-lane
/// vectors and scalar compares; written with the intrinsics, the packet is one vector.
///
/// The directions are read in halves of two lanes: they were just written, and a 32-byte load
/// is not served from the smaller stores that wrote them (see `scene::accel::shape_lanes`).
///
/// # Safety
///
/// The processor must have AVX2.
#[target_feature(enable = "avx2")]
pub(in crate::render::fast::fixed_origin) unsafe fn quads_hit_avx2(
    quads: &[(Quad, f64)],
    candidates: u64,
    origin: DVec3,
    d: &Directions,
    min: f64,
    closest: &mut Lanes,
    index: &mut [u64; WIDTH],
) {
    // SAFETY: for every intrinsic below, AVX2 is there (this function's contract); each load and
    // store reads or writes two or four elements of an array of four.
    unsafe {
        let (dx, dy, dz) = (halves(&d.x), halves(&d.y), halves(&d.z));
        let (ox, oy, oz) = (
            lanes_splat(origin.x),
            lanes_splat(origin.y),
            lanes_splat(origin.z),
        );
        let (lo, zero, one) = (lanes_splat(min), _mm256_setzero_pd(), lanes_splat(1.0));
        let mut best = _mm256_loadu_pd(closest.as_ptr());
        let mut which = _mm256_castsi256_pd(_mm256_loadu_si256(index.as_ptr().cast()));
        for (me, (quad, offset)) in quads.iter().enumerate() {
            if me < 64 && (candidates >> me) & 1 == 0 {
                continue;
            }
            let (n, q, u, v, w) = (quad.normal, quad.q, quad.u, quad.v, quad.w);
            // `n.x d.x + n.y d.y + n.z d.z`, left to right.
            let denom = _mm256_add_pd(
                _mm256_add_pd(
                    _mm256_mul_pd(lanes_splat(n.x), dx),
                    _mm256_mul_pd(lanes_splat(n.y), dy),
                ),
                _mm256_mul_pd(lanes_splat(n.z), dz),
            );
            let t = _mm256_div_pd(lanes_splat(*offset), denom);
            let in_time = _mm256_and_pd(
                _mm256_cmp_pd::<_CMP_LE_OQ>(lo, t),
                _mm256_cmp_pd::<_CMP_LE_OQ>(t, best),
            );
            if _mm256_movemask_pd(in_time) == 0 {
                continue;
            }
            // `ray.at(t) - q`.
            let px = _mm256_sub_pd(_mm256_add_pd(ox, _mm256_mul_pd(dx, t)), lanes_splat(q.x));
            let py = _mm256_sub_pd(_mm256_add_pd(oy, _mm256_mul_pd(dy, t)), lanes_splat(q.y));
            let pz = _mm256_sub_pd(_mm256_add_pd(oz, _mm256_mul_pd(dz, t)), lanes_splat(q.z));
            // `w . (planar x v)` and `w . (u x planar)`, term by term as the scalar code.
            let p = [px, py, pz];
            let u = [lanes_splat(u.x), lanes_splat(u.y), lanes_splat(u.z)];
            let v = [lanes_splat(v.x), lanes_splat(v.y), lanes_splat(v.z)];
            let (alpha, beta) = (dot_cross(w, p, v), dot_cross(w, u, p));
            let magnitude = _mm256_andnot_pd(lanes_splat(-0.0), denom);
            let finite = _mm256_cmp_pd::<_CMP_LT_OQ>(
                _mm256_andnot_pd(lanes_splat(-0.0), t),
                lanes_splat(f64::INFINITY),
            );
            let hit = _mm256_and_pd(
                _mm256_and_pd(
                    _mm256_cmp_pd::<_CMP_GE_OQ>(magnitude, lanes_splat(PARALLEL_EPSILON)),
                    _mm256_and_pd(finite, in_time),
                ),
                _mm256_and_pd(
                    lanes_between::<false>(zero, alpha, one),
                    lanes_between::<false>(zero, beta, one),
                ),
            );
            best = _mm256_blendv_pd(best, t, hit);
            which = _mm256_blendv_pd(
                which,
                _mm256_castsi256_pd(_mm256_set1_epi64x(me as i64)),
                hit,
            );
        }
        _mm256_storeu_pd(closest.as_mut_ptr(), best);
        _mm256_storeu_si256(index.as_mut_ptr().cast(), _mm256_castpd_si256(which));
    }
}

/// The four lanes of `x`, read as two halves (see [`quads_hit_avx2`]).
///
/// # Safety
///
/// The processor must have AVX2.
#[inline(always)]
unsafe fn halves(x: &Lanes) -> __m256d {
    // SAFETY: AVX2 is there (this function's contract); each load reads two of the four.
    unsafe { _mm256_set_m128d(_mm_loadu_pd(x.as_ptr().add(2)), _mm_loadu_pd(x.as_ptr())) }
}

/// `w . (a x b)` lane by lane, as the scalar quad test computes it (glam's cross product term by
/// term, `w.x (a.y b.z - a.z b.y) + w.y (a.z b.x - a.x b.z) + w.z (a.x b.y - a.y b.x)`; a
/// product's operands commute exactly).
///
/// # Safety
///
/// The processor must have AVX2.
#[inline(always)]
unsafe fn dot_cross(w: DVec3, a: [__m256d; 3], b: [__m256d; 3]) -> __m256d {
    // SAFETY: AVX2 is there (this function's contract).
    unsafe {
        let x = _mm256_sub_pd(_mm256_mul_pd(a[1], b[2]), _mm256_mul_pd(a[2], b[1]));
        let y = _mm256_sub_pd(_mm256_mul_pd(a[2], b[0]), _mm256_mul_pd(a[0], b[2]));
        let z = _mm256_sub_pd(_mm256_mul_pd(a[0], b[1]), _mm256_mul_pd(a[1], b[0]));
        _mm256_add_pd(
            _mm256_add_pd(
                _mm256_mul_pd(lanes_splat(w.x), x),
                _mm256_mul_pd(lanes_splat(w.y), y),
            ),
            _mm256_mul_pd(lanes_splat(w.z), z),
        )
    }
}
