use std::path::Path;

use super::{ImageError, write_atomically};

/// An 8-bit RGB image, row-major, top row first.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Rgb8Image {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// `3 * width * height` bytes, R, G, B per pixel.
    pub data: Vec<u8>,
}

/// The PNG file of an 8-bit RGB image.
pub fn encode_png(image: &Rgb8Image) -> Result<Vec<u8>, String> {
    let mut bytes = Vec::new();
    let encoder = image::codecs::png::PngEncoder::new(&mut bytes);
    image::ImageEncoder::write_image(
        encoder,
        &image.data,
        image.width as u32,
        image.height as u32,
        image::ExtendedColorType::Rgb8,
    )
    .map_err(|e| e.to_string())?;
    Ok(bytes)
}

/// Writes an 8-bit RGB PNG atomically.
pub fn write_png(path: &Path, image: &Rgb8Image) -> Result<(), ImageError> {
    let bytes = encode_png(image).map_err(|e| ImageError::format(path, e))?;
    write_atomically(path, &bytes)
}

/// Reads a PNG as 8-bit RGB. 8-bit RGB and RGBA files are accepted (alpha is dropped); anything
/// else (16-bit, grey, palette) is an error naming the file and what it is.
pub fn read_png(path: &Path) -> Result<Rgb8Image, ImageError> {
    let bytes =
        std::fs::read(path).map_err(|e| ImageError::io(path, format!("cannot read: {e}")))?;
    let decoded = image::load_from_memory_with_format(&bytes, image::ImageFormat::Png)
        .map_err(|e| ImageError::format(path, format!("not a readable PNG: {e}")))?;
    let (width, height) = (decoded.width() as usize, decoded.height() as usize);
    let data = match decoded {
        image::DynamicImage::ImageRgb8(img) => img.into_raw(),
        image::DynamicImage::ImageRgba8(img) => img
            .into_raw()
            .chunks_exact(4)
            .flat_map(|p| [p[0], p[1], p[2]])
            .collect(),
        other => {
            return Err(ImageError::format(
                path,
                format!(
                    "has colour type {:?}; expected 8-bit RGB or RGBA",
                    other.color()
                ),
            ));
        }
    };
    Ok(Rgb8Image {
        width,
        height,
        data,
    })
}
