//! A candidate's session ([`Session`]): one sandbox, the hello, pipelined requests, per-case
//! time-outs, restarts after a crash, a time budget, and the whole process group killed on drop.
//!
//! A [`Session`] makes one [`Sandbox`] (bubblewrap where it works, else limits, its own session
//! and a uid of its own; never root; see [`crate::sandbox`]) from its [`CandidateCommand`] and
//! starts every process of the candidate, restarts included, through it (one
//! [`pipe`](crate::candidate::process::pipe) each); when a process is killed or the session ends, every process the
//! candidate started ends too ([`crate::sandbox::bounds::reaper::Reaper`]).
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
//!   waited for ([`crate::candidate::process::lines`]); a malformed answer, an answer with an id in no request, an
//!   answer for a later request or an oversize line makes that case a `protocol` error at once
//!   ([`Outcome::Protocol`]), without a restart; an answer for a case already settled is stray
//!   output of the waited one, which keeps waiting for its own id, so nothing shifts. The hello
//!   must say protocol 1 and name only known shapes ([`HarnessError::BadHello`] otherwise).
//! - **Caps on the harness's side**: lines are parsed on the reader thread and only capped text
//!   is queued ([`crate::candidate::process::pipe`]); each error field is cut to 4 KiB and, past
//!   [`RUN_DETAIL_BYTES`] per session, to [`SMALL_ERROR_BYTES`] without traceback; stray lines
//!   are quoted briefly, 8 per case and [`RUN_JUNK_BYTES`] per session.
//! - **A time budget** ([`RunOptions::budget`]): past it the cases not answered are `not_run`
//!   with the reason, and the candidate is killed; a restart's hello ends with it too, so a
//!   candidate that is slow to start and dies on every case costs the budget, not more.
//! - **Short failure messages**: why the candidate could not start quotes at most
//!   [`STDERR_EXCERPT_CHARS`] of its stderr (the message is repeated for every case it costs, so
//!   a candidate flooding stderr cannot make a report of megabytes).

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};
use std::process::ExitStatus;
use std::sync::mpsc::RecvTimeoutError;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use crate::candidate::process::command::CandidateCommand;
use crate::candidate::process::error::HarnessError;
use crate::candidate::process::lines::{
    Meaning, RUN_JUNK_BYTES, describe_line, meaning, oversize_message, push_junk,
};
use crate::candidate::process::options::RunOptions;
use crate::candidate::process::outcome::Outcome;
use crate::candidate::process::pipe::{Line, MAX_LINE_BYTES, Proc, Tail, describe_status};
use crate::candidate::process::protocol::{
    Answer, CandidateError, HELLO_LINE, Hello, ParsedLine, Request,
};
use crate::oracle::vectors::{Case, ShapeKind};
use crate::sandbox::{facts::SandboxFacts, lifecycle::Sandbox};

/// Characters of the candidate's stderr quoted in a start failure's message (its last lines).
pub const STDERR_EXCERPT_CHARS: usize = 300;

/// Bytes of candidate text (error types, messages, tracebacks) kept over one session: past
/// it, each error keeps [`SMALL_ERROR_BYTES`] of each field and no traceback.
pub const RUN_DETAIL_BYTES: usize = 256 * 1024;

/// What each error field keeps once [`RUN_DETAIL_BYTES`] are used up.
pub const SMALL_ERROR_BYTES: usize = 200;

/// The last [`STDERR_EXCERPT_CHARS`] characters of `text`, with `...` before them when cut.
fn excerpt_end(text: &str) -> String {
    let count = text.chars().count();
    if count <= STDERR_EXCERPT_CHARS {
        return text.to_string();
    }
    let tail: String = text.chars().skip(count - STDERR_EXCERPT_CHARS).collect();
    format!("...{tail}")
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
    /// What the session noticed about the candidate's use of the protocol ([`Session::notes`]).
    notes: Vec<String>,
    /// Stdout lines read after a hello, over every process of the session (restarts included).
    lines_seen_ever: usize,
}

/// The usual reason a candidate's lines never arrive.
const FLUSH_HINT: &str = "the usual cause: stdout not flushed after each line (fflush(stdout) \
                          in C, print(..., flush=True) in Python)";

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
                ops: None,
                error: None,
                unknown_keys: Vec::new(),
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
            notes: Vec::new(),
            lines_seen_ever: 0,
        };
        match session.launch()? {
            Ok(hello) => {
                session.notes.extend(hello.warnings());
                session.hello = hello;
            }
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
        if session.hello.name.is_empty() || session.command.is_course_adapter() {
            // The course adapter was told a neutral name; reports use the real label.
            session.hello.name = session.command.label.clone();
        }
        crate::sandbox::facts::announce(&session.sandbox_facts());
        Ok(session)
    }

    /// What the session noticed about the candidate's use of the protocol that is no case's
    /// failure: keys of its hello the protocol does not name, answers that never came after
    /// the hello (stdout not flushed).
    pub fn notes(&self) -> &[String] {
        &self.notes
    }

    /// The candidate's hello (its name, shapes and any import error).
    pub fn hello(&self) -> &Hello {
        &self.hello
    }

    /// Why the candidate could not be started, when it could not (every case then died).
    pub fn start_failure(&self) -> Option<&str> {
        self.broken.as_deref()
    }

    /// The last [`STDERR_TAIL_BYTES`](crate::candidate::process::pipe::STDERR_TAIL_BYTES) bytes the candidate wrote to stderr, over all restarts.
    pub fn stderr_tail(&self) -> String {
        self.stderr.lock().unwrap_or_else(|e| e.into_inner()).text()
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
        let Some(submission) = self.command.submission() else {
            return;
        };
        let dir = self.sandbox.dir();
        let inside = self.sandbox.inside_dir();
        if inside != dir {
            let to = submission.display().to_string();
            for text in [&mut error.message, &mut error.traceback] {
                *text = crate::sandbox::view::replace_path(text, &inside, &to);
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
        let proc = Proc::spawn(
            &self.command.program,
            &self.command.args,
            &self.sandbox,
            self.stderr.clone(),
        )?;
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
                Ok(Line::Partial(head)) => {
                    let line = format!("{head} without its newline");
                    push_junk(&mut junk, line, &mut self.junk_left)
                }
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
                            "no hello answer within {:.1} s{}",
                            self.options.hello_timeout.as_secs_f64(),
                            if junk.is_empty() {
                                format!(" ({FLUSH_HINT})")
                            } else {
                                String::new()
                            }
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
            .filter(|_| !self.command.is_course_adapter())
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
                outcomes[i] = Some(Outcome::Unsupported {
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
        // A run can end between two of the watchdog's ticks (code that fills its /tmp at import
        // and then answers every case with the error): measure once more while it lives. What
        // it passed is said in the notes whichever found it: a tick that comes after the last
        // answer stops the code with no case left to die of it.
        if self.sandbox.violation().is_none() {
            self.sandbox.measure_now();
        }
        if let Some(violation) = self.sandbox.violation()
            && !self.notes.contains(&violation)
        {
            self.notes.push(violation);
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

    /// Sends one request (a JSON object with its `op`; `id` is set here, and `"sync": true`
    /// so a batching candidate answers at once) and waits up to `timeout` for the answer with
    /// that id. Other lines meanwhile are stray output and ignored. A candidate that does not
    /// answer in time, or dies, is killed, and the next call starts it again (a restart); once
    /// the time budget is used up every call fails with its reason.
    pub fn call(
        &mut self,
        id: &str,
        request: &serde_json::Value,
        timeout: Duration,
    ) -> CallOutcome {
        self.check_budget();
        if let Some(reason) = &self.budget_used {
            return CallOutcome::Failed(reason.clone());
        }
        if let Some(message) = &self.broken {
            return CallOutcome::Failed(message.clone());
        }
        if self.proc.is_none() {
            self.restarts += 1;
            match self.launch() {
                Ok(Ok(_)) => {}
                Ok(Err(message)) => {
                    let message = format!("could not restart the candidate: {message}");
                    self.broken = Some(message.clone());
                    return CallOutcome::Failed(message);
                }
                Err(e) => return CallOutcome::Failed(e.to_string()),
            }
        }
        let mut object = match request {
            serde_json::Value::Object(map) => map.clone(),
            _ => serde_json::Map::new(),
        };
        object.insert("id".into(), serde_json::Value::String(id.to_string()));
        object.remove("sync");
        let body = serde_json::Value::Object(object).to_string();
        let line = format!("{{\"sync\":true,{}\n", &body[1..]);
        let by_call = Instant::now() + timeout;
        let (deadline, by_budget) = match self.budget_deadline() {
            Some(b) if b < by_call => (b, true),
            _ => (by_call, false),
        };
        let proc = self.proc.as_ref().expect("a running candidate");
        proc.send(line.into_bytes());
        // What it wrote of a last line it never ended (said when it dies).
        let mut partial: Option<String> = None;
        loop {
            let proc = self.proc.as_mut().expect("a running candidate");
            let left = deadline.saturating_duration_since(Instant::now());
            let next = if left.is_zero() {
                Err(RecvTimeoutError::Timeout)
            } else {
                proc.lines.recv_timeout(left)
            };
            match next {
                Ok(Line::Parsed(ParsedLine::Result { id: got, text })) if got == id => {
                    return result_of(&text);
                }
                Ok(Line::Parsed(ParsedLine::Answer {
                    id: got, answer, ..
                })) if got == id => {
                    let answer = self.keep(answer);
                    return match answer.error {
                        Some(error) => CallOutcome::Error(error),
                        None => CallOutcome::Protocol(
                            "it answered with an intersection's answer, not a \"result\"".into(),
                        ),
                    };
                }
                Ok(Line::Parsed(ParsedLine::Malformed {
                    id: got,
                    problem,
                    quoted,
                })) if got.as_deref().is_none_or(|g| g == id) => {
                    return CallOutcome::Protocol(format!(
                        "a malformed answer ({problem}): the line was {quoted}"
                    ));
                }
                Ok(Line::Oversize(head)) => {
                    return CallOutcome::Protocol(oversize_message(&head, MAX_LINE_BYTES));
                }
                Ok(Line::Parsed(_)) => {}
                Ok(Line::Partial(head)) => partial = Some(head),
                Ok(Line::Eof) | Err(RecvTimeoutError::Disconnected) => {
                    let mut proc = self.proc.take().expect("a running candidate");
                    let status = proc.exit_status();
                    let _ = proc.kill();
                    let wrote = partial
                        .take()
                        .map(|head| format!(", after writing {head} without its newline"))
                        .unwrap_or_default();
                    return CallOutcome::Failed(format!(
                        "the candidate died on this request: {}{wrote}",
                        self.describe_end(status)
                    ));
                }
                Err(RecvTimeoutError::Timeout) => {
                    if let Some(proc) = self.proc.take() {
                        let _ = proc.kill();
                    }
                    if by_budget {
                        self.check_budget();
                        if let Some(reason) = &self.budget_used {
                            return CallOutcome::Failed(reason.clone());
                        }
                    }
                    return CallOutcome::TimedOut;
                }
            }
        }
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
    /// is the one blamed. Each line is judged by [`meaning`] (the strict protocol).
    fn collect(
        &mut self,
        cases: &[Case],
        pending: &[usize],
        outcomes: &mut [Option<Outcome>],
        index: &HashMap<&str, usize>,
    ) {
        let mut waiting = Waiting {
            since: Instant::now(),
            early: HashMap::new(),
        };
        for &i in pending {
            if let Some(outcome) = waiting.early.remove(&i) {
                outcomes[i] = Some(outcome);
                continue;
            }
            let (outcome, go_on) = self.wait_for(cases, i, outcomes, index, &mut waiting);
            if outcome.is_some() {
                outcomes[i] = outcome;
            }
            if !go_on {
                return;
            }
            waiting.since = Instant::now();
        }
    }

    /// Waits for the answer to case `i`: its outcome (`None` when the case is to be run
    /// again), and whether the batch goes on (`false` once the process is lost or the budget
    /// is used up).
    fn wait_for(
        &mut self,
        cases: &[Case],
        i: usize,
        outcomes: &[Option<Outcome>],
        index: &HashMap<&str, usize>,
        waiting: &mut Waiting,
    ) -> (Option<Outcome>, bool) {
        let case = &cases[i];
        let mut junk: Vec<String> = Vec::new();
        // What the process had written of a line when it died (an Eof follows).
        let mut partial: Option<String> = None;
        loop {
            let case_deadline = waiting.since + self.options.timeout;
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
            let parsed = match next {
                Ok(Line::Parsed(parsed)) => {
                    self.lines_seen_ever += 1;
                    parsed
                }
                Ok(Line::Oversize(head)) => {
                    let message = oversize_message(&head, MAX_LINE_BYTES);
                    return (Some(Outcome::Protocol { message, junk }), true);
                }
                Ok(Line::Partial(head)) => {
                    partial = Some(head);
                    continue;
                }
                Ok(Line::Eof) | Err(RecvTimeoutError::Disconnected) => {
                    return (self.lost(case, junk, partial), false);
                }
                Err(RecvTimeoutError::Timeout) if by_budget => {
                    self.check_budget();
                    return (None, false);
                }
                Err(RecvTimeoutError::Timeout) => return (self.timed_out(case, junk), false),
            };
            match meaning(parsed, case, i, index, |k| outcomes[k].is_some()) {
                Meaning::Own { answer, prefix } => {
                    if !prefix.is_empty() {
                        push_junk(&mut junk, prefix, &mut self.junk_left);
                    }
                    let answer = self.keep(answer);
                    return (Some(Outcome::Answered { answer, junk }), true);
                }
                Meaning::Protocol(message) => {
                    return (Some(Outcome::Protocol { message, junk }), true);
                }
                Meaning::Early {
                    later,
                    answer,
                    prefix,
                    message,
                } => {
                    let mut later_junk = Vec::new();
                    if !prefix.is_empty() {
                        push_junk(&mut later_junk, prefix, &mut self.junk_left);
                    }
                    let answer = self.keep(answer);
                    waiting.early.insert(
                        later,
                        Outcome::Answered {
                            answer,
                            junk: later_junk,
                        },
                    );
                    return (Some(Outcome::Protocol { message, junk }), true);
                }
                Meaning::Stray(line) => push_junk(&mut junk, line, &mut self.junk_left),
            }
        }
    }

    /// The process ended while `case` was waited for: the first time, sync mode and nothing
    /// recorded (the case runs again); in sync mode, the case died. `partial` is what it had
    /// written of a line: the answer it died writing is this case's (a line is only judged once
    /// its newline came), so the blame stays here.
    fn lost(&mut self, case: &Case, junk: Vec<String>, partial: Option<String>) -> Option<Outcome> {
        let mut proc = self.proc.take().expect("a running candidate");
        let status = proc.exit_status();
        let _ = proc.kill();
        if !self.sync {
            self.sync = true;
            return None;
        }
        let during = match partial {
            Some(head) => format!(" in the middle of a line (it had written {head})"),
            None => String::new(),
        };
        let message = format!(
            "the candidate died on this case{during}: {}",
            self.describe_end(status)
        );
        self.count(CountKind::Crash, case.shape.kind());
        Some(Outcome::Died { message, junk })
    }

    /// No answer to `case` within its time-out: the process is killed; the first time, sync
    /// mode and nothing recorded (the case runs again); in sync mode, the case timed out.
    fn timed_out(&mut self, case: &Case, junk: Vec<String>) -> Option<Outcome> {
        let proc = self.proc.take().expect("a running candidate");
        let _ = proc.kill();
        if !self.sync {
            self.sync = true;
            return None;
        }
        // Only a candidate that never answered anything: one that answers some cases and hangs
        // on others flushes, and its restarted processes have seen nothing yet.
        if self.lines_seen_ever == 0 && !self.notes.iter().any(|n| n.contains(FLUSH_HINT)) {
            self.notes.push(format!(
                "no line came from the candidate after its hello while it was sent requests \
                 to answer one at a time; {FLUSH_HINT}"
            ));
        }
        self.count(CountKind::Timeout, case.shape.kind());
        Some(Outcome::Timeout { junk })
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

/// The outcome of an answer line holding a `result` (its text): the `result`, or a protocol
/// error when the line holds a key beside `id` and `result` (an answer's keys are fixed: a
/// marker such as `"unsteered"` next to them is not ignored).
fn result_of(text: &str) -> CallOutcome {
    match serde_json::from_str::<serde_json::Value>(text) {
        Ok(serde_json::Value::Object(mut map)) => {
            match map.keys().find(|k| *k != "id" && *k != "result") {
                Some(k) => CallOutcome::Protocol(format!(
                    "the answer has the key \"{}\" beside \"id\" and \"result\", which the protocol does not name",
                    crate::escape::truncate(k, 60)
                )),
                None => CallOutcome::Result(map.remove("result").unwrap_or_default()),
            }
        }
        Ok(_) => CallOutcome::Protocol("the answer is not a JSON object".into()),
        Err(e) => CallOutcome::Protocol(format!("a malformed answer: {e}")),
    }
}

/// What one request sent with [`Session::call`] got.
#[derive(Clone, Debug, PartialEq)]
pub enum CallOutcome {
    /// The answer's `result` object.
    Result(serde_json::Value),
    /// The candidate raised an error instead (file names are the submission's).
    Error(CandidateError),
    /// No answer within the time given: the candidate was killed (the next call restarts it).
    TimedOut,
    /// No answer: the candidate died, could not start, or the session's time budget is used
    /// up; why.
    Failed(String),
    /// An answer that breaks the protocol: a malformed line, an intersection's answer, a key
    /// beside `id` and `result`; why. A failure of the request, counted apart by the callers
    /// (a person should look at it: the bundled adapter never makes one).
    Protocol(String),
}

enum CountKind {
    Timeout,
    Crash,
}

/// What waiting for one batch keeps between its cases.
struct Waiting {
    /// When the last case was settled (the next one's time-out runs from here).
    since: Instant,
    /// Answers that came for later cases of the batch, by case index.
    early: HashMap<usize, Outcome>,
}

#[cfg(test)]
mod tests {
    use std::time::Duration;

    use super::*;

    /// A submission whose import writes a file into its working folder and reports who and
    /// where it is on stderr.
    fn nosy_submission() -> tempfile::TempDir {
        let dir = crate::bench::harness::assemble_fixture("honest_reference").unwrap();
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
        let cases: Vec<Case> = crate::oracle::suite::default_suite(0)
            .into_iter()
            .filter(|c| c.shape.kind() == ShapeKind::Sphere)
            .collect();
        let report = crate::candidate::check_session(&mut session, &cases).unwrap();
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
        if crate::sandbox::identity::running_as_root() {
            // Never root, and a uid of its own.
            assert!(facts.uid >= 1 << 30, "{facts:?}");
        }
        if facts.isolation == crate::sandbox::policy::Isolation::Bubblewrap {
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
        let cases: Vec<Case> = crate::oracle::suite::default_suite(0)
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
}
