//! The fast path against `Scene::closest`, bit for bit.

use super::*;
use crate::geometry::{Sphere, Triangle};
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
        // The week-4 scenes take the fast path; the others are checked more briefly.
        let count = if description.render.integrator == crate::scene::Integrator::Albedo {
            250_000
        } else {
            20_000
        };
        for _ in 0..count {
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
                Object::MovingSphere(m) => targets.push(m.sphere.center),
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
        let mut packet = Directions::default();
        let mut expected_indices = [NO_HIT; WIDTH];
        for (n, target) in targets.into_iter().enumerate() {
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
            // Packets of consecutive targets: neighbours in the image, or unrelated features.
            packet.set(n % WIDTH, d);
            expected_indices[n % WIDTH] = expected.map_or(NO_HIT, |(_, i)| i as u64);
            if n % WIDTH == WIDTH - 1 {
                assert_eq!(
                    fast.closest_packet(&packet, Interval::CAMERA, ALL_CANDIDATES),
                    expected_indices,
                    "{} along {packet:?}",
                    builtin.name
                );
            }
            checked += 1;
        }
    }
    assert!(checked > 1_000_000);
}

/// Triangles from random eyes, alone and mixed with spheres and quads, over rays aimed at
/// their vertices, at points of their edges (and just off them, by a few ulps and by
/// `1e-9`), and anywhere: the edge pre-classification answers exactly as `Scene::closest`,
/// in packets and one ray at a time. Far, huge and tiny triangles take the same paths.
#[test]
fn triangles_agree_with_the_scene_bit_for_bit_near_their_edges() {
    let mut rng = PixelSampler::new(23, 0);
    let mut r = move |lo: f64, hi: f64| lo + (hi - lo) * rng.next_f64();
    let mut checked = 0usize;
    for scene_index in 0..300 {
        let scale = [1.0, 1e-3, 1e4, 1e-150, 1e150][scene_index % 5];
        let mut point =
            |spread: f64| DVec3::new(r(-1.0, 1.0), r(-1.0, 1.0), r(-3.0, -1.0)) * spread * scale;
        let triangles: Vec<Triangle> = (0..3)
            .map(|_| Triangle::new(point(1.0), point(1.0), point(1.0)))
            .collect();
        let mut shapes: Vec<Object> = triangles.iter().map(|&t| Object::Triangle(t)).collect();
        if scene_index % 3 == 1 {
            shapes.insert(1, Object::Sphere(Sphere::new(point(1.0), 0.3 * scale)));
            shapes.push(Object::Quad(Quad::new(
                point(1.0),
                DVec3::new(0.5, 0.1, 0.0) * scale,
                DVec3::new(0.0, 0.4, 0.2) * scale,
            )));
        }
        let scene = scene_of(&shapes);
        let origin = DVec3::new(r(-0.2, 0.2), r(-0.2, 0.2), r(0.0, 0.5)) * scale;
        let fast = FixedOrigin::new(&scene, origin);
        let mut targets = Vec::new();
        for t in &triangles {
            for (p, q) in [(t.a, t.b), (t.b, t.c), (t.c, t.a)] {
                targets.push(p);
                for _ in 0..40 {
                    let on_edge = p + (q - p) * r(0.0, 1.0);
                    targets.push(on_edge);
                    let off = (q - p).cross(t.normal);
                    for k in [1e-9, -1e-9, 4e-16, -4e-16, 1e-15, -1e-15] {
                        targets.push(on_edge + off * k);
                    }
                }
            }
            for _ in 0..100 {
                targets.push(t.a + (t.b - t.a) * r(-0.5, 1.5) + (t.c - t.a) * r(-0.5, 1.5));
            }
        }
        let mut packet = Directions::default();
        let mut expected_indices = [NO_HIT; WIDTH];
        for (n, target) in targets.into_iter().enumerate() {
            let d = target - origin;
            let expected = scene.closest(&Ray::new(origin, d), Interval::CAMERA);
            assert_eq!(
                fast.closest(d, Interval::CAMERA)
                    .map(|(t, i)| (t.to_bits(), i)),
                expected.map(|(t, i)| (t.to_bits(), i)),
                "scene {scene_index} along {d}"
            );
            packet.set(n % WIDTH, d);
            expected_indices[n % WIDTH] = expected.map_or(NO_HIT, |(_, i)| i as u64);
            if n % WIDTH == WIDTH - 1 {
                assert_eq!(
                    fast.closest_packet(&packet, Interval::CAMERA, ALL_CANDIDATES),
                    expected_indices,
                    "scene {scene_index} along {packet:?}"
                );
            }
            checked += 1;
        }
    }
    assert!(checked > 500_000, "{checked}");
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

/// A scene of `shapes`, all with one material.
fn scene_of(shapes: &[Object]) -> Scene {
    Scene {
        objects: shapes
            .iter()
            .map(|&shape| crate::scene::SceneObject { shape, material: 0 })
            .collect(),
        materials: vec![crate::scene::Material::Lambertian {
            albedo: DVec3::splat(0.5),
        }],
    }
}

/// Exact cases the random rays above almost never meet, each with a known answer: equal
/// spheres keep the first (the open `surrounds`), equal quads the last (the closed
/// `contains`), a ray tangent to a sphere with a discriminant of exactly 0 hits it at `t = 5`,
/// a ray through a quad's corner hits it, a quad exactly at `t = 1e-6` is hit (closed) and one
/// at `t = 2^-20 < 1e-6` is not. Every lane of a packet gets the scene's answer, in any lane.
#[test]
fn packets_keep_ties_tangents_and_boundaries() {
    let eye = DVec3::new(-5.0, 0.0, 0.0);
    let sphere = Sphere::new(DVec3::new(0.0, 0.0, -1.0), 1.0);
    // A square in the plane x = x0 facing -x (normal (1, 0, 0) from u x v = (4, 0, 0)), from
    // (x0, 0, 0) to (x0, 2, -2).
    let square_at = |x0: f64| {
        Quad::new(
            DVec3::new(x0, 0.0, 0.0),
            DVec3::new(0.0, 0.0, -2.0),
            DVec3::new(0.0, 2.0, 0.0),
        )
    };
    let square = square_at(0.0);
    let cases: [(&str, DVec3, Vec<Object>, DVec3, u64); 7] = [
        (
            "equal spheres",
            eye,
            vec![Object::Sphere(sphere), Object::Sphere(sphere)],
            DVec3::new(5.0, 0.0, -1.0),
            0,
        ),
        (
            "equal quads",
            eye,
            vec![Object::Quad(square), Object::Quad(square)],
            DVec3::new(5.0, 1.0, -1.0),
            1,
        ),
        // f = (-5, 0, 1), a = 1, b' = -5: the perpendicular is (0, 0, 1) and the
        // discriminant 1 * (1 - 1) = 0 exactly; q = 5, both roots 25 / 5 = 5 / 1 = 5.
        (
            "tangent sphere",
            eye,
            vec![Object::Sphere(sphere)],
            DVec3::new(1.0, 0.0, 0.0),
            0,
        ),
        (
            "quad corner",
            eye,
            vec![Object::Quad(square)],
            DVec3::new(5.0, 0.0, 0.0),
            0,
        ),
        // offset = 1e-6 - 0 and t = 1e-6 / 1, both exact.
        (
            "quad at t = 1e-6",
            DVec3::new(0.0, 1.0, -1.0),
            vec![Object::Quad(square_at(1e-6))],
            DVec3::new(1.0, 0.0, 0.0),
            0,
        ),
        // -5 + 2^-20 is exact, so t = 2^-20 ~ 9.5e-7.
        (
            "quad at t = 2^-20",
            DVec3::new(-5.0, 1.0, -1.0),
            vec![Object::Quad(square_at(-5.0 + 2f64.powi(-20)))],
            DVec3::new(1.0, 0.0, 0.0),
            NO_HIT,
        ),
        (
            "no hit behind",
            eye,
            vec![Object::Sphere(sphere), Object::Quad(square)],
            DVec3::new(-1.0, 0.0, 0.0),
            NO_HIT,
        ),
    ];
    let filler = DVec3::new(0.0, 1.0, 0.0);
    for (what, origin, shapes, d, answer) in cases {
        let scene = scene_of(&shapes);
        let expected = scene
            .closest(&Ray::new(origin, d), Interval::CAMERA)
            .map_or(NO_HIT, |(_, i)| i as u64);
        assert_eq!(expected, answer, "{what}: the scene's own answer");
        let fast = FixedOrigin::new(&scene, origin);
        for slot in 0..WIDTH {
            let mut packet = Directions::default();
            for k in 0..WIDTH {
                packet.set(k, if k == slot { d } else { filler });
            }
            let got = fast.closest_packet(&packet, Interval::CAMERA, ALL_CANDIDATES);
            assert_eq!(got[slot], answer, "{what} in lane {slot}");
        }
    }
}

/// A packet where one lane's intermediates overflow (a direction near `f64::MAX`, or one so
/// short its square underflows) takes the scalar path for all its lanes, and every lane still
/// gets the scene's answer; so does a lane with a NaN direction.
#[test]
fn packets_with_an_overflowing_lane_agree_with_the_scene() {
    for name in ["week04-sphere", "week04-quad", "edge-cases", "triangles"] {
        let description = crate::scene::builtin(name).unwrap();
        let scene = description.scene();
        let camera = description.camera(Some(32));
        let fast = FixedOrigin::new(&scene, camera.center);
        let ordinary = [
            camera.pixel00 + 16.0 * camera.pixel_delta_u + 9.0 * camera.pixel_delta_v,
            camera.pixel00 + 3.0 * camera.pixel_delta_u + 20.0 * camera.pixel_delta_v,
            camera.pixel00 + 28.0 * camera.pixel_delta_u + 2.0 * camera.pixel_delta_v,
        ]
        .map(|target| target - camera.center);
        for odd in [
            DVec3::new(0.0, -1e300, -1e300),
            DVec3::new(1e-200, -1e-200, -1e-200),
            DVec3::new(f64::NAN, 0.0, -1.0),
            DVec3::new(0.0, 0.0, f64::NEG_INFINITY),
        ] {
            for slot in 0..WIDTH {
                let mut packet = Directions::default();
                for k in 0..WIDTH {
                    let d = if k == slot {
                        odd
                    } else {
                        ordinary[k % ordinary.len()]
                    };
                    packet.set(k, d);
                }
                let expected: [u64; WIDTH] = std::array::from_fn(|k| {
                    scene
                        .closest(&Ray::new(camera.center, packet.lane(k)), Interval::CAMERA)
                        .map_or(NO_HIT, |(_, i)| i as u64)
                });
                assert_eq!(
                    fast.closest_packet(&packet, Interval::CAMERA, ALL_CANDIDATES),
                    expected,
                    "{name}: {odd} in lane {slot}"
                );
            }
        }
    }
}

/// A quad near the origin: half of them axis-aligned with whole-number corners, half with random
/// edges from 1e-2 to 6 long (slivers among them).
#[cfg(target_arch = "x86_64")]
fn random_quad(s: &mut PixelSampler) -> Quad {
    let q = DVec3::new(
        s.uniform(-3.0, 3.0),
        s.uniform(-3.0, 3.0),
        s.uniform(-3.0, 3.0),
    );
    if s.next_f64() < 0.5 {
        let (a, b) = (s.uniform(0.5, 6.0).round(), s.uniform(0.5, 6.0).round());
        match (s.next_f64() * 3.0) as u32 {
            0 => Quad::new(q.round(), DVec3::X * a, DVec3::Z * b),
            1 => Quad::new(q.round(), DVec3::Y * a, DVec3::X * b),
            _ => Quad::new(q.round(), DVec3::Z * a, DVec3::Y * b),
        }
    } else {
        let u = s.unit_vector() * 10f64.powf(s.uniform(-2.0, 0.8));
        let v = s.unit_vector() * 10f64.powf(s.uniform(-2.0, 0.8));
        Quad::new(q, u, v)
    }
}

/// A direction from `origin` aimed at one of `quads`: a corner, an edge, a centre or a point
/// around it, sometimes pushed nearly into the quad's plane, sometimes anywhere.
#[cfg(target_arch = "x86_64")]
fn aimed_direction(s: &mut PixelSampler, quads: &[(Quad, f64)], origin: DVec3) -> DVec3 {
    let (quad, _) = quads[(s.next_f64() * quads.len() as f64) as usize];
    let (a, b) = match (s.next_f64() * 4.0) as u32 {
        0 => (s.next_f64().round(), s.next_f64().round()),
        1 => (s.next_f64().round(), s.next_f64()),
        2 => (s.uniform(-0.2, 1.2), s.uniform(-0.2, 1.2)),
        _ => (0.5, 0.5),
    };
    let mut target = quad.q + a * quad.u + b * quad.v;
    if s.next_f64() < 0.1 {
        // Nearly in the quad's plane.
        target +=
            (target - origin).cross(quad.normal) * 10.0 + quad.normal * s.uniform(-1e-9, 1e-9);
    }
    if s.next_f64() < 0.1 {
        target = origin + s.unit_vector();
    }
    target - origin
}

/// Both forms of the quad packet test on the same packet, which must agree bit for bit (each
/// lane's `t` and index); returns the indices.
#[cfg(target_arch = "x86_64")]
fn both_quad_forms(
    quads: &[(Quad, f64)],
    candidates: u64,
    origin: DVec3,
    d: &Directions,
    min: f64,
    start: Lanes,
) -> [u64; WIDTH] {
    use super::quad::avx2::quads_hit_avx2;
    use super::quad::quad_hit_lanes;
    let (mut t, mut index) = (start, [NO_HIT; WIDTH]);
    for (me, (quad, offset)) in quads.iter().enumerate() {
        if is_candidate(candidates, me) {
            quad_hit_lanes(quad, *offset, origin, d, min, &mut t, &mut index, me as u64);
        }
    }
    let (mut t_avx, mut index_avx) = (start, [NO_HIT; WIDTH]);
    // SAFETY: the processor has AVX2 (the caller checked it).
    unsafe {
        quads_hit_avx2(
            quads,
            candidates,
            origin,
            d,
            min,
            &mut t_avx,
            &mut index_avx,
        )
    };
    assert_eq!(t.map(f64::to_bits), t_avx.map(f64::to_bits), "{d:?} {min}");
    assert_eq!(index, index_avx, "{d:?} {min}");
    index
}

/// The quad packets' AVX2 form (`quads_hit_avx2`) against the portable one (`quad_hit_lanes`
/// over the same quads), bit for bit: each lane's closest `t` and index, on 2000 sets of up to
/// 70 quads (`random_quad`), packets aimed at their corners, edges and centres and at random
/// (`aimed_direction`), rays nearly in a quad's plane, grazing rays about the parallel bound,
/// every candidate mask, intervals starting at 1e-6 and at 0.5, and packets that already hold a
/// hit.
#[cfg(target_arch = "x86_64")]
#[test]
fn quad_packets_in_vectors_answer_as_the_portable_lanes() {
    if crate::scene::skipped_without_lanes("the AVX2 quad packets are not checked") {
        return;
    }
    let mut s = PixelSampler::new(29, 5);
    let (mut hits, mut grazing) = (0usize, [0usize; 2]);
    for set in 0..2000 {
        let mut origin = DVec3::new(
            s.uniform(-4.0, 4.0),
            s.uniform(-4.0, 4.0),
            s.uniform(-4.0, 12.0),
        );
        let count = 1 + (s.next_f64() * if set % 10 == 0 { 70.0 } else { 8.0 }) as usize;
        let shapes: Vec<Quad> = (0..count).map(|_| random_quad(&mut s)).collect();
        // One set in four: the eye within about 1e-8 of the first quad's plane, and half the
        // lanes along that plane, tilted to meet it near the quad at `t` between 1/2 and 2,
        // with `|n . d|` about the parallel bound (1e-8), on either side of it.
        let graze = set % 4 == 3;
        let first = shapes[0];
        let height = s.uniform(0.5e-8, 2e-8) * if s.next_f64() < 0.5 { -1.0 } else { 1.0 };
        if graze {
            origin = first.q + first.u * s.uniform(-1.0, 2.0) - first.v * s.uniform(0.5, 3.0)
                + first.normal * height;
        }
        let quads: Vec<(Quad, f64)> = (shapes.iter())
            .map(|quad| (*quad, quad.d - quad.normal.dot(origin)))
            .collect();
        let candidates = if s.next_f64() < 0.5 {
            ALL_CANDIDATES
        } else {
            (s.next_f64() * u64::MAX as f64) as u64
        };
        for _ in 0..20 {
            let mut d = Directions::default();
            for k in 0..WIDTH {
                let mut direction = aimed_direction(&mut s, &quads, origin);
                if graze && k % 2 == 0 {
                    let inside = first.q + first.u * s.next_f64() + first.v * s.next_f64();
                    let along = inside - origin;
                    let along = along - first.normal * first.normal.dot(along);
                    direction = along - first.normal * (height * s.uniform(0.5, 2.0));
                    grazing[usize::from(first.normal.dot(direction).abs() >= 1e-8)] += 1;
                }
                d.set(k, direction);
            }
            let min = if s.next_f64() < 0.8 { 1e-6 } else { 0.5 };
            let start = if s.next_f64() < 0.7 {
                [f64::INFINITY; WIDTH]
            } else {
                [0, 1, 2, 3].map(|_| s.uniform(0.0, 20.0))
            };
            let index = both_quad_forms(&quads, candidates, origin, &d, min, start);
            hits += index.iter().filter(|&&i| i != NO_HIT).count();
        }
    }
    // Most lanes aim at a quad, but half the sets leave out about half their quads and some
    // packets start with a hit nearer than the quads: still, a quarter of the lanes hit one.
    assert!(hits > 2000 * 20 * WIDTH / 4, "{hits}");
    // Grazing lanes on both sides of the parallel bound.
    assert!(grazing.iter().all(|&n| n > 1000), "{grazing:?}");
}
