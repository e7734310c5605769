//! Running trusted helper programs inside a sandbox, as its code would run: an interpreter's
//! probe ([`Sandbox::probe_output`]) and the check that the sandbox user can run an adapter and
//! read its files ([`Sandbox::probe_access`]).

use std::ffi::{OsStr, OsString};
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::Stdio;
use std::time::{Duration, Instant};

use super::bounds::reaper::kill_group;
use super::lifecycle::Sandbox;

impl Sandbox {
    /// as an interpreter's. Returns the exit status's success and stdout, or why it did not run.
    pub fn probe_output(
        &self,
        program: &Path,
        args: &[&OsStr],
        timeout: Duration,
    ) -> Result<(bool, String, String), String> {
        // Started and recorded under the gate, so an interruption's cleanup finds it.
        let gate = crate::interrupt::spawn_gate().ok_or_else(|| "interrupted".to_string())?;
        let mut child = self
            .command(program)
            .args(args)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| format!("{}: {e}", program.display()))?;
        self.reaper.track(child.id());
        drop(gate);
        let out = child.stdout.take();
        let err = child.stderr.take();
        let read = |s: Option<std::process::ChildStdout>| {
            std::thread::spawn(move || {
                let mut text = String::new();
                if let Some(s) = s {
                    let _ = s.take(1 << 16).read_to_string(&mut text);
                }
                text
            })
        };
        let out = read(out);
        let err = std::thread::spawn(move || {
            let mut text = String::new();
            if let Some(s) = err {
                let _ = s.take(1 << 16).read_to_string(&mut text);
            }
            text
        });
        let deadline = Instant::now() + timeout;
        let status = loop {
            match child.try_wait() {
                Ok(Some(s)) => break Some(s),
                Ok(None) if Instant::now() < deadline => {
                    std::thread::sleep(Duration::from_millis(2))
                }
                _ => break None,
            }
        };
        let Some(status) = status else {
            self.reaper.reap();
            kill_group(&mut child);
            self.reaper.untrack(child.id());
            return Err(format!(
                "{} did not finish within {:.0} s",
                program.display(),
                timeout.as_secs_f64()
            ));
        };
        self.reaper.untrack(child.id());
        self.reaper.reap();
        let out = out.join().unwrap_or_default();
        let err = err.join().unwrap_or_default();
        Ok((status.success(), out, err))
    }

    /// For a program that cannot be probed by running it (an adapter command): checks, inside
    /// the sandbox and as its user, that `program` is executable and every argument naming an
    /// existing absolute path is readable; `Err` names what is not.
    pub fn probe_access(&self, program: &Path, args: &[OsString]) -> Result<(), String> {
        let files: Vec<&OsString> = args
            .iter()
            .filter(|a| Path::new(a).is_absolute() && Path::new(a).exists())
            .collect();
        let script = r#"p=$1; shift
case $p in */*) [ -x "$p" ] || { echo "$p"; exit 1; } ;; *) command -v "$p" >/dev/null || { echo "$p"; exit 1; } ;; esac
for f; do [ -r "$f" ] || { echo "$f"; exit 1; }; done"#;
        let mut words: Vec<&OsStr> = vec![OsStr::new("-c"), OsStr::new(script), OsStr::new("sh")];
        words.push(program.as_os_str());
        words.extend(files.iter().map(|f| f.as_os_str()));
        match self.probe_output(Path::new("/bin/sh"), &words, Duration::from_secs(10)) {
            Ok((true, _, _)) => Ok(()),
            Ok((false, out, err)) => {
                let what = out.trim();
                let what = if what.is_empty() { err.trim() } else { what };
                // bubblewrap itself may be what could not reach it: "Can't find source path
                // P: Permission denied".
                let path = what.split_once("source path ").map_or(what, |(_, rest)| {
                    rest.rsplit_once(':').map_or(rest, |r| r.0)
                });
                let path = Path::new(path.trim());
                let fix = if path.is_absolute() && self.drops_user() {
                    access_fix(path, path == program)
                } else {
                    None
                };
                Err(match fix {
                    Some(fix) => format!(
                        "the sandbox user (uid {}) cannot run or read {}: {fix}, or pass \
                         --unsandboxed to run your own code without a sandbox",
                        self.uid(),
                        path.display()
                    ),
                    None => format!(
                        "the sandbox user (uid {}) cannot run or read {what}: make it readable by \
                         all, or pass --unsandboxed to run your own code without a sandbox",
                        self.uid()
                    ),
                })
            }
            Err(e) => Err(e),
        }
    }
}

/// What keeps users other than the owner from `path`, and the command that lets them reach it:
/// the first folder above it they cannot enter (`chmod o+x FOLDER`), else the file itself
/// (`chmod o+r`, `o+rx` for a `program`). `None` when the modes let them (the cause is elsewhere).
pub(super) fn access_fix(path: &Path, program: bool) -> Option<String> {
    use std::os::unix::fs::PermissionsExt;
    let mode = |p: &Path| {
        std::fs::metadata(p)
            .ok()
            .map(|m| m.permissions().mode() & 0o7777)
    };
    let mut folder = PathBuf::from("/");
    for part in path.parent()?.components().skip(1) {
        folder.push(part);
        if let Some(m) = mode(&folder)
            && m & 0o001 == 0
        {
            return Some(format!(
                "the folder {} is closed to other users (mode {m:o}): `chmod o+x {}` lets the \
                 sandbox reach what is in it",
                folder.display(),
                folder.display()
            ));
        }
    }
    let m = mode(path)?;
    let (needed, bits) = if program || path.is_dir() {
        ("rx", 0o005)
    } else {
        ("r", 0o004)
    };
    (m & bits != bits).then(|| {
        format!(
            "it is closed to other users (mode {m:o}): `chmod o+{needed} {}` opens it",
            path.display()
        )
    })
}
