//! The statistical checks on honest and mistaken Rust samplers: fixed seeds here (fast, and
//! deterministic), the measurement with many seeds in `power` (ignored; its figures are in
//! `docs/weekly-checks.md`).

use super::camera::JitterSetting;
use super::surfaces::{DielectricSetting, MetalSetting};
use super::*;
use crate::weekly::stats::DEFAULT_ALPHA;

/// Every check of the catalogue, in a setting like the one the weekly runs use.
pub(crate) fn every_check() -> Vec<(&'static str, SamplerCheck)> {
    let s = std::f64::consts::FRAC_1_SQRT_2;
    let n = DVec3::new(0.0, 0.6, 0.8);
    let p = DVec3::new(1.0, 2.0, 3.0);
    let a = DVec3::new(0.5, 0.25, 1.0);
    // Schlick at cos 0.2 into glass (ratio 1/1.5): r0 = 0.04, 0.04 + 0.96 * 0.8^5; fed the
    // sine (0.9798) instead: 0.04 + 0.96 * 0.0202^5.
    let sine = (1.0f64 - 0.04).sqrt();
    let dielectric = DielectricSetting {
        point: p,
        albedo: DVec3::ONE,
        reflected: DVec3::new(0.0, 0.2, 0.96f64.sqrt()),
        refracted: Some(DVec3::new(0.0, -0.9, 0.19f64.sqrt())),
        p_reflect: 0.04 + 0.96 * 0.8f64.powi(5),
        p_wrong_cosine: 0.04 + 0.96 * (1.0 - sine).powi(5),
    };
    vec![
        ("unit sphere", SamplerCheck::unit_sphere()),
        ("cosine hemisphere", SamplerCheck::cosine_hemisphere()),
        ("unit disk", SamplerCheck::unit_disk()),
        (
            "lambertian n + u",
            SamplerCheck::lambertian_n_plus_u(p, n, a),
        ),
        (
            "lambertian cosine",
            SamplerCheck::lambertian_cosine(p, n, a),
        ),
        (
            "metal",
            SamplerCheck::metal(MetalSetting {
                point: p,
                normal: DVec3::Y,
                albedo: a,
                mirror: DVec3::new(s, s, 0.0),
                raw_mirror: DVec3::new(2.0, 2.0, 0.0),
                roughness: 1.0,
                given_roughness: 3.0,
            }),
        ),
        ("dielectric", SamplerCheck::dielectric(dielectric)),
        (
            "jitter week 9",
            SamplerCheck::jitter(JitterSetting {
                stratum: (4, 1),
                step: 1.0 / 3.0,
                unfrozen_step: 1.0 / 5.0,
            }),
        ),
        (
            "jitter week 10",
            SamplerCheck::jitter(JitterSetting {
                stratum: (3, 7),
                step: 1.0 / 10f64.sqrt(),
                unfrozen_step: 0.1,
            }),
        ),
        (
            "lens",
            SamplerCheck::lens((2.0f64.to_radians()).tan() / (1.0f64.to_radians()).tan()),
        ),
        ("ray time", SamplerCheck::ray_time()),
    ]
}

/// Honest samples pass every check on 100 fixed seeds at the default rate, and at a
/// false-alarm rate of 5% the rejections of 400 seeds stay within the binomial's 1e-6 bounds
/// (6 to 42): the tests are calibrated, neither blind nor jumpy.
#[test]
fn honest_samplers_pass_and_the_tests_are_calibrated() {
    for (what, check) in every_check() {
        let (failed, _) =
            rejection_rate(&check, &check.course, check.samples, 100, 11, DEFAULT_ALPHA);
        assert_eq!(failed, 0, "{what}: an honest sampler failed");
        // Checks whose course hypothesis has cells (the statistics, not only invariants).
        let (failed, _) = rejection_rate(&check, &check.course, check.samples, 400, 12, 0.05);
        assert!((6..=42).contains(&failed), "{what}: {failed} of 400 at 5%");
    }
}

/// Every catalogued mistake fails its check and is named, on 20 fixed seeds.
#[test]
fn every_mistake_fails_and_is_named() {
    for (what, check) in every_check() {
        for m in &check.mistakes {
            let (failed, named) = rejection_rate(&check, m, check.samples, 20, 13, DEFAULT_ALPHA);
            assert_eq!(failed, 20, "{what}: {} passed", m.name);
            assert_eq!(named, 20, "{what}: {} not named", m.name);
        }
    }
}

/// A sample that breaks the course's invariant fails the check at once, and says why.
#[test]
fn an_invariant_breaks_on_one_sample() {
    let check = SamplerCheck::unit_disk();
    let mut r = PixelSampler::new(1, 1);
    let mut samples: Vec<Sample> = (0..100).map(|_| check.course.draw(&mut r)).collect();
    samples[37] = [0.9, 0.9, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    let v = check.judge(&samples, DEFAULT_ALPHA);
    assert!(!v.passed);
    let (at, why) = v.fit.first_failure.clone().expect("a failure");
    assert_eq!(at, 37);
    assert!(why.contains("outside the unit disk"), "{why}");
}

/// The measurement quoted in the docs: false alarms of each check over 100 000 honest runs,
/// and the power against each mistake (the fraction of runs failed, and named) over 2 000.
/// `cargo test --release --lib functions::samplers::tests::power -- --ignored --nocapture`
/// (`RTORACLE_POWER_RUNS=2000,200` for fewer runs).
#[test]
#[ignore]
fn power() {
    // RTORACLE_POWER_RUNS=HONEST,MISTAKE runs fewer (a quick look on a loaded machine).
    let (runs, mruns) = std::env::var("RTORACLE_POWER_RUNS")
        .ok()
        .and_then(|v| {
            let (a, b) = v.split_once(',')?;
            Some((a.parse().ok()?, b.parse().ok()?))
        })
        .unwrap_or((100_000u64, 2000u64));
    for (what, check) in every_check() {
        let (failed, _) = rejection_rate(
            &check,
            &check.course,
            check.samples,
            runs,
            99,
            DEFAULT_ALPHA,
        );
        println!(
            "{what} ({} samples): false alarms {failed} / {runs}",
            check.samples
        );
        for m in &check.mistakes {
            let (f, named) = rejection_rate(&check, m, check.samples, mruns, 98, DEFAULT_ALPHA);
            println!(
                "    {}: failed {f} / {mruns}, named {named} / {mruns}",
                m.name
            );
        }
    }
}
