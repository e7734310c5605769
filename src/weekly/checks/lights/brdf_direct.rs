//! Week 8's direct term through the BRDFs, and the physical cosine it is told from.

use super::*;

pub(super) fn brdf_direct_check(seed: u64) -> FunctionCheck {
    let phong_mat = Mat::Phong {
        albedo: DVec3::new(0.7, 0.2, 0.4),
        kd: 0.6,
        ks: 0.9,
        alpha: 8.0,
    };
    let blinn_mat = Mat::Blinn {
        albedo: DVec3::new(0.7, 0.2, 0.4),
        kd: 0.6,
        ks: 0.9,
        alpha: 8.0,
    };
    let lambert = Mat::Lambertian(DVec3::new(0.5, 0.25, 1.0));
    let settings = RenderSettings {
        integrator: Integrator::Brdf,
        background: Background::Flat,
        ..RenderSettings::default()
    };
    let mut cases = Vec::new();
    let mut unit_cos = Vec::new();
    for (k, s) in direct_scenes(seed, "brdf-direct", &[lambert, phong_mat, blinn_mat])
        .iter()
        .enumerate()
    {
        let want = shade(&s.objects, settings, s.origin, s.direction);
        let mut class = match scene_ambiguity(s) {
            Some(why) => Class::Ambiguous(why),
            None => Class::Definite,
        };
        // The physical alternative: n . unit(c - P) instead of n . (c - P).
        let alternative = physical_cosine(s);
        if let (Class::Definite, Err(why)) = (&class, &alternative) {
            class = Class::Ambiguous(why.clone());
        }
        cases.push(Case {
            id: format!("brdf-direct-{k:04}"),
            request: json!({"op": "shade", "objects": s.objects.iter().map(Obj::json).collect::<Vec<_>>(), "ray": {"origin": jvec(s.origin), "direction": jvec(s.direction)}, "depth": 1, "integrator": {"direct_light": true, "sky": false}}),
            expect: color(want),
            class,
            input: s.words(),
            repro: py::script(
                &format!("import RT_integrator as rti\n{}\nprint(rti.Integrator(True, False).compute_scattering(ray, scene, 1).e)", s.py()),
                &py::list(want),
            ),
        });
        unit_cos.push(alternative.ok().map(color));
    }
    FunctionCheck {
        id: "direct-term",
        function: "RT_integrator.Integrator.compute_scattering(ray, scene, 1) (the BRDF direct term)",
        week: week(8),
        given: false,
        op: "shade",
        tolerance: "each component within 1e-9 max(1, |colour|); hits, shadows and the 1e-6 cosine cut decided away from rounding, cases within it not scored",
        body: Body::Cases {
            cases,
            variants: vec![Variant {
                name: "cosine_of_unit_vectors",
                says: "the direct term's cosine uses the unit direction to the light (physically right; the course uses n . (c - P), which grows with the distance)",
                standing: Standing::Physical,
                expect: unit_cos,
            }],
            normalise: None,
        },
        timeout: CASE_TIMEOUT,
    }
}

/// Week 8's direct term with `n . unit(c - P)` (the physical cosine) for the scene's camera
/// ray: the BRDF of the hit's material (the reference's Phong and Blinn; a Lambertian's is its
/// albedo) times the emission and the cut cosine, over the unoccluded lights. `Err` when the
/// 1e-6 cut is within rounding.
fn physical_cosine(s: &Scene) -> Result<DVec3, String> {
    let Ok(Some((i, t))) = s.primary() else {
        return Ok(shade_miss());
    };
    let obj = s.objects[i];
    let p = s.origin + t * s.direction;
    let outward = match obj {
        Obj::Sphere { center, radius, .. } => (p - center) / radius,
        Obj::Quad { u, v, .. } => u.cross(v).normalize(),
    };
    let n = if s.direction.dot(outward) < 0.0 {
        outward
    } else {
        -outward
    };
    let mut le = DVec3::ZERO;
    if let Mat::Light(e) = obj.mat() {
        return Ok(e);
    }
    for o in &s.objects {
        let Obj::Sphere {
            center,
            mat: Mat::Light(e),
            ..
        } = *o
        else {
            continue;
        };
        let Ok((all, _)) = shadow_hits(&s.objects, p, center) else {
            return Err("a shadow ray is within rounding".into());
        };
        if all > 1 {
            continue;
        }
        let l = center - p;
        let c = n.dot(l.normalize());
        if (c - 1e-6).abs() < 1e-12 {
            return Err("the cosine is within rounding of the 1e-6 cut".into());
        }
        let c = if c < 1e-6 { 0.0 } else { c };
        let f = match obj.mat() {
            Mat::Lambertian(a) => a,
            Mat::Phong {
                albedo,
                kd,
                ks,
                alpha,
            } => phong(albedo, kd, ks, alpha, s.direction, l, n),
            Mat::Blinn {
                albedo,
                kd,
                ks,
                alpha,
            } => blinn(albedo, kd, ks, alpha, s.direction, l, n),
            Mat::Light(_) => DVec3::ZERO,
        };
        le += f * e * c;
    }
    Ok(le)
}
