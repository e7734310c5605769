//! Diffuse and metal scattering and the samplers behind them: week 5's `random_vec3_unit` and
//! Lambertian `n + u`, week 7's `Metal`, week 9's cosine hemisphere, `ONB` and the Lambertian
//! through it.
//!
//! A scattering's formula is checked with the course's `random_double` steered (the values it
//! returns given by the request, [`super::steer`]): the course's `Vec3.random_vec3_unit()` and
//! `random_cosine_hemisphere_on_z()` draw through it, so the answer of course-shaped code is
//! exact. An answer drawn otherwise is judged by what it does: it must keep the invariant of the
//! statistical check of the same scattering (real random numbers, seeded), and counts as right
//! only when that check passed.

use glam::DVec3;
use serde_json::json;

use super::optics::{HitInput, sample_requests, scatter_samples, scattered};
use super::{
    Body, CASE_TIMEOUT, Case, FunctionCheck, SAMPLES_TIMEOUT, Variant, jnum, jvec, py, steer,
    stream, week,
};
use crate::oracle::band::Iv;
use crate::render::{Onb, reflect};
use crate::weekly::expect::{Class, Expected, Want, numbers};
use crate::weekly::samplers::mistakes;
use crate::weekly::samplers::{
    HEMISPHERE_SAMPLES, LAMBERTIAN_SAMPLES, METAL_SAMPLES, Sample, SamplerCheck, Standing,
    UNIT_SPHERE_SAMPLES, surfaces::MetalSetting,
};

pub(crate) fn checks(seed: u64) -> Vec<FunctionCheck> {
    vec![
        unit_sphere_check(seed),
        lambertian_check(seed),
        lambertian_lobe_check(seed, false),
        cosine_hemisphere_check(seed),
        onb_check(seed),
        lambertian_onb_check(seed),
        lambertian_lobe_check(seed, true),
        metal_check(seed),
        metal_fuzz_check(seed),
    ]
}

/// The three numbers of each sample of a vector sampler.
pub(crate) fn vector_samples(answer: &serde_json::Value) -> Result<Vec<Sample>, String> {
    let samples = answer
        .get("samples")
        .and_then(serde_json::Value::as_array)
        .ok_or("the answer has no \"samples\" list")?;
    samples
        .iter()
        .map(|s| {
            let v = numbers(Some(s), 3).ok_or_else(|| {
                format!(
                    "a sample is not 3 numbers: {}",
                    crate::weekly::expect::show(s)
                )
            })?;
            Ok([v[0], v[1], v[2], 0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
        })
        .collect()
}

fn unit_sphere_check(seed: u64) -> FunctionCheck {
    FunctionCheck {
        id: "unit-sphere",
        function: "RT_utility.Vec3.random_vec3_unit()",
        week: week(5),
        given: true,
        op: "sample_unit_vector",
        tolerance: "every sample of length 1 within 1e-9; uniform on the sphere by chi-square over 128 cells of equal area",
        body: Body::Samples {
            requests: sample_requests(
                json!({"op": "sample_unit_vector"}),
                UNIT_SPHERE_SAMPLES,
                3,
                seed,
                "unit-sphere",
            ),
            extract: Box::new(vector_samples),
            check: SamplerCheck::unit_sphere(),
            repro: py::script(
                "print([rtu.Vec3.random_vec3_unit().e for _ in range(5)])",
                "unit vectors, uniform on the sphere",
            ),
        },
        timeout: SAMPLES_TIMEOUT,
    }
}

fn cosine_hemisphere_check(seed: u64) -> FunctionCheck {
    FunctionCheck {
        id: "cosine-hemisphere",
        function: "RT_utility.Vec3.random_cosine_hemisphere_on_z()",
        week: week(9),
        given: false,
        op: "sample_cosine_hemisphere",
        tolerance: "every sample a unit vector with z >= 0; cos^2(theta) and the azimuth uniform by chi-square over 80 cells",
        body: Body::Samples {
            requests: sample_requests(
                json!({"op": "sample_cosine_hemisphere"}),
                HEMISPHERE_SAMPLES,
                3,
                seed,
                "cosine-hemisphere",
            ),
            extract: Box::new(vector_samples),
            check: SamplerCheck::cosine_hemisphere(),
            repro: py::script(
                "print([rtu.Vec3.random_cosine_hemisphere_on_z().e for _ in range(5)])",
                "unit vectors about z with density cos(theta) / pi",
            ),
        },
        timeout: SAMPLES_TIMEOUT,
    }
}

/// The hits the Lambertian checks scatter from: straight down onto a floor, and oblique hits on
/// tilted normals from both sides.
fn lambertian_hits(seed: u64, id: &str) -> Vec<HitInput> {
    let mut hits = vec![HitInput {
        origin: DVec3::new(1.0, 4.0, 3.0),
        direction: DVec3::new(0.0, -2.0, 0.0),
        point: DVec3::new(1.0, 2.0, 3.0),
        outward: DVec3::Y,
    }];
    let mut r = stream(seed, id);
    for k in 0..5 {
        let n = mistakes::unit_vector(&mut r);
        let point = 2.0 * mistakes::unit_vector(&mut r);
        let mut d = mistakes::unit_vector(&mut r) * 3.0;
        if d.dot(n) > -0.1 {
            d -= (d.dot(n) + 1.0) * n;
        }
        let outward = if k % 2 == 0 { n } else { -n };
        hits.push(HitInput {
            origin: point - d,
            direction: d,
            point,
            outward,
        });
    }
    hits
}

const ALBEDO: DVec3 = DVec3::new(0.5, 0.25, 1.0);

/// The `random_double` values of the Lambertian cases: for the first hit `u = x` and `u = -n`
/// exactly (`n + u = 0`, where the course uses `n`); then random unit vectors, every other one
/// after a point the rejection loop throws away.
fn lambertian_values(seed: u64, hits: &[HitInput]) -> Vec<(usize, Vec<f64>)> {
    let mut r = stream(seed, "lambertian-u");
    let mut out = Vec::new();
    for (k, h) in hits.iter().enumerate() {
        if k == 0 {
            let (n, _) = h.facing();
            out.push((k, steer::cube_values(DVec3::new(0.5, 0.0, 0.0))));
            out.push((k, steer::cube_values(-0.5 * n)));
        } else {
            out.push((k, steer::unit_vector_values(&mut r, k % 2 == 1)));
        }
    }
    out
}

fn lambertian_check(seed: u64) -> FunctionCheck {
    let hits = lambertian_hits(seed, "lambertian");
    let mut cases = Vec::new();
    let mut behaviour = Vec::new();
    let (mut normalised, mut hemisphere) = (Vec::new(), Vec::new());
    for (k, values) in lambertian_values(seed, &hits) {
        let h = &hits[k];
        let (n, _) = h.facing();
        let (u, _) = steer::course_unit_vector(&values).expect("values for one unit vector");
        let raw = n + u;
        // The course's near_zero: every component below 1e-8.
        let degenerate = raw.abs().max_element() < 1e-8;
        // Within rounding of the threshold (one component between 0.5e-8 and 2e-8, the
        // others below): the case is not scored.
        let near = !degenerate && raw.abs().max_element() < 2e-8;
        let d = if degenerate { n } else { raw };
        let tol = 1e-9;
        let (ray, hit) = h.json();
        let i = cases.len();
        let id = format!("lambertian-{i:04}");
        cases.push(Case {
            request: json!({"op": "scatter", "material": {"type": "lambertian", "albedo": jvec(ALBEDO)}, "ray": ray, "hit": hit, "replace": {"random_double": values.iter().map(|&v| jnum(v)).collect::<Vec<_>>()}, "seed": steer::case_seed(seed, &id)}),
            id,
            expect: scattered(h.point, d, tol, ALBEDO),
            class: if near { Class::Ambiguous("n + u within rounding of the 1e-8 threshold".into()) } else { Class::Definite },
            input: format!("{}, random_double() = {} (random_vec3_unit() = {})", h.words(), py_values(&values), py::list(u)),
            repro: py::script(
                &format!(
                    "{}\n{}\ns = m.scattering(ray, hit)\n{}",
                    py::random_doubles(&values),
                    h.py(&format!("rtm.Lambertian({})", py::color(ALBEDO))),
                        py::PRINT_SCATTERED
                ),
                &py::list(d),
            ),
        });
        behaviour.push(steer::scatter_behaviour(SamplerCheck::lambertian_n_plus_u(
            h.point, n, ALBEDO,
        )));
        normalised.push((!degenerate).then(|| scattered(h.point, raw.normalize(), tol, ALBEDO)));
        let flipped = if u.dot(n) < 0.0 { -u } else { u };
        hemisphere.push(
            (!degenerate && u.dot(n).abs() > 1e-9)
                .then(|| scattered(h.point, flipped, tol, ALBEDO)),
        );
    }
    FunctionCheck {
        id: "lambertian",
        function: "RT_material.Lambertian.scattering(ray, hit)",
        week: week(5),
        given: false,
        op: "scatter",
        tolerance: "with random_double() steered: the direction n + random_vec3_unit() (n when every component is below 1e-8) within 1e-9, origin the hit point, attenuation the albedo; an answer drawn otherwise counts when it is n + u for a unit u and lambertian-lobe passes",
        body: Body::Steered {
            cases,
            variants: vec![
                Variant {
                    name: "n_plus_u_normalised",
                    says: "Lambertian normalises n + u (the course does not; its length weighs week 8's cosine)",
                    standing: Standing::Mistake,
                    expect: normalised,
                },
                Variant {
                    name: "hemisphere_instead_of_cosine_lobe",
                    says: "Lambertian scatters a unit vector flipped to the normal's side (the hemisphere uniformly) instead of n + u (the cosine lobe)",
                    standing: Standing::Mistake,
                    expect: hemisphere,
                },
            ],
            partners: &["lambertian-lobe"],
            behaviour,
            normalise: None,
        },
        timeout: CASE_TIMEOUT,
    }
}

/// The values of `random_double` as a Python list.
fn py_values(values: &[f64]) -> String {
    let list: Vec<String> = values.iter().map(|&v| py::f(v)).collect();
    format!("[{}]", list.join(", "))
}

fn lambertian_lobe_check(seed: u64, cosine: bool) -> FunctionCheck {
    // Straight down onto a tilted surface.
    let n = DVec3::new(0.0, 0.6, 0.8);
    let point = DVec3::new(1.0, 2.0, 3.0);
    let hit = HitInput {
        origin: point + 2.0 * n,
        direction: -2.0 * n,
        point,
        outward: n,
    };
    let (ray, hj) = hit.json();
    let base = json!({"op": "sample_scatter", "material": {"type": "lambertian", "albedo": jvec(ALBEDO)}, "ray": ray, "hit": hj});
    let id = "lambertian-lobe";
    FunctionCheck {
        id,
        function: "RT_material.Lambertian.scattering(ray, hit) (its distribution)",
        week: week(if cosine { 9 } else { 5 }),
        given: false,
        op: "sample_scatter",
        tolerance: if cosine {
            "every direction a unit vector on the normal's side; the cosine lobe about the normal by chi-square over 80 cells"
        } else {
            "every direction n + u for a unit u (|d|^2 = 2 d . n within 1e-9); d / |d| in the cosine lobe by chi-square over 80 cells"
        },
        body: Body::Samples {
            requests: sample_requests(base, LAMBERTIAN_SAMPLES, 9, seed, id),
            extract: Box::new(scatter_samples),
            check: if cosine {
                SamplerCheck::lambertian_cosine(point, n, ALBEDO)
            } else {
                SamplerCheck::lambertian_n_plus_u(point, n, ALBEDO)
            },
            repro: py::script(
                &format!(
                    "{}\nprint([m.scattering(ray, hit).scattered_ray.getDirection().e for _ in range(5)])",
                    hit.py(&format!("rtm.Lambertian({})", py::color(ALBEDO)))
                ),
                if cosine {
                    "unit directions in the cosine lobe about the normal"
                } else {
                    "n + u for uniform unit vectors u"
                },
            ),
        },
        timeout: SAMPLES_TIMEOUT,
    }
}

/// Whether `|unit(w).x| > 0.9` is decided by rounding.
fn onb_switch_is_close(w: DVec3) -> bool {
    let x = Iv::point(w.x);
    let len = (x * x + Iv::point(w.y) * Iv::point(w.y) + Iv::point(w.z) * Iv::point(w.z)).sqrt();
    let ux = (x / len).abs();
    (ux - Iv::point(0.9)).widen(8.0).contains(0.0)
}

fn onb_check(seed: u64) -> FunctionCheck {
    let mut inputs = vec![
        (DVec3::new(0.0, 0.0, 2.0), DVec3::new(1.0, 2.0, 3.0)),
        (DVec3::X, DVec3::new(1.0, 2.0, 3.0)),
        (DVec3::new(0.0, 1.0, 0.0), DVec3::new(0.5, -0.25, 2.0)),
        (DVec3::new(-0.95, 0.1, 0.2), DVec3::new(1.0, 0.0, 0.0)),
    ];
    let mut r = stream(seed, "onb");
    for _ in 0..6 {
        let w = mistakes::unit_vector(&mut r) * (0.2 + 3.0 * r.next_f64());
        let l = mistakes::unit_vector(&mut r) * 2.0;
        inputs.push((w, l));
    }
    let mut cases = Vec::new();
    let (mut swapped, mut right) = (Vec::new(), Vec::new());
    for (k, &(w, l)) in inputs.iter().enumerate() {
        let b = Onb::from_w(w);
        let local = b.local(l);
        let tol = 1e-9 * l.length().max(1.0);
        let expect = |u: DVec3, v: DVec3, w: DVec3, local: DVec3| {
            Expected::one("u", Want::vector(u, 1e-9))
                .and("v", Want::vector(v, 1e-9))
                .and("w", Want::vector(w, 1e-9))
                .and("local", Want::vector(local, tol))
        };
        cases.push(Case {
            id: format!("onb-{k:04}"),
            request: json!({"op": "onb", "w": jvec(w), "local": jvec(l)}),
            expect: expect(b.u, b.v, b.w, local),
            class: if onb_switch_is_close(w) {
                Class::Ambiguous("|unit(n).x| is within rounding of 0.9, where the helper vector switches".into())
            } else {
                Class::Definite
            },
            input: format!("build_from_w({}), local({}, {}, {})", py::list(w), py::f(l.x), py::f(l.y), py::f(l.z)),
            repro: py::script(
                &format!(
                    "o = rtu.ONB()\no.build_from_w({})\nprint(o.u().e, o.v().e, o.w().e, o.local(rtu.Vec3({}, {}, {})).e)",
                    py::vec(w),
                    py::f(l.x),
                    py::f(l.y),
                    py::f(l.z)
                ),
                &format!("u = {}, v = {}, w = {}, local {}", py::list(b.u), py::list(b.v), py::list(b.w), py::list(local)),
            ),
        });
        swapped.push(Some(expect(
            b.u,
            b.v,
            b.w,
            l.z * b.u + l.y * b.v + l.x * b.w,
        )));
        right.push(Some(expect(
            b.v.cross(b.w),
            b.v,
            b.w,
            l.x * b.v.cross(b.w) + l.y * b.v + l.z * b.w,
        )));
    }
    FunctionCheck {
        id: "onb",
        function: "RT_utility.ONB.build_from_w(n), ONB.local(Vec3), ONB.u(), v(), w()",
        week: week(9),
        given: false,
        op: "onb",
        tolerance: "u, v, w within 1e-9; local within 1e-9 max(1, |(x, y, z)|); cases within rounding of |w.x| = 0.9 are not scored",
        body: Body::Cases {
            cases,
            variants: vec![
                Variant {
                    name: "lobe_around_wrong_axis",
                    says: "ONB.local puts z along u and x along w, so the cosine lobe lies about a tangent instead of the normal",
                    standing: Standing::Mistake,
                    expect: swapped,
                },
                Variant {
                    name: "onb_right_handed",
                    says: "u = v x w (a right-handed basis) where the course has u = w x v",
                    standing: Standing::Mistake,
                    expect: right,
                },
            ],
            normalise: None,
        },
        timeout: CASE_TIMEOUT,
    }
}

fn lambertian_onb_check(seed: u64) -> FunctionCheck {
    let hits = lambertian_hits(seed, "lambertian-onb");
    let mut r = stream(seed, "lambertian-onb-c");
    let mut cases = Vec::new();
    let mut behaviour = Vec::new();
    let mut wrong_axis = Vec::new();
    for (k, h) in hits.iter().enumerate() {
        let (n, _) = h.facing();
        // random_double() = r1, r2: phi = 2 pi r1, z = sqrt(1 - r2).
        let (r1, r2) = if k == 0 {
            (0.25, 0.5)
        } else {
            (r.next_f64(), r.next_f64())
        };
        let c = steer::course_cosine_hemisphere(r1, r2);
        let b = Onb::from_w(n);
        let d = b.local(c);
        let (ray, hit) = h.json();
        let id = format!("lambertian-onb-{k:04}");
        cases.push(Case {
            request: json!({"op": "scatter", "material": {"type": "lambertian", "albedo": jvec(ALBEDO)}, "ray": ray, "hit": hit, "replace": {"random_double": [jnum(r1), jnum(r2)]}, "seed": steer::case_seed(seed, &id)}),
            id,
            expect: scattered(h.point, d, 1e-9, ALBEDO),
            class: if onb_switch_is_close(n) {
                Class::Ambiguous("|n.x| is within rounding of 0.9, where the ONB's helper vector switches".into())
            } else {
                Class::Definite
            },
            input: format!("{}, random_double() = {}, {} (random_cosine_hemisphere_on_z() = {})", h.words(), py::f(r1), py::f(r2), py::list(c)),
            repro: py::script(
                &format!(
                    "{}\n{}\ns = m.scattering(ray, hit)\n{}",
                    py::random_doubles(&[r1, r2]),
                    h.py(&format!("rtm.Lambertian({})", py::color(ALBEDO))),
                    py::PRINT_SCATTERED
                ),
                &py::list(d),
            ),
        });
        behaviour.push(steer::scatter_behaviour(SamplerCheck::lambertian_cosine(
            h.point, n, ALBEDO,
        )));
        wrong_axis.push(Some(scattered(
            h.point,
            c.z * b.u + c.y * b.v + c.x * b.w,
            1e-9,
            ALBEDO,
        )));
    }
    FunctionCheck {
        id: "lambertian",
        function: "RT_material.Lambertian.scattering(ray, hit)",
        week: week(9),
        given: false,
        op: "scatter",
        tolerance: "with random_double() steered: the direction ONB(n).local(random_cosine_hemisphere_on_z()) within 1e-9, origin the hit point, attenuation the albedo; an answer drawn otherwise counts when it is a unit vector on the normal's side and lambertian-lobe passes",
        body: Body::Steered {
            cases,
            variants: vec![Variant {
                name: "lobe_around_wrong_axis",
                says: "the cosine direction is taken along the wrong axes of the ONB: the lobe lies about a tangent",
                standing: Standing::Mistake,
                expect: wrong_axis,
            }],
            partners: &["lambertian-lobe"],
            behaviour,
            normalise: None,
        },
        timeout: CASE_TIMEOUT,
    }
}

/// The hits of the metal checks, their roughness and the values of `random_double` (for the
/// course's `random_vec3_unit()`: x, -y, z and (1, 1, 0) / sqrt(2) first, then random, every
/// other one after a point the rejection loop throws away).
fn metal_inputs(seed: u64) -> Vec<(HitInput, f64, Vec<f64>)> {
    let base = HitInput {
        origin: DVec3::new(-1.0, 1.0, 0.0),
        direction: DVec3::new(1.0, -1.0, 0.0),
        point: DVec3::ZERO,
        outward: DVec3::Y,
    };
    let cube = |x: f64, y: f64, z: f64| steer::cube_values(DVec3::new(x, y, z));
    let mut inputs = vec![
        (HitInput { ..base }, 0.5, cube(0.5, 0.0, 0.0)),
        (HitInput { ..base }, 1.0, cube(0.0, -0.5, 0.0)),
        (HitInput { ..base }, 3.0, cube(0.0, 0.0, 0.5)),
        (HitInput { ..base }, 0.0, cube(0.5, 0.5, 0.0)),
    ];
    let mut r = stream(seed, "metal");
    for k in 0..6 {
        let n = mistakes::unit_vector(&mut r);
        let point = mistakes::unit_vector(&mut r);
        let mut d = mistakes::unit_vector(&mut r) * (0.5 + 5.0 * r.next_f64());
        if d.dot(n) > -0.05 {
            d -= (d.dot(n) + 1.0) * n;
        }
        let outward = if k % 2 == 0 { n } else { -n };
        inputs.push((
            HitInput {
                origin: point - d,
                direction: d,
                point,
                outward,
            },
            [0.1, 0.5, 0.9][k % 3],
            steer::unit_vector_values(&mut r, k % 2 == 0),
        ));
    }
    inputs
}

fn metal_check(seed: u64) -> FunctionCheck {
    let albedo = DVec3::new(0.8, 0.6, 0.4);
    let mut cases = Vec::new();
    let mut variants: Vec<(&'static str, &'static str, Vec<Option<Expected>>)> = vec![
        (
            "metal_roughness_ignored",
            "Metal reflects the unit direction without adding roughness times a random unit vector",
            Vec::new(),
        ),
        (
            "metal_reflects_raw_direction",
            "Metal reflects the raw incoming direction (the course reflects the unit one)",
            Vec::new(),
        ),
        (
            "metal_roughness_not_clamped",
            "Metal uses a roughness above 1 as it is (the course clamps it to 1)",
            Vec::new(),
        ),
        (
            "metal_never_absorbs",
            "Metal keeps the albedo for directions into the surface (the course zeroes the attenuation at d . n <= 1e-8)",
            Vec::new(),
        ),
    ];
    let mut behaviour = Vec::new();
    for (k, (h, roughness, values)) in metal_inputs(seed).into_iter().enumerate() {
        let (n, _) = h.facing();
        let (u, _) = steer::course_unit_vector(&values).expect("values for one unit vector");
        let fuzz = roughness.min(1.0);
        let answer = |mirror: DVec3, fuzz: f64, absorbs: bool| -> (Expected, bool) {
            let d = mirror + fuzz * u;
            let dn = d.dot(n);
            let near = (dn - 1e-8).abs() < 1e-12;
            let a = if absorbs && dn <= 1e-8 {
                DVec3::ZERO
            } else {
                albedo
            };
            (scattered(h.point, d, 1e-9, a), near)
        };
        let mirror = reflect(h.direction.normalize(), n);
        let (expect, near) = answer(mirror, fuzz, true);
        let defined = |(e, near): (Expected, bool)| (!near).then_some(e);
        variants[0].2.push(defined(answer(mirror, 0.0, true)));
        variants[1]
            .2
            .push(defined(answer(reflect(h.direction, n), fuzz, true)));
        variants[2].2.push(defined(answer(mirror, roughness, true)));
        variants[3].2.push(defined(answer(mirror, fuzz, false)));
        let (ray, hit) = h.json();
        let id = format!("metal-{k:04}");
        behaviour.push(steer::scatter_behaviour(SamplerCheck::metal(
            MetalSetting {
                point: h.point,
                normal: n,
                albedo,
                mirror,
                raw_mirror: reflect(h.direction, n),
                roughness: fuzz,
                given_roughness: roughness,
            },
        )));
        cases.push(Case {
            request: json!({"op": "scatter", "material": {"type": "metal", "albedo": jvec(albedo), "roughness": jnum(roughness)}, "ray": ray, "hit": hit, "replace": {"random_double": values.iter().map(|&v| jnum(v)).collect::<Vec<_>>()}, "seed": steer::case_seed(seed, &id)}),
            id,
            expect,
            class: if near { Class::Ambiguous("d . n is within rounding of 1e-8".into()) } else { Class::Definite },
            input: format!("Metal(roughness {}): {}, random_double() = {} (random_vec3_unit() = {})", py::f(roughness), h.words(), py_values(&values), py::list(u)),
            repro: py::script(
                &format!(
                    "{}\n{}\ns = m.scattering(ray, hit)\n{}",
                    py::random_doubles(&values),
                    h.py(&format!("rtm.Metal({}, {})", py::color(albedo), py::f(roughness))),
                    py::PRINT_SCATTERED
                ),
                "the direction and attenuation above",
            ),
        });
    }
    FunctionCheck {
        id: "metal",
        function: "RT_material.Metal.scattering(ray, hit)",
        week: week(7),
        given: false,
        op: "scatter",
        tolerance: "with random_double() steered: reflect(unit(d), n) + min(roughness, 1) random_vec3_unit() within 1e-9; the attenuation the albedo, or 0 where d . n <= 1e-8; an answer drawn otherwise counts when it lies min(roughness, 1) from the mirror direction and metal-fuzz passes",
        body: Body::Steered {
            cases,
            variants: variants
                .into_iter()
                .map(|(name, says, expect)| Variant {
                    name,
                    says,
                    standing: Standing::Mistake,
                    expect,
                })
                .collect(),
            partners: &["metal-fuzz"],
            behaviour,
            normalise: None,
        },
        timeout: CASE_TIMEOUT,
    }
}

fn metal_fuzz_check(seed: u64) -> FunctionCheck {
    let albedo = DVec3::new(0.8, 0.6, 0.4);
    let n = DVec3::Y;
    let d = DVec3::new(2.0, -2.0, 0.0);
    let hit = HitInput {
        origin: -d,
        direction: d,
        point: DVec3::ZERO,
        outward: n,
    };
    let setting = MetalSetting {
        point: hit.point,
        normal: n,
        albedo,
        mirror: reflect(d.normalize(), n),
        raw_mirror: reflect(d, n),
        roughness: 0.5,
        given_roughness: 0.5,
    };
    let (ray, hj) = hit.json();
    let base = json!({"op": "sample_scatter", "material": {"type": "metal", "albedo": jvec(albedo), "roughness": 0.5}, "ray": ray, "hit": hj});
    FunctionCheck {
        id: "metal-fuzz",
        function: "RT_material.Metal.scattering(ray, hit) (its fuzz)",
        week: week(7),
        given: false,
        op: "sample_scatter",
        tolerance: "every direction at distance roughness from the mirror direction within 1e-9; its offset uniform on the sphere by chi-square over 128 cells",
        body: Body::Samples {
            requests: sample_requests(base, METAL_SAMPLES, 9, seed, "metal-fuzz"),
            extract: Box::new(scatter_samples),
            check: SamplerCheck::metal(setting),
            repro: py::script(
                &format!(
                    "{}\nprint([m.scattering(ray, hit).scattered_ray.getDirection().e for _ in range(5)])",
                    hit.py(&format!("rtm.Metal({}, 0.5)", py::color(albedo)))
                ),
                "directions 0.5 from the mirror direction (0.7071, 0.7071, 0)",
            ),
        },
        timeout: SAMPLES_TIMEOUT,
    }
}
