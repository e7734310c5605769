use crate::geometry::{HitRecord, Interval, MovingSphere, Quad, Ray, Shape, Sphere, Triangle};

use super::Material;

/// One of the primitives a scene is made of (an enum, so closest-hit loops dispatch statically).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Object {
    /// A sphere.
    Sphere(Sphere),
    /// A sphere that moves with the ray's time.
    MovingSphere(MovingSphere),
    /// A parallelogram.
    Quad(Quad),
    /// A triangle.
    Triangle(Triangle),
}

impl Object {
    /// Whether the test is closed at the interval's ends (quads and triangles, the course's
    /// `contains`) rather than open (spheres, `surrounds`): at exactly the same `t` as an
    /// earlier object, a closed one replaces it in [`Scene::closest`] and an open one does not.
    #[inline]
    pub fn is_closed(&self) -> bool {
        matches!(self, Object::Quad(_) | Object::Triangle(_))
    }
}

impl Shape for Object {
    #[inline]
    fn intersect(&self, ray: &Ray, interval: Interval) -> Option<HitRecord> {
        match self {
            Object::Sphere(s) => s.intersect(ray, interval),
            Object::MovingSphere(s) => s.intersect(ray, interval),
            Object::Quad(q) => q.intersect(ray, interval),
            Object::Triangle(t) => t.intersect(ray, interval),
        }
    }

    #[inline]
    fn hit_t(&self, ray: &Ray, interval: Interval) -> Option<f64> {
        match self {
            Object::Sphere(s) => s.hit_t(ray, interval),
            Object::MovingSphere(s) => s.hit_t(ray, interval),
            Object::Quad(q) => q.hit_t(ray, interval),
            Object::Triangle(t) => t.hit_t(ray, interval),
        }
    }
}

/// An object with the index of its material in [`Scene::materials`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneObject {
    /// The geometry.
    pub shape: Object,
    /// Index into [`Scene::materials`].
    pub material: usize,
}

/// A list of objects and their materials, intersected the way the course's `Scene` does it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Scene {
    /// The objects, in the order they were added (the order decides ties, as in the course).
    pub objects: Vec<SceneObject>,
    /// The materials the objects refer to.
    pub materials: Vec<Material>,
}

impl Scene {
    /// The closest hit's `t` and object index: each object in turn is intersected with
    /// `[interval.min, closest so far]`, as the course's `find_intersection` does, so an object
    /// at exactly the same `t` as an earlier one replaces it only when its test is closed.
    #[inline]
    pub fn closest(&self, ray: &Ray, interval: Interval) -> Option<(f64, usize)> {
        let mut best = None;
        let mut closest = interval.max;
        for (index, object) in self.objects.iter().enumerate() {
            if let Some(t) = object
                .shape
                .hit_t(ray, Interval::new(interval.min, closest))
            {
                closest = t;
                best = Some((t, index));
            }
        }
        best
    }

    /// How many objects, tested one by one in order, are hit within `interval` (not shrunk),
    /// stopping at `limit` (the test follows the increment, so a first hit counts even when
    /// `limit` is 0).
    #[inline]
    pub fn count_hits(&self, ray: &Ray, interval: Interval, limit: usize) -> usize {
        let mut count = 0;
        for o in &self.objects {
            if o.shape.hit_t(ray, interval).is_some() {
                count += 1;
                if count >= limit {
                    break;
                }
            }
        }
        count
    }

    /// The full record of the closest hit, its `material` set to the object's material index.
    pub fn hit(&self, ray: &Ray, interval: Interval) -> Option<HitRecord> {
        let mut best = None;
        let mut closest = interval.max;
        for object in &self.objects {
            if let Some(mut hit) = object
                .shape
                .intersect(ray, Interval::new(interval.min, closest))
            {
                closest = hit.t;
                hit.material = object.material;
                best = Some(hit);
            }
        }
        best
    }

    /// The material of object `index`.
    #[inline]
    pub fn material_of(&self, index: usize) -> &Material {
        &self.materials[self.objects[index].material]
    }
}
