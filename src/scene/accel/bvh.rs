//! A bounding volume hierarchy over a scene's objects that answers exactly as the linear scan
//! does ([`Scene::closest`]): the same object and the same `t`, bit for bit, ties included.
//!
//! The scan tests each object in order against `[min, closest so far]`; an object's answer does
//! not depend on the upper end except through it (a sphere reports its first root above `min`
//! when that is below the end, a quad or triangle its `t` when that is at most the end). So the
//! scan's answer is the object of least `t`, and among objects at exactly that `t` (in order) the
//! first one, replaced by each later one whose test is closed ([`Object::is_closed`]). The
//! hierarchy finds every object that may hit at or below the best `t` so far and applies that
//! rule, so the order it visits them in does not matter.
//!
//! Boxes are padded so that no hit an object's own floating-point test reports is ever outside
//! its box: by `1e-9 L` (`L` bounds every coordinate a ray or object has, so this holds the
//! rounding of the slab test and of the hit point), and for spheres by `1e-13 L^2 / |r|` (a
//! sphere's robust discriminant can report a line within about `10 eps (|f|^2 + r^2) / |r|` of
//! it as a hit) and for quads by `1e-14 L |u| |v| / |u x v|` (the rounding of `alpha` and `beta`
//! lets a skinny quad accept points that far outside it). The tests compare it with the scan on
//! random scenes and rays.

use glam::DVec3;

use crate::geometry::{Interval, Ray, Shape};
use crate::scene::{Object, Scene};

/// Objects per leaf at most.
const LEAF_SIZE: usize = 4;

/// Scenes with more objects than this get a hierarchy; smaller ones are scanned.
pub const BVH_MIN_OBJECTS: usize = 16;

/// An axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Aabb {
    lo: DVec3,
    hi: DVec3,
}

impl Aabb {
    const EMPTY: Aabb = Aabb {
        lo: DVec3::splat(f64::INFINITY),
        hi: DVec3::splat(f64::NEG_INFINITY),
    };

    fn of_points(points: &[DVec3]) -> Self {
        points.iter().fold(Self::EMPTY, |b, &p| Aabb {
            lo: b.lo.min(p),
            hi: b.hi.max(p),
        })
    }

    fn union(self, other: Aabb) -> Aabb {
        Aabb {
            lo: self.lo.min(other.lo),
            hi: self.hi.max(other.hi),
        }
    }

    fn padded(self, pad: f64) -> Aabb {
        Aabb {
            lo: self.lo - DVec3::splat(pad),
            hi: self.hi + DVec3::splat(pad),
        }
    }

    fn centre(self) -> DVec3 {
        (self.lo + self.hi) * 0.5
    }

    /// The parameters `(near, far)` where the ray's line is inside the box, clipped to
    /// `[min, max]`, or `None` when that is empty. An axis along which the ray does not move
    /// constrains nothing when the origin is inside the slab and excludes everything otherwise.
    #[inline]
    fn clip(&self, ray: &Ray, min: f64, max: f64) -> Option<(f64, f64)> {
        let (mut near, mut far) = (min, max);
        for axis in 0..3 {
            let (o, d) = (ray.origin[axis], ray.direction[axis]);
            let (lo, hi) = (self.lo[axis], self.hi[axis]);
            if d == 0.0 {
                if !(lo <= o && o <= hi) {
                    return None;
                }
                continue;
            }
            let inv = 1.0 / d;
            let (t0, t1) = ((lo - o) * inv, (hi - o) * inv);
            let (t0, t1) = if t0 <= t1 { (t0, t1) } else { (t1, t0) };
            // A NaN bound (an infinite coordinate) leaves the other end as it is.
            near = near.max(t0);
            far = far.min(t1);
            if near > far {
                return None;
            }
        }
        Some((near, far))
    }
}

/// A node: a box and either two children or a run of objects.
#[derive(Clone, Copy, Debug)]
struct Node {
    bounds: Aabb,
    /// A leaf's first entry in `order`, or an inner node's second child (the first follows it).
    start: u32,
    /// A leaf's number of objects; 0 for an inner node.
    count: u32,
}

/// The hierarchy of a scene's objects.
#[derive(Clone, Debug)]
pub(crate) struct Bvh {
    nodes: Vec<Node>,
    /// Object indices in leaf order.
    order: Vec<u32>,
}

/// The next `f64` above `x` (for a finite `x` or `-inf`; `+inf` stays).
#[inline]
fn next_up(x: f64) -> f64 {
    if x.is_nan() || x == f64::INFINITY {
        return x;
    }
    if x == 0.0 {
        return f64::from_bits(1);
    }
    let bits = x.to_bits();
    f64::from_bits(if x > 0.0 { bits + 1 } else { bits - 1 })
}

/// The object's box, padded as the module's docs say, with `reach` bounding every coordinate.
fn bounds_of(object: &Object, reach: f64) -> Aabb {
    let base = 1e-9 * reach;
    match object {
        Object::Sphere(s) => {
            let r = s.radius.abs();
            Aabb::of_points(&[s.center - DVec3::splat(r), s.center + DVec3::splat(r)])
                .padded(base + 1e-13 * reach * reach / r)
        }
        Object::MovingSphere(m) => {
            let r = m.sphere.radius.abs();
            let at = |c: DVec3| Aabb::of_points(&[c - DVec3::splat(r), c + DVec3::splat(r)]);
            at(m.sphere.center)
                .union(at(m.end))
                .padded(base + 1e-13 * reach * reach / r)
        }
        Object::Quad(q) => {
            let skew = q.u.length() * q.v.length() / q.u.cross(q.v).length();
            Aabb::of_points(&[q.q, q.q + q.u, q.q + q.v, q.q + q.u + q.v])
                .padded(base + 1e-14 * reach * skew)
        }
        Object::Triangle(t) => Aabb::of_points(&[t.a, t.b, t.c]).padded(base),
    }
}

/// The best hit so far, with what the tie rule needs.
#[derive(Clone, Copy, Debug)]
struct Best {
    t: f64,
    /// The first object (in scene order) found at `t`.
    first: usize,
    /// The last object with a closed test found at `t`.
    last_closed: Option<usize>,
}

impl Bvh {
    /// The hierarchy of `scene`'s objects, or `None` when a box is not finite (a scene at the
    /// edge of `f64`, which the linear scan handles). `reach` bounds the magnitude of every
    /// coordinate of every ray origin (the eye, its lens, or a point on an object).
    pub(crate) fn new(scene: &Scene, reach: f64) -> Option<Self> {
        let reach = scene
            .objects
            .iter()
            .map(|o| {
                let b = bounds_of(&o.shape, 0.0);
                b.lo.abs().max(b.hi.abs()).max_element()
            })
            .fold(reach.abs(), f64::max);
        let boxes: Vec<Aabb> = scene
            .objects
            .iter()
            .map(|o| bounds_of(&o.shape, reach))
            .collect();
        let finite = |b: &Aabb| b.lo.is_finite() && b.hi.is_finite();
        if !reach.is_finite() || reach > 1e100 || !boxes.iter().all(finite) || boxes.is_empty() {
            return None;
        }
        let mut order: Vec<u32> = (0..boxes.len() as u32).collect();
        let mut nodes = Vec::with_capacity(2 * boxes.len() / LEAF_SIZE + 1);
        Self::build(&boxes, &mut order, 0, &mut nodes);
        Some(Self { nodes, order })
    }

    /// Builds the node of `order[offset..]`'s slice `items`, appending it (and its subtree) to
    /// `nodes`: split at the median of the centres along the longest axis of their extent, ties
    /// broken by object index, so the tree depends only on the scene.
    fn build(boxes: &[Aabb], items: &mut [u32], offset: usize, nodes: &mut Vec<Node>) {
        let bounds = items
            .iter()
            .fold(Aabb::EMPTY, |b, &i| b.union(boxes[i as usize]));
        let me = nodes.len();
        nodes.push(Node {
            bounds,
            start: offset as u32,
            count: items.len() as u32,
        });
        if items.len() <= LEAF_SIZE {
            return;
        }
        let centres = items.iter().fold(Aabb::EMPTY, |b, &i| {
            let c = boxes[i as usize].centre();
            Aabb {
                lo: b.lo.min(c),
                hi: b.hi.max(c),
            }
        });
        let extent = centres.hi - centres.lo;
        let axis = if extent.x >= extent.y && extent.x >= extent.z {
            0
        } else if extent.y >= extent.z {
            1
        } else {
            2
        };
        items.sort_by(|&a, &b| {
            let (ca, cb) = (
                boxes[a as usize].centre()[axis],
                boxes[b as usize].centre()[axis],
            );
            ca.total_cmp(&cb).then(a.cmp(&b))
        });
        let half = items.len() / 2;
        let (left, right) = items.split_at_mut(half);
        Self::build(boxes, left, offset, nodes);
        let second = nodes.len();
        Self::build(boxes, right, offset + half, nodes);
        nodes[me].start = second as u32;
        nodes[me].count = 0;
    }

    /// The same answer as `scene.closest(ray, interval)` (see the module's docs).
    #[inline]
    pub(crate) fn closest(
        &self,
        scene: &Scene,
        ray: &Ray,
        interval: Interval,
    ) -> Option<(f64, usize)> {
        let mut best: Option<Best> = None;
        let mut stack = [0u32; 64];
        let mut depth = 1;
        while depth > 0 {
            depth -= 1;
            let index = stack[depth];
            let node = self.nodes[index as usize];
            let bound = best.map_or(interval.max, |b| b.t);
            if node.bounds.clip(ray, interval.min, bound).is_none() {
                continue;
            }
            if node.count == 0 {
                // The first child follows its parent; the second is at `start`.
                stack[depth] = index + 1;
                stack[depth + 1] = node.start;
                depth += 2;
                continue;
            }
            let run = node.start as usize..(node.start + node.count) as usize;
            for &k in &self.order[run] {
                let k = k as usize;
                let object = &scene.objects[k].shape;
                let bound = best.map_or(interval.max, |b| b.t);
                let within = Interval::new(interval.min, next_up(bound));
                let Some(t) = object.hit_t(ray, within) else {
                    continue;
                };
                let closed = object.is_closed();
                match &mut best {
                    None if t < interval.max || (t == interval.max && closed) => {
                        best = Some(Best {
                            t,
                            first: k,
                            last_closed: closed.then_some(k),
                        });
                    }
                    Some(b) if t < b.t => {
                        *b = Best {
                            t,
                            first: k,
                            last_closed: closed.then_some(k),
                        };
                    }
                    Some(b) if t == b.t => {
                        b.first = b.first.min(k);
                        if closed {
                            b.last_closed = Some(b.last_closed.map_or(k, |c| c.max(k)));
                        }
                    }
                    _ => {}
                }
            }
        }
        let b = best?;
        let winner = if b.t < interval.max {
            match b.last_closed {
                Some(c) if c > b.first => c,
                _ => b.first,
            }
        } else {
            b.last_closed?
        };
        Some((b.t, winner))
    }

    /// How many objects `ray` hits within `interval` (each tested against the whole interval),
    /// counting up to `limit`.
    pub(crate) fn count_hits(
        &self,
        scene: &Scene,
        ray: &Ray,
        interval: Interval,
        limit: usize,
    ) -> usize {
        let mut count = 0;
        let mut stack = [0u32; 64];
        let mut depth = 1;
        while depth > 0 {
            depth -= 1;
            let index = stack[depth];
            let node = self.nodes[index as usize];
            if node.bounds.clip(ray, interval.min, interval.max).is_none() {
                continue;
            }
            if node.count == 0 {
                // The first child follows its parent; the second is at `start`.
                stack[depth] = index + 1;
                stack[depth + 1] = node.start;
                depth += 2;
                continue;
            }
            let run = node.start as usize..(node.start + node.count) as usize;
            for &k in &self.order[run] {
                if scene.objects[k as usize]
                    .shape
                    .hit_t(ray, interval)
                    .is_some()
                {
                    count += 1;
                    if count >= limit {
                        return count;
                    }
                }
            }
        }
        count
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{MovingSphere, Quad, Sphere, Triangle};
    use crate::render::PixelSampler;
    use crate::scene::{Material, SceneObject, World};

    /// A random scene of `count` objects: spheres of both signs (some moving), quads and
    /// triangles, at scales from `1e-3` to `1e3` times `spread`, with now and then an exact
    /// duplicate of an earlier object (ties, open and closed) and big objects around the rays'
    /// origins.
    fn random_scene(s: &mut PixelSampler, count: usize, spread: f64) -> Scene {
        let mut objects: Vec<Object> = Vec::new();
        for _ in 0..count {
            if !objects.is_empty() && s.next_f64() < 0.15 {
                let k = (s.next_f64() * objects.len() as f64) as usize;
                objects.push(objects[k]);
                continue;
            }
            let centre = DVec3::new(
                s.uniform(-1.0, 1.0),
                s.uniform(-1.0, 1.0),
                s.uniform(-1.0, 1.0),
            ) * spread;
            let size = spread * 10f64.powf(s.uniform(-3.0, 0.3));
            let object = match (s.next_f64() * 5.0) as usize {
                0 => Object::Sphere(Sphere::new(centre, size)),
                1 => Object::Sphere(Sphere::new(centre, -size)),
                2 => Object::MovingSphere(MovingSphere::new(
                    Sphere::new(centre, size),
                    centre + s.unit_vector() * size * 3.0,
                )),
                3 => Object::Quad(Quad::new(
                    centre,
                    s.unit_vector() * size,
                    s.unit_vector() * size * s.uniform(0.01, 2.0),
                )),
                _ => Object::Triangle(Triangle::new(
                    centre,
                    centre + s.unit_vector() * size,
                    centre + s.unit_vector() * size,
                )),
            };
            objects.push(object);
        }
        Scene {
            objects: objects
                .into_iter()
                .map(|shape| SceneObject { shape, material: 0 })
                .collect(),
            materials: vec![Material::Lambertian { albedo: DVec3::ONE }],
        }
    }

    /// The hierarchy answers exactly as the linear scan, closest hit and occlusion count, on
    /// random scenes and rays: rays from far away, from inside the scene, from points on its
    /// objects (as bounces start), towards objects' centres and corners and anywhere, at
    /// random times, with the camera's and the book's intervals.
    #[test]
    fn the_hierarchy_answers_as_the_scan() {
        let mut s = PixelSampler::new(31, 0);
        let mut checked = 0;
        for scene_number in 0..120 {
            let spread = [1.0, 1e-3, 1e3, 50.0][scene_number % 4];
            let count = [17, 40, 200][scene_number % 3];
            let scene = random_scene(&mut s, count, spread);
            let world = World::from(scene.clone()).with_hierarchy(3.0 * spread);
            assert!(world.has_hierarchy());
            for _ in 0..2000 {
                let target = match (s.next_f64() * 3.0) as usize {
                    0 => {
                        let k = (s.next_f64() * count as f64) as usize;
                        match scene.objects[k].shape {
                            Object::Sphere(x) => x.center + s.unit_vector() * x.radius,
                            Object::MovingSphere(m) => m.sphere.center,
                            Object::Quad(q) => q.q + q.u * s.next_f64().round() + q.v,
                            Object::Triangle(t) => t.b,
                        }
                    }
                    _ => {
                        DVec3::new(
                            s.uniform(-1.0, 1.0),
                            s.uniform(-1.0, 1.0),
                            s.uniform(-1.0, 1.0),
                        ) * spread
                    }
                };
                let origin = match (s.next_f64() * 3.0) as usize {
                    0 => s.unit_vector() * 3.0 * spread,
                    1 => {
                        DVec3::new(
                            s.uniform(-1.0, 1.0),
                            s.uniform(-1.0, 1.0),
                            s.uniform(-1.0, 1.0),
                        ) * spread
                    }
                    _ => {
                        // A point on an object, as a bounce starts.
                        let ray = Ray::new(s.unit_vector() * 3.0 * spread, target);
                        match scene.closest(&ray, Interval::CAMERA) {
                            Some((t, _)) => ray.at(t),
                            None => target * 0.5,
                        }
                    }
                };
                let mut ray = Ray::new(origin, target - origin);
                ray.time = s.next_f64();
                for interval in [
                    Interval::CAMERA,
                    Interval::new(0.001, f64::INFINITY),
                    Interval::new(1e-6, 0.7),
                ] {
                    let expected = scene.closest(&ray, interval);
                    let got = world.closest(&ray, interval);
                    assert_eq!(
                        got.map(|(t, k)| (t.to_bits(), k)),
                        expected.map(|(t, k)| (t.to_bits(), k)),
                        "scene {scene_number}, {ray:?}, {interval:?}"
                    );
                    let scan = scene
                        .objects
                        .iter()
                        .filter(|o| o.shape.hit_t(&ray, interval).is_some())
                        .count();
                    assert_eq!(world.count_hits(&ray, interval, usize::MAX), scan);
                    assert_eq!(world.count_hits(&ray, interval, 2), scan.min(2));
                    checked += 1;
                }
            }
        }
        assert!(checked > 500_000);
    }

    /// Ties, by hand: equal spheres keep the first, equal quads the last, a sphere and a quad at
    /// the same `t` the quad when it comes later and the sphere when it comes first... and the
    /// hierarchy agrees on every order of 20 such objects.
    #[test]
    fn the_hierarchy_keeps_the_scan_s_ties() {
        let sphere = Object::Sphere(Sphere::new(DVec3::new(0.0, 0.0, -5.0), 1.0));
        // The plane z = -4 through the sphere's near point, facing +z.
        let quad = Object::Quad(Quad::new(
            DVec3::new(-1.0, -1.0, -4.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(0.0, 2.0, 0.0),
        ));
        let ray = Ray::new(DVec3::ZERO, DVec3::new(0.0, 0.0, -1.0));
        assert_eq!(sphere.hit_t(&ray, Interval::CAMERA), Some(4.0));
        assert_eq!(quad.hit_t(&ray, Interval::CAMERA), Some(4.0));
        let mut s = PixelSampler::new(2, 2);
        for _ in 0..300 {
            let objects: Vec<Object> = (0..20)
                .map(|_| if s.next_f64() < 0.5 { sphere } else { quad })
                .collect();
            let scene = Scene {
                objects: objects
                    .iter()
                    .map(|&shape| SceneObject { shape, material: 0 })
                    .collect(),
                materials: vec![],
            };
            let world = World::from(scene.clone()).with_hierarchy(10.0);
            for interval in [Interval::CAMERA, Interval::new(1e-6, 4.0)] {
                assert_eq!(
                    world.closest(&ray, interval),
                    scene.closest(&ray, interval),
                    "{objects:?} {interval:?}"
                );
            }
        }
    }
}
