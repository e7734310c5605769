//! The fast path of a pinhole camera (no defocus, so every primary ray leaves the camera's
//! centre): a pixel's samples in packets of [`WIDTH`], one array per coordinate, through the
//! scene prepared for that origin ([`FixedOrigin`]).
//!
//! It promises the film of the general path (`Trace for Scene`), bit for bit: each lane does the
//! general path's operations in its order (the camera's `pixel00 + x du + y dv - centre`, the
//! closest hit, the course's sky from `unit(d).y`), vector lanes round as scalars do and nothing
//! is fused, and the samples are accumulated one at a time in their order.
//! `renderer::tests::packets_render_the_general_paths_film` checks it.

use glam::DVec3;

use crate::geometry::Interval;
use crate::render::PixelSampler;
use crate::render::fast::fixed_origin::{ALL_CANDIDATES, Candidates, Cone, FixedOrigin};
use crate::render::fast::packet::{Directions, NO_HIT, WIDTH};
use crate::render::job::{Job, Moments, Spread, Trace};
use crate::scene::{Camera, Scene};

/// The cone from the camera's centre that holds every direction the samples of pixel `(i, j)`
/// can take, or `None` when it is too wide to be worth it or the rounding too large to bound.
///
/// A sample's position is `x = i + ox`, `y = j + oy` with offsets in `[-0.5, 0.5]` (every jitter
/// draws them there, and rounding the sum cannot leave the closed square), so its exact
/// direction `pixel00 + x du + y dv - centre` lies in the parallelogram of the square's corners,
/// and inside the round cone around the centre's direction through the farthest corner (a round
/// cone of half-angle below 90 degrees is convex). The computed direction is off that by at most
/// `E = 2^-50 (|pixel00| + (|i| + 1/2) |du| + (|j| + 1/2) |dv| + |centre|)` per coordinate (four
/// roundings of `2^-53` each, with room to spare), which turns it by at most `2 |E| / h`, `h`
/// being the distance from the centre to the image plane; the corners themselves are computed,
/// so that is counted twice.
fn footprint(camera: &Camera, i: usize, j: usize) -> Option<Cone> {
    let (p, du, dv, c) = (
        camera.pixel00,
        camera.pixel_delta_u,
        camera.pixel_delta_v,
        camera.center,
    );
    let (x, y) = (i as f64, j as f64);
    let at = |x: f64, y: f64| p + x * du + y * dv - c;
    let centre = at(x, y);
    let corners = [
        at(x - 0.5, y - 0.5),
        at(x + 0.5, y - 0.5),
        at(x - 0.5, y + 0.5),
        at(x + 0.5, y + 0.5),
    ];
    let error = 2f64.powi(-50) * (p.abs() + (x + 0.5) * du.abs() + (y + 0.5) * dv.abs() + c.abs())
        + DVec3::splat(1e-300);
    let error = error.length();
    // A lower bound of that distance: the computed normal is off by a few `2^-53` relative,
    // which `1e-12` covers while `|centre| < 1000 h`.
    let height = centre.dot(du.cross(dv).normalize()).abs() * (1.0 - 1e-12) - error;
    if !(height > 0.0 && error / height < 1e-3 && centre.length() < 1e3 * height) {
        return None;
    }
    let axis = centre.normalize();
    let angle = |d: DVec3| axis.cross(d).length().atan2(axis.dot(d));
    let widest = corners.map(angle).into_iter().fold(0.0, f64::max);
    let half_angle = widest + 4.0 * error / height + 1e-12;
    let longest = corners.map(DVec3::length).into_iter().fold(0.0, f64::max) + 2.0 * error;
    let cone = Cone {
        axis,
        half_angle,
        length2_min: (height - error) * (height - error) * (1.0 - 1e-9),
        length2_max: longest * longest * (1.0 + 1e-9),
    };
    (axis.is_finite() && half_angle.is_finite() && half_angle <= 1.0 && longest.is_finite())
        .then_some(cone)
}

/// A scene prepared for rays from one origin, with each object's albedo.
pub(in crate::render) struct Pinhole {
    prepared: FixedOrigin,
    /// Each object's albedo, with a fourth lane of zero.
    albedos: Vec<[f64; 4]>,
}

impl Pinhole {
    /// `scene` prepared for rays leaving `origin`.
    pub(in crate::render) fn new(scene: &Scene, origin: DVec3) -> Self {
        Self {
            prepared: FixedOrigin::new(scene, origin),
            albedos: (0..scene.objects.len())
                .map(|index| {
                    let a = scene.material_of(index).albedo();
                    [a.x, a.y, a.z, 0.0]
                })
                .collect(),
        }
    }

    /// The colours of a packet of samples of `PIXELS` pixels (1 or 2, [`WIDTH`] / `PIXELS`
    /// lanes each): for each pixel `pixels[p]`, its samples `first..first + count` (`count` at
    /// most its lanes; the lanes past it repeat its first lane's ray and are not to be used),
    /// their offsets drawn from `samplers[p]` in order.
    #[inline(always)]
    // Lane loops index several arrays in step.
    #[allow(clippy::needless_range_loop)]
    fn packet<const JITTER: u8, const PIXELS: usize>(
        &self,
        job: &Job<'_, Self>,
        samplers: &mut [PixelSampler; PIXELS],
        pixels: [(usize, usize); PIXELS],
        first: u32,
        count: usize,
        candidates: Candidates,
    ) -> [[f64; 4]; WIDTH] {
        let camera = job.camera;
        let per = WIDTH / PIXELS;
        let mut x = [0.0; WIDTH];
        let mut y = [0.0; WIDTH];
        for k in 0..WIDTH {
            let (pixel, lane) = (k / per, k % per);
            if lane < count {
                let (ox, oy) = job.offsets::<JITTER>(&mut samplers[pixel], first + lane as u32);
                let (i, j) = pixels[pixel];
                (x[k], y[k]) = (i as f64 + ox, j as f64 + oy);
            } else {
                (x[k], y[k]) = (x[pixel * per], y[pixel * per]);
            }
        }
        let (p, du, dv, c) = (
            camera.pixel00,
            camera.pixel_delta_u,
            camera.pixel_delta_v,
            camera.center,
        );
        // One loop per coordinate, so that each becomes vector operations across the lanes.
        let mut d = Directions::default();
        for k in 0..WIDTH {
            d.x[k] = p.x + x[k] * du.x + y[k] * dv.x - c.x;
        }
        for k in 0..WIDTH {
            d.y[k] = p.y + x[k] * du.y + y[k] * dv.y - c.y;
        }
        for k in 0..WIDTH {
            d.z[k] = p.z + x[k] * du.z + y[k] * dv.z - c.z;
        }
        let index = self
            .prepared
            .closest_packet(&d, Interval::CAMERA, candidates);
        // The sky of every lane (`sky_height` and `sky_at`), then the albedo where a lane hit.
        let mut a = [0.0; WIDTH];
        for k in 0..WIDTH {
            let length = (d.x[k] * d.x[k] + d.y[k] * d.y[k] + d.z[k] * d.z[k]).sqrt();
            a[k] = 0.5 * (d.y[k] / length + 1.0);
        }
        let mut colours = [[0.0; 4]; WIDTH];
        for k in 0..WIDTH {
            let a = a[k];
            let sky = [
                (1.0 - a) + a * 0.5,
                (1.0 - a) + a * 0.7,
                (1.0 - a) + a * 1.0,
                0.0,
            ];
            colours[k] = if index[k] == NO_HIT {
                sky
            } else {
                self.albedos[index[k] as usize]
            };
        }
        colours
    }
}

/// One pixel's place in a row: its index, its footprint's candidates, and the object that
/// covers it, if one does.
#[derive(Clone, Copy, Debug)]
struct Pixel {
    i: usize,
    candidates: Candidates,
    covering: Option<usize>,
}

impl Pinhole {
    /// Pixel `(i, j)`'s candidates and covering object.
    fn pixel(&self, camera: &Camera, i: usize, j: usize) -> Pixel {
        let cone = footprint(camera, i, j);
        let candidates = cone.map_or(ALL_CANDIDATES, |cone| self.prepared.candidates(&cone));
        Pixel {
            i,
            candidates,
            covering: cone.and_then(|cone| self.prepared.covering(&cone, candidates)),
        }
    }

    /// Renders `PIXELS` pixels of row `j` side by side (each with its own stream and sums, so
    /// two pixels' chains of dependent operations, the random streams' and Welford's divisions,
    /// run at once), into `means[p]` and (when `VARIANCE`) `variances[p]`.
    #[inline(always)]
    fn pixels<const VARIANCE: bool, const JITTER: u8, const PIXELS: usize>(
        job: &Job<'_, Self>,
        j: usize,
        pixels: [Pixel; PIXELS],
        means: [&mut DVec3; PIXELS],
        mut variances: [Option<&mut Spread>; PIXELS],
    ) {
        let (width, spp) = (job.camera.width, job.spp);
        let per = WIDTH / PIXELS;
        let candidates = pixels.iter().fold(0, |all, p| all | p.candidates);
        let places = pixels.map(|p| (p.i, j));
        let mut samplers = pixels.map(|p| PixelSampler::new(job.seed, (j * width + p.i) as u64));
        // A first packet starts the sums, full packets follow (loops of a fixed length), then
        // a last, partial one.
        let count = (spp as usize).min(per);
        let colours =
            job.tracer
                .packet::<JITTER, PIXELS>(job, &mut samplers, places, 0, count, candidates);
        let mut moments: [Moments; PIXELS] =
            std::array::from_fn(|p| Moments::new(colours[p * per]));
        let add = |moments: &mut [Moments; PIXELS],
                   colours: &[[f64; 4]; WIDTH],
                   first: u32,
                   count: usize| {
            for (p, moments) in moments.iter_mut().enumerate() {
                for lane in 0..count {
                    moments.add::<VARIANCE>(colours[p * per + lane], first + lane as u32);
                }
            }
        };
        add(&mut moments, &colours, 0, count);
        let mut first = count as u32;
        while first + per as u32 <= spp {
            let colours = job.tracer.packet::<JITTER, PIXELS>(
                job,
                &mut samplers,
                places,
                first,
                per,
                candidates,
            );
            add(&mut moments, &colours, first, per);
            first += per as u32;
        }
        if first < spp {
            let count = (spp - first) as usize;
            let colours = job.tracer.packet::<JITTER, PIXELS>(
                job,
                &mut samplers,
                places,
                first,
                count,
                candidates,
            );
            add(&mut moments, &colours, first, count);
        }
        for ((moments, mean), variance) in moments.iter().zip(means).zip(variances.iter_mut()) {
            moments.store::<VARIANCE>(spp, mean, variance.as_deref_mut());
        }
    }
}

impl Trace for Pinhole {
    /// Pixels two at a time, except those an object covers (that object's albedo, no sample
    /// drawn) and a last one left alone.
    #[inline(always)]
    fn row<const VARIANCE: bool, const JITTER: u8>(
        job: &Job<'_, Self>,
        j: usize,
        means: &mut [DVec3],
        variances: &mut [Spread],
    ) {
        let width = job.camera.width;
        let pinhole = job.tracer;
        // The pixels not covered, rendered `GROUP` at a time, then the rest in smaller groups.
        let mut waiting: Vec<Pixel> = Vec::with_capacity(GROUP);
        for i in 0..width {
            let pixel = pinhole.pixel(job.camera, i, j);
            if let Some(me) = pixel.covering {
                // Every sample is that object's albedo: the mean is that colour exactly, and
                // Welford's sums of equal values stay zero (`c (c - c) = 0`, then `delta = 0`).
                let [x, y, z, _] = pinhole.albedos[me];
                means[i] = DVec3::new(x, y, z);
                if VARIANCE {
                    variances[i] = Spread::ZERO;
                }
                continue;
            }
            waiting.push(pixel);
            if waiting.len() == GROUP {
                Self::group::<VARIANCE, JITTER, GROUP>(job, j, &waiting, means, variances);
                waiting.clear();
            }
        }
        let mut rest = &waiting[..];
        while !rest.is_empty() {
            rest = match rest.len() {
                1 => {
                    Self::group::<VARIANCE, JITTER, 1>(job, j, rest, means, variances);
                    &[]
                }
                _ => {
                    Self::group::<VARIANCE, JITTER, 2>(job, j, &rest[..2], means, variances);
                    &rest[2..]
                }
            };
        }
    }
}

/// How many pixels are rendered side by side: each has its own random stream and sums, so the
/// chains of dependent operations of that many pixels (the streams' multiplications, Welford's
/// divisions) run at once.
const GROUP: usize = 2;

impl Pinhole {
    /// [`Self::pixels`] for the `PIXELS` pixels `group` of row `j`, into their places in the
    /// row's `means` and `variances`.
    #[inline(always)]
    fn group<const VARIANCE: bool, const JITTER: u8, const PIXELS: usize>(
        job: &Job<'_, Self>,
        j: usize,
        group: &[Pixel],
        means: &mut [DVec3],
        variances: &mut [Spread],
    ) {
        let pixels: [Pixel; PIXELS] = std::array::from_fn(|p| group[p]);
        let mut group_means = [DVec3::ZERO; PIXELS];
        let mut group_variances = [Spread::ZERO; PIXELS];
        {
            let mean_refs = group_means.each_mut();
            let variance_refs = group_variances.each_mut().map(Some);
            Self::pixels::<VARIANCE, JITTER, PIXELS>(job, j, pixels, mean_refs, variance_refs);
        }
        for (p, pixel) in pixels.iter().enumerate() {
            means[pixel.i] = group_means[p];
            if VARIANCE {
                variances[pixel.i] = group_variances[p];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Quad, Sphere, Triangle};
    use crate::render::PixelJitter;
    use crate::render::job::film_bits;
    use crate::scene::{CameraSettings, Material, Object, SceneObject, World};

    /// A random scene made to test the footprints: spheres and triangles of every size from a
    /// fraction of a pixel to wider than the image, many with an edge or a silhouette through
    /// the image, some behind the camera, one around it now and then, and a quad sometimes;
    /// seen by a random camera, often far from the world's origin.
    fn random_scene(sampler: &mut PixelSampler) -> (Scene, Camera) {
        let mut u = |lo: f64, hi: f64| lo + (hi - lo) * sampler.next_f64();
        let far = if u(0.0, 1.0) < 0.5 {
            0.0
        } else {
            10f64.powf(u(0.0, 5.0))
        };
        let look_from = DVec3::new(u(-1.0, 1.0), u(-1.0, 1.0), u(-1.0, 1.0)) + DVec3::splat(far);
        let forward = DVec3::new(u(-1.0, 1.0), u(-1.0, 1.0), u(-1.0, 1.0)).normalize();
        let settings = CameraSettings {
            look_from: look_from.to_array(),
            look_at: (look_from + forward).to_array(),
            up: [u(-0.3, 0.3), 1.0, u(-0.3, 0.3)],
            vfov: u(5.0, 120.0),
            focus_distance: u(0.5, 20.0),
            defocus_angle: 0.0,
        };
        let camera = Camera::new(&settings, 12, u(0.7, 1.6));
        // A point of the image plane (at the focus distance) seen through pixel (x, y),
        // moved along its ray by `depth` (negative: behind the camera).
        let through = |x: f64, y: f64, depth: f64| {
            let on_plane = camera.pixel00 + x * camera.pixel_delta_u + y * camera.pixel_delta_v;
            camera.center + (on_plane - camera.center) * depth
        };
        let pixel = camera.pixel_delta_u.length();
        let mut objects = Vec::new();
        let count = u(1.0, 5.0) as usize;
        for n in 0..count {
            let (x, y) = (u(-2.0, 14.0), u(-2.0, 12.0));
            // Often exactly on a pixel's corner or edge.
            let (x, y) = if u(0.0, 1.0) < 0.4 {
                (x.round() - 0.5, y.round() - 0.5)
            } else {
                (x, y)
            };
            let depth = if u(0.0, 1.0) < 0.1 {
                -u(0.2, 3.0)
            } else {
                u(0.2, 3.0)
            };
            let size = pixel * depth.abs() * 10f64.powf(u(-1.0, 1.5));
            let centre = through(x, y, depth);
            let shape = match (n + (u(0.0, 3.0) as usize)) % 5 {
                0 if u(0.0, 1.0) < 0.15 => Object::Quad(Quad::new(
                    centre,
                    camera.pixel_delta_u * u(1.0, 6.0) * depth,
                    camera.pixel_delta_v * u(1.0, 6.0) * depth,
                )),
                0 | 1 => Object::Sphere(Sphere::new(centre, size)),
                2 if u(0.0, 1.0) < 0.1 => Object::Sphere(Sphere::new(camera.center, size)),
                _ => {
                    let corner = |sampler_x: f64, sampler_y: f64| {
                        through(
                            x + sampler_x,
                            y + sampler_y,
                            depth * (1.0 + 0.2 * sampler_x),
                        )
                    };
                    let spread = 10f64.powf(u(-0.5, 1.2));
                    Object::Triangle(Triangle::new(
                        corner(u(-1.0, 1.0) * spread, u(-1.0, 1.0) * spread),
                        corner(u(-1.0, 1.0) * spread, u(-1.0, 1.0) * spread),
                        corner(u(-1.0, 1.0) * spread, u(-1.0, 1.0) * spread),
                    ))
                }
            };
            objects.push(SceneObject { shape, material: n });
        }
        let materials = (0..count)
            .map(|n| Material::Lambertian {
                albedo: DVec3::new(0.1 * n as f64, 0.5, 1.0 - 0.1 * n as f64),
            })
            .collect();
        (Scene { objects, materials }, camera)
    }

    /// The pinhole path (footprint culling, covered pixels, pixels in pairs) renders the film the
    /// general path renders one ray at a time through `Scene::closest`, bit for bit, over random
    /// scenes whose objects straddle pixels; and the scenes do exercise the culling and the
    /// covering (a check that the test tests something).
    #[test]
    fn footprints_keep_the_film_of_the_general_path() {
        let mut sampler = PixelSampler::new(11, 3);
        let (mut culled, mut covered, mut pixels) = (0, 0, 0);
        for scene_number in 0..3000 {
            let (scene, camera) = random_scene(&mut sampler);
            let pinhole = Pinhole::new(&scene, camera.center);
            for j in 0..camera.height {
                for i in 0..camera.width {
                    let pixel = pinhole.pixel(&camera, i, j);
                    let all = (1 << scene.objects.len()) - 1;
                    culled += usize::from(pixel.candidates & all != all);
                    covered += usize::from(pixel.covering.is_some());
                    pixels += 1;
                }
            }
            let jitter = [
                PixelJitter::Uniform,
                PixelJitter::Stratified,
                PixelJitter::Centre,
            ][scene_number % 3];
            let spp = [1, 2, 3, 5, 8, 13][scene_number % 6];
            let world = World::from(scene.clone());
            let general = Job::new(&world, &camera, spp, scene_number as u64, jitter);
            let fast = Job::new(&pinhole, &camera, spp, scene_number as u64, jitter);
            assert_eq!(
                film_bits(&fast),
                film_bits(&general),
                "scene {scene_number}: {scene:?} {camera:?}"
            );
        }
        assert!(culled * 5 > pixels, "{culled} of {pixels} pixels culled");
        assert!(
            covered * 40 > pixels,
            "{covered} of {pixels} pixels covered"
        );
    }

    /// Every sample of a pixel lies in its footprint's cone: the rays the renderer draws, at
    /// random offsets and at the square's very corners, against the cone's angle and lengths.
    #[test]
    fn footprints_hold_their_samples() {
        let mut sampler = PixelSampler::new(5, 8);
        for _ in 0..300 {
            let (_, camera) = random_scene(&mut sampler);
            for j in 0..camera.height {
                for i in 0..camera.width {
                    let Some(cone) = footprint(&camera, i, j) else {
                        continue;
                    };
                    assert_cone_holds_samples(&camera, (i, j), &cone, &mut sampler, 8, "");
                }
            }
        }
    }

    /// Asserts that `cone` holds the directions of pixel `(i, j)`'s samples as the renderer
    /// computes them: at the four corners of its square, then at `random` offsets drawn from
    /// `sampler`. `what` names the case in the message.
    fn assert_cone_holds_samples(
        camera: &Camera,
        (i, j): (usize, usize),
        cone: &Cone,
        sampler: &mut PixelSampler,
        random: usize,
        what: &str,
    ) {
        for k in 0..4 + random {
            let (ox, oy) = match k {
                0..4 => ((k % 2) as f64 - 0.5, (k / 2) as f64 - 0.5),
                _ => (sampler.next_f64() - 0.5, sampler.next_f64() - 0.5),
            };
            let d = camera
                .ray_through(i as f64 + ox, j as f64 + oy, (0.0, 0.0))
                .direction;
            let angle = cone.axis.cross(d).length().atan2(cone.axis.dot(d));
            let a = d.dot(d);
            assert!(
                angle <= cone.half_angle && (cone.length2_min..=cone.length2_max).contains(&a),
                "{what} pixel ({i}, {j}): {d} (at {angle} rad, length^2 {a}) outside {cone:?} \
                 {camera:?}"
            );
        }
    }

    /// A scene of `shapes`, object `k` with its own albedo.
    fn scene_of(shapes: Vec<Object>) -> Scene {
        let n = shapes.len();
        Scene {
            objects: shapes
                .into_iter()
                .enumerate()
                .map(|(k, shape)| SceneObject { shape, material: k })
                .collect(),
            materials: (0..n)
                .map(|k| Material::Lambertian {
                    albedo: DVec3::new(0.01 * (k % 100) as f64, 0.3, 0.9),
                })
                .collect(),
        }
    }

    /// Whether the pinhole path renders the general path's film, bit for bit.
    fn same_film(scene: &Scene, camera: &Camera, spp: u32, seed: u64, jitter: PixelJitter) -> bool {
        let pinhole = Pinhole::new(scene, camera.center);
        // A world of more than 16 objects intersects through its hierarchy: the fast path must
        // agree with that too.
        let world = World::from(scene.clone());
        let general = Job::new(&world, camera, spp, seed, jitter);
        let fast = Job::new(&pinhole, camera, spp, seed, jitter);
        film_bits(&fast) == film_bits(&general)
    }

    /// A counterexample found by search: the eye inside a sphere of negative radius (the same
    /// surface as the positive one, the normal flipped), far from the world's origin. The ball
    /// that rules a sphere out was its signed radius plus the rounding slack of
    /// `center - origin`, which shrank it (to 0.28e-3 here, below the eye's 1e-3 from the
    /// centre): the sphere was ruled out for every pixel and the image was sky, where every
    /// ray hits the sphere's far side (at `t` about `(1.5e-3 + 1e-3) / |d|`, above `1e-6`).
    #[test]
    fn a_negative_sphere_around_the_eye_is_never_ruled_out() {
        for (eye, offset, radius, focus) in [
            (DVec3::new(1e12, 0.0, 0.0), 1e-3, -1.5e-3, 100.0),
            (DVec3::new(1e6, 0.0, 0.0), 1e-9, -1.5e-9, 1e-4),
        ] {
            let settings = CameraSettings {
                look_from: eye.to_array(),
                look_at: (eye - DVec3::Z).to_array(),
                up: [0.0, 1.0, 0.0],
                vfov: 20.0,
                focus_distance: focus,
                defocus_angle: 0.0,
            };
            let camera = Camera::new(&settings, 8, 1.0);
            let sphere = Sphere::new(eye + DVec3::new(0.0, offset, 0.0), radius);
            let scene = scene_of(vec![Object::Sphere(sphere)]);
            // The general path's own answer: the sphere, for every pixel's centre ray.
            for (i, j) in [(0, 0), (7, 7), (3, 4)] {
                let ray = camera.ray_through(i as f64, j as f64, (0.0, 0.0));
                let hit = scene.closest(&ray, Interval::CAMERA).map(|(_, k)| k);
                assert_eq!(hit, Some(0), "{eye}: pixel ({i}, {j})");
            }
            let pinhole = Pinhole::new(&scene, camera.center);
            assert!(footprint(&camera, 3, 4).is_some(), "{eye}: no footprint");
            assert_eq!(pinhole.pixel(&camera, 3, 4).candidates & 1, 1, "{eye}");
            for jitter in [PixelJitter::Uniform, PixelJitter::Centre] {
                assert!(same_film(&scene, &camera, 3, 1, jitter), "{eye} {jitter:?}");
            }
        }
    }

    /// A uniform number in `[lo, hi)` from `sampler`.
    fn uniform(sampler: &mut PixelSampler, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * sampler.next_f64()
    }

    /// One of `choices`, uniformly.
    fn one_of<T: Copy>(sampler: &mut PixelSampler, choices: &[T]) -> T {
        choices[((sampler.next_f64() * choices.len() as f64) as usize).min(choices.len() - 1)]
    }

    /// A camera at an extreme: up to 1e12 from the world's origin, fields of view from 0.001
    /// to 179.9 degrees, focus distances from 1e-3 to 1e5, up vectors within 1e-12 of the view
    /// direction, images of one pixel, tall and narrow, or thousands of pixels in one row.
    fn extreme_camera(sampler: &mut PixelSampler, widest: usize) -> Camera {
        let far = one_of(sampler, &[0.0, 1e3, 1e6, 1e9, 1e12]) * one_of(sampler, &[1.0, -1.0]);
        let mut u = |lo: f64, hi: f64| uniform(sampler, lo, hi);
        let look_from = DVec3::new(u(-1.0, 1.0), u(-1.0, 1.0), u(-1.0, 1.0))
            + DVec3::new(far, far * u(-1.0, 1.0), far * u(0.0, 1.0));
        let forward = DVec3::new(u(-1.0, 1.0), u(-1.0, 1.0), u(-1.0, 1.0)).normalize();
        let near_forward = u(0.0, 1.0) < 0.2;
        let jiggle = DVec3::new(u(-1.0, 1.0), u(-1.0, 1.0), u(-1.0, 1.0));
        let (distance, focus) = (u(0.1, 10.0), 10f64.powf(u(-3.0, 5.0)));
        let shape = u(0.0, 5.0) as usize;
        let (long, short, aspect) = (u(500.0, widest as f64), u(1.0, 40.0), u(0.1, 8.0));
        let up = if near_forward {
            let tilt = one_of(sampler, &[1e-3, 1e-6, 1e-9, 1e-12]);
            (forward + jiggle * tilt).to_array()
        } else {
            [jiggle.x * 0.3, 1.0, jiggle.z * 0.3]
        };
        let vfov = one_of(
            sampler,
            &[
                0.001, 0.01, 1.0, 30.0, 90.0, 120.0, 170.0, 175.0, 179.0, 179.9,
            ],
        );
        let settings = CameraSettings {
            look_from: look_from.to_array(),
            look_at: (look_from + forward * distance).to_array(),
            up,
            vfov,
            focus_distance: focus,
            defocus_angle: 0.0,
        };
        let (width, aspect) = match shape {
            0 => (long as usize, 1e9),
            1 => (1, aspect.min(1.0) * 0.2),
            _ => (short as usize, aspect),
        };
        Camera::new(&settings, width, aspect)
    }

    /// A random scene at the extremes, seen by [`extreme_camera`]: spheres (a third of them
    /// with negative radii) and triangles from 1e-9 to 1e9 across, some around or tangent to a
    /// pixel's corner ray, behind the eye or around it; degenerate triangles (collinear, a
    /// repeated vertex), triangles edge-on to the eye (within 0 to 1e-6 of its plane), big ones
    /// near the eye; quads; and now and then more than 64 objects.
    fn extreme_scene(sampler: &mut PixelSampler, widest: usize) -> (Scene, Camera) {
        let camera = extreme_camera(sampler, widest);
        let through = |x: f64, y: f64, depth: f64| {
            let on_plane = camera.pixel00 + x * camera.pixel_delta_u + y * camera.pixel_delta_v;
            camera.center + (on_plane - camera.center) * depth
        };
        let pixel = camera.pixel_delta_u.length();
        let facing = camera.pixel_delta_u.cross(camera.pixel_delta_v).normalize();
        let (w, h) = (camera.width as f64, camera.height as f64);
        let count = if sampler.next_f64() < 0.15 {
            uniform(sampler, 60.0, 80.0) as usize
        } else {
            uniform(sampler, 1.0, 5.0) as usize
        };
        let mut objects = Vec::new();
        for _ in 0..count {
            let mut u = |lo: f64, hi: f64| uniform(sampler, lo, hi);
            let (x, y) = (u(-2.0, w + 2.0), u(-2.0, h + 2.0));
            // Often exactly on a pixel's corner or edge.
            let (x, y) = if u(0.0, 1.0) < 0.5 {
                (x.round() - 0.5, y.round() - 0.5)
            } else {
                (x, y)
            };
            let depth = if u(0.0, 1.0) < 0.1 {
                -u(0.2, 3.0)
            } else {
                10f64.powf(u(-2.0, 2.0))
            };
            let size = match u(0.0, 8.0) as usize {
                0 => 1e-9,
                1 => 1e9,
                _ => pixel * depth.abs() * 10f64.powf(u(-3.0, 3.0)),
            };
            let sign = if u(0.0, 1.0) < 0.3 { -1.0 } else { 1.0 };
            let centre = through(x, y, depth);
            let shape = match u(0.0, 10.0) as usize {
                0 => Object::Quad(Quad::new(
                    centre,
                    camera.pixel_delta_u * u(0.5, 6.0) * depth,
                    camera.pixel_delta_v * u(0.5, 6.0) * depth,
                )),
                1 | 2 => Object::Sphere(Sphere::new(centre, sign * size)),
                3 if u(0.0, 1.0) < 0.5 => {
                    // Around the eye.
                    let off = DVec3::new(u(-1.0, 1.0), u(-1.0, 1.0), u(-1.0, 1.0)) * size * 0.5;
                    Object::Sphere(Sphere::new(camera.center + off, sign * size))
                }
                3 => {
                    // Tangent to a pixel corner's ray.
                    let corner = through(x.round() - 0.5, y.round() - 0.5, 1.0) - camera.center;
                    let side = corner.cross(camera.pixel_delta_u).normalize();
                    let c = camera.center + corner * depth.abs() + side * size;
                    Object::Sphere(Sphere::new(c, sign * size))
                }
                4 => {
                    // Degenerate: collinear, or a repeated vertex.
                    let b = through(x + u(-3.0, 3.0), y + u(-3.0, 3.0), depth);
                    let c = if u(0.0, 1.0) < 0.5 {
                        centre + (b - centre) * u(-1.0, 2.0)
                    } else {
                        b
                    };
                    Object::Triangle(Triangle::new(centre, b, c))
                }
                5 => {
                    // Edge-on: the eye on, or nearly on, its plane.
                    let b = through(x + u(-3.0, 3.0), y + u(-3.0, 3.0), depth * u(0.5, 2.0));
                    let (p, q) = (u(0.1, 3.0), u(0.1, 3.0));
                    let tilt = one_of(sampler, &[0.0, 1e-12, 1e-9, 1e-6]);
                    let c = camera.center
                        + (centre - camera.center) * p
                        + (b - camera.center) * q
                        + facing * tilt * (centre - camera.center).length();
                    Object::Triangle(Triangle::new(centre, b, c))
                }
                6 => {
                    // A big triangle whose plane passes at or near the eye.
                    let s = size * 100.0;
                    let n = DVec3::new(u(-1.0, 1.0), u(-1.0, 1.0), u(-1.0, 1.0));
                    let base = camera.center + n * one_of(sampler, &[0.0, 1e-9, 1e-3, 1.0]) * s;
                    Object::Triangle(Triangle::new(
                        base + DVec3::new(s, 0.0, 0.0).cross(n),
                        base + DVec3::new(0.0, s, 0.0).cross(n),
                        base + DVec3::new(0.0, 0.0, s).cross(n),
                    ))
                }
                _ => {
                    let spread = 10f64.powf(u(-1.0, 2.0));
                    let mut corner = || {
                        through(
                            x + u(-1.0, 1.0) * spread,
                            y + u(-1.0, 1.0) * spread,
                            depth * (1.0 + 0.2 * u(-1.0, 1.0)),
                        )
                    };
                    Object::Triangle(Triangle::new(corner(), corner(), corner()))
                }
            };
            objects.push(shape);
        }
        (scene_of(objects), camera)
    }

    /// `scenes` extreme scenes ([`extreme_scene`]) from stream `seed`: the pinhole path renders
    /// the general path's film bit for bit (spp 1 to 20, every jitter), and every footprint
    /// holds its pixel's samples (the corners and random offsets, as the renderer computes
    /// them). Returns the pixels counted, culled and covered.
    fn extreme_films(scenes: usize, seed: u64, widest: usize) -> (usize, usize, usize) {
        let mut sampler = PixelSampler::new(seed, 77);
        let (mut pixels, mut culled, mut covered) = (0, 0, 0);
        for number in 0..scenes {
            let (scene, camera) = extreme_scene(&mut sampler, widest);
            let spp = uniform(&mut sampler, 1.0, 21.0) as u32;
            let jitter = one_of(
                &mut sampler,
                &[
                    PixelJitter::Uniform,
                    PixelJitter::Stratified,
                    PixelJitter::Centre,
                ],
            );
            let pinhole = Pinhole::new(&scene, camera.center);
            let all = match scene.objects.len() {
                n @ 0..64 => (1 << n) - 1,
                _ => u64::MAX,
            };
            for j in 0..camera.height {
                for i in 0..camera.width {
                    let pixel = pinhole.pixel(&camera, i, j);
                    culled += usize::from(pixel.candidates & all != all);
                    covered += usize::from(pixel.covering.is_some());
                    pixels += 1;
                    let Some(cone) = footprint(&camera, i, j) else {
                        continue;
                    };
                    let what = format!("scene {number}");
                    assert_cone_holds_samples(&camera, (i, j), &cone, &mut sampler, 4, &what);
                }
            }
            assert!(
                same_film(&scene, &camera, spp, number as u64, jitter),
                "scene {number} ({spp} spp, {jitter:?}): {scene:?} {camera:?}"
            );
        }
        (pixels, culled, covered)
    }

    /// The pinhole path keeps the general path's film at the extremes (see [`extreme_films`]),
    /// and the scenes do exercise the culling and the covering.
    #[test]
    fn footprints_keep_the_film_in_extreme_scenes() {
        let (pixels, culled, covered) = extreme_films(150, 1, 1200);
        assert!(culled * 10 > pixels, "{culled} of {pixels} pixels culled");
        assert!(covered > 20, "{covered} of {pixels} pixels covered");
    }

    /// [`footprints_keep_the_film_in_extreme_scenes`] at length (about a minute in release):
    /// `cargo test --release --lib extreme_scenes_at_length -- --ignored`.
    #[test]
    #[ignore]
    fn footprints_keep_the_film_in_extreme_scenes_at_length() {
        for seed in 2..8 {
            extreme_films(500, seed, 3000);
        }
    }

    /// The directions of samples on the border of pixel `(i, j)`'s square, as the renderer
    /// computes them.
    fn border(camera: &Camera, i: usize, j: usize) -> Vec<DVec3> {
        let n = 24;
        (0..=n)
            .flat_map(|k| {
                let t = k as f64 / n as f64 - 0.5;
                [(t, -0.5), (t, 0.5), (-0.5, t), (0.5, t)]
            })
            .map(|(ox, oy)| {
                camera
                    .ray_through(i as f64 + ox, j as f64 + oy, (0.0, 0.0))
                    .direction
            })
            .collect()
    }

    /// `cameras` extreme cameras, each with a sphere (of either sign) or a triangle facing it
    /// near one pixel, grown from 1e-12 to 1e12 times its distance: at each size where the
    /// object starts or stops being ruled out, or covering the pixel (found by bisection, to
    /// the last bit), the general path agrees with the claim on the pixel's border (where a
    /// round or convex object's hits and misses change). Returns the thresholds checked.
    fn thresholds(cameras: usize, seed: u64) -> (usize, usize) {
        let mut sampler = PixelSampler::new(seed, 78);
        let (mut ruled, mut covered) = (0, 0);
        for number in 0..cameras {
            let camera = extreme_camera(&mut sampler, 3000);
            let mut u = |lo: f64, hi: f64| uniform(&mut sampler, lo, hi);
            let i = (u(0.0, 1.0) * camera.width as f64) as usize;
            let j = (u(0.0, 1.0) * camera.height as f64) as usize;
            let depth = 10f64.powf(u(-3.0, 3.0));
            let (dx, dy) = (u(-3.0, 3.0), u(-3.0, 3.0));
            let sign = if u(0.0, 1.0) < 0.3 { -1.0 } else { 1.0 };
            let sphere = u(0.0, 1.0) < 0.5;
            let Some(cone) = footprint(&camera, i, j) else {
                continue;
            };
            let target = camera.ray_through(i as f64 + dx, j as f64 + dy, (0.0, 0.0));
            let centre = camera.center + target.direction * depth;
            let object = |size: f64| {
                if sphere {
                    return Object::Sphere(Sphere::new(centre, sign * size));
                }
                let (a, b) = (
                    camera.pixel_delta_u.normalize() * size,
                    camera.pixel_delta_v.normalize() * size,
                );
                let k = 0.75f64.sqrt();
                Object::Triangle(Triangle::new(
                    centre + a,
                    centre - a * 0.5 + b * k,
                    centre - a * 0.5 - b * k,
                ))
            };
            // (ruled out, covering) at `size`.
            let claims = |size: f64| {
                let scene = scene_of(vec![object(size)]);
                let prepared = FixedOrigin::new(&scene, camera.center);
                let candidates = prepared.candidates(&cone);
                [
                    candidates & 1 == 0,
                    prepared.covering(&cone, candidates).is_some(),
                ]
            };
            let directions = border(&camera, i, j);
            let hits = |size: f64| {
                let scene = scene_of(vec![object(size)]);
                directions
                    .iter()
                    .map(|&d| {
                        let ray = crate::geometry::Ray::new(camera.center, d);
                        scene.closest(&ray, Interval::CAMERA).is_some()
                    })
                    .collect::<Vec<bool>>()
            };
            let sizes: Vec<f64> = (0..=96)
                .map(|k| depth * 10f64.powf(-12.0 + 24.0 * k as f64 / 96.0))
                .collect();
            let states: Vec<[bool; 2]> = sizes.iter().map(|&s| claims(s)).collect();
            for step in 0..sizes.len() - 1 {
                for which in 0..2 {
                    let before = states[step][which];
                    if before == states[step + 1][which] {
                        continue;
                    }
                    let (mut lo, mut hi) = (sizes[step], sizes[step + 1]);
                    loop {
                        let middle = 0.5 * (lo + hi);
                        if middle == lo || middle == hi {
                            break;
                        }
                        if claims(middle)[which] == before {
                            lo = middle;
                        } else {
                            hi = middle;
                        }
                    }
                    let size = if before { lo } else { hi };
                    let hits = hits(size);
                    let wrong = if which == 0 {
                        ruled += 1;
                        hits.iter().any(|&hit| hit)
                    } else {
                        covered += 1;
                        !hits.iter().all(|&hit| hit)
                    };
                    assert!(
                        !wrong,
                        "camera {number}, pixel ({i}, {j}): {} at size {size}: {:?} {camera:?}",
                        ["ruled out", "covering"][which],
                        object(size)
                    );
                }
            }
        }
        (ruled, covered)
    }

    /// Ruling out and covering hold at their very thresholds (see [`thresholds`]).
    #[test]
    fn culling_holds_at_its_thresholds() {
        let (ruled, covered) = thresholds(150, 1);
        assert!(
            ruled > 40 && covered > 40,
            "{ruled} and {covered} thresholds"
        );
    }

    /// [`culling_holds_at_its_thresholds`] at length (about a minute in release).
    #[test]
    #[ignore]
    fn culling_holds_at_its_thresholds_at_length() {
        for seed in 2..6 {
            thresholds(4000, seed);
        }
    }
}
