//! The material checks measured on rtoracle's own models, in process: the false-alarm rate on
//! the honest book materials over many seeds, and the power against each catalogued mistake.

use serde_json::json;

use super::laws::{Law, Status};
use super::materials::{MaterialCase, MaterialOptions, check_materials};
use super::models::{Family, Mistake, ModelSource};

fn book() -> Vec<MaterialCase> {
    vec![
        MaterialCase::new(
            "lambertian",
            json!({"type": "lambertian", "albedo": [0.8, 0.6, 0.4]}),
        ),
        MaterialCase::new(
            "metal",
            json!({"type": "metal", "albedo": [0.9, 0.8, 0.7], "roughness": 0.3}),
        ),
        MaterialCase::new(
            "dielectric",
            json!({"type": "dielectric", "albedo": [1.0, 1.0, 1.0], "ior": 1.5}),
        ),
    ]
}

fn options(seed: u64) -> MaterialOptions {
    MaterialOptions {
        seed,
        ..MaterialOptions::default()
    }
}

/// The honest book materials pass every law but one over 30 seeds (the run's false-alarm rate
/// is 1e-4, so a failure here would be a bug, not bad luck: the chance that any of the 30 runs
/// fails by chance is under 0.3%; the seeds are fixed, so the test is deterministic). The one:
/// the book's fuzzy metal is not reciprocal (its weight is the albedo, so
/// `f = albedo pdf / cos theta_i`), which is the model's own.
#[test]
fn honest_book_materials_pass_over_many_seeds() {
    for seed in 0..30 {
        let mut source = ModelSource::new(Family::Book);
        let report = check_materials(&mut source, None, &book(), options(seed));
        for m in &report.materials {
            for l in m.laws() {
                let expected_failure = m.name == "metal" && l.law == Law::Reciprocity;
                assert_eq!(
                    l.status == Status::Failed,
                    expected_failure,
                    "seed {seed}, {}: {:?} {} {:?}",
                    m.name,
                    l.law,
                    l.detail,
                    l.p_value
                );
            }
        }
    }
}

/// The fuzzy metal's broken reciprocity is a finding about the model when the reference is
/// the book's own models: the run passes.
#[test]
fn the_book_metal_is_a_finding_about_the_model() {
    let mut source = ModelSource::new(Family::Book);
    let mut reference = ModelSource::new(Family::Book);
    let report = check_materials(&mut source, Some(&mut reference), &book(), options(3));
    assert!(report.passed(), "{}", report.to_text());
    let metal = &report.materials[1];
    assert_eq!(metal.reciprocity.status, Status::Finding);
}

/// Each catalogued mistake fails the law that must catch it, in every one of 10 seeds
/// (deterministic laws catch theirs at every seed; the chi-square's power against uniform
/// sampling reported with the cosine pdf is 10 of 10 at 10 000 samples), and no other mistake
/// is blamed on the honest materials of the same run.
#[test]
fn every_catalogued_mistake_is_caught() {
    for mistake in Mistake::ALL {
        let case: Vec<MaterialCase> = book()
            .into_iter()
            .filter(|c| c.material["type"] == mistake.material_type())
            .collect();
        for seed in 0..10 {
            let mut source = ModelSource::with_mistake(mistake);
            let report = check_materials(&mut source, None, &case, options(seed));
            let m = &report.materials[0];
            let caught = m
                .laws()
                .any(|l| mistake.caught_by().contains(&l.law.name()) && l.status == Status::Failed);
            assert!(
                caught,
                "{} seed {seed}:\n{}",
                mistake.name(),
                report.to_text()
            );
        }
    }
}

/// The course's own materials break laws the course's code breaks: its Lambertian's BRDF is
/// the albedo (energy `pi albedo`), its weight is `BRDF cos` (biased), its Phong with
/// `kd + ks > 1` gains energy; all findings against the course's models.
#[test]
fn the_course_models_breaches_are_findings() {
    let cases = vec![
        MaterialCase::new(
            "lambertian",
            json!({"type": "lambertian", "albedo": [0.8, 0.6, 0.4]}),
        ),
        MaterialCase::new(
            "phong",
            json!({"type": "phong", "albedo": [0.7, 0.2, 0.4], "kd": 0.6, "ks": 0.9, "alpha": 0.8}),
        ),
    ];
    let family = Family::Course { cosine: true };
    let mut source = ModelSource::new(family);
    let plain = check_materials(&mut source, None, &cases, options(1));
    for m in &plain.materials {
        assert!(
            m.laws()
                .any(|l| l.law == Law::Energy && l.status == Status::Failed),
            "{}",
            plain.to_text()
        );
        assert!(
            m.laws()
                .any(|l| l.law == Law::Unbiased && l.status == Status::Failed)
        );
    }
    let mut reference = ModelSource::new(family);
    let judged = check_materials(&mut source, Some(&mut reference), &cases, options(1));
    assert!(judged.passed(), "{}", judged.to_text());
}
