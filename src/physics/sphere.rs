//! The sphere of directions cut into cells, and integrals over it.
//!
//! Cells are taken in the frame of the surface's normal `n`: [`BANDS`] bands of equal area in
//! `z = cos theta` (from -1 to 1, both hemispheres: a BRDF's pdf must vanish below the surface)
//! and [`SECTORS`] sectors in azimuth, so every cell has the same solid angle `4 pi / CELLS`.
//! In `(z, phi)` the solid angle is `dz dphi`, so an integral over a cell is a plain integral
//! over a rectangle.
//!
//! [`integrate`] integrates up to four functions over every cell at once, adaptively: a
//! rectangle's 2x2 Gauss-Legendre rule against the sum of its four quarters' rules; where the
//! two disagree by more than the caller's tolerance, each quarter is refined in the next round,
//! down to [`MAX_DEPTH`] levels or [`MAX_NODES`] evaluations. The functions are evaluated a
//! round at a time (one batch of directions per round), which is what a candidate answering
//! over a pipe needs. Each cell's result comes with an error estimate, the sum over its
//! accepted rectangles of `|rule - refined rule|`, which the checks add to their allowances.

use std::f64::consts::PI;

use glam::DVec3;

/// Bands in `cos theta`.
pub const BANDS: usize = 16;
/// Sectors in azimuth.
pub const SECTORS: usize = 32;
/// Cells on the sphere.
pub const CELLS: usize = BANDS * SECTORS;
/// Deepest refinement of a cell (a rectangle a quarter of its parent's size each level).
pub const MAX_DEPTH: u32 = 5;
/// Shallowest and deepest refinement of a cell whose integral disagrees with the samples found
/// in it.
pub const DEPTHS_SUSPECT: (u32, u32) = (4, 9);
/// Most evaluations of one integration (past it every rectangle left is accepted as it is,
/// with its error estimate).
pub const MAX_NODES: usize = 150_000;

/// The frame of a normal: `t`, `b`, `n`, right-handed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// First tangent.
    pub t: DVec3,
    /// Second tangent.
    pub b: DVec3,
    /// The normal.
    pub n: DVec3,
}

impl Frame {
    /// The frame of the unit normal `n`.
    pub fn new(n: DVec3) -> Frame {
        let (t, b) = n.any_orthonormal_pair();
        Frame { t, b, n }
    }

    /// `d` in this frame's coordinates.
    pub fn local(&self, d: DVec3) -> DVec3 {
        DVec3::new(d.dot(self.t), d.dot(self.b), d.dot(self.n))
    }

    /// The world direction of `(z, phi)`.
    pub fn direction(&self, z: f64, phi: f64) -> DVec3 {
        let r = (1.0 - z * z).max(0.0).sqrt();
        r * phi.cos() * self.t + r * phi.sin() * self.b + z * self.n
    }
}

/// The cell of the unit direction `d` (in `frame`).
pub fn cell_of(frame: &Frame, d: DVec3) -> usize {
    let l = frame.local(d);
    let band = (((l.z.clamp(-1.0, 1.0) + 1.0) * 0.5 * BANDS as f64) as usize).min(BANDS - 1);
    let phi = l.y.atan2(l.x).rem_euclid(2.0 * PI);
    let sector = ((phi / (2.0 * PI) * SECTORS as f64) as usize).min(SECTORS - 1);
    band * SECTORS + sector
}

/// The rectangle `[z0, z1] x [p0, p1]` of cell `cell`.
fn cell_rect(cell: usize) -> Rect {
    let (band, sector) = (cell / SECTORS, cell % SECTORS);
    let dz = 2.0 / BANDS as f64;
    let dp = 2.0 * PI / SECTORS as f64;
    Rect {
        z0: -1.0 + band as f64 * dz,
        z1: -1.0 + (band + 1) as f64 * dz,
        p0: sector as f64 * dp,
        p1: (sector + 1) as f64 * dp,
        cell,
        depth: 0,
        rule: [0.0; 4],
    }
}

/// Up to four values of the integrand at one direction.
pub type Values = [f64; 4];

#[derive(Clone, Copy, Debug)]
struct Rect {
    z0: f64,
    z1: f64,
    p0: f64,
    p1: f64,
    cell: usize,
    depth: u32,
    /// Its own 2x2 rule's value (known from the round before).
    rule: Values,
}

impl Rect {
    fn area(&self) -> f64 {
        (self.z1 - self.z0) * (self.p1 - self.p0)
    }

    /// The 2x2 Gauss-Legendre nodes, as `(z, phi)`.
    fn nodes(&self) -> [(f64, f64); 4] {
        let g = 0.5 / 3f64.sqrt();
        let (zm, zh) = (0.5 * (self.z0 + self.z1), self.z1 - self.z0);
        let (pm, ph) = (0.5 * (self.p0 + self.p1), self.p1 - self.p0);
        [
            (zm - g * zh, pm - g * ph),
            (zm + g * zh, pm - g * ph),
            (zm - g * zh, pm + g * ph),
            (zm + g * zh, pm + g * ph),
        ]
    }

    fn quarters(&self) -> [Rect; 4] {
        let (zm, pm) = (0.5 * (self.z0 + self.z1), 0.5 * (self.p0 + self.p1));
        let q = |z0, z1, p0, p1| Rect {
            z0,
            z1,
            p0,
            p1,
            cell: self.cell,
            depth: self.depth + 1,
            rule: [0.0; 4],
        };
        [
            q(self.z0, zm, self.p0, pm),
            q(zm, self.z1, self.p0, pm),
            q(self.z0, zm, pm, self.p1),
            q(zm, self.z1, pm, self.p1),
        ]
    }
}

/// Each cell's integrals and error estimates.
#[derive(Clone, Debug, PartialEq)]
pub struct CellIntegrals {
    /// The integral of each function over each cell.
    pub value: Vec<Values>,
    /// The error estimate of each.
    pub error: Vec<Values>,
    /// Evaluations spent.
    pub nodes: usize,
    /// Whether [`MAX_NODES`] stopped the refinement.
    pub capped: bool,
}

impl CellIntegrals {
    /// The integral of function `k` over the sphere, and its error estimate.
    pub fn total(&self, k: usize) -> (f64, f64) {
        (
            self.value.iter().map(|v| v[k]).sum(),
            self.error.iter().map(|e| e[k]).sum(),
        )
    }
}

/// Integrates `f` over every cell of the sphere in `frame` ([`integrate_cells`] of them all, to
/// [`MAX_DEPTH`]).
#[allow(clippy::type_complexity)]
pub fn integrate<E>(
    frame: &Frame,
    f: &mut dyn FnMut(&[DVec3]) -> Result<Vec<Values>, E>,
    accept: &dyn Fn(&Values, &Values, f64) -> bool,
) -> Result<CellIntegrals, E> {
    let all: Vec<usize> = (0..CELLS).collect();
    integrate_cells(frame, &all, (0, MAX_DEPTH), f, accept)
}

/// Integrates `f` over the cells `cells` of the sphere in `frame` (the others are left 0),
/// refining every rectangle to at least `depths.0` levels below its cell (so that a lobe
/// between the first nodes is found) and at most `depths.1`. `f` gets a batch of unit
/// directions and returns their values; `accept(rule, refined, area)` says whether a
/// rectangle's refined rule is close enough to its own rule.
#[allow(clippy::type_complexity)]
pub fn integrate_cells<E>(
    frame: &Frame,
    cells: &[usize],
    (min_depth, max_depth): (u32, u32),
    f: &mut dyn FnMut(&[DVec3]) -> Result<Vec<Values>, E>,
    accept: &dyn Fn(&Values, &Values, f64) -> bool,
) -> Result<CellIntegrals, E> {
    let mut value = vec![[0.0; 4]; CELLS];
    let mut error = vec![[0.0; 4]; CELLS];
    let mut nodes = 0;
    // The cells' own rules first.
    let mut work: Vec<Rect> = cells.iter().map(|&c| cell_rect(c)).collect();
    let dirs: Vec<DVec3> = work
        .iter()
        .flat_map(|r| r.nodes().map(|(z, p)| frame.direction(z, p)))
        .collect();
    let got = f(&dirs)?;
    nodes += got.len();
    for (r, vals) in work.iter_mut().zip(got.chunks(4)) {
        r.rule = rule(vals, r.area());
    }
    let mut capped = false;
    while !work.is_empty() {
        let quarters: Vec<Rect> = work.iter().flat_map(Rect::quarters).collect();
        let dirs: Vec<DVec3> = quarters
            .iter()
            .flat_map(|r| r.nodes().map(|(z, p)| frame.direction(z, p)))
            .collect();
        let got = f(&dirs)?;
        nodes += got.len();
        let mut next = Vec::new();
        let stop = nodes + 16 * 4 * work.len() > MAX_NODES;
        for (parent, kids) in work.iter().zip(quarters.chunks(4).zip(got.chunks(16))) {
            let (rects, vals) = kids;
            let mut refined = [0.0; 4];
            let mut rules = [[0.0; 4]; 4];
            for (k, rect) in rects.iter().enumerate() {
                rules[k] = rule(&vals[4 * k..4 * k + 4], rect.area());
                for c in 0..4 {
                    refined[c] += rules[k][c];
                }
            }
            let done = parent.depth + 1 >= max_depth || stop;
            let deep_enough = parent.depth + 1 >= min_depth;
            if done || (deep_enough && accept(&parent.rule, &refined, parent.area())) {
                capped |= stop && !accept(&parent.rule, &refined, parent.area());
                for c in 0..4 {
                    value[parent.cell][c] += refined[c];
                    error[parent.cell][c] += (refined[c] - parent.rule[c]).abs();
                }
            } else {
                for (k, rect) in rects.iter().enumerate() {
                    next.push(Rect {
                        rule: rules[k],
                        ..*rect
                    });
                }
            }
        }
        work = next;
    }
    Ok(CellIntegrals {
        value,
        error,
        nodes,
        capped,
    })
}

/// The 2x2 rule's value from the four nodes' values.
fn rule(vals: &[Values], area: f64) -> Values {
    let mut out = [0.0; 4];
    for v in vals {
        for c in 0..4 {
            out[c] += v[c];
        }
    }
    out.map(|s| s * area / 4.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Closed forms: the sphere's area `4 pi` and the cosine over the upper hemisphere `pi`, each
    /// to 1e-9 or better, and `cos^8` over it `2 pi / 9` within the error estimate (the
    /// refinement stops at its depth); every cell has the area `4 pi / CELLS`.
    #[test]
    fn integrals_match_closed_forms() {
        let frame = Frame::new(DVec3::new(0.3, -0.4, 0.5).normalize());
        let n = frame.n;
        let mut f = |dirs: &[DVec3]| -> Result<Vec<Values>, ()> {
            Ok(dirs
                .iter()
                .map(|d| {
                    let c = d.dot(n);
                    [1.0, c.max(0.0), c.max(0.0).powi(8), 0.0]
                })
                .collect())
        };
        let r = integrate(&frame, &mut f, &|a, b, _| {
            (0..4).all(|k| (a[k] - b[k]).abs() <= 1e-13)
        })
        .unwrap();
        assert!((r.total(0).0 - 4.0 * PI).abs() < 1e-9);
        assert!((r.total(1).0 - PI).abs() < 1e-9, "{:?}", r.total(1));
        let (v, e) = r.total(2);
        assert!(
            (v - 2.0 * PI / 9.0).abs() <= e + 1e-12 && e < 1e-6,
            "{v} {e}"
        );
        for v in &r.value {
            assert!((v[0] - 4.0 * PI / CELLS as f64).abs() < 1e-12);
        }
    }

    /// Every direction lands in the cell whose rectangle holds its `(z, phi)`.
    #[test]
    fn cells_hold_their_directions() {
        let frame = Frame::new(DVec3::new(-0.2, 0.9, 0.1).normalize());
        for cell in 0..CELLS {
            let r = cell_rect(cell);
            let d = frame.direction(0.5 * (r.z0 + r.z1), 0.5 * (r.p0 + r.p1));
            assert_eq!(cell_of(&frame, d), cell);
        }
    }
}
