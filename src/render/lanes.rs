//! Lanes of paths: in a scene of static spheres, the renderer traces four pixels' paths at a
//! time, so that each closest-hit and shadow query tests one sphere against four rays in one
//! vector (AVX2 where the processor has it: the caller, [`Job::row`](super::job), is compiled
//! for it).
//!
//! It promises the film of the one-ray-at-a-time row, bit for bit. Each lane renders whole
//! pixels, one after the other along the row, each from its own random stream, sample after
//! sample in order; every bounce is the integrator's own [`step`], given the closest hit that
//! [`SphereSet::closest_lanes`] finds for it (the scalar loop's answer, lane by lane) and the
//! shadow tests [`SphereSet::occluded_lanes`] answered beforehand (pure functions of the hit
//! point, which the step would otherwise compute itself). A lane whose numbers over- or
//! underflow is answered by the scalar path. Only the order in which pixels are worked on
//! changes, not what any pixel draws or computes.

use glam::DVec3;

use super::PixelSampler;
use super::integrator::{Path, Shadows, hit_interval, occluded, step};
use super::job::{Job, Moments, Spread};
use crate::scene::{Integrator, LANES, Profile, RayLanes, SphereSet, World, has_lanes};

/// One lane's work: the pixel it renders, its random stream, the sample in flight and the
/// pixel's sums so far.
struct Lane {
    pixel: usize,
    sampler: PixelSampler,
    sample: u32,
    moments: Option<Moments>,
    path: Path,
}

/// The spheres to trace `world` through in lanes, when it takes them: a scene of static spheres
/// (no hierarchy) whose paths have at least one bounce, on a processor with the lanes' vector
/// instructions ([`has_lanes`]).
#[inline(always)]
pub(super) fn takes_lanes(world: &World) -> Option<&SphereSet> {
    let albedo =
        world.profile == Profile::Course && world.settings.integrator == Integrator::Albedo;
    if (albedo || world.settings.max_depth > 0) && has_lanes() {
        world.sphere_set()
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

/// Renders row `j` of `job` (a world whose spheres are `set`, [`takes_lanes`]) into `means`
/// (and `variances` when `VARIANCE`), four pixels at a time.
///
/// `set` must come from [`takes_lanes`], which checked that the processor has the lanes'
/// instructions.
#[inline(always)]
pub(super) fn row<const VARIANCE: bool, const JITTER: u8>(
    job: &Job<'_, World>,
    set: &SphereSet,
    j: usize,
    means: &mut [DVec3],
    variances: &mut [Spread],
) {
    let world = job.tracer;
    let interval = hit_interval(world);
    let lights = shadowed_lights(world);
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
                rays.set(k, lane.path.ray.origin, lane.path.ray.direction);
                busy = true;
            }
        }
        if !busy {
            return;
        }
        // SAFETY: `takes_lanes` checked the processor (this function's contract).
        let answers = unsafe { set.closest_lanes(&rays, interval) };
        let mut hits = [None; LANES];
        for (k, hit) in hits.iter_mut().enumerate() {
            *hit = match (&lanes[k], answers[k]) {
                (Some(lane), Err(())) => world.closest(&lane.path.ray, interval),
                (_, answer) => answer.unwrap_or(None),
            };
        }
        let shadows = if lights > 0 {
            shadows_at(world, set, &lanes, &hits, lights)
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

/// The occlusion test of the first `lights` point lights at each lane's hit point, four lanes
/// at a time: for the lanes whose ray hit something that is not a light (the others' steps read
/// no shadow).
#[inline(always)]
fn shadows_at(
    world: &World,
    set: &SphereSet,
    lanes: &[Option<Lane>; LANES],
    hits: &[Option<(f64, usize)>; LANES],
    lights: usize,
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
    for (l, light) in world.point_lights.iter().take(lights).enumerate() {
        // `occluded`'s shadow ray: from the point to the light's centre, on `(1e-6, |c - p|)`.
        let mut rays = RayLanes::default();
        let mut reach = [0.0; LANES];
        for (k, point) in points.iter().enumerate() {
            if let Some(p) = *point {
                let to_light = light.center - p;
                rays.set(k, p, to_light);
                reach[k] = to_light.length();
            }
        }
        // SAFETY: `takes_lanes` checked the processor (`row`'s contract).
        let answers = unsafe { set.occluded_lanes(&rays, 1e-6, &reach) };
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
