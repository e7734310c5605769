//! Everything a render reads ([`World`]): the objects and materials, the images of the textures
//! prepared for the profile, the point lights, the settings, and, for the closest-hit and
//! occlusion queries, a bounding volume hierarchy (large scenes) or the objects side by side
//! (small scenes of spheres, moving spheres and quads).

use glam::DVec3;

use super::accel::bvh::{BVH_MIN_OBJECTS, Bvh};
use super::accel::shape_set::ShapeSet;
use super::{Material, Object, Profile, RenderSettings, Scene, TextureImage};
use crate::geometry::{Interval, Ray};

/// A point light: the course's `find_point_lights` makes one of every sphere whose material is a
/// light, at its centre (at time 0 for a moving one), whatever its radius.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLight {
    /// Where it is.
    pub center: DVec3,
    /// Its emitted colour `E`.
    pub emit: DVec3,
    /// The object it comes from.
    pub object: usize,
}

/// A scene ready to render. It dereferences to its [`Scene`] (objects and materials).
#[derive(Clone, Debug)]
pub struct World {
    scene: Scene,
    /// The rules it is rendered by.
    pub profile: Profile,
    /// The integrator and its settings.
    pub settings: RenderSettings,
    /// The images of the scene's textures, prepared for `profile`.
    pub images: Vec<TextureImage>,
    /// The point lights, in object order.
    pub point_lights: Vec<PointLight>,
    /// Whether an object moves (so rays draw a time).
    pub moving: bool,
    /// The scene's `samples_per_pixel` (the course's jittered sampling takes its strata and its
    /// division from it); 1 unless set.
    pub samples_per_pixel: u32,
    bvh: Option<Bvh>,
    /// The objects side by side, when every object is a sphere, a moving sphere or a quad and
    /// there is no hierarchy.
    shapes: Option<ShapeSet>,
}

impl std::ops::Deref for World {
    type Target = Scene;

    fn deref(&self) -> &Scene {
        &self.scene
    }
}

impl From<Scene> for World {
    /// A week-4 world: `scene` under the default settings, with no images, its lights found and
    /// a hierarchy when it is large.
    fn from(scene: Scene) -> Self {
        World::new(
            scene,
            Profile::Course,
            RenderSettings::default(),
            Vec::new(),
            0.0,
        )
    }
}

impl World {
    /// The world of `scene` rendered by `profile` with `settings`, reading `images`; `eye_reach`
    /// bounds the magnitude of the coordinates of every point a camera ray may start from (the
    /// eye and its lens), for the hierarchy's padding.
    pub fn new(
        scene: Scene,
        profile: Profile,
        settings: RenderSettings,
        images: Vec<TextureImage>,
        eye_reach: f64,
    ) -> Self {
        let point_lights = scene
            .objects
            .iter()
            .enumerate()
            .filter_map(|(object, o)| {
                let center = match o.shape {
                    Object::Sphere(s) => s.center,
                    Object::MovingSphere(m) => m.sphere.center,
                    _ => return None,
                };
                match scene.materials.get(o.material) {
                    Some(&Material::DiffuseLight { emit }) => Some(PointLight {
                        center,
                        emit,
                        object,
                    }),
                    _ => None,
                }
            })
            .collect();
        let moving = scene
            .objects
            .iter()
            .any(|o| matches!(o.shape, Object::MovingSphere(_)));
        let bvh = if scene.objects.len() > BVH_MIN_OBJECTS {
            Bvh::new(&scene, eye_reach)
        } else {
            None
        };
        let shapes = if bvh.is_none() {
            ShapeSet::new(&scene)
        } else {
            None
        };
        Self {
            scene,
            profile,
            settings,
            images,
            point_lights,
            moving,
            samples_per_pixel: 1,
            bvh,
            shapes,
        }
    }

    /// The objects and materials.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// Whether the hierarchy is used (more than [`BVH_MIN_OBJECTS`] objects of finite extent).
    pub fn has_hierarchy(&self) -> bool {
        self.bvh.is_some()
    }

    /// The closest hit's `t` and object index: exactly [`Scene::closest`]'s answer, through the
    /// hierarchy when there is one, or the side-by-side list of a small scene of spheres and
    /// quads.
    #[inline(always)]
    pub fn closest(&self, ray: &Ray, interval: Interval) -> Option<(f64, usize)> {
        match &self.bvh {
            Some(bvh) => bvh.closest(&self.scene, ray, interval),
            None => match self.shapes.as_ref().and_then(|s| s.closest(ray, interval)) {
                Some(answer) => answer,
                None => self.scene.closest(ray, interval),
            },
        }
    }

    /// How many objects `ray` hits within `interval`, each tested against the whole interval (the
    /// course's occlusion test), counting up to `limit`: exactly [`Scene::count_hits`]'s answer.
    #[inline(always)]
    pub fn count_hits(&self, ray: &Ray, interval: Interval, limit: usize) -> usize {
        match &self.bvh {
            Some(bvh) => bvh.count_hits(&self.scene, ray, interval, limit),
            None => match self.shapes.as_ref() {
                Some(set) => set
                    .count_hits(ray, interval, limit)
                    .unwrap_or_else(|| self.scene.count_hits(ray, interval, limit)),
                None => self.scene.count_hits(ray, interval, limit),
            },
        }
    }

    /// The objects side by side, when every object is a sphere, a moving sphere or a quad and
    /// there is no hierarchy: the renderer then traces four paths at a time through their lanes
    /// queries.
    #[inline(always)]
    pub(crate) fn shape_set(&self) -> Option<&ShapeSet> {
        self.shapes.as_ref()
    }

    /// A copy without the side-by-side objects (the scene's own loop, one ray at a time), for
    /// tests that compare the two.
    #[cfg(test)]
    pub(crate) fn without_shape_set(mut self) -> Self {
        self.shapes = None;
        self
    }

    /// A copy without the hierarchy (the linear scan), for tests that compare the two.
    #[cfg(test)]
    pub(crate) fn without_hierarchy(mut self) -> Self {
        self.bvh = None;
        self
    }

    /// A copy with the hierarchy switched on (when the scene's boxes are finite) whatever the
    /// number of objects, for tests that compare it with the scan.
    #[cfg(test)]
    pub(crate) fn with_hierarchy(mut self, eye_reach: f64) -> Self {
        self.bvh = Bvh::new(&self.scene, eye_reach);
        self
    }
}
