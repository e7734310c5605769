//! Choosing the Python that runs the course adapter (issue 10): one that has the assignment's
//! modules (`python_requires`, default [`DEFAULT_REQUIRES`]: numpy and Pillow, which the
//! course's `RT_utility.py` imports) and that the sandbox user can run.
//!
//! Promises:
//! - The choice is `--python PATH`, else `$RTORACLE_PYTHON`, else the usual places in order
//!   (`/usr/bin/python3`, `/usr/local/bin/python3`, `python3` on the harness's `PATH`,
//!   `/usr/bin/python3.N` and `/usr/local/bin/python3.N`, newest first), deduplicated by real
//!   path; the first that has every required module wins.
//! - Each is probed **inside the same sandbox, as the same kind of sandbox user** the
//!   submissions get ([`Sandbox::probe_output`]), so an interpreter under `/root` (pyenv's) or
//!   one whose libraries the sandbox cannot see is never chosen. The probe finds each module with
//!   `importlib.util.find_spec` (run with `-I`, as the adapter is), without importing it: one
//!   interpreter start (~30 ms), not numpy's import (~300 ms). It is retried once when it
//!   fails to run, and a probe that fails never leads to running anything as root: the sandbox
//!   fails closed before any probe.
//! - An interpreter given explicitly (`--python`, `RTORACLE_PYTHON`) that cannot run or lacks a
//!   module is an error naming it and the modules; another is never picked silently.
//! - When none fits: [`PythonError::NoneFits`], one line naming the missing modules and how to
//!   get them (`apt-get install python3-numpy python3-pil`, `python3 -m pip install numpy
//!   pillow`, or `--python`).
//! - The answer is cached for the process (per request), so a batch probes once.

use std::collections::HashMap;
use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, OnceLock};
use std::time::Duration;

use crate::sandbox::{lifecycle::Sandbox, policy::SandboxError, policy::SandboxPolicy};

/// The modules the course's code imports at module level (`RT_utility.py`: numpy and Pillow;
/// `docs/sandbox.md`, "The interpreter").
pub const DEFAULT_REQUIRES: [&str; 2] = ["numpy", "PIL"];

/// [`DEFAULT_REQUIRES`] as owned strings (the rubric's default `python_requires`).
pub fn default_requires() -> Vec<String> {
    DEFAULT_REQUIRES.iter().map(|s| s.to_string()).collect()
}

/// Why no interpreter can be used.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum PythonError {
    /// The interpreter given explicitly cannot be used.
    #[error("{origin} {python}: {problem}")]
    Given {
        /// `--python` or `RTORACLE_PYTHON`.
        origin: String,
        /// The interpreter.
        python: String,
        /// What is wrong (missing modules, cannot run), with how to fix it.
        problem: String,
    },
    /// None of the usual places has the modules.
    #[error(
        "no Python 3 that the sandbox can run has {missing} ({tried}); install {them}: {hint}, or pass --python PATH"
    )]
    NoneFits {
        /// The modules the best interpreter lacks, comma-separated.
        missing: String,
        /// What each interpreter tried lacked or why it could not run.
        tried: String,
        /// `it` or `them`.
        them: String,
        /// The install commands.
        hint: String,
    },
    /// No sandbox can be made (the probe runs in one).
    #[error(transparent)]
    Sandbox(#[from] SandboxError),
}

/// What a probe found.
#[derive(Debug)]
enum Probe {
    /// It ran: its version and the modules it lacks.
    Ran {
        version: String,
        missing: Vec<String>,
    },
    /// It could not be run in the sandbox.
    Failed(String),
}

const PROBE_SCRIPT: &str = r#"import sys, json, importlib.util
def lacks(n):
    try:
        return importlib.util.find_spec(n) is None
    except Exception:
        return True
print(json.dumps({"major": sys.version_info[0], "version": "%d.%d" % sys.version_info[:2], "missing": [n for n in sys.argv[1:] if lacks(n)]}))
"#;

fn probe_once(sandbox: &Sandbox, python: &Path, requires: &[String]) -> Probe {
    let mut args: Vec<&OsStr> = vec![OsStr::new("-I"), OsStr::new("-c"), OsStr::new(PROBE_SCRIPT)];
    args.extend(requires.iter().map(OsStr::new));
    match sandbox.probe_output(python, &args, Duration::from_secs(20)) {
        Err(e) => Probe::Failed(e),
        Ok((ok, out, err)) => {
            let line = out.lines().last().unwrap_or("");
            match serde_json::from_str::<serde_json::Value>(line) {
                Ok(v) if ok && v["major"] == 3 => Probe::Ran {
                    version: v["version"].as_str().unwrap_or("3").to_string(),
                    missing: v["missing"]
                        .as_array()
                        .map(|a| {
                            a.iter()
                                .filter_map(|m| m.as_str().map(str::to_string))
                                .collect()
                        })
                        .unwrap_or_default(),
                },
                Ok(v) if ok => Probe::Failed(format!("is not Python 3 ({})", v["version"])),
                _ => {
                    let why = err
                        .lines()
                        .rev()
                        .find(|l| !l.trim().is_empty())
                        .unwrap_or("");
                    Probe::Failed(format!(
                        "cannot be run by the sandbox user (uid {}){}",
                        sandbox.uid(),
                        if why.is_empty() {
                            String::new()
                        } else {
                            format!(": {}", crate::escape::truncate(why.trim(), 200))
                        }
                    ))
                }
            }
        }
    }
}

/// Probes `python`, once more if it could not be run (a transient failure).
fn probe(sandbox: &mut Sandbox, python: &Path, requires: &[String]) -> Probe {
    sandbox.expose(python);
    match probe_once(sandbox, python, requires) {
        Probe::Failed(_) => probe_once(sandbox, python, requires),
        ran => ran,
    }
}

/// Install commands for `modules` (Debian's packages, pip's names).
fn install_hint(modules: &[String]) -> String {
    let debian: Vec<String> = modules
        .iter()
        .map(|m| match m.as_str() {
            "PIL" => "python3-pil".to_string(),
            other => format!("python3-{}", other.to_lowercase()),
        })
        .collect();
    let pip: Vec<String> = modules
        .iter()
        .map(|m| match m.as_str() {
            "PIL" => "pillow".to_string(),
            other => other.to_lowercase(),
        })
        .collect();
    format!(
        "apt-get install {}, or python3 -m pip install {}",
        debian.join(" "),
        pip.join(" ")
    )
}

/// The usual places, in order (without duplicates by real path).
fn usual_places() -> Vec<PathBuf> {
    let mut places: Vec<PathBuf> = vec!["/usr/bin/python3".into(), "/usr/local/bin/python3".into()];
    if let Some(path) = std::env::var_os("PATH") {
        if let Some(p) = std::env::split_paths(&path)
            .map(|d| d.join("python3"))
            .find(|p| p.is_file())
        {
            places.push(p);
        }
    }
    for dir in ["/usr/bin", "/usr/local/bin"] {
        let mut versioned: Vec<(u32, PathBuf)> = std::fs::read_dir(dir)
            .into_iter()
            .flatten()
            .flatten()
            .filter_map(|e| {
                let name = e.file_name().to_string_lossy().to_string();
                let minor: u32 = name.strip_prefix("python3.")?.parse().ok()?;
                Some((minor, e.path()))
            })
            .collect();
        versioned.sort_by_key(|v| std::cmp::Reverse(v.0));
        places.extend(versioned.into_iter().map(|(_, p)| p));
    }
    let mut seen = Vec::new();
    places
        .into_iter()
        .filter(|p| p.is_file())
        .filter(|p| {
            let real = p.canonicalize().unwrap_or_else(|_| p.clone());
            if seen.contains(&real) {
                false
            } else {
                seen.push(real);
                true
            }
        })
        .collect()
}

type Key = (
    Option<PathBuf>,
    Option<PathBuf>,
    Vec<String>,
    bool,
    Option<String>,
);

fn cache() -> &'static Mutex<HashMap<Key, Result<PathBuf, PythonError>>> {
    static CACHE: OnceLock<Mutex<HashMap<Key, Result<PathBuf, PythonError>>>> = OnceLock::new();
    CACHE.get_or_init(|| Mutex::new(HashMap::new()))
}

fn key(explicit: Option<&Path>, requires: &[String], policy: &SandboxPolicy) -> Key {
    (
        explicit.map(Path::to_path_buf),
        std::env::var_os("RTORACLE_PYTHON").map(PathBuf::from),
        requires.to_vec(),
        policy.unsandboxed,
        std::env::var(crate::sandbox::policy::Mode::ENV).ok(),
    )
}

/// The interpreter to run the course adapter with: `explicit` (`--python`), else
/// `$RTORACLE_PYTHON`, else the first of the usual places that has every module of `requires`,
/// probed inside a sandbox made with `policy`. Cached for the process.
pub fn choose(
    explicit: Option<&Path>,
    requires: &[String],
    policy: &SandboxPolicy,
) -> Result<PathBuf, PythonError> {
    let k = key(explicit, requires, policy);
    if let Some(hit) = cache().lock().unwrap_or_else(|e| e.into_inner()).get(&k) {
        return hit.clone();
    }
    let result = choose_uncached(explicit, requires, policy);
    let mut c = cache().lock().unwrap_or_else(|e| e.into_inner());
    if let Ok(p) = &result {
        // The same interpreter given explicitly later (the CLI passes its choice on) needs no
        // second probe.
        c.insert(key(Some(p), requires, policy), result.clone());
    }
    c.insert(k, result.clone());
    result
}

fn choose_uncached(
    explicit: Option<&Path>,
    requires: &[String],
    policy: &SandboxPolicy,
) -> Result<PathBuf, PythonError> {
    let env = std::env::var_os("RTORACLE_PYTHON").filter(|v| !v.is_empty());
    let given = match (explicit, &env) {
        (Some(p), _) => Some(("--python", p.to_path_buf())),
        (None, Some(v)) => Some(("RTORACLE_PYTHON", PathBuf::from(v))),
        _ => None,
    };
    let mut sandbox = Sandbox::new(policy.clone(), &[])?;
    if let Some((origin, python)) = given {
        let bad = |problem: String| PythonError::Given {
            origin: origin.to_string(),
            python: python.display().to_string(),
            problem,
        };
        let resolved = resolve(&python).ok_or_else(|| bad("no such program".into()))?;
        return match probe(&mut sandbox, &resolved, requires) {
            Probe::Ran { missing, .. } if missing.is_empty() => Ok(resolved),
            Probe::Ran { missing, .. } => Err(bad(format!(
                "lacks {} (install {}: {}, or pass another --python)",
                missing.join(", "),
                if missing.len() == 1 { "it" } else { "them" },
                install_hint(&missing)
            ))),
            Probe::Failed(why) => Err(bad(why)),
        };
    }
    let mut tried = Vec::new();
    let mut best: Option<Vec<String>> = None;
    for python in usual_places() {
        match probe(&mut sandbox, &python, requires) {
            Probe::Ran { missing, .. } if missing.is_empty() => return Ok(python),
            Probe::Ran { missing, version } => {
                tried.push(format!(
                    "{} ({version}) lacks {}",
                    python.display(),
                    missing.join(", ")
                ));
                if best.as_ref().is_none_or(|b| missing.len() < b.len()) {
                    best = Some(missing);
                }
            }
            Probe::Failed(why) => tried.push(format!("{} {why}", python.display())),
        }
    }
    let missing = best.unwrap_or_else(|| requires.to_vec());
    Err(PythonError::NoneFits {
        missing: missing.join(", "),
        tried: if tried.is_empty() {
            "no python3 found".into()
        } else {
            tried.join("; ")
        },
        them: if missing.len() == 1 { "it" } else { "them" }.into(),
        hint: install_hint(&missing),
    })
}

/// `python` made absolute: a bare name is looked up on the harness's `PATH`.
fn resolve(python: &Path) -> Option<PathBuf> {
    if python.components().count() > 1 {
        return std::path::absolute(python).ok().filter(|p| p.exists());
    }
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|d| d.join(python))
        .find(|p| p.is_file())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hints_name_debian_and_pip_packages() {
        assert_eq!(
            install_hint(&default_requires()),
            "apt-get install python3-numpy python3-pil, or python3 -m pip install numpy pillow"
        );
    }

    #[test]
    fn the_system_python_with_numpy_is_chosen_and_a_python_without_it_is_named() {
        if !Path::new("/usr/bin/python3").is_file() {
            eprintln!("skipped: no /usr/bin/python3");
            return;
        }
        let policy = SandboxPolicy::grading();
        let have = std::process::Command::new("/usr/bin/python3")
            .args(["-I", "-c", "import numpy, PIL"])
            .status()
            .map(|s| s.success())
            .unwrap_or(false);
        if have {
            let chosen = choose(None, &default_requires(), &policy);
            // RTORACLE_PYTHON may point elsewhere; without it the system Python wins.
            if std::env::var_os("RTORACLE_PYTHON").is_none() {
                assert_eq!(chosen.unwrap(), PathBuf::from("/usr/bin/python3"));
            }
        }
        // A module no Python has: an explicit interpreter is named with it, never swapped.
        let requires = vec!["rtoracle_no_such_module".to_string()];
        let err = choose(Some(Path::new("/usr/bin/python3")), &requires, &policy).unwrap_err();
        let text = err.to_string();
        assert!(
            text.starts_with("--python /usr/bin/python3: lacks rtoracle_no_such_module"),
            "{text}"
        );
        assert!(
            text.contains("python3 -m pip install rtoracle_no_such_module"),
            "{text}"
        );
    }
}
