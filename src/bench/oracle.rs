//! The oracle's benchmark (`rtoracle bench oracle`, `cargo bench --bench oracle`): the
//! reference against the exact oracle on random cases across scales and distances, the naive
//! course formula's wrong decisions near the silhouette of far spheres, the classification rate
//! and the suite's generation time, each beside a baseline measured in the same run.

use std::fmt::Write;
use std::time::Instant;

use crate::geometry::{Interval, Shape};
use crate::oracle::classify::{analyse, classify_with};
use crate::oracle::exact::{self, Decision};
use crate::oracle::generate::{CAMERA, Stream, random_plane, random_sphere};
use crate::oracle::mistakes::honest;
use crate::oracle::profile::{Judging, Precision, Profile};
use crate::oracle::suite::default_suite_with;
use crate::oracle::vectors::{Class, ShapeKind, ShapeSpec};

/// What to run.
#[derive(Clone, Copy, Debug)]
pub struct Options {
    /// Random sphere cases for the agreement figure (10^6 in the issue).
    pub sphere_cases: usize,
    /// Random quad and triangle cases (each).
    pub plane_cases: usize,
    /// Near-silhouette rays per distance.
    pub silhouette_cases: usize,
    /// Seed.
    pub seed: u64,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            sphere_cases: 1_000_000,
            plane_cases: 200_000,
            silhouette_cases: 100_000,
            seed: 1,
        }
    }
}

/// Reference-versus-exact figures over random cases.
#[derive(Clone, Copy, Debug, Default)]
pub struct Agreement {
    /// Cases run.
    pub cases: usize,
    /// Definite cases among them.
    pub definite: usize,
    /// Definite cases where the reference's decision differs from the exact one.
    pub wrong: usize,
    /// Largest `|t_ref - t_exact| / |t_exact|` over definite hits.
    pub max_rel_t: f64,
    /// Cases the interval filter decided without big integers.
    pub by_filter: usize,
    /// Definite cases where the course's naive formula decides differently from the exact one.
    pub naive_wrong: usize,
}

/// Runs the reference and the oracle on `n` random cases of `kind`.
pub fn agreement(kind: ShapeKind, n: usize, seed: u64) -> Agreement {
    let mut r = Stream::new(seed, &format!("bench-{kind}"));
    let naive = honest()
        .into_iter()
        .find(|v| v.shape == kind)
        .expect("an honest variant per shape");
    let mut a = Agreement::default();
    for _ in 0..n {
        let c = match kind {
            ShapeKind::Sphere => random_sphere(&mut r, 1e8, None),
            ShapeKind::Quad => random_plane(&mut r, false),
            ShapeKind::Triangle => random_plane(&mut r, true),
        };
        a.cases += 1;
        let an = analyse(&c.shape, &c.ray, c.interval);
        a.by_filter += usize::from(an.by_filter);
        if !an.class.is_definite() {
            continue;
        }
        a.definite += 1;
        let hit = c
            .shape
            .object()
            .intersect(&c.ray.ray(), Interval::new(c.interval[0], c.interval[1]));
        let exact_hit = an.class == Class::Hit;
        if hit.is_some() != exact_hit {
            a.wrong += 1;
        }
        if let (Some(h), Some(e)) = (hit, an.hit) {
            let rel = ((h.t - e.t) / e.t).abs();
            a.max_rel_t = a.max_rel_t.max(rel);
        }
        let n = (naive.run)(&c.shape, &c.ray, c.interval);
        if matches!(n, Ok(Some(_))) != exact_hit {
            a.naive_wrong += 1;
        }
    }
    a
}

/// Wrong-decision shares on near-silhouette rays at `ratio` radii: `(naive, reference)`, as
/// fractions of all the rays (the exact decision is the truth; no band is applied).
pub fn silhouette(ratio: f64, n: usize, seed: u64) -> (f64, f64, usize) {
    let mut r = Stream::new(seed, &format!("silhouette-{ratio}"));
    let naive = honest()[0];
    let (mut nw, mut rw) = (0usize, 0usize);
    for _ in 0..n {
        let c = silhouette_case(&mut r, ratio);
        let (decision, _) = exact::decide(&c.shape, &c.ray, CAMERA);
        let exact_hit = matches!(decision, Decision::SphereHit(_));
        let n_hit = matches!((naive.run)(&c.shape, &c.ray, CAMERA), Ok(Some(_)));
        let r_hit = c
            .shape
            .object()
            .intersect(&c.ray.ray(), Interval::CAMERA)
            .is_some();
        nw += usize::from(n_hit != exact_hit);
        rw += usize::from(r_hit != exact_hit);
    }
    (nw as f64 / n as f64, rw as f64 / n as f64, n)
}

/// A sphere at a log-uniform scale seen from exactly `ratio` radii, the ray aimed at a point
/// `0.9 .. 1.1` radii from the centre, perpendicular to the line of sight.
pub fn silhouette_case(r: &mut Stream, ratio: f64) -> crate::oracle::generate::Raw {
    use crate::oracle::generate::{add, cross, dot, raw_parts, scale, sub};
    let s = r.log_scale(-20.0, 20.0);
    let radius = s * r.uniform(0.5, 2.0);
    let center = scale(r.unit(), s * r.uniform(0.0, 8.0));
    let from = r.unit();
    let origin = add(center, scale(from, ratio * radius));
    let mut p = cross(from, r.unit());
    p = scale(p, 1.0 / dot(p, p).sqrt());
    let target = add(center, scale(p, radius * r.uniform(0.9, 1.1)));
    raw_parts(
        ShapeSpec::Sphere { center, radius },
        origin,
        sub(target, origin),
        CAMERA,
    )
}

/// CPU seconds used so far by the calling thread (`CLOCK_THREAD_CPUTIME_ID`): a rate per core
/// that other processes sharing the machine do not change.
fn cpu_seconds() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec; the call only writes it.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    if rc != 0 {
        // Wall time since the first call, when the thread clock is not available.
        static START: std::sync::OnceLock<Instant> = std::sync::OnceLock::new();
        return START.get_or_init(Instant::now).elapsed().as_secs_f64();
    }
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

/// Runs the benchmark and returns its report.
pub fn run(opts: Options) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "rtoracle bench oracle (seed {})", opts.seed);
    agreement_section(&mut s, opts);
    silhouette_section(&mut s, opts);
    speed_section(&mut s, opts.seed);
    s
}

/// Section 1: the reference against the exact oracle, per shape.
fn agreement_section(s: &mut String, opts: Options) {
    let _ = writeln!(
        s,
        "\n1. reference vs exact on random cases (scales 2^-20..2^20, spheres seen from up to 1e8 radii)"
    );
    let _ = writeln!(
        s,
        "   {:<9} {:>9} {:>9} {:>11} {:>13} {:>10} {:>13}",
        "shape", "cases", "definite", "ref wrong", "max rel t err", "filter", "naive wrong"
    );
    for (kind, n) in [
        (ShapeKind::Sphere, opts.sphere_cases),
        (ShapeKind::Quad, opts.plane_cases),
        (ShapeKind::Triangle, opts.plane_cases),
    ] {
        if n == 0 {
            continue;
        }
        let a = agreement(kind, n, opts.seed);
        let _ = writeln!(
            s,
            "   {:<9} {:>9} {:>9} {:>11} {:>13.2e} {:>9.2}% {:>13}",
            kind.name(),
            a.cases,
            a.definite,
            a.wrong,
            a.max_rel_t,
            100.0 * a.by_filter as f64 / a.cases as f64,
            a.naive_wrong
        );
    }
}

/// Section 2: wrong decisions of the naive formula and the reference near far silhouettes.
fn silhouette_section(s: &mut String, opts: Options) {
    let _ = writeln!(
        s,
        "\n2. wrong decisions on near-silhouette rays (aimed 0.9..1.1 radii from the centre), against the exact answer"
    );
    let _ = writeln!(
        s,
        "   {:<16} {:>8} {:>22} {:>22}",
        "distance/radius", "rays", "naive course formula", "reference (RTG ch. 7)"
    );
    for ratio in [1e7, 1e8] {
        let (nw, rw, n) = silhouette(ratio, opts.silhouette_cases, opts.seed);
        let _ = writeln!(
            s,
            "   {:<16e} {:>8} {:>21.2}% {:>21.2}%",
            ratio,
            n,
            100.0 * nw,
            100.0 * rw
        );
    }
}

/// Section 3: per judging, the classification rate against the naive course formula on the
/// same vectors, and the default suite's generation time.
fn speed_section(s: &mut String, seed: u64) {
    let _ = writeln!(
        s,
        "\n3. speed (one thread, in CPU seconds of this thread, so a loaded machine does not skew it), per judging"
    );
    let _ = writeln!(
        s,
        "   {:<11} {:>16} {:>18} {:>7} {:>14} {:>9}",
        "judging", "classify vec/s", "naive formula /s", "ratio", "suite gen (s)", "definite"
    );
    for judging in [
        Judging::COURSE,
        Judging::ROBUST,
        Judging::new(Profile::Course, Precision::F32),
        Judging::new(Profile::Robust, Precision::F32),
    ] {
        let row = speed(seed, judging);
        let _ = writeln!(
            s,
            "   {:<11} {:>16.0} {:>18.0} {:>6.1}x {:>14.3} {:>9}",
            judging.to_string(),
            row.classify_rate,
            row.naive_rate,
            row.naive_rate / row.classify_rate,
            row.generate_seconds,
            row.definite
        );
    }
    let _ = writeln!(
        s,
        "   (classify: vectors/s over the {} vectors of the default suite; ratio: how many times faster the naive course formula alone runs; suite gen: the default suite generated and classified)",
        crate::oracle::suite::DEFAULT_COUNT
    );
}

/// One row of the speed section.
struct SpeedRow {
    /// Vectors classified per CPU second.
    classify_rate: f64,
    /// Vectors the naive course formula runs per CPU second.
    naive_rate: f64,
    /// CPU seconds to generate and classify the default suite.
    generate_seconds: f64,
    /// Definite vectors in the suite.
    definite: usize,
}

/// Generates the default suite under `judging`, then times classifying it and running the naive
/// course formula on it (three passes each).
fn speed(seed: u64, judging: Judging) -> SpeedRow {
    let variants = honest();
    let t0 = cpu_seconds();
    let suite = default_suite_with(seed, judging);
    let generate_seconds = cpu_seconds() - t0;
    let passes = 3;
    let (mut n_hit, mut n_naive) = (0usize, 0usize);
    let t0 = cpu_seconds();
    for _ in 0..passes {
        for c in &suite {
            n_hit += usize::from(
                classify_with(&c.shape, &c.ray, c.interval, judging).class == Class::Hit,
            );
        }
    }
    let classify_s = cpu_seconds() - t0;
    let t0 = cpu_seconds();
    for _ in 0..passes {
        for c in &suite {
            let v = variants
                .iter()
                .find(|v| v.shape == c.shape.kind())
                .expect("variant");
            n_naive += usize::from(matches!((v.run)(&c.shape, &c.ray, c.interval), Ok(Some(_))));
        }
    }
    let naive_s = (cpu_seconds() - t0).max(1e-9);
    // The counts keep the timed loops from being optimised away.
    std::hint::black_box((n_hit, n_naive));
    SpeedRow {
        classify_rate: (passes * suite.len()) as f64 / classify_s,
        naive_rate: (passes * suite.len()) as f64 / naive_s,
        generate_seconds,
        definite: suite
            .iter()
            .filter(|c| c.expect.class.is_definite())
            .count(),
    }
}
