//! What the failing regions show: each one's change per channel in words, and their order.
//!
//! The statistic finds the regions (the verdict); this module ranks them by what a reader
//! learns from them, not by where they are: first the region with the most evidence (its area
//! times the strength of its differences, `|z|` capped at `Z_CAP` per pixel, so a large region
//! beats a small one whose `z` saturates), then, for the regions listed, each next one the one
//! whose evidence is greatest after a discount for lying near a region already listed, so the
//! first crops show distinct places. Each region says, per channel, whether the candidate is
//! higher or lower than the golden there ([`channel_change`]): a blue quad turned red is "red up,
//! blue down: a different colour, not a brighter one".

use super::Region;

/// `|z|` at which a pixel's evidence stops growing.
const Z_CAP: f64 = 50.0;
/// A channel counts as changed at a pixel from this `|z|` on.
const Z_CHANGED: f32 = 2.0;
/// A channel went up (down) in a set of pixels when at least this share of them changed that
/// way, and three times as many as the other way.
const SHARE: f64 = 0.03;

/// The names of the channels, in words.
const CHANNEL_NAMES: [&str; 3] = ["red", "green", "blue"];

/// How each channel of a set of pixels differs from the golden.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ChannelChange {
    /// No change that stands out.
    Same,
    /// Higher than the golden.
    Up,
    /// Lower than the golden.
    Down,
    /// Much higher in some pixels and much lower in others: the shapes differ.
    Both,
}

/// The change of each channel over the pixels `pixels` (indices into `z`, the signed `z` per
/// pixel and channel).
pub fn channel_changes(z: &[[f32; 3]], pixels: impl Iterator<Item = usize>) -> [ChannelChange; 3] {
    let (mut up, mut down, mut n) = ([0usize; 3], [0usize; 3], 0usize);
    for i in pixels {
        n += 1;
        for c in 0..3 {
            if z[i][c] >= Z_CHANGED {
                up[c] += 1;
            } else if z[i][c] <= -Z_CHANGED {
                down[c] += 1;
            }
        }
    }
    let least = (SHARE * n as f64).max(1.0);
    [0, 1, 2].map(|c| {
        let (u, d) = (up[c] as f64, down[c] as f64);
        match (u >= least, d >= least) {
            (true, false) => ChannelChange::Up,
            (false, true) => ChannelChange::Down,
            (true, true) if u >= 3.0 * d => ChannelChange::Up,
            (true, true) if d >= 3.0 * u => ChannelChange::Down,
            (true, true) => ChannelChange::Both,
            (false, false) => ChannelChange::Same,
        }
    })
}

/// Channel names joined: `red`, `red and blue`, `red, green and blue`.
fn names(channels: &[usize]) -> String {
    let words: Vec<&str> = channels.iter().map(|&c| CHANNEL_NAMES[c]).collect();
    match words.as_slice() {
        [] => String::new(),
        [one] => one.to_string(),
        [rest @ .., last] => format!("{} and {last}", rest.join(", ")),
    }
}

/// The change of three channels in words: "red up, blue down: a different colour, not a
/// brighter one".
pub fn channel_change(changes: [ChannelChange; 3]) -> String {
    let which = |k: ChannelChange| -> Vec<usize> { (0..3).filter(|&c| changes[c] == k).collect() };
    let (up, down, both) = (
        which(ChannelChange::Up),
        which(ChannelChange::Down),
        which(ChannelChange::Both),
    );
    if !both.is_empty() {
        return format!(
            "{} higher in some pixels and lower in others: an edge or a shape moved, or more noise than the claimed samples give",
            names(&both)
        );
    }
    match (up.len(), down.len()) {
        (0, 0) => "no channel stands out: a small difference spread over many pixels".to_string(),
        (3, 0) => "brighter in every channel".to_string(),
        (0, 3) => "darker in every channel".to_string(),
        (_, 0) => format!(
            "{} up, the rest unchanged: brighter, and a different colour",
            names(&up)
        ),
        (0, _) => format!(
            "{} down, the rest unchanged: darker, and a different colour",
            names(&down)
        ),
        _ => format!(
            "{} up, {} down: a different colour, not a brighter one",
            names(&up),
            names(&down)
        ),
    }
}

/// The pixel indices inside `r`.
fn pixels_of(r: &Region, width: usize) -> impl Iterator<Item = usize> + '_ {
    (r.y..r.y + r.height).flat_map(move |y| (r.x..r.x + r.width).map(move |x| y * width + x))
}

/// The evidence of a region: the sum over its pixels of the largest `|z|` of the three channels,
/// each capped at [`Z_CAP`].
fn evidence(r: &Region, z: &[[f32; 3]], width: usize) -> f64 {
    pixels_of(r, width)
        .map(|i| {
            z[i].iter()
                .map(|v| f64::from(v.abs()))
                .fold(0.0, f64::max)
                .min(Z_CAP)
        })
        .sum()
}

/// The regions with their change in words, ranked (see the module docs); the first `listed` are
/// chosen for distinct places. `z` is the signed `z` per pixel and channel of a `width`-wide
/// image.
pub fn rank(
    regions: Vec<Region>,
    z: &[[f32; 3]],
    (width, height): (usize, usize),
    listed: usize,
) -> Vec<Region> {
    let mut scored: Vec<(f64, Region)> = regions
        .into_iter()
        .map(|mut r| {
            r.change = Some(channel_change(channel_changes(z, pixels_of(&r, width))));
            (evidence(&r, z, width), r)
        })
        .collect();
    // Strongest first; ties by adjusted p, then by place (deterministic).
    scored.sort_by(|(ea, a), (eb, b)| {
        eb.total_cmp(ea)
            .then(a.adjusted_p.total_cmp(&b.adjusted_p))
            .then((a.y, a.x).cmp(&(b.y, b.x)))
    });
    // Distinct places for the listed ones: a region at distance d from the nearest one listed
    // keeps 1 - exp(-d / reach) of its evidence.
    let reach = 0.15 * ((width * width + height * height) as f64).sqrt();
    let centre = |r: &Region| {
        (
            r.x as f64 + r.width as f64 / 2.0,
            r.y as f64 + r.height as f64 / 2.0,
        )
    };
    let mut out: Vec<Region> = Vec::with_capacity(scored.len());
    let mut nearest = vec![f64::INFINITY; scored.len()];
    let mut taken = vec![false; scored.len()];
    for _ in 0..listed.min(scored.len()) {
        let pick = (0..scored.len())
            .filter(|&k| !taken[k])
            .max_by(|&a, &b| {
                let value = |k: usize| scored[k].0 * (1.0 - (-nearest[k] / reach).exp());
                value(a).total_cmp(&value(b)).then(b.cmp(&a))
            })
            .expect("a region is left");
        taken[pick] = true;
        let (px, py) = centre(&scored[pick].1);
        for (k, (_, r)) in scored.iter().enumerate() {
            let (x, y) = centre(r);
            nearest[k] = nearest[k].min(((x - px).powi(2) + (y - py).powi(2)).sqrt());
        }
        out.push(scored[pick].1.clone());
    }
    out.extend(
        scored
            .into_iter()
            .zip(taken)
            .filter(|(_, t)| !t)
            .map(|((_, r), _)| r),
    );
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn region(x: usize, y: usize, w: usize, h: usize) -> Region {
        Region {
            x,
            y,
            width: w,
            height: h,
            scale: "pixel".into(),
            channel: "R".into(),
            adjusted_p: 0.0,
            z: 1000.0,
            change: None,
        }
    }

    #[test]
    fn channel_changes_are_said_in_words() {
        use ChannelChange::*;
        assert_eq!(
            channel_change([Up, Same, Down]),
            "red up, blue down: a different colour, not a brighter one"
        );
        assert_eq!(channel_change([Down; 3]), "darker in every channel");
        assert_eq!(channel_change([Up; 3]), "brighter in every channel");
        assert!(channel_change([Same, Same, Up]).starts_with("blue up, the rest unchanged"));
        assert!(channel_change([Both, Same, Up]).contains("an edge or a shape moved"));
        assert!(channel_change([Same; 3]).starts_with("no channel stands out"));
        assert_eq!(names(&[0, 1, 2]), "red, green and blue");
    }

    /// Pixels of a blue quad turned red: red much higher, blue much lower, green the same; a few
    /// noisy pixels do not make a channel change.
    #[test]
    fn a_colour_change_is_told_per_channel() {
        let mut z = vec![[0.5f32, -0.3, 0.2]; 100];
        for p in z.iter_mut().take(60) {
            *p = [40.0, 0.4, -35.0];
        }
        z[99] = [0.0, 9.0, 0.0];
        assert_eq!(
            channel_changes(&z, 0..100),
            [ChannelChange::Up, ChannelChange::Same, ChannelChange::Down]
        );
    }

    /// Six equal regions in a row at the top and one far away: the far one is listed second,
    /// not sixth; the larger of two equally strong regions comes first.
    #[test]
    fn regions_are_ranked_by_evidence_then_distinct_places() {
        let (w, h) = (200, 200);
        let z = vec![[60.0f32, 0.0, 0.0]; w * h];
        let mut regions: Vec<Region> = (0..6).map(|k| region(8 * k, 0, 8, 8)).collect();
        regions.push(region(184, 184, 8, 8));
        regions.push(region(100, 100, 16, 16));
        let ranked = rank(regions, &z, (w, h), 50);
        assert_eq!(
            (ranked[0].x, ranked[0].width),
            (100, 16),
            "the largest first"
        );
        let far = ranked.iter().position(|r| r.x == 184).unwrap();
        assert!(far <= 2, "{far}: {ranked:?}");
        assert!(ranked.iter().all(|r| r.change.is_some()));
        assert_eq!(ranked.len(), 8);
    }
}
