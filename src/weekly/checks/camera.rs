//! The camera and motion: the frame and defocus radius (the reference's [`Camera`]), week 9's
//! jittered strata, week 10's lens, ray time and `random_in_unit_disk`, `move_sphere` and the
//! intersection of a moving sphere at a ray's time (the reference's [`MovingSphere`]).
//!
//! The camera's random functions are judged from the rays it makes (`get_jittered_ray`): each
//! ray's sample point `origin + direction` on the focus plane gives its offset within the pixel
//! (in pixels, along the reference's `pixel_du`, `pixel_dv`), its origin the lens point (in the
//! reference's `u`, `v`, in units of its defocus radius), and its time.

use glam::DVec3;
use serde_json::json;

use super::lambert::vector_samples;
use super::optics::sample_requests;
use super::{
    Body, CASE_TIMEOUT, Case, FunctionCheck, SAMPLES_TIMEOUT, Variant, jnum, jvec, py, stream, week,
};
use crate::geometry::{Interval, MovingSphere, Ray, Shape, Sphere};
use crate::oracle::classify::classify;
use crate::oracle::vectors::{Class as HitClass, RaySpec, ShapeSpec};
use crate::scene::{Camera, CameraSettings};
use crate::weekly::expect::{Class, Expected, Want, numbers};
use crate::weekly::samplers::mistakes;
use crate::weekly::samplers::{
    CAMERA_SAMPLES, DISK_SAMPLES, Sample, SamplerCheck, Standing, camera::JitterSetting,
};

/// A camera as a request states it (the course's `Camera` fields set before `init_camera`).
#[derive(Clone, Copy, Debug)]
pub(crate) struct CameraInput {
    pub(crate) settings: CameraSettings,
    pub(crate) width: usize,
    pub(crate) aspect_ratio: f64,
    pub(crate) spp: u32,
}

impl CameraInput {
    pub(crate) fn json(&self) -> serde_json::Value {
        let s = &self.settings;
        json!({
            "width": self.width, "aspect_ratio": jnum(self.aspect_ratio), "spp": self.spp,
            "vfov": jnum(s.vfov), "look_from": s.look_from, "look_at": s.look_at, "vup": s.up,
            "defocus_angle": jnum(s.defocus_angle), "focus_distance": jnum(s.focus_distance),
        })
    }

    pub(crate) fn reference(&self) -> Camera {
        Camera::new(&self.settings, self.width, self.aspect_ratio)
    }

    /// The reference's frame: `u`, `v`, `w` and the defocus radius.
    pub(crate) fn frame(&self) -> (DVec3, DVec3, DVec3, f64) {
        let c = self.reference();
        let u = c.pixel_delta_u.normalize();
        let v = -c.pixel_delta_v.normalize();
        (u, v, u.cross(v), c.defocus_disk_u.length())
    }

    pub(crate) fn py(&self) -> String {
        let s = &self.settings;
        let v = |a: [f64; 3]| py::vec(DVec3::from(a));
        format!(
            "import RT_camera as rtc\ncam = rtc.Camera()\ncam.img_width = {}\ncam.aspect_ratio = {}\ncam.samples_per_pixel = {}\ncam.vertical_fov = {}\ncam.look_from = {}\ncam.look_at = {}\ncam.vec_up = {}\ncam.init_camera({}, {})",
            self.width,
            py::f(self.aspect_ratio),
            self.spp,
            py::f(s.vfov),
            v(s.look_from),
            v(s.look_at),
            v(s.up),
            py::f(s.defocus_angle),
            py::f(s.focus_distance)
        )
    }
}

/// Week 10's depth-of-field camera (from (-2, 2, 1) at (0, 0, -1), vfov 60, focus 5, 2 degrees).
pub(crate) fn dof_camera(spp: u32, defocus_angle: f64) -> CameraInput {
    CameraInput {
        settings: CameraSettings {
            look_from: [-2.0, 2.0, 1.0],
            look_at: [0.0, 0.0, -1.0],
            up: [0.0, 1.0, 0.0],
            vfov: 60.0,
            focus_distance: 5.0,
            defocus_angle,
        },
        width: 32,
        aspect_ratio: 16.0 / 9.0,
        spp,
    }
}

pub(crate) fn checks(seed: u64) -> Vec<FunctionCheck> {
    let mut v = vec![
        camera_check(seed),
        unit_disk_check(seed),
        move_sphere_check(seed),
        moving_intersect_check(seed),
    ];
    v.extend(camera_ray_checks(seed, 9));
    v.extend(camera_ray_checks(seed, 10));
    v
}

fn camera_check(seed: u64) -> FunctionCheck {
    let mut inputs = vec![
        dof_camera(100, 2.0),
        CameraInput {
            settings: CameraSettings {
                look_from: [0.0, 0.0, 10.0],
                look_at: [0.0; 3],
                up: [0.0, 1.0, 0.0],
                vfov: 90.0,
                focus_distance: 3.0,
                defocus_angle: 0.0,
            },
            width: 400,
            aspect_ratio: 1.0,
            spp: 10,
        },
    ];
    let mut r = stream(seed, "camera");
    for _ in 0..4 {
        let from = 5.0 * mistakes::unit_vector(&mut r);
        inputs.push(CameraInput {
            settings: CameraSettings {
                look_from: from.to_array(),
                look_at: (0.5 * mistakes::unit_vector(&mut r)).to_array(),
                up: [0.0, 1.0, 0.0],
                vfov: 20.0 + 100.0 * r.next_f64(),
                focus_distance: 1.0 + 9.0 * r.next_f64(),
                defocus_angle: 5.0 * r.next_f64(),
            },
            width: 16 + (r.next_f64() * 300.0) as usize,
            aspect_ratio: [16.0 / 9.0, 1.0, 2.0][(r.next_f64() * 3.0) as usize % 3],
            spp: 10,
        });
    }
    let mut cases = Vec::new();
    let mut doubled = Vec::new();
    for (k, c) in inputs.iter().enumerate() {
        let cam = c.reference();
        let (u, v, w, radius) = c.frame();
        let scale = DVec3::from(c.settings.look_from)
            .abs()
            .max_element()
            .max(c.settings.focus_distance);
        let tol = 1e-9 * scale.max(1.0);
        let expect = |radius: f64| {
            Expected::one("center", Want::vector(cam.center, tol))
                .and("u", Want::vector(u, 1e-9))
                .and("v", Want::vector(v, 1e-9))
                .and("w", Want::vector(w, 1e-9))
                .and("pixel00", Want::vector(cam.pixel00, tol))
                .and("pixel_du", Want::vector(cam.pixel_delta_u, tol))
                .and("pixel_dv", Want::vector(cam.pixel_delta_v, tol))
                .and("defocus_radius", Want::Number { value: radius, tol })
                .and(
                    "height",
                    Want::Number {
                        value: cam.height as f64,
                        tol: 0.0,
                    },
                )
        };
        cases.push(Case {
            id: format!("camera-{k:04}"),
            request: json!({"op": "camera", "camera": c.json()}),
            expect: expect(radius),
            class: Class::Definite,
            input: format!(
                "Camera from {} at {}, vfov {}, {} wide at aspect {}, init_camera({}, {})",
                py::list(DVec3::from(c.settings.look_from)),
                py::list(DVec3::from(c.settings.look_at)),
                py::f(c.settings.vfov),
                c.width,
                py::f(c.aspect_ratio),
                py::f(c.settings.defocus_angle),
                py::f(c.settings.focus_distance)
            ),
            repro: py::script(
                &format!("{}\nprint({{'center': cam.center.e, 'u': cam.camera_frame_u.e, 'v': cam.camera_frame_v.e, 'w': cam.camera_frame_w.e, 'pixel00': cam.pixel00_location.e, 'pixel_du': cam.pixel_du.e, 'pixel_dv': cam.pixel_dv.e, 'defocus_radius': cam.defocus_disk_u.len(), 'height': cam.img_height}})", c.py()),
                &format!("u = {}, v = {}, w = {}, defocus_radius = {}", py::list(u), py::list(v), py::list(w), py::f(radius)),
            ),
        });
        let a = c.settings.defocus_angle * std::f64::consts::PI / 180.0;
        doubled.push(
            (c.settings.defocus_angle > 0.0).then(|| expect(c.settings.focus_distance * a.tan())),
        );
    }
    FunctionCheck {
        id: "camera",
        function: "RT_camera.Camera.init_camera(defocus_angle, focus_distance) (frame, pixels, defocus radius)",
        week: week(10),
        given: true,
        op: "camera",
        tolerance: "u, v, w within 1e-9; positions, pixel steps and the radius within 1e-9 max(1, scene scale); the height exact",
        body: Body::Cases {
            cases,
            variants: vec![Variant {
                name: "defocus_radius_doubled",
                says: "the defocus radius is focus tan(angle) instead of focus tan(angle / 2)",
                standing: Standing::Mistake,
                expect: doubled,
            }],
            normalise: None,
        },
        timeout: CASE_TIMEOUT,
    }
}

fn unit_disk_check(seed: u64) -> FunctionCheck {
    FunctionCheck {
        id: "unit-disk",
        function: "RT_utility.Vec3.random_vec3_in_unit_disk()",
        week: week(10),
        given: true,
        op: "sample_unit_disk",
        tolerance: "every point in the open unit disk of the xy plane; uniform by chi-square over 128 cells of equal area",
        body: Body::Samples {
            requests: sample_requests(
                json!({"op": "sample_unit_disk"}),
                DISK_SAMPLES,
                3,
                seed,
                "unit-disk",
            ),
            extract: Box::new(vector_samples),
            check: SamplerCheck::unit_disk(),
            repro: py::script(
                "print([rtu.Vec3.random_vec3_in_unit_disk().e for _ in range(5)])",
                "points uniform in the unit disk",
            ),
        },
        timeout: SAMPLES_TIMEOUT,
    }
}

/// The camera rays' seven numbers: origin, direction, time.
fn camera_samples(answer: &serde_json::Value) -> Result<Vec<[f64; 7]>, String> {
    let samples = answer
        .get("samples")
        .and_then(serde_json::Value::as_array)
        .ok_or("the answer has no \"samples\" list")?;
    samples
        .iter()
        .map(|s| {
            let v = numbers(Some(s), 7).ok_or_else(|| {
                format!(
                    "a sample is not 7 numbers: {}",
                    crate::weekly::expect::show(s)
                )
            })?;
            let mut out = [0.0; 7];
            out.copy_from_slice(&v);
            Ok(out)
        })
        .collect()
}

/// The jitter, lens and time checks of week `of`'s camera rays (week 9: the jitter alone, at
/// spp 30 and no lens; week 10: all three, at spp 100 through a 2-degree lens).
/// A sample of the first few numbers, the rest 0.
fn padded(xs: &[f64]) -> Sample {
    let mut s = [0.0; 9];
    s[..xs.len()].copy_from_slice(xs);
    s
}

fn camera_ray_checks(seed: u64, of: u8) -> Vec<FunctionCheck> {
    let (spp, angle, stratum, step) = if of == 9 {
        (30, 0.0, (4u32, 1u32), 1.0 / 3.0)
    } else {
        (100, 2.0, (3, 7), 1.0 / 10f64.sqrt())
    };
    let camera = dof_camera(spp, angle);
    let (pixel_i, pixel_j) = (3usize, 4usize);
    let cam = camera.reference();
    let (u, v, w, radius) = camera.frame();
    let centre =
        cam.pixel00 + pixel_i as f64 * cam.pixel_delta_u + pixel_j as f64 * cam.pixel_delta_v;
    let (du, dv) = (cam.pixel_delta_u, cam.pixel_delta_v);
    let base = json!({"op": "sample_camera_ray", "camera": camera.json(), "pixel": [pixel_i, pixel_j], "stratum": [stratum.0, stratum.1]});
    let requests = sample_requests(base, CAMERA_SAMPLES, 7, seed, &format!("camera-rays-{of}"));
    let repro = py::script(
        &format!(
            "{}\nrays = [cam.get_jittered_ray({pixel_i}, {pixel_j}, {}, {}) for _ in range(5)]\nprint([(r.getOrigin().e, r.getDirection().e) for r in rays])",
            camera.py(),
            stratum.0,
            stratum.1
        ),
        "rays through the stratum's part of the pixel",
    );
    let jitter = move |a: &serde_json::Value| -> Result<Vec<Sample>, String> {
        Ok(camera_samples(a)?
            .iter()
            .map(|s| {
                let o = DVec3::new(s[0], s[1], s[2]);
                let d = DVec3::new(s[3], s[4], s[5]);
                let off = o + d - centre;
                padded(&[
                    off.dot(du) / du.length_squared(),
                    off.dot(dv) / dv.length_squared(),
                ])
            })
            .collect())
    };
    let centre_eye = cam.center;
    let lens = move |a: &serde_json::Value| -> Result<Vec<Sample>, String> {
        Ok(camera_samples(a)?
            .iter()
            .map(|s| {
                let off = DVec3::new(s[0], s[1], s[2]) - centre_eye;
                padded(&[off.dot(u) / radius, off.dot(v) / radius, off.dot(w)])
            })
            .collect())
    };
    let time = |a: &serde_json::Value| -> Result<Vec<Sample>, String> {
        Ok(camera_samples(a)?.iter().map(|s| padded(&[s[6]])).collect())
    };
    let function = "RT_camera.Camera.get_jittered_ray(i, j, s_i, s_j)";
    let mut checks = vec![FunctionCheck {
        id: "jitter",
        function,
        week: week(of),
        // Week 10's skeleton keeps week 9's jitter (only the lens and the time are new).
        given: of == 10,
        op: "sample_camera_ray",
        tolerance: "every sample inside its stratum 0.5 (-0.5 + step (s + [0, 1))) pixels from the pixel's centre (step the course's frozen one_over_sqrt_spp); uniform in it by chi-square over 8 x 8 cells",
        body: Body::Samples {
            requests: requests.clone(),
            extract: Box::new(jitter),
            check: SamplerCheck::jitter(JitterSetting {
                stratum,
                step,
                unfrozen_step: 1.0 / (spp as f64).sqrt().floor(),
            }),
            repro: repro.clone(),
        },
        timeout: SAMPLES_TIMEOUT,
    }];
    if of == 10 {
        let doubled = (2f64 * std::f64::consts::PI / 180.0).tan()
            / (1f64 * std::f64::consts::PI / 180.0).tan();
        checks.push(FunctionCheck {
            id: "lens",
            function,
            week: week(10),
            given: false,
            op: "sample_camera_ray",
            tolerance: "every origin on the lens plane within 1e-9 and inside the defocus disk; uniform over it by chi-square over 128 cells of equal area",
            body: Body::Samples { requests: requests.clone(), extract: Box::new(lens), check: SamplerCheck::lens(doubled), repro: repro.clone() },
            timeout: SAMPLES_TIMEOUT,
        });
        checks.push(FunctionCheck {
            id: "ray-time",
            function,
            week: week(10),
            given: false,
            op: "sample_camera_ray",
            tolerance: "every time in [0, 1); uniform by chi-square over 20 cells",
            body: Body::Samples {
                requests,
                extract: Box::new(time),
                check: SamplerCheck::ray_time(),
                repro,
            },
            timeout: SAMPLES_TIMEOUT,
        });
    }
    checks
}

fn move_sphere_check(seed: u64) -> FunctionCheck {
    let mut inputs = vec![
        (DVec3::ZERO, DVec3::new(0.0, 2.0, 0.0), 0.25),
        (
            DVec3::new(-1.0, 0.0, -1.0),
            DVec3::new(-1.0, 0.5, -1.0),
            0.7,
        ),
    ];
    let mut r = stream(seed, "move-sphere");
    for _ in 0..6 {
        inputs.push((
            3.0 * mistakes::unit_vector(&mut r),
            3.0 * mistakes::unit_vector(&mut r),
            r.next_f64(),
        ));
    }
    let mut cases = Vec::new();
    let mut reversed = Vec::new();
    for (k, &(c0, c1, t)) in inputs.iter().enumerate() {
        let want = MovingSphere::new(Sphere::new(c0, 1.0), c1).at(t).center;
        cases.push(Case {
            id: format!("move-sphere-{k:04}"),
            request: json!({"op": "move_sphere", "center": jvec(c0), "moving_to": jvec(c1), "time": jnum(t)}),
            expect: Expected::one("center", Want::vector(want, 1e-12)),
            class: Class::Definite,
            input: format!("Sphere({}, 1.0) moving to {}, at time {}", py::list(c0), py::list(c1), py::f(t)),
            repro: py::script(
                &format!("s = rto.Sphere({}, 1.0)\ns.add_moving({})\nprint(s.move_sphere({}).e)", py::vec(c0), py::vec(c1), py::f(t)),
                &py::list(want),
            ),
        });
        reversed.push(Some(Expected::one(
            "center",
            Want::vector(c1 + (c0 - c1) * t, 1e-12),
        )));
    }
    FunctionCheck {
        id: "move-sphere",
        function: "RT_object.Sphere.move_sphere(time)",
        week: week(10),
        given: true,
        op: "move_sphere",
        tolerance: "each component within 1e-12",
        body: Body::Cases {
            cases,
            variants: vec![Variant {
                name: "motion_reversed",
                says: "the sphere moves from its end to its start",
                standing: Standing::Mistake,
                expect: reversed,
            }],
            normalise: None,
        },
        timeout: CASE_TIMEOUT,
    }
}

/// The moving spheres and rays of the moving-intersect check: `(c0, c1, origin, d, time)`.
fn moving_inputs(seed: u64) -> Vec<(DVec3, DVec3, DVec3, DVec3, f64)> {
    let mut inputs = vec![(
        DVec3::ZERO,
        DVec3::new(0.0, 2.0, 0.0),
        DVec3::new(5.0, 2.0, 0.0),
        DVec3::new(-1.0, 0.0, 0.0),
        1.0,
    )];
    inputs.push((
        DVec3::ZERO,
        DVec3::new(0.0, 2.0, 0.0),
        DVec3::new(5.0, 2.0, 0.0),
        DVec3::new(-1.0, 0.0, 0.0),
        0.0,
    ));
    // Moving along x, hit off the axis: a normal taken from the start centre stays a valid
    // argument of get_uv's acos, so the mistake answers instead of raising.
    inputs.push((
        DVec3::ZERO,
        DVec3::new(2.0, 0.0, 0.0),
        DVec3::new(5.0, 0.5, 0.0),
        DVec3::new(-1.0, 0.0, 0.0),
        1.0,
    ));
    let mut r = stream(seed, "moving-intersect");
    for _ in 0..8 {
        let c0 = 2.0 * mistakes::unit_vector(&mut r);
        let c1 = c0 + mistakes::unit_vector(&mut r);
        let t = r.next_f64();
        let at = c0 + (c1 - c0) * t;
        let origin = at + 5.0 * mistakes::unit_vector(&mut r);
        let d = (at + 0.8 * mistakes::unit_vector(&mut r) - origin) * (0.5 + r.next_f64());
        inputs.push((c0, c1, origin, d, t));
    }
    inputs
}

/// What `intersect` answers for the hit `h` (or a miss).
fn hit_expected(h: Option<crate::geometry::HitRecord>) -> Expected {
    match h {
        None => Expected::one("hit", Want::Bool(false)),
        Some(h) => Expected::one("hit", Want::Bool(true))
            .and(
                "t",
                Want::Number {
                    value: h.t,
                    tol: 1e-9 * h.t.abs().max(1.0),
                },
            )
            .and("point", Want::vector(h.point, 1e-9))
            .and("normal", Want::vector(h.normal, 1e-6))
            .and("front_face", Want::Bool(h.front_face))
            .and(
                "uv",
                Want::Pair {
                    value: [h.uv.0, h.uv.1],
                    tol: 1e-6,
                },
            ),
    }
}

fn moving_intersect_check(seed: u64) -> FunctionCheck {
    let inputs = moving_inputs(seed);
    let interval = [1e-6, f64::MAX];
    let mut cases = Vec::new();
    let mut frozen = Vec::new();
    let mut start_normal = Vec::new();
    for (k, &(c0, c1, origin, d, t)) in inputs.iter().enumerate() {
        let moving = MovingSphere::new(Sphere::new(c0, 1.0), c1);
        let ray = Ray::at_time(origin, d, t);
        let hit_of = |s: &dyn Shape| s.intersect(&ray, Interval::new(interval[0], interval[1]));
        let answer = hit_expected;
        let hit = hit_of(&moving);
        let moved = moving.at(t);
        start_normal.push(hit.and_then(|h| {
            // The normal from the start centre, as long as get_uv's acos takes it.
            let outward = h.point - c0;
            (outward.y.abs() < 0.999).then(|| {
                let front = d.dot(outward) < 0.0;
                let n = if front { outward } else { -outward };
                Expected::one("hit", Want::Bool(true))
                    .and("point", Want::vector(h.point, 1e-9))
                    .and("normal", Want::vector(n, 1e-6))
            })
        }));
        let spec = ShapeSpec::Sphere {
            center: moved.center.to_array(),
            radius: 1.0,
        };
        let decided = classify(
            &spec,
            &RaySpec {
                origin: origin.to_array(),
                direction: d.to_array(),
            },
            interval,
        );
        let pole = hit.is_some_and(|h| {
            let n = (h.point - moved.center).normalize();
            n.y.abs() > 0.9999 || (n.z.abs() < 1e-9 && n.x < 0.0)
        });
        let class = match decided.class {
            HitClass::Hit | HitClass::Miss if !pole => Class::Definite,
            HitClass::Hit | HitClass::Miss => {
                Class::Ambiguous("the hit is at a pole or on the seam, where u is undecided".into())
            }
            _ => Class::Ambiguous(
                "the ray meets the moved sphere within rounding of its edge".into(),
            ),
        };
        cases.push(Case {
            id: format!("moving-intersect-{k:04}"),
            request: json!({"op": "intersect_at_time", "sphere": {"center": jvec(c0), "radius": 1.0, "moving_to": jvec(c1)}, "ray": {"origin": jvec(origin), "direction": jvec(d), "time": jnum(t)}, "interval": [jnum(interval[0]), jnum(interval[1])]}),
            expect: answer(hit),
            class,
            input: format!("Sphere({}, 1.0) moving to {}; a ray from {} along {} at time {}", py::list(c0), py::list(c1), py::list(origin), py::list(d), py::f(t)),
            repro: py::script(
                &format!(
                    "s = rto.Sphere({}, 1.0)\ns.add_moving({})\nh = s.intersect({}, rtu.Interval(1e-06, rtu.infinity_number))\nprint({{'hit': False}} if h is None else {{'hit': True, 't': h.getT(), 'point': h.getP().e, 'normal': h.getNormal().e, 'front_face': h.front_face, 'uv': h.getUV()}})",
                    py::vec(c0),
                    py::vec(c1),
                    py::ray(origin, d, t)
                ),
                &match hit {
                    Some(h) => format!("a hit at t = {}", py::f(h.t)),
                    None => "a miss (None)".into(),
                },
            ),
        });
        let still = Sphere::new(c0, 1.0);
        let still_spec = ShapeSpec::Sphere {
            center: c0.to_array(),
            radius: 1.0,
        };
        let still_class = classify(
            &still_spec,
            &RaySpec {
                origin: origin.to_array(),
                direction: d.to_array(),
            },
            interval,
        )
        .class;
        frozen.push(
            matches!(still_class, HitClass::Hit | HitClass::Miss).then(|| answer(hit_of(&still))),
        );
    }
    FunctionCheck {
        id: "moving-intersect",
        function: "RT_object.Sphere.intersect(ray, interval) of a moving sphere at the ray's time",
        week: week(10),
        given: true,
        op: "intersect_at_time",
        tolerance: "hit or miss exact (the oracle's); t within 1e-9 max(1, t), the point within 1e-9, the normal within 1e-6, (u, v) within 1e-6",
        body: Body::Cases {
            cases,
            variants: vec![
                Variant {
                    name: "intersect_ignores_time",
                    says: "a moving sphere is intersected at its start, whatever the ray's time",
                    standing: Standing::Mistake,
                    expect: frozen,
                },
                Variant {
                    name: "moving_normal_from_start_centre",
                    says: "the hit is found on the moved sphere, but its normal is taken from the start centre",
                    standing: Standing::Mistake,
                    expect: start_normal,
                },
            ],
            normalise: None,
        },
        timeout: CASE_TIMEOUT,
    }
}
