//! The statistic: per pixel and channel, the distance from the candidate's interval to the
//! golden's mean over its standard error, tested with Bernstein bounds at four scales.

use super::stats::{bernstein_p, sidak};
use super::{
    CompareOptions, Comparison, Diagnosis, NoiseCheck, Region, ScaleResult, Verdict,
    candidate::CandidateImage, encoding::Encoding, noise_model::Golden,
};

/// The false-failure bound of the noise check (on top of the four scales' `alpha`).
pub const NOISE_ALPHA: f64 = 1e-6;
/// Fewer noisy pixels than this and neither the effective spp nor the noise check is computed.
const NOISE_MIN_PIXELS: usize = 100;
/// Regions the report lists (the heatmap outlines all of them).
pub const REGIONS_LISTED: usize = 50;

/// The names of the scales, in order.
pub const SCALES: [&str; 4] = ["pixel", "tile8", "tile32", "global"];
const CHANNELS: [&str; 3] = ["R", "G", "B"];
/// Relative precision of a half float: EXR candidates are their values +- this.
const HALF_EPSILON: f64 = 1.0 / 2048.0;
/// Side of the cells failing regions are built from.
const CELL: usize = 8;
/// Regions never cross a block of this many cells a side (32 pixels), so a failing outline of
/// an object gives boxes along it rather than one box around the whole object.
const BLOCK: usize = 4;
/// A cell of a failing 32x32 tile is boxed when its own sum leans the tile's way by this `z`.
const CELL_Z: f64 = 2.0;

/// The intervals of linear values a candidate's pixels stand for, and the width of a code at a
/// given linear value (to tell pixels whose noise shows through the quantisation).
struct Intervals {
    lo: Vec<[f64; 3]>,
    hi: Vec<[f64; 3]>,
    encoding: Option<Encoding>,
    table: [(f64, f64); 256],
    /// The upper end of the encoding's top code's interval (an 8-bit candidate): the film clamps,
    /// so that code stands for every value from its lower end up, above 1 too.
    top_hi: Option<f64>,
    /// The lower end of that code's interval (see [`Intervals::censored_below`]).
    top_lo: Option<f64>,
}

impl Intervals {
    fn of(candidate: &CandidateImage, encoding: Encoding) -> Self {
        let table = encoding.table();
        match candidate {
            CandidateImage::Rgb8 { data, .. } => {
                let mut lo = Vec::with_capacity(data.len() / 3);
                let mut hi = Vec::with_capacity(data.len() / 3);
                for p in data.chunks_exact(3) {
                    let t = [
                        table[p[0] as usize],
                        table[p[1] as usize],
                        table[p[2] as usize],
                    ];
                    lo.push(t.map(|x| x.0));
                    hi.push(t.map(|x| x.1));
                }
                Intervals {
                    lo,
                    hi,
                    encoding: Some(encoding),
                    table,
                    top_hi: Some(table[encoding.encode(1.0) as usize].1),
                    top_lo: Some(table[encoding.encode(1.0) as usize].0),
                }
            }
            CandidateImage::Linear { data, .. } => {
                let spread = |x: f32| {
                    let x = x as f64;
                    let e = x.abs() * HALF_EPSILON + 1e-7;
                    (x - e, x + e)
                };
                Intervals {
                    lo: data.iter().map(|p| p.map(|x| spread(x).0)).collect(),
                    hi: data.iter().map(|p| p.map(|x| spread(x).1)).collect(),
                    encoding: None,
                    table,
                    top_hi: None,
                    top_lo: None,
                }
            }
        }
    }

    /// The `below` a sum adds for term `t` of a candidate whose interval's own upper end is
    /// `raw_hi`: a lower bound on how much darker the candidate is than an honest one, under the
    /// clamping film's censoring.
    ///
    /// An 8-bit film clamps each pixel's mean: an honest candidate shows `min(mean, clamp)`,
    /// whose expectation lies below the golden's mean wherever the mean may reach the top code
    /// (overexposed lights and highlights). Summed over many such pixels, `mu - hi` would then
    /// lean dark for an honest image. So the sums compare the candidate with a lower bound of
    /// that expectation instead: with `Y` the candidate's mean minus the top code's lower end
    /// `top`, `E[min(mean, top)] = mu - E[Y+]`, and `E[Y+] = (E[Y] + E|Y|) / 2 <= (m + sqrt(m^2
    /// + v)) / 2` for `m = mu - top` and `v` the variance of the candidate's mean. The top code's
    /// own upper end is used (not "any brighter value", which the pixel scale keeps). Far below
    /// the top the shortfall is about `v / (4 |m|)`, a small share of a standard deviation.
    #[inline]
    fn censored_below(&self, t: &Term, raw_hi: f64) -> f64 {
        match self.top_lo {
            Some(top) => {
                let m = t.mu - top;
                let shortfall = 0.5 * (m + (m * m + t.variance).sqrt());
                t.mu - t.slack - shortfall - raw_hi
            }
            None => t.below,
        }
    }

    /// Width of the interval a candidate with the value `mu` would have.
    #[inline]
    fn width_at(&self, mu: f64) -> f64 {
        match self.encoding {
            Some(e) => {
                let (lo, hi) = self.table[e.encode(mu) as usize];
                hi - lo
            }
            None => 2.0 * (mu.abs() * HALF_EPSILON + 1e-7),
        }
    }
}

/// Sums of one tile or of the whole image, per channel.
#[derive(Clone, Copy, Default)]
struct Sums {
    /// Sum of `L - mu_hi`: a lower bound on how much brighter the candidate is.
    above: f64,
    /// Sum of `mu_lo - U`: a lower bound on how much darker it is.
    below: f64,
    variance: f64,
    bound: f64,
    count: usize,
}

impl Sums {
    fn add(&mut self, above: f64, below: f64, variance: f64, bound: f64) {
        self.above += above;
        self.below += below;
        self.variance += variance;
        self.bound = self.bound.max(bound);
        self.count += 1;
    }

    /// The `z` of these sums in the direction of `sign`'s (the candidate brighter when
    /// positive); negative when they lean the other way.
    fn leaning(&self, sign: f64) -> f64 {
        let t = if sign >= 0.0 { self.above } else { self.below };
        if t > 0.0 {
            z_of(t, self.variance)
        } else if self.variance > 0.0 {
            t / self.variance.sqrt()
        } else {
            t
        }
    }

    /// `(p, signed z)`.
    fn test(&self) -> (f64, f64) {
        if self.count == 0 {
            return (1.0, 0.0);
        }
        let (t, sign) = if self.above >= self.below {
            (self.above.max(0.0), 1.0)
        } else {
            (self.below.max(0.0), -1.0)
        };
        let p = bernstein_p(t, self.variance, self.bound);
        (p, sign * z_of(t, self.variance))
    }
}

#[inline]
fn z_of(t: f64, variance: f64) -> f64 {
    if t <= 0.0 {
        0.0
    } else if variance > 0.0 {
        (t / variance.sqrt()).min(1000.0)
    } else {
        1000.0
    }
}

/// The worst evidence in one cell of the region grid.
#[derive(Clone, Copy)]
struct Worst {
    p: f64,
    scale: usize,
    channel: usize,
    z: f64,
}

fn mark(cell: &mut Option<Worst>, w: Worst) {
    if cell.is_none_or(|c| w.p < c.p) {
        *cell = Some(w);
    }
}

/// Everything one pass of the statistic finds.
#[derive(Clone, Debug)]
pub struct Evaluation {
    /// Whether every scale passed.
    pub passed: bool,
    /// Per scale.
    pub scales: Vec<ScaleResult>,
    /// Failing regions, worst first (all of them).
    pub regions: Vec<Region>,
    /// Whether the candidate is as noisy as `N` samples allow.
    pub noise: Option<NoiseCheck>,
    /// Signed z per pixel and channel.
    pub z_map: Vec<[f32; 3]>,
    /// Mean (candidate mid-point - golden) per channel.
    pub bias: [f64; 3],
    /// relMSE of the candidate's mid-points against the golden's means.
    pub rel_mse: f64,
    /// Estimated samples per pixel.
    pub effective_spp: Option<f64>,
    /// Sum of min(z^2, 100) over pixel and 8x8-tile tests: how badly the image fits.
    pub misfit: f64,
    /// The encoding used to read the codes (`None` for linear candidates).
    pub encoding: Option<Encoding>,
}

/// The grids over an image: 8- and 32-pixel tiles, and the cells regions are built from.
#[derive(Clone, Copy)]
struct Grids {
    width: usize,
    height: usize,
    /// Tiles of 8 pixels a row.
    t8x: usize,
    /// Tiles of 32 pixels a row.
    t32x: usize,
    /// Cells a row and a column.
    cx: usize,
    cy: usize,
}

impl Grids {
    fn of(width: usize, height: usize) -> Self {
        let grid = |s: usize| (width.div_ceil(s), height.div_ceil(s));
        let (t8x, _) = grid(8);
        let (t32x, _) = grid(32);
        let (cx, cy) = grid(CELL);
        Grids {
            width,
            height,
            t8x,
            t32x,
            cx,
            cy,
        }
    }

    /// The sums of channel `c` of the `size`-pixel tile (8 or 32) holding pixel `(x, y)`.
    #[inline]
    fn tile(&self, size: usize, x: usize, y: usize, c: usize) -> usize {
        let tx = if size == 8 { self.t8x } else { self.t32x };
        ((y / size) * tx + x / size) * 3 + c
    }

    /// The cell holding pixel `(x, y)`.
    #[inline]
    fn cell(&self, x: usize, y: usize) -> usize {
        (y / CELL) * self.cx + x / CELL
    }
}

/// What the test claims of the candidate and the golden, from the options.
#[derive(Clone, Copy)]
struct Claim {
    /// The candidate's samples per pixel `N`.
    n: f64,
    /// The golden's samples per pixel `M`.
    m: f64,
    lambda: f64,
    /// Each scale's share of `alpha`.
    threshold: f64,
    /// Pixel-scale tests (pixels times channels).
    pixel_tests: f64,
}

/// One channel of one pixel: the candidate's interval `[lo, hi]` against the golden's mean
/// `mu`, per-sample variance `s2` and bound `b` (the sums'; the pixel test uses the golden's
/// tail-tolerant bound, `Golden::tail_bound`).
struct Term {
    lo: f64,
    hi: f64,
    mu: f64,
    s2: f64,
    b: f64,
    /// `lo - mu_hi`: how much brighter the candidate surely is (when positive).
    above: f64,
    /// `mu_lo - hi`: how much darker (when positive).
    below: f64,
    /// The variance of the candidate's mean minus the golden's under the claim.
    variance: f64,
    /// Bernstein's bound on one term of a sum.
    bound: f64,
    /// The pixel test's p-value (before the Sidak correction), with the tail-tolerant bound.
    p: f64,
    /// Its signed z.
    z: f64,
    /// The golden's slack for `f32` and float-order rounding.
    slack: f64,
}

impl Term {
    #[inline]
    fn of(lo: f64, hi: f64, mu: f64, s2: f64, (b, tail): (f64, f64), claim: &Claim) -> Self {
        // The golden's range: its mean up to f32 and float-order rounding.
        let slack = 1e-6 * (1.0 + mu.abs());
        let (mu_lo, mu_hi) = (mu - slack, mu + slack);
        // Samples the golden may have missed: an unseen event of probability up to
        // about 4/M with the neighbourhood's contrast.
        let s2_eff = s2.max(4.0 * b * b / claim.m);
        let variance = claim.lambda * s2_eff / claim.n + s2 / claim.m;
        let bound = b / claim.n;
        let above = lo - mu_hi;
        let below = mu_lo - hi;
        let (t, sign) = if above > 0.0 {
            (above, 1.0)
        } else if below > 0.0 {
            (below, -1.0)
        } else {
            (0.0, 0.0)
        };
        Term {
            lo,
            hi,
            mu,
            s2,
            b,
            above,
            below,
            variance,
            bound,
            p: bernstein_p(t, variance, tail / claim.n),
            z: sign * z_of(t, variance),
            slack,
        }
    }
}

/// The sums the effective spp and the noise check are computed from.
#[derive(Default)]
struct NoiseSums {
    /// The effective spp's numerator, denominator and pixel-channels.
    neff_num: f64,
    neff_den: f64,
    neff_count: usize,
    /// Squared residuals, their bound under the claim of N samples, the bound on their
    /// variance and the largest one's cap.
    sq_sum: f64,
    sq_bound: f64,
    sq_var: f64,
    sq_max: f64,
}

/// What the pass over the pixels accumulates.
struct PixelPass {
    tiles8: Vec<Sums>,
    tiles32: Vec<Sums>,
    global: [Sums; 3],
    /// The worst evidence per cell.
    cells: Vec<Option<Worst>>,
    pixel_min_p: f64,
    pixel_max_z: f64,
    pixel_failing: usize,
    z_map: Vec<[f32; 3]>,
    /// Sum of (candidate mid-point - golden) per channel.
    bias: [f64; 3],
    /// Sum of relMSE's terms.
    rel_mse: f64,
    noise: NoiseSums,
    misfit: f64,
}

impl PixelPass {
    /// Runs the pixel-scale tests and fills the tiles' sums.
    fn run(iv: &Intervals, golden: &Golden, claim: &Claim, g: &Grids) -> Self {
        let mut pass = PixelPass {
            tiles8: vec![Sums::default(); g.t8x * g.height.div_ceil(8) * 3],
            tiles32: vec![Sums::default(); g.t32x * g.height.div_ceil(32) * 3],
            global: [Sums::default(); 3],
            cells: vec![None; g.cx * g.cy],
            pixel_min_p: 1.0,
            pixel_max_z: 0.0,
            pixel_failing: 0,
            z_map: vec![[0.0f32; 3]; g.width * g.height],
            bias: [0.0; 3],
            rel_mse: 0.0,
            noise: NoiseSums::default(),
            misfit: 0.0,
        };
        for y in 0..g.height {
            for x in 0..g.width {
                pass.pixel(x, y, iv, golden, claim, g);
            }
        }
        pass
    }

    fn pixel(
        &mut self,
        x: usize,
        y: usize,
        iv: &Intervals,
        golden: &Golden,
        claim: &Claim,
        g: &Grids,
    ) {
        let i = y * g.width + x;
        // A pixel's channels come from the same samples: its terms are summed first, and
        // the pixels (independent) enter the bound as one term each.
        let (mut px_sq, mut px_bound, mut px_cap) = (0.0f64, 0.0f64, 0.0f64);
        for c in 0..3 {
            let mu = golden.mean[i][c];
            let s2 = golden.variance[i][c];
            let bounds = (golden.bound[i][c], golden.tail_bound[i][c]);
            let (lo, mut hi) = (iv.lo[i][c], iv.hi[i][c]);
            let raw_hi = hi;
            if iv.top_hi == Some(hi) {
                // The top code of a clamping film: any mean from its lower end up gives it.
                hi = hi.max(mu);
            }
            let t = Term::of(lo, hi, mu, s2, bounds, claim);
            let z = t.z;
            self.misfit += (z * z).min(100.0);
            self.z_map[i][c] = z as f32;
            self.pixel_max_z = self.pixel_max_z.max(z.abs());
            if t.p < 1.0 {
                let adjusted = sidak(t.p, claim.pixel_tests);
                self.pixel_min_p = self.pixel_min_p.min(adjusted);
                if adjusted < claim.threshold {
                    self.pixel_failing += 1;
                    let w = Worst {
                        p: adjusted,
                        scale: 0,
                        channel: c,
                        z,
                    };
                    mark(&mut self.cells[g.cell(x, y)], w);
                }
            }
            let mid = 0.5 * (lo + hi);
            self.bias[c] += mid - mu;
            self.rel_mse += super::stats::rel_mse_term(mid, mu);
            // Pixels whose noise shows through the quantisation enter the sums; the others
            // are decided exactly at the pixel scale (a rule that reads only the golden).
            let width_here = iv.width_at(mu);
            if t.variance.sqrt() >= width_here {
                let below = iv.censored_below(&t, raw_hi);
                let (above, variance, bound) = (t.above, t.variance, t.bound);
                self.tiles8[g.tile(8, x, y, c)].add(above, below, variance, bound);
                self.tiles32[g.tile(32, x, y, c)].add(above, below, variance, bound);
                self.global[c].add(above, below, variance, bound);
                if s2 > 0.0 && hi - lo < 1.0 {
                    let (sq, e, cap) = self.noise.add(&t, claim);
                    px_sq += sq;
                    px_bound += e;
                    px_cap += cap;
                }
            }
        }
        if px_cap > 0.0 {
            let n = &mut self.noise;
            n.sq_sum += px_sq;
            n.sq_bound += px_bound;
            n.sq_var += px_cap * px_bound;
            n.sq_max = n.sq_max.max(px_cap);
        }
    }

    /// The pixel scale's result.
    fn pixel_scale(&self, claim: &Claim) -> ScaleResult {
        ScaleResult {
            scale: SCALES[0].into(),
            tests: claim.pixel_tests as usize,
            smallest_adjusted_p: self.pixel_min_p,
            threshold: claim.threshold,
            largest_abs_z: self.pixel_max_z,
            failing: self.pixel_failing,
        }
    }

    /// The result of the tile scale `scale` (1: 8 pixels, 2: 32), marking the cells of its
    /// failing tiles (the 8x8 ones tile8's sums counted pixels in).
    fn tile_scale(&mut self, scale: usize, g: &Grids, threshold: f64) -> ScaleResult {
        let sums = if scale == 1 {
            &self.tiles8
        } else {
            &self.tiles32
        };
        let tests = sums.len();
        let (mut min_p, mut max_z) = (1.0f64, 0.0f64);
        let mut failing = vec![];
        for (k, s) in sums.iter().enumerate() {
            let (p, z) = s.test();
            max_z = max_z.max(z.abs());
            if p >= 1.0 {
                continue;
            }
            self.misfit += if scale == 1 { (z * z).min(100.0) } else { 0.0 };
            let adjusted = sidak(p, tests as f64);
            min_p = min_p.min(adjusted);
            if adjusted < threshold {
                failing.push((k, adjusted, z));
            }
        }
        for &(k, adjusted, z) in &failing {
            self.mark_tile(k, scale, g, adjusted, z);
        }
        ScaleResult {
            scale: SCALES[scale].into(),
            tests,
            smallest_adjusted_p: min_p,
            threshold,
            largest_abs_z: max_z,
            failing: failing.len(),
        }
    }

    /// Marks the cells of the failing tile `k / 3` (channel `k % 3`) of the tile scale `scale`
    /// (cells are 8x8 tiles). A failing 32x32 tile marks only the cells that carry its evidence:
    /// those whose own sum leans its way by at least [`CELL_Z`] (or, when none does, the one
    /// that leans most), so a box never covers a corner of the tile where nothing changed.
    fn mark_tile(&mut self, k: usize, scale: usize, g: &Grids, adjusted: f64, z: f64) {
        let (size, tx) = if scale == 1 { (8, g.t8x) } else { (32, g.t32x) };
        let (tile, c) = (k / 3, k % 3);
        let (x0, y0) = ((tile % tx) * size, (tile / tx) * size);
        let mut leaning = Vec::new();
        for yy in (y0..(y0 + size).min(g.height)).step_by(CELL) {
            for xx in (x0..(x0 + size).min(g.width)).step_by(CELL) {
                let cell = &self.tiles8[g.tile(8, xx, yy, c)];
                if cell.count > 0 {
                    leaning.push((g.cell(xx, yy), cell.leaning(z)));
                }
            }
        }
        if scale == 2 {
            let most = leaning
                .iter()
                .map(|l| l.1)
                .fold(f64::NEG_INFINITY, f64::max);
            let least = most.min(CELL_Z);
            leaning.retain(|l| l.1 >= least);
        }
        let w = Worst {
            p: adjusted,
            scale,
            channel: c,
            z,
        };
        for (cell, _) in leaning {
            mark(&mut self.cells[cell], w);
        }
    }

    /// The global scale's result, and its worst failing channel.
    fn global_scale(&self, threshold: f64) -> (ScaleResult, Option<Worst>) {
        let (mut g_min, mut g_z, mut g_fail, mut g_worst) = (1.0f64, 0.0f64, 0usize, None);
        for (c, s) in self.global.iter().enumerate() {
            let (p, z) = s.test();
            g_z = g_z.max(z.abs());
            let adjusted = sidak(p, 3.0);
            if adjusted < g_min {
                g_min = adjusted;
            }
            if adjusted < threshold {
                g_fail += 1;
                let w = Worst {
                    p: adjusted,
                    scale: 3,
                    channel: c,
                    z,
                };
                mark(&mut g_worst, w);
            }
        }
        let result = ScaleResult {
            scale: SCALES[3].into(),
            tests: 3,
            smallest_adjusted_p: g_min,
            threshold,
            largest_abs_z: g_z,
            failing: g_fail,
        };
        (result, g_worst)
    }
}

impl NoiseSums {
    /// Adds one pixel-channel whose noise shows through the quantisation; returns its squared
    /// residual, the bound on its expectation and its cap under the claim.
    fn add(&mut self, t: &Term, claim: &Claim) -> (f64, f64, f64) {
        let Term {
            lo, hi, mu, s2, b, ..
        } = *t;
        let mid = 0.5 * (lo + hi);
        self.neff_num += s2;
        self.neff_den += (mid - mu).powi(2) - (hi - lo).powi(2) / 12.0 - s2 / claim.m;
        self.neff_count += 1;
        // Under the claim, d = mid - mu = (mean - mu) + (mid - mean) with
        // E (mean - mu)^2 <= lambda s2_eff / n + s2 / m (the variance the tests
        // allow) and |mid - mean| <= w / 2, so E d^2 <= e (Minkowski), and
        // |d| <= b + w / 2 + slack, so d^2 <= cap and Var d^2 <= cap e.
        let w = hi - lo;
        let e = (t.variance.sqrt() + w / 2.0).powi(2);
        let cap = (b + w / 2.0 + t.slack).powi(2);
        ((mid - mu).powi(2), e, cap)
    }

    /// The effective spp, when enough pixels show their noise.
    fn effective_spp(&self) -> Option<f64> {
        (self.neff_count >= NOISE_MIN_PIXELS && self.neff_den > 0.0)
            .then(|| self.neff_num / self.neff_den)
    }

    /// Whether the candidate is as noisy as `claimed_spp` samples allow, when enough pixels
    /// show their noise.
    fn check(&self, claimed_spp: u32) -> Option<NoiseCheck> {
        (self.neff_count >= NOISE_MIN_PIXELS).then(|| {
            // Bernstein's inequality for the sum of the independent squared residuals (bounded
            // by sq_max, variances summing to at most sq_var) above its bound under the claim.
            let excess = self.sq_sum - self.sq_bound;
            let p = if excess <= 0.0 {
                1.0
            } else {
                (-excess * excess / (2.0 * self.sq_var + 2.0 * self.sq_max * excess / 3.0))
                    .exp()
                    .min(1.0)
            };
            NoiseCheck {
                claimed_spp,
                effective_spp: self.effective_spp(),
                pixels: self.neff_count,
                p,
                threshold: NOISE_ALPHA,
                passed: p >= NOISE_ALPHA,
            }
        })
    }
}

/// Runs the statistic on a candidate read with `encoding` against `golden`.
pub fn evaluate(
    candidate: &CandidateImage,
    golden: &Golden,
    encoding: Encoding,
    options: &CompareOptions,
) -> Evaluation {
    let (width, height) = (golden.width, golden.height);
    let iv = Intervals::of(candidate, encoding);
    let claim = Claim {
        n: options.samples_per_pixel.max(1) as f64,
        m: golden.samples_per_pixel as f64,
        lambda: options.lambda,
        threshold: options.alpha / SCALES.len() as f64,
        pixel_tests: (width * height * 3) as f64,
    };
    let grids = Grids::of(width, height);
    let mut pass = PixelPass::run(&iv, golden, &claim, &grids);
    let mut scales = vec![pass.pixel_scale(&claim)];
    scales.push(pass.tile_scale(1, &grids, claim.threshold));
    scales.push(pass.tile_scale(2, &grids, claim.threshold));
    let (global, global_worst) = pass.global_scale(claim.threshold);
    scales.push(global);

    let mut regions = regions_of(&pass.cells, grids.cx, grids.cy, width, height);
    if let (true, Some(w)) = (regions.is_empty(), global_worst) {
        regions.push(region(0, 0, width, height, w));
    }
    let effective_spp = pass.noise.effective_spp();
    let noise = pass.noise.check(options.samples_per_pixel);
    let passed = scales.iter().all(|s| s.failing == 0) && noise.as_ref().is_none_or(|n| n.passed);
    let pixels = (width * height) as f64;
    Evaluation {
        passed,
        scales,
        regions,
        noise,
        z_map: pass.z_map,
        bias: pass.bias.map(|b| b / pixels),
        rel_mse: pass.rel_mse / (3.0 * pixels),
        effective_spp,
        misfit: pass.misfit,
        encoding: iv.encoding,
    }
}

fn region(x: usize, y: usize, width: usize, height: usize, w: Worst) -> Region {
    Region {
        x,
        y,
        width,
        height,
        scale: SCALES[w.scale].into(),
        channel: CHANNELS[w.channel].into(),
        adjusted_p: w.p,
        z: w.z,
        change: None,
    }
}

/// Connected groups of failing cells (8-connected within 32x32 blocks), as pixel boxes, worst
/// first (all of them: the report lists the first [`REGIONS_LISTED`], the heatmap outlines
/// every one, so an image wrong all over is outlined all over).
fn regions_of(
    cells: &[Option<Worst>],
    cx: usize,
    cy: usize,
    width: usize,
    height: usize,
) -> Vec<Region> {
    let mut seen = vec![false; cells.len()];
    let mut out = Vec::new();
    for start in 0..cells.len() {
        if seen[start] || cells[start].is_none() {
            continue;
        }
        seen[start] = true;
        let mut stack = vec![start];
        let (mut x0, mut y0, mut x1, mut y1) = (usize::MAX, usize::MAX, 0, 0);
        let mut worst = cells[start].unwrap();
        while let Some(k) = stack.pop() {
            let (x, y) = (k % cx, k / cx);
            x0 = x0.min(x);
            y0 = y0.min(y);
            x1 = x1.max(x);
            y1 = y1.max(y);
            let w = cells[k].unwrap();
            if w.p < worst.p || (w.p == worst.p && w.z.abs() > worst.z.abs()) {
                worst = w;
            }
            for dy in -1isize..=1 {
                for dx in -1isize..=1 {
                    let (nx, ny) = (x as isize + dx, y as isize + dy);
                    if nx < 0 || ny < 0 || nx >= cx as isize || ny >= cy as isize {
                        continue;
                    }
                    let j = ny as usize * cx + nx as usize;
                    let same_block =
                        (nx as usize / BLOCK, ny as usize / BLOCK) == (x / BLOCK, y / BLOCK);
                    if same_block && !seen[j] && cells[j].is_some() {
                        seen[j] = true;
                        stack.push(j);
                    }
                }
            }
        }
        let (px, py) = (x0 * CELL, y0 * CELL);
        let pw = ((x1 + 1) * CELL).min(width) - px;
        let ph = ((y1 + 1) * CELL).min(height) - py;
        out.push(region(px, py, pw, ph, worst));
    }
    out.sort_by(|a, b| {
        a.adjusted_p
            .total_cmp(&b.adjusted_p)
            .then(b.z.abs().total_cmp(&a.z.abs()))
            .then((a.y, a.x).cmp(&(b.y, b.x)))
    });
    out
}

impl Evaluation {
    /// The report of this evaluation.
    pub(crate) fn into_comparison(
        self,
        candidate: &CandidateImage,
        golden: &Golden,
        options: &CompareOptions,
        diagnosis: Option<Diagnosis>,
    ) -> Comparison {
        let (width, height) = candidate.size();
        let regions_total = self.regions.len();
        let ranked =
            super::regions::rank(self.regions, &self.z_map, (width, height), REGIONS_LISTED);
        let listed = ranked.iter().take(REGIONS_LISTED).cloned().collect();
        Comparison {
            verdict: if self.passed {
                Verdict::Pass
            } else {
                Verdict::Fail
            },
            candidate: None,
            width,
            height,
            candidate_spp: options.samples_per_pixel,
            golden_spp: golden.samples_per_pixel,
            scene: golden.scene.clone(),
            encoding: self
                .encoding
                .map_or_else(|| "exr".to_string(), |e| e.name().to_string()),
            alpha: options.alpha,
            scales: self.scales,
            regions: listed,
            regions_total,
            outline: ranked,
            noise: self.noise,
            bias: self.bias,
            rel_mse: Some(self.rel_mse),
            flip: None,
            flip_map: Vec::new(),
            effective_spp: self.effective_spp,
            diagnosis,
            z_map: self.z_map,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat golden (every sample the same colour) is decided exactly: the right codes pass,
    /// one code off fails.
    #[test]
    fn a_flat_golden_is_decided_exactly() {
        let (w, h) = (16, 16);
        let colour = [0.25, 0.5, 0.64];
        let golden =
            Golden::new(w, h, 1024, vec![colour; w * h], vec![[0.0; 3]; w * h], None).unwrap();
        let codes: Vec<u8> = (0..w * h)
            .flat_map(|_| colour.map(|x| Encoding::Course.encode(x)))
            .collect();
        let options = CompareOptions::default();
        let good = CandidateImage::Rgb8 {
            width: w,
            height: h,
            data: codes.clone(),
        };
        assert!(evaluate(&good, &golden, Encoding::Course, &options).passed);
        let mut off = codes;
        off[3 * 37 + 1] += 1;
        let bad = CandidateImage::Rgb8 {
            width: w,
            height: h,
            data: off,
        };
        let e = evaluate(&bad, &golden, Encoding::Course, &options);
        assert!(!e.passed);
        assert_eq!(e.scales[0].failing, 1);
        // The region is the cell of pixel 37 = (5, 2).
        assert_eq!((e.regions[0].x, e.regions[0].y), (0, 0));
        assert_eq!(e.regions[0].channel, "G");
        assert!(e.regions[0].z > 0.0);
    }

    /// The film clamps: a golden brighter than 1 in blue is written as the top code (254 in the
    /// course's encoding) and passes; a lower code still fails, and so does the top code where
    /// the golden is below the code's interval.
    #[test]
    fn the_top_code_stands_for_every_brighter_value() {
        let (w, h) = (8, 8);
        let golden = Golden::new(
            w,
            h,
            1024,
            vec![[0.5, 0.9, 1.2]; w * h],
            vec![[1e-4, 1e-4, 1e-4]; w * h],
            None,
        )
        .unwrap();
        let options = CompareOptions::default();
        let image = |blue: u8| CandidateImage::Rgb8 {
            width: w,
            height: h,
            data: (0..w * h)
                .flat_map(|_| {
                    [
                        Encoding::Course.encode(0.5),
                        Encoding::Course.encode(0.9),
                        blue,
                    ]
                })
                .collect(),
        };
        assert_eq!(Encoding::Course.encode(1.2), 254);
        assert!(evaluate(&image(254), &golden, Encoding::Course, &options).passed);
        assert!(!evaluate(&image(250), &golden, Encoding::Course, &options).passed);
        let dim = Golden::new(
            w,
            h,
            1024,
            vec![[0.5, 0.9, 0.9]; w * h],
            vec![[1e-4, 1e-4, 1e-4]; w * h],
            None,
        )
        .unwrap();
        assert!(!evaluate(&image(254), &dim, Encoding::Course, &options).passed);
    }

    /// An overexposed region (every pixel's mean 1.02 in blue, its samples `1.02 +- 0.45`) is
    /// censored by the film: an honest 4-spp candidate shows the top code two times in three
    /// and is darker otherwise, so `mu - hi` summed over the region leans dark by about 24
    /// standard deviations. The sums compare it with the expected clamped mean instead, so the
    /// honest candidate passes (fixed seed), and the same region rendered at half its
    /// brightness still fails at a sum's scale.
    #[test]
    fn an_overexposed_region_is_judged_by_its_clamped_mean() {
        let (w, h, n) = (64, 64, 4u32);
        let (mu, spread) = (1.02, 0.2f64.sqrt());
        let golden = Golden::new(
            w,
            h,
            4096,
            vec![[0.25, 0.25, mu]; w * h],
            vec![[0.0, 0.0, spread * spread]; w * h],
            None,
        )
        .unwrap();
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut coin = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state >> 63 == 1
        };
        let image = |blue: &mut dyn FnMut() -> f64| CandidateImage::Rgb8 {
            width: w,
            height: h,
            data: (0..w * h)
                .flat_map(|_| {
                    let q = Encoding::Course.encode(0.25);
                    [q, q, Encoding::Course.encode(blue())]
                })
                .collect(),
        };
        let mut honest = || {
            let sum: f64 = (0..n)
                .map(|_| if coin() { mu + spread } else { mu - spread })
                .sum();
            sum / n as f64
        };
        let options = CompareOptions {
            samples_per_pixel: n,
            ..CompareOptions::default()
        };
        let e = evaluate(&image(&mut honest), &golden, Encoding::Course, &options);
        assert!(e.passed, "{:?}", e.scales);
        let e = evaluate(&image(&mut || 0.51), &golden, Encoding::Course, &options);
        assert!(!e.passed);
        assert!(
            e.scales[1..].iter().any(|s| s.failing > 0),
            "{:?}",
            e.scales
        );
    }

    /// relMSE against a golden of 1: a linear candidate of 0.9 gives 0.01 / 1.01 (by hand:
    /// `(0.9 - 1)^2 / (1 + 0.01)` everywhere), one equal to the golden 0.
    #[test]
    fn rel_mse_of_a_uniform_scale() {
        let golden = Golden::new(4, 4, 4096, vec![[1.0; 3]; 16], vec![[0.0; 3]; 16], None).unwrap();
        let scaled = CandidateImage::Linear {
            width: 4,
            height: 4,
            data: vec![[0.9; 3]; 16],
        };
        let options = CompareOptions::default();
        let e = evaluate(&scaled, &golden, Encoding::Course, &options);
        assert!((e.rel_mse - 0.01 / 1.01).abs() < 1e-6, "{}", e.rel_mse);
        let same = CandidateImage::Linear {
            width: 4,
            height: 4,
            data: vec![[1.0; 3]; 16],
        };
        assert!(evaluate(&same, &golden, Encoding::Course, &options).rel_mse < 1e-12);
    }

    /// A linear candidate equal to the golden passes; off by 1% in red fails, darker.
    #[test]
    fn linear_candidates_use_half_float_intervals() {
        let golden = Golden::new(4, 4, 4096, vec![[0.5; 3]; 16], vec![[0.0; 3]; 16], None).unwrap();
        let same = CandidateImage::Linear {
            width: 4,
            height: 4,
            data: vec![[0.5; 3]; 16],
        };
        let options = CompareOptions::default();
        assert!(evaluate(&same, &golden, Encoding::Course, &options).passed);
        let mut data = vec![[0.5f32; 3]; 16];
        data[5][0] = 0.495;
        let off = CandidateImage::Linear {
            width: 4,
            height: 4,
            data,
        };
        let e = evaluate(&off, &golden, Encoding::Course, &options);
        assert!(!e.passed);
        assert!(e.regions[0].z < 0.0);
        assert_eq!(e.encoding, None);
    }
}
