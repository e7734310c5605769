//! The checks a scene passes before any work starts ([`SceneDescription::validate`]): every
//! number finite, every value usable, every name defined, every key meaningful for its kind,
//! every texture file readable. Each failure is one line naming the scene and the key.

use std::collections::HashSet;

use glam::DVec3;

use crate::scene::error::invalid;
use crate::scene::texture::{GENERATED_PICTURES, read_picture};
use crate::scene::{
    MaterialEntry, MaterialKind, ObjectEntry, PixelSampling, Profile, SceneDescription, SceneError,
    TextureEntry, TextureKind,
};

/// The largest width or height a scene may have, in pixels.
pub const MAX_SIDE: usize = 100_000;

/// The largest `max_depth` a scene may ask for.
pub const MAX_DEPTH_LIMIT: u32 = 10_000;

fn check_num(path: &str, field: &str, x: f64) -> Result<(), SceneError> {
    if x.is_finite() {
        Ok(())
    } else {
        Err(invalid(
            path,
            format!("{field} is {x}, but every number in a scene must be finite"),
        ))
    }
}

fn check_vec(path: &str, field: &str, v: [f64; 3]) -> Result<(), SceneError> {
    for (axis, x) in ["x", "y", "z"].iter().zip(v) {
        check_num(path, &format!("{field}.{axis}"), x)?;
    }
    Ok(())
}

/// `x` finite and at least 0 (or, with `positive`, above 0).
fn check_non_negative(path: &str, field: &str, x: f64, positive: bool) -> Result<(), SceneError> {
    check_num(path, field, x)?;
    if x < 0.0 || (positive && x == 0.0) {
        let want = if positive { "positive" } else { "at least 0" };
        return Err(invalid(
            path,
            format!("{field} is {x:?}, it must be {want}"),
        ));
    }
    Ok(())
}

impl SceneDescription {
    /// Checks every number is finite, every value usable, every name defined and every texture
    /// file readable (relative files are looked for in [`SceneDescription::base_dir`]); `name`
    /// labels errors.
    pub fn validate(&self, name: &str) -> Result<(), SceneError> {
        self.validate_image(name)?;
        self.validate_camera(name)?;
        self.validate_render(name)?;
        self.validate_textures(name)?;
        self.validate_materials(name)?;
        self.validate_objects(name)
    }

    /// The `[image]` table's checks.
    fn validate_image(&self, name: &str) -> Result<(), SceneError> {
        let image = &self.image;
        if image.width == 0 {
            return Err(invalid(name, "image.width must be at least 1".into()));
        }
        check_num(name, "image.aspect_ratio", image.aspect_ratio)?;
        if image.aspect_ratio <= 0.0 {
            return Err(invalid(
                name,
                format!(
                    "image.aspect_ratio is {:?}, it must be positive",
                    image.aspect_ratio
                ),
            ));
        }
        if image.width > MAX_SIDE {
            return Err(invalid(
                name,
                format!("image.width is {}, at most {MAX_SIDE} pixels", image.width),
            ));
        }
        if image.width as f64 / image.aspect_ratio >= (MAX_SIDE + 1) as f64 {
            return Err(invalid(
                name,
                format!(
                    "image.aspect_ratio is {:?}: a {}-pixel-wide image would be more than \
                     {MAX_SIDE} pixels high",
                    image.aspect_ratio, image.width
                ),
            ));
        }
        if image.samples_per_pixel == 0 {
            return Err(invalid(
                name,
                "image.samples_per_pixel must be at least 1".into(),
            ));
        }
        Ok(())
    }

    /// The `[camera]` table's checks.
    fn validate_camera(&self, name: &str) -> Result<(), SceneError> {
        let cam = &self.camera;
        check_vec(name, "camera.look_from", cam.look_from)?;
        check_vec(name, "camera.look_at", cam.look_at)?;
        check_vec(name, "camera.up", cam.up)?;
        check_num(name, "camera.vfov", cam.vfov)?;
        check_num(name, "camera.focus_distance", cam.focus_distance)?;
        check_num(name, "camera.defocus_angle", cam.defocus_angle)?;
        if !(cam.vfov > 0.0 && cam.vfov < 180.0) {
            return Err(invalid(
                name,
                format!(
                    "camera.vfov is {:?}, it must lie strictly between 0 and 180 degrees",
                    cam.vfov
                ),
            ));
        }
        if cam.focus_distance <= 0.0 {
            return Err(invalid(
                name,
                format!(
                    "camera.focus_distance is {:?}, it must be positive",
                    cam.focus_distance
                ),
            ));
        }
        if !(0.0..180.0).contains(&cam.defocus_angle) {
            return Err(invalid(
                name,
                format!(
                    "camera.defocus_angle is {:?}, it must lie in [0, 180)",
                    cam.defocus_angle
                ),
            ));
        }
        let view = DVec3::from(cam.look_from) - DVec3::from(cam.look_at);
        if view == DVec3::ZERO {
            return Err(invalid(
                name,
                "camera.look_from equals camera.look_at".into(),
            ));
        }
        if DVec3::from(cam.up).cross(view) == DVec3::ZERO {
            return Err(invalid(
                name,
                "camera.up is zero or parallel to the viewing direction".into(),
            ));
        }
        Ok(())
    }

    /// The `[render]` table's checks.
    fn validate_render(&self, name: &str) -> Result<(), SceneError> {
        let render = &self.render;
        if !(1..=MAX_DEPTH_LIMIT).contains(&render.max_depth) {
            return Err(invalid(
                name,
                format!(
                    "render.max_depth is {}, it must lie in [1, {MAX_DEPTH_LIMIT}]",
                    render.max_depth
                ),
            ));
        }
        check_vec(name, "render.background_color", render.background_color)?;
        match (render.sampling, render.jitter_step) {
            (PixelSampling::CourseJittered, None) => Err(invalid(
                name,
                "render.sampling is \"course-jittered\", which needs render.jitter_step (the \
                 course's frozen one_over_sqrt_spp)"
                    .into(),
            )),
            (PixelSampling::CourseJittered, Some(step)) => {
                check_non_negative(name, "render.jitter_step", step, true)
            }
            (PixelSampling::Uniform, Some(_)) => Err(invalid(
                name,
                "render.jitter_step applies only to render.sampling = \"course-jittered\"".into(),
            )),
            (PixelSampling::Uniform, None) => Ok(()),
        }
    }

    /// The `[[textures]]` checks, reading every image file.
    fn validate_textures(&self, name: &str) -> Result<(), SceneError> {
        let mut seen = HashSet::new();
        for (i, t) in self.textures.iter().enumerate() {
            if !seen.insert(t.name.as_str()) {
                return Err(invalid(
                    name,
                    format!("textures[{i}]: the name '{}' is used twice", t.name),
                ));
            }
            self.validate_texture(name, i, t)?;
        }
        Ok(())
    }

    /// One texture's keys: those of its kind and no other.
    fn validate_texture(&self, name: &str, i: usize, t: &TextureEntry) -> Result<(), SceneError> {
        let key = |k: &str| format!("textures[{i}].{k}");
        let given = [
            ("color", t.color.is_some()),
            ("scale", t.scale.is_some()),
            ("even", t.even.is_some()),
            ("odd", t.odd.is_some()),
            ("file", t.file.is_some()),
            ("generated", t.generated.is_some()),
        ];
        let (kind, wanted): (&str, &[&str]) = match t.kind {
            TextureKind::Solid => ("solid", &["color"]),
            TextureKind::Checker => ("checker", &["scale", "even", "odd"]),
            TextureKind::Image => ("image", &["file", "generated"]),
        };
        for (k, set) in given {
            if set && !wanted.contains(&k) {
                return Err(invalid(
                    name,
                    format!("{} does not apply to a {kind} texture", key(k)),
                ));
            }
        }
        match t.kind {
            TextureKind::Solid => match t.color {
                Some(c) => check_vec(name, &key("color"), c),
                None => Err(invalid(name, format!("{} is missing", key("color")))),
            },
            TextureKind::Checker => {
                let (Some(scale), Some(even), Some(odd)) = (t.scale, t.even, t.odd) else {
                    let missing = ["scale", "even", "odd"]
                        .into_iter()
                        .zip([t.scale.is_none(), t.even.is_none(), t.odd.is_none()])
                        .find_map(|(k, m)| m.then_some(k))
                        .unwrap_or("scale");
                    return Err(invalid(name, format!("{} is missing", key(missing))));
                };
                check_non_negative(name, &key("scale"), scale, true)?;
                check_vec(name, &key("even"), even)?;
                check_vec(name, &key("odd"), odd)
            }
            TextureKind::Image => match (&t.file, &t.generated) {
                (Some(_), Some(_)) | (None, None) => Err(invalid(
                    name,
                    format!(
                        "textures[{i}]: an image texture takes exactly one of file and generated"
                    ),
                )),
                (None, Some(g)) if !GENERATED_PICTURES.contains(&g.as_str()) => Err(invalid(
                    name,
                    format!(
                        "{} is '{g}', not one of the generated pictures ({})",
                        key("generated"),
                        GENERATED_PICTURES.join(", ")
                    ),
                )),
                (None, Some(_)) => Ok(()),
                (Some(file), None) => {
                    let path = self.resolve(file);
                    read_picture(&path).map(|_| ()).map_err(|reason| {
                        invalid(
                            name,
                            format!("{} = '{}': {reason}", key("file"), path.display()),
                        )
                    })
                }
            },
        }
    }

    /// The `[[materials]]` checks.
    fn validate_materials(&self, name: &str) -> Result<(), SceneError> {
        for (i, m) in self.materials.iter().enumerate() {
            check_vec(name, &format!("materials[{i}].albedo"), m.albedo)?;
            if self.materials[..i].iter().any(|other| other.name == m.name) {
                return Err(invalid(
                    name,
                    format!("materials[{i}]: the name '{}' is used twice", m.name),
                ));
            }
            self.validate_material(name, i, m)?;
        }
        Ok(())
    }

    /// One material's keys: those of its kind, each in range, and none of another kind's.
    fn validate_material(&self, name: &str, i: usize, m: &MaterialEntry) -> Result<(), SceneError> {
        let key = |k: &str| format!("materials[{i}].{k}");
        let keys = m.kind.keys();
        for k in m.keys_set() {
            if !keys.iter().any(|(wanted, _)| *wanted == k) {
                return Err(invalid(
                    name,
                    format!("{} does not apply to a {} material", key(k), m.kind.name()),
                ));
            }
        }
        for (k, required) in keys {
            if *required && !m.keys_set().contains(k) {
                return Err(invalid(
                    name,
                    format!(
                        "{} is missing (a {} material needs it)",
                        key(k),
                        m.kind.name()
                    ),
                ));
            }
        }
        let positive = [
            ("ior", m.ior, true),
            ("alpha", m.alpha, m.kind == MaterialKind::CookTorrance),
        ];
        for (k, value, strict) in positive {
            if let Some(x) = value {
                check_non_negative(name, &key(k), x, strict)?;
            }
        }
        for (k, value) in [("roughness", m.roughness), ("kd", m.kd), ("ks", m.ks)] {
            if let Some(x) = value {
                check_non_negative(name, &key(k), x, false)?;
            }
        }
        if let Some(texture) = &m.texture {
            if !self.textures.iter().any(|t| &t.name == texture) {
                return Err(invalid(
                    name,
                    format!(
                        "{} names the texture '{texture}', which is not defined",
                        key("texture")
                    ),
                ));
            }
        }
        if self.profile == Profile::Physical
            && matches!(
                m.kind,
                MaterialKind::Phong | MaterialKind::Blinn | MaterialKind::CookTorrance
            )
        {
            return Err(invalid(
                name,
                format!(
                    "materials[{i}].type is {}, one of the course's BRDF models, which the \
                     physical profile does not have (render it with the course profile)",
                    m.kind.name()
                ),
            ));
        }
        Ok(())
    }

    /// The `[[objects]]` checks.
    fn validate_objects(&self, name: &str) -> Result<(), SceneError> {
        for (i, o) in self.objects.iter().enumerate() {
            let field = |f: &str| format!("objects[{i}].{f}");
            match o {
                ObjectEntry::Sphere {
                    center,
                    radius,
                    moving_center,
                    ..
                } => {
                    check_vec(name, &field("center"), *center)?;
                    check_num(name, &field("radius"), *radius)?;
                    if *radius == 0.0 {
                        return Err(invalid(
                            name,
                            format!("{} is 0: a sphere needs a non-zero radius", field("radius")),
                        ));
                    }
                    if let Some(end) = moving_center {
                        check_vec(name, &field("moving_center"), *end)?;
                    }
                }
                ObjectEntry::Quad { q, u, v, .. } => {
                    check_vec(name, &field("q"), *q)?;
                    check_vec(name, &field("u"), *u)?;
                    check_vec(name, &field("v"), *v)?;
                    if DVec3::from(*u).cross(DVec3::from(*v)) == DVec3::ZERO {
                        return Err(invalid(
                            name,
                            format!("objects[{i}]: u and v are parallel, the quad is degenerate"),
                        ));
                    }
                }
                ObjectEntry::Triangle { a, b, c, .. } => {
                    check_vec(name, &field("a"), *a)?;
                    check_vec(name, &field("b"), *b)?;
                    check_vec(name, &field("c"), *c)?;
                    let (a, b, c) = (DVec3::from(*a), DVec3::from(*b), DVec3::from(*c));
                    if (b - a).cross(c - a) == DVec3::ZERO {
                        return Err(invalid(
                            name,
                            format!(
                                "objects[{i}]: the vertices are collinear, the triangle is degenerate"
                            ),
                        ));
                    }
                }
            }
            if !self.materials.iter().any(|m| m.name == o.material()) {
                return Err(invalid(
                    name,
                    format!(
                        "{} names the material '{}', which is not defined",
                        field("material"),
                        o.material()
                    ),
                ));
            }
        }
        Ok(())
    }
}
