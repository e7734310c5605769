//! `Dielectric.scattering`: the face's ratio, the unit direction, refraction or reflection as
//! the random number decides.

use super::*;

/// One dielectric case: the hit, the IOR, the random number.
struct DielectricInput {
    hit: HitInput,
    ior: f64,
    u: f64,
}

fn dielectric_inputs(seed: u64) -> Vec<DielectricInput> {
    let s3 = 3f64.sqrt();
    let mut inputs = vec![
        // Entering 30 degrees from the normal with a raw direction of length 2; leaving.
        DielectricInput {
            hit: HitInput {
                origin: DVec3::new(-1.0, s3, 0.0),
                direction: DVec3::new(1.0, -s3, 0.0),
                point: DVec3::ZERO,
                outward: DVec3::Y,
            },
            ior: 1.5,
            u: 1.0,
        },
        DielectricInput {
            hit: HitInput {
                origin: DVec3::new(-0.5, -s3 / 2.0, 0.0),
                direction: DVec3::new(0.5, s3 / 2.0, 0.0),
                point: DVec3::ZERO,
                outward: DVec3::Y,
            },
            ior: 1.5,
            u: 1.0,
        },
    ];
    let mut r = stream(seed, "dielectric");
    let iors = [1.5, 1.0, 0.5, 2.4, 1.33];
    for k in 0..14 {
        let (n, v) = random_arrival(&mut r);
        let d = v * (0.5 + 9.0 * r.next_f64());
        let outward = if k % 2 == 0 { n } else { -n };
        let point = mistakes::unit_vector(&mut r);
        inputs.push(DielectricInput {
            hit: HitInput {
                origin: point - d,
                direction: d,
                point,
                outward,
            },
            ior: iors[k % iors.len()],
            u: if k % 3 == 1 { 0.0 } else { 1.0 },
        });
    }
    inputs
}

/// What `Dielectric(albedo, ior).scattering` answers: the ratio by the face, the unit direction
/// (`unit_direction`: the course's), refracted or reflected by `branch_of`.
fn dielectric_answer(
    c: &DielectricInput,
    albedo: DVec3,
    back_ratio_inverted: bool,
    raw: bool,
    wrong_cos: bool,
) -> (Branch, Expected) {
    let (n, front) = c.hit.facing();
    let ratio = if front || back_ratio_inverted {
        1.0 / c.ior
    } else {
        c.ior
    };
    let v = if raw {
        c.hit.direction
    } else {
        c.hit.direction.normalize()
    };
    let branch = decide(v, n, ratio, c.u, wrong_cos);
    let (d, tol) = refract_answer(v, n, ratio, branch.reflects());
    (
        branch,
        scattered(c.hit.point, d, tol * v.length().max(1.0), albedo),
    )
}

/// What any answer of a dielectric case must keep: the reflected or the refracted direction
/// (the invariant of `dielectric-choice`, in this case's setting).
fn dielectric_behaviour(c: &DielectricInput, albedo: DVec3) -> steer::Behaviour {
    let (n, front) = c.hit.facing();
    let ratio = if front { 1.0 / c.ior } else { c.ior };
    let v = c.hit.direction.normalize();
    let cos = course_cos(v, n);
    let tir = ratio * (1.0 - cos * cos).sqrt() > 1.0;
    steer::scatter_behaviour(SamplerCheck::dielectric(DielectricSetting {
        point: c.hit.point,
        albedo,
        reflected: reflect(v, n),
        refracted: (!tir).then(|| refracted(v, n, ratio, cos)),
        p_reflect: if tir { 1.0 } else { schlick(cos, ratio) },
        p_wrong_cosine: schlick((1.0 - cos * cos).sqrt(), ratio),
    }))
}

pub(super) fn dielectric_check(seed: u64) -> FunctionCheck {
    let albedo = DVec3::ONE;
    let mut behaviour = Vec::new();
    let mut cases = Vec::new();
    let mut variants: Vec<(&'static str, &'static str, Vec<Option<Expected>>)> = vec![
        (
            "refraction_ratio_inverted_on_back_face",
            "Dielectric uses 1 / IOR on both faces (leaving the glass bends the ray the wrong way)",
            Vec::new(),
        ),
        (
            "refract_raw_direction",
            "Dielectric refracts the ray's raw (unnormalised) direction, not the unit one",
            Vec::new(),
        ),
        (
            "schlick_wrong_cosine",
            "refract feeds Schlick the sine of the angle instead of its cosine",
            Vec::new(),
        ),
    ];
    for (k, c) in dielectric_inputs(seed).iter().enumerate() {
        let (branch, expect) = dielectric_answer(c, albedo, false, false, false);
        let definite = |b: Branch| !matches!(b, Branch::Rounding(_));
        let mut push = |i: usize, (b, e): (Branch, Expected)| {
            variants[i]
                .2
                .push((definite(b) && definite(branch)).then_some(e));
        };
        push(0, dielectric_answer(c, albedo, true, false, false));
        push(1, dielectric_answer(c, albedo, false, true, false));
        push(2, dielectric_answer(c, albedo, false, false, true));
        let (ray, hit) = c.hit.json();
        let (_, front) = c.hit.facing();
        behaviour.push(dielectric_behaviour(c, albedo));
        let id = format!("dielectric-{k:04}");
        cases.push(Case {
            request: json!({"op": "scatter", "material": {"type": "dielectric", "albedo": jvec(albedo), "ior": jnum(c.ior)}, "ray": ray, "hit": hit, "replace": {"random_double": [jnum(c.u), jnum(c.u), jnum(c.u), jnum(c.u)]}, "seed": steer::case_seed(seed, &id)}),
            id,
            expect,
            class: class_of(branch),
            input: format!(
                "Dielectric(IOR {}): {} ({} face), random_double() = {}",
                py::f(c.ior),
                c.hit.words(),
                if front { "front" } else { "back" },
                py::f(c.u)
            ),
            repro: py::script(
                &format!(
                    "{}\n{}\ns = m.scattering(ray, hit)\n{}",
                    py::random_doubles(&[c.u; 4]),
                    c.hit.py(&format!("rtm.Dielectric({}, {})", py::color(albedo), py::f(c.ior))),
                    py::PRINT_SCATTERED
                ),
                "the direction above",
            ),
        });
    }
    FunctionCheck {
        id: "dielectric",
        function: "RT_material.Dielectric.scattering(ray, hit)",
        week: week(6),
        given: false,
        op: "scatter",
        tolerance: "with random_double() steered: the direction's components within 1e-9 (more near grazing refraction); cases within rounding of a decision are not scored; an answer drawn otherwise counts when it is the reflected or the refracted direction and dielectric-choice passes",
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
            partners: &["dielectric-choice"],
            behaviour,
            normalise: None,
        },
        timeout: CASE_TIMEOUT,
    }
}
