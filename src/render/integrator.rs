//! The integrators: what a camera ray brings back, in each of the course's weeks and in the book.
//!
//! All four are loops over the path's hits rather than recursions, carrying the product of the
//! weights so far (the course's `a Li` and `BRDF Li c(n . w)` are linear in `Li`): the same
//! values, up to rounding, as the recursive code.

use glam::DVec3;

use super::PixelSampler;
use super::brdf::{blinn, cook_torrance, phong};
use super::scatter;
use super::surface::Surface;
use crate::geometry::{Interval, Ray};
use crate::scene::{Background, DirectTerm, Integrator, Material, Profile, Scene, World};

/// The course's sky: `a = 0.5 (unit(d).y + 1)`, `(1 - a) (1, 1, 1) + a (0.5, 0.7, 1.0)`.
#[inline]
pub fn sky(direction: DVec3) -> DVec3 {
    sky_at(sky_height(direction))
}

/// The sky's height coordinate along `direction`: `a = 0.5 (unit(d).y + 1)`, computing
/// `unit_vector(direction).y` without the two divisions whose results are not used. The lanes'
/// `RayLanes::unit_y` computes `d.y / |d|` with the same operations.
#[inline(always)]
pub(crate) fn sky_height(direction: DVec3) -> f64 {
    0.5 * (direction.y / direction.length() + 1.0)
}

/// The sky's colour at height `a = 0.5 (unit(d).y + 1)`: `(1 - a) (1, 1, 1) + a (0.5, 0.7, 1.0)`.
#[inline(always)]
pub(crate) fn sky_at(a: f64) -> DVec3 {
    (1.0 - a) * DVec3::ONE + a * DVec3::new(0.5, 0.7, 1.0)
}

/// The course's week-4 integrator over a bare [`Scene`] (solid colours, the sky): the albedo of
/// the closest hit in `(1e-6, f64::MAX)`, or the sky on a miss. [`trace`] is the general one.
#[inline]
pub fn radiance(scene: &Scene, ray: &Ray) -> DVec3 {
    match scene.closest(ray, Interval::CAMERA) {
        Some((_, index)) => scene.material_of(index).albedo(),
        None => sky(ray.direction),
    }
}

/// The background seen along `direction`; `unit_y`, when given, is `direction`'s unit vector's
/// `y` computed beforehand (`d.y / |d|`, with the same operations: the lanes compute four of
/// them in one vector).
#[inline]
fn background(world: &World, direction: DVec3, unit_y: Option<f64>) -> DVec3 {
    match world.settings.background {
        Background::Sky => match unit_y {
            Some(y) => sky_at(0.5 * (y + 1.0)),
            None => sky(direction),
        },
        Background::Flat => DVec3::from(world.settings.background_color),
    }
}

/// The radiance along a camera ray in `world`, drawing from `sampler`: the profile's integrator.
///
/// One `Path` taken one `step` at a time, each step given the closest hit of the path's ray.
/// The renderer's lanes of paths (`render::fast::lanes`) take the same steps, four paths at a time.
#[inline(always)]
pub fn trace(world: &World, ray: &Ray, sampler: &mut PixelSampler) -> DVec3 {
    let mut path = Path::new(world, *ray);
    if path.is_exhausted() {
        return DVec3::ZERO;
    }
    let interval = hit_interval(world);
    loop {
        let hit = world.closest(&path.ray, interval);
        if let Some(colour) = step(world, &mut path, hit, Shadows::UNKNOWN, None, sampler) {
            return colour;
        }
    }
}

/// Where the profile's integrator looks for hits: `(1e-6, f64::MAX)` in the course, the book's
/// `(0.001, infinity)`.
#[inline(always)]
pub(crate) fn hit_interval(world: &World) -> Interval {
    match world.profile {
        Profile::Course => Interval::CAMERA,
        Profile::Physical => Interval::new(0.001, f64::INFINITY),
    }
}

/// A path in flight: the ray it traces next, the product of the weights so far (the course's
/// `a Li` and `BRDF Li c(n . w)` are linear in `Li`, so the recursion is a loop: the same values,
/// up to rounding, as the recursive code), what it has gathered, and the bounces it has left.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Path {
    /// The ray whose closest hit the next step takes.
    pub(crate) ray: Ray,
    weight: DVec3,
    total: DVec3,
    left: u32,
}

impl Path {
    /// A path starting with the camera ray `ray`: week 4's one look-up, or the scene's
    /// `max_depth` bounces.
    #[inline(always)]
    pub(crate) fn new(world: &World, ray: Ray) -> Self {
        let left = match (world.profile, world.settings.integrator) {
            (Profile::Course, Integrator::Albedo) => 1,
            _ => world.settings.max_depth,
        };
        Self {
            ray,
            weight: DVec3::ONE,
            total: DVec3::ZERO,
            left,
        }
    }

    /// Whether the path has no bounce at all (a depth of 0: black, with nothing traced).
    #[inline(always)]
    pub(crate) fn is_exhausted(&self) -> bool {
        self.left == 0
    }
}

/// What is already known of the course's occlusion test at a step's hit point: bit `l` of
/// `known` set when point light `l`'s answer is bit `l` of `occluded`. The lanes of paths test
/// the shadow rays of four paths at once, before the step; what is not known is tested when the
/// step needs it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Shadows {
    /// The lights whose answer is known.
    pub(crate) known: u32,
    /// Of those, the ones occluded.
    pub(crate) occluded: u32,
}

impl Shadows {
    /// Nothing known yet.
    pub(crate) const UNKNOWN: Shadows = Shadows {
        known: 0,
        occluded: 0,
    };

    /// Whether `p` is in the shadow of point light number `light`: the known answer, or
    /// [`occluded`].
    #[inline(always)]
    fn of(self, world: &World, p: DVec3, light: usize) -> bool {
        if light < 32 && self.known & (1 << light) != 0 {
            self.occluded & (1 << light) != 0
        } else {
            occluded(world, p, world.point_lights[light].center)
        }
    }
}

/// One bounce of `path`, whose ray's closest hit in [`hit_interval`] is `hit`: the path's colour
/// when it ends here, `None` when it goes on (with its next ray in `path.ray`). `shadows` and
/// `unit_y` are what the caller computed beforehand of the step's shadow tests and of the
/// background's `unit(d).y` (see [`Shadows`] and `background`); they change no result.
#[inline(always)]
pub(crate) fn step(
    world: &World,
    path: &mut Path,
    hit: Option<(f64, usize)>,
    shadows: Shadows,
    unit_y: Option<f64>,
    sampler: &mut PixelSampler,
) -> Option<DVec3> {
    match (world.profile, world.settings.integrator) {
        (Profile::Physical, _) => physical(world, path, hit, unit_y, sampler),
        (Profile::Course, Integrator::Albedo) => Some(albedo(world, &path.ray, hit, unit_y)),
        (Profile::Course, Integrator::Direct) => direct(world, path, hit, shadows, unit_y, sampler),
        (Profile::Course, Integrator::Brdf) => brdf(world, path, hit, shadows, unit_y, sampler),
    }
}

/// Week 4: the colour of the closest hit in `(1e-6, f64::MAX)` (a texture's value there), the
/// background on a miss.
#[inline(always)]
fn albedo(world: &World, ray: &Ray, hit: Option<(f64, usize)>, unit_y: Option<f64>) -> DVec3 {
    match hit {
        Some((t, object)) => {
            let material = world.material_of(object);
            match material {
                Material::Textured { .. } => {
                    Surface::of(world, ray, t, object, Interval::CAMERA).colour(world, material)
                }
                other => other.albedo(),
            }
        }
        None => background(world, ray.direction, unit_y),
    }
}

/// The course's occlusion test (weeks 5 to 10, `RT_scene.py`'s `find_occlusion`): whether the
/// point `p` is in the shadow of the point light at `center`.
///
/// Course departures, week 5: the shadow ray is `p + t (c - p)`, unnormalised, so the light is
/// at `t = 1`, but it is tested on `(1e-6, |c - p|)`, in *t units*; every object is tested
/// against that whole interval (the closest `t` never shrinks), and the point is occluded when
/// **more than one** object is hit, the light's own sphere counting as one. So when
/// `|c - p| > 1` objects beyond the light cast shadows, and when the light's sphere is not
/// reached (about `0.11 < |c - p| < 0.89` for a radius of 0.1) one occluder alone does not.
/// Shadow rays carry time 0 (week 10).
#[inline]
pub fn occluded(world: &World, p: DVec3, center: DVec3) -> bool {
    let to_light = center - p;
    let shadow = Ray::new(p, to_light);
    world.count_hits(&shadow, Interval::new(1e-6, to_light.length()), 2) > 1
}

/// Weeks 5 to 7's direct term at `p`: over the unoccluded point lights, `E min(1, 1/d)`
/// (`DirectTerm::Clamped`) or `E / d` (`DirectTerm::Unclamped`), `d = |c - p|`.
///
/// Course departure, weeks 5 to 7: no cosine and no `1 / (pi d^2)`, only `min(1, 1/d)` (or
/// `1/d`); every scattering material receives it, mirrors and glass too. A light at distance 0
/// (its centre on the surface) is left out, where the course divides by zero.
#[inline(always)]
fn direct_term(world: &World, p: DVec3, shadows: Shadows) -> DVec3 {
    let mut le = DVec3::ZERO;
    for (l, light) in world.point_lights.iter().enumerate() {
        let d = (light.center - p).length();
        if d == 0.0 || shadows.of(world, p, l) {
            continue;
        }
        le += match world.settings.direct_term {
            DirectTerm::Clamped => light.emit * (1.0f64).min(1.0 / d),
            DirectTerm::Unclamped => light.emit * (1.0 / d),
        };
    }
    le
}

/// The opening of a course bounce (weeks 5 to 10), the same in both integrators: on a miss the
/// path's colour with the background, at a light its colour with the light's; otherwise the hit's
/// material, surface record and the scattered ray (drawn from `sampler`).
#[inline(always)]
fn course_bounce<'w>(
    world: &'w World,
    path: &Path,
    hit: Option<(f64, usize)>,
    unit_y: Option<f64>,
    sampler: &mut PixelSampler,
) -> Result<(&'w Material, Surface, scatter::Scattered), DVec3> {
    let ray = path.ray;
    let Some((t, object)) = hit else {
        return Err(path.total + path.weight * background(world, ray.direction, unit_y));
    };
    let material = world.material_of(object);
    let surface = Surface::of(world, &ray, t, object, Interval::CAMERA);
    match scatter::course(world, material, &ray, &surface, sampler) {
        Some(scattered) => Ok((material, surface, scattered)),
        None => Err(path.total + path.weight * material.albedo()),
    }
}

/// Weeks 5 to 7's `compute_scattering(ray, scene, depth)`: depth 0 is black; every hit in
/// `(1e-6, f64::MAX)`; a light returns its emission; otherwise `Le a + Li a` (the clamped term)
/// or `Le + a Li` (the unclamped one), `Li` the scattered ray's; a miss returns the background.
#[inline(always)]
fn direct(
    world: &World,
    path: &mut Path,
    hit: Option<(f64, usize)>,
    shadows: Shadows,
    unit_y: Option<f64>,
    sampler: &mut PixelSampler,
) -> Option<DVec3> {
    let (_, hit, scattered) = match course_bounce(world, path, hit, unit_y, sampler) {
        Ok(bounce) => bounce,
        Err(colour) => return Some(colour),
    };
    let a = scattered.attenuation;
    let le = direct_term(world, hit.point, shadows);
    path.total += match world.settings.direct_term {
        DirectTerm::Clamped => path.weight * (le * a),
        DirectTerm::Unclamped => path.weight * le,
    };
    path.weight *= a;
    path.next(scattered.ray)
}

impl Path {
    /// After a bounce: the path's total when its weight is zero (whatever comes back is
    /// multiplied by zero) or it has no bounce left, else `None` with `ray` its next ray.
    #[inline(always)]
    fn next(&mut self, ray: Ray) -> Option<DVec3> {
        self.left -= 1;
        if self.weight == DVec3::ZERO || self.left == 0 {
            return Some(self.total);
        }
        self.ray = ray;
        None
    }
}

/// Week 8's `c(x)`: 0 when `x < 1e-6`, else `x`.
#[inline]
fn cutoff(x: f64) -> f64 {
    if x < 1e-6 { 0.0 } else { x }
}

/// `BRDF(ray_view, ray_light, hit)` of `material` (week 8): the albedo (or texture value) of the
/// materials without a model of their own, the model's value of Phong, Blinn and
/// Cook-Torrance.
#[inline(always)]
fn brdf_of(world: &World, material: &Material, view: DVec3, light: DVec3, hit: &Surface) -> DVec3 {
    let n = hit.normal;
    match *material {
        Material::Phong {
            albedo,
            kd,
            ks,
            alpha,
        } => phong(albedo, kd, ks, alpha, view, light, n),
        Material::Blinn {
            albedo,
            kd,
            ks,
            alpha,
        } => blinn(albedo, kd, ks, alpha, view, light, n),
        Material::CookTorrance {
            kd, ks, alpha, ior, ..
        } => cook_torrance(kd, ks, alpha, ior, view, light, n),
        ref other => hit.colour(world, other),
    }
}

/// Weeks 8 to 10's `compute_scattering`: at each hit,
/// `Le = sum over unoccluded point lights of BRDF(ray, c - P) E c(n . (c - P))` (when
/// `direct_light`), plus `BRDF(ray, w) Li c(n . w)` for the scattered direction `w`.
///
/// Course departures, weeks 8 to 10: `c - P` is not normalised, so a light's weight grows with
/// its distance; `n . w` is not normalised either (week 8's Lambertian `n + u` gives weights in
/// `[0, 2]`, a mirror's `n . reflect(d)` scales with the camera ray's length); nothing is
/// divided by a pdf and the Lambertian has no `1 / pi`, so cosine sampling (weeks 9 and 10)
/// shows a Lambertian at about 2/3 of its brightness; the scatter's attenuation is ignored, so a
/// dielectric's transmitted rays (`n . w < 0`) count for nothing and glass shows its reflection
/// only. The occlusion test is week 5's ([`occluded`]); the facts leave open whether week 8's
/// direct term tests it, and it is assumed to.
#[inline(always)]
fn brdf(
    world: &World,
    path: &mut Path,
    hit: Option<(f64, usize)>,
    shadows: Shadows,
    unit_y: Option<f64>,
    sampler: &mut PixelSampler,
) -> Option<DVec3> {
    let ray = path.ray;
    let (material, hit, scattered) = match course_bounce(world, path, hit, unit_y, sampler) {
        Ok(bounce) => bounce,
        Err(colour) => return Some(colour),
    };
    let n = hit.normal;
    if world.settings.direct_light {
        let mut le = DVec3::ZERO;
        for (l, light) in world.point_lights.iter().enumerate() {
            let to_light = light.center - hit.point;
            if shadows.of(world, hit.point, l) {
                continue;
            }
            let f = brdf_of(world, material, ray.direction, to_light, &hit);
            le += f * light.emit * cutoff(n.dot(to_light));
        }
        path.total += path.weight * le;
    }
    // On the last bounce nothing reads the weight again (`next` returns the total whatever
    // it is), so its BRDF, a `pow` for Phong and Blinn, is not evaluated; the scattered ray was
    // drawn all the same, so the pixel's random stream goes on as the course's does.
    if path.left > 1 {
        let w = scattered.ray.direction;
        path.weight *= brdf_of(world, material, ray.direction, w, &hit) * cutoff(n.dot(w));
    }
    path.next(scattered.ray)
}

/// The book's `ray_color` (book 1, with book 2's emission and background): depth 0 is black;
/// hits in `(0.001, infinity)`; a light returns its emission, an absorbed ray black, a scattered
/// one its attenuation times what it brings back; a miss the background.
#[inline(always)]
fn physical(
    world: &World,
    path: &mut Path,
    hit: Option<(f64, usize)>,
    unit_y: Option<f64>,
    sampler: &mut PixelSampler,
) -> Option<DVec3> {
    let ray = path.ray;
    let Some((t, object)) = hit else {
        return Some(path.weight * background(world, ray.direction, unit_y));
    };
    let material = world.material_of(object);
    if let Material::DiffuseLight { emit } = *material {
        return Some(path.weight * emit);
    }
    let hit = Surface::of(world, &ray, t, object, hit_interval(world));
    let Some(scattered) = scatter::physical(world, material, &ray, &hit, sampler) else {
        return Some(DVec3::ZERO);
    };
    path.weight *= scattered.attenuation;
    // The book's total stays zero: what a path brings back is its weight times what it ends on;
    // a path that runs out of bounces is black.
    path.left -= 1;
    if path.left == 0 {
        return Some(DVec3::ZERO);
    }
    path.ray = scattered.ray;
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::unit_vector;

    /// The shortcut computes the same `a` as the course's `unit_vector(d).y`, bit for bit.
    #[test]
    fn sky_uses_the_y_of_the_unit_vector() {
        let mut s = crate::render::PixelSampler::new(3, 5);
        for _ in 0..100_000 {
            let d = DVec3::new(
                s.next_f64() * 40.0 - 20.0,
                s.next_f64() * 40.0 - 20.0,
                s.next_f64() * 40.0 - 20.0,
            );
            let a = 0.5 * (unit_vector(d).y + 1.0);
            let expected = (1.0 - a) * DVec3::ONE + a * DVec3::new(0.5, 0.7, 1.0);
            assert_eq!(sky(d), expected, "{d}");
        }
    }

    /// Closed forms: straight up is the top colour, straight down white, horizontal the average.
    #[test]
    fn sky_gradient_ends() {
        assert_eq!(sky(DVec3::Y), DVec3::new(0.5, 0.7, 1.0));
        assert_eq!(sky(-DVec3::Y * 3.0), DVec3::ONE);
        assert_eq!(sky(DVec3::X), DVec3::new(0.75, 0.85, 1.0));
    }

    use crate::geometry::{Quad, Sphere};
    use crate::scene::{Object, RenderSettings, SceneObject, World};

    const FLOOR_ALBEDO: DVec3 = DVec3::new(0.5, 0.25, 1.0);
    const EMIT: DVec3 = DVec3::new(1.0, 0.5, 2.0);

    /// A floor (the square `y = 0`, `|x|, |z| <= 4`, facing up) of `floor`, a point light of
    /// radius 0.1 at `(0, 2, 0)`, and `extra` objects (material 0 is the floor's, 1 the
    /// light's, 2 a mirror), under `settings`.
    fn world(floor: Material, extra: Vec<SceneObject>, settings: RenderSettings) -> World {
        let mut objects = vec![
            SceneObject {
                shape: Object::Quad(Quad::new(
                    DVec3::new(-4.0, 0.0, 4.0),
                    DVec3::new(8.0, 0.0, 0.0),
                    DVec3::new(0.0, 0.0, -8.0),
                )),
                material: 0,
            },
            SceneObject {
                shape: Object::Sphere(Sphere::new(DVec3::new(0.0, 2.0, 0.0), 0.1)),
                material: 1,
            },
        ];
        objects.extend(extra);
        let scene = Scene {
            objects,
            materials: vec![
                floor,
                Material::DiffuseLight { emit: EMIT },
                Material::Mirror {
                    albedo: DVec3::new(0.8, 0.7, 0.6),
                },
            ],
        };
        World::new(scene, Profile::Course, settings, Vec::new(), 10.0)
    }

    fn settings(integrator: Integrator, max_depth: u32) -> RenderSettings {
        RenderSettings {
            integrator,
            max_depth,
            background: Background::Flat,
            ..RenderSettings::default()
        }
    }

    /// Straight down onto the floor at `(1, 0, 0)`.
    fn down_at_one() -> Ray {
        Ray::new(DVec3::new(1.0, 1.0, 0.0), DVec3::new(0.0, -1.0, 0.0))
    }

    /// Depth 1 is exactly the direct term (the scattered ray's radiance is depth 0, black):
    /// `E min(1, 1/d) a` with `d = sqrt(5)`; the week-5 solution's version `E / d`, not times
    /// the albedo; week 8's `BRDF E n . (c - P)` with the Lambertian's BRDF its albedo and
    /// `n . (c - P) = 2`.
    #[test]
    fn depth_one_is_the_direct_term() {
        let lambertian = Material::Lambertian {
            albedo: FLOOR_ALBEDO,
        };
        let d = (DVec3::new(0.0, 2.0, 0.0) - DVec3::new(1.0, 0.0, 0.0)).length();
        let mut sampler = PixelSampler::new(1, 1);
        let w = world(lambertian, vec![], settings(Integrator::Direct, 1));
        assert_eq!(
            trace(&w, &down_at_one(), &mut sampler),
            (EMIT * (1.0 / d)) * FLOOR_ALBEDO
        );
        let mut unclamped = settings(Integrator::Direct, 1);
        unclamped.direct_term = DirectTerm::Unclamped;
        let w = world(lambertian, vec![], unclamped);
        assert_eq!(trace(&w, &down_at_one(), &mut sampler), EMIT * (1.0 / d));
        let w = world(lambertian, vec![], settings(Integrator::Brdf, 1));
        assert_eq!(
            trace(&w, &down_at_one(), &mut sampler),
            FLOOR_ALBEDO * EMIT * 2.0
        );
        // A camera ray that hits the light sees its emission.
        let at_light = Ray::new(DVec3::new(0.0, 1.5, 0.3), DVec3::new(0.0, 0.5, -0.3));
        let w = world(lambertian, vec![], settings(Integrator::Direct, 1));
        assert_eq!(trace(&w, &at_light, &mut sampler), EMIT);
    }

    /// The course's occlusion test in t units: from 1.5 away, a sphere behind the light shadows;
    /// from 0.5 away (where the light's own sphere of radius 0.1 is beyond the interval) one
    /// occluder alone does not, two do; from `sqrt(5)` away one occluder in between does.
    #[test]
    fn occlusion_counts_hits_in_t_units() {
        let lambertian = Material::Lambertian {
            albedo: FLOOR_ALBEDO,
        };
        let ball = |c: [f64; 3], r: f64| SceneObject {
            shape: Object::Sphere(Sphere::new(DVec3::from(c), r)),
            material: 0,
        };
        let light = DVec3::new(0.0, 2.0, 0.0);
        // From (0, 0.5, 0), 1.5 away: the light's sphere at t = 0.93, a ball beyond it at
        // t = 1.2 (inside the interval's 1.5).
        let below = DVec3::new(0.0, 0.5, 0.0);
        let behind = world(
            lambertian,
            vec![ball([0.0, 2.6, 0.0], 0.3)],
            settings(Integrator::Direct, 1),
        );
        assert!(occluded(&behind, below, light));
        let alone = world(lambertian, vec![], settings(Integrator::Direct, 1));
        assert!(!occluded(&alone, below, light));
        // Farther beyond, at t = 1.6, it is out of the interval.
        let far = world(
            lambertian,
            vec![ball([0.0, 3.2, 0.0], 0.3)],
            settings(Integrator::Direct, 1),
        );
        assert!(!occluded(&far, below, light));
        let one = world(
            lambertian,
            vec![ball([0.0, 2.25, 0.0], 0.05)],
            settings(Integrator::Direct, 1),
        );
        assert!(!occluded(&one, DVec3::new(0.0, 2.5, 0.0), light));
        let two = world(
            lambertian,
            vec![ball([0.0, 2.25, 0.0], 0.05), ball([0.0, 2.35, 0.0], 0.03)],
            settings(Integrator::Direct, 1),
        );
        assert!(occluded(&two, DVec3::new(0.0, 2.5, 0.0), light));
        let between = world(
            lambertian,
            vec![ball([0.5, 1.0, 0.0], 0.2)],
            settings(Integrator::Direct, 1),
        );
        assert!(occluded(&between, DVec3::new(1.0, 0.0, 0.0), light));
        // And then the direct term is 0.
        let mut sampler = PixelSampler::new(1, 1);
        assert_eq!(trace(&between, &down_at_one(), &mut sampler), DVec3::ZERO);
    }

    /// A mirror at depth 2 with no light in view: its albedo times what the reflected ray
    /// sees; in the book's profile the same with the unit reflection.
    #[test]
    fn a_mirror_shows_the_reflected_background() {
        let mirror = Material::Mirror {
            albedo: DVec3::new(0.8, 0.7, 0.6),
        };
        let mut s = settings(Integrator::Direct, 2);
        s.background = Background::Sky;
        // The floor alone, a mirror, without the light.
        let mut dark = world(mirror, vec![], s).scene().clone();
        dark.objects.truncate(1);
        let ray = Ray::new(DVec3::new(3.0, 1.0, 0.0), DVec3::new(-2.0, -1.0, 0.5));
        let reflected = DVec3::new(-2.0, 1.0, 0.5);
        let mut sampler = PixelSampler::new(1, 1);
        let w = World::new(dark.clone(), Profile::Course, s, Vec::new(), 10.0);
        assert_eq!(
            trace(&w, &ray, &mut sampler),
            DVec3::new(0.8, 0.7, 0.6) * sky(reflected)
        );
        let w = World::new(dark, Profile::Physical, s, Vec::new(), 10.0);
        let unit = crate::geometry::unit_vector(reflected);
        assert_eq!(
            trace(&w, &ray, &mut sampler),
            DVec3::new(0.8, 0.7, 0.6) * sky(unit)
        );
    }
}
