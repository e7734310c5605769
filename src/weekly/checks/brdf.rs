//! Week 8's BRDFs: `Phong.BRDF`, `Blinn.BRDF`, `CookTorrance.BRDF`, as the course defines
//! them (the reference's [`phong`], [`blinn`], [`cook_torrance`]), with the course's
//! unnormalised view and light vectors.
//!
//! Cook-Torrance is the course's own `BRDF` (its `Gterm` takes `tan^2` from `v.H` of the unit
//! half vector; [`cook_torrance`]). It returns a number (the course's), which its integrator
//! cannot multiply with a colour; a grey colour of that value is accepted too (what the code
//! evidently intends). Its thresholds (`chi(x)` and the clamps at 1e-8) and the inputs where the
//! course's code divides by zero (`V + L = 0`) or takes the root of a negative number
//! (`1 + alpha^2 tan^2 < 0` with unnormalised vectors) are kept out of the scored cases.

use glam::DVec3;
use serde_json::json;

use super::optics::HitInput;
use super::{
    Body, CASE_TIMEOUT, Case, FunctionCheck, Normalise, Variant, jnum, jvec, py, stream, week,
};
use crate::render::{blinn, cook_torrance, halfvector, phong};
use crate::weekly::expect::{Class, Expected, Want};
use crate::weekly::samplers::Standing;
use crate::weekly::samplers::mistakes;

/// One BRDF case: the hit (the view ray arriving at it), and the light's direction.
#[derive(Clone, Copy)]
struct Input {
    hit: HitInput,
    light: DVec3,
}

fn inputs(seed: u64, id: &str) -> Vec<Input> {
    let mut v = vec![
        // Straight down from (0, 2, 0), the light along (1, 1, 0): Phong's R . V = 1/sqrt 2;
        // Blinn's H from the unnormalised V and L.
        Input {
            hit: HitInput {
                origin: DVec3::new(0.0, 2.0, 0.0),
                direction: DVec3::new(0.0, -2.0, 0.0),
                point: DVec3::ZERO,
                outward: DVec3::Y,
            },
            light: DVec3::new(1.0, 1.0, 0.0),
        },
        // Along (1, -1, 0): Phong's R . V = 1.
        Input {
            hit: HitInput {
                origin: DVec3::new(-1.0, 1.0, 0.0),
                direction: DVec3::new(1.0, -1.0, 0.0),
                point: DVec3::ZERO,
                outward: DVec3::Y,
            },
            light: DVec3::new(1.0, 1.0, 0.0),
        },
        // The light straight up, seen straight down.
        Input {
            hit: HitInput {
                origin: DVec3::new(0.0, 1.0, 0.0),
                direction: DVec3::new(0.0, -1.0, 0.0),
                point: DVec3::ZERO,
                outward: DVec3::Y,
            },
            light: DVec3::Y,
        },
    ];
    let mut r = stream(seed, id);
    for _ in 0..10 {
        let n = mistakes::unit_vector(&mut r);
        let point = mistakes::unit_vector(&mut r);
        // A view from the normal's side, of length 1 to 15, and a light on that side too.
        let mut view = mistakes::unit_vector(&mut r);
        if view.dot(n) > -0.1 {
            view -= (view.dot(n) + 1.0) * n;
        }
        let view = view.normalize() * (1.0 + 14.0 * r.next_f64());
        let mut l = mistakes::unit_vector(&mut r);
        if l.dot(n) < 0.1 {
            l += (0.1 - l.dot(n) + r.next_f64()) * n;
        }
        let l = l * (0.5 + 3.0 * r.next_f64());
        v.push(Input {
            hit: HitInput {
                origin: point - view,
                direction: view,
                point,
                outward: n,
            },
            light: l,
        });
    }
    v
}

fn request(material: serde_json::Value, c: &Input) -> serde_json::Value {
    let (view, hit) = c.hit.json();
    json!({"op": "brdf", "material": material, "view": view, "light": {"origin": jvec(c.hit.point), "direction": jvec(c.light)}, "hit": hit})
}

fn repro(ctor: &str, c: &Input, answer: &str) -> String {
    py::script(
        &format!(
            "{}\nprint(m.BRDF(ray, {}, hit))",
            c.hit.py(ctor),
            py::ray(c.hit.point, c.light, 0.0)
        ),
        answer,
    )
}

fn colour(c: DVec3) -> Expected {
    Expected::one(
        "color",
        Want::vector(c, 1e-9 * c.abs().max_element().max(1.0)),
    )
}

pub(crate) fn checks(seed: u64) -> Vec<FunctionCheck> {
    vec![
        model_check(seed, false),
        model_check(seed, true),
        cook_torrance_check(seed),
    ]
}

/// Phong's (`is_blinn` false) or Blinn's check.
fn model_check(seed: u64, is_blinn: bool) -> FunctionCheck {
    let albedo = DVec3::new(0.7, 0.2, 0.4);
    let (kd, ks) = (0.6, 0.9);
    let alphas = [0.8, 8.0, 30.0, 300.0];
    let name = if is_blinn { "Blinn" } else { "Phong" };
    let mut cases = Vec::new();
    let (mut swapped, mut no_kd, mut unit_half) = (Vec::new(), Vec::new(), Vec::new());
    for (k, c) in inputs(seed, name).iter().enumerate() {
        let alpha = alphas[k % alphas.len()];
        let (n, _) = c.hit.facing();
        let view = c.hit.direction;
        let model = |b: bool, view: DVec3, light: DVec3| {
            if b {
                blinn(albedo, kd, ks, alpha, view, light, n)
            } else {
                phong(albedo, kd, ks, alpha, view, light, n)
            }
        };
        let want = model(is_blinn, view, c.light);
        let material = json!({"type": name.to_lowercase(), "albedo": jvec(albedo), "kd": kd, "ks": ks, "alpha": jnum(alpha)});
        let ctor = format!(
            "rtm.{name}({}, {kd}, {ks}, {})",
            py::color(albedo),
            py::f(alpha)
        );
        cases.push(Case {
            id: format!("{}-{k:04}", name.to_lowercase()),
            request: request(material, c),
            expect: colour(want),
            class: Class::Definite,
            input: format!(
                "{ctor}: {}, the light along {}",
                c.hit.words(),
                py::list(c.light)
            ),
            repro: repro(&ctor, c, &py::list(want)),
        });
        swapped.push(Some(colour(model(!is_blinn, view, c.light))));
        no_kd.push(Some(colour(
            want - kd * albedo / std::f64::consts::PI + albedo,
        )));
        unit_half
            .push(is_blinn.then(|| colour(model(true, view.normalize(), c.light.normalize()))));
    }
    let mut variants = vec![
        Variant {
            name: "phong_blinn_swapped",
            says: "Phong computes Blinn's BRDF and Blinn Phong's",
            standing: Standing::Mistake,
            expect: swapped,
        },
        Variant {
            name: "brdf_missing_kd_over_pi",
            says: "the diffuse term is the albedo, without kd / pi",
            standing: Standing::Mistake,
            expect: no_kd,
        },
    ];
    if is_blinn {
        variants.push(Variant {
            name: "blinn_normalised_half_vector",
            says: "Blinn's half vector is built from the unit V and L (the course halves them as they are, so its highlight depends on the rays' lengths)",
            standing: Standing::Mistake,
            expect: unit_half,
        });
    }
    FunctionCheck {
        id: if is_blinn { "blinn" } else { "phong" },
        function: if is_blinn {
            "RT_material.Blinn.BRDF(ray_view, ray_light, hit)"
        } else {
            "RT_material.Phong.BRDF(ray_view, ray_light, hit)"
        },
        week: week(8),
        given: false,
        op: "brdf",
        tolerance: "each component within 1e-9 max(1, |value|)",
        body: Body::Cases {
            cases,
            variants,
            normalise: None,
        },
        timeout: CASE_TIMEOUT,
    }
}

/// A grey colour answer (the code made to return a colour) read as the course's number.
fn grey_as_number(answer: serde_json::Value) -> serde_json::Value {
    use crate::weekly::expect::vector;
    if answer.get("value").is_some() {
        return answer;
    }
    match vector(answer.get("color")) {
        Some(c) if c.x == c.y && c.y == c.z => json!({"value": c.x}),
        _ => answer,
    }
}

/// Why the course's Cook-Torrance cannot be scored on this input, if it cannot: a dot product
/// within rounding of one of its `1e-8` thresholds (the clamps of `V.N`, `L.N`, `H.N`, `V.H`,
/// `L.H` and `chi`), a half vector of length 0 (the course's `unit_vector` divides by zero) or
/// a negative root in `Gterm` (`1 + alpha^2 tan^2 < 0`, where `v.H > 1` with the unnormalised
/// vectors and `alpha > 1`; the course's `math.sqrt` raises `ValueError`).
fn cook_torrance_trouble(c: &Input, alpha: f64) -> Option<Class> {
    let (n, _) = c.hit.facing();
    let v = -c.hit.direction;
    let l = c.light;
    let half = halfvector(v, l);
    if half.length() < 1e-9 * (v.length() + l.length()) {
        return Some(Class::CourseFails(
            "V + L = 0: the course's unit_vector of the half vector divides by zero".into(),
        ));
    }
    let h = half.normalize();
    let near = |x: f64| (x - 1e-8).abs() < 1e-12 * (1.0 + x.abs());
    if near(h.dot(n)) {
        return Some(Class::Ambiguous(
            "N . H within rounding of the 1e-8 threshold".into(),
        ));
    }
    for x in [v, l] {
        let xn = n.dot(x);
        let xh = x.dot(h);
        if near(xn) || near(xh) || near(xh.max(1e-8) / xn.max(1e-8)) {
            return Some(Class::Ambiguous(
                "a value within rounding of the 1e-8 thresholds".into(),
            ));
        }
        let c2 = xh.max(1e-8).powi(2);
        let inside = 1.0 + alpha * alpha * (1.0 - c2) / c2;
        if inside < 1e-9 {
            return Some(Class::CourseFails("1 + alpha^2 tan^2 < 0 with the unnormalised vectors: the course's sqrt raises ValueError".into()));
        }
    }
    None
}

fn cook_torrance_check(seed: u64) -> FunctionCheck {
    let (kd, ks, ior) = (0.6, 0.9, 1.5);
    let alphas = [0.5, 0.1, 0.8];
    let mut cases = Vec::new();
    let mut no_pi = Vec::new();
    for (k, c) in inputs(seed, "cook-torrance").iter().enumerate() {
        let alpha = alphas[k % alphas.len()];
        let (n, _) = c.hit.facing();
        let want = cook_torrance(kd, ks, alpha, ior, c.hit.direction, c.light, n).x;
        let class = cook_torrance_trouble(c, alpha).unwrap_or(Class::Definite);
        let material = json!({"type": "cook_torrance", "albedo": [1.0, 1.0, 1.0], "kd": kd, "ks": ks, "alpha": jnum(alpha), "ior": ior});
        let ctor = format!(
            "rtm.CookTorrance({kd}, {ks}, {}, {ior})  # week 8: rtm.CookTorrance(rtu.Color(1, 1, 1), {kd}, {ks}, {}, {ior})",
            py::f(alpha),
            py::f(alpha)
        );
        let tol = 1e-9 * want.abs().max(1.0);
        cases.push(Case {
            id: format!("cook-torrance-{k:04}"),
            request: request(material, c),
            expect: Expected::one("value", Want::Number { value: want, tol }),
            class,
            input: format!(
                "CookTorrance(kd {kd}, ks {ks}, alpha {}, IOR {ior}): {}, the light along {}",
                py::f(alpha),
                c.hit.words(),
                py::list(c.light)
            ),
            repro: repro(&ctor, c, &py::f(want)),
        });
        let v = want - kd / std::f64::consts::PI + kd;
        no_pi.push(Some(Expected::one(
            "value",
            Want::Number {
                value: v,
                tol: 1e-9 * v.abs().max(1.0),
            },
        )));
    }
    FunctionCheck {
        id: "cook-torrance",
        function: "RT_material.CookTorrance.BRDF(ray_view, ray_light, hit)",
        week: week(8),
        given: false,
        op: "brdf",
        tolerance: "the number (or every component of a grey colour) within 1e-9 max(1, |value|); inputs where the course's code raises or a 1e-8 threshold decides are not scored",
        body: Body::Cases {
            cases,
            variants: vec![Variant {
                name: "cook_torrance_missing_pi",
                says: "the diffuse term is kd, without the division by pi",
                standing: Standing::Mistake,
                expect: no_pi,
            }],
            normalise: Some(grey_as_number as Normalise),
        },
        timeout: CASE_TIMEOUT,
    }
}
