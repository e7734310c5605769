//! The renderer's fast path for a pinhole camera, where every primary ray leaves the same point.
//!
//! Whatever depends only on the origin and an object is computed once per render instead of once
//! per ray (a sphere's `origin - center` and `|origin - center|^2 - r^2`, a quad's
//! `d - normal . origin`, a triangle's vertices relative to the origin), and whatever depends only
//! on the direction is computed once per ray for all objects (`|d|^2`, the triangles' shear).
//! The decisions themselves are the very functions the shapes' [`Shape`](crate::geometry::Shape)
//! implementations call, fed the same values, so the closest hit is the same, bit for bit, as
//! [`Scene::closest`]'s (a test checks it on millions of rays).

use glam::DVec3;

use crate::geometry::{Interval, Quad, Ray};
use crate::geometry::{Shape, Sphere, Triangle, pick_root, roots_of};
use crate::scene::{Object, Scene};

/// The sphere pre-filter's margin, relative to `a (f . f + r2)`.
///
/// Before the robust roots (which cost a division, and a square root on a hit) the fast path
/// evaluates the naive discriminant `b'^2 - a c` and skips the sphere when it is below
/// `-PREFILTER_MARGIN a (f . f + r2)`. Both discriminants estimate the same exact value
/// `a r^2 - (a |f|^2 - b'^2)`, the naive one within about `15 eps a (|f|^2 + r^2)` and the robust one
/// within about `20 eps a (|f|^2 + r^2)` (`eps = 2^-53`; each term is bounded by
/// `a (|f|^2 + r^2)` since `b'^2 <= a |f|^2`). So a naive value below `-1e-12 a (|f|^2 + r^2)`, which
/// is some 4500 `eps` away, means the robust discriminant is negative too: the sphere is missed
/// either way and skipping it changes nothing. Any NaN or infinity makes the comparison false and
/// takes the robust path; so does `a` or `|f|^2 + r^2` outside `[1e-100, 1e100)`, where underflow
/// could make the relative bounds wrong.
const PREFILTER_MARGIN: f64 = 1e-12;
const SANE_MIN: f64 = 1e-100;
const SANE_MAX: f64 = 1e100;

/// A sphere's origin-dependent constants.
#[derive(Clone, Copy, Debug)]
struct PreparedSphere {
    /// The sphere itself, for the rare rays whose intermediates over- or underflow.
    sphere: Sphere,
    /// `origin - center`.
    f: DVec3,
    /// `radius^2`.
    r2: f64,
    /// `f . f - r2`.
    c: f64,
    /// `f . f + r2`, the scale of the discriminant's rounding errors, or NaN where the
    /// pre-filter is off (see [`PREFILTER_MARGIN`]).
    scale: f64,
}

impl PreparedSphere {
    fn new(sphere: &Sphere, origin: DVec3) -> Self {
        let f = origin - sphere.center;
        let r2 = sphere.radius * sphere.radius;
        let scale = f.dot(f) + r2;
        Self {
            sphere: *sphere,
            f,
            r2,
            c: f.dot(f) - r2,
            scale: if (SANE_MIN..SANE_MAX).contains(&scale) {
                scale
            } else {
                f64::NAN
            },
        }
    }

    /// The sphere's hit along `d` within `within`, given `a = d . d` and
    /// `a_margin = a * PREFILTER_MARGIN` (or NaN).
    #[inline(always)]
    fn hit_t(
        &self,
        origin: DVec3,
        d: DVec3,
        a: f64,
        a_margin: f64,
        within: Interval,
    ) -> Option<f64> {
        let half_b = self.f.dot(d);
        if half_b * half_b - a * self.c < -(a_margin * self.scale) {
            // A sure miss: see the pre-filter's note above.
            return None;
        }
        match roots_of(self.f, d, a, half_b, self.r2, self.c) {
            Ok(roots) => roots.and_then(|roots| pick_root(roots, within)),
            // Over- or underflow: the sphere's own path rescales.
            Err(()) => self.sphere.hit_t(&Ray::new(origin, d), within),
        }
    }
}

/// One object with its origin-dependent constants.
#[derive(Clone, Copy, Debug)]
enum Prepared {
    Sphere(PreparedSphere),
    Quad {
        quad: Quad,
        /// `quad.d - quad.normal . origin`.
        offset: f64,
    },
    /// Triangles take their own (watertight, exactly-decided near edges) path.
    Triangle(Triangle),
}

/// The objects, with the common cases of a scene of one kind stored without the enum, so the
/// closest-hit loop over them has no branch on the kind (the course's scenes are all spheres or
/// all quads). The order is kept either way.
#[derive(Clone, Debug)]
enum Layout {
    Spheres(Vec<PreparedSphere>),
    Quads(Vec<(Quad, f64)>),
    Mixed(Vec<Prepared>),
}

/// A scene prepared for rays from one origin.
#[derive(Clone, Debug)]
pub(crate) struct FixedOrigin {
    origin: DVec3,
    layout: Layout,
}

impl FixedOrigin {
    /// `scene` prepared for rays leaving `origin`.
    pub(crate) fn new(scene: &Scene, origin: DVec3) -> Self {
        let objects: Vec<Prepared> = scene
            .objects
            .iter()
            .map(|o| match o.shape {
                Object::Sphere(s) => Prepared::Sphere(PreparedSphere::new(&s, origin)),
                Object::Quad(quad) => Prepared::Quad {
                    quad,
                    offset: quad.plane_offset(origin),
                },
                Object::Triangle(t) => Prepared::Triangle(t),
            })
            .collect();
        let layout = if objects.iter().all(|o| matches!(o, Prepared::Sphere(_))) {
            Layout::Spheres(
                objects
                    .iter()
                    .filter_map(|o| match o {
                        Prepared::Sphere(s) => Some(*s),
                        _ => None,
                    })
                    .collect(),
            )
        } else if objects.iter().all(|o| matches!(o, Prepared::Quad { .. })) {
            Layout::Quads(
                objects
                    .iter()
                    .filter_map(|o| match o {
                        Prepared::Quad { quad, offset } => Some((*quad, *offset)),
                        _ => None,
                    })
                    .collect(),
            )
        } else {
            Layout::Mixed(objects)
        };
        Self { origin, layout }
    }

    /// The origin every ray leaves from.
    #[inline]
    pub(crate) fn origin(&self) -> DVec3 {
        self.origin
    }

    /// The closest hit's `t` and object index along direction `d`: the same answer as
    /// `scene.closest(&Ray::new(origin, d), interval)`.
    #[inline(always)]
    pub(crate) fn closest(&self, d: DVec3, interval: Interval) -> Option<(f64, usize)> {
        // Each layout has its own loop; the two homogeneous ones are inlined into the sample
        // loop, the mixed one is not (measured on the course's scenes).
        match &self.layout {
            Layout::Spheres(spheres) => Self::closest_sphere(self.origin, spheres, d, interval),
            Layout::Quads(quads) => self.closest_quad(quads, d, interval),
            Layout::Mixed(objects) => self.closest_mixed(objects, d, interval),
        }
    }

    /// `a * PREFILTER_MARGIN` for `a = d . d`, or NaN (pre-filter off) unless `a` is far from
    /// overflow and underflow.
    #[inline(always)]
    fn margin(a: f64) -> f64 {
        if (SANE_MIN..SANE_MAX).contains(&a) {
            a * PREFILTER_MARGIN
        } else {
            f64::NAN
        }
    }

    #[inline(always)]
    fn closest_sphere(
        origin: DVec3,
        spheres: &[PreparedSphere],
        d: DVec3,
        interval: Interval,
    ) -> Option<(f64, usize)> {
        let a = d.dot(d);
        let a_margin = Self::margin(a);
        let mut best = None;
        let mut closest = interval.max;
        for (index, sphere) in spheres.iter().enumerate() {
            let within = Interval::new(interval.min, closest);
            if let Some(t) = sphere.hit_t(origin, d, a, a_margin, within) {
                closest = t;
                best = Some((t, index));
            }
        }
        best
    }

    #[inline(always)]
    fn closest_quad(
        &self,
        quads: &[(Quad, f64)],
        d: DVec3,
        interval: Interval,
    ) -> Option<(f64, usize)> {
        let ray = Ray::new(self.origin, d);
        let mut best = None;
        let mut closest = interval.max;
        for (index, (quad, offset)) in quads.iter().enumerate() {
            let within = Interval::new(interval.min, closest);
            if let Some((t, _, _)) = quad.solve_from(&ray, *offset, within) {
                closest = t;
                best = Some((t, index));
            }
        }
        best
    }

    #[inline(never)]
    fn closest_mixed(
        &self,
        objects: &[Prepared],
        d: DVec3,
        interval: Interval,
    ) -> Option<(f64, usize)> {
        let ray = Ray::new(self.origin, d);
        let a = d.dot(d);
        let a_margin = Self::margin(a);
        let mut best = None;
        let mut closest = interval.max;
        for (index, object) in objects.iter().enumerate() {
            let within = Interval::new(interval.min, closest);
            let t = match *object {
                Prepared::Sphere(ref sphere) => sphere.hit_t(self.origin, d, a, a_margin, within),
                Prepared::Quad { ref quad, offset } => {
                    quad.solve_from(&ray, offset, within).map(|(t, _, _)| t)
                }
                Prepared::Triangle(ref triangle) => triangle.hit_t(&ray, within),
            };
            if let Some(t) = t {
                closest = t;
                best = Some((t, index));
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::PixelSampler;
    use crate::scene::BUILTIN_SCENES;

    /// Every built-in scene, from its camera's eye, over rays through (and far beyond) the image,
    /// plus rays aimed at object features (centres, corners, edges, vertices) where ties and
    /// boundaries live: the fast path answers exactly as `Scene::closest`.
    #[test]
    fn agrees_with_the_scene_bit_for_bit() {
        let mut checked = 0usize;
        for builtin in BUILTIN_SCENES {
            let description = builtin.description();
            let scene = description.scene();
            let camera = description.camera(Some(64));
            let fast = FixedOrigin::new(&scene, camera.center);
            let mut rng = PixelSampler::new(11, checked as u64);
            let mut targets: Vec<DVec3> = Vec::new();
            for _ in 0..250_000 {
                // Positions over three times the image in each direction.
                let x = (rng.next_f64() * 3.0 - 1.0) * camera.width as f64;
                let y = (rng.next_f64() * 3.0 - 1.0) * camera.height as f64;
                targets.push(camera.pixel00 + x * camera.pixel_delta_u + y * camera.pixel_delta_v);
            }
            for o in &scene.objects {
                match o.shape {
                    Object::Sphere(s) => {
                        targets.push(s.center);
                        // The silhouette seen from the eye (tangent rays) and just inside and outside
                        // it, where the pre-filter and the robust discriminant are closest to 0.
                        for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
                            for k in [0.0, 1e-15, -1e-15, 1e-12, -1e-12, 1e-9, -1e-9, 1e-6] {
                                targets.push(s.center + axis * s.radius * (1.0 + k));
                                targets.push(s.center - axis * s.radius * (1.0 + k));
                            }
                        }
                    }
                    Object::Quad(q) => {
                        for (a, b) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0), (0.5, 0.0)] {
                            targets.push(q.q + a * q.u + b * q.v);
                        }
                    }
                    Object::Triangle(t) => {
                        targets.extend([t.a, t.b, t.c, (t.a + t.b) * 0.5, (t.b + t.c) * 0.5]);
                    }
                }
            }
            for target in targets {
                let d = target - camera.center;
                let ray = Ray::new(camera.center, d);
                let expected = scene.closest(&ray, Interval::CAMERA);
                let got = fast.closest(d, Interval::CAMERA);
                assert_eq!(
                    got.map(|(t, i)| (t.to_bits(), i)),
                    expected.map(|(t, i)| (t.to_bits(), i)),
                    "{} along {d}",
                    builtin.name
                );
                checked += 1;
            }
        }
        assert!(checked > 1_000_000);
    }

    /// Degenerate and non-finite directions take the same (missing) path in both.
    #[test]
    fn agrees_on_degenerate_directions() {
        let description = crate::scene::builtin("triangles").unwrap();
        let scene = description.scene();
        let origin = DVec3::new(0.0, 0.0, 6.0);
        let fast = FixedOrigin::new(&scene, origin);
        for d in [
            DVec3::ZERO,
            DVec3::new(f64::NAN, 0.0, -1.0),
            DVec3::new(0.0, f64::INFINITY, -1.0),
            DVec3::new(1e-300, 0.0, 0.0),
            DVec3::new(0.0, 0.0, -1e300),
        ] {
            let expected = scene.closest(&Ray::new(origin, d), Interval::CAMERA);
            assert_eq!(
                fast.closest(d, Interval::CAMERA)
                    .map(|(t, i)| (t.to_bits(), i)),
                expected.map(|(t, i)| (t.to_bits(), i)),
                "{d}"
            );
        }
    }
}
