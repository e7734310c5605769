//! The copy checks against the course's images, independent renders and copies of them.

use super::*;
use crate::image_io::{encode_png, read_png};

fn small_render(scene: &str, seed: u64) -> Rgb8Image {
    let d = crate::scene::builtin(scene).unwrap();
    render_png_pixels(&d, Some(96), seed).unwrap()
}

/// `image` written as a PNG another way and read back: RGBA with an opaque alpha channel, the
/// strongest compression with an adaptive filter, and a text chunk.
fn re_encoded(image: &Rgb8Image) -> Rgb8Image {
    use image::ImageEncoder;
    use image::codecs::png::{CompressionType, FilterType, PngEncoder};
    let rgba: Vec<u8> = image
        .data
        .chunks_exact(3)
        .flat_map(|p| [p[0], p[1], p[2], 255])
        .collect();
    let mut bytes = Vec::new();
    PngEncoder::new_with_quality(&mut bytes, CompressionType::Best, FilterType::Adaptive)
        .write_image(
            &rgba,
            image.width as u32,
            image.height as u32,
            image::ExtendedColorType::Rgba8,
        )
        .unwrap();
    let bytes = with_text_chunk(&bytes, "Software", "an image editor");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("re-encoded.png");
    std::fs::write(&path, bytes).unwrap();
    read_png(&path).unwrap()
}

fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= b as u32;
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0xedb8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

/// `png` with a `tEXt` chunk after its header chunk.
fn with_text_chunk(png: &[u8], key: &str, text: &str) -> Vec<u8> {
    let ihdr_end = 8 + 4 + 4 + 13 + 4;
    let mut body = b"tEXt".to_vec();
    body.extend(key.as_bytes());
    body.push(0);
    body.extend(text.as_bytes());
    let mut out = png[..ihdr_end].to_vec();
    out.extend(((body.len() - 4) as u32).to_be_bytes());
    out.extend(&body);
    out.extend(crc32(&body).to_be_bytes());
    out.extend(&png[ihdr_end..]);
    out
}

/// `image` with `k` of its busy pixels (the ones the comparison reads) set to other values.
fn with_pixels_changed(image: &Rgb8Image, k: usize, salt: u64) -> Rgb8Image {
    let fp = Fingerprint::of(image);
    let mut out = image.clone();
    let n = fp.busy.len() as u64;
    for i in 0..k as u64 {
        let (pos, v) = fp.busy[((i * 7919 + salt * 104_729) % n) as usize];
        let j = 3 * pos as usize;
        out.data[j..j + 3].copy_from_slice(&v.map(|c| c.wrapping_add(128)));
    }
    out
}

/// The figures `docs/grading.md` states ("Copies"): `cargo test --lib grade::checkers::copies::tests --
/// --nocapture`. 21 independent renders of each course scene (seeds 1 to 21, 96 pixels wide,
/// the scene's 20 samples per pixel) make 210 pairs each; none may share its noise, and every
/// copy of each render (as it is, re-encoded, with 1, 3 or 10 pixels changed) must.
#[test]
fn independent_renders_never_share_noise_and_copies_always_do() {
    let mut pairs = 0;
    let mut false_flags = 0;
    let mut copies = 0;
    let mut detected = 0;
    let mut least_independent = f64::INFINITY;
    let mut most_copied = 0.0f64;
    for scene in ["week04-sphere", "week04-quad"] {
        let renders: Vec<Rgb8Image> = (1..=21).map(|s| small_render(scene, s)).collect();
        let prints: Vec<Fingerprint> = renders.iter().map(Fingerprint::of).collect();
        for (i, a) in prints.iter().enumerate() {
            for b in &prints[i + 1..] {
                let m = shared_noise(a, b);
                pairs += 1;
                false_flags += m.shared as usize;
                least_independent =
                    least_independent.min(m.differing as f64 / m.common_busy.max(1) as f64);
            }
        }
        for (i, r) in renders.iter().enumerate() {
            let mut variants = vec![r.clone(), re_encoded(r)];
            for k in [1, 3, 10] {
                variants.push(with_pixels_changed(r, k, i as u64));
                variants.push(re_encoded(&with_pixels_changed(r, k, i as u64 + 100)));
            }
            for v in variants {
                let m = shared_noise(&prints[i], &Fingerprint::of(&v));
                copies += 1;
                detected += m.shared as usize;
                most_copied = most_copied.max(m.differing as f64 / m.common_busy.max(1) as f64);
            }
        }
    }
    eprintln!(
        "independent pairs: {pairs}, flagged {false_flags}, smallest share of differing busy \
         pixels {least_independent:.3}; copies: {copies}, detected {detected}, largest share \
         {most_copied:.3} (threshold {SHARED_AT_MOST})"
    );
    assert!(pairs >= 400);
    assert_eq!(false_flags, 0);
    assert_eq!(detected, copies);
    // Both sides keep a wide margin from the threshold.
    assert!(
        least_independent > 3.0 * SHARED_AT_MOST,
        "{least_independent}"
    );
    assert!(most_copied < SHARED_AT_MOST / 2.0, "{most_copied}");
}

#[test]
fn the_reference_tracers_own_render_is_recognised_and_another_seeds_is_not() {
    for scene in ["week04-sphere", "week04-quad"] {
        let source = SceneSource::Builtin(scene.into());
        let own = render_default(&source).unwrap();
        let found = recognise(&Fingerprint::of(&re_encoded(&own)), &source);
        assert!(
            matches!(found, Some(CopyFinding::ReferenceRender { .. })),
            "{scene}: {found:?}"
        );
        let changed = with_pixels_changed(&own, 5, 1);
        assert!(recognise(&Fingerprint::of(&changed), &source).is_some());
        let d = crate::scene::builtin(scene).unwrap();
        let other = render_png_pixels(&d, None, 12345).unwrap();
        assert_eq!(
            recognise(&Fingerprint::of(&other), &source),
            None,
            "{scene}"
        );
    }
}

#[test]
fn the_courses_published_images_are_recognised_whatever_their_encoding() {
    let Some(dir) = std::env::var_os("RTORACLE_COURSE_FIXTURES") else {
        eprintln!("skipped: RTORACLE_COURSE_FIXTURES is not set");
        return;
    };
    for (scene, file, _) in COURSE_IMAGES {
        let published = read_png(&std::path::Path::new(&dir).join(file)).unwrap();
        let source = SceneSource::Builtin(scene.into());
        for image in [published.clone(), re_encoded(&published)] {
            let found = recognise(&Fingerprint::of(&image), &source);
            assert_eq!(
                found,
                Some(CopyFinding::CourseImage { file: file.into() }),
                "{file}"
            );
        }
        // Pixel for pixel: one pixel changed is no longer the published image.
        let mut one_off = published.clone();
        one_off.data[0] ^= 1;
        assert_eq!(course_image(&pixels_sha256(&one_off)), None);
        // The published image is an independent render: not the reference's own.
        let reference = reference_render(&source).unwrap();
        assert!(!shared_noise(&Fingerprint::of(&published), &reference).shared);
        // And its encoding is not what matters: the plain re-encoding hashes the same.
        let bytes = encode_png(&published).unwrap();
        let d = tempfile::tempdir().unwrap();
        std::fs::write(d.path().join("x.png"), bytes).unwrap();
        let again = read_png(&d.path().join("x.png")).unwrap();
        assert_eq!(course_image(&pixels_sha256(&again)), Some(file));
    }
}
