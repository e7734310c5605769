//! A scene written for Mitsuba 3, an independent renderer, to check the reference against.
//!
//! Promises: [`to_mitsuba_xml`] writes a scene of the `physical` profile as a Mitsuba 3 scene file
//! (format version 3.0.0) that renders the same image in expectation, or says in one line why it
//! cannot: only where the two renderers share the physics.
//!
//! - Camera: `perspective`, `fov_axis` `y` at the scene's `vfov`, `lookat` from the scene's
//!   `look_from`, `look_at` and `up`; the film `hdrfilm` of the scene's size with a `box` filter
//!   (each sample uniform in its pixel, as the reference's uniform jitter). A defocus angle is
//!   refused (Mitsuba's thin lens is parametrised otherwise).
//! - Integrator: `path` with `max_depth` the scene's `max_depth` (a path of `k` bounces that then
//!   escapes has `k + 1` segments in both), Russian roulette left to Mitsuba (it is unbiased).
//! - Background: the flat `background_color` as a `constant` emitter. The book's sky gradient
//!   has no emitter to write inline, so a sky scene is refused.
//! - Materials: `lambertian` as a two-sided `diffuse` (the book's scatters on both sides);
//!   `mirror` and `metal` of roughness 0 as a two-sided `conductor` of material `none` (a
//!   reflectance of the albedo at every angle); `diffuse_light` as an `area` emitter of radiance
//!   `albedo` on a black surface, on both sides of a quad (two rectangles back to back,
//!   `1e-5` of the quad's scale apart: Mitsuba computes in f32, whose step at 2.5 is 2.4e-7) and outside a sphere (a ray from inside a light sphere sees it dark
//!   in Mitsuba). Refused: the dielectric (the book's Schlick against Mitsuba's exact Fresnel),
//!   rough metal (the book's fuzz is no microfacet model), the course's BRDFs and textures.
//! - Shapes: spheres (`sphere`), quads (`rectangle` with a matrix taking `[-1, 1]^2` to
//!   `Q + a u + b v`); triangles and moving spheres are refused.
//!
//! Names are written through [`crate::escape::xml`], so a material called `a"b` stays text.

use std::fmt::Write as _;

use crate::scene::{
    Background, MaterialEntry, MaterialKind, ObjectEntry, Profile, SceneDescription,
};

/// Why a scene cannot be written for Mitsuba (one line).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("cannot write it for Mitsuba 3: {0}")]
pub struct MitsubaError(pub String);

fn refuse<T>(why: impl Into<String>) -> Result<T, MitsubaError> {
    Err(MitsubaError(why.into()))
}

fn rgb(v: [f64; 3]) -> String {
    format!("{:?}, {:?}, {:?}", v[0], v[1], v[2])
}

fn xyz(v: [f64; 3]) -> String {
    format!("{:?}, {:?}, {:?}", v[0], v[1], v[2])
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn scale(a: [f64; 3], k: f64) -> [f64; 3] {
    a.map(|x| x * k)
}

fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// A `rectangle` whose `[-1, 1]^2` is `q + a u + b v` (`a`, `b` in `[0, 1]`), facing `u x v`.
fn rectangle(out: &mut String, q: [f64; 3], u: [f64; 3], v: [f64; 3], inner: &str) {
    let n = cross(u, v);
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    let n = scale(n, 1.0 / len);
    let (hu, hv) = (scale(u, 0.5), scale(v, 0.5));
    let c = add(q, add(hu, hv));
    let m = [
        [hu[0], hv[0], n[0], c[0]],
        [hu[1], hv[1], n[1], c[1]],
        [hu[2], hv[2], n[2], c[2]],
        [0.0, 0.0, 0.0, 1.0],
    ];
    let values: Vec<String> = m.iter().flatten().map(|x| format!("{x:?}")).collect();
    let _ = writeln!(
        out,
        "    <shape type=\"rectangle\">\n        <transform name=\"to_world\"><matrix value=\"{}\"/></transform>\n{inner}    </shape>",
        values.join(" ")
    );
}

/// The BSDF of a material, or why it is not shared.
fn bsdf(m: &MaterialEntry) -> Result<String, MitsubaError> {
    let id = crate::escape::xml(&m.name);
    Ok(match m.kind {
        MaterialKind::Lambertian => format!(
            "    <bsdf type=\"twosided\" id=\"{id}\">\n        <bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"{}\"/></bsdf>\n    </bsdf>\n",
            rgb(m.albedo)
        ),
        MaterialKind::Mirror => mirror(&id, m.albedo),
        MaterialKind::Metal if m.roughness == Some(0.0) => mirror(&id, m.albedo),
        MaterialKind::DiffuseLight => format!(
            "    <bsdf type=\"diffuse\" id=\"{id}\"><rgb name=\"reflectance\" value=\"0, 0, 0\"/></bsdf>\n"
        ),
        MaterialKind::Metal => {
            return refuse(format!(
                "material {}: a rough metal (the book's fuzz is no microfacet model Mitsuba has)",
                crate::escape::terminal_line(&m.name)
            ));
        }
        MaterialKind::Dielectric => {
            return refuse(format!(
                "material {}: a dielectric (the book's Schlick approximation against Mitsuba's exact Fresnel)",
                crate::escape::terminal_line(&m.name)
            ));
        }
        other => {
            return refuse(format!(
                "material {}: a {} material (none of Mitsuba's BSDFs is the same)",
                crate::escape::terminal_line(&m.name),
                other.name()
            ));
        }
    })
}

fn mirror(id: &str, albedo: [f64; 3]) -> String {
    format!(
        "    <bsdf type=\"twosided\" id=\"{id}\">\n        <bsdf type=\"conductor\"><string name=\"material\" value=\"none\"/><rgb name=\"specular_reflectance\" value=\"{}\"/></bsdf>\n    </bsdf>\n",
        rgb(albedo)
    )
}

/// The scene as a Mitsuba 3 scene file (see the module's promises), or why it cannot be.
pub fn to_mitsuba_xml(d: &SceneDescription) -> Result<String, MitsubaError> {
    if d.profile != Profile::Physical {
        return refuse(
            "it is a course-profile scene (the course's integrators are not path tracers Mitsuba has); give --profile physical",
        );
    }
    if d.render.background == Background::Sky {
        return refuse(
            "its background is the book's sky gradient, which has no Mitsuba emitter to write inline",
        );
    }
    if d.camera.defocus_angle != 0.0 {
        return refuse("its camera has a defocus angle");
    }
    if !d.textures.is_empty() {
        return refuse("it has textures");
    }
    let camera = d.camera(None);
    let mut out = String::new();
    out.push_str("<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<!-- Written by rtoracle (scene::description::mitsuba): the reference's physics where Mitsuba shares it. -->\n<scene version=\"3.0.0\">\n");
    let _ = writeln!(
        out,
        "    <integrator type=\"path\"><integer name=\"max_depth\" value=\"{}\"/></integrator>",
        d.render.max_depth
    );
    let c = &d.camera;
    let _ = writeln!(
        out,
        "    <sensor type=\"perspective\">\n        <string name=\"fov_axis\" value=\"y\"/>\n        <float name=\"fov\" value=\"{:?}\"/>\n        <transform name=\"to_world\"><lookat origin=\"{}\" target=\"{}\" up=\"{}\"/></transform>\n        <sampler type=\"independent\"><integer name=\"sample_count\" value=\"{}\"/></sampler>\n        <film type=\"hdrfilm\">\n            <integer name=\"width\" value=\"{}\"/>\n            <integer name=\"height\" value=\"{}\"/>\n            <rfilter type=\"box\"/>\n            <string name=\"pixel_format\" value=\"rgb\"/>\n        </film>\n    </sensor>",
        c.vfov,
        xyz(c.look_from),
        xyz(c.look_at),
        xyz(c.up),
        d.image.samples_per_pixel,
        camera.width,
        camera.height
    );
    let _ = writeln!(
        out,
        "    <emitter type=\"constant\"><rgb name=\"radiance\" value=\"{}\"/></emitter>",
        rgb(d.render.background_color)
    );
    for m in &d.materials {
        out.push_str(&bsdf(m)?);
    }
    let material = |name: &str| {
        d.materials.iter().find(|m| m.name == name).ok_or_else(|| {
            MitsubaError(format!(
                "no material called {}",
                crate::escape::terminal_line(name)
            ))
        })
    };
    for object in &d.objects {
        let m = material(object.material())?;
        let id = crate::escape::xml(&m.name);
        let light = m.kind == MaterialKind::DiffuseLight;
        let inner = if light {
            format!(
                "        <ref id=\"{id}\"/>\n        <emitter type=\"area\"><rgb name=\"radiance\" value=\"{}\"/></emitter>\n",
                rgb(m.albedo)
            )
        } else {
            format!("        <ref id=\"{id}\"/>\n")
        };
        match object {
            ObjectEntry::Sphere {
                moving_center: Some(_),
                ..
            } => return refuse("it has a moving sphere"),
            ObjectEntry::Sphere { center, radius, .. } => {
                let _ = writeln!(
                    out,
                    "    <shape type=\"sphere\">\n        <point name=\"center\" value=\"{}\"/>\n        <float name=\"radius\" value=\"{:?}\"/>\n{inner}    </shape>",
                    xyz(*center),
                    radius.abs()
                );
            }
            ObjectEntry::Quad { q, u, v, .. } if light => {
                // Two rectangles back to back, each emitting on its own side, far enough apart
                // for Mitsuba's f32 to tell them apart (a hundred steps of f32 at the quad's
                // scale), near enough to change no image.
                let n = cross(*u, *v);
                let n = scale(n, 1.0 / (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt());
                let size = [*q, *u, *v]
                    .iter()
                    .flatten()
                    .fold(1.0f64, |m, x| m.max(x.abs()));
                let gap = 1e-5 * size;
                rectangle(&mut out, add(*q, scale(n, gap)), *u, *v, &inner);
                rectangle(&mut out, add(*q, scale(n, -gap)), *v, *u, &inner);
            }
            ObjectEntry::Quad { q, u, v, .. } => rectangle(&mut out, *q, *u, *v, &inner),
            ObjectEntry::Triangle { .. } => return refuse("it has a triangle"),
        }
    }
    out.push_str("</scene>\n");
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn physical(d: &mut SceneDescription) {
        d.profile = Profile::Physical;
        d.render.background = Background::Flat;
    }

    /// A rectangle's matrix takes the corners of `[-1, 1]^2` to `Q`, `Q + u`, `Q + v` and
    /// `Q + u + v` (by hand: the columns are `u / 2`, `v / 2`, the unit normal and the centre).
    #[test]
    fn a_rectangle_s_corners_are_the_quad_s() {
        let mut out = String::new();
        let (q, u, v) = ([1.0, 2.0, 3.0], [2.0, 0.0, 0.0], [0.0, 0.0, -4.0]);
        rectangle(&mut out, q, u, v, "");
        let values: Vec<f64> = out
            .split("value=\"")
            .nth(1)
            .unwrap()
            .split('"')
            .next()
            .unwrap()
            .split(' ')
            .map(|x| x.parse().unwrap())
            .collect();
        let apply = |a: f64, b: f64| {
            [0, 1, 2].map(|r| values[4 * r] * a + values[4 * r + 1] * b + values[4 * r + 3])
        };
        assert_eq!(apply(-1.0, -1.0), q);
        assert_eq!(apply(1.0, -1.0), add(q, u));
        assert_eq!(apply(-1.0, 1.0), add(q, v));
        assert_eq!(apply(1.0, 1.0), add(q, add(u, v)));
        // The normal column is unit(u x v) = (0, 1, 0).
        assert_eq!([values[2], values[6], values[10]], [0.0, 1.0, 0.0]);
    }

    /// What Mitsuba does not share is refused in words: the course profile, the sky, a
    /// dielectric, a rough metal, a triangle.
    #[test]
    fn what_is_not_shared_is_refused() {
        let course = crate::scene::builtin("week05-quad").unwrap();
        assert!(
            to_mitsuba_xml(&course)
                .unwrap_err()
                .0
                .contains("course-profile")
        );
        let mut sky = crate::scene::builtin("rtiow-materials").unwrap();
        assert!(to_mitsuba_xml(&sky).unwrap_err().0.contains("sky"));
        sky.render.background = Background::Flat;
        let e = to_mitsuba_xml(&sky).unwrap_err().0;
        assert!(e.contains("dielectric") || e.contains("rough metal"), "{e}");
        let mut tri = crate::scene::builtin("triangles").unwrap();
        physical(&mut tri);
        let e = to_mitsuba_xml(&tri).unwrap_err().0;
        assert!(e.contains("triangle") || e.contains("material"), "{e}");
    }

    /// The quads of week 5 in the physical profile are written whole: a sensor of the scene's
    /// size, the flat background, one rectangle per quad (two for the light), and a name that
    /// needs escaping stays text.
    #[test]
    fn week5_s_lit_quads_are_written() {
        let mut d = crate::scene::builtin("week05-quad-light").unwrap();
        physical(&mut d);
        let old = d.materials[0].name.clone();
        d.materials[0].name = "a\"b<c".into();
        for o in &mut d.objects {
            if let ObjectEntry::Quad { material, .. } = o
                && *material == old
            {
                *material = "a\"b<c".into();
            }
        }
        let xml = to_mitsuba_xml(&d).unwrap();
        let quads = d.objects.len();
        let lights = d
            .objects
            .iter()
            .filter(|o| {
                d.materials
                    .iter()
                    .any(|m| m.name == o.material() && m.kind == MaterialKind::DiffuseLight)
            })
            .count();
        assert_eq!(xml.matches("type=\"rectangle\"").count(), quads + lights);
        assert!(xml.contains("<integer name=\"width\" value=\"400\"/>"));
        assert!(xml.contains("type=\"constant\""));
        assert!(xml.contains("a&quot;b&lt;c"), "{xml}");
        assert!(!xml.contains("a\"b<c"));
    }
}
