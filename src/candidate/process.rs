//! Running a candidate as a child process: spawn in the [sandbox](crate::sandbox), hello,
//! pipelined requests, per-case timeouts, restart after a crash, kill the whole process group on
//! drop.
//!
//! A [`Session`] makes one [`Sandbox`] (bubblewrap where it works, else limits, its own session
//! and a uid of its own; never root; see [`crate::sandbox`]) and starts every process of the
//! candidate, restarts included, through it; when a process is killed or the session ends,
//! every process the candidate started ends too ([`crate::sandbox::Reaper`]). The course
//! adapter's submission files (its top-level Python modules, regular files up to
//! [`MAX_STAGED_FILE_BYTES`] each and [`MAX_STAGED_TOTAL_BYTES`] in all; those left out are
//! named, at most [`MAX_SKIPPED_NAMED`] of them) are copied into that folder, so the candidate never runs in (or writes to) the submission itself, and the adapter
//! is told a neutral name, never the submission's path. The interpreter is chosen by
//! [`python`](super::python).
//!
//! Requests are pipelined: a writer thread writes every pending request as fast as the pipe
//! takes them while the session reads answers. Candidates may batch their answers; after the
//! first crash or timeout the session asks for one flush per answer (`"sync": true`) and runs
//! the cases again from the one it was waiting for, so blame always lands on the right case. The
//! timeout of a case runs from the answer to the previous case (or from the hello), so a
//! candidate that is merely busy on earlier cases is never charged for them.
//!
//! What a session promises:
//! - **A strict protocol** ([`Session::run`]): every stdout line is judged against the case
//!   waited for; a malformed answer, an answer with an id in no request, an answer for a later
//!   request or an oversize line makes that case a `protocol` error at once ([`Outcome::Protocol`]),
//!   without a restart; an answer for a case already settled is stray output of the waited one,
//!   which keeps waiting for its own id, so nothing shifts. The hello must say protocol 1 and
//!   name only known shapes ([`HarnessError::BadHello`] otherwise).
//! - **Caps on the harness's side**: lines are parsed on the reader thread and only capped text
//!   is queued ([`LINE_QUEUE`] lines); answer lines over [`MAX_LINE_BYTES`] are skipped, not
//!   kept; each error field is cut to 4 KiB and, past [`RUN_DETAIL_BYTES`] per session, to
//!   [`SMALL_ERROR_BYTES`] without traceback; stray lines are quoted briefly, 8 per case and
//!   [`RUN_JUNK_BYTES`] per session; stderr keeps its last [`STDERR_TAIL_BYTES`].
//! - **A time budget** ([`RunOptions::budget`]): past it the cases not answered are `not_run`
//!   with the reason, and the candidate is killed; a restart's hello ends with it too, so a
//!   candidate that is slow to start and dies on every case costs the budget, not more.
//! - **Short failure messages**: why the candidate could not start quotes at most
//!   [`STDERR_EXCERPT_CHARS`] of its stderr (the message is repeated for every case it costs, so
//!   a candidate flooding stderr cannot make a report of megabytes).

use std::collections::{BTreeMap, HashMap, VecDeque};
use std::ffi::OsString;
use std::io::{BufRead, BufReader, Read, Write};
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdout, ExitStatus, Stdio};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender, SyncSender};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use super::protocol::{
    Answer, CandidateError, HELLO_LINE, Hello, MAX_QUOTE_CHARS, ParsedLine, Request, parse_line,
    quote_line,
};
use crate::oracle::vectors::{Case, ShapeKind};
use crate::sandbox::{Reaper, Sandbox, SandboxError, SandboxFacts, SandboxPolicy};

/// The name the course adapter has in the sandbox folder.
const ADAPTER_NAME: &str = "course_adapter.py";

/// The name the course adapter is given (`--name`): neutral, so the code inside learns nothing
/// of where the grader keeps the submission; reports use the harness's own label.
const NEUTRAL_NAME: &str = "python-course";

/// Largest submission file copied into the sandbox.
pub const MAX_STAGED_FILE_BYTES: u64 = crate::sandbox::MAX_COPIED_FILE_BYTES;

/// Most bytes of submission files copied into the sandbox in all.
pub const MAX_STAGED_TOTAL_BYTES: u64 = 8 << 20;

/// Most submission files copied into the sandbox.
pub const MAX_STAGED_FILES: usize = 200;

/// Most files left out of the sandbox that its facts name (the rest are counted).
pub const MAX_SKIPPED_NAMED: usize = 20;

/// How many bytes of the candidate's stderr are kept for the report.
pub const STDERR_TAIL_BYTES: usize = 4096;

/// Characters of the candidate's stderr quoted in a start failure's message (its last lines).
pub const STDERR_EXCERPT_CHARS: usize = 300;

/// Longest answer line accepted: a longer one is a protocol error of the case waiting, and is
/// skipped up to its newline without being kept (only its first bytes are quoted).
pub const MAX_LINE_BYTES: usize = 1 << 20;

/// Lines read ahead of the session. Each holds at most a few capped texts (see
/// [`parse_line`]), so what is queued stays within a few tens of MB however big the lines.
pub const LINE_QUEUE: usize = 1024;

/// Bytes of candidate text (error types, messages, tracebacks) kept over one session: past
/// it, each error keeps [`SMALL_ERROR_BYTES`] of each field and no traceback.
pub const RUN_DETAIL_BYTES: usize = 256 * 1024;

/// What each error field keeps once [`RUN_DETAIL_BYTES`] are used up.
pub const SMALL_ERROR_BYTES: usize = 200;

/// Bytes of stray output quoted over one session; past it stray lines are counted, not kept.
pub const RUN_JUNK_BYTES: usize = 64 * 1024;

/// The embedded adapter for the course's Python API.
pub const PYTHON_COURSE_ADAPTER: &str = include_str!("python_course.py");

/// How a candidate is run.
#[derive(Clone, Debug, PartialEq)]
pub struct RunOptions {
    /// Time allowed for one case, counted from the answer to the previous one.
    pub timeout: Duration,
    /// Time allowed for starting and answering the hello (imports happen here).
    pub hello_timeout: Duration,
    /// After this many timeouts in a shape group the rest of the group is not run.
    pub max_timeouts_per_group: u32,
    /// After this many crashes in a shape group the rest of the group is not run.
    pub max_crashes_per_group: u32,
    /// The sandbox's limits and switches.
    pub limits: SandboxPolicy,
    /// Wall time allowed for the whole session (the hello and every case, restarts included):
    /// past it the cases not yet answered are `not_run` with the reason. `None`: no limit.
    pub budget: Option<Duration>,
}

impl Default for RunOptions {
    fn default() -> Self {
        RunOptions {
            timeout: Duration::from_secs(2),
            hello_timeout: Duration::from_secs(10),
            max_timeouts_per_group: 3,
            max_crashes_per_group: 50,
            limits: SandboxPolicy::default(),
            budget: None,
        }
    }
}

/// What the harness got for one case.
#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    /// An answer line with the case's id; `junk` holds the non-answer lines printed while the
    /// case ran (a protocol error when not empty).
    Answered {
        /// The answer.
        answer: Answer,
        /// Stray output before the answer.
        junk: Vec<String>,
    },
    /// A line that is not a valid answer to this case's request (a malformed answer, an answer
    /// with another id, an oversize line): a protocol error, decided when the line arrived.
    Protocol {
        /// What was wrong, with the line quoted.
        message: String,
        /// Stray output before it.
        junk: Vec<String>,
    },
    /// No answer within the timeout: the candidate was killed and restarted.
    Timeout {
        /// Stray output while waiting.
        junk: Vec<String>,
    },
    /// The candidate's process died (or could not be restarted) on this case.
    Died {
        /// How it died.
        message: String,
        /// Stray output before it died.
        junk: Vec<String>,
    },
    /// The case was not sent: unsupported shape, or its group used up its timeouts.
    NotRun {
        /// Why.
        reason: String,
    },
}

/// Why the harness itself cannot run a candidate.
#[derive(Debug, thiserror::Error)]
pub enum HarnessError {
    /// The program could not be started.
    // Reasons are in the messages, not `#[source]`s, so a report of the whole chain prints each
    // once.
    #[error("cannot start the candidate {program}: {reason}")]
    Spawn {
        /// The program.
        program: String,
        /// Why.
        reason: std::io::Error,
    },
    /// The candidate did not complete the hello.
    #[error("the candidate {program} did not answer the hello: {message}")]
    Hello {
        /// The program.
        program: String,
        /// What happened, with the end of its stderr.
        message: String,
    },
    /// The candidate's hello cannot be accepted (another protocol version, an unknown shape).
    #[error("the candidate {program} cannot be checked: {problem}")]
    BadHello {
        /// The program.
        program: String,
        /// What is wrong with its hello.
        problem: String,
    },
    /// The adapter command line is unusable.
    #[error("the adapter command {command:?} {problem}")]
    Command {
        /// The command line.
        command: String,
        /// What is wrong.
        problem: String,
    },
    /// The submission folder is unusable.
    #[error("{path}: {problem}")]
    Submission {
        /// The folder.
        path: String,
        /// What is wrong.
        problem: String,
    },
    /// No usable Python interpreter (the message says which were tried and how to fix it).
    #[error("{0}")]
    Python(String),
    /// No sandbox may be made here: untrusted code is not run (fail closed).
    #[error("{0}")]
    Sandbox(#[from] SandboxError),
    /// An I/O error of the harness (temporary files, pipes).
    #[error("{context}: {reason}")]
    Io {
        /// What the harness was doing.
        context: String,
        /// Why it failed.
        reason: std::io::Error,
    },
}

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
    submission: Option<PathBuf>,
    /// Whether the bundled course adapter is written into the sandbox folder.
    course_adapter: bool,
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
    /// interpreter is [`python::choose`](super::python::choose)'s (with numpy and Pillow, runnable
    /// in the sandbox). The top-level `.py` files of `dir` are copied into the sandbox folder when
    /// the session starts, and the adapter imports them from there. Anything the submission
    /// prints is a protocol error of its case.
    pub fn python_course(dir: &Path) -> Result<Self, HarnessError> {
        Self::python_course_with(dir, None, false)
    }

    /// [`CandidateCommand::python_course`] with a chosen interpreter (`None`: as there; a given one
    /// is used as it is, so probe it first with [`python::choose`](super::python::choose)), and with
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
            None => super::python::choose(
                None,
                &super::python::default_requires(),
                &SandboxPolicy::default(),
            )
            .map_err(|e| match e {
                super::python::PythonError::Sandbox(e) => HarnessError::Sandbox(e),
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
            if !name.ends_with(".py") || name == ADAPTER_NAME {
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
    fn sandbox(&self, policy: SandboxPolicy) -> Result<Sandbox, HarnessError> {
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
        } else {
            let found = if self.program.components().count() > 1 {
                self.program.exists()
            } else {
                std::env::split_paths(crate::sandbox::SANDBOX_PATH)
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
            if sandbox.isolation() != crate::sandbox::Isolation::Unsandboxed {
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

/// The last bytes of a stream.
#[derive(Debug, Default)]
struct Tail(VecDeque<u8>);

impl Tail {
    fn push(&mut self, bytes: &[u8]) {
        let bytes = &bytes[bytes.len().saturating_sub(STDERR_TAIL_BYTES)..];
        let over = (self.0.len() + bytes.len()).saturating_sub(STDERR_TAIL_BYTES);
        self.0.drain(..over);
        self.0.extend(bytes);
    }
}

/// What the reader thread passes on: each stdout line parsed (and capped) on that thread.
enum Line {
    Parsed(ParsedLine),
    /// A line longer than [`MAX_LINE_BYTES`]: its first characters, quoted.
    Oversize(String),
    Eof,
}

/// One running child process.
struct Proc {
    child: Child,
    pid: i32,
    /// Ends every process the candidate started (its PID namespace or its uid).
    reaper: Reaper,
    /// Whether the child is bubblewrap, which exits `128 + N` when the candidate dies of signal
    /// `N`: such statuses are read back as the signal.
    bwrap: bool,
    writer: Option<Sender<Vec<u8>>>,
    lines: Receiver<Line>,
    stderr_done: std::thread::JoinHandle<()>,
}

impl Proc {
    fn spawn(
        command: &CandidateCommand,
        sandbox: &Sandbox,
        stderr: Arc<Mutex<Tail>>,
    ) -> Result<Proc, HarnessError> {
        let mut cmd = sandbox.command(&command.program);
        cmd.args(&command.args)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped());
        // Started and recorded under the gate, so an interruption's cleanup finds it.
        let gate = crate::interrupt::spawn_gate().ok_or_else(|| HarnessError::Spawn {
            program: command.program.display().to_string(),
            reason: std::io::Error::new(std::io::ErrorKind::Interrupted, "interrupted"),
        })?;
        let mut child = cmd.spawn().map_err(|reason| HarnessError::Spawn {
            program: command.program.display().to_string(),
            reason,
        })?;
        let pid = child.id() as i32;
        let reaper = sandbox.reaper();
        reaper.track(child.id());
        drop(gate);
        let stdin = child.stdin.take().expect("piped stdin");
        let stdout = child.stdout.take().expect("piped stdout");
        let mut err = child.stderr.take().expect("piped stderr");

        let (wtx, wrx) = mpsc::channel::<Vec<u8>>();
        std::thread::spawn(move || {
            let mut stdin = stdin;
            for buf in wrx {
                if stdin.write_all(&buf).is_err() {
                    break;
                }
            }
        });
        // Bounded: a candidate that floods stdout is slowed down, not buffered without end.
        let (ltx, lrx) = mpsc::sync_channel(LINE_QUEUE);
        std::thread::spawn(move || read_lines(stdout, ltx));
        let stderr_done = std::thread::spawn(move || {
            let mut buf = [0u8; 8192];
            loop {
                match err.read(&mut buf) {
                    Ok(0) => break,
                    Ok(n) => stderr
                        .lock()
                        .unwrap_or_else(|e| e.into_inner())
                        .push(&buf[..n]),
                    Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                    Err(_) => break,
                }
            }
        });
        Ok(Proc {
            child,
            pid,
            reaper,
            bwrap: sandbox.isolation() == crate::sandbox::Isolation::Bubblewrap,
            writer: Some(wtx),
            lines: lrx,
            stderr_done,
        })
    }

    fn send(&self, bytes: Vec<u8>) {
        if let Some(w) = &self.writer {
            let _ = w.send(bytes);
        }
    }

    /// Kills the whole process group and reaps the child; waits briefly for its stderr.
    fn kill(mut self) -> Option<ExitStatus> {
        self.writer = None;
        // SAFETY: plain system call; the child is not reaped yet, so its pid (= pgid) is ours.
        unsafe {
            libc::killpg(self.pid, libc::SIGKILL);
        }
        self.reaper.reap();
        let status = self.child.wait().ok().map(|s| self.through_bwrap(s));
        self.reaper.untrack(self.pid as u32);
        let until = Instant::now() + Duration::from_millis(200);
        while !self.stderr_done.is_finished() && Instant::now() < until {
            std::thread::sleep(Duration::from_millis(2));
        }
        status
    }

    /// The candidate's status from bubblewrap's: `128 + N` is death by signal `N`.
    fn through_bwrap(&self, status: ExitStatus) -> ExitStatus {
        match status.code() {
            Some(code) if self.bwrap && (129..160).contains(&code) => {
                ExitStatus::from_raw(code - 128)
            }
            _ => status,
        }
    }

    /// The exit status if the process has exited (after its stdout closed).
    fn exit_status(&mut self) -> Option<ExitStatus> {
        let until = Instant::now() + Duration::from_millis(500);
        loop {
            if let Ok(Some(status)) = self.child.try_wait() {
                self.reaper.untrack(self.pid as u32);
                return Some(self.through_bwrap(status));
            }
            if Instant::now() >= until {
                return None;
            }
            std::thread::sleep(Duration::from_millis(2));
        }
    }
}

impl Drop for Proc {
    fn drop(&mut self) {
        // SAFETY: as in `kill`; harmless if the group is already gone.
        unsafe {
            libc::killpg(self.pid, libc::SIGKILL);
        }
        self.reaper.reap();
        let _ = self.child.wait();
        self.reaper.untrack(self.pid as u32);
    }
}

fn read_lines(stdout: ChildStdout, tx: SyncSender<Line>) {
    let mut reader = BufReader::with_capacity(1 << 16, stdout);
    let mut line: Vec<u8> = Vec::new();
    // Set once the line in hand passed MAX_LINE_BYTES: the rest up to the newline is dropped.
    let mut oversize = false;
    let finish = |line: &[u8], oversize: bool| {
        let text = String::from_utf8_lossy(line);
        if oversize {
            Line::Oversize(quote_line(&text))
        } else {
            Line::Parsed(parse_line(&text))
        }
    };
    loop {
        let (done, used) = match reader.fill_buf() {
            Ok([]) => {
                if !line.is_empty() {
                    let _ = tx.send(finish(&line, oversize));
                }
                let _ = tx.send(Line::Eof);
                return;
            }
            Ok(buf) => {
                let (end, done) = match buf.iter().position(|&b| b == b'\n') {
                    Some(i) => (i, true),
                    None => (buf.len(), false),
                };
                let room = MAX_LINE_BYTES.saturating_sub(line.len());
                if end > room {
                    oversize = true;
                }
                // Only the start of an oversize line is kept, for the quotation.
                let keep = if oversize {
                    (4 * MAX_QUOTE_CHARS).saturating_sub(line.len())
                } else {
                    room
                };
                line.extend_from_slice(&buf[..end.min(keep)]);
                if oversize && line.len() > 4 * MAX_QUOTE_CHARS {
                    line.truncate(4 * MAX_QUOTE_CHARS);
                }
                (done, if done { end + 1 } else { end })
            }
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(_) => {
                let _ = tx.send(Line::Eof);
                return;
            }
        };
        reader.consume(used);
        if done {
            let item = finish(&line, oversize);
            line.clear();
            oversize = false;
            if tx.send(item).is_err() {
                return;
            }
        }
    }
}

fn describe_status(status: Option<ExitStatus>) -> String {
    match status {
        None => "its process closed its output".into(),
        Some(s) => match (s.code(), s.signal()) {
            (Some(code), _) => format!("its process exited with code {code}"),
            (_, Some(sig)) => {
                let name = match sig {
                    libc::SIGKILL => " (SIGKILL)",
                    libc::SIGSEGV => " (SIGSEGV)",
                    libc::SIGABRT => " (SIGABRT)",
                    libc::SIGXCPU => " (SIGXCPU: CPU time limit)",
                    libc::SIGXFSZ => " (SIGXFSZ: file size limit)",
                    libc::SIGTERM => " (SIGTERM)",
                    libc::SIGBUS => " (SIGBUS)",
                    _ => "",
                };
                format!("its process was killed by signal {sig}{name}")
            }
            _ => format!("its process ended ({s})"),
        },
    }
}

/// Most stray lines quoted for one case; the rest are counted.
const MAX_JUNK_LINES: usize = 8;

/// Records a stray line (already quoted and capped), keeping memory bounded however much a
/// candidate prints: at most [`MAX_JUNK_LINES`] per case and [`RUN_JUNK_BYTES`] per session
/// (`budget` holds what is left of it).
fn push_junk(junk: &mut Vec<String>, line: String, budget: &mut usize) {
    if junk.len() < MAX_JUNK_LINES && line.len() <= *budget {
        *budget -= line.len();
        junk.push(line);
    } else if junk.last().map(String::as_str) != Some(MORE_JUNK) {
        junk.push(MORE_JUNK.into());
    }
}

/// A line that is stray output where it came, in words.
fn describe_line(line: ParsedLine) -> String {
    match line {
        ParsedLine::Junk(text) => text,
        ParsedLine::Hello(_) => "another hello".into(),
        ParsedLine::BadHello(problem) => format!("a line like a hello ({problem})"),
        ParsedLine::Answer { id, .. } => format!("an answer for {}", quote_line(&id)),
        ParsedLine::Malformed { quoted, .. } => quoted,
    }
}

/// The last [`STDERR_EXCERPT_CHARS`] characters of `text`, with `...` before them when cut.
fn excerpt_end(text: &str) -> String {
    let count = text.chars().count();
    if count <= STDERR_EXCERPT_CHARS {
        return text.to_string();
    }
    let tail: String = text.chars().skip(count - STDERR_EXCERPT_CHARS).collect();
    format!("...{tail}")
}

/// The note that ends a case's stray lines when some were not kept.
const MORE_JUNK: &str = "(more lines not shown)";

/// A candidate process and its bookkeeping, restarted as needed.
///
/// Start and use a session on a thread that outlives it: on Linux the child gets `SIGKILL`
/// when the thread that spawned it exits (`PR_SET_PDEATHSIG`), which is what kills it when the
/// harness dies; restarts spawn from the thread calling [`Session::run`]. Dropping the session
/// kills the whole process group.
pub struct Session {
    command: CandidateCommand,
    options: RunOptions,
    proc: Option<Proc>,
    hello: Hello,
    stderr: Arc<Mutex<Tail>>,
    timeouts: BTreeMap<ShapeKind, u32>,
    crashes: BTreeMap<ShapeKind, u32>,
    exhausted: BTreeMap<ShapeKind, String>,
    restarts: u32,
    broken: Option<String>,
    sync: bool,
    sandbox: Sandbox,
    facts: Option<SandboxFacts>,
    /// When the session started (its time budget runs from here).
    started: Instant,
    /// Set when the time budget ran out: the reason given to every case not answered.
    budget_used: Option<String>,
    /// What is left of [`RUN_DETAIL_BYTES`].
    detail_left: usize,
    /// What is left of [`RUN_JUNK_BYTES`].
    junk_left: usize,
}

impl Session {
    /// Starts the candidate and does the hello. A hello failure is an error when
    /// [`CandidateCommand::hello_failure_is_fatal`], else every case will report it.
    pub fn start(command: CandidateCommand, options: RunOptions) -> Result<Session, HarnessError> {
        let sandbox = command.sandbox(options.limits.clone())?;
        let mut session = Session {
            command,
            options,
            proc: None,
            hello: Hello {
                name: String::new(),
                protocol: None,
                shapes: None,
                error: None,
            },
            stderr: Arc::new(Mutex::new(Tail::default())),
            timeouts: BTreeMap::new(),
            crashes: BTreeMap::new(),
            exhausted: BTreeMap::new(),
            restarts: 0,
            broken: None,
            sync: false,
            sandbox,
            facts: None,
            started: Instant::now(),
            budget_used: None,
            detail_left: RUN_DETAIL_BYTES,
            junk_left: RUN_JUNK_BYTES,
        };
        match session.launch()? {
            Ok(hello) => session.hello = hello,
            Err(message) => {
                if session.command.hello_failure_is_fatal {
                    return Err(HarnessError::Hello {
                        program: session.command.label.clone(),
                        message,
                    });
                }
                session.broken = Some(message);
            }
        }
        if session.hello.name.is_empty() || session.command.course_adapter {
            // The course adapter was told a neutral name; reports use the real label.
            session.hello.name = session.command.label.clone();
        }
        crate::sandbox::announce(&session.sandbox_facts());
        Ok(session)
    }

    /// The candidate's hello (its name, shapes and any import error).
    pub fn hello(&self) -> &Hello {
        &self.hello
    }

    /// Why the candidate could not be started, when it could not (every case then died).
    pub fn start_failure(&self) -> Option<&str> {
        self.broken.as_deref()
    }

    /// The last [`STDERR_TAIL_BYTES`] bytes the candidate wrote to stderr, over all restarts.
    pub fn stderr_tail(&self) -> String {
        let tail = self.stderr.lock().unwrap_or_else(|e| e.into_inner());
        let (a, b) = tail.0.as_slices();
        String::from_utf8_lossy(&[a, b].concat()).into_owned()
    }

    /// How many times the candidate was restarted.
    pub fn restarts(&self) -> u32 {
        self.restarts
    }

    /// The command being run.
    pub fn command(&self) -> &CandidateCommand {
        &self.command
    }

    /// What the sandbox did: limits, the isolation, the uid the candidate ran as (and a note on
    /// why not a stronger isolation), and the namespaces its first process was seen in.
    pub fn sandbox_facts(&self) -> SandboxFacts {
        self.facts
            .clone()
            .unwrap_or_else(|| self.sandbox.facts(None))
    }

    /// The sandbox's folder as the harness sees it.
    pub fn sandbox_dir(&self) -> &Path {
        self.sandbox.dir()
    }

    /// The sandbox's folder as the candidate sees it (`/sandbox` under bubblewrap; file names
    /// in its tracebacks start here).
    pub fn sandbox_inside_dir(&self) -> PathBuf {
        self.sandbox.inside_dir()
    }

    /// Names the submission's own files in a candidate's error: the course adapter runs a copy
    /// of them in the sandbox folder, so its tracebacks say `<sandbox>/sphere.py` where the
    /// student's file is `<submission>/sphere.py`.
    fn localise(&self, error: &mut CandidateError) {
        let Some(submission) = &self.command.submission else {
            return;
        };
        let dir = self.sandbox.dir();
        let inside = self.sandbox.inside_dir();
        if inside != dir {
            let to = submission.display().to_string();
            for text in [&mut error.message, &mut error.traceback] {
                *text = crate::sandbox::replace_path(text, &inside, &to);
            }
        }
        let mut seen = vec![dir.to_path_buf()];
        if let Ok(real) = dir.canonicalize() {
            seen.push(real);
        }
        // The longer first, in case one is inside the other (`/private/tmp/x` and `/tmp/x`).
        seen.sort_by_key(|p| std::cmp::Reverse(p.as_os_str().len()));
        seen.dedup();
        for from in seen {
            let (from, to) = (from.display().to_string(), submission.display().to_string());
            for text in [&mut error.message, &mut error.traceback] {
                if text.contains(&from) {
                    *text = text.replace(&from, &to);
                }
            }
        }
    }

    /// How the candidate's process ended: the sandbox's reason when it stopped the code, else
    /// the exit status in words.
    fn describe_end(&self, status: Option<ExitStatus>) -> String {
        self.sandbox
            .violation()
            .unwrap_or_else(|| describe_status(status))
    }

    /// Spawns and does the hello: `Ok(Err(message))` when the hello failed (or the sandbox has
    /// stopped the code for good).
    fn launch(&mut self) -> Result<Result<Hello, String>, HarnessError> {
        if let Some(violation) = self.sandbox.violation() {
            return Ok(Err(violation));
        }
        let proc = Proc::spawn(&self.command, &self.sandbox, self.stderr.clone())?;
        if self.facts.is_none() {
            self.facts = Some(self.sandbox.facts(Some(proc.pid as u32)));
        }
        proc.send(format!("{HELLO_LINE}\n").into_bytes());
        // A restart's hello ends with the budget too, so the budget bounds the whole session.
        let by_hello = Instant::now() + self.options.hello_timeout;
        let (deadline, by_budget) = match self.budget_deadline() {
            Some(b) if b < by_hello => (b, true),
            _ => (by_hello, false),
        };
        let mut junk = Vec::new();
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            // Checked here too: a candidate printing without pause always has a line ready.
            let next = if left.is_zero() {
                Err(RecvTimeoutError::Timeout)
            } else {
                proc.lines.recv_timeout(left)
            };
            match next {
                Ok(Line::Parsed(ParsedLine::Hello(mut hello))) => {
                    if let Err(problem) = hello.check() {
                        let _ = proc.kill();
                        return Err(HarnessError::BadHello {
                            program: self.command.label.clone(),
                            problem,
                        });
                    }
                    self.proc = Some(proc);
                    if let Some(error) = &mut hello.error {
                        self.localise(error);
                    }
                    return Ok(Ok(hello));
                }
                Ok(Line::Parsed(ParsedLine::BadHello(problem))) => {
                    let _ = proc.kill();
                    return Err(HarnessError::BadHello {
                        program: self.command.label.clone(),
                        problem,
                    });
                }
                Ok(Line::Parsed(other)) => {
                    push_junk(&mut junk, describe_line(other), &mut self.junk_left)
                }
                Ok(Line::Oversize(head)) => push_junk(&mut junk, head, &mut self.junk_left),
                Ok(Line::Eof) | Err(RecvTimeoutError::Disconnected) => {
                    let mut proc = proc;
                    let status = proc.exit_status();
                    let _ = proc.kill();
                    return Ok(Err(self.failure_message(self.describe_end(status), &junk)));
                }
                Err(RecvTimeoutError::Timeout) => {
                    let _ = proc.kill();
                    if by_budget {
                        self.check_budget();
                    }
                    let what = match &self.budget_used {
                        Some(reason) if by_budget => reason.clone(),
                        _ => format!(
                            "no hello answer within {:.1} s",
                            self.options.hello_timeout.as_secs_f64()
                        ),
                    };
                    return Ok(Err(self.failure_message(what, &junk)));
                }
            }
        }
    }

    fn failure_message(&self, what: String, junk: &[String]) -> String {
        let mut message = what;
        if !junk.is_empty() {
            message.push_str(&format!("; it printed {}", junk.join(", ")));
        }
        let tail = self.stderr_tail();
        let tail = tail.trim();
        if !tail.is_empty() {
            let last: Vec<&str> = tail.lines().rev().take(3).collect();
            let last: Vec<&str> = last.into_iter().rev().collect();
            message.push_str(&format!(
                "; stderr ends: {}",
                excerpt_end(&last.join(" | "))
            ));
        }
        if let Some(hint) = self
            .sandbox
            .view_hint(tail)
            .filter(|_| !self.command.course_adapter)
        {
            message.push_str("; ");
            message.push_str(&hint);
        }
        message
    }

    /// Runs `cases` in order and returns one outcome per case.
    pub fn run(&mut self, cases: &[Case]) -> Result<Vec<Outcome>, HarnessError> {
        let mut outcomes: Vec<Option<Outcome>> = vec![None; cases.len()];
        for (i, case) in cases.iter().enumerate() {
            let kind = case.shape.kind();
            if !self.hello.supports(kind) && self.broken.is_none() {
                outcomes[i] = Some(Outcome::NotRun {
                    reason: format!("the candidate does not support {kind}s"),
                });
            }
        }
        let lines: Vec<Option<String>> = cases
            .iter()
            .zip(&outcomes)
            .map(|(c, o)| {
                o.is_none()
                    .then(|| format!("{}\n", Request::for_case(c).to_line()))
            })
            .collect();
        // Where each id is (the first case with it), to tell late, early and unknown answers.
        let mut index: HashMap<&str, usize> = HashMap::with_capacity(cases.len());
        for (i, case) in cases.iter().enumerate() {
            index.entry(case.id.as_str()).or_insert(i);
        }
        loop {
            self.check_budget();
            // Cases still to run, skipping exhausted groups.
            let mut pending = Vec::new();
            for (i, case) in cases.iter().enumerate() {
                if outcomes[i].is_some() {
                    continue;
                }
                if let Some(reason) = &self.budget_used {
                    outcomes[i] = Some(Outcome::NotRun {
                        reason: reason.clone(),
                    });
                } else if let Some(reason) = self.exhausted.get(&case.shape.kind()) {
                    outcomes[i] = Some(Outcome::NotRun {
                        reason: reason.clone(),
                    });
                } else {
                    pending.push(i);
                }
            }
            if pending.is_empty() {
                break;
            }
            if let Some(message) = &self.broken {
                for i in pending {
                    outcomes[i] = Some(Outcome::Died {
                        message: message.clone(),
                        junk: Vec::new(),
                    });
                }
                break;
            }
            if self.proc.is_none() {
                self.restarts += 1;
                match self.launch()? {
                    Ok(_) => {}
                    Err(message) => {
                        self.broken = Some(format!("could not restart the candidate: {message}"));
                        continue;
                    }
                }
            }
            let proc = self.proc.as_ref().expect("a running candidate");
            let mut bytes = Vec::with_capacity(pending.len() * 210);
            for &i in &pending {
                let line = lines[i].as_deref().unwrap_or("");
                if self.sync {
                    // `{"sync":true,` + the rest of the request.
                    bytes.extend_from_slice(b"{\"sync\":true,");
                    bytes.extend_from_slice(&line.as_bytes()[1..]);
                } else {
                    bytes.extend_from_slice(line.as_bytes());
                }
            }
            proc.send(bytes);
            self.collect(cases, &pending, &mut outcomes, &index);
        }
        Ok(outcomes
            .into_iter()
            .map(|o| o.expect("every case has an outcome"))
            .collect())
    }

    /// When the time budget runs out, if there is one.
    fn budget_deadline(&self) -> Option<Instant> {
        self.options.budget.map(|b| self.started + b)
    }

    /// Marks the budget used up when its deadline has passed (and kills the candidate).
    fn check_budget(&mut self) {
        if self.budget_used.is_some() {
            return;
        }
        if let (Some(deadline), Some(budget)) = (self.budget_deadline(), self.options.budget) {
            if Instant::now() >= deadline {
                self.budget_used = Some(format!(
                    "the submission's {} s budget for code checks was used up",
                    budget.as_secs_f64()
                ));
                if let Some(proc) = self.proc.take() {
                    let _ = proc.kill();
                }
            }
        }
    }

    /// Whether the time budget ran out (the cases not answered by then are `not_run`).
    pub fn budget_used_up(&self) -> Option<&str> {
        self.budget_used.as_deref()
    }

    /// An answer as the session keeps it: the error's tracebacks renamed to the submission's
    /// files, its fields capped further once the session's [`RUN_DETAIL_BYTES`] are used up.
    fn keep(&mut self, mut answer: Answer) -> Answer {
        if let Some(error) = answer.error.take() {
            let mut error = if self.detail_left == 0 {
                let mut e = error.capped_to(SMALL_ERROR_BYTES);
                e.traceback.clear();
                e
            } else {
                error
            };
            self.localise(&mut error);
            self.detail_left = self.detail_left.saturating_sub(error.text_len());
            answer.error = Some(error);
        }
        answer
    }

    /// Reads the answers to `pending`, in order, until all are in or the process is lost.
    ///
    /// A candidate may batch its answers unless asked to flush each (`"sync": true`). So the
    /// first death or timeout records nothing: the answers it had not written died with it
    /// and the real culprit may be a later case. The session switches to sync mode and the
    /// cases are run again from the one it was waiting for; from then on the case waited for
    /// is the one blamed.
    ///
    /// Every line is judged against the case waited for (the strict protocol):
    /// - its valid answer settles it; stray lines before it make it a `protocol` error;
    /// - a malformed answer carrying its id (or no id), an answer with an id that is not in
    ///   the run, or an oversize line settle it at once as a `protocol` error;
    /// - an answer for a case already settled (late, or a duplicate) is stray output of the
    ///   case waited for, which keeps waiting for its own answer;
    /// - an answer for a later case settles the waited case as a `protocol` error (answers
    ///   come in request order) and is kept for that later case.
    fn collect(
        &mut self,
        cases: &[Case],
        pending: &[usize],
        outcomes: &mut [Option<Outcome>],
        index: &HashMap<&str, usize>,
    ) {
        let timeout = self.options.timeout;
        let mut last = Instant::now();
        let mut early: HashMap<usize, Outcome> = HashMap::new();
        for &i in pending {
            let case = &cases[i];
            if let Some(outcome) = early.remove(&i) {
                outcomes[i] = Some(outcome);
                continue;
            }
            let mut junk: Vec<String> = Vec::new();
            loop {
                let case_deadline = last + timeout;
                let (until, by_budget) = match self.budget_deadline() {
                    Some(b) if b < case_deadline => (b, true),
                    _ => (case_deadline, false),
                };
                let proc = self.proc.as_mut().expect("a running candidate");
                let left = until.saturating_duration_since(Instant::now());
                let next = if left.is_zero() {
                    Err(RecvTimeoutError::Timeout)
                } else {
                    proc.lines.recv_timeout(left)
                };
                let protocol =
                    |message: String, junk: Vec<String>| Outcome::Protocol { message, junk };
                match next {
                    Ok(Line::Parsed(parsed)) => match parsed {
                        ParsedLine::Answer {
                            id,
                            answer,
                            junk: prefix,
                        } if id == case.id => {
                            if !prefix.is_empty() {
                                push_junk(&mut junk, prefix, &mut self.junk_left);
                            }
                            let answer = self.keep(answer);
                            outcomes[i] = Some(Outcome::Answered { answer, junk });
                            last = Instant::now();
                            break;
                        }
                        ParsedLine::Malformed {
                            id,
                            problem,
                            quoted,
                        } if id.is_none() || id.as_deref() == Some(case.id.as_str()) => {
                            let message =
                                format!("a malformed answer ({problem}): the line was {quoted}");
                            outcomes[i] = Some(protocol(message, junk));
                            last = Instant::now();
                            break;
                        }
                        ParsedLine::Answer { id, .. }
                        | ParsedLine::Malformed { id: Some(id), .. }
                            if index
                                .get(id.as_str())
                                .is_some_and(|&k| outcomes[k].is_some()) =>
                        {
                            let line = format!("a second answer for {}", quote_line(&id));
                            push_junk(&mut junk, line, &mut self.junk_left);
                        }
                        ParsedLine::Answer {
                            id,
                            answer,
                            junk: prefix,
                        } if index.get(id.as_str()).is_some_and(|&k| k > i) => {
                            let k = index[id.as_str()];
                            let mut later_junk = Vec::new();
                            if !prefix.is_empty() {
                                push_junk(&mut later_junk, prefix, &mut self.junk_left);
                            }
                            let answer = self.keep(answer);
                            early.insert(
                                k,
                                Outcome::Answered {
                                    answer,
                                    junk: later_junk,
                                },
                            );
                            let message = format!(
                                "no answer to this request before the answer for the later \
                                 request {} (answers come in request order)",
                                quote_line(&id)
                            );
                            outcomes[i] = Some(protocol(message, junk));
                            last = Instant::now();
                            break;
                        }
                        ParsedLine::Answer { id, answer, .. } => {
                            let line = serde_json::to_string(&answer).unwrap_or_default();
                            let message = format!(
                                "an answer with id {} instead of {}: {}",
                                quote_line(&id),
                                quote_line(&case.id),
                                quote_line(&line)
                            );
                            outcomes[i] = Some(protocol(message, junk));
                            last = Instant::now();
                            break;
                        }
                        ParsedLine::Malformed {
                            id: Some(id),
                            problem,
                            quoted,
                        } => {
                            let message = format!(
                                "a malformed answer with id {} instead of {} ({problem}): the \
                                 line was {quoted}",
                                quote_line(&id),
                                quote_line(&case.id)
                            );
                            outcomes[i] = Some(protocol(message, junk));
                            last = Instant::now();
                            break;
                        }
                        other => {
                            push_junk(&mut junk, describe_line(other), &mut self.junk_left);
                        }
                    },
                    Ok(Line::Oversize(head)) => {
                        let message = format!(
                            "a line longer than {} MiB (answer lines are at most that): it \
                             began {head}",
                            MAX_LINE_BYTES >> 20
                        );
                        outcomes[i] = Some(protocol(message, junk));
                        last = Instant::now();
                        break;
                    }
                    Ok(Line::Eof) | Err(RecvTimeoutError::Disconnected) => {
                        let mut proc = self.proc.take().expect("a running candidate");
                        let status = proc.exit_status();
                        let _ = proc.kill();
                        if !self.sync {
                            self.sync = true;
                            return;
                        }
                        let message = format!(
                            "the candidate died on this case: {}",
                            self.describe_end(status)
                        );
                        outcomes[i] = Some(Outcome::Died { message, junk });
                        self.count(CountKind::Crash, case.shape.kind());
                        return;
                    }
                    Err(RecvTimeoutError::Timeout) if by_budget => {
                        self.check_budget();
                        return;
                    }
                    Err(RecvTimeoutError::Timeout) => {
                        let proc = self.proc.take().expect("a running candidate");
                        let _ = proc.kill();
                        if !self.sync {
                            self.sync = true;
                            return;
                        }
                        outcomes[i] = Some(Outcome::Timeout { junk });
                        self.count(CountKind::Timeout, case.shape.kind());
                        return;
                    }
                }
            }
        }
    }

    fn count(&mut self, what: CountKind, kind: ShapeKind) {
        let (map, max, noun) = match what {
            CountKind::Timeout => (
                &mut self.timeouts,
                self.options.max_timeouts_per_group,
                "timeouts",
            ),
            CountKind::Crash => (
                &mut self.crashes,
                self.options.max_crashes_per_group,
                "crashes",
            ),
        };
        let n = map.entry(kind).or_insert(0);
        *n += 1;
        if *n >= max {
            self.exhausted
                .entry(kind)
                .or_insert_with(|| format!("not run after {max} {noun} in the {kind} group"));
        }
    }
}

enum CountKind {
    Timeout,
    Crash,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A submission whose import writes a file into its working folder and reports who and
    /// where it is on stderr.
    fn nosy_submission() -> tempfile::TempDir {
        let dir = super::super::bench::assemble_fixture("honest_reference").unwrap();
        let object = dir.path().join("RT_object.py");
        let mut text = std::fs::read_to_string(&object).unwrap();
        text.push_str(
            "\nimport os, sys\nopen('written-by-import', 'w').write('x')\n\
             print('uid', os.getuid(), 'cwd', os.getcwd(), 'home', os.environ.get('HOME'), file=sys.stderr)\n",
        );
        std::fs::write(&object, text).unwrap();
        dir
    }

    #[test]
    fn the_course_adapter_runs_on_a_copy_in_the_sandbox_as_the_sandbox_user() {
        let sub = nosy_submission();
        // /usr/bin/python3 can be run by a sandbox user; elsewhere the chosen interpreter.
        let system = Path::new("/usr/bin/python3");
        let python = system.is_file().then_some(system);
        let command = CandidateCommand::python_course_with(sub.path(), python, true).unwrap();
        let mut session = Session::start(command, RunOptions::default()).unwrap();
        let cases: Vec<Case> = crate::oracle::default_suite(0)
            .into_iter()
            .filter(|c| c.shape.kind() == ShapeKind::Sphere)
            .collect();
        let report = super::super::check_session(&mut session, &cases).unwrap();
        assert!(report.passed(), "{}", report.to_text(3));
        let dir = session.sandbox_dir().canonicalize().unwrap();
        let inside = session.sandbox_inside_dir();
        let inside = inside.canonicalize().unwrap_or(inside);
        let tail = session.stderr_tail();
        // It ran in the sandbox folder, with HOME there, and wrote there, not in the submission.
        assert!(
            tail.contains(&format!(
                "cwd {} home {}",
                inside.display(),
                inside.display()
            )),
            "{tail}"
        );
        assert!(dir.join("written-by-import").is_file());
        assert!(!sub.path().join("written-by-import").exists());
        let facts = session.sandbox_facts();
        assert_eq!(report.sandbox.as_ref(), Some(&facts));
        assert!(tail.contains(&format!("uid {} ", facts.uid)), "{tail}");
        if crate::sandbox::running_as_root() {
            // Never root, and a uid of its own.
            assert!(facts.uid >= 1 << 30, "{facts:?}");
        }
        if facts.isolation == crate::sandbox::Isolation::Bubblewrap {
            assert_eq!(facts.network_isolated, Some(true), "{facts:?}");
        }
        // The adapter was told a neutral name; the report keeps the real label.
        assert!(report.candidate.contains(&sub.path().display().to_string()));
        drop(session);
        assert!(
            !dir.exists(),
            "the sandbox folder is removed with the session"
        );
    }

    /// An adapter in a folder the sandbox user may read, run by `/usr/bin/python3`.
    fn python_adapter(script: &str) -> Option<(tempfile::TempDir, CandidateCommand)> {
        if !Path::new("/usr/bin/python3").is_file() {
            eprintln!("skipped: no /usr/bin/python3");
            return None;
        }
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        std::fs::set_permissions(dir.path(), std::fs::Permissions::from_mode(0o755)).unwrap();
        let path = dir.path().join("adapter.py");
        std::fs::write(&path, script).unwrap();
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o644)).unwrap();
        let command = CandidateCommand::adapter(&format!("/usr/bin/python3 {}", path.display()));
        Some((dir, command.unwrap()))
    }

    /// A candidate that starts quickly once, then takes far longer than the budget to say hello
    /// on every restart, and dies on every request: it costs the budget, not the budget plus a
    /// last hello, because a restart's hello ends with the budget.
    ///
    /// The restart's hello (30 s) dwarfs the budget (5 s), so the bound below holds however
    /// loaded the machine is: only the missing clamp can cross it. (An earlier version slept
    /// 0.9 s on every start and failed on a loaded CI machine whose first start alone passed 2 s.)
    #[test]
    fn a_restart_s_hello_ends_when_the_budget_does() {
        let Some((_dir, command)) = python_adapter(
            "import os, sys, time\nsys.stdin.readline()\n\
             marker = os.path.join(os.getcwd(), 'started-once')\n\
             if os.path.exists(marker):\n    time.sleep(30)\n\
             open(marker, 'w').close()\n\
             print('{\"name\":\"slow\",\"protocol\":1}', flush=True)\n\
             sys.stdin.readline()\nsys.exit(3)\n",
        ) else {
            return;
        };
        let options = RunOptions {
            hello_timeout: Duration::from_secs(60),
            max_crashes_per_group: 1000,
            budget: Some(Duration::from_secs(5)),
            ..RunOptions::default()
        };
        let cases: Vec<Case> = crate::oracle::default_suite(0)
            .into_iter()
            .filter(|c| c.shape.kind() == ShapeKind::Sphere)
            .take(50)
            .collect();
        let start = Instant::now();
        let mut session = Session::start(command, options).unwrap();
        let outcomes = session.run(&cases).unwrap();
        let took = start.elapsed();
        assert!(session.budget_used_up().is_some());
        assert!(
            outcomes
                .iter()
                .any(|o| matches!(o, Outcome::NotRun { reason } if reason.contains("budget")))
        );
        // Without the clamp the restart's hello runs its 30 s.
        assert!(took < Duration::from_secs(20), "{took:?}");
    }

    /// A candidate that floods stderr with long lines and never says hello: the message every
    /// case gets quotes a short excerpt of its stderr (the whole 4 KiB tail made `check --json`
    /// 17.8 MB for the 2950 cases of the default suite).
    #[test]
    fn a_start_failure_quotes_little_of_a_flooded_stderr() {
        let Some((_dir, command)) = python_adapter(
            "import sys, time\nfor i in range(3000):\n    sys.stderr.write('e' * 700 + '\\n')\n\
             sys.stderr.flush()\ntime.sleep(30)\n",
        ) else {
            return;
        };
        let command = CandidateCommand {
            hello_failure_is_fatal: false,
            ..command
        };
        let options = RunOptions {
            hello_timeout: Duration::from_millis(1500),
            ..RunOptions::default()
        };
        let session = Session::start(command, options).unwrap();
        let message = session.start_failure().unwrap().to_string();
        assert!(
            message.starts_with("no hello answer within 1.5 s"),
            "{message}"
        );
        assert!(message.contains("stderr ends: "), "{message}");
        assert!(message.len() < 500, "{} bytes: {message}", message.len());
    }

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

    #[test]
    fn stray_output_is_quoted_briefly_and_bounded() {
        let mut junk = Vec::new();
        let mut left = RUN_JUNK_BYTES;
        for _ in 0..1000 {
            push_junk(&mut junk, quote_line(&"x".repeat(10_000)), &mut left);
        }
        assert_eq!(junk.len(), MAX_JUNK_LINES + 1);
        assert_eq!(junk[0].len(), MAX_QUOTE_CHARS + 5);
        assert_eq!(junk[MAX_JUNK_LINES], MORE_JUNK);
        // Over a session: once the total is used up, lines are only counted.
        let mut left = 3 * (MAX_QUOTE_CHARS + 5);
        let mut kept = 0;
        for _ in 0..100 {
            let mut junk = Vec::new();
            push_junk(&mut junk, quote_line(&"y".repeat(500)), &mut left);
            kept += (junk[0] != MORE_JUNK) as usize;
        }
        assert_eq!(kept, 3);
    }

    #[test]
    fn the_stderr_tail_keeps_the_last_bytes() {
        let mut t = Tail::default();
        t.push(&[b'a'; 3000]);
        t.push(&[b'b'; 3000]);
        assert_eq!(t.0.len(), STDERR_TAIL_BYTES);
        assert_eq!(t.0.iter().filter(|&&b| b == b'b').count(), 3000);
        t.push(&[b'c'; 10000]);
        assert!(t.0.iter().all(|&b| b == b'c'));
    }
}
