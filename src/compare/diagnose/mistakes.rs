//! A catalogue of common mistakes, injected into the reference renderer: the images the
//! comparison must reject (and the diagnosis must name). Used by tests and the benchmark.

use glam::DVec3;
use rayon::prelude::*;

use crate::geometry::{Interval, unit_vector};
use crate::image_io::Rgb8Image;
use crate::render::{PixelSampler, encode_course_png, radiance};
use crate::scene::SceneDescription;

/// One mistake a student's ray tracer commonly makes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Mistake {
    /// None: the reference itself (uniform jitter, course encoding).
    Honest,
    /// Linear values written as codes: `floor(255 * clamp(x, 0, 0.999))`.
    NoGamma,
    /// Gamma 2.2 where the course asks for 2: `floor(255 * clamp(x^(1/2.2), 0, 0.999))`.
    Gamma22,
    /// The course's gamma applied twice: `floor(255 * clamp(sqrt(sqrt(x)), 0, 0.999))`.
    GammaTwice,
    /// Every albedo times 0.97.
    AlbedoScaled,
    /// The camera's `pixel00` without its half-pixel offset: every sample half a pixel left and up.
    HalfPixelShift,
    /// Jitter in `[0, 1)` instead of `[-0.5, 0.5)`.
    JitterZeroOne,
    /// Rows written bottom to top.
    YFlipped,
    /// Each row written right to left: the image mirrored left to right, as a camera whose
    /// horizontal axis points the wrong way (`u = cross(w, vup)`) renders it. Not in
    /// [`MUST_FAIL`]: a scene symmetric about its vertical midline (the course's sphere scene)
    /// looks the same mirrored, and rightly passes.
    XFlipped,
    /// Channels written in BGR order.
    Bgr,
    /// The vertical field of view 5% wider.
    WiderFov,
    /// The scene's last object left out (the right sphere of the sphere scene).
    ObjectMissing,
    /// The sky's gradient upside down (blue at the bottom).
    SkyReversed,
}

/// Every mistake the comparison must reject (`docs/comparing-images.md`, "Measured false alarms
/// and power").
pub const MUST_FAIL: [Mistake; 11] = [
    Mistake::NoGamma,
    Mistake::Gamma22,
    Mistake::GammaTwice,
    Mistake::AlbedoScaled,
    Mistake::HalfPixelShift,
    Mistake::JitterZeroOne,
    Mistake::YFlipped,
    Mistake::Bgr,
    Mistake::WiderFov,
    Mistake::ObjectMissing,
    Mistake::SkyReversed,
];

/// Every mistake of the catalogue with the name `examples/mistake.rs` (and the README test's
/// `mistake:` fixture) calls it by.
pub const BY_ARGUMENT: [(&str, Mistake); 13] = [
    ("honest", Mistake::Honest),
    ("no-gamma", Mistake::NoGamma),
    ("gamma22", Mistake::Gamma22),
    ("gamma-twice", Mistake::GammaTwice),
    ("albedo", Mistake::AlbedoScaled),
    ("half-pixel", Mistake::HalfPixelShift),
    ("jitter01", Mistake::JitterZeroOne),
    ("flip-y", Mistake::YFlipped),
    ("flip-x", Mistake::XFlipped),
    ("bgr", Mistake::Bgr),
    ("fov", Mistake::WiderFov),
    ("missing", Mistake::ObjectMissing),
    ("sky", Mistake::SkyReversed),
];

impl Mistake {
    /// The mistake called `argument` in [`BY_ARGUMENT`].
    pub fn from_argument(argument: &str) -> Option<Mistake> {
        BY_ARGUMENT
            .iter()
            .find(|(name, _)| *name == argument)
            .map(|&(_, m)| m)
    }

    /// A short name.
    pub fn name(self) -> &'static str {
        match self {
            Mistake::Honest => "honest",
            Mistake::NoGamma => "no gamma",
            Mistake::Gamma22 => "gamma 2.2",
            Mistake::GammaTwice => "gamma applied twice",
            Mistake::AlbedoScaled => "albedo x 0.97",
            Mistake::HalfPixelShift => "half-pixel camera shift",
            Mistake::JitterZeroOne => "jitter in [0, 1)",
            Mistake::YFlipped => "y flipped",
            Mistake::XFlipped => "x flipped",
            Mistake::Bgr => "BGR order",
            Mistake::WiderFov => "field of view +5%",
            Mistake::ObjectMissing => "one object missing",
            Mistake::SkyReversed => "sky gradient reversed",
        }
    }
}

/// The reversed sky: the course's gradient with its two ends swapped.
fn reversed_sky(direction: DVec3) -> DVec3 {
    let a = 0.5 * (unit_vector(direction).y + 1.0);
    a * DVec3::ONE + (1.0 - a) * DVec3::new(0.5, 0.7, 1.0)
}

/// Renders `description` at `spp` samples per pixel with `seed`, with `mistake` injected, and
/// encodes it as 8-bit RGB. [`Mistake::Honest`] gives exactly the reference's PNG bytes.
pub fn render_with_mistake(
    description: &SceneDescription,
    mistake: Mistake,
    spp: u32,
    seed: u64,
) -> Rgb8Image {
    let mut description = description.clone();
    match mistake {
        Mistake::AlbedoScaled => {
            for m in &mut description.materials {
                m.albedo = m.albedo.map(|a| a * 0.97);
            }
        }
        Mistake::WiderFov => description.camera.vfov *= 1.05,
        Mistake::ObjectMissing => {
            description.objects.pop();
        }
        _ => {}
    }
    let scene = description.scene();
    let camera = description.camera(None);
    let (w, h) = (camera.width, camera.height);
    let spp = spp.max(1);
    let rows: Vec<Vec<u8>> = (0..h)
        .into_par_iter()
        .map(|j| {
            let mut row = Vec::with_capacity(3 * w);
            for i in 0..w {
                let mut sampler = PixelSampler::new(seed, (j * w + i) as u64);
                let mut sum = DVec3::ZERO;
                for _ in 0..spp {
                    let (mut ox, mut oy) = (sampler.next_f64() - 0.5, sampler.next_f64() - 0.5);
                    match mistake {
                        Mistake::JitterZeroOne => {
                            ox += 0.5;
                            oy += 0.5;
                        }
                        Mistake::HalfPixelShift => {
                            ox -= 0.5;
                            oy -= 0.5;
                        }
                        _ => {}
                    }
                    let disk = if camera.defocus {
                        sampler.in_unit_disk()
                    } else {
                        (0.0, 0.0)
                    };
                    let ray = camera.ray_through(i as f64 + ox, j as f64 + oy, disk);
                    sum += if mistake == Mistake::SkyReversed {
                        match scene.closest(&ray, Interval::CAMERA) {
                            Some((_, k)) => scene.material_of(k).albedo(),
                            None => reversed_sky(ray.direction),
                        }
                    } else {
                        radiance(&scene, &ray)
                    };
                }
                let mean = sum / spp as f64;
                for x in mean.to_array() {
                    row.push(match mistake {
                        Mistake::NoGamma => (255.0 * x.clamp(0.0, 0.999)) as u8,
                        Mistake::GammaTwice => {
                            (255.0 * x.max(0.0).sqrt().sqrt().clamp(0.0, 0.999)) as u8
                        }
                        Mistake::Gamma22 => {
                            (255.0 * x.max(0.0).powf(1.0 / 2.2).clamp(0.0, 0.999)) as u8
                        }
                        _ => encode_course_png(x),
                    });
                }
            }
            row
        })
        .collect();
    let mut rows = rows;
    if mistake == Mistake::YFlipped {
        rows.reverse();
    }
    if mistake == Mistake::XFlipped {
        for row in &mut rows {
            let mirrored: Vec<u8> = row.chunks_exact(3).rev().flatten().copied().collect();
            *row = mirrored;
        }
    }
    let mut data: Vec<u8> = rows.into_iter().flatten().collect();
    if mistake == Mistake::Bgr {
        for p in data.chunks_exact_mut(3) {
            p.swap(0, 2);
        }
    }
    Rgb8Image {
        width: w,
        height: h,
        data,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::{RenderOptions, render};

    #[test]
    fn the_honest_catalogue_entry_is_the_reference() {
        let mut d = crate::scene::builtin("week04-sphere").unwrap();
        d.image.width = 64;
        let ours = render_with_mistake(&d, Mistake::Honest, 4, 9);
        let film = render(
            &d.scene(),
            &d.camera(None),
            &RenderOptions {
                samples_per_pixel: 4,
                seed: 9,
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!(ours.data, film.to_course_rgb8());
    }

    /// Every mistake has one argument name, and every name one mistake.
    #[test]
    fn each_mistake_has_its_own_argument_name() {
        let mut all: Vec<Mistake> = MUST_FAIL.to_vec();
        all.extend([Mistake::Honest, Mistake::XFlipped]);
        for m in &all {
            let names: Vec<&str> = BY_ARGUMENT
                .iter()
                .filter(|(_, x)| x == m)
                .map(|(n, _)| *n)
                .collect();
            assert_eq!(names.len(), 1, "{m:?}: {names:?}");
            assert_eq!(Mistake::from_argument(names[0]), Some(*m));
        }
        assert_eq!(BY_ARGUMENT.len(), all.len());
        assert_eq!(Mistake::from_argument("flipped"), None);
    }

    #[test]
    fn flips_and_swaps_are_what_they_say() {
        let mut d = crate::scene::builtin("week04-quad").unwrap();
        d.image.width = 16;
        let honest = render_with_mistake(&d, Mistake::Honest, 2, 1);
        let flipped = render_with_mistake(&d, Mistake::YFlipped, 2, 1);
        let bgr = render_with_mistake(&d, Mistake::Bgr, 2, 1);
        let row = 3 * 16;
        assert_eq!(honest.data[..row], flipped.data[flipped.data.len() - row..]);
        assert_eq!(honest.data[0], bgr.data[2]);
        assert_eq!(honest.data[2], bgr.data[0]);
        // Mirrored: pixel i of each row is pixel 15 - i of the honest row, every channel kept.
        let mirrored = render_with_mistake(&d, Mistake::XFlipped, 2, 1);
        for (h, m) in honest
            .data
            .chunks_exact(row)
            .zip(mirrored.data.chunks_exact(row))
        {
            for i in 0..16 {
                assert_eq!(h[3 * i..3 * i + 3], m[3 * (15 - i)..3 * (15 - i) + 3]);
            }
        }
        assert_ne!(
            honest.data, mirrored.data,
            "the quad scene is not symmetric"
        );
    }
}
