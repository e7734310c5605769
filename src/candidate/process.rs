//! Running a candidate as a child process: spawn with limits, hello, pipelined requests,
//! per-case timeouts, restart after a crash, kill the whole process group on drop.
//!
//! The child runs in a fresh temporary working folder, in its own session and process group
//! (`setsid`), with a cleared environment (`PATH`, `LANG`, `LC_ALL`, `HOME` and `TMPDIR` set to
//! the working folder, `PYTHONIOENCODING=utf-8`, `PYTHONDONTWRITEBYTECODE=1`,
//! `PYTHONHASHSEED=0`), limits on CPU time, address space, open files and file size, no core
//! dumps, a new network namespace without any interface up where the harness may create one,
//! and `SIGKILL` when the harness thread that started it dies (Linux).
//!
//! Requests are pipelined: a writer thread writes every pending request as fast as the pipe
//! takes them while the session reads answers. Candidates may batch their answers; after the
//! first crash or timeout the session asks for one flush per answer (`"sync": true`) and runs
//! the cases again from the one it was waiting for, so blame always lands on the right case. The timeout of a case runs from the answer to the
//! previous case (or from the hello), so a candidate that is merely busy on earlier cases is
//! never charged for them.

use std::collections::{BTreeMap, VecDeque};
use std::ffi::OsString;
use std::io::{BufRead, BufReader, Read, Write};
use std::os::unix::process::{CommandExt, ExitStatusExt};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdout, Command, ExitStatus, Stdio};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender, SyncSender};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use super::protocol::{Answer, HELLO_LINE, Hello, ParsedLine, Request, parse_answer_line};
use crate::oracle::vectors::{Case, ShapeKind};

/// How many bytes of the candidate's stderr are kept for the report.
pub const STDERR_TAIL_BYTES: usize = 4096;

/// Longest stdout line kept (longer ones are truncated, so junk cannot fill memory).
const MAX_LINE_BYTES: usize = 1 << 20;

/// Longest piece of junk quoted in a report.
const JUNK_QUOTE: usize = 200;

/// The embedded adapter for the course's Python API.
pub const PYTHON_COURSE_ADAPTER: &str = include_str!("python_course.py");

/// Resource limits applied to the candidate with `setrlimit` before `exec`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// CPU seconds per process (a restart starts afresh).
    pub cpu_seconds: u64,
    /// Address space in bytes.
    pub memory_bytes: u64,
    /// Open file descriptors.
    pub open_files: u64,
    /// Largest file the candidate may write, in bytes.
    pub file_size_bytes: u64,
    /// Run the candidate in a new, empty network namespace (Linux, when the harness is
    /// allowed to create one: as root or with `CAP_SYS_ADMIN`; silently skipped otherwise).
    pub isolate_network: bool,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            cpu_seconds: 600,
            memory_bytes: 2 << 30,
            open_files: 64,
            file_size_bytes: 64 << 20,
            isolate_network: true,
        }
    }
}

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
    /// Resource limits.
    pub limits: Limits,
}

impl Default for RunOptions {
    fn default() -> Self {
        RunOptions {
            timeout: Duration::from_secs(2),
            hello_timeout: Duration::from_secs(10),
            max_timeouts_per_group: 3,
            max_crashes_per_group: 50,
            limits: Limits::default(),
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
    #[error("cannot start the candidate {program}: {source}")]
    Spawn {
        /// The program.
        program: String,
        /// Why.
        source: std::io::Error,
    },
    /// The candidate did not complete the hello.
    #[error("the candidate {program} did not answer the hello: {message}")]
    Hello {
        /// The program.
        program: String,
        /// What happened, with the end of its stderr.
        message: String,
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
    /// No usable Python interpreter.
    #[error("cannot find python3 to run the course adapter ({0}); set RTORACLE_PYTHON")]
    Python(String),
    /// An I/O error of the harness (temporary files, pipes).
    #[error("{context}: {source}")]
    Io {
        /// What the harness was doing.
        context: String,
        /// Why it failed.
        source: std::io::Error,
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
    /// Keeps the embedded adapter's temporary file alive.
    _files: Option<Arc<tempfile::TempDir>>,
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
            _files: None,
        })
    }

    /// The bundled adapter for the course's Python API run on the submission folder `dir`. The
    /// interpreter is `$RTORACLE_PYTHON` or `python3`, resolved once to its real path.
    pub fn python_course(dir: &Path) -> Result<Self, HarnessError> {
        if !dir.is_dir() {
            return Err(HarnessError::Submission {
                path: dir.display().to_string(),
                problem: "is not a folder (expected the submission folder holding RT_object.py)"
                    .into(),
            });
        }
        let dir = std::path::absolute(dir).map_err(|source| HarnessError::Io {
            context: dir.display().to_string(),
            source,
        })?;
        let python = resolve_python()?;
        let files = tempfile::Builder::new()
            .prefix("rtoracle-adapter-")
            .tempdir()
            .map_err(|source| HarnessError::Io {
                context: "creating a temporary folder for the adapter".into(),
                source,
            })?;
        let script = files.path().join("rtoracle_python_course.py");
        std::fs::write(&script, PYTHON_COURSE_ADAPTER).map_err(|source| HarnessError::Io {
            context: script.display().to_string(),
            source,
        })?;
        Ok(CandidateCommand {
            program: python,
            args: vec!["-I".into(), "-B".into(), script.into(), dir.clone().into()],
            label: format!("python-course {}", dir.display()),
            hello_failure_is_fatal: false,
            _files: Some(Arc::new(files)),
        })
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

fn resolve_python() -> Result<PathBuf, HarnessError> {
    let python = std::env::var_os("RTORACLE_PYTHON").unwrap_or_else(|| "python3".into());
    let out = Command::new(&python)
        .args(["-I", "-c", "import sys; print(sys.executable)"])
        .stdin(Stdio::null())
        .output()
        .map_err(|e| HarnessError::Python(format!("{}: {e}", python.to_string_lossy())))?;
    let path = String::from_utf8_lossy(&out.stdout).trim().to_string();
    if !out.status.success() || path.is_empty() {
        return Err(HarnessError::Python(format!(
            "{} exited with {}",
            python.to_string_lossy(),
            out.status
        )));
    }
    Ok(PathBuf::from(path))
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

enum Line {
    Text(String),
    Eof,
}

/// One running child process.
struct Proc {
    child: Child,
    pid: i32,
    writer: Option<Sender<Vec<u8>>>,
    lines: Receiver<Line>,
    stderr_done: std::thread::JoinHandle<()>,
    _workdir: tempfile::TempDir,
}

impl Proc {
    fn spawn(
        command: &CandidateCommand,
        limits: Limits,
        stderr: Arc<Mutex<Tail>>,
    ) -> Result<Proc, HarnessError> {
        let io = |context: &str| {
            let context = context.to_string();
            move |source| HarnessError::Io { context, source }
        };
        let workdir = tempfile::Builder::new()
            .prefix("rtoracle-run-")
            .tempdir()
            .map_err(io("creating the candidate's working folder"))?;
        let mut cmd = Command::new(&command.program);
        cmd.args(&command.args)
            .env_clear()
            .env(
                "PATH",
                std::env::var_os("PATH").unwrap_or_else(|| "/usr/local/bin:/usr/bin:/bin".into()),
            )
            .env("LANG", "C.UTF-8")
            .env("LC_ALL", "C.UTF-8")
            .env("HOME", workdir.path())
            .env("TMPDIR", workdir.path())
            .env("PYTHONIOENCODING", "utf-8")
            .env("PYTHONDONTWRITEBYTECODE", "1")
            .env("PYTHONHASHSEED", "0")
            .current_dir(workdir.path())
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped());
        // SAFETY: the closure only makes async-signal-safe system calls and allocates nothing.
        unsafe {
            cmd.pre_exec(move || {
                if libc::setsid() < 0 {
                    return Err(std::io::Error::last_os_error());
                }
                #[cfg(target_os = "linux")]
                {
                    libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL as libc::c_ulong);
                    if limits.isolate_network {
                        // No network: fails without privileges, which is fine.
                        libc::unshare(libc::CLONE_NEWNET);
                    }
                }
                let set = |resource, value: u64| {
                    let lim = libc::rlimit {
                        rlim_cur: value as libc::rlim_t,
                        rlim_max: value as libc::rlim_t,
                    };
                    libc::setrlimit(resource, &lim);
                };
                set(libc::RLIMIT_CPU, limits.cpu_seconds);
                set(libc::RLIMIT_AS, limits.memory_bytes);
                set(libc::RLIMIT_NOFILE, limits.open_files);
                set(libc::RLIMIT_FSIZE, limits.file_size_bytes);
                set(libc::RLIMIT_CORE, 0);
                Ok(())
            });
        }
        let mut child = cmd.spawn().map_err(|source| HarnessError::Spawn {
            program: command.program.display().to_string(),
            source,
        })?;
        let pid = child.id() as i32;
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
        let (ltx, lrx) = mpsc::sync_channel(4096);
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
            writer: Some(wtx),
            lines: lrx,
            stderr_done,
            _workdir: workdir,
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
        let status = self.child.wait().ok();
        let until = Instant::now() + Duration::from_millis(200);
        while !self.stderr_done.is_finished() && Instant::now() < until {
            std::thread::sleep(Duration::from_millis(2));
        }
        status
    }

    /// The exit status if the process has exited (after its stdout closed).
    fn exit_status(&mut self) -> Option<ExitStatus> {
        let until = Instant::now() + Duration::from_millis(500);
        loop {
            if let Ok(Some(status)) = self.child.try_wait() {
                return Some(status);
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
        let _ = self.child.wait();
    }
}

fn read_lines(stdout: ChildStdout, tx: SyncSender<Line>) {
    let mut reader = BufReader::with_capacity(1 << 16, stdout);
    let mut line: Vec<u8> = Vec::new();
    loop {
        let (done, used) = match reader.fill_buf() {
            Ok([]) => {
                if !line.is_empty() {
                    let _ = tx.send(Line::Text(String::from_utf8_lossy(&line).into_owned()));
                }
                let _ = tx.send(Line::Eof);
                return;
            }
            Ok(buf) => match buf.iter().position(|&b| b == b'\n') {
                Some(i) => {
                    let room = MAX_LINE_BYTES.saturating_sub(line.len());
                    line.extend_from_slice(&buf[..i.min(room)]);
                    (true, i + 1)
                }
                None => {
                    let room = MAX_LINE_BYTES.saturating_sub(line.len());
                    line.extend_from_slice(&buf[..buf.len().min(room)]);
                    (false, buf.len())
                }
            },
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(_) => {
                let _ = tx.send(Line::Eof);
                return;
            }
        };
        reader.consume(used);
        if done {
            let text = String::from_utf8_lossy(&line).into_owned();
            line.clear();
            if tx.send(Line::Text(text)).is_err() {
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

/// Records a stray line, keeping memory bounded however much a candidate prints.
fn push_junk(junk: &mut Vec<String>, line: &str) {
    if junk.len() < MAX_JUNK_LINES {
        junk.push(quote(line));
    } else if junk.len() == MAX_JUNK_LINES {
        junk.push("(more lines not shown)".into());
    }
}

fn quote(s: &str) -> String {
    let mut q: String = s.chars().take(JUNK_QUOTE).collect();
    if q.len() < s.len() {
        q.push_str("...");
    }
    q
}

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
}

impl Session {
    /// Starts the candidate and does the hello. A hello failure is an error when
    /// [`CandidateCommand::hello_failure_is_fatal`], else every case will report it.
    pub fn start(command: CandidateCommand, options: RunOptions) -> Result<Session, HarnessError> {
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
        if session.hello.name.is_empty() {
            session.hello.name = session.command.label.clone();
        }
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

    /// Spawns and does the hello: `Ok(Err(message))` when the hello failed.
    fn launch(&mut self) -> Result<Result<Hello, String>, HarnessError> {
        let proc = Proc::spawn(&self.command, self.options.limits, self.stderr.clone())?;
        proc.send(format!("{HELLO_LINE}\n").into_bytes());
        let deadline = Instant::now() + self.options.hello_timeout;
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
                Ok(Line::Text(line)) => {
                    if let Some(hello) = Hello::parse(&line) {
                        self.proc = Some(proc);
                        return Ok(Ok(hello));
                    }
                    push_junk(&mut junk, &line);
                }
                Ok(Line::Eof) | Err(RecvTimeoutError::Disconnected) => {
                    let mut proc = proc;
                    let status = proc.exit_status();
                    let _ = proc.kill();
                    return Ok(Err(self.failure_message(describe_status(status), &junk)));
                }
                Err(RecvTimeoutError::Timeout) => {
                    let _ = proc.kill();
                    let what = format!(
                        "no hello answer within {:.1} s",
                        self.options.hello_timeout.as_secs_f64()
                    );
                    return Ok(Err(self.failure_message(what, &junk)));
                }
            }
        }
    }

    fn failure_message(&self, what: String, junk: &[String]) -> String {
        let mut message = what;
        if !junk.is_empty() {
            message.push_str(&format!("; it printed {:?}", junk.join("\n")));
        }
        let tail = self.stderr_tail();
        let tail = tail.trim();
        if !tail.is_empty() {
            let last: Vec<&str> = tail.lines().rev().take(3).collect();
            let last: Vec<&str> = last.into_iter().rev().collect();
            message.push_str(&format!("; stderr ends: {}", last.join(" | ")));
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
        loop {
            // Cases still to run, skipping exhausted groups.
            let mut pending = Vec::new();
            for (i, case) in cases.iter().enumerate() {
                if outcomes[i].is_some() {
                    continue;
                }
                if let Some(reason) = self.exhausted.get(&case.shape.kind()) {
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
            self.collect(cases, &pending, &mut outcomes);
        }
        Ok(outcomes
            .into_iter()
            .map(|o| o.expect("every case has an outcome"))
            .collect())
    }

    /// Reads the answers to `pending`, in order, until all are in or the process is lost.
    ///
    /// A candidate may batch its answers unless asked to flush each (`"sync": true`). So the
    /// first death or timeout records nothing: the answers it had not written died with it
    /// and the real culprit may be a later case. The session switches to sync mode and the
    /// cases are run again from the one it was waiting for; from then on the case waited for
    /// is the one blamed.
    fn collect(&mut self, cases: &[Case], pending: &[usize], outcomes: &mut [Option<Outcome>]) {
        let timeout = self.options.timeout;
        let mut last = Instant::now();
        for &i in pending {
            let case = &cases[i];
            let mut junk: Vec<String> = Vec::new();
            loop {
                let proc = self.proc.as_mut().expect("a running candidate");
                let left = (last + timeout).saturating_duration_since(Instant::now());
                let next = if left.is_zero() {
                    Err(RecvTimeoutError::Timeout)
                } else {
                    proc.lines.recv_timeout(left)
                };
                match next {
                    Ok(Line::Text(line)) => match parse_answer_line(&line) {
                        ParsedLine::Answer {
                            id,
                            answer,
                            junk: prefix,
                        } if id == case.id => {
                            if !prefix.is_empty() {
                                push_junk(&mut junk, &prefix);
                            }
                            outcomes[i] = Some(Outcome::Answered { answer, junk });
                            last = Instant::now();
                            break;
                        }
                        ParsedLine::Answer { id, .. } => {
                            push_junk(&mut junk, &format!("an answer for id {id:?}: {line}"));
                        }
                        ParsedLine::Junk(text) => push_junk(&mut junk, &text),
                    },
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
                            describe_status(status)
                        );
                        outcomes[i] = Some(Outcome::Died { message, junk });
                        self.count(CountKind::Crash, case.shape.kind());
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
        for _ in 0..1000 {
            push_junk(&mut junk, &"x".repeat(10_000));
        }
        assert_eq!(junk.len(), MAX_JUNK_LINES + 1);
        assert_eq!(junk[0].len(), JUNK_QUOTE + 3);
        assert_eq!(junk[MAX_JUNK_LINES], "(more lines not shown)");
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
