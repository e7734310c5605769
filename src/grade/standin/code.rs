//! The stand-in code checker (see the [module docs](super)).

use std::collections::BTreeMap;
use std::io::{BufRead, BufReader, Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, Stdio};
use std::sync::mpsc::{Receiver, RecvTimeoutError, channel};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use serde_json::{Value, json};

use crate::grade::inputs::{CodeChecker, CodeOutcome, FailureKind, FailureSummary, GroupCounts};
use crate::grade::rubric::sha256_hex;
use crate::grade::sandbox::{Sandbox, SandboxPolicy, kill_group};
use crate::oracle::default_suite;
use crate::oracle::vectors::{Case, Class, ShapeKind, ShapeSpec};

const DRIVER: &str = include_str!("driver.py");
const DRIVER_NAME: &str = "_rtoracle_driver.py";
const STDERR_TAIL: usize = 2000;

/// Runs the placeholder suite through the embedded Python driver, one sandboxed interpreter per
/// submission (restarted after a crash or a timeout).
#[derive(Clone, Debug)]
pub struct StandinCodeChecker {
    /// Seed of the suite.
    pub seed: u64,
    /// Wall-clock limit per vector.
    pub case_timeout: Duration,
    /// Wall-clock limit for importing the submission.
    pub import_timeout: Duration,
    /// After this many timeouts in a group, the rest of the group is not run.
    pub max_timeouts_per_group: usize,
    /// The sandbox's limits.
    pub policy: SandboxPolicy,
    /// The interpreter (default: `RTORACLE_PYTHON`, else `/usr/bin/python3`, else `python3`).
    pub python: Option<PathBuf>,
}

impl Default for StandinCodeChecker {
    fn default() -> Self {
        StandinCodeChecker {
            seed: 0,
            case_timeout: Duration::from_secs(2),
            import_timeout: Duration::from_secs(5),
            max_timeouts_per_group: 2,
            policy: SandboxPolicy::default(),
            python: None,
        }
    }
}

/// The interpreter to use.
fn find_python(explicit: Option<&Path>) -> PathBuf {
    if let Some(p) = explicit {
        return p.to_path_buf();
    }
    if let Some(p) = std::env::var_os("RTORACLE_PYTHON") {
        return PathBuf::from(p);
    }
    for p in ["/usr/bin/python3", "/usr/local/bin/python3"] {
        if Path::new(p).is_file() {
            return PathBuf::from(p);
        }
    }
    // Resolve `python3` on PATH to the real interpreter (shims need an environment we clear).
    std::process::Command::new("python3")
        .args(["-c", "import sys; print(sys.executable)"])
        .output()
        .ok()
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .map(|s| PathBuf::from(s.trim()))
        .filter(|p| p.is_file())
        .unwrap_or_else(|| PathBuf::from("python3"))
}

/// One running interpreter.
struct Session {
    child: Child,
    stdin: ChildStdin,
    lines: Receiver<String>,
}

enum Reply {
    Line(String),
    Timeout,
    Died,
}

impl Session {
    fn start(
        sandbox: &Sandbox,
        python: &Path,
        stderr: &Arc<Mutex<String>>,
    ) -> std::io::Result<Self> {
        let mut child = sandbox
            .command(python)
            .args(["-I", "-S", DRIVER_NAME])
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()?;
        let stdin = child.stdin.take().expect("piped");
        let stdout = child.stdout.take().expect("piped");
        let mut err = child.stderr.take().expect("piped");
        let (tx, lines) = channel();
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines() {
                match line {
                    Ok(l) => {
                        if tx.send(l).is_err() {
                            break;
                        }
                    }
                    Err(_) => break,
                }
            }
        });
        let tail = Arc::clone(stderr);
        std::thread::spawn(move || {
            let mut buf = [0u8; 4096];
            while let Ok(n) = err.read(&mut buf) {
                if n == 0 {
                    break;
                }
                let mut t = tail.lock().unwrap_or_else(|e| e.into_inner());
                t.push_str(&String::from_utf8_lossy(&buf[..n]));
                if t.len() > 4 * STDERR_TAIL {
                    let cut = t.len() - STDERR_TAIL;
                    let cut = (cut..t.len()).find(|&i| t.is_char_boundary(i)).unwrap_or(0);
                    t.drain(..cut);
                }
            }
        });
        Ok(Session {
            child,
            stdin,
            lines,
        })
    }

    fn read(&self, timeout: Duration) -> Reply {
        match self.lines.recv_timeout(timeout) {
            Ok(l) => Reply::Line(l),
            Err(RecvTimeoutError::Timeout) => Reply::Timeout,
            Err(RecvTimeoutError::Disconnected) => Reply::Died,
        }
    }

    fn ask(&mut self, case: &Case, timeout: Duration) -> Reply {
        let request = json!({
            "id": case.id,
            "shape": case.shape,
            "ray": case.ray,
            "interval": [
                crate::oracle::vectors::num::to_value(case.interval[0]),
                crate::oracle::vectors::num::to_value(case.interval[1])
            ],
        });
        if writeln!(self.stdin, "{request}")
            .and_then(|_| self.stdin.flush())
            .is_err()
        {
            return Reply::Died;
        }
        self.read(timeout)
    }

    fn stop(mut self) {
        kill_group(&mut self.child);
    }
}

fn tail_of(s: &str) -> String {
    let start = s.len().saturating_sub(STDERR_TAIL);
    let start = (start..=s.len())
        .find(|&i| s.is_char_boundary(i))
        .unwrap_or(0);
    s[start..].to_string()
}

/// Formats a number for Python source.
fn py(x: f64) -> String {
    if x.is_nan() {
        "float('nan')".into()
    } else if x.is_infinite() {
        if x > 0.0 {
            "float('inf')"
        } else {
            "float('-inf')"
        }
        .into()
    } else {
        format!("{x:?}")
    }
}

fn py3(v: [f64; 3]) -> String {
    format!("rtu.Vec3({}, {}, {})", py(v[0]), py(v[1]), py(v[2]))
}

/// A ready-to-run Python script reproducing `case` with the course's API, to be run from the
/// submission folder.
pub fn python_repro(case: &Case) -> String {
    let shape = match case.shape {
        ShapeSpec::Sphere { center, radius } => {
            format!("rto.Sphere({}, {})", py3(center), py(radius))
        }
        ShapeSpec::Quad { q, u, v } => format!("rto.Quad({}, {}, {})", py3(q), py3(u), py3(v)),
        ShapeSpec::Triangle { a, b, c } => {
            format!("rto.Triangle({}, {}, {})", py3(a), py3(b), py3(c))
        }
    };
    let e = &case.expect;
    let expected = match (e.class, e.t) {
        (Class::Hit, Some(t)) => {
            let mut s = format!("a hit at t = {}", py(t));
            if let Some(n) = e.normal {
                s.push_str(&format!(
                    ", normal ({}, {}, {})",
                    py(n[0]),
                    py(n[1]),
                    py(n[2])
                ));
            }
            if let Some(f) = e.front_face {
                s.push_str(&format!(
                    ", front_face {}",
                    if f { "True" } else { "False" }
                ));
            }
            s
        }
        (Class::Miss, _) => "no hit (None)".into(),
        (Class::Ambiguous, _) => "ambiguous: either answer is accepted".into(),
        _ => "any answer (degenerate input)".into(),
    };
    format!(
        "# {id}: save as repro.py in your submission folder and run `python3 repro.py`\n\
         import RT_utility as rtu, RT_ray as rtr, RT_object as rto\n\
         shape = {shape}\n\
         ray = rtr.Ray({o}, {d})\n\
         hit = shape.intersect(ray, rtu.Interval({t0}, {t1}))\n\
         print(None if hit is None else (hit.getT(), hit.getP().e, hit.getNormal().e, hit.front_face))\n\
         # expected: {expected}\n",
        id = case.id,
        o = py3(case.ray.origin),
        d = py3(case.ray.direction),
        t0 = py(case.interval[0]),
        t1 = py(case.interval[1]),
    )
}

fn as_f64(v: &Value) -> Option<f64> {
    match v {
        Value::Number(n) => n.as_f64(),
        Value::String(s) => match s.as_str() {
            "inf" => Some(f64::INFINITY),
            "-inf" => Some(f64::NEG_INFINITY),
            "nan" => Some(f64::NAN),
            _ => None,
        },
        _ => None,
    }
}

fn as_vec3(v: &Value) -> Option<[f64; 3]> {
    let a = v.as_array()?;
    if a.len() != 3 {
        return None;
    }
    Some([as_f64(&a[0])?, as_f64(&a[1])?, as_f64(&a[2])?])
}

/// `|a - b| <= tol`, false when either is NaN.
fn within(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol
}

/// Judges one answer: `Ok(())` when it is right (or anything goes), `Err((kind, message))` when
/// it is wrong.
fn judge(case: &Case, answer: &Value) -> Result<(), (FailureKind, String)> {
    if let Some(err) = answer.get("error") {
        let ty = err
            .get("type")
            .and_then(Value::as_str)
            .unwrap_or("Exception");
        let msg = err.get("message").and_then(Value::as_str).unwrap_or("");
        return Err((FailureKind::Error, format!("raised {ty}: {msg}")));
    }
    let Some(hit) = answer.get("hit").and_then(Value::as_bool) else {
        return Err((FailureKind::Protocol, "the answer has no hit/miss".into()));
    };
    let e = &case.expect;
    let expect_hit = match e.class {
        Class::Hit => true,
        Class::Miss => false,
        Class::Ambiguous => e.t.is_some(),
        Class::Any => return Ok(()),
    };
    if hit != expect_hit {
        return Err((
            FailureKind::Mismatch,
            if expect_hit {
                format!(
                    "returned None, expected a hit at t = {}",
                    e.t.map_or("?".into(), py)
                )
            } else {
                "returned a hit, expected None (a miss)".into()
            },
        ));
    }
    if !hit {
        return Ok(());
    }
    let (Some(t), Some(normal)) = (
        answer.get("t").and_then(as_f64),
        answer.get("normal").and_then(as_vec3),
    ) else {
        return Err((
            FailureKind::Protocol,
            "the hit has no numeric t or normal".into(),
        ));
    };
    if let Some(te) = e.t {
        let tol = e.t_tol.unwrap_or(1e-9 * te.abs().max(1.0));
        if !within(t, te, tol) {
            return Err((
                FailureKind::Mismatch,
                format!("t = {}, expected {} (tolerance {})", py(t), py(te), py(tol)),
            ));
        }
    }
    if let Some(ne) = e.normal {
        if (0..3).any(|k| !within(normal[k], ne[k], 1e-6)) {
            return Err((
                FailureKind::Mismatch,
                format!(
                    "normal ({}, {}, {}), expected ({}, {}, {})",
                    py(normal[0]),
                    py(normal[1]),
                    py(normal[2]),
                    py(ne[0]),
                    py(ne[1]),
                    py(ne[2])
                ),
            ));
        }
    }
    if let Some(fe) = e.front_face {
        let f = answer.get("front_face").and_then(Value::as_bool);
        if f != Some(fe) {
            return Err((
                FailureKind::Mismatch,
                format!("front_face {f:?}, expected {fe}"),
            ));
        }
    }
    Ok(())
}

impl StandinCodeChecker {
    fn suite(&self) -> Vec<Case> {
        default_suite(self.seed)
    }
}

impl CodeChecker for StandinCodeChecker {
    fn describe(&self) -> String {
        format!(
            "stand-in Python driver, placeholder default suite (seed {}), {} ms per vector",
            self.seed,
            self.case_timeout.as_millis()
        )
    }

    fn vectors_sha256(&self) -> String {
        let text: String = self
            .suite()
            .iter()
            .map(|c| c.to_json_line() + "\n")
            .collect();
        sha256_hex(text.as_bytes())
    }

    fn check(&self, submission: &Path, groups: &[ShapeKind]) -> CodeOutcome {
        let cases: Vec<Case> = self
            .suite()
            .into_iter()
            .filter(|c| groups.contains(&c.shape.kind()))
            .collect();
        let mut out = CodeOutcome {
            per_group: groups
                .iter()
                .map(|&g| (g, GroupCounts::default()))
                .collect(),
            ..Default::default()
        };
        for c in &cases {
            let counts = out.per_group.get_mut(&c.shape.kind()).expect("asked for");
            if c.expect.class.is_definite() {
                counts.definite_total += 1;
            }
        }
        let fatal = |out: &mut CodeOutcome, msg: String| {
            for counts in out.per_group.values_mut() {
                counts.not_run = counts.definite_total;
            }
            out.fatal = Some(msg);
        };

        // The submission's Python files, without following links out of the folder.
        let mut files = Vec::new();
        if let Ok(entries) = std::fs::read_dir(submission) {
            for entry in entries.flatten() {
                let name = entry.file_name().to_string_lossy().to_string();
                let is_file = entry.file_type().map(|t| t.is_file()).unwrap_or(false);
                if is_file && name.ends_with(".py") && name != DRIVER_NAME {
                    files.push((entry.path(), name));
                }
            }
        }
        if !files.iter().any(|(_, n)| n == "RT_object.py") {
            fatal(&mut out, "RT_object.py is not in the submission".into());
            return out;
        }
        let mut sandbox = match Sandbox::new(self.policy.clone(), &files) {
            Ok(s) => s,
            Err(e) => {
                fatal(&mut out, format!("cannot prepare the sandbox: {e}"));
                return out;
            }
        };
        if let Err(e) = sandbox.add_file(DRIVER_NAME, DRIVER.as_bytes()) {
            fatal(&mut out, format!("cannot prepare the sandbox: {e}"));
            return out;
        }
        let python = find_python(self.python.as_deref());
        if !sandbox.probe(&python, &["-I", "-S", "-c", "pass"]) {
            fatal(
                &mut out,
                format!("cannot run the Python interpreter {}", python.display()),
            );
            out.sandbox = serde_json::to_value(sandbox.facts(None)).unwrap_or_default();
            return out;
        }

        let stderr = Arc::new(Mutex::new(String::new()));
        let mut session: Option<Session> = None;
        let mut timeouts: BTreeMap<ShapeKind, usize> = BTreeMap::new();
        let mut definite_failures = Vec::new();
        let mut other_failures = Vec::new();
        let mut facts = None;
        for case in &cases {
            let kind = case.shape.kind();
            let definite = case.expect.class.is_definite();
            let ambiguous = case.expect.class == Class::Ambiguous;
            let summary = |k: FailureKind, message: String, actual: Value| FailureSummary {
                id: case.id.clone(),
                shape: kind,
                tags: case.expect.tags.clone(),
                kind: k,
                definite,
                expected: serde_json::to_value(&case.expect).unwrap_or_default(),
                actual,
                message,
                repro: python_repro(case),
            };
            let timed_out = timeouts.get(&kind).copied().unwrap_or(0);
            if timed_out >= self.max_timeouts_per_group {
                if definite {
                    out.per_group.get_mut(&kind).expect("asked for").not_run += 1;
                    definite_failures.push(summary(
                        FailureKind::NotRun,
                        format!("not run: {timed_out} earlier vectors of this group timed out"),
                        Value::Null,
                    ));
                }
                continue;
            }
            if session.is_none() {
                let started = match Session::start(&sandbox, &python, &stderr) {
                    Ok(s) => s,
                    Err(e) => {
                        fatal(&mut out, format!("cannot start {}: {e}", python.display()));
                        break;
                    }
                };
                if facts.is_none() {
                    facts = Some(sandbox.facts(Some(&started.child)));
                }
                let first = started.read(self.import_timeout);
                let problem = match &first {
                    Reply::Line(l) => match serde_json::from_str::<Value>(l) {
                        Ok(v) if v.get("ready").is_some() => None,
                        Ok(v) if v.get("fatal").is_some() => Some(format!(
                            "importing the submission failed:\n{}",
                            v["fatal"].as_str().unwrap_or("")
                        )),
                        _ => Some(format!("the driver answered {l:?} instead of ready")),
                    },
                    Reply::Timeout => Some(format!(
                        "importing the submission did not finish within {} s",
                        self.import_timeout.as_secs_f64()
                    )),
                    Reply::Died => Some("Python died while importing the submission".into()),
                };
                if let Some(msg) = problem {
                    started.stop();
                    // Counts of what ran before stay; the rest is not run.
                    for counts in out.per_group.values_mut() {
                        counts.not_run = counts.definite_total
                            - counts.passed
                            - counts.failed
                            - counts.errors
                            - counts.timeouts;
                    }
                    out.fatal = Some(msg);
                    break;
                }
                session = Some(started);
            }
            let s = session.as_mut().expect("started above");
            let reply = s.ask(case, self.case_timeout);
            let counts = out.per_group.get_mut(&kind).expect("asked for");
            let verdict: Result<(), (FailureKind, String, Value)> = match reply {
                Reply::Line(l) => match serde_json::from_str::<Value>(&l) {
                    Ok(v) if v.get("id").and_then(Value::as_str) == Some(case.id.as_str()) => {
                        let mut actual = v.clone();
                        if let Some(o) = actual.as_object_mut() {
                            o.remove("id");
                        }
                        judge(case, &v).map_err(|(k, m)| (k, m, actual))
                    }
                    _ => Err((
                        FailureKind::Protocol,
                        "unreadable answer from the driver".into(),
                        Value::String(l),
                    )),
                },
                Reply::Timeout | Reply::Died => {
                    let died = matches!(reply, Reply::Died);
                    session.take().expect("running").stop();
                    *timeouts.entry(kind).or_default() += 1;
                    Err((
                        FailureKind::Timeout,
                        if died {
                            "the Python process died on this vector (crash or resource limit)"
                                .into()
                        } else {
                            format!(
                                "no answer within {} s (infinite loop?)",
                                self.case_timeout.as_secs_f64()
                            )
                        },
                        Value::Null,
                    ))
                }
            };
            if ambiguous {
                counts.ambiguous += 1;
                if verdict.is_ok() {
                    counts.ambiguous_passed += 1;
                }
            }
            match verdict {
                Ok(()) => {
                    if definite {
                        counts.passed += 1;
                    }
                }
                Err((k, message, actual)) => {
                    if definite {
                        match k {
                            FailureKind::Error => counts.errors += 1,
                            FailureKind::Timeout => counts.timeouts += 1,
                            _ => counts.failed += 1,
                        }
                        definite_failures.push(summary(k, message, actual));
                    } else if ambiguous {
                        other_failures.push(summary(k, message, actual));
                    }
                }
            }
        }
        if let Some(s) = session {
            s.stop();
        }
        definite_failures.sort_by_key(|f| f.shape);
        other_failures.sort_by_key(|f| f.shape);
        out.failures = definite_failures;
        out.failures.extend(other_failures);
        out.stderr_tail = tail_of(&stderr.lock().unwrap_or_else(|e| e.into_inner()));
        out.sandbox =
            serde_json::to_value(facts.unwrap_or_else(|| sandbox.facts(None))).unwrap_or_default();
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::oracle::vectors::Expect;

    fn case(class: Class, t: Option<f64>) -> Case {
        let mut c = default_suite(0).remove(0);
        c.expect = Expect {
            class,
            tags: vec![],
            t,
            t_tol: t.map(|_| 1e-9),
            point: None,
            normal: t.map(|_| [0.0, 0.0, 1.0]),
            front_face: t.map(|_| true),
        };
        c
    }

    #[test]
    fn answers_are_judged_on_hit_t_normal_and_front_face() {
        let hit = case(Class::Hit, Some(4.0));
        let good = json!({"hit": true, "t": 4.0, "normal": [0.0, 0.0, 1.0], "front_face": true});
        assert!(judge(&hit, &good).is_ok());
        let within =
            json!({"hit": true, "t": 4.0 + 5e-10, "normal": [0.0, 0.0, 1.0], "front_face": true});
        assert!(judge(&hit, &within).is_ok());
        for (bad, kind) in [
            (json!({"hit": false}), FailureKind::Mismatch),
            (
                json!({"hit": true, "t": 4.0 + 2e-9, "normal": [0.0, 0.0, 1.0], "front_face": true}),
                FailureKind::Mismatch,
            ),
            (
                json!({"hit": true, "t": 4.0, "normal": [0.0, 0.0, -1.0], "front_face": true}),
                FailureKind::Mismatch,
            ),
            (
                json!({"hit": true, "t": 4.0, "normal": [0.0, 0.0, 1.0], "front_face": false}),
                FailureKind::Mismatch,
            ),
            (
                json!({"hit": true, "t": "nan", "normal": [0.0, 0.0, 1.0], "front_face": true}),
                FailureKind::Mismatch,
            ),
            (
                json!({"hit": true, "t": "x", "normal": [0.0, 0.0, 1.0]}),
                FailureKind::Protocol,
            ),
            (
                json!({"error": {"type": "ZeroDivisionError", "message": "float division by zero"}}),
                FailureKind::Error,
            ),
        ] {
            assert_eq!(judge(&hit, &bad).unwrap_err().0, kind, "{bad}");
        }
        let miss = case(Class::Miss, None);
        assert!(judge(&miss, &json!({"hit": false})).is_ok());
        assert_eq!(judge(&miss, &good).unwrap_err().0, FailureKind::Mismatch);
        let any = case(Class::Any, None);
        assert!(judge(&any, &good).is_ok() && judge(&any, &json!({"hit": false})).is_ok());
    }

    #[test]
    fn the_repro_is_python_with_exact_numbers() {
        let mut c = default_suite(0).remove(0);
        c.ray.origin = [0.1, 5e-324, 1e300];
        c.interval = [1e-6, f64::INFINITY];
        let r = python_repro(&c);
        assert!(r.contains("rtu.Vec3(0.1, 5e-324, 1e300)"), "{r}");
        assert!(r.contains("rtu.Interval(1e-6, float('inf'))"), "{r}");
        assert!(
            r.contains("rto.Sphere(rtu.Vec3(0.0, 0.0, 0.0), 1.0)"),
            "{r}"
        );
        assert!(r.contains("# expected: a hit at t = 4.0"), "{r}");
    }

    fn honest() -> PathBuf {
        crate::grade::bench::fixtures_dir().join("honest")
    }

    #[test]
    fn the_honest_fixture_passes_every_vector_in_the_sandbox() {
        let out =
            StandinCodeChecker::default().check(&honest(), &[ShapeKind::Sphere, ShapeKind::Quad]);
        assert_eq!(out.fatal, None, "{}", out.stderr_tail);
        let suite = default_suite(0);
        for kind in [ShapeKind::Sphere, ShapeKind::Quad] {
            let n = suite
                .iter()
                .filter(|c| c.shape.kind() == kind && c.expect.class.is_definite())
                .count();
            let c = &out.per_group[&kind];
            assert_eq!((c.definite_total, c.passed), (n, n), "{kind}");
        }
        assert!(out.failures.is_empty(), "{:?}", out.failures);
        // SAFETY: geteuid has no preconditions.
        if unsafe { libc::geteuid() } == 0 && out.sandbox["note"].is_null() {
            assert_eq!(out.sandbox["uid"], 65534, "{}", out.sandbox);
        }
    }

    #[test]
    fn an_interpreter_the_drop_user_cannot_run_falls_back_and_says_so() {
        // Python under /root (mode 0700) cannot be run by `nobody`.
        let private = Path::new("/root/.pyenv/versions/3.11.7/bin/python3");
        // SAFETY: geteuid has no preconditions.
        if unsafe { libc::geteuid() } != 0 || !private.exists() {
            eprintln!("skipped: needs root and a Python under /root");
            return;
        }
        let checker = StandinCodeChecker {
            python: Some(private.to_path_buf()),
            ..Default::default()
        };
        let out = checker.check(&honest(), &[ShapeKind::Sphere]);
        assert_eq!(out.fatal, None);
        assert_eq!(out.per_group[&ShapeKind::Sphere].passed, 2);
        let note = out.sandbox["note"].as_str().unwrap_or("");
        assert!(note.contains("cannot run"), "{}", out.sandbox);
    }
}
