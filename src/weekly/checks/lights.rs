//! Lights and integrators: week 5's `find_occlusion` and direct term, each week's background,
//! week 8's BRDF direct term; `compute_scattering(ray, scene, 1)` is exactly the direct term.
//!
//! The expected colours are the reference's ([`crate::render::trace`] on a world built from the
//! case's objects, at depth 1, in the course profile). Every hit and miss the answer rests on
//! (the camera ray's, each shadow ray's against each object on `(1e-6, |c - P|)`) is decided
//! by the intersection oracle ([`crate::oracle::classify::classify`], the course profile): a
//! case with an ambiguous one is not scored.

use glam::DVec3;
use serde_json::json;

use super::{Body, CASE_TIMEOUT, Case, FunctionCheck, Variant, jnum, jvec, py, stream, week};
use crate::geometry::Ray;
use crate::oracle::classify::classify;
use crate::oracle::vectors::{Class as HitClass, RaySpec, ShapeSpec};
use crate::render::{PixelSampler, blinn, phong, sky, trace};
use crate::scene::{
    Background, CameraSettings, ImageSettings, Integrator, MaterialEntry, MaterialKind,
    ObjectEntry, Profile, RenderSettings, SceneDescription, World,
};
use crate::weekly::expect::{Class, Expected, Want};
use crate::weekly::samplers::Standing;
use crate::weekly::samplers::mistakes;

/// A material of the light checks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Mat {
    Lambertian(DVec3),
    Light(DVec3),
    Phong {
        albedo: DVec3,
        kd: f64,
        ks: f64,
        alpha: f64,
    },
    Blinn {
        albedo: DVec3,
        kd: f64,
        ks: f64,
        alpha: f64,
    },
}

impl Mat {
    fn json(&self) -> serde_json::Value {
        match *self {
            Mat::Lambertian(a) => json!({"type": "lambertian", "albedo": jvec(a)}),
            Mat::Light(e) => json!({"type": "diffuse_light", "color": jvec(e)}),
            Mat::Phong {
                albedo,
                kd,
                ks,
                alpha,
            } => {
                json!({"type": "phong", "albedo": jvec(albedo), "kd": jnum(kd), "ks": jnum(ks), "alpha": jnum(alpha)})
            }
            Mat::Blinn {
                albedo,
                kd,
                ks,
                alpha,
            } => {
                json!({"type": "blinn", "albedo": jvec(albedo), "kd": jnum(kd), "ks": jnum(ks), "alpha": jnum(alpha)})
            }
        }
    }

    fn py(&self) -> String {
        match *self {
            Mat::Lambertian(a) => format!("rtm.Lambertian({})", py::color(a)),
            Mat::Light(e) => format!("rtl.Diffuse_light({})", py::color(e)),
            Mat::Phong {
                albedo,
                kd,
                ks,
                alpha,
            } => format!(
                "rtm.Phong({}, {}, {}, {})",
                py::color(albedo),
                py::f(kd),
                py::f(ks),
                py::f(alpha)
            ),
            Mat::Blinn {
                albedo,
                kd,
                ks,
                alpha,
            } => format!(
                "rtm.Blinn({}, {}, {}, {})",
                py::color(albedo),
                py::f(kd),
                py::f(ks),
                py::f(alpha)
            ),
        }
    }

    fn entry(&self, name: &str) -> MaterialEntry {
        let (kind, albedo) = match *self {
            Mat::Lambertian(a) => (MaterialKind::Lambertian, a),
            Mat::Light(e) => (MaterialKind::DiffuseLight, e),
            Mat::Phong { albedo, .. } => (MaterialKind::Phong, albedo),
            Mat::Blinn { albedo, .. } => (MaterialKind::Blinn, albedo),
        };
        let mut m = MaterialEntry::new(name, kind, albedo.to_array());
        if let Mat::Phong { kd, ks, alpha, .. } | Mat::Blinn { kd, ks, alpha, .. } = *self {
            m.kd = Some(kd);
            m.ks = Some(ks);
            m.alpha = Some(alpha);
        }
        m
    }
}

/// An object of the light checks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Obj {
    Sphere {
        center: DVec3,
        radius: f64,
        mat: Mat,
    },
    Quad {
        q: DVec3,
        u: DVec3,
        v: DVec3,
        mat: Mat,
    },
}

impl Obj {
    fn mat(&self) -> Mat {
        match *self {
            Obj::Sphere { mat, .. } | Obj::Quad { mat, .. } => mat,
        }
    }

    fn json(&self) -> serde_json::Value {
        match *self {
            Obj::Sphere {
                center,
                radius,
                mat,
            } => {
                json!({"type": "sphere", "center": jvec(center), "radius": jnum(radius), "material": mat.json()})
            }
            Obj::Quad { q, u, v, mat } => {
                json!({"type": "quad", "q": jvec(q), "u": jvec(u), "v": jvec(v), "material": mat.json()})
            }
        }
    }

    fn py(&self) -> String {
        match *self {
            Obj::Sphere {
                center,
                radius,
                mat,
            } => format!(
                "rto.Sphere({}, {}, {})",
                py::vec(center),
                py::f(radius),
                mat.py()
            ),
            Obj::Quad { q, u, v, mat } => format!(
                "rto.Quad({}, {}, {}, {})",
                py::vec(q),
                py::vec(u),
                py::vec(v),
                mat.py()
            ),
        }
    }

    fn shape(&self) -> ShapeSpec {
        match *self {
            Obj::Sphere { center, radius, .. } => ShapeSpec::Sphere {
                center: center.to_array(),
                radius,
            },
            Obj::Quad { q, u, v, .. } => ShapeSpec::Quad {
                q: q.to_array(),
                u: u.to_array(),
                v: v.to_array(),
            },
        }
    }

    fn is_light(&self) -> bool {
        matches!(self.mat(), Mat::Light(_))
    }
}

/// The oracle's decision on `ray` against `obj` in `interval`: `Some(t)` for a hit, `None`
/// for a miss, `Err` when rounding decides.
fn decide(
    obj: &Obj,
    origin: DVec3,
    direction: DVec3,
    interval: [f64; 2],
) -> Result<Option<f64>, ()> {
    let ray = RaySpec {
        origin: origin.to_array(),
        direction: direction.to_array(),
    };
    let e = classify(&obj.shape(), &ray, interval);
    match e.class {
        HitClass::Hit => Ok(Some(e.t.unwrap_or(f64::NAN))),
        HitClass::Miss => Ok(None),
        _ => Err(()),
    }
}

/// How many objects the course's shadow ray from `p` to the light at `c` hits (every object
/// tested on the whole interval `(1e-6, |c - p|)` in t units), and how many of them are
/// lights; `Err` when rounding decides one of them.
fn shadow_hits(objects: &[Obj], p: DVec3, c: DVec3) -> Result<(usize, usize), ()> {
    let to_light = c - p;
    let interval = [1e-6, to_light.length()];
    let (mut all, mut lights) = (0, 0);
    for o in objects {
        if decide(o, p, to_light, interval)?.is_some() {
            all += 1;
            if o.is_light() {
                lights += 1;
            }
        }
    }
    Ok((all, lights))
}

/// The world of `objects` with `settings`, in the course profile.
fn world(objects: &[Obj], settings: RenderSettings) -> World {
    let materials: Vec<MaterialEntry> = objects
        .iter()
        .enumerate()
        .map(|(i, o)| o.mat().entry(&format!("m{i}")))
        .collect();
    let entries = objects
        .iter()
        .enumerate()
        .map(|(i, o)| match *o {
            Obj::Sphere { center, radius, .. } => ObjectEntry::Sphere {
                center: center.to_array(),
                radius,
                material: format!("m{i}"),
                moving_center: None,
            },
            Obj::Quad { q, u, v, .. } => ObjectEntry::Quad {
                q: q.to_array(),
                u: u.to_array(),
                v: v.to_array(),
                material: format!("m{i}"),
            },
        })
        .collect();
    SceneDescription {
        profile: Profile::Course,
        image: ImageSettings {
            width: 1,
            aspect_ratio: 1.0,
            samples_per_pixel: 1,
        },
        camera: CameraSettings {
            look_from: [0.0, 0.0, 1.0],
            look_at: [0.0, 0.0, 0.0],
            up: [0.0, 1.0, 0.0],
            vfov: 90.0,
            focus_distance: 10.0,
            defocus_angle: 0.0,
        },
        render: settings,
        textures: Vec::new(),
        materials,
        objects: entries,
        base_dir: None,
    }
    .scene()
}

/// `compute_scattering(ray, scene, 1)` by the reference.
fn shade(objects: &[Obj], settings: RenderSettings, origin: DVec3, direction: DVec3) -> DVec3 {
    let mut w = world(
        objects,
        RenderSettings {
            max_depth: 1,
            ..settings
        },
    );
    w.settings.max_depth = 1;
    trace(
        &w,
        &Ray::new(origin, direction),
        &mut PixelSampler::new(0, 0),
    )
}

/// A scene of the light checks and its camera ray.
#[derive(Clone, Debug)]
struct Scene {
    objects: Vec<Obj>,
    origin: DVec3,
    direction: DVec3,
}

impl Scene {
    /// Python lines that make `scene` and `ray`.
    fn py(&self) -> String {
        let mut lines = vec![
            "import RT_scene as rts, RT_light as rtl".to_string(),
            "scene = rts.Scene()".to_string(),
        ];
        for o in &self.objects {
            lines.push(format!("scene.add_object({})", o.py()));
        }
        lines.push("scene.find_lights()".into());
        lines.push(format!(
            "ray = {}",
            py::ray(self.origin, self.direction, 0.0)
        ));
        lines.join("\n")
    }

    fn words(&self) -> String {
        let objs: Vec<String> = self
            .objects
            .iter()
            .map(|o| match *o {
                Obj::Sphere {
                    center,
                    radius,
                    mat,
                } => format!(
                    "sphere {} r {} ({})",
                    py::list(center),
                    py::f(radius),
                    kind(mat)
                ),
                Obj::Quad { q, u, v, mat } => format!(
                    "quad Q {} u {} v {} ({})",
                    py::list(q),
                    py::list(u),
                    py::list(v),
                    kind(mat)
                ),
            })
            .collect();
        format!(
            "{}; a ray from {} along {}",
            objs.join(", "),
            py::list(self.origin),
            py::list(self.direction)
        )
    }

    /// The closest hit of the camera ray in `(1e-6, f64::MAX)`: its object and t, `None` for a
    /// miss, `Err` when rounding decides.
    fn primary(&self) -> Result<Option<(usize, f64)>, ()> {
        let mut best: Option<(usize, f64)> = None;
        for (i, o) in self.objects.iter().enumerate() {
            if let Some(t) = decide(o, self.origin, self.direction, [1e-6, f64::MAX])? {
                if best.is_none_or(|(_, b)| t < b) {
                    best = Some((i, t));
                }
            }
        }
        Ok(best)
    }
}

fn kind(m: Mat) -> &'static str {
    match m {
        Mat::Lambertian(_) => "Lambertian",
        Mat::Light(_) => "Diffuse_light",
        Mat::Phong { .. } => "Phong",
        Mat::Blinn { .. } => "Blinn",
    }
}

pub(crate) fn checks(seed: u64) -> Vec<FunctionCheck> {
    vec![
        occlusion_check(seed),
        direct_check(seed),
        background_check(5),
        background_check(6),
        background_check(7),
        background_check(8),
        brdf_direct::brdf_direct_check(seed),
    ]
}

mod brdf_direct;

const GREY: Mat = Mat::Lambertian(DVec3::splat(0.5));

fn light(c: DVec3) -> Obj {
    Obj::Sphere {
        center: c,
        radius: 0.1,
        mat: Mat::Light(DVec3::ONE),
    }
}

fn occlusion_check(seed: u64) -> FunctionCheck {
    let big = Obj::Sphere {
        center: DVec3::new(0.0, 0.0, 2.0),
        radius: 0.5,
        mat: GREY,
    };
    let small = Obj::Sphere {
        center: DVec3::new(0.0, 0.0, 0.25),
        radius: 0.05,
        mat: GREY,
    };
    let far = Obj::Sphere {
        center: DVec3::new(0.0, 0.0, -3.0),
        radius: 0.5,
        mat: GREY,
    };
    let l = light(DVec3::ZERO);
    let mut inputs: Vec<(Vec<Obj>, DVec3, DVec3)> = vec![
        (vec![l, big], DVec3::new(0.0, 0.0, 4.0), DVec3::ZERO),
        // Off the axis: a shadow ray down the y axis would meet the light at its pole, where
        // week 7's get_uv raises (the course's own code).
        (vec![l, big], DVec3::new(0.5, 3.0, 0.0), DVec3::ZERO),
        (vec![l, small], DVec3::new(0.0, 0.0, 0.5), DVec3::ZERO),
        (vec![l, far], DVec3::new(0.0, 0.0, 4.0), DVec3::ZERO),
        (vec![l], DVec3::new(0.0, 0.0, 4.0), DVec3::ZERO),
    ];
    let mut r = stream(seed, "occlusion");
    for _ in 0..10 {
        let c = 2.0 * mistakes::unit_vector(&mut r);
        let p = c + (0.3 + 4.0 * r.next_f64()) * mistakes::unit_vector(&mut r);
        let mut objects = vec![light(c)];
        for _ in 0..3 {
            let t = r.next_f64() * 1.6;
            let center = p + t * (c - p) + 0.4 * mistakes::unit_vector(&mut r);
            objects.push(Obj::Sphere {
                center,
                radius: 0.1 + 0.3 * r.next_f64(),
                mat: GREY,
            });
        }
        inputs.push((objects, p, c));
    }
    let mut cases = Vec::new();
    let mut variants: Vec<(&'static str, &'static str, Vec<Option<Expected>>)> = vec![
        (
            "shadows_inverted",
            "find_occlusion answers the opposite: lit where the course shadows and back",
            Vec::new(),
        ),
        (
            "light_sphere_not_counted",
            "find_occlusion skips the lights' spheres but still wants more than one hit",
            Vec::new(),
        ),
        (
            "light_sphere_occludes",
            "find_occlusion shadows on any hit, so the light's own sphere shadows",
            Vec::new(),
        ),
    ];
    for (k, (objects, p, c)) in inputs.iter().enumerate() {
        let to_light = *c - *p;
        let decided = shadow_hits(objects, *p, *c);
        let (occluded, class, hits) = match decided {
            Ok((all, lights)) => (all > 1, Class::Definite, Some((all, lights))),
            Err(()) => (false, Class::Ambiguous("a shadow ray meets an object within rounding of its edge or of the interval's end".into()), None),
        };
        let want = |b: bool| Some(Expected::one("occluded", Want::Bool(b)));
        match hits {
            Some((all, lights)) => {
                variants[0].2.push(want(all <= 1));
                variants[1].2.push(want(all - lights > 1));
                variants[2].2.push(want(all > 0));
            }
            None => variants.iter_mut().for_each(|v| v.2.push(None)),
        }
        let scene = Scene {
            objects: objects.clone(),
            origin: *p,
            direction: to_light,
        };
        cases.push(Case {
            id: format!("occlusion-{k:04}"),
            request: json!({"op": "occlusion", "objects": objects.iter().map(Obj::json).collect::<Vec<_>>(), "ray": {"origin": jvec(*p), "direction": jvec(to_light)}, "interval": [1e-6, jnum(to_light.length())]}),
            expect: Expected::one("occluded", Want::Bool(occluded)),
            class,
            input: format!("the shadow ray from {} to the light at {}: {}", py::list(*p), py::list(*c), scene.words()),
            repro: py::script(
                &format!("{}\nprint(scene.find_occlusion(ray, rtu.Interval(1e-06, ray.getDirection().len())))", scene.py()),
                &occluded.to_string(),
            ),
        });
    }
    FunctionCheck {
        id: "occlusion",
        function: "RT_scene.Scene.find_occlusion(shadow_ray, interval)",
        week: week(5),
        given: false,
        op: "occlusion",
        tolerance: "exact (occluded or not); every hit decided by the intersection oracle, cases within rounding not scored",
        body: Body::Cases {
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
            normalise: None,
        },
        timeout: CASE_TIMEOUT,
    }
}

fn color(c: DVec3) -> Expected {
    Expected::one(
        "color",
        Want::vector(c, 1e-9 * c.abs().max_element().max(1.0)),
    )
}

/// The scenes of the direct-term checks: a Lambertian sphere seen head on, lit, shadowed, lit
/// by two lights, hit on a light; then random floors and spheres.
fn direct_scenes(seed: u64, id: &str, mats: &[Mat]) -> Vec<Scene> {
    let a = mats[0];
    let base = |extra: Vec<Obj>| {
        let mut objects = vec![
            Obj::Sphere {
                center: DVec3::ZERO,
                radius: 1.0,
                mat: a,
            },
            light(DVec3::new(0.0, 2.0, 1.0)),
        ];
        objects.extend(extra);
        Scene {
            objects,
            origin: DVec3::new(0.0, 0.0, 5.0),
            direction: DVec3::new(0.0, 0.0, -1.0),
        }
    };
    let mut scenes = vec![
        base(vec![]),
        base(vec![Obj::Sphere {
            center: DVec3::new(0.0, 1.0, 1.0),
            radius: 0.3,
            mat: GREY,
        }]),
        base(vec![light(DVec3::new(0.5, 0.0, 1.5))]),
        Scene {
            origin: DVec3::new(0.0, 2.0, 4.0),
            direction: DVec3::new(0.0, 0.0, -1.0),
            ..base(vec![])
        },
    ];
    let mut r = stream(seed, id);
    for k in 0..8 {
        let mat = mats[k % mats.len()];
        let floor = Obj::Quad {
            q: DVec3::new(-3.0, -1.0, -3.0),
            u: DVec3::new(6.0, 0.0, 0.0),
            v: DVec3::new(0.0, 0.0, 6.0),
            mat,
        };
        let ball = Obj::Sphere {
            center: DVec3::new(r.next_f64() - 0.5, -0.5, r.next_f64() - 0.5),
            radius: 0.5,
            mat: mats[(k + 1) % mats.len()],
        };
        let mut objects = vec![floor, ball];
        for _ in 0..(1 + k % 2) {
            let c = DVec3::new(
                4.0 * r.next_f64() - 2.0,
                0.2 + 2.5 * r.next_f64(),
                4.0 * r.next_f64() - 2.0,
            );
            objects.push(light(c));
        }
        let target = DVec3::new(2.0 * r.next_f64() - 1.0, -1.0, 2.0 * r.next_f64() - 1.0);
        let origin = DVec3::new(0.3, 3.0, 4.0);
        scenes.push(Scene {
            objects,
            origin,
            direction: target - origin,
        });
    }
    scenes
}

/// Whether a scene's answer rests on a decision within rounding; the reason.
fn scene_ambiguity(s: &Scene) -> Option<String> {
    let Ok(primary) = s.primary() else {
        return Some("the camera ray meets an object within rounding of its edge".into());
    };
    let (_, t) = primary?;
    let p = s.origin + t * s.direction;
    for o in s.objects.iter().filter(|o| o.is_light()) {
        if let Obj::Sphere { center, .. } = o {
            if shadow_hits(&s.objects, p, *center).is_err() {
                return Some("a shadow ray meets an object within rounding of its edge or of the interval's end".into());
            }
        }
    }
    None
}

fn direct_check(seed: u64) -> FunctionCheck {
    let a = Mat::Lambertian(DVec3::new(0.5, 0.25, 1.0));
    let settings = RenderSettings {
        integrator: Integrator::Direct,
        background: Background::Flat,
        ..RenderSettings::default()
    };
    let unclamped = RenderSettings {
        direct_term: crate::scene::DirectTerm::Unclamped,
        ..settings
    };
    let mut cases = Vec::new();
    let mut older = Vec::new();
    let mut unshadowed = Vec::new();
    for (k, s) in direct_scenes(seed, "direct-term", &[a, GREY])
        .iter()
        .enumerate()
    {
        let want = shade(&s.objects, settings, s.origin, s.direction);
        let class = match scene_ambiguity(s) {
            Some(why) => Class::Ambiguous(why),
            None => Class::Definite,
        };
        cases.push(Case {
            id: format!("direct-term-{k:04}"),
            request: json!({"op": "shade", "objects": s.objects.iter().map(Obj::json).collect::<Vec<_>>(), "ray": {"origin": jvec(s.origin), "direction": jvec(s.direction)}, "depth": 1}),
            expect: color(want),
            class,
            input: s.words(),
            repro: py::script(
                &format!("import RT_integrator as rti\n{}\nprint(rti.Integrator().compute_scattering(ray, scene, 1).e)", s.py()),
                &py::list(want),
            ),
        });
        older.push(Some(color(shade(
            &s.objects,
            unclamped,
            s.origin,
            s.direction,
        ))));
        unshadowed.push(unshadowed_term(s).map(color));
    }
    FunctionCheck {
        id: "direct-term",
        function: "RT_integrator.Integrator.compute_scattering(ray, scene, 1) (the direct term)",
        week: week(5),
        given: false,
        op: "shade",
        tolerance: "each component within 1e-9 max(1, |colour|); hits and shadows decided by the oracle, cases within rounding not scored. The current reference (E min(1, 1/d), times the albedo) is checked; the earlier one (E / d, not times the albedo) is named when it fits",
        body: Body::Cases {
            cases,
            variants: vec![
                Variant {
                    name: "older_direct_term_one_over_d",
                    says: "the earlier reference: E / d instead of E min(1, 1/d), and Le + a Li with Le not multiplied by the albedo",
                    standing: Standing::Alternative,
                    expect: older,
                },
                Variant {
                    name: "shadows_missing",
                    says: "the direct term ignores the shadow test: every point light lights every point",
                    standing: Standing::Mistake,
                    expect: unshadowed,
                },
            ],
            normalise: None,
        },
        timeout: CASE_TIMEOUT,
    }
}

/// Week 5's direct term with no shadow test: a light's own emission where the camera ray hits a
/// light, else the albedo times the sum over the point lights of `E min(1, 1/d)` (`None` for a
/// miss, another material, or a camera ray within rounding).
fn unshadowed_term(s: &Scene) -> Option<DVec3> {
    let (i, t) = s.primary().ok()??;
    let p = s.origin + t * s.direction;
    let albedo = match s.objects[i].mat() {
        Mat::Light(e) => return Some(e),
        Mat::Lambertian(a) => a,
        _ => return None,
    };
    let mut sum = DVec3::ZERO;
    for o in &s.objects {
        if let Obj::Sphere {
            center,
            mat: Mat::Light(e),
            ..
        } = *o
        {
            sum += e * (1.0 / (center - p).length()).min(1.0);
        }
    }
    Some(albedo * sum)
}

fn background_check(of: u8) -> FunctionCheck {
    let directions = [
        DVec3::Y,
        DVec3::new(1.0, 0.0, -1.0),
        DVec3::new(0.3, -2.0, 0.5),
        DVec3::new(0.0, 0.5, -3.0),
    ];
    let grey = DVec3::splat(0.01);
    // Week 8's integrator takes bSkyBG: both settings are asked.
    let settings: Vec<Option<bool>> = if of >= 8 {
        vec![Some(false), Some(true)]
    } else {
        vec![None]
    };
    let mut cases = Vec::new();
    let mut other = Vec::new();
    for sky_flag in settings {
        for &d in &directions {
            let is_sky = match sky_flag {
                Some(f) => f,
                None => of == 6,
            };
            let want = if is_sky { sky(d) } else { grey };
            let mut request = json!({"op": "shade", "objects": [], "ray": {"origin": [0.0, 0.0, 0.0], "direction": jvec(d)}, "depth": 1});
            let ctor = match sky_flag {
                Some(f) => {
                    request["integrator"] = json!({"direct_light": true, "sky": f});
                    format!(
                        "rti.Integrator(bSkyBG={})",
                        if f { "True" } else { "False" }
                    )
                }
                None => "rti.Integrator()".into(),
            };
            let k = cases.len();
            cases.push(Case {
                id: format!("background-{of}-{k:04}"),
                request,
                expect: color(want),
                class: Class::Definite,
                input: format!("a ray along {} in an empty scene, {ctor}", py::list(d)),
                repro: py::script(
                    &format!("import RT_scene as rts, RT_integrator as rti\nprint({ctor}.compute_scattering({}, rts.Scene(), 1).e)", py::ray(DVec3::ZERO, d, 0.0)),
                    &py::list(want),
                ),
            });
            other.push(Some(color(if is_sky { grey } else { sky(d) })));
        }
    }
    let (name, says, standing) = match of {
        6 => (
            "sky_not_added",
            "a miss is still week 5's flat 0.01 grey, not the sky",
            Standing::Mistake,
        ),
        7 => (
            "sky_kept",
            "a miss is week 6's sky instead of the course's flat 0.01 grey (the README says sky; the solution's code does not)",
            Standing::Alternative,
        ),
        8 => (
            "sky_setting_ignored",
            "a miss ignores bSkyBG",
            Standing::Mistake,
        ),
        _ => (
            "sky_instead_of_grey",
            "a miss is the sky instead of the course's flat 0.01 grey",
            Standing::Mistake,
        ),
    };
    FunctionCheck {
        id: "background",
        function: "RT_integrator.Integrator.compute_scattering(ray, scene, 1) (a miss)",
        week: week(of),
        // Week 7's skeleton already has the flat grey back.
        given: of == 7,
        op: "shade",
        tolerance: "each component within 1e-9",
        body: Body::Cases {
            cases,
            variants: if of >= 8 {
                Vec::new()
            } else {
                vec![Variant {
                    name,
                    says,
                    standing,
                    expect: other,
                }]
            },
            normalise: None,
        },
        timeout: CASE_TIMEOUT,
    }
}

fn shade_miss() -> DVec3 {
    DVec3::splat(0.01)
}
