use glam::DVec3;

use super::{HitRecord, Interval, Ray, Shape, unit_vector};

/// A triangle `(a, b, c)` intersected watertightly (Woop, Benthin and Wald, JCGT 2013).
///
/// The ray is moved to the origin and sheared so that it runs along +z; the three edge functions
/// are then 2D cross products of the transformed vertices. An edge shared by two triangles yields
/// the exact negation of the same floating-point value in both, so a ray through the edge hits at
/// least one of them. Edges are closed (an edge function of zero counts as inside); both faces are
/// hit; `t` must lie in the *closed* interval, as for quads.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    /// The first vertex.
    pub a: DVec3,
    /// The second vertex.
    pub b: DVec3,
    /// The third vertex.
    pub c: DVec3,
    /// `unit((b - a) x (c - a))`.
    pub normal: DVec3,
}

impl Triangle {
    /// A triangle with vertices `a`, `b`, `c` (counter-clockwise seen from the normal's side).
    pub fn new(a: DVec3, b: DVec3, c: DVec3) -> Self {
        Self {
            a,
            b,
            c,
            normal: unit_vector((b - a).cross(c - a)),
        }
    }

    /// The watertight decision with `(t, beta, gamma)`, the barycentric weights of `b` and `c`.
    #[inline]
    fn solve(&self, ray: &Ray, interval: Interval) -> Option<(f64, f64, f64)> {
        let shear = Shear::of(ray.direction)?;
        solve_sheared(
            self.a - ray.origin,
            self.b - ray.origin,
            self.c - ray.origin,
            &shear,
            interval,
        )
    }
}

/// The per-ray part of the watertight test: the axis permutation that makes the direction's
/// largest component z, and the shear that maps the direction onto +z. It depends only on the
/// direction, so the renderer computes it once per ray for all triangles.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Shear {
    kx: usize,
    ky: usize,
    kz: usize,
    sx: f64,
    sy: f64,
    sz: f64,
}

impl Shear {
    /// The shear of direction `d`, or `None` when `d` has no usable largest component (zero or
    /// not finite), in which case no triangle is hit.
    #[inline]
    pub(crate) fn of(d: DVec3) -> Option<Shear> {
        let ad = d.abs();
        // The axis along which the direction is largest becomes z.
        let kz = if ad.x > ad.y {
            if ad.x > ad.z { 0 } else { 2 }
        } else if ad.y > ad.z {
            1
        } else {
            2
        };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        // Keep the winding: swap when the direction points down the z axis.
        if d[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let dz = d[kz];
        if dz == 0.0 || !dz.is_finite() {
            return None;
        }
        Some(Shear {
            kx,
            ky,
            kz,
            sx: d[kx] / dz,
            sy: d[ky] / dz,
            sz: 1.0 / dz,
        })
    }
}

/// The watertight decision for the vertices relative to the ray's origin (`a - origin`, ...)
/// under the ray's `shear`. [`Triangle`]'s `intersect` and the renderer's fixed-origin fast path
/// (which subtracts the origin once per render) both call it, so they agree bit for bit.
#[inline(always)]
pub(crate) fn solve_sheared(
    a: DVec3,
    b: DVec3,
    c: DVec3,
    shear: &Shear,
    interval: Interval,
) -> Option<(f64, f64, f64)> {
    let Shear {
        kx,
        ky,
        kz,
        sx,
        sy,
        sz,
    } = *shear;
    let (ax, ay) = (a[kx] - sx * a[kz], a[ky] - sy * a[kz]);
    let (bx, by) = (b[kx] - sx * b[kz], b[ky] - sy * b[kz]);
    let (cx, cy) = (c[kx] - sx * c[kz], c[ky] - sy * c[kz]);

    // Edge functions: U for edge bc, V for ca, W for ab.
    let u = cx * by - cy * bx;
    let v = ax * cy - ay * cx;
    let w = bx * ay - by * ax;
    let negative = u < 0.0 || v < 0.0 || w < 0.0;
    let positive = u > 0.0 || v > 0.0 || w > 0.0;
    if (negative && positive) || u.is_nan() || v.is_nan() || w.is_nan() {
        return None;
    }
    let det = u + v + w;
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let (az, bz, cz) = (sz * a[kz], sz * b[kz], sz * c[kz]);
    let t = (u * az + v * bz + w * cz) / det;
    if !interval.contains(t) {
        return None;
    }
    Some((t, v / det, w / det))
}

impl Shape for Triangle {
    #[inline]
    fn intersect(&self, ray: &Ray, interval: Interval) -> Option<HitRecord> {
        let (t, beta, gamma) = self.solve(ray, interval)?;
        if !self.normal.is_finite() {
            return None;
        }
        Some(HitRecord::new(ray, t, self.normal, (beta, gamma)))
    }

    #[inline]
    fn hit_t(&self, ray: &Ray, interval: Interval) -> Option<f64> {
        self.intersect(ray, interval).map(|h| h.t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri() -> Triangle {
        Triangle::new(
            DVec3::new(0.0, 0.0, -1.0),
            DVec3::new(1.0, 0.0, -1.0),
            DVec3::new(0.0, 1.0, -1.0),
        )
    }

    #[test]
    fn interior_hit_has_barycentrics() {
        let ray = Ray::new(DVec3::new(0.25, 0.5, 0.0), DVec3::new(0.0, 0.0, -1.0));
        let hit = tri().intersect(&ray, Interval::CAMERA).unwrap();
        assert_eq!(hit.t, 1.0);
        assert_eq!(hit.uv, (0.25, 0.5));
        assert!(hit.front_face);
    }

    #[test]
    fn vertices_and_edges_are_closed_and_outside_misses() {
        let down = DVec3::new(0.0, 0.0, -1.0);
        for p in [
            DVec3::ZERO,
            DVec3::X,
            DVec3::Y,
            DVec3::new(0.5, 0.5, 0.0),
            DVec3::new(0.5, 0.0, 0.0),
        ] {
            assert!(
                tri()
                    .intersect(&Ray::new(p, down), Interval::CAMERA)
                    .is_some(),
                "{p}"
            );
        }
        let out = Ray::new(DVec3::new(0.6, 0.6, 0.0), down);
        assert!(tri().intersect(&out, Interval::CAMERA).is_none());
    }

    #[test]
    fn back_face_is_hit_with_flipped_normal() {
        let ray = Ray::new(DVec3::new(0.25, 0.25, -2.0), DVec3::new(0.0, 0.0, 1.0));
        let hit = tri().intersect(&ray, Interval::CAMERA).unwrap();
        assert!(!hit.front_face);
        assert_eq!(hit.normal, DVec3::new(0.0, 0.0, -1.0));
    }

    /// A small deterministic generator for the tests (SplitMix64), uniform in `[lo, hi)`.
    struct Gen(u64);
    impl Gen {
        fn next(&mut self, lo: f64, hi: f64) -> f64 {
            self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^= z >> 31;
            lo + (hi - lo) * ((z >> 11) as f64 / (1u64 << 53) as f64)
        }
        fn vec(&mut self, lo: f64, hi: f64) -> DVec3 {
            DVec3::new(self.next(lo, hi), self.next(lo, hi), self.next(lo, hi))
        }
    }

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs()))
    }

    /// A ray aimed at `a + beta (b - a) + gamma (c - a)` hits there at t = 1 with barycentrics
    /// `(beta, gamma)`, from either side.
    #[test]
    fn aimed_rays_hit_where_they_are_aimed() {
        let mut g = Gen(3);
        for _ in 0..10_000 {
            let t = Triangle::new(g.vec(-10.0, 10.0), g.vec(-10.0, 10.0), g.vec(-10.0, 10.0));
            if !t.normal.is_finite() {
                continue;
            }
            let (mut beta, mut gamma) = (g.next(0.01, 0.98), g.next(0.01, 0.98));
            if beta + gamma > 0.99 {
                (beta, gamma) = (0.99 - beta, 0.99 - gamma);
            }
            let p = t.a + beta * (t.b - t.a) + gamma * (t.c - t.a);
            let side = if g.next(0.0, 1.0) < 0.5 { 1.0 } else { -1.0 };
            let origin = p + (t.normal * side + g.vec(-0.5, 0.5)) * g.next(0.5, 20.0);
            let ray = Ray::new(origin, p - origin);
            if t.normal.dot(ray.direction).abs() < 1e-2 * ray.direction.length() {
                continue;
            }
            let hit = t.intersect(&ray, Interval::CAMERA).unwrap();
            assert!(close(hit.t, 1.0, 1e-8), "{}", hit.t);
            assert!(
                close(hit.uv.0, beta, 1e-6) && close(hit.uv.1, gamma, 1e-6),
                "{:?} vs ({beta}, {gamma})",
                hit.uv
            );
        }
    }

    /// Two coplanar triangles sharing an edge: a ray through any point of the edge hits at least
    /// one of them (watertightness), from random origins on both sides.
    #[test]
    fn rays_through_a_shared_edge_hit_one_of_the_triangles() {
        let mut g = Gen(4);
        for _ in 0..2_000 {
            let (p, q) = (g.vec(-5.0, 5.0), g.vec(-5.0, 5.0));
            let first = Triangle::new(p, q, g.vec(-5.0, 5.0));
            // The other apex across the edge, in the same plane (two faces of a fold seen from
            // outside can both project to one side of the edge: a ray grazing the fold can then
            // rightly pass beside both).
            let across = first.a + first.b - first.c + (first.b - first.a) * g.next(-0.5, 0.5);
            let second = Triangle::new(q, p, across);
            for _ in 0..20 {
                let s = g.next(0.001, 0.999);
                let on_edge = p + s * (q - p);
                let origin = on_edge + g.vec(-10.0, 10.0);
                let ray = Ray::new(origin, on_edge - origin);
                let hits = first
                    .intersect(&ray, Interval::new(0.0, f64::MAX))
                    .is_some()
                    || second
                        .intersect(&ray, Interval::new(0.0, f64::MAX))
                        .is_some();
                assert!(hits, "a ray through {on_edge} fell between the triangles");
            }
        }
    }
}
