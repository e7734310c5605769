use glam::DVec3;

use super::{HitRecord, Interval, Ray, Shape, unit_vector};
use crate::arithmetic::{Decision, Dyadic, Iv, Line, PlaneKind, plane_decide};

/// The relative error bound of an edge function, generous (2^-48; the rounding unit is 2^-53).
const EDGE_ERROR: f64 = 3.552713678800501e-15;

const TINY: f64 = 3.054936363499605e-151; // 2^-500
const HUGE: f64 = 3.273390607896142e150; // 2^500

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
    ///
    /// A direction whose largest component is outside `2^-500 .. 2^500` is first scaled by a
    /// power of two (exact), so that `1 / d_z` neither overflows nor loses bits as a subnormal,
    /// and `t` is scaled back.
    #[inline]
    fn solve(&self, ray: &Ray, interval: Interval) -> Option<(f64, f64, f64)> {
        let big = ray.direction.abs().max_element();
        let (t, beta, gamma) = if (TINY..=HUGE).contains(&big) || !big.is_finite() || big == 0.0 {
            self.solve_unbounded(ray)?
        } else {
            let e = libm::ilogb(big);
            let d = ray.direction;
            let scaled = DVec3::new(
                libm::scalbn(d.x, -e),
                libm::scalbn(d.y, -e),
                libm::scalbn(d.z, -e),
            );
            let (t, beta, gamma) = self.solve_unbounded(&Ray::new(ray.origin, scaled))?;
            (libm::scalbn(t, -e), beta, gamma)
        };
        if !interval.contains(t) {
            return None;
        }
        Some((t, beta, gamma))
    }

    /// The watertight test without the interval check.
    #[inline]
    fn solve_unbounded(&self, ray: &Ray) -> Option<(f64, f64, f64)> {
        let d = ray.direction;
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
        let sx = d[kx] / dz;
        let sy = d[ky] / dz;

        let a = self.a - ray.origin;
        let b = self.b - ray.origin;
        let c = self.c - ray.origin;
        let (ax, ay) = (a[kx] - sx * a[kz], a[ky] - sy * a[kz]);
        let (bx, by) = (b[kx] - sx * b[kz], b[ky] - sy * b[kz]);
        let (cx, cy) = (c[kx] - sx * c[kz], c[ky] - sy * c[kz]);

        // Edge functions: U for edge bc, V for ca, W for ab.
        let u = cx * by - cy * bx;
        let v = ax * cy - ay * cx;
        let w = bx * ay - by * ax;
        // A generous bound on each edge function's rounding error (the shear, the products and
        // the difference): a sign inside its bound is not trusted.
        let m = |p: DVec3| {
            (
                p[kx].abs() + (sx * p[kz]).abs(),
                p[ky].abs() + (sy * p[kz]).abs(),
            )
        };
        let ((max, may), (mbx, mby), (mcx, mcy)) = (m(a), m(b), m(c));
        let bound = |p: f64, q: f64| EDGE_ERROR * p + EDGE_ERROR * q + 1e-300;
        let clear = [
            (u, bound(mcx * mby, mcy * mbx)),
            (v, bound(max * mcy, may * mcx)),
            (w, bound(mbx * may, mby * max)),
        ]
        .map(|(e, err)| {
            if e > err {
                1
            } else if e < -err {
                -1
            } else {
                0
            }
        });
        if clear.contains(&1) && clear.contains(&-1) {
            return None;
        }
        let det = u + v + w;
        if clear.contains(&0) || det == 0.0 || !det.is_finite() {
            // Too close to an edge (or over- or underflowing) for f64: decide exactly. Exact
            // edge tests are watertight too, and the same for every triangle sharing the edge.
            if !self.inside_exactly(ray) {
                return None;
            }
        }
        // The decision is watertight; `t` comes from the plane equation, as the course computes
        // it for quads (`(D - n.O) / n.d` with the unit normal): the sheared-space formula
        // `(u a_z + v b_z + w c_z) / det` loses all relative accuracy when the origin is very
        // near the plane, where this one keeps it.
        let t = (self.normal.dot(self.a) - self.normal.dot(ray.origin)) / self.normal.dot(d);
        if !t.is_finite() {
            return None;
        }
        let (beta, gamma) = if det != 0.0 && det.is_finite() {
            (v / det, w / det)
        } else {
            (0.0, 0.0)
        };
        Some((t, beta, gamma))
    }

    /// Whether the ray's line meets the closed triangle, decided exactly (big integers behind
    /// an interval filter, see [`crate::arithmetic`]).
    #[cold]
    fn inside_exactly(&self, ray: &Ray) -> bool {
        let finite = |v: DVec3| super::is_finite(v);
        let all_finite = [self.a, self.b, self.c, ray.origin, ray.direction]
            .into_iter()
            .all(finite);
        if !all_finite {
            return false;
        }
        let line = Line {
            origin: ray.origin.to_array(),
            direction: ray.direction.to_array(),
        };
        let all = [f64::NEG_INFINITY, f64::INFINITY];
        let (a, b, c) = (self.a.to_array(), self.b.to_array(), self.c.to_array());
        let decided = plane_decide::<Iv>(a, b, c, PlaneKind::Triangle, &line, all)
            .or_else(|| plane_decide::<Dyadic>(a, b, c, PlaneKind::Triangle, &line, all));
        matches!(decided, Some((Decision::PlaneHit, _)))
    }
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
}
