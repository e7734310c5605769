//! Lanes of paths: in a small scene of spheres, moving spheres and quads, the renderer traces
//! four pixels' paths at a time, so that each closest-hit and shadow query tests one object
//! against four rays in one vector (AVX2 where the processor has it: the caller,
//! [`Job::row`](crate::render::job), is compiled for it).
//!
//! It promises the film of the one-ray-at-a-time row, bit for bit. Each lane renders whole
//! pixels, one after the other along the row, each from its own random stream, sample after
//! sample in order; every bounce is the integrator's own [`step`], given the closest hit that
//! [`ShapeSet::closest_lanes`] finds for it (the scalar loop's answer, lane by lane) and the
//! shadow tests [`ShapeSet::shadowed_lanes`] answered beforehand (pure functions of the hit
//! point, which the step would otherwise compute itself), and, under the sky, the `unit(d).y` of
//! the four rays its colour reads on a miss ([`RayLanes::unit_y`], one vector square root and
//! division, whose time then hides under the hit query's). A lane whose numbers over- or
//! underflow is answered by the scalar path. Only the order in which pixels are worked on
//! changes, not what any pixel draws or computes.

use glam::DVec3;

use crate::render::PixelSampler;
use crate::render::integrator::{Path, Shadows, hit_interval, occluded, step};
use crate::render::job::{Job, Moments, Spread};
use crate::scene::{Background, Integrator, LANES, Profile, RayLanes, ShapeSet, World, has_lanes};

/// One lane's work: the pixel it renders, its random stream, the sample in flight and the
/// pixel's sums so far.
struct Lane {
    pixel: usize,
    sampler: PixelSampler,
    sample: u32,
    moments: Option<Moments>,
    path: Path,
}

/// The objects to trace `world` through in lanes, when it takes them: a scene of spheres,
/// moving spheres and quads (no hierarchy) whose paths have at least one bounce, on a
/// processor with the lanes' vector instructions ([`has_lanes`]).
#[inline(always)]
pub(in crate::render) fn takes_lanes(world: &World) -> Option<&ShapeSet> {
    let albedo =
        world.profile == Profile::Course && world.settings.integrator == Integrator::Albedo;
    if (albedo || world.settings.max_depth > 0) && has_lanes() {
        world.shape_set()
    } else {
        None
    }
}

/// How many of the point lights the lanes test for shadows before a step: all of them (up to 32)
/// when the integrator reads the occlusion test, else none.
fn shadowed_lights(world: &World) -> usize {
    let reads = match (world.profile, world.settings.integrator) {
        (Profile::Course, Integrator::Direct) => true,
        (Profile::Course, Integrator::Brdf) => world.settings.direct_light,
        _ => false,
    };
    if reads && world.point_lights.len() <= 32 {
        world.point_lights.len()
    } else {
        0
    }
}

/// Starts sample `lane.sample` of the lane's pixel: its camera ray, drawn from the pixel's
/// stream.
#[inline(always)]
fn begin<const JITTER: u8>(job: &Job<'_, World>, lane: &mut Lane, j: usize) {
    let world = job.tracer;
    let ray = job.sample_ray::<JITTER>(
        &mut lane.sampler,
        (lane.pixel, j),
        lane.sample,
        world.moving,
    );
    lane.path = Path::new(world, ray);
}

/// A lane on pixel `pixel` of row `j`, its first sample begun.
#[inline(always)]
fn start<const JITTER: u8>(job: &Job<'_, World>, pixel: usize, j: usize) -> Lane {
    let width = job.camera.width;
    let mut lane = Lane {
        pixel,
        sampler: PixelSampler::new(job.seed, (j * width + pixel) as u64),
        sample: 0,
        moments: None,
        path: Path::new(
            job.tracer,
            crate::geometry::Ray::new(DVec3::ZERO, DVec3::ZERO),
        ),
    };
    begin::<JITTER>(job, &mut lane, j);
    lane
}

/// Renders row `j` of `job` (a world whose objects are `set`, [`takes_lanes`]) into `means`
/// (and `variances` when `VARIANCE`), four pixels at a time. A job of no sample renders nothing,
/// as the scalar row.
///
/// # Safety
///
/// The processor must have AVX2: `set` comes from [`takes_lanes`], which checked it.
#[inline(always)]
pub(in crate::render) unsafe fn row<const VARIANCE: bool, const JITTER: u8>(
    job: &Job<'_, World>,
    set: &ShapeSet,
    j: usize,
    means: &mut [DVec3],
    variances: &mut [Spread],
) {
    if job.spp == 0 {
        return;
    }
    let world = job.tracer;
    let interval = hit_interval(world);
    let lights = shadowed_lights(world);
    // The spheres each point light's shadow rays are aimed at the centre of.
    let aimed: Vec<u64> = (world.point_lights.iter().take(lights))
        .map(|light| set.centred_at(light.center))
        .collect();
    let sky = world.settings.background == Background::Sky;
    let mut next = 0;
    let mut lanes: [Option<Lane>; LANES] = [None, None, None, None];
    for lane in &mut lanes {
        if next < means.len() {
            *lane = Some(start::<JITTER>(job, next, j));
            next += 1;
        }
    }
    loop {
        let mut rays = RayLanes::default();
        let mut busy = false;
        for (k, lane) in lanes.iter().enumerate() {
            if let Some(lane) = lane {
                let ray = &lane.path.ray;
                rays.set(k, ray.origin, ray.direction, ray.time);
                busy = true;
            }
        }
        if !busy {
            return;
        }
        // The sky's `unit(d).y` of all four rays in one vector, before it is known which miss:
        // its square root and division then take no time of their own.
        let unit_y = if sky {
            // SAFETY: the processor has AVX2 (this function's contract).
            Some(unsafe { rays.unit_y() })
        } else {
            None
        };
        // SAFETY: the processor has AVX2 (this function's contract).
        let answers = unsafe { set.closest_lanes(&rays, interval) };
        let mut hits = [None; LANES];
        for (k, hit) in hits.iter_mut().enumerate() {
            *hit = match (&lanes[k], answers[k]) {
                (Some(lane), Err(())) => world.closest(&lane.path.ray, interval),
                (_, answer) => answer.unwrap_or(None),
            };
        }
        let shadows = if lights > 0 {
            // SAFETY: the processor has AVX2 (this function's contract).
            unsafe { shadows_at(world, set, &lanes, &hits, &aimed) }
        } else {
            [Shadows::UNKNOWN; LANES]
        };
        for k in 0..LANES {
            let Some(lane) = &mut lanes[k] else {
                continue;
            };
            let Some(mut colour) = step(
                world,
                &mut lane.path,
                hits[k],
                shadows[k],
                unit_y.map(|y| y[k]),
                &mut lane.sampler,
            ) else {
                continue;
            };
            if JITTER == 3 {
                colour *= job.scale;
            }
            let colour = [colour.x, colour.y, colour.z, 0.0];
            lane.moments
                .get_or_insert_with(|| Moments::new(colour))
                .add::<VARIANCE>(colour, lane.sample);
            lane.sample += 1;
            if lane.sample < job.spp {
                begin::<JITTER>(job, lane, j);
                continue;
            }
            if let Some(moments) = &lane.moments {
                let i = lane.pixel;
                moments.store::<VARIANCE>(job.spp, &mut means[i], variances.get_mut(i));
            }
            lanes[k] = (next < means.len()).then(|| {
                next += 1;
                start::<JITTER>(job, next - 1, j)
            });
        }
    }
}

/// The occlusion test of the first point lights (one per entry of `aimed`, which holds the
/// [`ShapeSet::centred_at`] of each light's centre) at each lane's hit point, four lanes at a
/// time: for the lanes whose ray hit something that is not a light (the others' steps read no
/// shadow).
///
/// # Safety
///
/// The processor must have AVX2 ([`row`]'s contract).
#[inline(always)]
unsafe fn shadows_at(
    world: &World,
    set: &ShapeSet,
    lanes: &[Option<Lane>; LANES],
    hits: &[Option<(f64, usize)>; LANES],
    aimed: &[u64],
) -> [Shadows; LANES] {
    let mut points = [None; LANES];
    for k in 0..LANES {
        if let (Some(lane), Some((t, object))) = (&lanes[k], hits[k]) {
            if !world.material_of(object).is_light() {
                points[k] = Some(lane.path.ray.at(t));
            }
        }
    }
    let mut shadows = [Shadows::UNKNOWN; LANES];
    if points.iter().all(Option::is_none) {
        return shadows;
    }
    for (l, (light, &aimed)) in world.point_lights.iter().zip(aimed).enumerate() {
        // `occluded`'s shadow ray: from the point to the light's centre, on `(1e-6, |c - p|)`.
        let mut rays = RayLanes::default();
        for (k, point) in points.iter().enumerate() {
            if let Some(p) = *point {
                // Shadow rays carry time 0 (`occluded`'s `Ray::new`).
                rays.set(k, p, light.center - p, 0.0);
            }
        }
        // SAFETY: the processor has AVX2 (this function's contract).
        let answers = unsafe { set.shadowed_lanes(&rays, 1e-6, aimed) };
        for (k, point) in points.iter().enumerate() {
            let Some(p) = *point else {
                continue;
            };
            let dark = answers[k].unwrap_or_else(|()| occluded(world, p, light.center));
            shadows[k].known |= 1 << l;
            if dark {
                shadows[k].occluded |= 1 << l;
            }
        }
    }
    shadows
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{MovingSphere, Quad, Sphere};
    use crate::render::job::{PixelJitter, film_bits};
    use crate::scene::{
        Background, DiffuseSampling, DirectTerm, Material, Object, RenderSettings, Scene,
        SceneObject, Texture, builtin, skipped_without_lanes,
    };

    /// Every material the integrators know, in both profiles' reach.
    fn materials() -> Vec<Material> {
        let c = |r, g, b| DVec3::new(r, g, b);
        vec![
            Material::Lambertian {
                albedo: c(0.7, 0.3, 0.3),
            },
            Material::Mirror {
                albedo: c(0.8, 0.8, 0.8),
            },
            Material::Dielectric {
                albedo: c(1.0, 1.0, 1.0),
                ior: 1.5,
            },
            Material::DiffuseLight {
                emit: c(4.0, 4.0, 3.0),
            },
            Material::Phong {
                albedo: c(0.7, 0.2, 0.4),
                kd: 0.6,
                ks: 0.9,
                alpha: 8.0,
            },
            Material::Blinn {
                albedo: c(0.2, 0.7, 0.4),
                kd: 0.6,
                ks: 0.9,
                alpha: 30.0,
            },
            Material::Metal {
                albedo: c(0.8, 0.6, 0.2),
                roughness: 0.3,
            },
            Material::CookTorrance {
                albedo: c(0.5, 0.5, 0.5),
                kd: 0.4,
                ks: 0.6,
                alpha: 0.3,
                ior: 1.5,
            },
            Material::Textured {
                texture: Texture::Checker {
                    scale: 0.32,
                    even: c(0.2, 0.2, 0.2),
                    odd: c(0.9, 0.9, 0.9),
                },
            },
        ]
    }

    /// A ground sphere and `n` random spheres (some hollow, some tiny, some lights) around
    /// week 6's view, of random materials; when `mixed`, some of them move and a box of quads
    /// (a floor, a back wall, a side wall and a square light) is added.
    fn random_scene(s: &mut PixelSampler, n: usize, lights: bool, mixed: bool) -> Scene {
        let materials = materials();
        let pick = |s: &mut PixelSampler| loop {
            let m = (s.next_f64() * materials.len() as f64) as usize;
            if lights || !materials[m].is_light() {
                return m;
            }
        };
        let mut objects = vec![SceneObject {
            shape: Object::Sphere(Sphere::new(DVec3::new(0.0, -100.5, -1.0), 100.0)),
            material: pick(s),
        }];
        for _ in 0..n {
            let center = DVec3::new(
                s.uniform(-2.0, 2.0),
                s.uniform(-0.5, 1.5),
                s.uniform(-3.0, 0.5),
            );
            let radius = match (s.next_f64() * 4.0) as u32 {
                0 => -s.uniform(0.1, 0.5),
                1 => s.uniform(0.01, 0.05),
                _ => s.uniform(0.2, 0.8),
            };
            let material = pick(s);
            let sphere = Sphere::new(center, radius);
            let shape = if mixed && s.next_f64() < 0.4 {
                let end = center + s.unit_vector() * s.uniform(0.0, 0.5);
                Object::MovingSphere(MovingSphere::new(sphere, end))
            } else {
                Object::Sphere(sphere)
            };
            objects.push(SceneObject { shape, material });
            // A shell, as the book's hollow glass: paths between the two surfaces start inside
            // the outer sphere and leave it.
            if radius > 0.1 && s.next_f64() < 0.5 {
                objects.push(SceneObject {
                    shape: Object::Sphere(Sphere::new(center, -0.8 * radius)),
                    material,
                });
            }
        }
        if mixed {
            let c = DVec3::new;
            for (q, u, v) in [
                (c(-3.0, -0.5, -4.0), c(6.0, 0.0, 0.0), c(0.0, 0.0, 5.0)),
                (c(-3.0, -0.5, -4.0), c(0.0, 4.0, 0.0), c(6.0, 0.0, 0.0)),
                (c(-3.0, -0.5, -4.0), c(0.0, 0.0, 5.0), c(0.0, 4.0, 0.0)),
                (c(-0.5, 2.5, -2.0), c(1.0, 0.0, 0.0), c(0.0, 0.0, 1.0)),
            ] {
                objects.push(SceneObject {
                    shape: Object::Quad(Quad::new(q, u, v)),
                    material: pick(s),
                });
            }
        }
        Scene { objects, materials }
    }

    /// The film bits of `world` through the lanes (the dispatch's path for a world of
    /// spheres and quads) and through the scalar loop, at week 6's camera `width` pixels wide.
    fn both_films(
        world: &World,
        width: usize,
        spp: u32,
        seed: u64,
        jitter: PixelJitter,
    ) -> (Vec<u64>, Vec<u64>) {
        let camera = builtin("week06-dielectric").unwrap().camera(Some(width));
        assert!(
            takes_lanes(world).is_some(),
            "a world of spheres and quads takes the lanes"
        );
        let lanes = film_bits(&Job::new(world, &camera, spp, seed, jitter));
        let scalar_world = world.clone().without_shape_set();
        assert!(takes_lanes(&scalar_world).is_none());
        let scalar = film_bits(&Job::new(&scalar_world, &camera, spp, seed, jitter));
        (lanes, scalar)
    }

    /// On random scenes of spheres (36), then of spheres, moving spheres and quads (36), every
    /// integrator and setting of both profiles, rows whose width is and is not a multiple of
    /// four, every jitter: the lanes render the scalar loop's film (means, variances,
    /// deviations) bit for bit.
    #[test]
    fn lanes_render_the_scalar_film() {
        if skipped_without_lanes("the renderer takes no lanes") {
            return;
        }
        let mut s = PixelSampler::new(17, 3);
        let mut compared = 0;
        for round in 0..72 {
            // A mixed scene of up to 15 objects, so that it takes no hierarchy.
            let n = if round < 36 {
                1 + round % 9
            } else {
                1 + round % 5
            };
            let scene = random_scene(&mut s, n, round % 3 != 0, round >= 36);
            let mut settings = RenderSettings {
                max_depth: 1 + (round % 7) as u32,
                background: if round % 2 == 0 {
                    Background::Sky
                } else {
                    Background::Flat
                },
                ..RenderSettings::default()
            };
            let (integrator, profile) = match round % 6 {
                0 => (Integrator::Direct, Profile::Course),
                1 => (Integrator::Brdf, Profile::Course),
                2 => (Integrator::Albedo, Profile::Course),
                3 => (Integrator::Direct, Profile::Course),
                4 => (Integrator::Brdf, Profile::Course),
                _ => (Integrator::Direct, Profile::Physical),
            };
            settings.integrator = integrator;
            settings.direct_term = if round % 4 == 3 {
                DirectTerm::Unclamped
            } else {
                DirectTerm::Clamped
            };
            settings.direct_light = round % 5 != 4;
            settings.diffuse_sampling = if round % 3 == 1 {
                DiffuseSampling::Cosine
            } else {
                DiffuseSampling::UnitSphere
            };
            let world = World::new(scene, profile, settings, Vec::new(), 10.0);
            let jitter = [
                PixelJitter::Uniform,
                PixelJitter::Stratified,
                PixelJitter::Centre,
            ][round % 3];
            let width = [13, 16, 21][round % 3];
            let (lanes, scalar) = both_films(
                &world,
                width,
                1 + (round % 4) as u32 * 3,
                round as u64,
                jitter,
            );
            assert!(lanes == scalar, "round {round}: {integrator:?} {profile:?}");
            compared += 1;
        }
        assert_eq!(compared, 72);
    }

    /// A sphere too large for the lanes' arithmetic (its squared radius overflows) hands every
    /// lane back to the scalar path, to the same film; so does a light among such spheres.
    #[test]
    fn lanes_hand_back_what_only_the_scalar_path_solves() {
        if skipped_without_lanes("the renderer takes no lanes") {
            return;
        }
        let mut s = PixelSampler::new(3, 9);
        let mut scene = random_scene(&mut s, 4, true, true);
        scene.objects.push(SceneObject {
            shape: Object::Sphere(Sphere::new(DVec3::new(0.0, 0.0, 1e200), 1e160)),
            material: 0,
        });
        scene.objects.push(SceneObject {
            shape: Object::Sphere(Sphere::new(DVec3::new(0.5, 1.0, -1.0), 0.05)),
            material: 3,
        });
        for integrator in [Integrator::Direct, Integrator::Brdf] {
            let settings = RenderSettings {
                integrator,
                max_depth: 4,
                ..RenderSettings::default()
            };
            let world = World::new(scene.clone(), Profile::Course, settings, Vec::new(), 10.0);
            let (lanes, scalar) = both_films(&world, 6, 5, 1, PixelJitter::Uniform);
            assert!(lanes == scalar, "{integrator:?}");
        }
    }

    /// Every built-in scene without a hierarchy or a triangle (all of weeks 4 to 10, the book's
    /// first two and the edge cases: spheres, moving spheres and quads) takes the lanes, and
    /// renders the same film through them as through the scalar loop.
    #[test]
    fn built_in_scenes_render_the_scalar_film() {
        if skipped_without_lanes("the renderer takes no lanes") {
            return;
        }
        let mut taken = 0;
        for name in crate::scene::builtin_names() {
            let description = builtin(name).unwrap();
            let world = description.scene();
            let triangles = world
                .objects
                .iter()
                .any(|o| matches!(o.shape, Object::Triangle(_)));
            if world.has_hierarchy() || triangles {
                continue;
            }
            assert!(takes_lanes(&world).is_some(), "{name} takes no lanes");
            let (lanes, scalar) = both_films(&world, 9, 3, 5, PixelJitter::Uniform);
            assert!(lanes == scalar, "{name}");
            taken += 1;
        }
        assert!(taken >= 19, "only {taken} built-in scenes take the lanes");
    }
}
