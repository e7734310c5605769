//! Throughput of candidate checking, with baselines measured in the same run:
//! the in-process Rust reference through the same judging code, and a trivial Python adapter
//! that answers "miss" to everything (the protocol's ceiling), against the course adapter on
//! the honest fixture. Also the wall time of the default suite, and of a submission that hangs
//! on every miss with the default 2 s timeout.
//!
//! Run with `rtoracle bench candidate` or `cargo bench --bench candidate` (needs a python3 with
//! numpy and Pillow; the fixtures are embedded in the binary).

use std::path::PathBuf;
use std::time::{Duration, Instant};

use crate::bench::fixtures::python_files_in;
use crate::candidate::fuzzing::generate::random_cases;
use crate::candidate::process::command::CandidateCommand;
use crate::candidate::process::error::HarnessError;
use crate::candidate::process::options::RunOptions;
use crate::candidate::rust::{Reference, check_candidate};
use crate::oracle::vectors::ShapeKind;

/// A Python 3 that can import the course's requirements (numpy and Pillow), which the fixtures
/// (like the course's own `RT_utility.py`) import at module level: `$RTORACLE_PYTHON`, else the
/// first of `/usr/bin/python3`, `/usr/local/bin/python3` and `python3` on `PATH` that can.
pub fn course_python() -> Option<PathBuf> {
    let mut candidates: Vec<PathBuf> = Vec::new();
    if let Some(p) = std::env::var_os("RTORACLE_PYTHON") {
        candidates.push(p.into());
    }
    candidates.extend(["/usr/bin/python3", "/usr/local/bin/python3", "python3"].map(PathBuf::from));
    candidates.into_iter().find(|p| {
        std::process::Command::new(p)
            .args(["-I", "-c", "import numpy, PIL"])
            .stdin(std::process::Stdio::null())
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .status()
            .is_ok_and(|s| s.success())
    })
}

/// [`course_python`] for a test named `test`: `None` after saying on stderr that the test is
/// skipped (`cargo test` shows it with `--nocapture`, or in the test's output when it fails),
/// unless `RTORACLE_REQUIRE_PYTHON=1` (as `.ci/run` sets), which makes a missing interpreter a
/// failure instead.
pub fn course_python_or_skip(test: &str) -> Option<PathBuf> {
    let found = course_python();
    if found.is_none() {
        let why = "no python3 with numpy and PIL (apt-get install python3-numpy python3-pil, \
                   or set RTORACLE_PYTHON)";
        if std::env::var_os("RTORACLE_REQUIRE_PYTHON").is_some_and(|v| v == "1") {
            panic!("{test}: {why}, and RTORACLE_REQUIRE_PYTHON=1");
        }
        eprintln!("skipped {test}: {why}");
    }
    found
}

/// A submission folder for the fixture `variant` (the common modules, then the variant's own
/// `.py` files: its `RT_object.py` and any common module it replaces, as a later week's
/// `RT_ray.py`) in a new temporary folder, written from the copies embedded in the binary
/// ([`crate::bench::fixtures`]), so it works from an installed binary.
pub fn assemble_fixture(variant: &str) -> std::io::Result<tempfile::TempDir> {
    let own = python_files_in(&format!("python/variants/{variant}"));
    if !own.iter().any(|(name, _)| *name == "RT_object.py") {
        return Err(std::io::Error::new(
            std::io::ErrorKind::NotFound,
            format!("fixture {variant} has no RT_object.py"),
        ));
    }
    let dir = tempfile::Builder::new()
        .prefix(&format!("rtoracle-fixture-{variant}-"))
        .tempdir()?;
    for (name, bytes) in python_files_in("python/common").into_iter().chain(own) {
        std::fs::write(dir.path().join(name), bytes)?;
    }
    Ok(dir)
}

/// A Python adapter that answers every request with a miss, flushing each answer: the cost of
/// the protocol alone for an adapter that does not batch.
pub const ECHO_ADAPTER: &str = r#"import json, sys
out = sys.stdout
stdin = sys.stdin.buffer
stdin.readline()
out.write('{"name":"echo","protocol":1}\n'); out.flush()
for line in stdin:
    out.write('{"id":' + json.dumps(json.loads(line)["id"]) + ',"hit":false}\n'); out.flush()
"#;

fn rate(n: usize, d: Duration) -> f64 {
    n as f64 / d.as_secs_f64()
}

/// CPU seconds used so far by this process (the harness) and by its reaped children (the
/// candidates).
fn cpu_seconds() -> [f64; 2] {
    let mut total = [0.0; 2];
    for (k, who) in [libc::RUSAGE_SELF, libc::RUSAGE_CHILDREN]
        .into_iter()
        .enumerate()
    {
        // SAFETY: getrusage fills the struct it is given.
        let mut u: libc::rusage = unsafe { std::mem::zeroed() };
        // SAFETY: `u` is a live rusage for getrusage to fill.
        if unsafe { libc::getrusage(who, &mut u) } == 0 {
            for t in [u.ru_utime, u.ru_stime] {
                total[k] += t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
            }
        }
    }
    total
}

/// Wall time and CPU time (harness, candidate) of `f`.
fn timed<T>(f: impl FnOnce() -> T) -> (T, Duration, [f64; 2]) {
    let c = cpu_seconds();
    let t = Instant::now();
    let out = f();
    let d = cpu_seconds();
    (out, t.elapsed(), [d[0] - c[0], d[1] - c[1]])
}

/// What the benchmark runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Options {
    /// Random cases through each candidate.
    pub cases: usize,
    /// Whether the default suite is run too, through the honest and the hanging submission.
    pub suites: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            cases: 20_000,
            suites: true,
        }
    }
}

impl Options {
    /// A run of a few seconds that shows the benchmark works (1,000 cases, no suites): not a
    /// measurement.
    pub fn quick() -> Self {
        Options {
            cases: 1_000,
            suites: false,
        }
    }
}

/// Runs the benchmark and returns its report (or why it could not run).
pub fn run(options: Options) -> Result<String, HarnessError> {
    let io = |context: &str| {
        let context = context.to_string();
        move |reason| HarnessError::Io { context, reason }
    };
    let mut out = String::new();
    let n = options.cases;
    let cases = random_cases(11, 0, n, &[ShapeKind::Sphere, ShapeKind::Quad]);
    out.push_str(&format!(
        "{} definite random cases (spheres and quads), one process each, 2-core machine\n\n",
        cases.len()
    ));

    let (report, d_ref, c_ref) = timed(|| check_candidate(&mut Reference, &cases));
    assert!(report.passed(), "the reference passes its own cases");

    let tmp = tempfile::tempdir().map_err(io("temporary folder"))?;
    let echo = tmp.path().join("echo.py");
    std::fs::write(&echo, ECHO_ADAPTER).map_err(io("writing the echo adapter"))?;
    let python = course_python().ok_or_else(|| {
        HarnessError::Python("no python3 with numpy and PIL for the course fixtures".into())
    })?;
    let cmd = CandidateCommand::adapter(&format!("{} -I {}", python.display(), echo.display()))?;
    let (r, d_echo, c_echo) =
        timed(|| crate::candidate::check_command(cmd, &cases, RunOptions::default()));
    r?;

    let honest = assemble_fixture("honest_reference").map_err(io("assembling the fixture"))?;
    let cmd = CandidateCommand::python_course_with(honest.path(), Some(&python), false)?;
    let (report, d_py, c_py) =
        timed(|| crate::candidate::check_command(cmd, &cases, RunOptions::default()));
    let py_ok = report?.passed();

    let rows = [
        ("in-process Rust reference (baseline)", d_ref, c_ref),
        ("Python echo adapter, one flush per answer", d_echo, c_echo),
        ("course adapter + honest Python submission", d_py, c_py),
    ];
    out.push_str(&format!(
        "{:<44} {:>7} {:>10} {:>9} {:>9} {:>13}\n",
        "candidate", "wall s", "vectors/s", "harness", "candidate", "idle-2-core/s"
    ));
    for (name, d, c) in rows {
        // With the harness and the candidate on their own cores, the slower one sets the pace.
        out.push_str(&format!(
            "{:<44} {:>7.3} {:>10.0} {:>8.3}s {:>8.3}s {:>13.0}\n",
            name,
            d.as_secs_f64(),
            rate(cases.len(), d),
            c[0],
            c[1],
            cases.len() as f64 / c[0].max(c[1]).max(1e-9)
        ));
    }
    out.push_str(&format!(
        "course adapter / echo adapter wall time: {:.2}x; course adapter passed: {}\n",
        d_py.as_secs_f64() / d_echo.as_secs_f64(),
        py_ok
    ));
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    out.push_str(&format!(
        "load average during the run: {}; harness and candidate columns are CPU seconds;\n\
         idle-2-core/s = vectors / max(harness, candidate CPU), the rate with a core each\n",
        load.split_whitespace()
            .take(3)
            .collect::<Vec<_>>()
            .join(" ")
    ));
    if !options.suites {
        return Ok(out);
    }

    let suite = crate::oracle::suite::default_suite(0);
    let t = Instant::now();
    let report = crate::candidate::check_command(
        CandidateCommand::python_course_with(honest.path(), Some(&python), false)?,
        &suite,
        RunOptions::default(),
    )?;
    out.push_str(&format!(
        "\ndefault suite ({} vectors) through the course adapter, start to report: {:.3} s (passed: {})\n",
        suite.len(),
        t.elapsed().as_secs_f64(),
        report.passed()
    ));

    let hang = assemble_fixture("hostile_hang_on_miss").map_err(io("assembling the fixture"))?;
    let t = Instant::now();
    let report = crate::candidate::check_command(
        CandidateCommand::python_course_with(hang.path(), Some(&python), false)?,
        &suite,
        RunOptions::default(),
    )?;
    out.push_str(&format!(
        "default suite, submission hanging on every miss, 2 s timeout: {:.1} s ({} timeouts, {} not run)\n",
        t.elapsed().as_secs_f64(),
        report.counts.timeouts,
        report.counts.not_run
    ));
    Ok(out)
}
