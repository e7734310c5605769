//! The noise-aware image comparison: is a candidate image a render of the golden's scene with
//! `N` samples per pixel, or does it differ by more than Monte Carlo noise can explain?
//!
//! Each 8-bit code is an interval of linear values under the chosen [`Encoding`]; the golden
//! gives each pixel's mean and per-sample variance; Bernstein bounds turn the distance from the
//! candidate's interval to the golden's mean into p-values at four scales (pixel, 8x8 tile,
//! 32x32 tile, whole image), each given a quarter of the per-image false-failure rate and
//! adjusted with Šidák's formula over its tests. When an image fails, [`diagnose`] tests the
//! common mistakes as alternative hypotheses. See `docs/comparing-images.md`.

pub mod encoding;
pub mod candidate;
pub mod flip;
pub mod heatmap;
pub mod noise_model;
pub mod regions;
pub mod report;
pub mod stats;
pub mod twosample;
pub mod verdict;
pub mod diagnose;

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::image_io::ImageError;
use candidate::CandidateImage;
use encoding::Encoding;
use noise_model::Golden;
use verdict::evaluate;

/// What stops a comparison (one line, naming the file when there is one).
#[derive(Debug, thiserror::Error)]
pub enum CompareError {
    /// An image could not be read.
    #[error(transparent)]
    Image(#[from] ImageError),
    /// A file was read but cannot be used as asked.
    #[error("{path}: {message}")]
    Input {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        message: String,
    },
    /// The golden is unusable.
    #[error("golden: {0}")]
    Golden(String),
    /// The report folder cannot be written (or may not be replaced).
    #[error(transparent)]
    Output(#[from] crate::output::OutputError),
}

/// How to compare.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CompareOptions {
    /// The candidate's samples per pixel `N`.
    pub samples_per_pixel: u32,
    /// The encoding the assignment asks for (how 8-bit codes are read).
    pub encoding: Encoding,
    /// The per-image false-failure rate, split equally across the four scales.
    pub alpha: f64,
    /// How much more per-sample variance than the golden's an honest sampler may have.
    pub lambda: f64,
    /// Test the common mistakes when the image fails.
    pub diagnose: bool,
}

impl Default for CompareOptions {
    fn default() -> Self {
        Self {
            samples_per_pixel: 20,
            encoding: Encoding::Course,
            alpha: 1e-4,
            lambda: 2.25,
            diagnose: true,
        }
    }
}

/// Pass or fail.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Verdict {
    /// Within Monte Carlo noise at every scale.
    Pass,
    /// Outside it at some scale.
    Fail,
}

/// The result at one scale.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ScaleResult {
    /// `pixel`, `tile8`, `tile32` or `global`.
    pub scale: String,
    /// Number of tests (pixel or tile and channel) at this scale.
    pub tests: usize,
    /// The smallest p-value after Šidák's adjustment for `tests`.
    pub smallest_adjusted_p: f64,
    /// The threshold: a quarter of the per-image false-failure rate.
    pub threshold: f64,
    /// The largest `|z|` (distance over standard error) at this scale.
    pub largest_abs_z: f64,
    /// Tests whose adjusted p fell below the threshold.
    pub failing: usize,
}

/// A failing region of the image.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Region {
    /// Left column.
    pub x: usize,
    /// Top row.
    pub y: usize,
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// The scale of the strongest evidence inside.
    pub scale: String,
    /// The channel of the strongest evidence (`R`, `G` or `B`).
    pub channel: String,
    /// The smallest adjusted p inside.
    pub adjusted_p: f64,
    /// Its signed z: positive when the candidate is brighter than the golden.
    pub z: f64,
    /// What each channel does inside, in words ("red up, blue down: a different colour, not a
    /// brighter one"; see [`regions::channel_change`]).
    #[serde(default)]
    pub change: Option<String>,
}

/// The noise check: is the candidate no noisier than `N` samples per pixel allow? The squared
/// differences from the golden over the pixels whose noise shows through the quantisation are
/// summed and compared with their bound under the claim (Bernstein's inequality; false-failure
/// bound [`NOISE_ALPHA`](verdict::NOISE_ALPHA)), so a 1-spp image does not pass as 41 spp.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct NoiseCheck {
    /// The samples per pixel claimed (`--spp`).
    pub claimed_spp: u32,
    /// The samples per pixel the candidate's noise suggests.
    pub effective_spp: Option<f64>,
    /// The pixels (and channels) the check used.
    pub pixels: usize,
    /// The p-value of the squared differences under the claim.
    pub p: f64,
    /// The threshold.
    pub threshold: f64,
    /// Whether `p >= threshold`.
    pub passed: bool,
}

/// One alternative hypothesis the diagnosis tried.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct HypothesisScore {
    /// Short name (`encoding:linear`, `flip-y`, `flip-x`, `bgr`, `shift:+0.5`, `shift:-0.5`).
    pub name: String,
    /// The mistake it stands for, in words.
    pub mistake: String,
    /// Its misfit over the misfit of the image as given (below 1 explains some of it).
    pub misfit_ratio: f64,
    /// Whether the image passes under this hypothesis.
    pub passes: bool,
}

/// What the diagnosis found.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Diagnosis {
    /// One sentence: the mistake that explains the image, or that none does.
    pub summary: String,
    /// The best hypothesis's name, when one explains the image.
    pub best: Option<String>,
    /// Every hypothesis tried, best first.
    pub hypotheses: Vec<HypothesisScore>,
}

/// The full result of a comparison (serialised as the JSON report).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Comparison {
    /// Pass or fail.
    pub verdict: Verdict,
    /// The candidate's file, as given, when it came from one.
    #[serde(default)]
    pub candidate: Option<String>,
    /// Image width.
    pub width: usize,
    /// Image height.
    pub height: usize,
    /// The candidate's samples per pixel.
    pub candidate_spp: u32,
    /// The golden's samples per pixel.
    pub golden_spp: u32,
    /// The golden's scene, when known.
    pub scene: Option<String>,
    /// How the candidate's codes were read (`exr` for linear candidates).
    pub encoding: String,
    /// The per-image false-failure rate.
    pub alpha: f64,
    /// One entry per scale: pixel, tile8, tile32, global.
    pub scales: Vec<ScaleResult>,
    /// The failing regions, worst first (at most 50; `regions_total` says how many there are).
    pub regions: Vec<Region>,
    /// How many failing regions there are in all.
    #[serde(default)]
    pub regions_total: usize,
    /// Every failing region (the heatmap outlines them all).
    #[serde(skip)]
    pub outline: Vec<Region>,
    /// Whether the candidate is as noisy as its claimed samples per pixel allow (absent when
    /// too few pixels show their noise through the quantisation).
    #[serde(default)]
    pub noise: Option<NoiseCheck>,
    /// Mean of (candidate - golden) per channel, linear, over all pixels (mid-points of the
    /// candidate's intervals).
    pub bias: [f64; 3],
    /// How far, not whether: relMSE, the mean over pixels and channels of `(candidate -
    /// golden)^2 / (golden^2 + 0.01)` (the candidate's mid-points; in `compare A B`, A's means
    /// against B's). It never decides the verdict. Absent from reports written before it.
    #[serde(default)]
    pub rel_mse: Option<f64>,
    /// How far, as people see it: NVIDIA's FLIP of the candidate against the golden (in
    /// `compare A B`, of A against B) as an sRGB display shows them ([`flip`]). It never decides
    /// the verdict. Absent from reports written before it.
    #[serde(default)]
    pub flip: Option<flip::FlipSummary>,
    /// FLIP's error per pixel, for the HTML report's map (empty when there is none).
    #[serde(skip)]
    pub flip_map: Vec<f32>,
    /// The candidate's samples per pixel as its noise suggests (from the noisy pixels).
    pub effective_spp: Option<f64>,
    /// The diagnosis, when the image fails and diagnosis was asked for.
    pub diagnosis: Option<Diagnosis>,
    /// Signed z per pixel and channel, clamped to +-1000; for pictures.
    #[serde(skip)]
    pub z_map: Vec<[f32; 3]>,
}

impl Comparison {
    /// Records FLIP's summary and map (none when `flip` is `None`).
    pub fn set_flip(&mut self, flip: Option<flip::Flip>) {
        (self.flip, self.flip_map) = match flip {
            Some(f) => (Some(f.summary), f.map),
            None => (None, Vec::new()),
        };
    }

    /// Whether the candidate passed.
    pub fn passed(&self) -> bool {
        self.verdict == Verdict::Pass
    }

    /// The noise check in plain words: "the pixels differ from the golden as much as a render of
    /// about 2.4 spp would, not 20 spp (p 1.2e-30 < 1e-6)", or that they are within the noise of
    /// the claim, or that too few pixels show their noise to tell.
    pub fn noise_sentence(&self) -> String {
        let Some(n) = &self.noise else {
            return format!(
                "noise: too few pixels show their noise through the codes to tell the candidate's samples per pixel (judged as {} spp)",
                self.candidate_spp
            );
        };
        let about = |fewer: &str| {
            n.effective_spp
                .map_or_else(|| fewer.to_string(), |e| format!("about {e:.1}"))
        };
        if n.passed {
            format!(
                "noise: the pixels differ from the golden as much as a render of {} spp would, within the noise of {} spp (p {:.2e} >= {:.0e})",
                about("at least"),
                n.claimed_spp,
                n.p,
                n.threshold
            )
        } else {
            format!(
                "noise: the pixels differ from the golden as much as a render of {} spp would, not {} spp (p {:.2e} < {:.0e})",
                about("fewer"),
                n.claimed_spp,
                n.p,
                n.threshold
            )
        }
    }
}

/// Compares a candidate with a golden. Errors when the sizes differ.
pub fn compare_image(
    candidate: &CandidateImage,
    golden: &Golden,
    options: &CompareOptions,
) -> Result<Comparison, CompareError> {
    let (w, h) = candidate.size();
    if (w, h) != (golden.width, golden.height) {
        return Err(CompareError::Golden(format!(
            "the candidate is {w}x{h} but the golden is {}x{}",
            golden.width, golden.height
        )));
    }
    if options.samples_per_pixel == 0 {
        return Err(CompareError::Golden(
            "the candidate's samples per pixel must be at least 1".into(),
        ));
    }
    let evaluation = evaluate(candidate, golden, options.encoding, options);
    let diagnosis = if !evaluation.passed && options.diagnose {
        Some(diagnose::diagnose(candidate, golden, options, &evaluation))
    } else {
        None
    };
    let mut comparison = evaluation.into_comparison(candidate, golden, options, diagnosis);
    let test = candidate.linear_mid_points(options.encoding);
    comparison.set_flip(flip::flip_of(&golden.mean, &test, w, h));
    Ok(comparison)
}

/// Reads a candidate file and compares it, naming the file in errors (size mismatches too).
pub fn compare_file(
    path: &Path,
    golden: &Golden,
    options: &CompareOptions,
) -> Result<Comparison, CompareError> {
    let candidate = CandidateImage::load(path)?;
    check_size(path, &candidate, golden.width, golden.height)?;
    let mut comparison = compare_image(&candidate, golden, options)?;
    comparison.candidate = Some(path.display().to_string());
    Ok(comparison)
}

/// Checks the candidate has the golden's size, with an error naming the file.
pub fn check_size(
    path: &Path,
    candidate: &CandidateImage,
    width: usize,
    height: usize,
) -> Result<(), CompareError> {
    let (w, h) = candidate.size();
    if (w, h) != (width, height) {
        return Err(CompareError::Input {
            path: path.to_path_buf(),
            message: format!("is {w}x{h} but the golden is {width}x{height}"),
        });
    }
    Ok(())
}
