//! *Ray Tracing in One Weekend*'s material scenes (book 1, 4th edition), for the `physical`
//! profile: a ground, a Lambertian centre, a hollow glass sphere on the left (glass of index 1.5
//! around a bubble of index `1/1.5`), a fuzzy metal on the right; 400x225, 100 samples, depth 50.

use super::parts::{camera, dielectric, lambertian, metal, sphere};
use crate::scene::{ImageSettings, Profile, RenderSettings, SceneDescription};

/// The book's hollow-glass scene seen by the book's default camera (from the origin along -z,
/// vfov 90, focus distance 10).
pub(super) fn rtiow_materials() -> SceneDescription {
    let mut d = SceneDescription::new(
        ImageSettings {
            width: 400,
            aspect_ratio: 16.0 / 9.0,
            samples_per_pixel: 100,
        },
        camera([0.0, 0.0, 0.0], [0.0, 0.0, -1.0], 90.0, 10.0),
        vec![
            lambertian("ground", [0.8, 0.8, 0.0]),
            lambertian("center", [0.1, 0.2, 0.5]),
            dielectric("left", [1.0, 1.0, 1.0], 1.5),
            dielectric("bubble", [1.0, 1.0, 1.0], 1.0 / 1.5),
            metal("right", [0.8, 0.6, 0.2], 1.0),
        ],
        vec![
            sphere([0.0, -100.5, -1.0], 100.0, "ground"),
            sphere([0.0, 0.0, -1.2], 0.5, "center"),
            sphere([-1.0, 0.0, -1.0], 0.5, "left"),
            sphere([-1.0, 0.0, -1.0], 0.4, "bubble"),
            sphere([1.0, 0.0, -1.0], 0.5, "right"),
        ],
    );
    d.profile = Profile::Physical;
    d.render = RenderSettings {
        max_depth: 50,
        ..RenderSettings::default()
    };
    d
}

/// The same scene from `(-2, 2, 1)` towards `(0, 0, -1)`, vfov 20, with a defocus angle of 10
/// degrees focused at 3.4 (the book's defocus-blur chapter).
pub(super) fn rtiow_defocus() -> SceneDescription {
    let mut d = rtiow_materials();
    d.camera = camera([-2.0, 2.0, 1.0], [0.0, 0.0, -1.0], 20.0, 3.4);
    d.camera.defocus_angle = 10.0;
    d
}

/// The recipe of the book's final scene (book 1, chapter 14): a grey ground sphere of radius
/// 1000, a 22 x 22 grid of small spheres (radius 0.2, each jittered in its cell, left out within
/// 0.9 of `(4, 0.2, 0)`) that are diffuse (80%, albedo the product of two random colours), metal
/// (15%, albedo in `[0.5, 1)`, fuzz in `[0, 0.5)`) or glass (5%, index 1.5), and three big
/// spheres (glass, diffuse `(0.4, 0.2, 0.1)`, metal `(0.7, 0.6, 0.5)` of fuzz 0); 1200x675, 500
/// samples, depth 50, from `(13, 2, 3)` towards the origin, vfov 20, defocus 0.6 degrees at
/// focus 10; the `physical` profile.
///
/// The random numbers come from a SplitMix64 stream of `seed` (the top 53 bits of each output
/// over `2^53`), drawn in the book's order, not from the book's `rand()`: the scene has the
/// book's distribution, not its very spheres. It has about 490 objects, each with its own
/// material, so it renders through the hierarchy.
pub fn rtiow_final_scene(seed: u64) -> SceneDescription {
    let mut random = SplitMix(seed);
    let mut d = rtiow_materials();
    d.image = ImageSettings {
        width: 1200,
        aspect_ratio: 16.0 / 9.0,
        samples_per_pixel: 500,
    };
    d.camera = camera([13.0, 2.0, 3.0], [0.0, 0.0, 0.0], 20.0, 10.0);
    d.camera.defocus_angle = 0.6;
    d.materials = vec![lambertian("ground", [0.5, 0.5, 0.5])];
    d.objects = vec![sphere([0.0, -1000.0, 0.0], 1000.0, "ground")];
    for a in -11..11 {
        for b in -11..11 {
            let choose = random.next_f64();
            let centre = [
                a as f64 + 0.9 * random.next_f64(),
                0.2,
                b as f64 + 0.9 * random.next_f64(),
            ];
            let offset = [centre[0] - 4.0, 0.0, centre[2]];
            if (offset[0] * offset[0] + offset[2] * offset[2]).sqrt() <= 0.9 {
                continue;
            }
            let name = format!("s{}", d.objects.len());
            let material = if choose < 0.8 {
                let mut colour = || [random.next_f64(), random.next_f64(), random.next_f64()];
                let (p, q) = (colour(), colour());
                lambertian(&name, [p[0] * q[0], p[1] * q[1], p[2] * q[2]])
            } else if choose < 0.95 {
                let albedo = [
                    random.uniform(0.5, 1.0),
                    random.uniform(0.5, 1.0),
                    random.uniform(0.5, 1.0),
                ];
                metal(&name, albedo, random.uniform(0.0, 0.5))
            } else {
                dielectric(&name, [1.0, 1.0, 1.0], 1.5)
            };
            d.materials.push(material);
            d.objects.push(sphere(centre, 0.2, &name));
        }
    }
    d.materials.push(dielectric("glass", [1.0, 1.0, 1.0], 1.5));
    d.materials.push(lambertian("diffuse", [0.4, 0.2, 0.1]));
    d.materials.push(metal("metal", [0.7, 0.6, 0.5], 0.0));
    d.objects.push(sphere([0.0, 1.0, 0.0], 1.0, "glass"));
    d.objects.push(sphere([-4.0, 1.0, 0.0], 1.0, "diffuse"));
    d.objects.push(sphere([4.0, 1.0, 0.0], 1.0, "metal"));
    d
}

/// SplitMix64, for the final scene's recipe.
struct SplitMix(u64);

impl SplitMix {
    fn next_f64(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        (z >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next_f64()
    }
}
