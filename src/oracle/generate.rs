//! Edge-case generators: every family of `docs/oracle.md` ("How the cases are generated") built
//! exactly in `f64` (integer and dyadic
//! geometry, so tangents, edges, corners and interval ends are exact), ulp ladders around them,
//! and random cases across scales `2^-20 .. 2^20`. Every case is then classified exactly.
//!
//! Each (shape, category) pair draws from its own PCG stream seeded from the seed and its name,
//! so a case's id (`quad-corner-0007`) and bytes depend only on the seed and the count.

use rand_core::Rng;
use rand_pcg::Pcg64;

use super::classify::classify_tagged_with;
use super::profile::Judging;
use super::vectors::{Case, RaySpec, ShapeKind, ShapeSpec};

/// The course camera's interval `(1e-6, f64::MAX)`.
pub const CAMERA: [f64; 2] = [1e-6, f64::MAX];

/// A deterministic random stream.
pub struct Stream(Pcg64);

fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

fn hash_name(name: &str) -> u64 {
    // FNV-1a: stable across platforms and versions.
    name.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ b as u64).wrapping_mul(0x100_0000_01b3)
    })
}

impl Stream {
    /// The stream for `seed` and a name.
    pub fn new(seed: u64, name: &str) -> Self {
        let h = hash_name(name);
        let state = ((mix(seed) as u128) << 64) | mix(h ^ 0x9e37_79b9_7f4a_7c15) as u128;
        Stream(Pcg64::new(state, ((h as u128) << 64) | seed as u128))
    }
    /// 64 random bits.
    pub fn bits(&mut self) -> u64 {
        self.0.next_u64()
    }
    /// Uniform in `[0, 1)`.
    pub fn f(&mut self) -> f64 {
        (self.bits() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
    /// Uniform in `[lo, hi)`.
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.f()
    }
    /// Uniform integer in `lo..=hi`.
    pub fn int(&mut self, lo: i64, hi: i64) -> i64 {
        lo + (self.bits() % ((hi - lo + 1) as u64)) as i64
    }
    /// A fair coin.
    pub fn coin(&mut self) -> bool {
        self.bits() & 1 == 1
    }
    /// `2^k` for a uniform integer `k` in `lo..=hi`.
    pub fn pow2(&mut self, lo: i64, hi: i64) -> f64 {
        pow2(self.int(lo, hi))
    }
    /// A log-uniform scale in `[2^lo, 2^hi)`.
    pub fn log_scale(&mut self, lo: f64, hi: f64) -> f64 {
        libm::exp2(self.uniform(lo, hi))
    }
    /// An integer vector with components in `lo..=hi`.
    pub fn ivec(&mut self, lo: i64, hi: i64) -> [f64; 3] {
        [0; 3].map(|_| self.int(lo, hi) as f64)
    }
    /// A uniform direction on the unit sphere.
    pub fn unit(&mut self) -> [f64; 3] {
        loop {
            let v = [0; 3].map(|_| self.uniform(-1.0, 1.0));
            let l = dot(v, v);
            if l > 1e-4 && l <= 1.0 {
                return scale(v, 1.0 / l.sqrt());
            }
        }
    }
}

/// `2^k` exactly.
pub fn pow2(k: i64) -> f64 {
    libm::exp2(k as f64)
}

/// `x` moved by `n` units in the last place (through zero, across signs, as the ordered bit
/// patterns count).
pub fn nudge(x: f64, n: i64) -> f64 {
    let b = x.to_bits() as i64;
    let key = if b < 0 { i64::MIN - b } else { b };
    let key = key.saturating_add(n);
    let b = if key < 0 { i64::MIN - key } else { key };
    f64::from_bits(b as u64)
}

/// Dot product.
pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
/// `a + b`.
pub fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
/// `a - b`.
pub fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
/// `a * s`.
pub fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    a.map(|x| x * s)
}
/// `a x b`.
pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// A generated case before classification.
#[derive(Clone, Debug)]
pub struct Raw {
    /// The primitive.
    pub shape: ShapeSpec,
    /// The ray.
    pub ray: RaySpec,
    /// The interval.
    pub interval: [f64; 2],
    /// The generator's tags.
    pub tags: Vec<&'static str>,
}

fn raw(
    shape: ShapeSpec,
    origin: [f64; 3],
    direction: [f64; 3],
    interval: [f64; 2],
    tags: &[&'static str],
) -> Raw {
    Raw {
        shape,
        ray: RaySpec { origin, direction },
        interval,
        tags: tags.to_vec(),
    }
}

/// A raw case with no tags.
pub fn raw_parts(
    shape: ShapeSpec,
    origin: [f64; 3],
    direction: [f64; 3],
    interval: [f64; 2],
) -> Raw {
    raw(shape, origin, direction, interval, &[])
}

/// Integer Pythagorean frames: `(d, n, L)` with `d . n = 0` and `|d| = |n| = L`.
const FRAMES: [([f64; 3], [f64; 3], f64); 4] = [
    ([2.0, 3.0, 6.0], [6.0, 2.0, -3.0], 7.0),
    ([1.0, 2.0, 2.0], [2.0, 1.0, -2.0], 3.0),
    ([4.0, 4.0, 7.0], [1.0, -8.0, 4.0], 9.0),
    ([2.0, 3.0, 6.0], [3.0, -6.0, 2.0], 7.0),
];

/// A frame under a random signed permutation of the axes (which keeps orthogonality).
fn frame(r: &mut Stream, i: usize) -> ([f64; 3], [f64; 3], f64) {
    let (d, n, l) = FRAMES[i % FRAMES.len()];
    let perms = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    let p = perms[r.int(0, 5) as usize];
    let s = [0; 3].map(|_| if r.coin() { 1.0 } else { -1.0 });
    let apply = |v: [f64; 3]| [v[p[0]] * s[0], v[p[1]] * s[1], v[p[2]] * s[2]];
    (apply(d), apply(n), l)
}

/// A random sphere case: scale log-uniform in `2^-20 .. 2^20`, the origin at up to
/// `max_ratio` radii from the centre, aimed at an offset of `offset` radii from the centre
/// (`None`: uniform in `[0, 1.3]`), the direction's length log-uniform in `1e-3 .. 1e3`.
pub fn random_sphere(r: &mut Stream, max_ratio: f64, offset: Option<(f64, f64)>) -> Raw {
    let s = r.log_scale(-20.0, 20.0);
    let radius = s * r.uniform(0.5, 2.0);
    let center = scale(r.unit(), s * r.uniform(0.0, 8.0));
    let ratio = libm::exp2(r.uniform(0.6, max_ratio.log2()));
    let dir_from = r.unit();
    let origin = add(center, scale(dir_from, ratio * radius));
    // A direction perpendicular to dir_from for the offset.
    let mut perp = cross(dir_from, r.unit());
    let pl = dot(perp, perp).sqrt();
    if pl < 1e-3 {
        perp = cross(dir_from, [1.0, 0.0, 0.0]);
    }
    perp = scale(perp, 1.0 / dot(perp, perp).sqrt());
    let (lo, hi) = offset.unwrap_or((0.0, 1.3));
    let target = add(center, scale(perp, radius * r.uniform(lo, hi)));
    let d = sub(target, origin);
    let len = r.log_scale(-10.0, 10.0) / dot(d, d).sqrt();
    let direction = scale(d, len);
    raw(
        ShapeSpec::Sphere { center, radius },
        origin,
        direction,
        CAMERA,
        &["random"],
    )
}

/// A random quad (`triangle == false`) or triangle case at a log-uniform scale.
pub fn random_plane(r: &mut Stream, triangle: bool) -> Raw {
    let s = r.log_scale(-20.0, 20.0);
    let q = scale(r.unit(), s * r.uniform(0.0, 8.0));
    let u = scale(r.unit(), s * r.uniform(0.3, 3.0));
    let v = scale(r.unit(), s * r.uniform(0.3, 3.0));
    let (lo, hi) = if triangle { (-0.2, 0.8) } else { (-0.4, 1.4) };
    let (a, b) = (r.uniform(lo, hi), r.uniform(lo, hi));
    let p = add(q, add(scale(u, a), scale(v, b)));
    let d = scale(r.unit(), r.log_scale(-10.0, 10.0));
    let origin = sub(p, scale(d, s * r.uniform(0.5, 20.0) / dot(d, d).sqrt()));
    let shape = if triangle {
        ShapeSpec::Triangle {
            a: q,
            b: add(q, u),
            c: add(q, v),
        }
    } else {
        ShapeSpec::Quad { q, u, v }
    };
    raw(shape, origin, d, CAMERA, &["random"])
}

/// Scales every position and the direction by `2^k` and translates by `offset`.
fn rescale(c: &Raw, k: i64, offset: [f64; 3]) -> Raw {
    let f = pow2(k);
    let pos = |p: [f64; 3]| add(scale(p, f), offset);
    let shape = match c.shape {
        ShapeSpec::Sphere { center, radius } => ShapeSpec::Sphere {
            center: pos(center),
            radius: radius * f,
        },
        ShapeSpec::Quad { q, u, v } => ShapeSpec::Quad {
            q: pos(q),
            u: scale(u, f),
            v: scale(v, f),
        },
        ShapeSpec::Triangle { a, b, c } => ShapeSpec::Triangle {
            a: pos(a),
            b: pos(b),
            c: pos(c),
        },
    };
    let mut out = c.clone();
    out.shape = shape;
    out.ray.origin = pos(c.ray.origin);
    out.ray.direction = scale(c.ray.direction, f);
    out.tags.push("scale");
    out
}

/// Every input number of a case: the shape's, the origin, the direction, the interval.
pub fn flatten(c: &Raw) -> Vec<f64> {
    let mut v = c.shape.numbers();
    v.extend(c.ray.origin);
    v.extend(c.ray.direction);
    v.extend(c.interval);
    v
}

/// The case of kind `kind` whose input numbers are `x` (as [`flatten`] lists them).
pub fn unflatten(kind: ShapeKind, x: &[f64], tags: Vec<&'static str>) -> Raw {
    let v3 = |i: usize| [x[i], x[i + 1], x[i + 2]];
    let (shape, n) = match kind {
        ShapeKind::Sphere => (
            ShapeSpec::Sphere {
                center: v3(0),
                radius: x[3],
            },
            4,
        ),
        ShapeKind::Quad => (
            ShapeSpec::Quad {
                q: v3(0),
                u: v3(3),
                v: v3(6),
            },
            9,
        ),
        ShapeKind::Triangle => (
            ShapeSpec::Triangle {
                a: v3(0),
                b: v3(3),
                c: v3(6),
            },
            9,
        ),
    };
    Raw {
        shape,
        ray: RaySpec {
            origin: v3(n),
            direction: v3(n + 3),
        },
        interval: [x[n + 6], x[n + 7]],
        tags,
    }
}

/// Replaces one input number (shape, ray or interval) with NaN, +-inf or -0.
fn poison(r: &mut Stream, c: &Raw) -> Raw {
    let bad = [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, -0.0][r.int(0, 3) as usize];
    let mut x = flatten(c);
    let k = r.int(0, x.len() as i64 - 1) as usize;
    x[k] = bad;
    unflatten(c.shape.kind(), &x, vec!["nonfinite"])
}

/// An exact tangent: `O = C + k n - s d`, `r = L k`, so `disc = 0` and `t = s` exactly.
fn tangent_parts(r: &mut Stream, i: usize) -> ([f64; 3], f64, [f64; 3], [f64; 3], [f64; 3]) {
    let (d, n, l) = frame(r, i);
    let k = r.pow2(-6, 6);
    let center = scale(r.ivec(-50, 50), r.pow2(-4, 4));
    let d = scale(d, r.pow2(-3, 3));
    let s = r.int(1, 64) as f64 * r.pow2(-3, 3);
    let origin = sub(add(center, scale(n, k)), scale(d, s));
    (center, l * k, origin, d, n)
}

fn sphere_case(cat: &str, r: &mut Stream, i: usize) -> Raw {
    let sph = |center, radius| ShapeSpec::Sphere { center, radius };
    match cat {
        "tangent" => {
            let (c, rad, o, d, _) = tangent_parts(r, i);
            raw(sph(c, rad), o, d, CAMERA, &["tangent"])
        }
        "near-tangent" => {
            let (c, rad, mut o, d, n) = tangent_parts(r, i);
            // Move O across the tangent along the axis where n is largest, by 2^j ulps.
            let axis = (0..3)
                .max_by(|&a, &b| n[a].abs().total_cmp(&n[b].abs()))
                .unwrap_or(0);
            let j = (i / 2) % 41;
            let step = 1i64 << j;
            o[axis] = nudge(o[axis], if i % 2 == 0 { step } else { -step });
            raw(sph(c, rad), o, d, CAMERA, &["near-tangent"])
        }
        "inside" => {
            let s = r.log_scale(-20.0, 20.0);
            let c = scale(r.unit(), s * r.uniform(0.0, 4.0));
            let o = add(c, scale(r.unit(), s * r.uniform(0.0, 0.9)));
            let d = scale(r.unit(), r.log_scale(-10.0, 10.0));
            raw(sph(c, s), o, d, CAMERA, &["inside"])
        }
        "behind" => {
            let s = r.log_scale(-20.0, 20.0);
            let o = scale(r.unit(), s * r.uniform(0.0, 4.0));
            let d = scale(r.unit(), r.log_scale(-10.0, 10.0));
            let far = s * r.uniform(2.0, 100.0) / dot(d, d).sqrt();
            let c = add(
                sub(o, scale(d, far)),
                scale(r.unit(), s * r.uniform(0.0, 0.5)),
            );
            raw(sph(c, s), o, d, CAMERA, &["behind"])
        }
        "interval-boundary" => {
            // Head-on through the centre: roots s -+ rho exactly, |d| = L 2^m.
            let (d, _, l) = frame(r, i);
            let m = r.pow2(-2, 2);
            let d = scale(d, m);
            let rho = r.int(1, 8) as f64 * r.pow2(-2, 1);
            let s = rho + r.int(1, 64) as f64 * r.pow2(-2, 2);
            let c = scale(r.ivec(-20, 20), r.pow2(-2, 2));
            let s = if i % 7 == 6 { rho } else { s };
            let o = sub(c, scale(d, s));
            let radius = rho * l * m;
            let (near, far) = (s - rho, s + rho);
            let j = r.int(0, 40);
            let step = 1i64 << j;
            let interval = match i % 7 {
                0 => [near, f64::MAX],
                1 => [1e-6, near],
                2 => [far, f64::MAX],
                3 => [nudge(near, -step), f64::MAX],
                4 => [nudge(near, step), f64::MAX],
                5 => [1e-6, nudge(far, if r.coin() { step } else { -step })],
                _ => CAMERA,
            };
            raw(sph(c, radius), o, d, interval, &["interval-boundary"])
        }
        "negative-radius" => {
            let mut c = random_sphere(r, 1e3, None);
            if let ShapeSpec::Sphere { radius, .. } = &mut c.shape {
                *radius = -*radius;
            }
            c.tags = vec!["negative-radius"];
            c
        }
        "scale" => {
            let c = random_sphere(r, 1e4, None);
            let k = r.int(-60, 60);
            let off = if r.coin() {
                scale(r.ivec(-1000, 1000), r.pow2(10, 30))
            } else {
                [0.0; 3]
            };
            rescale(&c, k, off)
        }
        "far" => {
            let mut c = random_sphere(r, 1e8, Some((0.0, 1.3)));
            c.tags = vec!["far"];
            c
        }
        "unnormalised" => {
            let mut c = random_sphere(r, 1e3, None);
            let len = libm::pow(10.0, r.uniform(-3.0, 3.0))
                / dot(c.ray.direction, c.ray.direction).sqrt();
            c.ray.direction = scale(c.ray.direction, len);
            c.tags = vec!["unnormalised"];
            c
        }
        "degenerate" => {
            let mut c = random_sphere(r, 1e3, None);
            if i % 2 == 0 {
                if let ShapeSpec::Sphere { radius, .. } = &mut c.shape {
                    *radius = if r.coin() { 0.0 } else { -0.0 };
                }
            } else {
                c.ray.direction = [0.0; 3];
            }
            c.tags = vec!["degenerate"];
            c
        }
        "nonfinite" => {
            let c = random_sphere(r, 1e3, None);
            poison(r, &c)
        }
        _ => random_sphere(r, 1e3, None),
    }
}

/// Integer edges `u`, `v` that span a plane, and an integer direction not too close to it.
fn int_quad(r: &mut Stream, span: i64) -> ([f64; 3], [f64; 3], [f64; 3], [f64; 3]) {
    loop {
        let q = r.ivec(-span, span);
        let u = r.ivec(-span, span);
        let v = r.ivec(-span, span);
        let n = cross(u, v);
        let d = r.ivec(-8, 8);
        let nn = dot(n, n);
        let nd = dot(n, d);
        if nn > 0.0 && nd * nd >= 0.01 * nn * dot(d, d) {
            return (q, u, v, d);
        }
    }
}

fn plane_shape(triangle: bool, q: [f64; 3], u: [f64; 3], v: [f64; 3]) -> ShapeSpec {
    if triangle {
        ShapeSpec::Triangle {
            a: q,
            b: add(q, u),
            c: add(q, v),
        }
    } else {
        ShapeSpec::Quad { q, u, v }
    }
}

/// Surface coordinates on an edge (`corner == false`) or at a corner / vertex.
fn edge_coords(r: &mut Stream, triangle: bool, corner: bool) -> (f64, f64) {
    let k = r.int(1, 63) as f64 / 64.0;
    if triangle {
        if corner {
            [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)][r.int(0, 2) as usize]
        } else {
            [(k, 0.0), (0.0, k), (k, 1.0 - k)][r.int(0, 2) as usize]
        }
    } else if corner {
        (r.int(0, 1) as f64, r.int(0, 1) as f64)
    } else {
        let e = r.int(0, 1) as f64;
        if r.coin() { (e, k) } else { (k, e) }
    }
}

/// `Q + a u + b v`.
fn surface_point(q: [f64; 3], u: [f64; 3], v: [f64; 3], a: f64, b: f64) -> [f64; 3] {
    add(q, add(scale(u, a), scale(v, b)))
}

/// A random dyadic `k / 64` with `k` in `lo..=hi`.
fn sixty_fourths(r: &mut Stream, lo: i64, hi: i64) -> f64 {
    r.int(lo, hi) as f64 / 64.0
}

/// One case of a quad or triangle category (`i` is the case's index in its category).
fn plane_case(cat: &str, triangle: bool, r: &mut Stream, i: usize) -> Raw {
    match cat {
        "edge" | "corner" => edge_case(triangle, cat == "corner", r, i),
        "skewed" | "skinny" => lean_case(triangle, cat == "skewed", r),
        "parallel" => parallel_case(triangle, r, i),
        "grazing" => grazing_case(triangle, r),
        "interval-boundary" => plane_interval_case(triangle, r, i),
        "behind" => {
            let (q, u, v, d) = int_quad(r, 8);
            let p = surface_point(q, u, v, sixty_fourths(r, 0, 64), sixty_fourths(r, 0, 32));
            let o = add(p, scale(d, r.pow2(0, 4)));
            raw(plane_shape(triangle, q, u, v), o, d, CAMERA, &["behind"])
        }
        "scale" => {
            let c = random_plane(r, triangle);
            let off = if r.coin() {
                scale(r.ivec(-1000, 1000), r.pow2(10, 30))
            } else {
                [0.0; 3]
            };
            rescale(&c, r.int(-60, 60), off)
        }
        "unnormalised" => {
            let mut c = random_plane(r, triangle);
            let len = libm::pow(10.0, r.uniform(-3.0, 3.0))
                / dot(c.ray.direction, c.ray.direction).sqrt();
            c.ray.direction = scale(c.ray.direction, len);
            c.tags = vec!["unnormalised"];
            c
        }
        "degenerate" => degenerate_plane_case(triangle, r, i),
        "nonfinite" => {
            let c = random_plane(r, triangle);
            poison(r, &c)
        }
        _ => random_plane(r, triangle),
    }
}

/// A ray through an edge or a corner (a vertex), exactly or, for odd `i`, off it by `2^j` ulps.
fn edge_case(triangle: bool, corner: bool, r: &mut Stream, i: usize) -> Raw {
    let (q, u, v, d) = int_quad(r, 8);
    let (a, b) = edge_coords(r, triangle, corner);
    let p = surface_point(q, u, v, a, b);
    let t = r.pow2(0, 4);
    let mut o = sub(p, scale(d, t));
    if i % 2 == 1 {
        // Just inside or outside by 2^j ulps.
        let j = r.int(0, 40);
        let axis = r.int(0, 2) as usize;
        o[axis] = nudge(o[axis], if r.coin() { 1 << j } else { -(1 << j) });
    }
    let tag = if corner { "corner" } else { "edge" };
    raw(plane_shape(triangle, q, u, v), o, d, CAMERA, &[tag])
}

/// A skewed primitive (`v` nearly along `u`, `skewed`) or a skinny one (one edge at least 16
/// times the other), hit or missed near its surface.
fn lean_case(triangle: bool, skewed: bool, r: &mut Stream) -> Raw {
    let (q, mut u, mut v, d) = int_quad(r, 8);
    if skewed {
        // v nearly along u: a thin parallelogram leaning far over.
        v = add(scale(u, r.int(2, 16) as f64), scale(v, r.pow2(-6, -1)));
    } else {
        u = scale(u, r.pow2(4, 8));
        v = scale(v, r.pow2(-8, -4));
    }
    let n = cross(u, v);
    let nd = dot(n, d);
    let d = if nd * nd < 0.01 * dot(n, n) * dot(d, d) {
        n
    } else {
        d
    };
    let (a, b) = (sixty_fourths(r, -16, 80), sixty_fourths(r, -16, 80));
    let p = surface_point(q, u, v, a, b);
    let o = sub(p, scale(d, r.pow2(0, 4)));
    let tag = if skewed { "skewed" } else { "skinny" };
    raw(plane_shape(triangle, q, u, v), o, d, CAMERA, &[tag])
}

/// A direction in the plane (`n . d = 0` exactly), the origin lifted off it, or in it for every
/// fourth case.
fn parallel_case(triangle: bool, r: &mut Stream, i: usize) -> Raw {
    let (q, u, v, _) = int_quad(r, 8);
    let n = cross(u, v);
    let (a, b) = (r.int(-4, 4) as f64, r.int(1, 4) as f64);
    let d = add(scale(u, a), scale(v, b));
    let p = surface_point(q, u, v, sixty_fourths(r, 0, 64), sixty_fourths(r, 0, 64));
    let lift = if i % 4 == 3 {
        0.0
    } else {
        r.int(-4, 4) as f64 * r.pow2(-10, 0)
    };
    let lift = if lift == 0.0 && i % 4 != 3 { 1.0 } else { lift };
    let o = sub(add(p, scale(n, lift)), scale(d, r.int(1, 4) as f64));
    raw(plane_shape(triangle, q, u, v), o, d, CAMERA, &["parallel"])
}

/// A direction in the plane tilted by `2^-j n`, aimed at the primitive's inside.
fn grazing_case(triangle: bool, r: &mut Stream) -> Raw {
    let (q, u, v, _) = int_quad(r, 8);
    let n = cross(u, v);
    let j = r.int(5, 60);
    let d = add(
        add(scale(u, r.int(-4, 4) as f64), scale(v, r.int(1, 4) as f64)),
        scale(n, pow2(-j)),
    );
    let p = surface_point(q, u, v, sixty_fourths(r, 8, 24), sixty_fourths(r, 8, 24));
    let o = sub(p, scale(d, r.pow2(0, 3)));
    raw(plane_shape(triangle, q, u, v), o, d, CAMERA, &["grazing"])
}

/// An inside hit at a dyadic `t` with an interval end at `t`, or `2^j` ulps beside it.
fn plane_interval_case(triangle: bool, r: &mut Stream, i: usize) -> Raw {
    let (q, u, v, d) = int_quad(r, 8);
    let p = surface_point(q, u, v, sixty_fourths(r, 8, 24), sixty_fourths(r, 8, 24));
    let t = r.pow2(0, 5);
    let o = sub(p, scale(d, t));
    let step = 1i64 << r.int(0, 40);
    let interval = match i % 5 {
        0 => [t, f64::MAX],
        1 => [1e-6, t],
        2 => [nudge(t, if r.coin() { step } else { -step }), f64::MAX],
        3 => [1e-6, nudge(t, if r.coin() { step } else { -step })],
        _ => [t, t],
    };
    raw(
        plane_shape(triangle, q, u, v),
        o,
        d,
        interval,
        &["interval-boundary"],
    )
}

/// Collinear or zero edges, and every fifth case a zero direction.
fn degenerate_plane_case(triangle: bool, r: &mut Stream, i: usize) -> Raw {
    let (q, u, _, d) = int_quad(r, 8);
    let v = match i % 3 {
        0 => scale(u, r.int(-3, 3) as f64),
        1 => [0.0; 3],
        _ => scale(u, 0.5),
    };
    let o = sub(q, scale(d, 2.0));
    let d = if i % 5 == 4 { [0.0; 3] } else { d };
    raw(
        plane_shape(triangle, q, u, v),
        o,
        d,
        CAMERA,
        &["degenerate"],
    )
}

/// The categories of a shape and their weights in a suite.
pub fn categories(kind: ShapeKind) -> &'static [(&'static str, u32)] {
    match kind {
        ShapeKind::Sphere => &[
            ("random", 14),
            ("far", 5),
            ("scale", 5),
            ("unnormalised", 4),
            ("tangent", 2),
            ("near-tangent", 6),
            ("inside", 3),
            ("behind", 3),
            ("interval-boundary", 4),
            ("negative-radius", 3),
            ("degenerate", 1),
            ("nonfinite", 2),
        ],
        ShapeKind::Quad => &[
            ("random", 14),
            ("skewed", 3),
            ("skinny", 3),
            ("edge", 4),
            ("corner", 3),
            ("parallel", 3),
            ("grazing", 2),
            ("interval-boundary", 3),
            ("behind", 2),
            ("scale", 4),
            ("unnormalised", 3),
            ("degenerate", 1),
            ("nonfinite", 2),
        ],
        ShapeKind::Triangle => &[
            ("random", 10),
            ("edge", 3),
            ("corner", 3),
            ("parallel", 1),
            ("grazing", 1),
            ("interval-boundary", 2),
            ("behind", 1),
            ("scale", 2),
            ("unnormalised", 1),
            ("degenerate", 1),
            ("nonfinite", 1),
        ],
    }
}

/// One raw case of `kind` and `category`, number `i` of its stream.
pub fn raw_case(kind: ShapeKind, category: &str, r: &mut Stream, i: usize) -> Raw {
    match kind {
        ShapeKind::Sphere => sphere_case(category, r, i),
        ShapeKind::Quad => plane_case(category, false, r, i),
        ShapeKind::Triangle => plane_case(category, true, r, i),
    }
}

/// How many cases each (shape, category) gets out of `count`: proportional to the weights,
/// largest remainders first, at least one each when `count` allows.
fn allocate(count: usize, shapes: &[ShapeKind]) -> Vec<(ShapeKind, &'static str, usize)> {
    let cells: Vec<(ShapeKind, &'static str, u32)> = shapes
        .iter()
        .flat_map(|&k| categories(k).iter().map(move |&(c, w)| (k, c, w)))
        .collect();
    let total: u64 = cells.iter().map(|c| c.2 as u64).sum();
    let mut out: Vec<(ShapeKind, &'static str, usize)> = cells
        .iter()
        .map(|&(k, c, w)| (k, c, (count as u64 * w as u64 / total) as usize))
        .collect();
    let mut left = count - out.iter().map(|c| c.2).sum::<usize>();
    let mut order: Vec<usize> = (0..cells.len()).collect();
    order.sort_by_key(|&i| std::cmp::Reverse((count as u64 * cells[i].2 as u64) % total));
    for i in order {
        if left == 0 {
            break;
        }
        out[i].2 += 1;
        left -= 1;
    }
    out
}

/// `count` classified cases of the given shapes for `seed`, ids like `quad-corner-0007`, under
/// the course profile in `f64`.
pub fn generate(seed: u64, count: usize, shapes: &[ShapeKind]) -> Vec<Case> {
    generate_with(seed, count, shapes, Judging::COURSE)
}

/// [`generate`] classified under `judging`: the same inputs and ids for every judging; the
/// classes, tags and tolerances are the judging's.
pub fn generate_with(seed: u64, count: usize, shapes: &[ShapeKind], judging: Judging) -> Vec<Case> {
    let mut cases = Vec::with_capacity(count);
    for (kind, category, n) in allocate(count, shapes) {
        let mut r = Stream::new(seed, &format!("{kind}-{category}"));
        for i in 0..n {
            let c = raw_case(kind, category, &mut r, i);
            let expect = classify_tagged_with(&c.shape, &c.ray, c.interval, &c.tags, judging);
            cases.push(Case {
                id: format!("{kind}-{category}-{i:04}"),
                shape: c.shape,
                ray: c.ray,
                interval: c.interval,
                expect,
            });
        }
    }
    cases
}
