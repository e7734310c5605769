//! OpenEXR files: linear `f32` R, G, B, optional `variance` and `deviation` layers, and string
//! attributes.
//!
//! rtoracle writes one single-part scan-line file per image: channels `R`, `G`, `B` (the
//! per-pixel mean) and, when the film kept them, `variance.R`, `variance.G`, `variance.B` (the
//! per-sample variance; OpenEXR reads the `variance.` prefix as a layer called `variance`) and
//! `deviation.R`, `deviation.G`, `deviation.B` (the largest distance of a sample from the mean).
//! All samples are `f32`, rounded to nearest from the film's `f64`, except the deviation, rounded
//! up (it is a bound). Blocks are ZIP-compressed 16 lines
//! at a time in increasing line order, written by one thread, and the header's attributes are
//! sorted by name (as OpenEXR's own library writes them), so the same film and attributes give
//! the same bytes every time, on any machine and any number of threads.

use std::io::Cursor;
use std::path::Path;

use exr::prelude::{
    AnyChannel, AnyChannels, AttributeValue, Encoding, FlatSamples, Image, Layer, LayerAttributes,
    Layers, ReadChannels, ReadLayers, SmallVec, Text, WritableImage,
};

use super::{ImageError, write_atomically};
use crate::render::Film;

/// An EXR image as rtoracle reads it: mean R, G, B, the optional per-sample variance, and the
/// header's string attributes.
#[derive(Clone, Debug, PartialEq)]
pub struct ExrImage {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Mean linear RGB, row-major, top row first.
    pub mean: Vec<[f32; 3]>,
    /// Per-sample variance of each channel, when the file has a `variance` layer.
    pub variance: Option<Vec<[f32; 3]>>,
    /// The largest distance of a sample from the mean, per channel, when the file has a
    /// `deviation` layer.
    pub deviation: Option<Vec<[f32; 3]>>,
    /// String attributes of the header, sorted by name.
    pub attributes: Vec<(String, String)>,
}

impl ExrImage {
    /// The film this image holds, as `samples_per_pixel` samples per pixel: its f32 values
    /// widened exactly to f64 (so writing it again gives the same values), its `variance` and
    /// `deviation` layers when it has them.
    pub fn to_film(&self, samples_per_pixel: u32) -> Film {
        let widen = |v: &[[f32; 3]]| -> Vec<glam::DVec3> {
            v.iter()
                .map(|p| glam::DVec3::new(p[0].into(), p[1].into(), p[2].into()))
                .collect()
        };
        Film {
            width: self.width,
            height: self.height,
            samples_per_pixel,
            mean: widen(&self.mean),
            variance: self.variance.as_deref().map(widen),
            deviation: self.deviation.as_deref().map(widen),
        }
    }

    /// The value of the string attribute `name`, if the header has it.
    pub fn attribute(&self, name: &str) -> Option<&str> {
        self.attributes
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_str())
    }
}

/// The nearest `f32` not below `x` (for a bound; `x` not negative, as a deviation is).
fn f32_at_least(x: f64) -> f32 {
    let near = x as f32;
    if (near as f64) < x {
        // The next f32 up: `near` is not negative (nor infinite, being below `x`), so its
        // successor is one step of its bits (0 steps to the smallest subnormal).
        f32::from_bits(near.to_bits() + 1)
    } else {
        near
    }
}

/// The four magic bytes every OpenEXR file starts with.
const MAGIC: [u8; 4] = [0x76, 0x2f, 0x31, 0x01];

/// Writes a film as EXR (f32 R, G, B, and `variance` and `deviation` layers when the film has
/// them) with the
/// given string attributes, atomically and deterministically ([`encode_exr`] gives the bytes).
pub fn write_exr(
    path: &Path,
    film: &Film,
    attributes: &[(String, String)],
) -> Result<(), ImageError> {
    let bytes = encode_exr(film, attributes, path)?;
    write_atomically(path, &bytes)
}

/// The bytes of the EXR file [`write_exr`] writes; `name` labels errors (an empty film, an empty
/// or duplicated attribute name, an attribute that collides with a standard one).
///
/// The same film and attributes always give the same bytes: one writer thread, increasing line
/// order, ZIP blocks of 16 lines, attributes sorted by name. Attribute values are stored as their
/// UTF-8 bytes.
pub fn encode_exr(
    film: &Film,
    attributes: &[(String, String)],
    name: &Path,
) -> Result<Vec<u8>, ImageError> {
    if film.width == 0 || film.height == 0 {
        return Err(ImageError::format(
            name,
            "cannot write an empty image as EXR",
        ));
    }
    let count = film.width * film.height;
    let wrong = |layer: &Option<Vec<glam::DVec3>>| layer.as_ref().is_some_and(|v| v.len() != count);
    if film.mean.len() != count || wrong(&film.variance) || wrong(&film.deviation) {
        return Err(ImageError::format(
            name,
            format!(
                "the film's pixel count does not match its size {}x{}",
                film.width, film.height
            ),
        ));
    }
    let channel = |label: &str, values: &[glam::DVec3], c: usize| {
        AnyChannel::new(
            label,
            FlatSamples::F32(values.iter().map(|v| v[c] as f32).collect()),
        )
    };
    let mut channels: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::new();
    for (c, label) in ["R", "G", "B"].into_iter().enumerate() {
        channels.push(channel(label, &film.mean, c));
    }
    if let Some(variance) = &film.variance {
        for (c, label) in ["variance.R", "variance.G", "variance.B"]
            .into_iter()
            .enumerate()
        {
            channels.push(channel(label, variance, c));
        }
    }
    if let Some(deviation) = &film.deviation {
        for (c, label) in ["deviation.R", "deviation.G", "deviation.B"]
            .into_iter()
            .enumerate()
        {
            let up = deviation.iter().map(|v| f32_at_least(v[c])).collect();
            channels.push(AnyChannel::new(label, FlatSamples::F32(up)));
        }
    }

    let mut layer_attributes = LayerAttributes::default();
    let mut seen = std::collections::BTreeSet::new();
    for (key, value) in attributes {
        if key.is_empty() || key.len() > 255 || key.contains('\0') {
            return Err(ImageError::format(
                name,
                format!("cannot write the attribute name {key:?}: 1 to 255 bytes, no NUL"),
            ));
        }
        if !seen.insert(key.as_str()) {
            return Err(ImageError::format(
                name,
                format!("the attribute {key:?} is given twice"),
            ));
        }
        if STANDARD_ATTRIBUTES.contains(&key.as_str()) {
            return Err(ImageError::format(
                name,
                format!("the attribute {key:?} is a standard OpenEXR attribute"),
            ));
        }
        layer_attributes.other.insert(
            Text::from_slice_unchecked(key.as_bytes()),
            AttributeValue::Text(Text::from_slice_unchecked(value.as_bytes())),
        );
    }

    let encoding = Encoding {
        compression: exr::prelude::Compression::ZIP16,
        blocks: exr::prelude::Blocks::ScanLines,
        line_order: exr::prelude::LineOrder::Increasing,
    };
    let layer = Layer::new(
        (film.width, film.height),
        layer_attributes,
        encoding,
        AnyChannels::sort(channels),
    );
    let image = Image::from_layer(layer);
    let mut bytes = Cursor::new(Vec::new());
    image
        .write()
        .non_parallel()
        .to_buffered(&mut bytes)
        .map_err(|e| ImageError::format(name, format!("cannot encode as EXR: {e}")))?;
    let mut bytes = bytes.into_inner();
    sort_header_attributes(&mut bytes)
        .map_err(|e| ImageError::format(name, format!("cannot encode as EXR: {e}")))?;
    Ok(bytes)
}

/// Attribute names OpenEXR defines itself; a string attribute of the same name would clash.
const STANDARD_ATTRIBUTES: &[&str] = &[
    "channels",
    "compression",
    "dataWindow",
    "displayWindow",
    "lineOrder",
    "pixelAspectRatio",
    "screenWindowCenter",
    "screenWindowWidth",
    "tiles",
    "type",
    "name",
    "version",
    "chunkCount",
];

/// Reorders the attributes of a single-part file's header by name (byte order, as OpenEXR's own
/// writer does). exr keeps custom attributes in a `HashMap`, whose order changes from run to run;
/// every attribute keeps its bytes, so the header's length and the offset table stay valid.
fn sort_header_attributes(bytes: &mut [u8]) -> Result<(), String> {
    if bytes.len() < 8 || bytes[..4] != MAGIC {
        return Err("the encoder did not produce an EXR header".into());
    }
    if bytes[5] & 0x10 != 0 || bytes[5] & 0x08 != 0 {
        return Err("a multi-part or deep file was produced".into());
    }
    let start = 8;
    let mut entries: Vec<(usize, usize)> = Vec::new();
    let mut at = start;
    loop {
        let nul = |from: usize| {
            bytes[from..]
                .iter()
                .position(|&b| b == 0)
                .map(|p| from + p)
                .ok_or_else(|| "unterminated header".to_string())
        };
        if *bytes.get(at).ok_or("unterminated header")? == 0 {
            break;
        }
        let name_end = nul(at)?;
        let type_end = nul(name_end + 1)?;
        let size_at = type_end + 1;
        let size = bytes
            .get(size_at..size_at + 4)
            .ok_or("unterminated header")?;
        let size = i32::from_le_bytes([size[0], size[1], size[2], size[3]]);
        let size = usize::try_from(size).map_err(|_| "negative attribute size")?;
        let end = size_at + 4 + size;
        if end > bytes.len() {
            return Err("unterminated header".into());
        }
        entries.push((at, end));
        at = end;
    }
    let name_of = |&(from, _): &(usize, usize)| {
        let len = bytes[from..].iter().position(|&b| b == 0).unwrap_or(0);
        bytes[from..from + len].to_vec()
    };
    let mut sorted = entries.clone();
    sorted.sort_by_key(name_of);
    let rewritten: Vec<u8> = sorted
        .iter()
        .flat_map(|&(from, to)| bytes[from..to].iter().copied())
        .collect();
    bytes[start..at].copy_from_slice(&rewritten);
    Ok(())
}

/// Reads an EXR written by rtoracle or any RGB(A) EXR.
///
/// The first part (layer) with `R`, `G` and `B` channels is read, at its largest resolution
/// level; any sample type (half, float, uint) becomes `f32`; `A` and other channels are
/// ignored except `variance.R`, `variance.G`, `variance.B` (or a part named `variance` with
/// `R`, `G`, `B`), which become [`ExrImage::variance`], and the same of `deviation`
/// ([`ExrImage::deviation`]). String attributes are returned sorted by
/// name. A missing, non-EXR, truncated or damaged file, or one without R, G, B, is an error
/// naming the file.
pub fn read_exr(path: &Path) -> Result<ExrImage, ImageError> {
    let bytes = std::fs::read(path).map_err(|e| ImageError::unreadable(path, &e))?;
    decode_exr(&bytes, path)
}

/// Decodes the bytes of an EXR file as [`read_exr`] does; `name` labels errors.
pub fn decode_exr(bytes: &[u8], name: &Path) -> Result<ExrImage, ImageError> {
    let image = decode_layers(bytes, name)?;
    let layers = &image.layer_data;
    let main = main_layer(layers, name)?;
    let samples = Samples {
        name,
        width: main.size.0,
        height: main.size.1,
    };
    let mean = samples.rgb(main)?;
    let variance = layer_of("variance", layers, main, &samples)?;
    let deviation = layer_of("deviation", layers, main, &samples)?;
    let mut attributes: Vec<(String, String)> = image
        .attributes
        .other
        .iter()
        .chain(main.attributes.other.iter())
        .filter_map(|(k, v)| match v {
            AttributeValue::Text(t) => Some((
                String::from_utf8_lossy(k.bytes()).into_owned(),
                String::from_utf8_lossy(t.bytes()).into_owned(),
            )),
            _ => None,
        })
        .collect();
    attributes.sort();
    attributes.dedup();
    Ok(ExrImage {
        width: samples.width,
        height: samples.height,
        mean,
        variance,
        deviation,
        attributes,
    })
}

/// A decoded file's layers: every channel of every part.
type Decoded = Image<Layers<AnyChannels<FlatSamples>>>;

/// One layer of a decoded file.
type DecodedLayer = Layer<AnyChannels<FlatSamples>>;

/// Checks the magic number and the header's sizes, then decodes every channel of every part.
fn decode_layers(bytes: &[u8], name: &Path) -> Result<Decoded, ImageError> {
    if bytes.len() < 4 || bytes[..4] != MAGIC {
        return Err(ImageError::format(
            name,
            "is not an OpenEXR file (it does not start with the EXR magic number)",
        ));
    }
    check_sizes(bytes, name)?;
    exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .all_layers()
        .all_attributes()
        .non_parallel()
        .pedantic()
        .from_buffered(Cursor::new(bytes))
        .map_err(|e| {
            ImageError::format(
                name,
                format!(
                    "is a truncated or damaged OpenEXR file: {}",
                    one_line(&e.to_string())
                ),
            )
        })
}

/// The first layer with `R`, `G` and `B` channels, or an error listing the channels there are.
fn main_layer<'a>(layers: &'a [DecodedLayer], name: &Path) -> Result<&'a DecodedLayer, ImageError> {
    if let Some(main) = layers
        .iter()
        .find(|l| ["R", "G", "B"].iter().all(|c| find(l, c).is_some()))
    {
        return Ok(main);
    }
    let names: Vec<String> = layers
        .iter()
        .flat_map(|l| {
            let prefix = l
                .attributes
                .layer_name
                .as_ref()
                .map(|n| format!("{n}/"))
                .unwrap_or_default();
            l.channel_data
                .list
                .iter()
                .map(move |c| format!("{prefix}{}", c.name))
        })
        .collect();
    Err(ImageError::format(
        name,
        format!(
            "has no R, G, B channels (it has {})",
            if names.is_empty() {
                "none".to_string()
            } else {
                names.join(", ")
            }
        ),
    ))
}

/// Reads the samples of a file's channels, which must each hold one sample per pixel.
struct Samples<'a> {
    /// The file, for errors.
    name: &'a Path,
    width: usize,
    height: usize,
}

impl Samples<'_> {
    /// The samples of one channel as `f32`.
    fn values(&self, channel: &AnyChannel<FlatSamples>) -> Result<Vec<f32>, ImageError> {
        let (width, height) = (self.width, self.height);
        if channel.sampling != exr::math::Vec2(1, 1) {
            return Err(ImageError::format(
                self.name,
                format!(
                    "channel {} is subsampled, which rtoracle does not read",
                    channel.name
                ),
            ));
        }
        let v: Vec<f32> = channel.sample_data.values_as_f32().collect();
        if v.len() != width * height {
            return Err(ImageError::format(
                self.name,
                format!(
                    "channel {} has {} samples for {width}x{height} pixels",
                    channel.name,
                    v.len()
                ),
            ));
        }
        Ok(v)
    }

    /// Three channels as one RGB pixel each.
    fn triple(&self, channels: [&AnyChannel<FlatSamples>; 3]) -> Result<Vec<[f32; 3]>, ImageError> {
        let [r, g, b] = channels.map(|c| self.values(c));
        let (r, g, b) = (r?, g?, b?);
        Ok((0..self.width * self.height)
            .map(|i| [r[i], g[i], b[i]])
            .collect())
    }

    /// The `R`, `G`, `B` channels of a layer known to have them.
    fn rgb(&self, layer: &DecodedLayer) -> Result<Vec<[f32; 3]>, ImageError> {
        let get = |c| find(layer, c).expect("checked above");
        self.triple([get("R"), get("G"), get("B")])
    }
}

/// The layer `name` (`variance` or `deviation`): `NAME.*` channels beside R, G, B, or a part
/// named `NAME`; `None` when the file has neither, an error when it has part of one.
fn layer_of(
    name: &str,
    layers: &[DecodedLayer],
    main: &DecodedLayer,
    samples: &Samples<'_>,
) -> Result<Option<Vec<[f32; 3]>>, ImageError> {
    let labels = ["R", "G", "B"].map(|c| format!("{name}.{c}"));
    let prefixed = labels.each_ref().map(|c| find(main, c));
    match prefixed {
        [Some(r), Some(g), Some(b)] => Ok(Some(samples.triple([r, g, b])?)),
        [None, None, None] => {
            let part = layers.iter().find(|l| {
                l.attributes
                    .layer_name
                    .as_ref()
                    .is_some_and(|n| n.bytes() == name.as_bytes())
            });
            match part {
                Some(part) if part.size != main.size => Err(ImageError::format(
                    samples.name,
                    format!("the {name} part's size differs from the image's"),
                )),
                Some(part) if ["R", "G", "B"].iter().all(|c| find(part, c).is_some()) => {
                    Ok(Some(samples.rgb(part)?))
                }
                _ => Ok(None),
            }
        }
        _ => {
            let missing: Vec<&str> = labels
                .iter()
                .zip(prefixed)
                .filter(|(_, c)| c.is_none())
                .map(|(n, _)| n.as_str())
                .collect();
            Err(ImageError::format(
                samples.name,
                format!(
                    "has a partial {name} layer (missing {})",
                    missing.join(", ")
                ),
            ))
        }
    }
}

/// The smallest limit on the decoded pixel bytes of a file (see [`check_sizes`]).
const MIN_DECODED_LIMIT: usize = 256 << 20;

/// How many times its own size a file may expand to when decoded (deflate's largest ratio is
/// about 1032).
const MAX_EXPANSION: usize = 2048;

/// Refuses a header whose sizes the file cannot hold, before anything is allocated for them: the
/// offset tables need 8 bytes per block, and the decoded samples may take at most
/// `max(256 MiB, 2048 x the file's length)` bytes. A damaged size field otherwise makes the
/// decoder try to allocate gigabytes and abort the process.
fn check_sizes(bytes: &[u8], name: &Path) -> Result<(), ImageError> {
    let damaged = |message: String| {
        ImageError::format(
            name,
            format!("is a truncated or damaged OpenEXR file: {message}"),
        )
    };
    let meta = exr::meta::MetaData::read_from_buffered(Cursor::new(bytes), true)
        .map_err(|e| damaged(one_line(&e.to_string())))?;
    let mut blocks = 0usize;
    let mut decoded = 0usize;
    for header in meta.headers.iter() {
        blocks = blocks.saturating_add(header.chunk_count);
        let size = header.layer_size;
        decoded = decoded.saturating_add(
            size.0
                .saturating_mul(size.1)
                .saturating_mul(header.channels.bytes_per_pixel.max(1)),
        );
    }
    if blocks.saturating_mul(8) > bytes.len() {
        return Err(damaged(format!(
            "its header promises {blocks} blocks, more than its {} bytes can hold",
            bytes.len()
        )));
    }
    let limit = MIN_DECODED_LIMIT.max(bytes.len().saturating_mul(MAX_EXPANSION));
    if decoded > limit {
        let size = meta.headers[0].layer_size;
        return Err(damaged(format!(
            "its header describes {}x{} pixels ({decoded} bytes of samples), too many for a {}-byte file",
            size.0,
            size.1,
            bytes.len()
        )));
    }
    Ok(())
}

/// The parts of an EXR as its header describes them, `(width, height, bytes per pixel)` each
/// (the largest resolution level), read without decoding anything: for judging an untrusted file
/// before [`decode_exr`] allocates for it. `Err` says why the header cannot be read.
pub fn exr_part_sizes(bytes: &[u8]) -> Result<Vec<(usize, usize, usize)>, String> {
    if bytes.len() < 4 || bytes[..4] != MAGIC {
        return Err("it does not start with the EXR magic number".into());
    }
    let meta = exr::meta::MetaData::read_from_buffered(Cursor::new(bytes), true)
        .map_err(|e| one_line(&e.to_string()))?;
    Ok(meta
        .headers
        .iter()
        .map(|h| {
            (
                h.layer_size.0,
                h.layer_size.1,
                h.channels.bytes_per_pixel.max(1),
            )
        })
        .collect())
}

/// The channel called `label` of `layer`.
fn find<'a>(layer: &'a DecodedLayer, label: &str) -> Option<&'a AnyChannel<FlatSamples>> {
    layer
        .channel_data
        .list
        .iter()
        .find(|c| c.name.bytes() == label.as_bytes())
}

/// The first line of a message, so errors stay on one line.
fn one_line(message: &str) -> String {
    message.lines().next().unwrap_or("").trim().to_string()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn film(variance: bool) -> Film {
        let (width, height) = (7, 5);
        let mean = (0..width * height)
            .map(|i| DVec3::new(i as f64 / 3.0, 0.1 * i as f64, 1.0 - 0.01 * i as f64))
            .collect();
        Film {
            width,
            height,
            samples_per_pixel: 4,
            mean,
            variance: variance.then(|| {
                (0..width * height)
                    .map(|i| DVec3::new(0.0, 1e-3 * i as f64, 0.25))
                    .collect()
            }),
            deviation: variance.then(|| {
                (0..width * height)
                    .map(|i| DVec3::new(0.0, 0.1 + 1e-3 * i as f64, 0.7))
                    .collect()
            }),
        }
    }

    fn attrs() -> Vec<(String, String)> {
        [("zeta", "last"), ("alpha", "first"), ("mid", "ünïcode ✓")]
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect()
    }

    #[test]
    fn round_trip_keeps_f32_values_and_attributes() {
        let f = film(true);
        let bytes = encode_exr(&f, &attrs(), Path::new("t.exr")).unwrap();
        let back = decode_exr(&bytes, Path::new("t.exr")).unwrap();
        assert_eq!((back.width, back.height), (7, 5));
        for (a, b) in f.mean.iter().zip(&back.mean) {
            assert_eq!([a.x as f32, a.y as f32, a.z as f32], *b);
        }
        let v = back.variance.clone().unwrap();
        for (a, b) in f.variance.unwrap().iter().zip(&v) {
            assert_eq!([a.x as f32, a.y as f32, a.z as f32], *b);
        }
        // The deviation is a bound: rounded up to the next f32 when f32 cannot hold it.
        let d = back.deviation.clone().unwrap();
        for (a, b) in f.deviation.unwrap().iter().zip(&d) {
            for (x, y) in a.to_array().into_iter().zip(*b) {
                let below = if y > 0.0 {
                    f32::from_bits(y.to_bits() - 1)
                } else {
                    -1.0
                };
                assert!(f64::from(y) >= x && f64::from(below) < x, "{x} {y}");
            }
        }
        // 0.1 rounds up to f32 anyway; 0.7 rounds down to nearest, so it is stored one up.
        assert!(f64::from(0.7f32) < 0.7);
        assert_eq!(d[0], [0.0, 0.1f32, f32::from_bits(0.7f32.to_bits() + 1)]);
        assert_eq!(back.attribute("mid"), Some("ünïcode ✓"));
        assert_eq!(back.attribute("alpha"), Some("first"));
        let names: Vec<&str> = back.attributes.iter().map(|(k, _)| k.as_str()).collect();
        assert_eq!(names, ["alpha", "mid", "zeta"]);
    }

    /// Widening is exact: the film an EXR holds, written again, gives the same bytes.
    #[test]
    fn to_film_writes_back_the_same_bytes() {
        let bytes = encode_exr(&film(true), &attrs(), Path::new("t.exr")).unwrap();
        let back = decode_exr(&bytes, Path::new("t.exr")).unwrap();
        let again = back.to_film(4);
        assert!(again.deviation.is_some() && again.variance.is_some());
        assert_eq!(
            encode_exr(&again, &attrs(), Path::new("t.exr")).unwrap(),
            bytes
        );
    }

    #[test]
    fn no_variance_layer_reads_back_as_none() {
        let bytes = encode_exr(&film(false), &[], Path::new("t.exr")).unwrap();
        let back = decode_exr(&bytes, Path::new("t.exr")).unwrap();
        assert!(back.variance.is_none());
        assert!(back.deviation.is_none());
        assert!(back.attributes.is_empty());
    }

    #[test]
    fn same_input_gives_same_bytes_whatever_the_attribute_order() {
        // exr keeps custom attributes in a HashMap with a random seed per map: without sorting,
        // these encodings would differ in their header.
        let mut reversed = attrs();
        reversed.reverse();
        let first = encode_exr(&film(true), &attrs(), Path::new("t.exr")).unwrap();
        for _ in 0..8 {
            assert_eq!(
                encode_exr(&film(true), &attrs(), Path::new("t.exr")).unwrap(),
                first
            );
            assert_eq!(
                encode_exr(&film(true), &reversed, Path::new("t.exr")).unwrap(),
                first
            );
        }
    }

    #[test]
    fn header_attributes_are_in_byte_order() {
        let bytes = encode_exr(&film(true), &attrs(), Path::new("t.exr")).unwrap();
        let mut names = Vec::new();
        let mut at = 8;
        while bytes[at] != 0 {
            let name_len = bytes[at..].iter().position(|&b| b == 0).unwrap();
            let name = bytes[at..at + name_len].to_vec();
            let type_len = bytes[at + name_len + 1..]
                .iter()
                .position(|&b| b == 0)
                .unwrap();
            let size_at = at + name_len + 1 + type_len + 1;
            let size = i32::from_le_bytes(bytes[size_at..size_at + 4].try_into().unwrap());
            names.push(name);
            at = size_at + 4 + size as usize;
        }
        let mut sorted = names.clone();
        sorted.sort();
        assert_eq!(names, sorted);
        // The standard attributes and ours.
        assert!(names.contains(&b"channels".to_vec()));
        assert!(names.contains(&b"zeta".to_vec()));
    }

    #[test]
    fn bad_files_are_one_line_errors_naming_the_file() {
        let p = Path::new("bad.exr");
        let err = decode_exr(b"P6 not an exr", p).unwrap_err().to_string();
        assert!(err.starts_with("bad.exr: is not an OpenEXR file"), "{err}");
        let err = decode_exr(b"", p).unwrap_err().to_string();
        assert!(err.contains("not an OpenEXR file"), "{err}");

        let good = encode_exr(&film(true), &attrs(), p).unwrap();
        // Cut anywhere: in the header, in the offset table, in the pixel data.
        for cut in [5, 20, 100, good.len() / 2, good.len() - 1] {
            let err = decode_exr(&good[..cut], p).unwrap_err().to_string();
            assert!(err.starts_with("bad.exr: "), "{cut}: {err}");
            assert_eq!(err.lines().count(), 1, "{err}");
        }
    }

    #[test]
    fn damaged_bytes_never_panic() {
        let good = encode_exr(&film(true), &attrs(), Path::new("t.exr")).unwrap();
        for at in 4..good.len() {
            for value in [0u8, 1, 0x7f, 0x80, 0xff, good[at] ^ 0x10] {
                let mut bad = good.clone();
                bad[at] = value;
                // Either an error or an image; never a panic or an absurd allocation.
                if let Ok(img) = decode_exr(&bad, Path::new("t.exr")) {
                    assert_eq!(img.mean.len(), img.width * img.height);
                }
            }
        }
    }

    #[test]
    fn missing_rgb_is_an_error_listing_the_channels() {
        let layer = Layer::new(
            (2, 2),
            LayerAttributes::default(),
            Encoding::UNCOMPRESSED,
            AnyChannels::sort(SmallVec::from_vec(vec![AnyChannel::new(
                "Y",
                FlatSamples::F32(vec![0.5; 4]),
            )])),
        );
        let mut bytes = Cursor::new(Vec::new());
        Image::from_layer(layer)
            .write()
            .non_parallel()
            .to_buffered(&mut bytes)
            .unwrap();
        let err = decode_exr(bytes.get_ref(), Path::new("grey.exr"))
            .unwrap_err()
            .to_string();
        assert_eq!(err, "grey.exr: has no R, G, B channels (it has Y)");
    }

    #[test]
    fn reads_ordinary_half_rgba() {
        use exr::prelude::f16;
        let ch = |n: &str, v: f32| AnyChannel::new(n, FlatSamples::F16(vec![f16::from_f32(v); 6]));
        let layer = Layer::new(
            (3, 2),
            LayerAttributes::default(),
            Encoding::FAST_LOSSLESS,
            AnyChannels::sort(SmallVec::from_vec(vec![
                ch("R", 0.5),
                ch("G", 0.25),
                ch("B", 2.0),
                ch("A", 1.0),
            ])),
        );
        let mut bytes = Cursor::new(Vec::new());
        Image::from_layer(layer)
            .write()
            .non_parallel()
            .to_buffered(&mut bytes)
            .unwrap();
        let img = decode_exr(bytes.get_ref(), Path::new("rgba.exr")).unwrap();
        assert_eq!((img.width, img.height), (3, 2));
        assert!(img.mean.iter().all(|p| *p == [0.5, 0.25, 2.0]));
        assert!(img.variance.is_none());
    }

    #[test]
    fn attribute_names_are_checked() {
        let f = film(false);
        let p = Path::new("t.exr");
        let dup = vec![("a".to_string(), "1".into()), ("a".to_string(), "2".into())];
        assert!(encode_exr(&f, &dup, p).is_err());
        assert!(encode_exr(&f, &[(String::new(), "x".into())], p).is_err());
        assert!(encode_exr(&f, &[("channels".into(), "x".into())], p).is_err());
    }
}
