//! Textures: a colour as a function of a hit's surface coordinates `(u, v)` and point `P`
//! (week 7's `tex_value(u, v, P)`), and the images they read.
//!
//! The two profiles differ in three places, each named where it is computed: the checker divides
//! by its scale in the course and multiplies by its inverse in the book; an image is read with no
//! v flip and no linearisation in the course, and flipped and linearised (as the book's
//! `rtw_image` does through `stbi_loadf`) in the book.

use std::path::Path;

use glam::DVec3;

use super::Profile;

/// A texture, as a material holds it (images by their index in the scene's image list).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Texture {
    /// One colour everywhere (`SolidColor(c)`).
    Solid(DVec3),
    /// The course's 3D checker on the world point (`CheckerTexture(scale, c1, c2)`): `even`
    /// where `floor(x/s) + floor(y/s) + floor(z/s)` is even, `odd` elsewhere.
    Checker {
        /// The side of a cell.
        scale: f64,
        /// The colour of the even cells (`c1`).
        even: DVec3,
        /// The colour of the odd cells (`c2`).
        odd: DVec3,
    },
    /// An image (`ImageTexture(file)`) times a tint (white leaves it exactly as it is).
    Image {
        /// Index of the image in the scene's list.
        image: usize,
        /// Multiplies the image's colour.
        tint: DVec3,
    },
}

impl Texture {
    /// The colour that stands for the texture where a single colour is wanted: the solid colour,
    /// the checker's even colour, the image's tint.
    pub fn base_colour(&self) -> DVec3 {
        match *self {
            Texture::Solid(c) => c,
            Texture::Checker { even, .. } => even,
            Texture::Image { tint, .. } => tint,
        }
    }

    /// The texture's value at surface coordinates `uv` and point `p`, reading images from
    /// `images` (prepared for `profile`, [`TextureImage::new`]).
    ///
    /// The checker: the course computes `floor(x / s) + floor(y / s) + floor(z / s)` (division)
    /// and tests it for evenness (Python's `%` is never negative); the book computes
    /// `floor(inv_scale x)` with `inv_scale = 1 / s` (a multiplication: it differs from the
    /// division in the last bit, which moves cell edges by an ulp). An index beyond
    /// `images` (a scene built by hand) gives the course's colour for an unusable file,
    /// `(0, 1, 1)`.
    #[inline(always)]
    pub fn value(
        &self,
        images: &[TextureImage],
        uv: (f64, f64),
        p: DVec3,
        profile: Profile,
    ) -> DVec3 {
        match *self {
            Texture::Solid(c) => c,
            Texture::Checker { scale, even, odd } => {
                // The course (`RT_texture.CheckerTexture`: `inv_scale = 1.0 / fScale`,
                // `floor(p.x() * inv_scale)`) and the book alike multiply by the inverse of the
                // scale; a division rounds differently where `p / scale` is within an ulp of a
                // whole number.
                let _ = profile;
                let inv = 1.0 / scale;
                let cells = (p.x * inv).floor() + (p.y * inv).floor() + (p.z * inv).floor();
                if is_even(cells) { even } else { odd }
            }
            Texture::Image { image, tint } => match images.get(image) {
                Some(image) => tint * image.lookup(uv),
                None => DVec3::new(0.0, 1.0, 1.0),
            },
        }
    }
}

/// Whether `cells`, a sum of floors (an integer, or infinite, or NaN), is even: exactly
/// `cells.rem_euclid(2.0) == 0.0` (the course's `% 2 == 0`), without the remainder's long
/// division. Half an integer of magnitude 2 or more is exact, and whole exactly when the
/// integer is even; 0 and -0 are even, 1 and -1 are not; infinities and NaN are not.
#[inline(always)]
fn is_even(cells: f64) -> bool {
    let half = cells * 0.5;
    cells.is_finite() && half.floor() == half
}

/// An image texture's texels, ready for one profile's lookups.
#[derive(Clone, Debug, PartialEq)]
pub struct TextureImage {
    width: usize,
    height: usize,
    /// Row-major, top row first.
    texels: Vec<DVec3>,
    /// Whether `v` is flipped (the book) or not (the course).
    flip_v: bool,
}

impl TextureImage {
    /// The texels of an 8-bit RGB image (`width x height`, row-major from the top, 3 bytes a
    /// pixel) for `profile`:
    ///
    /// - course: `byte / 255`, no linearisation (week 7's `ImageTexture`);
    /// - physical: the book's `rtw_image`: `stbi_loadf` linearises each byte in `f32` as
    ///   `(byte / 255)^2.2`, `convert_to_bytes` turns that back into a byte (`0` at or below 0,
    ///   `255` at or above 1, else `int(256 v)`), and the texture divides by 255.
    ///
    /// An empty image gets one texel of the course's colour for an unusable file, `(0, 1, 1)`.
    pub fn new(width: usize, height: usize, rgb: &[u8], profile: Profile) -> Self {
        if width == 0 || height == 0 || rgb.len() < 3 * width * height {
            return Self {
                width: 1,
                height: 1,
                texels: vec![DVec3::new(0.0, 1.0, 1.0)],
                flip_v: false,
            };
        }
        let value = |byte: u8| match profile {
            Profile::Course => byte as f64 / 255.0,
            Profile::Physical => {
                let linear = libm::powf(byte as f32 / 255.0, 2.2);
                let byte = if linear <= 0.0 {
                    0
                } else if linear >= 1.0 {
                    255
                } else {
                    (256.0 * linear) as u8
                };
                byte as f64 / 255.0
            }
        };
        let texels = rgb[..3 * width * height]
            .chunks_exact(3)
            .map(|p| DVec3::new(value(p[0]), value(p[1]), value(p[2])))
            .collect();
        Self {
            width,
            height,
            texels,
            flip_v: profile == Profile::Physical,
        }
    }

    /// The texel at surface coordinates `(u, v)`: both clamped to `[0, 1]` (`v` replaced by
    /// `1 - v` in the book), column `int(u W)`, row `int(v H)` from the top.
    ///
    /// At `u = 1` (or `v = 1`) the course's `int(u W)` is one past the last column and its code
    /// raises `IndexError`; what it evidently intends, and what the book's `pixel_data` does, is
    /// the last column, which is what this returns.
    #[inline]
    pub fn lookup(&self, (u, v): (f64, f64)) -> DVec3 {
        let u = u.clamp(0.0, 1.0);
        let v = v.clamp(0.0, 1.0);
        let v = if self.flip_v { 1.0 - v } else { v };
        let i = ((u * self.width as f64) as usize).min(self.width - 1);
        let j = ((v * self.height as f64) as usize).min(self.height - 1);
        self.texels[j * self.width + i]
    }

    /// Width in texels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in texels.
    pub fn height(&self) -> usize {
        self.height
    }
}

/// An 8-bit RGB picture as a texture file holds it, before it is prepared for a profile.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RgbPicture {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Row-major from the top, 3 bytes a pixel.
    pub data: Vec<u8>,
}

/// Why a picture file cannot be a texture; each says so in a few words, to follow the file's
/// name.
#[derive(Debug, thiserror::Error)]
pub enum PictureError {
    /// There is no file at the path.
    #[error("no such file")]
    Missing,
    /// The path is a folder.
    #[error("it is a folder, not an image")]
    Folder,
    /// The file could not be read.
    #[error("{0}")]
    Unreadable(std::io::Error),
    /// The content is no image format rtoracle knows.
    #[error("not a PNG or JPEG image")]
    NotAnImage,
    /// An image, of a format other than PNG and JPEG (its name).
    #[error("a {0} image, not a PNG or JPEG")]
    OtherFormat(String),
    /// A PNG or JPEG its decoder refused (the decoder's words).
    #[error("cannot decode it: {0}")]
    Undecodable(String),
}

/// Reads a PNG or JPEG file as 8-bit RGB (grey, palette, alpha and 16-bit images are converted:
/// alpha dropped, 16 bits rounded to 8), or says why it cannot.
///
/// The format is decided by the file's content, not its name. JPEG is decoded by the `image`
/// crate's decoder, whose output can differ by a code here and there from the libjpeg build
/// Pillow uses: a texture's golden is the reference's decoding.
pub fn read_picture(path: &Path) -> Result<RgbPicture, PictureError> {
    let bytes = std::fs::read(path).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => PictureError::Missing,
        std::io::ErrorKind::IsADirectory => PictureError::Folder,
        _ => PictureError::Unreadable(e),
    })?;
    let format = image::guess_format(&bytes).map_err(|_| PictureError::NotAnImage)?;
    if !matches!(format, image::ImageFormat::Png | image::ImageFormat::Jpeg) {
        return Err(PictureError::OtherFormat(format!("{format:?}")));
    }
    let decoded = image::load_from_memory_with_format(&bytes, format)
        .map_err(|e| PictureError::Undecodable(e.to_string()))?;
    let rgb = decoded.to_rgb8();
    Ok(RgbPicture {
        width: rgb.width() as usize,
        height: rgb.height() as usize,
        data: rgb.into_raw(),
    })
}

/// The names of the pictures rtoracle generates (in code, deterministically) to stand in for
/// the course's texture files, so that a scene using them renders the same anywhere.
pub const GENERATED_PICTURES: &[&str] = &["earth", "basketball", "soccer", "pepsi"];

/// The generated picture called `name` ([`GENERATED_PICTURES`]): 256 x 128 pixels, each a
/// pattern with features in every direction (so a swapped `u` and `v`, a flipped `v` or an
/// off-by-one column show), and a marker in its top-left corner.
pub fn generated_picture(name: &str) -> Option<RgbPicture> {
    let (width, height) = (256usize, 128usize);
    let pixel: fn(usize, usize) -> [u8; 3] = match name {
        // Oceans, a band of land that winds with longitude, polar caps.
        "earth" => |x, y| {
            if !(8..120).contains(&y) {
                return [235, 240, 245];
            }
            let coast = 64 + ((x * 7) % 48) as isize - 24 + (x / 32) as isize * 2;
            if (y as isize - coast).abs() < 14 || (x / 16 + y / 16) % 5 == 0 {
                [60 + (y % 32) as u8 * 2, 120 + (x % 64) as u8, 40]
            } else {
                [20, 50 + (y / 4) as u8, 150 + (x / 4) as u8 / 2]
            }
        },
        // Orange with black seams: two meridians and the equator.
        "basketball" => |x, y| {
            if x % 64 < 3 || (62..66).contains(&y) || (x + 2 * y) % 128 < 3 {
                [15, 10, 10]
            } else {
                [210, 105 + (y / 8) as u8, 30 + (x / 16) as u8]
            }
        },
        // White with black cells that shrink towards the poles.
        "soccer" => |x, y| {
            let cell = 8 + y.min(127 - y) / 4;
            if (x / cell + y / 16) % 3 == 0 {
                [20, 20, 25]
            } else {
                [245, 245, 240 - (x / 8) as u8]
            }
        },
        // Red over white over blue, with a wave between them.
        "pepsi" => |x, y| {
            let wave = ((x * 5) % 40) as isize - 20;
            let y = y as isize;
            if y < 40 + wave / 2 {
                [200, 20 + (x / 8) as u8, 40]
            } else if y < 80 + wave / 4 {
                [250, 250, 250]
            } else {
                [10, 40 + (x / 16) as u8, 160 + (y / 4) as u8]
            }
        },
        _ => return None,
    };
    let mut data = Vec::with_capacity(3 * width * height);
    for y in 0..height {
        for x in 0..width {
            // The marker: a magenta block in the top-left corner.
            let rgb = if x < 12 && y < 6 {
                [255, 0, 255]
            } else {
                pixel(x, y)
            };
            data.extend_from_slice(&rgb);
        }
    }
    Some(RgbPicture {
        width,
        height,
        data,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The parity shortcut decides as the course's remainder on every sum of floors: small and
    /// huge integers of both signs, the ends of exact integers (2^53), zeros, infinities, NaN,
    /// and a million sums of three random floors.
    #[test]
    fn evenness_is_the_remainders() {
        let mut values = vec![
            0.0,
            -0.0,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            f64::MAX,
        ];
        for k in -40i64..=40 {
            values.push(k as f64);
        }
        for e in [52, 53, 54, 60, 1000] {
            let big = 2f64.powi(e);
            for x in [big - 2.0, big - 1.0, big, big + 1.0, big + 2.0] {
                values.extend([x, -x]);
            }
        }
        let mut s = crate::render::PixelSampler::new(5, 8);
        for _ in 0..1_000_000 {
            let scale = 10f64.powf(s.uniform(-3.0, 17.0));
            let floors = [0; 3].map(|_| (s.uniform(-1.0, 1.0) * scale).floor());
            values.push(floors[0] + floors[1] + floors[2]);
        }
        for x in values {
            assert_eq!(is_even(x), x.rem_euclid(2.0) == 0.0, "{x:e}");
        }
    }

    /// The course's lookup, hand-worked on a 4 x 2 image: column `int(u W)`, row `int(v H)`
    /// from the top with no flip, `u = 1` on the last column; the book flips `v`.
    #[test]
    fn image_lookup_follows_the_uv_mapping() {
        let mut rgb = Vec::new();
        for y in 0..2u8 {
            for x in 0..4u8 {
                rgb.extend_from_slice(&[x * 50, y * 100, 7]);
            }
        }
        let course = TextureImage::new(4, 2, &rgb, Profile::Course);
        let texel = |x: u8, y: u8| {
            DVec3::new(
                (x * 50) as f64 / 255.0,
                (y * 100) as f64 / 255.0,
                7.0 / 255.0,
            )
        };
        assert_eq!(course.lookup((0.0, 0.0)), texel(0, 0));
        assert_eq!(course.lookup((0.26, 0.2)), texel(1, 0));
        assert_eq!(course.lookup((0.74, 0.5)), texel(2, 1));
        assert_eq!(course.lookup((1.0, 1.0)), texel(3, 1));
        assert_eq!(course.lookup((-3.0, 7.0)), texel(0, 1));
        let book = TextureImage::new(4, 2, &rgb, Profile::Physical);
        // v = 0.2 flips to 0.8: the bottom row; (100/255)^2.2 = 0.1277..., int(256 x) = 32.
        let got = book.lookup((0.26, 0.2));
        assert_eq!(got.y, 32.0 / 255.0);
        assert_eq!(got.x, {
            let l = libm::powf(50.0 / 255.0, 2.2);
            (256.0 * l) as u8 as f64 / 255.0
        });
        assert_eq!(book.lookup((0.0, 0.0)).y, got.y);
    }

    /// The 3D checker on hand-picked points: cells of side 0.5, `floor` rounds down on the
    /// negative side too, so `(-0.1, 0, 0)` is in cell -1 (odd) and `(-0.6, -0.1, 0)` in
    /// `-2 - 1 = -3` (odd), `(0.6, 0.6, 0.1)` in `1 + 1 + 0` (even).
    #[test]
    fn checker_counts_cells_on_the_world_point() {
        let (even, odd) = (DVec3::ONE, DVec3::ZERO);
        let checker = Texture::Checker {
            scale: 0.5,
            even,
            odd,
        };
        for profile in [Profile::Course, Profile::Physical] {
            let at = |x, y, z| checker.value(&[], (0.0, 0.0), DVec3::new(x, y, z), profile);
            assert_eq!(at(0.1, 0.1, 0.1), even);
            assert_eq!(at(-0.1, 0.0, 0.0), odd);
            assert_eq!(at(-0.6, -0.1, 0.0), odd);
            assert_eq!(at(0.6, 0.6, 0.1), even);
            assert_eq!(at(0.6, 0.1, 0.1), odd);
            assert_eq!(at(-0.6, -0.6, 0.0), even);
        }
    }

    #[test]
    fn generated_pictures_are_deterministic_and_distinct() {
        let all: Vec<RgbPicture> = GENERATED_PICTURES
            .iter()
            .map(|n| generated_picture(n).unwrap())
            .collect();
        for (i, p) in all.iter().enumerate() {
            assert_eq!(p.data.len(), 3 * p.width * p.height);
            assert_eq!(Some(p.clone()), generated_picture(GENERATED_PICTURES[i]));
            // Not symmetric under a v flip: row 0 differs from the last row.
            assert_ne!(p.data[..3 * p.width], p.data[p.data.len() - 3 * p.width..]);
            for q in &all[i + 1..] {
                assert_ne!(p.data, q.data);
            }
        }
        assert!(generated_picture("mars").is_none());
    }
}
