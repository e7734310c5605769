//! What a candidate runs ([`CandidateCommand`]): an `--adapter` command line split into words,
//! or the bundled course adapter on a submission folder, and the sandbox made for it (the
//! submission's modules staged, the program's folders shown, access probed).
//!
//! The course adapter's submission files (its top-level Python modules, regular files up to
//! [`MAX_STAGED_FILE_BYTES`] each and [`MAX_STAGED_TOTAL_BYTES`] in all; those left out are
//! named, at most [`MAX_SKIPPED_NAMED`] of them) are copied into the sandbox folder, so the
//! candidate never runs in (or writes to) the submission itself, and the adapter is told a
//! neutral name, never the submission's path. The interpreter is chosen by
//! [`python`](crate::candidate::process::python).

use std::ffi::OsString;
use std::path::{Path, PathBuf};

use crate::candidate::process::error::HarnessError;
use crate::sandbox::{lifecycle::Sandbox, policy::SandboxPolicy};

/// The name the course adapter has in the sandbox folder.
const ADAPTER_NAME: &str = "course_adapter.py";

/// The name the course adapter is given (`--name`): neutral, so the code inside learns nothing
/// of where the grader keeps the submission; reports use the harness's own label.
const NEUTRAL_NAME: &str = "python-course";

/// Largest submission file copied into the sandbox.
pub const MAX_STAGED_FILE_BYTES: u64 = crate::sandbox::lifecycle::MAX_COPIED_FILE_BYTES;

/// Most bytes of submission files copied into the sandbox in all.
pub const MAX_STAGED_TOTAL_BYTES: u64 = 8 << 20;

/// Most submission files copied into the sandbox.
pub const MAX_STAGED_FILES: usize = 200;

/// Most files left out of the sandbox that its facts name (the rest are counted).
pub const MAX_SKIPPED_NAMED: usize = 20;

/// The embedded adapter for the course's Python API.
pub const PYTHON_COURSE_ADAPTER: &str = include_str!("python_course.py");

/// The adapter's driver of the course's functions of weeks 5 to 10 (function requests,
/// `docs/PROTOCOL.md`), written beside the adapter, which loads it from its own folder. The
/// material requests' driver (`rtoracle physics`) is appended to it: it extends the driver's
/// `OPS` and `answer`.
pub const COURSE_FUNCTIONS_DRIVER: &str = concat!(
    include_str!("../../weekly/course_functions.py"),
    include_str!("../../physics/course_materials.py")
);

/// The driver's name in the sandbox folder (the adapter's `FUNCTIONS_FILE`).
const FUNCTIONS_NAME: &str = "rtoracle_course_functions.py";

/// The course adapter's driver of the submission's own `main.py` (render requests naming a
/// `program`), written beside the adapter.
pub const COURSE_PROGRAM_DRIVER: &str = include_str!("python_course_program.py");

/// The program driver's name in the sandbox folder (the adapter's `PROGRAM_FILE`).
const PROGRAM_NAME: &str = "rtoracle_course_program.py";

/// The program a candidate runs, and how its failures are treated.
#[derive(Clone, Debug)]
pub struct CandidateCommand {
    /// The executable (absolute, or looked up on `PATH`).
    pub program: PathBuf,
    /// Its arguments.
    pub args: Vec<OsString>,
    /// A label for reports.
    pub label: String,
    /// When the hello fails: `true` makes it a harness error (an adapter that does not speak the
    /// protocol), `false` reports it as an error on every case (a submission whose import hangs
    /// or kills the interpreter).
    pub hello_failure_is_fatal: bool,
    /// The submission folder whose top-level `.py` files are copied into the sandbox (course
    /// adapter only).
    pub(crate) submission: Option<PathBuf>,
    /// Whether the bundled course adapter is written into the sandbox folder.
    pub(crate) course_adapter: bool,
}

impl CandidateCommand {
    /// A command from a command line such as `'python3 my_adapter.py --fast'`. Words are split
    /// on whitespace, with `'...'` and `"..."` quoting; a word naming an existing file relative
    /// to the current folder is made absolute (the candidate runs in a temporary folder).
    pub fn adapter(command_line: &str) -> Result<Self, HarnessError> {
        let bad = |problem: &str| HarnessError::Command {
            command: command_line.to_string(),
            problem: problem.to_string(),
        };
        let words = split_words(command_line).ok_or_else(|| bad("has an unclosed quote"))?;
        let mut words = words.into_iter().map(|w| {
            let p = Path::new(&w);
            if p.is_relative() && p.exists() && (w.contains('/') || p.is_file()) {
                std::path::absolute(p)
                    .map(|p| p.into_os_string())
                    .unwrap_or_else(|_| w.into())
            } else {
                OsString::from(w)
            }
        });
        let program = words.next().ok_or_else(|| bad("is empty"))?;
        Ok(CandidateCommand {
            program: PathBuf::from(program),
            args: words.collect(),
            label: command_line.to_string(),
            hello_failure_is_fatal: true,
            submission: None,
            course_adapter: false,
        })
    }

    /// The bundled adapter for the course's Python API run on the submission folder `dir`. The
    /// interpreter is [`python::choose`](crate::candidate::process::python::choose)'s (with numpy and Pillow, runnable
    /// in the sandbox). The top-level `.py` files of `dir` are copied into the sandbox folder when
    /// the session starts, and the adapter imports them from there. Anything the submission
    /// prints is a protocol error of its case.
    pub fn python_course(dir: &Path) -> Result<Self, HarnessError> {
        Self::python_course_with(dir, None, false)
    }

    /// [`CandidateCommand::python_course`] with a chosen interpreter (`None`: as there; a given one
    /// is used as it is, so probe it first with [`python::choose`](crate::candidate::process::python::choose)), and with
    /// the submission's prints sent to stderr instead (`prints_to_stderr`: what grading wants,
    /// since nothing a student prints may change a grade but the answers).
    pub fn python_course_with(
        dir: &Path,
        python: Option<&Path>,
        prints_to_stderr: bool,
    ) -> Result<Self, HarnessError> {
        if !dir.is_dir() {
            return Err(HarnessError::Submission {
                path: dir.display().to_string(),
                problem: "is not a folder (expected the submission folder holding RT_object.py)"
                    .into(),
            });
        }
        let dir = std::path::absolute(dir).map_err(|reason| HarnessError::Io {
            context: dir.display().to_string(),
            reason,
        })?;
        let python = match python {
            Some(p) => p.to_path_buf(),
            None => crate::candidate::process::python::choose(
                None,
                &crate::candidate::process::python::default_requires(),
                &SandboxPolicy::default(),
            )
            .map_err(|e| match e {
                crate::candidate::process::python::PythonError::Sandbox(e) => {
                    HarnessError::Sandbox(e)
                }
                other => HarnessError::Python(other.to_string()),
            })?,
        };
        let label = format!("python-course {}", dir.display());
        let mut args: Vec<OsString> = vec![
            "-I".into(),
            "-B".into(),
            ADAPTER_NAME.into(),
            ".".into(),
            "--name".into(),
            NEUTRAL_NAME.into(),
        ];
        if prints_to_stderr {
            args.push("--prints-to-stderr".into());
        }
        Ok(CandidateCommand {
            program: python,
            args,
            label,
            hello_failure_is_fatal: false,
            submission: Some(dir),
            course_adapter: true,
        })
    }

    /// Whether this runs the bundled course adapter (failures then get Python reproductions).
    pub fn is_course_adapter(&self) -> bool {
        self.course_adapter
    }

    /// The submission folder the course adapter runs on (`None` for an adapter command).
    pub fn submission(&self) -> Option<&Path> {
        self.submission.as_deref()
    }

    /// The files to copy into the sandbox: the submission's top-level Python modules (a name
    /// that is a Python identifier plus `.py`; regular files only, never a link, FIFO or
    /// device; up to [`MAX_STAGED_FILE_BYTES`] each, [`MAX_STAGED_TOTAL_BYTES`] and
    /// [`MAX_STAGED_FILES`] in all), and the ones left out, each named (escaped) with why, the
    /// first [`MAX_SKIPPED_NAMED`] of them (a last line counts the others).
    #[allow(clippy::type_complexity)]
    fn staged_files(&self) -> Result<(Vec<(PathBuf, String)>, Vec<String>), HarnessError> {
        let Some(dir) = &self.submission else {
            return Ok((Vec::new(), Vec::new()));
        };
        let entries = std::fs::read_dir(dir).map_err(|reason| HarnessError::Io {
            context: dir.display().to_string(),
            reason,
        })?;
        let mut candidates = Vec::new();
        for entry in entries.flatten() {
            let raw = entry.file_name();
            let name = raw.to_string_lossy().to_string();
            if !name.ends_with(".py")
                || name == ADAPTER_NAME
                || name == FUNCTIONS_NAME
                || name == PROGRAM_NAME
            {
                continue;
            }
            candidates.push((name, entry));
        }
        candidates.sort_by(|a, b| a.0.cmp(&b.0));
        let mut files = Vec::new();
        let mut skipped = Vec::new();
        let mut total = 0u64;
        for (name, entry) in candidates {
            let shown = crate::escape::terminal_line(&name);
            let stem = &name[..name.len() - 3];
            let identifier = !stem.is_empty()
                && !stem.starts_with(|c: char| c.is_ascii_digit())
                && stem.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
            // Not followed: a link stays a link.
            let meta = std::fs::symlink_metadata(entry.path());
            let why = match &meta {
                _ if !identifier => Some("not a Python module name".to_string()),
                Err(e) => Some(e.to_string()),
                Ok(m) if m.file_type().is_symlink() => Some("a symbolic link".into()),
                Ok(m) if !m.is_file() => Some("not a regular file".into()),
                Ok(m) if m.len() > MAX_STAGED_FILE_BYTES => Some(format!(
                    "{} bytes, over the {} bytes a file may have",
                    m.len(),
                    MAX_STAGED_FILE_BYTES
                )),
                Ok(m) if total + m.len() > MAX_STAGED_TOTAL_BYTES => Some(format!(
                    "over the {MAX_STAGED_TOTAL_BYTES} bytes all files may have"
                )),
                Ok(_) if files.len() >= MAX_STAGED_FILES => {
                    Some(format!("over the {MAX_STAGED_FILES} files that are copied"))
                }
                Ok(m) => {
                    total += m.len();
                    None
                }
            };
            match why {
                Some(why) => skipped.push(format!("{shown} ({why})")),
                None => files.push((entry.path(), name)),
            }
        }
        if skipped.len() > MAX_SKIPPED_NAMED {
            let more = skipped.len() - MAX_SKIPPED_NAMED;
            skipped.truncate(MAX_SKIPPED_NAMED);
            skipped.push(format!("and {more} more files not copied"));
        }
        Ok((files, skipped))
    }

    /// Makes the sandbox for this command: the staged files, the adapter, the program's and its
    /// files' folders shown read-only, and (for an adapter) a check, inside the sandbox, that
    /// its user can run the program and read its files, before any untrusted code runs.
    pub(crate) fn sandbox(&self, policy: SandboxPolicy) -> Result<Sandbox, HarnessError> {
        let io = |reason| HarnessError::Io {
            context: "preparing the candidate's sandbox folder".into(),
            reason,
        };
        let (files, skipped) = self.staged_files()?;
        let mut sandbox = Sandbox::new(policy, &files)?;
        sandbox.set_skipped(skipped);
        sandbox.expose(&self.program);
        if self.course_adapter {
            sandbox
                .add_file(ADAPTER_NAME, PYTHON_COURSE_ADAPTER.as_bytes())
                .map_err(io)?;
            sandbox
                .add_file(FUNCTIONS_NAME, COURSE_FUNCTIONS_DRIVER.as_bytes())
                .map_err(io)?;
            sandbox
                .add_file(PROGRAM_NAME, COURSE_PROGRAM_DRIVER.as_bytes())
                .map_err(io)?;
        } else {
            let found = if self.program.components().count() > 1 {
                self.program.exists()
            } else {
                std::env::split_paths(crate::sandbox::start::command::SANDBOX_PATH)
                    .chain(
                        std::env::var_os("PATH")
                            .iter()
                            .flat_map(std::env::split_paths),
                    )
                    .any(|d| d.join(&self.program).is_file())
            };
            if !found {
                return Err(HarnessError::Spawn {
                    program: self.program.display().to_string(),
                    reason: std::io::Error::from_raw_os_error(libc::ENOENT),
                });
            }
            for a in &self.args {
                let p = Path::new(a);
                if p.is_absolute() && p.exists() {
                    sandbox.expose(p);
                }
            }
            if sandbox.isolation() != crate::sandbox::policy::Isolation::Unsandboxed {
                sandbox
                    .probe_access(&self.program, &self.args)
                    .map_err(|problem| HarnessError::Command {
                        command: self.label.clone(),
                        problem,
                    })?;
            }
        }
        Ok(sandbox)
    }
}

/// Splits a command line into words (whitespace, single and double quotes); `None` on an
/// unclosed quote.
fn split_words(line: &str) -> Option<Vec<String>> {
    let mut words = Vec::new();
    let mut word = String::new();
    let mut in_word = false;
    let mut quote: Option<char> = None;
    for ch in line.chars() {
        match quote {
            Some(q) if ch == q => quote = None,
            Some(_) => word.push(ch),
            None if ch == '\'' || ch == '"' => {
                quote = Some(ch);
                in_word = true;
            }
            None if ch.is_whitespace() => {
                if in_word {
                    words.push(std::mem::take(&mut word));
                    in_word = false;
                }
            }
            None => {
                word.push(ch);
                in_word = true;
            }
        }
    }
    if quote.is_some() {
        return None;
    }
    if in_word {
        words.push(word);
    }
    Some(words)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 30,000 empty `.py` files made the sandbox facts name each one left out: at most
    /// [`MAX_SKIPPED_NAMED`] are named, and the rest counted.
    #[test]
    fn a_submission_of_many_files_names_a_bounded_number_of_those_not_copied() {
        let dir = tempfile::tempdir().unwrap();
        for i in 0..MAX_STAGED_FILES + 300 {
            std::fs::write(dir.path().join(format!("m{i:04}.py")), b"").unwrap();
        }
        for i in 0..50 {
            std::fs::write(dir.path().join(format!("bad-{i:02}.py")), b"").unwrap();
        }
        let command =
            CandidateCommand::python_course_with(dir.path(), Some(Path::new("python3")), true)
                .unwrap();
        let (files, skipped) = command.staged_files().unwrap();
        assert_eq!(files.len(), MAX_STAGED_FILES);
        assert_eq!(skipped.len(), MAX_SKIPPED_NAMED + 1, "{}", skipped.len());
        assert_eq!(skipped[0], "bad-00.py (not a Python module name)");
        assert_eq!(
            skipped[MAX_SKIPPED_NAMED],
            format!("and {} more files not copied", 350 - MAX_SKIPPED_NAMED)
        );
    }

    #[test]
    fn words_split_like_a_shell() {
        assert_eq!(
            split_words(r#"python3 -c 'print("a b")' x"#).unwrap(),
            ["python3", "-c", "print(\"a b\")", "x"]
        );
        assert_eq!(split_words("  a   \"\" b ").unwrap(), ["a", "", "b"]);
        assert!(split_words("a 'b").is_none());
    }
}
