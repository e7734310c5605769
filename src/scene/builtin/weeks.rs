//! The course's fixed scenes of weeks 5 to 10, one per render function of its `main.py`, with
//! the cameras, sizes, sample counts, depths, materials and render calls of the instructor's
//! solution of each week (its objects in `main.py`'s order).
//!
//! Where the course's code does not settle a value, the choice is named in the scene's
//! function: week 5's `renderPointLightShadow` (from a deleted solution) takes
//! `renderPointLight`'s sample count and depth; week 7's pictures are the ones rtoracle
//! generates (the grader hands them to the submission's `main.py` in place of the course's
//! files, so both sides read the same texels); weeks 9 and 10 keep week 8's checker ground, and
//! week 9 its field of view and depth. Week 9's `renderBlinn` renders with `render()` (uniform
//! jitter), weeks 10's with `render_jittered()`.

use super::parts::{
    TextureSource, brdf, camera, checker, dielectric, lambertian, light, mirror, moving_sphere,
    picture, quad, solid, sphere, textured,
};
use super::week04::week04_quad;
use crate::scene::{
    Background, DiffuseSampling, ImageSettings, Integrator, MaterialKind, ObjectEntry,
    PixelSampling, RenderSettings, SceneDescription, SceneError,
};

/// The course's `render` settings of weeks 5 to 7: the direct-term integrator, the week's
/// depth and background.
fn direct(max_depth: u32, background: Background) -> RenderSettings {
    RenderSettings {
        integrator: Integrator::Direct,
        max_depth,
        background,
        ..RenderSettings::default()
    }
}

fn image(width: usize, aspect_ratio: f64, samples_per_pixel: u32) -> ImageSettings {
    ImageSettings {
        width,
        aspect_ratio,
        samples_per_pixel,
    }
}

/// Week 5's camera: from `(0, 0, 10)` at the origin, vfov 90, with the scene's focus distance
/// (which, with a pinhole, does not change the image).
fn week05(spp: u32, max_depth: u32, focus: f64) -> SceneDescription {
    let mut d = week04_quad();
    d.image = image(400, 1.0, spp);
    d.camera = camera([0.0, 0.0, 10.0], [0.0, 0.0, 0.0], 90.0, focus);
    d.render = direct(max_depth, Background::Flat);
    d
}

/// `renderQuad`: the week-4 quads under the week-5 integrator (spp 20, depth 3), no light: the
/// flat `0.01` background is all that lights them.
pub(super) fn week05_quad() -> SceneDescription {
    week05(20, 3, 10.0)
}

/// `renderQuadLight`: the right quad is `Diffuse_light(1, 1, 1)` (spp 10, depth 8, focus 3).
pub(super) fn week05_quad_light() -> SceneDescription {
    let mut d = week05(10, 8, 3.0);
    d.materials.push(light("light", [1.0, 1.0, 1.0]));
    if let Some(ObjectEntry::Quad { material, .. }) = d.objects.get_mut(2) {
        *material = "light".into();
    }
    d
}

/// The quads and a point light: `Sphere(at, 0.1, Diffuse_light(1, 1, 1))` (spp 10, depth 4,
/// focus 3).
fn week05_with_light(at: [f64; 3]) -> SceneDescription {
    let mut d = week05(10, 4, 3.0);
    d.materials.push(light("light", [1.0, 1.0, 1.0]));
    d.objects.push(sphere(at, 0.1, "light"));
    d
}

/// `renderPointLight`: the light at the origin (in the back quad's plane).
pub(super) fn week05_point_light() -> SceneDescription {
    week05_with_light([0.0, 0.0, 0.0])
}

/// `renderPointLightShadow` (week 5's deleted solution): the light at `(4, 0, 0)`, behind the
/// right quad; its sample count and depth taken from `renderPointLight`.
pub(super) fn week05_point_light_shadow() -> SceneDescription {
    week05_with_light([4.0, 0.0, 0.0])
}

/// Week 6's scene: the ground and centre spheres, a left pair (radius 0.5 and the hollow -0.4)
/// and a right sphere of the given materials; 400x225, spp 20, depth 7, focus 10, the sky.
fn week06(
    left: &str,
    right: &str,
    look_from: [f64; 3],
    look_at: [f64; 3],
    vfov: f64,
) -> SceneDescription {
    let mut d = SceneDescription::new(
        image(400, 16.0 / 9.0, 20),
        camera(look_from, look_at, vfov, 10.0),
        vec![
            lambertian("ground", [0.8, 0.8, 0.0]),
            lambertian("center", [0.7, 0.3, 0.3]),
            mirror("mirror", [0.8, 0.8, 0.8]),
            dielectric("glass", [1.0, 1.0, 1.0], 1.5),
        ],
        vec![
            sphere([0.0, -100.5, -1.0], 100.0, "ground"),
            sphere([0.0, 0.0, -1.0], 0.5, "center"),
            sphere([-1.0, 0.0, -1.0], 0.5, left),
            sphere([-1.0, 0.0, -1.0], -0.4, left),
            sphere([1.0, 0.0, -1.0], 0.5, right),
        ],
    );
    d.render = direct(7, Background::Sky);
    d
}

/// `renderMirrorPointLight`: mirrors left and right, from `(0, 0, 10)` at the origin, vfov 30, a
/// point light `Sphere((0, 2.5, 0), 0.1, E = 1)`.
pub(super) fn week06_mirror_point_light() -> SceneDescription {
    let mut d = week06("mirror", "mirror", [0.0, 0.0, 10.0], [0.0, 0.0, 0.0], 30.0);
    d.materials.retain(|m| m.name != "glass");
    d.materials.push(light("light", [1.0, 1.0, 1.0]));
    d.objects.push(sphere([0.0, 2.5, 0.0], 0.1, "light"));
    d
}

/// `renderMirrors`: mirrors left and right, from `(-2, 2, 1)` at `(0, 0, -1)`, vfov 50, no light.
pub(super) fn week06_mirrors() -> SceneDescription {
    let mut d = week06("mirror", "mirror", [-2.0, 2.0, 1.0], [0.0, 0.0, -1.0], 50.0);
    d.materials.retain(|m| m.name != "glass");
    d
}

/// `renderDielectric`: the right sphere is `Dielectric((1, 1, 1), 1.5)`.
pub(super) fn week06_dielectric() -> SceneDescription {
    week06("mirror", "glass", [-2.0, 2.0, 1.0], [0.0, 0.0, -1.0], 50.0)
}

/// Week 7's scenes: the ground, centre, left and right spheres of the given materials (in
/// `main.py`'s order), 400x225, spp 20, depth 5, vfov 60, from `(-2, 2, 1)` at `(0, 0, -1)`,
/// focus 10, the flat background (the skeleton's; its README says sky).
fn week07(
    textures: Vec<crate::scene::TextureEntry>,
    materials: Vec<crate::scene::MaterialEntry>,
    spheres: [&str; 4],
) -> SceneDescription {
    let mut d = SceneDescription::new(
        image(400, 16.0 / 9.0, 20),
        camera([-2.0, 2.0, 1.0], [0.0, 0.0, -1.0], 60.0, 10.0),
        materials,
        vec![
            sphere([0.0, -100.5, -1.0], 100.0, spheres[0]),
            sphere([0.0, 0.0, -1.0], 0.5, spheres[1]),
            sphere([-1.0, 0.0, -1.0], 0.5, spheres[2]),
            sphere([1.0, 0.0, -1.0], 0.5, spheres[3]),
        ],
    );
    d.textures = textures;
    d.render = direct(5, Background::Flat);
    d
}

/// The solution's black-and-white checker, `CheckerTexture(0.32, (.2, .2, .2), (.9, .9, .9))`.
fn checker_bw() -> crate::scene::TextureEntry {
    checker("checker_bw", 0.32, [0.2; 3], [0.9; 3])
}

/// `renderProceduralTexture` (the solution's `main.py`): the black-and-white checker on the
/// ground, `Lambertian(.7, .3, .3)` in the centre, `CheckerTexture(0.12, (.2, .3, .1), (.9, .9,
/// .9))` on the left, `SolidColor(.8, .2, .5)` on the right.
pub(super) fn week07_procedural_texture() -> SceneDescription {
    week07(
        vec![
            checker_bw(),
            checker("checker", 0.12, [0.2, 0.3, 0.1], [0.9; 3]),
            solid("solid", [0.8, 0.2, 0.5]),
        ],
        vec![
            textured("checker_bw", "checker_bw"),
            lambertian("center", [0.7, 0.3, 0.3]),
            textured("checker", "checker"),
            textured("solid", "solid"),
        ],
        ["checker_bw", "center", "checker", "solid"],
    )
}

/// `renderEarth` (the solution's `main.py`): the earth picture on the ground, the
/// black-and-white checker in the centre, the basketball on the left, the soccer ball on the
/// right, and `Quad((1, 0, -1), (1, 2, -1), (1, 0, 1))` with the pepsi picture.
pub(super) fn week07_earth(source: &TextureSource) -> Result<SceneDescription, SceneError> {
    let name = "week07-earth";
    let mut d = week07(
        vec![
            checker_bw(),
            picture(name, "earth", "earth", source)?,
            picture(name, "basketball", "basketball", source)?,
            picture(name, "soccer", "soccer", source)?,
            picture(name, "pepsi", "pepsi", source)?,
        ],
        vec![
            textured("earth", "earth"),
            textured("checker_bw", "checker_bw"),
            textured("basketball", "basketball"),
            textured("soccer", "soccer"),
            textured("pepsi", "pepsi"),
        ],
        ["earth", "checker_bw", "basketball", "soccer"],
    );
    d.objects.push(quad(
        [1.0, 0.0, -1.0],
        [1.0, 2.0, -1.0],
        [1.0, 0.0, 1.0],
        "pepsi",
    ));
    Ok(d)
}

/// Weeks 8 to 10's scene: the checker ground and three spheres at `x = -1, 0, 1` of the given
/// BRDF materials, 320x180, from `(-2, 2, 1)` at `(0, 0, -1)`, vfov 60, depth 5.
fn brdf_scene(
    spp: u32,
    focus: f64,
    spheres: [(MaterialKind, [f64; 3], f64, f64, f64); 3],
    render: RenderSettings,
) -> SceneDescription {
    let mut materials = vec![textured("ground", "ground")];
    for (k, (kind, albedo, kd, ks, alpha)) in spheres.into_iter().enumerate() {
        materials.push(brdf(
            ["left", "center", "right"][k],
            kind,
            albedo,
            kd,
            ks,
            alpha,
        ));
    }
    let mut d = SceneDescription::new(
        image(320, 16.0 / 9.0, spp),
        camera([-2.0, 2.0, 1.0], [0.0, 0.0, -1.0], 60.0, focus),
        materials,
        vec![
            sphere([0.0, -100.5, -1.0], 100.0, "ground"),
            sphere([-1.0, 0.0, -1.0], 0.5, "left"),
            sphere([0.0, 0.0, -1.0], 0.5, "center"),
            sphere([1.0, 0.0, -1.0], 0.5, "right"),
        ],
    );
    d.textures = vec![checker("ground", 0.32, [0.2; 3], [0.9; 3])];
    d.render = RenderSettings {
        integrator: Integrator::Brdf,
        max_depth: 5,
        ..render
    };
    d
}

/// Week 8's scenes: `kind(Color(.7, .2, .4), 0.6, 0.9, alpha)` for the three alphas, a point
/// light `Sphere((0, 1, 0), 0.05, E = 0.9)`, the flat background; spp 30, focus 10.
fn week08(kind: MaterialKind, alphas: [f64; 3]) -> SceneDescription {
    let colour = [0.7, 0.2, 0.4];
    let mut d = brdf_scene(
        30,
        10.0,
        alphas.map(|alpha| (kind, colour, 0.6, 0.9, alpha)),
        RenderSettings {
            background: Background::Flat,
            ..RenderSettings::default()
        },
    );
    d.materials.push(light("light", [0.9, 0.9, 0.9]));
    d.objects.push(sphere([0.0, 1.0, 0.0], 0.05, "light"));
    d
}

/// `renderPhong`: alphas 0.8, 8 and 30.
pub(super) fn week08_phong() -> SceneDescription {
    week08(MaterialKind::Phong, [0.8, 8.0, 30.0])
}

/// `renderBlinn`: alphas 0.08, 8 and 300.
pub(super) fn week08_blinn() -> SceneDescription {
    week08(MaterialKind::Blinn, [0.08, 8.0, 300.0])
}

/// Weeks 9 and 10's Blinn spheres: `((.8, .5, .8), .5, ks0, alpha0)`, `((.4, .5, .4), .5, ks1,
/// alpha1)`, `((.8, .5, .4), .5, ks2, alpha2)`.
fn week09_spheres(ks: [f64; 3], alphas: [f64; 3]) -> [(MaterialKind, [f64; 3], f64, f64, f64); 3] {
    let colours = [[0.8, 0.5, 0.8], [0.4, 0.5, 0.4], [0.8, 0.5, 0.4]];
    std::array::from_fn(|k| (MaterialKind::Blinn, colours[k], 0.5, ks[k], alphas[k]))
}

/// `renderBlinn` of week 9: cosine-sampled diffuse scattering, the sky, no light, spp 30, focus
/// 5, rendered as its `main.py` does, with `renderer.render()`: uniform jitter in the pixel
/// (`get_ray`'s `random_pixel_in_square`), not `render_jittered` (its output is
/// `week09_nojittered.png`; the jittered rays are checked by their function check).
pub(super) fn week09_blinn() -> SceneDescription {
    brdf_scene(
        30,
        5.0,
        week09_spheres([0.2, 0.6, 0.2], [0.08, 8.0, 300.0]),
        RenderSettings {
            diffuse_sampling: DiffuseSampling::Cosine,
            ..RenderSettings::default()
        },
    )
}

/// Week 10's scenes: Blinn alpha 8 with ks 0.2, 0.6, 0.2, cosine sampling, the sky, focus 5,
/// `render_jittered` with week 10's frozen step `1 / sqrt(10)`.
fn week10(spp: u32) -> SceneDescription {
    brdf_scene(
        spp,
        5.0,
        week09_spheres([0.2, 0.6, 0.2], [8.0, 8.0, 8.0]),
        RenderSettings {
            diffuse_sampling: DiffuseSampling::Cosine,
            sampling: PixelSampling::CourseJittered,
            jitter_step: Some(1.0 / 10f64.sqrt()),
            ..RenderSettings::default()
        },
    )
}

/// `renderDoF`: spp 100, a defocus angle of 2 degrees.
pub(super) fn week10_dof() -> SceneDescription {
    let mut d = week10(100);
    d.camera.defocus_angle = 2.0;
    d
}

/// `renderMoving`: spp 200, the left sphere moves up by 0.5 between times 0 and 1.
pub(super) fn week10_moving() -> SceneDescription {
    let mut d = week10(200);
    d.objects[1] = moving_sphere([-1.0, 0.0, -1.0], [-1.0, 0.5, -1.0], 0.5, "left");
    d
}
