//! The judging rules of [`super`] on a Rust stand-in for a candidate: nothing an answer says
//! about itself is believed, a function with no case right earns nothing, samplers answer
//! exactly what was asked, steered cases answered otherwise wait for their statistical check.

use std::collections::HashMap;
use std::time::Duration;

use serde_json::{Value, json};

use super::*;
use crate::weekly::checks::week_checks;

/// Answers every request with `answer(request)`.
struct StandIn<F: FnMut(&Value) -> Reply> {
    answer: F,
}

impl<F: FnMut(&Value) -> Reply> FunctionRunner for StandIn<F> {
    fn supports(&self, _: &str) -> bool {
        true
    }

    fn call(&mut self, request: &Value, _: Duration) -> Reply {
        (self.answer)(request)
    }
}

fn check(week: u8, id: &str) -> FunctionCheck {
    week_checks(Week::new(week).unwrap(), 7)
        .into_iter()
        .find(|c| c.id == id)
        .unwrap()
}

fn run(c: &FunctionCheck, answer: impl FnMut(&Value) -> Reply) -> FunctionResult {
    let mut memo = HashMap::new();
    run_check(
        &mut StandIn { answer },
        c,
        FunctionOptions::default(),
        &mut memo,
    )
}

/// The course's answer to each case of a `Cases` or `Steered` check, keyed by request.
fn course_answers(c: &FunctionCheck) -> HashMap<String, Value> {
    let cases = match &c.body {
        Body::Cases { cases, .. } | Body::Steered { cases, .. } => cases,
        Body::Samples { .. } => panic!("a statistical check"),
    };
    cases
        .iter()
        .map(|case| {
            let mut answer = serde_json::Map::new();
            for (key, want) in &case.expect.fields {
                let v = match want {
                    super::super::expect::Want::Vector { value, .. } => json!(value),
                    super::super::expect::Want::Pair { value, .. } => json!(value),
                    super::super::expect::Want::Number { value, .. } => json!(value),
                    super::super::expect::Want::Bool(b) => json!(b),
                };
                answer.insert(key.clone(), v);
            }
            (case.request.to_string(), Value::Object(answer))
        })
        .collect()
}

#[test]
fn a_marker_key_is_a_protocol_error_never_a_skip() {
    let c = check(5, "lambertian");
    let right = course_answers(&c);
    // The course's answers pass, every case scored.
    let r = run(&c, |req| Reply::Result(right[&req.to_string()].clone()));
    assert_eq!(r.status, Status::Passed, "{r:?}");
    assert_eq!(
        (r.counts.failed, r.counts.not_scored, r.counts.protocol),
        (0, 0, 0)
    );
    // The same answers with "unsteered" beside them: every case a protocol error.
    let r = run(&c, |req| {
        let mut v = right[&req.to_string()].clone();
        v["unsteered"] = json!(true);
        Reply::Result(v)
    });
    assert_eq!(r.status, Status::Failed);
    assert_eq!(r.counts.passed, 0);
    assert_eq!(r.counts.protocol, r.counts.failed);
    assert!(r.counts.protocol > 0);
    let problem = &r.failure.as_ref().unwrap().problem;
    assert!(
        problem.contains("protocol error") && problem.contains("unsteered"),
        "{problem}"
    );
    // An answer alone as a marker, and an empty one: the same.
    for marker in [json!({"unsteered": true}), json!({})] {
        let r = run(&c, |_| Reply::Result(marker.clone()));
        assert_eq!((r.status, r.counts.passed), (Status::Failed, 0), "{marker}");
        assert!(r.counts.protocol > 0, "{marker}");
    }
}

#[test]
fn a_function_with_no_case_right_earns_nothing_and_says_why() {
    // Every case of a deterministic check made ambiguous: nothing scored, so not passed.
    let mut c = check(6, "reflect");
    if let Body::Cases { cases, .. } = &mut c.body {
        for case in cases.iter_mut() {
            case.class = Class::Ambiguous("made so".into());
        }
    }
    let r = run(&c, |_| Reply::Result(json!({"vector": [0.0, 0.0, 0.0]})));
    assert_eq!(r.status, Status::Failed, "{r:?}");
    assert!(
        r.notes
            .iter()
            .any(|n| n.contains("could be scored, so it earns nothing")),
        "{:?}",
        r.notes
    );
}

#[test]
fn a_sampler_answers_exactly_the_samples_asked_for() {
    let c = check(5, "unit-sphere");
    // Unit vectors, but one fewer than asked for: a protocol error, failed.
    let r = run(&c, |req| {
        let n = req["n"].as_u64().unwrap() as usize;
        Reply::Result(json!({"samples": vec![[0.0, 0.0, 1.0]; n - 1]}))
    });
    assert_eq!((r.status, r.counts.protocol), (Status::Failed, 1), "{r:?}");
    assert!(r.failure.unwrap().problem.contains("where"));
    // No samples at all: the same (it used to pass, with no test to fail).
    let r = run(&c, |_| Reply::Result(json!({"samples": []})));
    assert_eq!((r.status, r.counts.protocol), (Status::Failed, 1));
    // A sample of the wrong arity.
    let r = run(&c, |req| {
        let n = req["n"].as_u64().unwrap() as usize;
        Reply::Result(json!({"samples": vec![[0.0, 1.0]; n]}))
    });
    assert_eq!((r.status, r.counts.protocol), (Status::Failed, 1));
    // Honest samples pass (seeded: the check's false-alarm rate does not apply to a fixed
    // stream).
    let mut rng = crate::render::PixelSampler::new(3, 4);
    let r = run(&c, |req| {
        let n = req["n"].as_u64().unwrap() as usize;
        let samples: Vec<[f64; 3]> = (0..n)
            .map(|_| crate::weekly::samplers::mistakes::unit_vector(&mut rng).to_array())
            .collect();
        Reply::Result(json!({"samples": samples}))
    });
    assert_eq!(r.status, Status::Passed, "{r:?}");
}

/// A Lambertian answering `n + u` for its own unit `u` (not the steered one) on every case.
fn drawn_otherwise(c: &FunctionCheck) -> impl FnMut(&Value) -> Reply {
    let mut rng = crate::render::PixelSampler::new(5, 6);
    let _ = c;
    move |req: &Value| {
        let n = glam::DVec3::from_slice(
            &req["hit"]["normal"]
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap())
                .collect::<Vec<_>>(),
        );
        let d = glam::DVec3::from_slice(
            &req["ray"]["direction"]
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap())
                .collect::<Vec<_>>(),
        );
        let n = if d.dot(n) < 0.0 { n } else { -n };
        let dir = n + crate::weekly::samplers::mistakes::unit_vector(&mut rng);
        Reply::Result(json!({
            "scattered": true, "origin": req["hit"]["point"], "direction": dir.to_array(),
            "time": 0.0, "attenuation": req["material"]["albedo"],
        }))
    }
}

#[test]
fn steered_cases_drawn_otherwise_count_only_with_their_statistical_check() {
    let c = check(5, "lambertian");
    let partner = |status: Status| FunctionResult {
        id: "lambertian-lobe".into(),
        status,
        ..run(&check(5, "background"), |_| Reply::NotRun("unused".into()))
    };
    for (lobe, want) in [
        (Status::Passed, Status::Passed),
        (Status::Failed, Status::Failed),
    ] {
        let mut results = vec![run(&c, drawn_otherwise(&c)), partner(lobe)];
        let cases = results[0].counts.failed;
        assert!(
            cases > 0 && results[0].by_behaviour == cases,
            "{:?}",
            results[0]
        );
        settle_steered(&mut results);
        let r = &results[0];
        assert_eq!(r.status, want, "{r:?}");
        assert_eq!(r.counts.protocol, 0);
        assert!(
            r.notes
                .iter()
                .any(|n| n.contains("judged by what the code does"))
        );
    }
    // A constant answer (the first case's, replayed): it breaks the invariant elsewhere (its
    // origin is not the hit point), so it is wrong whatever the statistical check says.
    let right = course_answers(&c);
    let first = right.values().next().unwrap().clone();
    let mut results = vec![
        run(&c, |_| Reply::Result(first.clone())),
        partner(Status::Passed),
    ];
    settle_steered(&mut results);
    assert_eq!(results[0].status, Status::Failed, "{:?}", results[0]);
}
