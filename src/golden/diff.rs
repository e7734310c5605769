//! Comparing two goldens pixel by pixel: `rtoracle golden --check` and the test suite's insta
//! snapshots use it to tell a regenerated golden from the committed one.

use crate::image_io::ExrImage;

use super::format::{
    ATTR_INPUTS, ATTR_PROFILE, ATTR_SCENE, ATTR_SCENE_SHA256, ATTR_SEED, ATTR_SPP,
};

/// How close two goldens' pixels must be to count as equal: `|a - b| <= absolute + relative *
/// max(|a|, |b|)` for every pixel and channel of the mean and of the variance.
///
/// The reference is bit-reproducible (f64 arithmetic, libm's `tan`, a seeded stream per pixel),
/// so a regenerated golden normally equals the committed one exactly; the tolerance only absorbs
/// last-bit differences (a few f32 ulps) and still catches a single sample out of 4096 changing
/// colour by more than about 0.05.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerance {
    /// Absolute allowance.
    pub absolute: f32,
    /// Allowance relative to the larger magnitude.
    pub relative: f32,
}

impl Default for Tolerance {
    fn default() -> Self {
        Self {
            absolute: 1e-6,
            relative: 1e-5,
        }
    }
}

impl Tolerance {
    /// Whether `a` and `b` are equal within the tolerance (two NaNs are equal; NaN and a number
    /// are not).
    pub fn accepts(&self, a: f32, b: f32) -> bool {
        if a.is_nan() || b.is_nan() {
            return a.is_nan() && b.is_nan();
        }
        (a - b).abs() <= self.absolute + self.relative * a.abs().max(b.abs())
    }
}

/// One pixel value that differs beyond the tolerance.
#[derive(Clone, Debug, PartialEq)]
pub struct PixelDifference {
    /// Column.
    pub x: usize,
    /// Row (0 at the top).
    pub y: usize,
    /// The channel: `R`, `G`, `B`, or one of the `variance.` or `deviation.` layer's.
    pub channel: &'static str,
    /// The expected (committed) value.
    pub expected: f32,
    /// The actual (regenerated) value.
    pub actual: f32,
}

/// How two goldens differ, if they do.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GoldenDiff {
    /// Differences that make the pixels incomparable (size, missing variance, different scene,
    /// hash, spp or seed attributes), one line each.
    pub structural: Vec<String>,
    /// Number of pixel values (pixel and channel) beyond the tolerance.
    pub values_differing: usize,
    /// Number of pixels with at least one channel beyond the tolerance.
    pub pixels_differing: usize,
    /// The value with the largest absolute difference.
    pub worst: Option<PixelDifference>,
}

impl GoldenDiff {
    /// Whether the goldens are equal within the tolerance.
    pub fn is_match(&self) -> bool {
        self.structural.is_empty() && self.values_differing == 0
    }

    /// A one-line account of the difference (or `"equal within tolerance"`).
    pub fn summary(&self, pixels: usize) -> String {
        if self.is_match() {
            return "equal within tolerance".to_string();
        }
        let mut parts = self.structural.clone();
        if self.values_differing > 0 {
            let mut s = format!(
                "{} of {pixels} pixels differ beyond tolerance ({} values)",
                self.pixels_differing, self.values_differing
            );
            if let Some(w) = &self.worst {
                s.push_str(&format!(
                    "; worst at x={} y={} {}: expected {}, got {} (difference {:e})",
                    w.x,
                    w.y,
                    w.channel,
                    w.expected,
                    w.actual,
                    (w.actual - w.expected).abs()
                ));
            }
            parts.push(s);
        }
        parts.join("; ")
    }
}

/// Attributes that must agree for two goldens to be the same golden (the tool version may
/// differ; the profile and the inputs are absent from both when they are the defaults).
const IDENTITY_ATTRIBUTES: &[&str] = &[
    ATTR_SCENE,
    ATTR_SCENE_SHA256,
    ATTR_SPP,
    ATTR_SEED,
    ATTR_PROFILE,
    ATTR_INPUTS,
];

/// Compares `actual` with `expected` pixel by pixel (mean, variance and deviation) within
/// `tolerance`,
/// and their identifying attributes (scene, scene hash, spp, seed, profile, inputs) exactly.
pub fn compare_goldens(
    expected: &ExrImage,
    actual: &ExrImage,
    tolerance: &Tolerance,
) -> GoldenDiff {
    let mut diff = GoldenDiff::default();
    for name in IDENTITY_ATTRIBUTES {
        let (e, a) = (expected.attribute(name), actual.attribute(name));
        if e != a {
            diff.structural.push(format!(
                "{name} is {} but {} was expected",
                a.map_or("missing".to_string(), |v| format!("'{v}'")),
                e.map_or("none".to_string(), |v| format!("'{v}'")),
            ));
        }
    }
    if (expected.width, expected.height) != (actual.width, actual.height) {
        diff.structural.push(format!(
            "the size is {}x{} but {}x{} was expected",
            actual.width, actual.height, expected.width, expected.height
        ));
        return diff;
    }
    const MEAN: [&str; 3] = ["R", "G", "B"];
    const VARIANCE: [&str; 3] = ["variance.R", "variance.G", "variance.B"];
    // (expected values, actual values, channel names) per layer.
    type LayerPair<'a> = (&'a [[f32; 3]], &'a [[f32; 3]], [&'static str; 3]);
    let mut layers: Vec<LayerPair> = vec![(&expected.mean, &actual.mean, MEAN)];
    const DEVIATION: [&str; 3] = ["deviation.R", "deviation.G", "deviation.B"];
    for (expected, actual, names, layer) in [
        (&expected.variance, &actual.variance, VARIANCE, "variance"),
        (
            &expected.deviation,
            &actual.deviation,
            DEVIATION,
            "deviation",
        ),
    ] {
        match (expected, actual) {
            (Some(e), Some(a)) => layers.push((e, a, names)),
            (None, None) => {}
            (Some(_), None) => diff
                .structural
                .push(format!("the {layer} layer is missing")),
            (None, Some(_)) => diff
                .structural
                .push(format!("there is a {layer} layer where none was expected")),
        }
    }
    let mut differing = vec![false; expected.width * expected.height];
    let mut worst_gap = -1.0f32;
    for (e, a, names) in layers {
        for (i, (pe, pa)) in e.iter().zip(a).enumerate() {
            for c in 0..3 {
                if !tolerance.accepts(pe[c], pa[c]) {
                    diff.values_differing += 1;
                    differing[i] = true;
                    let gap = (pe[c] - pa[c]).abs();
                    let gap = if gap.is_nan() { f32::INFINITY } else { gap };
                    if gap > worst_gap {
                        worst_gap = gap;
                        diff.worst = Some(PixelDifference {
                            x: i % expected.width,
                            y: i / expected.width,
                            channel: names[c],
                            expected: pe[c],
                            actual: pa[c],
                        });
                    }
                }
            }
        }
    }
    diff.pixels_differing = differing.iter().filter(|d| **d).count();
    diff
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(values: &[f32]) -> ExrImage {
        ExrImage {
            width: values.len(),
            height: 1,
            mean: values.iter().map(|&v| [v, v, v]).collect(),
            variance: Some(values.iter().map(|&v| [v * v, 0.0, 0.0]).collect()),
            deviation: Some(values.iter().map(|&v| [v, 0.0, 0.0]).collect()),
            attributes: vec![(ATTR_SCENE.to_string(), "s".to_string())],
        }
    }

    #[test]
    fn tolerance_accepts_last_bits_and_rejects_one_sample_in_4096() {
        let t = Tolerance::default();
        let x = 0.7f32;
        assert!(t.accepts(x, f32::from_bits(x.to_bits() + 3)));
        // One of 4096 samples changing colour by 0.05 moves the mean by 1.2e-5.
        assert!(!t.accepts(x, x + 0.05 / 4096.0));
        assert!(t.accepts(f32::NAN, f32::NAN));
        assert!(!t.accepts(f32::NAN, 0.0));
        assert!(t.accepts(0.0, 0.0));
    }

    #[test]
    fn compare_reports_the_worst_pixel() {
        let e = image(&[0.1, 0.2, 0.3, 0.4]);
        let mut a = e.clone();
        a.mean[2][1] = 0.35;
        a.mean[3][0] = 0.401;
        let d = compare_goldens(&e, &a, &Tolerance::default());
        assert!(!d.is_match());
        assert_eq!((d.pixels_differing, d.values_differing), (2, 2));
        let w = d.worst.unwrap();
        assert_eq!((w.x, w.y, w.channel), (2, 0, "G"));
        assert_eq!((w.expected, w.actual), (0.3, 0.35));
        assert!(compare_goldens(&e, &e, &Tolerance::default()).is_match());
    }

    #[test]
    fn compare_checks_variance_size_and_identity() {
        let e = image(&[0.1, 0.2]);
        let mut a = e.clone();
        a.variance.as_mut().unwrap()[1][0] = 1.0;
        let d = compare_goldens(&e, &a, &Tolerance::default());
        assert_eq!(d.worst.unwrap().channel, "variance.R");

        let mut a = e.clone();
        a.variance = None;
        assert!(!compare_goldens(&e, &a, &Tolerance::default()).is_match());

        let mut a = e.clone();
        a.deviation.as_mut().unwrap()[0][0] = 0.5;
        let d = compare_goldens(&e, &a, &Tolerance::default());
        assert_eq!(d.worst.unwrap().channel, "deviation.R");
        a.deviation = None;
        let d = compare_goldens(&e, &a, &Tolerance::default());
        assert_eq!(d.structural, ["the deviation layer is missing"]);

        let mut a = e.clone();
        a.attributes[0].1 = "other".into();
        let d = compare_goldens(&e, &a, &Tolerance::default());
        assert_eq!(
            d.structural,
            ["rtoracle.scene is 'other' but 's' was expected"]
        );

        let a = image(&[0.1, 0.2, 0.3]);
        let d = compare_goldens(&e, &a, &Tolerance::default());
        assert!(
            d.summary(2)
                .contains("the size is 3x1 but 2x1 was expected")
        );
    }
}
