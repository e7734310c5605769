//! Fitted hypotheses for the diagnosis: changes with a parameter that is estimated from the image
//! first, then tested like the others (the candidate against the golden transformed by it).
//!
//! - A uniform scale: the candidate's linear values are the golden's times `k` (one `k` for
//!   every channel: an exposure or brightness change, or every albedo scaled in a one-bounce
//!   scene; three different ones: a colour cast). `k` per channel is the median of
//!   candidate / golden over flat pixels, so edges and a few odd pixels do not move it.
//! - A zoom about the image's centre by `s` (a field of view or a camera distance that differs):
//!   `s` is the one of a grid from 0.70 to 1.45, refined to 0.001, whose zoomed golden is closest
//!   to the candidate (least squares on a subsample of pixels).

use crate::compare::{candidate::CandidateImage, encoding::Encoding, noise_model::Golden};

/// The candidate's linear value per pixel and channel: the middle of a code's interval, or an
/// EXR's value.
fn linear_values(candidate: &CandidateImage, encoding: Encoding) -> Vec<[f64; 3]> {
    match candidate {
        CandidateImage::Rgb8 { data, .. } => {
            let table = encoding.table();
            data.chunks_exact(3)
                .map(|p| [0, 1, 2].map(|c| 0.5 * (table[p[c] as usize].0 + table[p[c] as usize].1)))
                .collect()
        }
        CandidateImage::Linear { data, .. } => data.iter().map(|p| p.map(f64::from)).collect(),
    }
}

/// The median of `v` (sorted in place); `None` when empty.
fn median(v: &mut [f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    Some(v[v.len() / 2])
}

/// The scale per channel that takes the golden to the candidate, from the pixels whose golden
/// is flat (per-sample standard deviation below 0.02), not dark (mean at least 0.02) and whose
/// candidate is not near the film's clamp (below 0.95: a brighter image clamps there). For 8-bit codes it is the scale that the most
/// of those pixels' code intervals allow (each pixel's interval `[lo, hi]` allows the scales
/// `[lo / mu, hi / mu]`; the middle of the scales allowed by the most pixels), so the codes'
/// rounding does not bias it; for linear values, the median ratio. `None` with fewer than 100
/// such pixels in a channel.
pub(crate) fn channel_scales(
    candidate: &CandidateImage,
    golden: &Golden,
    encoding: Encoding,
) -> Option<[f64; 3]> {
    let table = encoding.table();
    let intervals: Vec<[(f64, f64); 3]> = match candidate {
        CandidateImage::Rgb8 { data, .. } => data
            .chunks_exact(3)
            .map(|p| [0, 1, 2].map(|c| table[p[c] as usize]))
            .collect(),
        CandidateImage::Linear { data, .. } => data
            .iter()
            .map(|p| p.map(|x| (f64::from(x), f64::from(x))))
            .collect(),
    };
    let mut k = [0.0; 3];
    for (c, k) in k.iter_mut().enumerate() {
        let mut allowed: Vec<(f64, f64)> = intervals
            .iter()
            .zip(&golden.mean)
            .zip(&golden.variance)
            .filter(|((iv, mu), s2)| {
                (0.02..=1.0).contains(&mu[c]) && s2[c] < 4e-4 && iv[c].1 < 0.95
            })
            .map(|((iv, mu), _)| (iv[c].0 / mu[c], iv[c].1 / mu[c]))
            .collect();
        if allowed.len() < 100 {
            return None;
        }
        *k = match candidate {
            CandidateImage::Rgb8 { .. } => most_allowed(&allowed),
            CandidateImage::Linear { .. } => {
                let mut ratios: Vec<f64> = allowed.iter_mut().map(|a| a.0).collect();
                median(&mut ratios)?
            }
        };
    }
    Some(k)
}

/// The middle of the values that the most of the intervals `[lo, hi]` contain.
fn most_allowed(intervals: &[(f64, f64)]) -> f64 {
    // Openings before closings at the same value, so touching intervals overlap.
    let mut events: Vec<(f64, i32)> = intervals
        .iter()
        .flat_map(|&(lo, hi)| [(lo, -1), (hi, 1)])
        .collect();
    events.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let (mut open, mut best, mut at) = (0i32, 0i32, 1.0);
    for (k, &(x, kind)) in events.iter().enumerate() {
        open -= kind;
        if kind < 0 && open > best {
            best = open;
            // The next event closes (or opens past) the segment where `open` intervals meet.
            at = 0.5 * (x + events.get(k + 1).map_or(x, |e| e.0));
        }
    }
    at
}

/// The golden with every mean times `k` (per channel) and every per-sample variance times
/// `k^2`, the candidate's clamp kept: means above 1 stay at 1.
pub(crate) fn scaled(golden: &Golden, k: [f64; 3]) -> Golden {
    let mean = golden
        .mean
        .iter()
        .map(|m| [0, 1, 2].map(|c| (m[c] * k[c]).min(1.0)))
        .collect();
    let variance = golden
        .variance
        .iter()
        .map(|v| [0, 1, 2].map(|c| v[c] * k[c] * k[c]))
        .collect();
    Golden::new(
        golden.width,
        golden.height,
        golden.samples_per_pixel,
        mean,
        variance,
        golden.scene.clone(),
    )
    .expect("a scaled golden has the same size and finite values")
    .with_vfov(golden.vfov)
    .with_deviation(golden.deviation.as_ref().map(|d| {
        d.iter()
            .map(|v| [0, 1, 2].map(|c| v[c] * k[c].abs()))
            .collect()
    }))
    .expect("scaled deviations stay finite distances")
}

/// The golden's mean and variance at the point `(x, y)` (pixel units, `(0.5, 0.5)` the centre of
/// the top-left pixel), interpolated bilinearly between the four nearest pixel centres (clamped at
/// the border); the variance gains the spread of the four means, as a sample may come from any.
fn sample(golden: &Golden, x: f64, y: f64) -> ([f64; 3], [f64; 3]) {
    let (w, h) = (golden.width as isize, golden.height as isize);
    let (fx, fy) = (x - 0.5, y - 0.5);
    let (x0, y0) = (fx.floor(), fy.floor());
    let (tx, ty) = (fx - x0, fy - y0);
    let at = |dx: isize, dy: isize| {
        let i = (x0 as isize + dx).clamp(0, w - 1);
        let j = (y0 as isize + dy).clamp(0, h - 1);
        (j * w + i) as usize
    };
    let corners = [
        (at(0, 0), (1.0 - tx) * (1.0 - ty)),
        (at(1, 0), tx * (1.0 - ty)),
        (at(0, 1), (1.0 - tx) * ty),
        (at(1, 1), tx * ty),
    ];
    let mut m = [0.0; 3];
    let mut v = [0.0; 3];
    for c in 0..3 {
        m[c] = corners.iter().map(|&(k, wt)| wt * golden.mean[k][c]).sum();
        let spread: f64 = corners
            .iter()
            .map(|&(k, wt)| wt * (golden.mean[k][c] - m[c]).powi(2))
            .sum();
        v[c] = corners
            .iter()
            .map(|&(k, wt)| wt * golden.variance[k][c])
            .sum::<f64>()
            + spread;
    }
    (m, v)
}

/// Where pixel `(i, j)` of an image zoomed by `s` about its centre looks in the original.
fn source_of(golden: &Golden, s: f64, i: usize, j: usize) -> (f64, f64) {
    let (cx, cy) = (golden.width as f64 / 2.0, golden.height as f64 / 2.0);
    (
        cx + (i as f64 + 0.5 - cx) / s,
        cy + (j as f64 + 0.5 - cy) / s,
    )
}

/// The golden zoomed by `s` about the image's centre (`s > 1`: magnified, as a narrower field of
/// view or a closer camera shows the scene).
pub(crate) fn zoomed(golden: &Golden, s: f64) -> Golden {
    let n = golden.width * golden.height;
    let mut mean = Vec::with_capacity(n);
    let mut variance = Vec::with_capacity(n);
    for j in 0..golden.height {
        for i in 0..golden.width {
            let (x, y) = source_of(golden, s, i, j);
            let (m, v) = sample(golden, x, y);
            mean.push(m);
            variance.push(v);
        }
    }
    Golden::new(
        golden.width,
        golden.height,
        golden.samples_per_pixel,
        mean,
        variance,
        golden.scene.clone(),
    )
    .expect("a zoomed golden has the same size and finite values")
    .with_vfov(golden.vfov)
}

/// The zoom factor that best takes the golden to the candidate (see the module docs), or `None`
/// when the best is within 0.5% of no zoom or the image is too small to tell.
pub(crate) fn best_zoom(
    candidate: &CandidateImage,
    golden: &Golden,
    encoding: Encoding,
) -> Option<f64> {
    if golden.width < 16 || golden.height < 16 {
        return None;
    }
    let values = linear_values(candidate, encoding);
    let step = (golden.width.max(golden.height) / 100).max(1);
    let misfit = |s: f64| -> f64 {
        let mut sum = 0.0;
        for j in (0..golden.height).step_by(step) {
            for i in (0..golden.width).step_by(step) {
                let (x, y) = source_of(golden, s, i, j);
                let (m, _) = sample(golden, x, y);
                let y_c = values[j * golden.width + i];
                sum += (0..3).map(|c| (y_c[c] - m[c]).powi(2)).sum::<f64>();
            }
        }
        sum
    };
    let best_of = |candidates: &mut dyn Iterator<Item = f64>| {
        candidates
            .map(|s| (s, misfit(s)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .expect("a non-empty grid")
    };
    let (coarse, _) = best_of(&mut (0..=75).map(|k| 0.70 + 0.01 * k as f64));
    let (fine, _) = best_of(&mut (-10..=10).map(|k| coarse + 0.001 * k as f64));
    ((fine - 1.0).abs() > 0.005).then_some(fine)
}

/// The vertical field of view a zoom by `s` gives a camera of `vfov` degrees:
/// `2 atan(tan(vfov / 2) / s)`.
pub(crate) fn zoomed_vfov(vfov: f64, s: f64) -> f64 {
    2.0 * ((vfov.to_radians() / 2.0).tan() / s).atan().to_degrees()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A golden of a bright square on a dark ground, `w` a side, the square's side `2 r`.
    fn square(w: usize, r: f64) -> Golden {
        let c = w as f64 / 2.0;
        let mean = (0..w * w)
            .map(|k| {
                let (x, y) = ((k % w) as f64 + 0.5 - c, (k / w) as f64 + 0.5 - c);
                if x.abs() < r && y.abs() < r {
                    [0.8, 0.5, 0.3]
                } else {
                    [0.1, 0.2, 0.4]
                }
            })
            .collect();
        Golden::new(w, w, 1024, mean, vec![[0.0; 3]; w * w], None).unwrap()
    }

    fn codes(g: &Golden) -> CandidateImage {
        CandidateImage::Rgb8 {
            width: g.width,
            height: g.height,
            data: g
                .mean
                .iter()
                .flat_map(|m| m.map(|x| Encoding::Course.encode(x)))
                .collect(),
        }
    }

    /// A square drawn 1.25 times larger is the golden zoomed by 1.25, found to 1%.
    #[test]
    fn the_zoom_of_a_larger_square_is_its_ratio() {
        let golden = square(120, 20.0);
        let larger = codes(&square(120, 25.0));
        let s = best_zoom(&larger, &golden, Encoding::Course).unwrap();
        assert!((s - 1.25).abs() < 0.0125, "{s}");
        // The same image is not zoomed.
        assert_eq!(best_zoom(&codes(&golden), &golden, Encoding::Course), None);
        // 90 degrees magnified by tan(45)/tan(40) is 80 degrees.
        let s80 = 1.0 / 40f64.to_radians().tan();
        assert!((zoomed_vfov(90.0, s80) - 80.0).abs() < 1e-9);
    }

    /// Codes of the golden's values times 0.81 give a scale of 0.81 in every channel, to the
    /// precision the codes allow.
    #[test]
    fn a_darker_image_has_its_scale() {
        let golden = square(40, 10.0);
        let darker = codes(&scaled(&golden, [0.81; 3]));
        let k = channel_scales(&darker, &golden, Encoding::Course).unwrap();
        for c in 0..3 {
            assert!((k[c] - 0.81).abs() < 0.02, "{k:?}");
        }
        let tinted = codes(&scaled(&golden, [1.0, 1.0, 0.7]));
        let k = channel_scales(&tinted, &golden, Encoding::Course).unwrap();
        assert!(
            (k[0] - 1.0).abs() < 0.02 && (k[2] - 0.7).abs() < 0.02,
            "{k:?}"
        );
        // Too few flat pixels: no estimate.
        let tiny = square(8, 2.0);
        assert_eq!(channel_scales(&codes(&tiny), &tiny, Encoding::Course), None);
    }
}
