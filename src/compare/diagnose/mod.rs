//! When an image fails: test the common mistakes as alternative hypotheses and name the one
//! that explains the image.
//!
//! `hypotheses` holds each mistake's transform of the golden (a scale, a zoom, a colour change);
//! [`mistakes`] is the catalogue of those mistakes injected into the reference renderer, the
//! images the comparison must reject and this diagnosis must name (used by tests and the
//! benchmark).

mod hypotheses;
pub mod mistakes;

use rayon::prelude::*;

use super::{
    CompareOptions, Diagnosis, HypothesisScore, candidate::CandidateImage, encoding::ENCODINGS,
    encoding::Encoding, noise_model::Golden, verdict::Evaluation, verdict::evaluate,
};

/// A hypothesis must remove at least this share of the misfit to be named as the explanation.
const EXPLAINS: f64 = 0.5;

fn encoding_mistake(e: Encoding, asked: Encoding) -> String {
    match e {
        Encoding::Linear => "fits the golden with no gamma applied (linear values written as codes)".into(),
        Encoding::Gamma22 => format!("fits the golden encoded with gamma 2.2, where the {asked} encoding is asked for"),
        Encoding::Srgb => format!("fits the golden encoded with the sRGB curve, where the {asked} encoding is asked for"),
        Encoding::Rtiow => "fits the golden encoded as the book does (256 * clamp(sqrt(x), 0, 0.999)), not as the course does (255 * ...)".into(),
        Encoding::GammaTwice => "fits the golden with the gamma applied twice (sqrt of sqrt: a value already gamma-encoded encoded again)".into(),
        Encoding::Course => "fits the golden encoded as the course does (255 * clamp(sqrt(x), 0, 0.999), truncated)".into(),
    }
}

/// The image whose pixel `(i, j)` is the candidate's pixel `from(i, j, width, height)`: a flip.
fn remapped(
    c: &CandidateImage,
    from: impl Fn(usize, usize, usize, usize) -> (usize, usize),
) -> CandidateImage {
    let (width, height) = c.size();
    let sources = (0..height)
        .flat_map(|j| (0..width).map(move |i| (i, j)))
        .map(|(i, j)| {
            let (si, sj) = from(i, j, width, height);
            sj * width + si
        });
    match c {
        CandidateImage::Rgb8 { data, .. } => CandidateImage::Rgb8 {
            width,
            height,
            data: sources
                .flat_map(|k| data[3 * k..3 * k + 3].iter().copied())
                .collect(),
        },
        CandidateImage::Linear { data, .. } => CandidateImage::Linear {
            width,
            height,
            data: sources.map(|k| data[k]).collect(),
        },
    }
}

/// The image with its rows in reverse order.
fn flip_y(c: &CandidateImage) -> CandidateImage {
    remapped(c, |i, j, _, h| (i, h - 1 - j))
}

/// The image with each row's pixels in reverse order (mirrored left to right).
fn flip_x(c: &CandidateImage) -> CandidateImage {
    remapped(c, |i, j, w, _| (w - 1 - i, j))
}

fn bgr(c: &CandidateImage) -> CandidateImage {
    match c {
        CandidateImage::Rgb8 {
            width,
            height,
            data,
        } => CandidateImage::Rgb8 {
            width: *width,
            height: *height,
            data: data
                .chunks_exact(3)
                .flat_map(|p| [p[2], p[1], p[0]])
                .collect(),
        },
        CandidateImage::Linear {
            width,
            height,
            data,
        } => CandidateImage::Linear {
            width: *width,
            height: *height,
            data: data.iter().map(|p| [p[2], p[1], p[0]]).collect(),
        },
    }
}

enum Try {
    Encoding(Encoding),
    FlipY,
    FlipX,
    Bgr,
    Shift(i32),
    /// Every linear value times `k` (per channel).
    Scale([f64; 3]),
    /// The image zoomed by `s` about its centre.
    Zoom(f64),
}

/// Scales within this of each other are "the same in every channel".
const SAME_SCALE: f64 = 0.02;

/// The exponent that turns a linear factor into the factor of the codes written under
/// `encoding` (codes are `x^(1/gamma)`, so a linear `k` is the codes times `k^(1/gamma)`; sRGB's
/// curve is `x^(1/2.4)` but for its dark end, so its factor is approximate there).
fn code_gamma(encoding: Encoding) -> f64 {
    match encoding {
        Encoding::Course | Encoding::Rtiow => 2.0,
        Encoding::Srgb => 2.4,
        Encoding::Gamma22 => 2.2,
        Encoding::Linear => 1.0,
        Encoding::GammaTwice => 4.0,
    }
}

/// How much darker or brighter a factor `f` makes what it multiplies: `10% darker`.
fn change_words(f: f64) -> String {
    let way = if f < 1.0 { "darker" } else { "brighter" };
    format!("{:.0}% {way}", 100.0 * (f - 1.0).abs())
}

/// The name and words of a uniform scale `k` of the linear values, said in the terms of the
/// file judged: for an 8-bit PNG the factor of its codes (under the `encoding` asked for), with
/// the linear factor beside it (`every code times 0.90 (linear x0.81)`: the picture darkened by
/// 10%); for an EXR (`codes` false) the factor of its values, which are linear.
fn scale_mistake(k: [f64; 3], codes: Option<Encoding>) -> (String, String) {
    let (lo, hi) = (
        k.iter().copied().fold(f64::INFINITY, f64::min),
        k.iter().copied().fold(0.0, f64::max),
    );
    // The factor of the file's own numbers, and the linear one beside it (for codes).
    let said = |k: f64| match codes {
        Some(e) => (k.powf(1.0 / code_gamma(e)), format!(" (linear x{k:.2})")),
        None => (k, String::new()),
    };
    let what = if codes.is_some() { "code" } else { "value" };
    if hi - lo <= SAME_SCALE * hi {
        let m = (k[0] + k[1] + k[2]) / 3.0;
        let (f, linear) = said(m);
        let how = match codes {
            Some(_) => format!("{} in the picture", change_words(f)),
            None => change_words(f),
        };
        (
            format!("scale:{m:.2}"),
            format!(
                "fits the golden with every {what} times {f:.2}{linear} (the same in red, green and blue: {how}): an exposure or brightness change, a light's strength, or every albedo scaled"
            ),
        )
    } else {
        let part = |name: &str, k: f64| {
            let (f, linear) = said(k);
            format!("{name} {what}s times {f:.2}{linear}")
        };
        (
            format!("scale:{:.2},{:.2},{:.2}", k[0], k[1], k[2]),
            format!(
                "fits the golden with {}, {} and {}: a colour cast (a light's or the albedos' colour scaled per channel)",
                part("red", k[0]),
                part("green", k[1]),
                part("blue", k[2])
            ),
        )
    }
}

/// The name and words of a zoom by `s` about the centre, naming the field of view when the
/// golden's is known.
fn zoom_mistake(s: f64, vfov: Option<f64>) -> (String, String) {
    let how = if s > 1.0 {
        format!("magnified {s:.3} times")
    } else {
        format!("shrunk to {s:.3} of its size")
    };
    let why = match vfov {
        Some(v) => format!(
            "a vertical field of view of about {:.1} degrees where the scene's is {v}, or the camera {} the scene",
            hypotheses::zoomed_vfov(v, s),
            if s > 1.0 { "closer to" } else { "farther from" }
        ),
        None => "a field of view or a camera distance that differs from the scene's".to_string(),
    };
    (
        format!("zoom:{s:.3}"),
        format!("fits the golden {how} about the centre: {why}"),
    )
}

/// Evaluates the candidate under one hypothesis: its name, the mistake in words, the result.
fn attempt(
    t: &Try,
    candidate: &CandidateImage,
    golden: &Golden,
    options: &CompareOptions,
) -> (String, String, Evaluation) {
    let asked = options.encoding;
    match *t {
        Try::Encoding(e) => (
            format!("encoding:{e}"),
            encoding_mistake(e, asked),
            evaluate(candidate, golden, e, options),
        ),
        Try::FlipY => (
            "flip-y".to_string(),
            "fits the golden upside down: rows written bottom to top (y flipped)"
                .to_string(),
            evaluate(&flip_y(candidate), golden, asked, options),
        ),
        Try::FlipX => (
            "flip-x".to_string(),
            "fits the golden mirrored left to right: columns written right to left, or the camera's horizontal axis reversed (x flipped)"
                .to_string(),
            evaluate(&flip_x(candidate), golden, asked, options),
        ),
        Try::Bgr => (
            "bgr".to_string(),
            "fits the golden with red and blue swapped: channels written in BGR order"
                .to_string(),
            evaluate(&bgr(candidate), golden, asked, options),
        ),
        Try::Shift(s) if s > 0 => (
            "shift:+0.5".to_string(),
            "fits the golden shifted half a pixel right and down: samples jittered in [0, 1) instead of [-0.5, 0.5)".to_string(),
            evaluate(candidate, &golden.half_pixel_shifted(1), asked, options),
        ),
        Try::Shift(_) => (
            "shift:-0.5".to_string(),
            "fits the golden shifted half a pixel left and up: a half-pixel camera shift (pixel00 without its half-pixel offset?)".to_string(),
            evaluate(candidate, &golden.half_pixel_shifted(-1), asked, options),
        ),
        Try::Scale(k) => {
            let codes = matches!(candidate, CandidateImage::Rgb8 { .. }).then_some(asked);
            let (name, mistake) = scale_mistake(k, codes);
            let e = evaluate(candidate, &hypotheses::scaled(golden, k), asked, options);
            (name, mistake, e)
        }
        Try::Zoom(s) => {
            let (name, mistake) = zoom_mistake(s, golden.vfov);
            let e = evaluate(candidate, &hypotheses::zoomed(golden, s), asked, options);
            (name, mistake, e)
        }
    }
}

/// Tries every hypothesis on a failed image and names the best one that explains at least half
/// of the misfit.
pub fn diagnose(
    candidate: &CandidateImage,
    golden: &Golden,
    options: &CompareOptions,
    base: &Evaluation,
) -> Diagnosis {
    let asked = options.encoding;
    let mut tries: Vec<Try> = Vec::new();
    if matches!(candidate, CandidateImage::Rgb8 { .. }) {
        for e in ENCODINGS.into_iter().filter(|&e| e != asked) {
            tries.push(Try::Encoding(e));
        }
    }
    tries.extend([
        Try::FlipY,
        Try::FlipX,
        Try::Bgr,
        Try::Shift(1),
        Try::Shift(-1),
    ]);
    if let Some(k) = hypotheses::channel_scales(candidate, golden, asked)
        .filter(|k| k.iter().any(|x| (x - 1.0).abs() > 0.005))
    {
        tries.push(Try::Scale(k));
    }
    if let Some(s) = hypotheses::best_zoom(candidate, golden, asked) {
        tries.push(Try::Zoom(s));
    }
    // The hypotheses are independent: evaluate them in parallel (each is deterministic).
    let mut scores: Vec<HypothesisScore> = tries
        .par_iter()
        .map(|t| {
            let (name, mistake, e) = attempt(t, candidate, golden, options);
            HypothesisScore {
                name,
                mistake,
                misfit_ratio: if base.misfit > 0.0 {
                    e.misfit / base.misfit
                } else {
                    1.0
                },
                passes: e.passed,
            }
        })
        .collect();
    scores.sort_by(|a, b| {
        b.passes
            .cmp(&a.passes)
            .then(a.misfit_ratio.total_cmp(&b.misfit_ratio))
    });
    let best = scores
        .first()
        .filter(|s| s.passes || s.misfit_ratio < EXPLAINS)
        .cloned();
    let summary = match &best {
        Some(s) if s.passes => s.mistake.clone(),
        Some(s) => format!(
            "closest explanation: {} (it removes {:.0}% of the misfit but the image still fails)",
            s.mistake,
            100.0 * (1.0 - s.misfit_ratio)
        ),
        None => "no common mistake explains the image (tried other encodings, y flipped, x flipped, BGR, half-pixel shifts, a uniform scale, a zoom): look at the failing regions".into(),
    };
    Diagnosis {
        summary,
        best: best.map(|s| s.name),
        hypotheses: scores,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scale is said in the file's own numbers: a PNG's codes under the course's encoding
    /// (codes are sqrt of the linear values, so linear x0.81 is every code times 0.9), an EXR's
    /// linear values as they are; the other factor beside it.
    #[test]
    fn a_scale_is_said_in_the_encoding_of_the_file_judged() {
        let (_, png) = scale_mistake([0.81; 3], Some(Encoding::Course));
        assert!(
            png.contains("every code times 0.90 (linear x0.81)")
                && png.contains("10% darker in the picture"),
            "{png}"
        );
        let (_, exr) = scale_mistake([0.81; 3], None);
        assert!(
            exr.contains("every value times 0.81 (") && exr.contains("19% darker"),
            "{exr}"
        );
        assert!(!exr.contains("linear x"), "{exr}");
        // Gamma 2.2: codes times 0.81^(1/2.2) = 0.9087.
        let (_, g22) = scale_mistake([0.81; 3], Some(Encoding::Gamma22));
        assert!(
            g22.contains("every code times 0.91 (linear x0.81)"),
            "{g22}"
        );
        // No curve: the codes are the linear values.
        let (_, lin) = scale_mistake([0.81; 3], Some(Encoding::Linear));
        assert!(
            lin.contains("every code times 0.81 (linear x0.81)"),
            "{lin}"
        );
        let (_, cast) = scale_mistake([0.64, 1.0, 1.21], Some(Encoding::Course));
        assert!(
            cast.contains("red codes times 0.80 (linear x0.64), green codes times 1.00 (linear x1.00) and blue codes times 1.10 (linear x1.21)"),
            "{cast}"
        );
    }

    /// On a 3 x 2 image of distinct pixels, both kinds: y reverses the rows, x each row, and
    /// both twice give the image back.
    #[test]
    fn flips_reverse_rows_or_columns() {
        let rgb = CandidateImage::Rgb8 {
            width: 3,
            height: 2,
            data: (0..18).collect(),
        };
        let pixels = |c: &CandidateImage| match c {
            CandidateImage::Rgb8 { data, .. } => {
                data.chunks(3).map(|p| p[0] / 3).collect::<Vec<_>>()
            }
            CandidateImage::Linear { data, .. } => data.iter().map(|p| p[0] as u8).collect(),
        };
        assert_eq!(pixels(&flip_y(&rgb)), [3, 4, 5, 0, 1, 2]);
        assert_eq!(pixels(&flip_x(&rgb)), [2, 1, 0, 5, 4, 3]);
        let linear = CandidateImage::Linear {
            width: 3,
            height: 2,
            data: (0..6).map(|k| [k as f32, 0.0, 0.0]).collect(),
        };
        assert_eq!(pixels(&flip_y(&linear)), [3, 4, 5, 0, 1, 2]);
        assert_eq!(pixels(&flip_x(&linear)), [2, 1, 0, 5, 4, 3]);
        assert_eq!(pixels(&flip_x(&flip_x(&rgb))), pixels(&rgb));
        // Channels stay with their pixel.
        match flip_x(&rgb) {
            CandidateImage::Rgb8 { data, .. } => assert_eq!(data[..3], [6, 7, 8]),
            _ => unreachable!(),
        }
    }
}
