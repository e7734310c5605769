//! The pipes of one candidate process (`Proc`): spawned through the sandbox with a writer
//! thread on its stdin, a reader thread that parses (and caps) each stdout line, a thread that
//! keeps the end of its stderr (`Tail`); killed with its whole process group.
//!
//! What the reader passes on is bounded: at most [`LINE_QUEUE`] parsed lines wait, a line over
//! [`MAX_LINE_BYTES`] is skipped up to its newline and only its start is quoted, and stderr
//! keeps its last [`STDERR_TAIL_BYTES`].

use std::collections::VecDeque;
use std::ffi::OsString;
use std::io::{BufRead, BufReader, Read, Write};
use std::os::unix::process::ExitStatusExt;
use std::path::Path;
use std::process::{Child, ChildStdout, ExitStatus, Stdio};
use std::sync::mpsc::{self, Receiver, Sender, SyncSender};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use crate::candidate::process::error::HarnessError;
use crate::candidate::process::protocol::{MAX_QUOTE_CHARS, ParsedLine, parse_line, quote_line};
use crate::sandbox::{bounds::reaper::Reaper, lifecycle::Sandbox};

/// How many bytes of the candidate's stderr are kept for the report.
pub const STDERR_TAIL_BYTES: usize = 4096;

/// Longest answer line accepted: a longer one is a protocol error of the case waiting, and is
/// skipped up to its newline without being kept (only its first bytes are quoted).
pub const MAX_LINE_BYTES: usize = 1 << 20;

/// Lines read ahead of the session. Each holds at most a few capped texts (see
/// [`parse_line`]), so what is queued stays within a few tens of MB however big the lines.
pub const LINE_QUEUE: usize = 1024;

/// The environment variable naming a file that every byte sent to a candidate is appended to:
/// how the tests (and a wary instructor) see everything that left the grader, to check that no
/// secret did (`tests/integration/attacks/mod.rs`). The grader's own environment only: a candidate
/// never sees it.
pub const RECORD_REQUESTS_ENV: &str = "RTORACLE_RECORD_REQUESTS";

/// Appends `bytes` to the file [`RECORD_REQUESTS_ENV`] names, when it names one (opened once per
/// process; a file that cannot be opened or written records nothing).
fn record(bytes: &[u8]) {
    static FILE: std::sync::OnceLock<Option<Mutex<std::fs::File>>> = std::sync::OnceLock::new();
    let file = FILE.get_or_init(|| {
        let path = std::env::var_os(RECORD_REQUESTS_ENV).filter(|p| !p.is_empty())?;
        std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(path)
            .ok()
            .map(Mutex::new)
    });
    if let Some(f) = file {
        let _ = f.lock().unwrap_or_else(|e| e.into_inner()).write_all(bytes);
    }
}

/// The last bytes of a stream.
#[derive(Debug, Default)]
pub(crate) struct Tail(VecDeque<u8>);

impl Tail {
    /// Appends `bytes`, keeping the last [`STDERR_TAIL_BYTES`].
    pub(crate) fn push(&mut self, bytes: &[u8]) {
        let bytes = &bytes[bytes.len().saturating_sub(STDERR_TAIL_BYTES)..];
        let over = (self.0.len() + bytes.len()).saturating_sub(STDERR_TAIL_BYTES);
        self.0.drain(..over);
        self.0.extend(bytes);
    }

    /// The bytes kept, as text (invalid UTF-8 replaced).
    pub(crate) fn text(&self) -> String {
        let (a, b) = self.0.as_slices();
        String::from_utf8_lossy(&[a, b].concat()).into_owned()
    }
}

/// What the reader thread passes on: each stdout line parsed (and capped) on that thread.
// A parsed line is a few hundred bytes and passed on once; boxing it would cost an allocation
// per line for nothing.
#[allow(clippy::large_enum_variant)]
pub(crate) enum Line {
    /// A line, parsed.
    Parsed(ParsedLine),
    /// A line longer than [`MAX_LINE_BYTES`]: its first characters, quoted.
    Oversize(String),
    /// What the process wrote after its last newline before its stdout ended (it died in the
    /// middle of a line): the start of it, quoted. An [`Line::Eof`] follows.
    Partial(String),
    /// The end of its stdout.
    Eof,
}

/// One running child process.
pub(crate) struct Proc {
    child: Child,
    /// The child's pid (and process group).
    pub(crate) pid: i32,
    /// Ends every process the candidate started (its PID namespace or its uid).
    reaper: Reaper,
    /// Whether the child is bubblewrap, which exits `128 + N` when the candidate dies of signal
    /// `N`: such statuses are read back as the signal.
    bwrap: bool,
    writer: Option<Sender<Vec<u8>>>,
    /// The stdout lines, parsed on the reader thread.
    pub(crate) lines: Receiver<Line>,
    stderr_done: std::thread::JoinHandle<()>,
}

impl Proc {
    /// Starts `program` with `args` in `sandbox`; its stderr goes to `stderr`.
    pub(crate) fn spawn(
        program: &Path,
        args: &[OsString],
        sandbox: &Sandbox,
        stderr: Arc<Mutex<Tail>>,
    ) -> Result<Proc, HarnessError> {
        let mut cmd = sandbox.command(program);
        cmd.args(args)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped());
        // Started and recorded under the gate, so an interruption's cleanup finds it.
        let gate = crate::interrupt::spawn_gate().ok_or_else(|| HarnessError::Spawn {
            program: program.display().to_string(),
            reason: std::io::Error::new(std::io::ErrorKind::Interrupted, "interrupted"),
        })?;
        let mut child = cmd.spawn().map_err(|reason| HarnessError::Spawn {
            program: program.display().to_string(),
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
            bwrap: sandbox.isolation() == crate::sandbox::policy::Isolation::Bubblewrap,
            writer: Some(wtx),
            lines: lrx,
            stderr_done,
        })
    }

    /// Queues `bytes` for the child's stdin (and records them when `RTORACLE_RECORD_REQUESTS`
    /// names a file: [`record`]).
    pub(crate) fn send(&self, bytes: Vec<u8>) {
        record(&bytes);
        if let Some(w) = &self.writer {
            let _ = w.send(bytes);
        }
    }

    /// Kills the whole process group and reaps the child; waits briefly for its stderr.
    pub(crate) fn kill(mut self) -> Option<ExitStatus> {
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
    pub(crate) fn exit_status(&mut self) -> Option<ExitStatus> {
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
                // A line is one once its newline came: what is left was cut off by the end.
                if !line.is_empty() {
                    let text = String::from_utf8_lossy(&line);
                    let _ = tx.send(Line::Partial(quote_line(&text)));
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

/// How a process ended, in words.
pub(crate) fn describe_status(status: Option<ExitStatus>) -> String {
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

#[cfg(test)]
mod tests {
    use super::*;

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
