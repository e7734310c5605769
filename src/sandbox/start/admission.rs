//! Letting a bubblewrap sandbox's first process start: what bubblewrap reports on its
//! `--info-fd` (the first process and its namespaces), read by a thread of the harness that sets
//! that process's limits and only then writes to its `--block-fd`.

use std::os::fd::{AsRawFd, FromRawFd, OwnedFd};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use crate::sandbox::bounds::ipc::Limits as IpcLimits;
use crate::sandbox::lifecycle::InfoSlot;

/// The harness's side of one bubblewrap start: the descriptors bubblewrap is given, and the
/// harness's copies of them, which must live until the command is spawned and then close.
#[derive(Debug)]
pub(in crate::sandbox) struct Admission {
    /// bubblewrap's `--info-fd`.
    pub info_fd: i32,
    /// bubblewrap's `--block-fd`.
    pub block_fd: i32,
    /// The child ends (`info_fd`, `block_fd`) as the harness holds them: kept open until the
    /// command is dropped after the spawn.
    pub _held: (OwnedFd, OwnedFd),
}

/// The limits set on a bubblewrap sandbox's first process before it goes on.
#[derive(Debug)]
pub(in crate::sandbox) struct Limits {
    /// `RLIMIT_NPROC` (a harness that is not root: see [`admit`]).
    pub processes: Option<u64>,
    /// Written inside its IPC namespace (a root harness: only root may write them there).
    pub ipc: Option<IpcLimits>,
}

/// Starts the admission of one bubblewrap command ([`admit`] on a thread of its own), filling
/// `slot` with what bubblewrap reports; `None` when its pipes or its thread cannot be made (the
/// command must then fail: its processes could not be limited).
pub(in crate::sandbox) fn start(
    slot: Arc<InfoSlot>,
    limits: Limits,
    namespaces: Arc<Mutex<Vec<u64>>>,
) -> Option<Admission> {
    let (info_read, info_write) = cloexec_pipe().ok()?;
    let (block_read, block_write) = cloexec_pipe().ok()?;
    std::thread::Builder::new()
        .name("sandbox-admit".into())
        .spawn(move || admit(info_read, block_write, slot, limits, namespaces))
        .ok()?;
    Some(Admission {
        info_fd: info_write.as_raw_fd(),
        block_fd: block_read.as_raw_fd(),
        _held: (info_write, block_read),
    })
}

/// Lets a bubblewrap sandbox's first process go on, once it has its limits: reads what
/// bubblewrap reports (`--info-fd`: the first process's pid and its namespaces), records its PID
/// namespace, sets `RLIMIT_NPROC` to `processes` on that process when asked (`Some`: a harness
/// that is not root, whose user the limit cannot be set for before bubblewrap, since it would
/// count all of that user's processes; inside the sandbox's own user namespace it counts the
/// sandbox's alone), and only then writes to its `--block-fd`. Where the limit cannot be set the
/// process is killed (fail closed). A per-submission uid got the limit before bubblewrap (its
/// processes are the sandbox's alone), and a root harness may lack `CAP_SYS_RESOURCE` (Docker
/// drops it) to set another uid's. A root harness also writes the limits of the sandbox's IPC
/// namespace from inside it (this thread enters it, and ends soon after); where they cannot be
/// written the watchdog still counts what the namespace holds.
fn admit(
    info: OwnedFd,
    block: OwnedFd,
    slot: Arc<InfoSlot>,
    limits: Limits,
    namespaces: Arc<Mutex<Vec<u64>>>,
) {
    let processes = limits.processes;
    let text = read_with_timeout(info, Duration::from_secs(10));
    let value: serde_json::Value = serde_json::from_str(&text).unwrap_or_default();
    let child = value["child-pid"]
        .as_u64()
        .and_then(|p| libc::pid_t::try_from(p).ok());
    if let Some(ns) = value["pid-namespace"].as_u64()
        && let Ok(mut list) = namespaces.lock()
    {
        list.push(ns);
    }
    if let Some(pid) = child {
        if let Some(ipc) = &limits.ipc {
            let _ = ipc.write_for(pid);
        }
        // SAFETY: plain system calls on a process bubblewrap just made and holds waiting.
        unsafe {
            let limited = processes.is_none_or(|n| {
                let rl = libc::rlimit {
                    rlim_cur: n as libc::rlim_t,
                    rlim_max: n as libc::rlim_t,
                };
                libc::prlimit(pid, libc::RLIMIT_NPROC, &rl, std::ptr::null_mut()) == 0
            });
            if limited {
                libc::write(block.as_raw_fd(), b"x".as_ptr().cast(), 1);
            } else {
                libc::kill(pid, libc::SIGKILL);
            }
        }
    }
    slot.set(text);
}

/// A pipe whose both ends close on exec (the child's end is made inheritable in `pre_exec`).
pub(in crate::sandbox) fn cloexec_pipe() -> std::io::Result<(OwnedFd, OwnedFd)> {
    let mut fds = [0; 2];
    // SAFETY: pipe2 writes two fds into the array on success.
    if unsafe { libc::pipe2(fds.as_mut_ptr(), libc::O_CLOEXEC) } != 0 {
        return Err(std::io::Error::last_os_error());
    }
    // SAFETY: both fds are fresh and owned by nobody else.
    Ok(unsafe { (OwnedFd::from_raw_fd(fds[0]), OwnedFd::from_raw_fd(fds[1])) })
}

/// Reads a pipe to its end or until `timeout`, at most 64 KiB.
fn read_with_timeout(fd: OwnedFd, timeout: Duration) -> String {
    let deadline = Instant::now() + timeout;
    let mut bytes = Vec::new();
    let mut buf = [0u8; 4096];
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() || bytes.len() > 1 << 16 {
            break;
        }
        let mut pfd = libc::pollfd {
            fd: fd.as_raw_fd(),
            events: libc::POLLIN,
            revents: 0,
        };
        // SAFETY: one valid pollfd.
        let ready = unsafe { libc::poll(&mut pfd, 1, left.as_millis().min(2000) as i32) };
        if ready <= 0 {
            break;
        }
        // SAFETY: reading into a local buffer of its length.
        let n = unsafe { libc::read(fd.as_raw_fd(), buf.as_mut_ptr().cast(), buf.len()) };
        if n <= 0 {
            break;
        }
        bytes.extend_from_slice(&buf[..n as usize]);
        // bubblewrap writes one JSON object: done as soon as it is whole.
        if serde_json::from_slice::<serde_json::Value>(&bytes).is_ok() {
            break;
        }
    }
    String::from_utf8_lossy(&bytes).into_owned()
}
