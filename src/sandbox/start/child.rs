//! What a sandbox's child does between `fork` and `exec`, before any untrusted code runs: its
//! own session, no inherited descriptors, the fallback's namespaces and read-only view, the
//! limits, the identity, and death with the harness.

use crate::sandbox::bounds::ipc::Limits as IpcLimits;
use crate::sandbox::policy::SandboxPolicy;
use crate::sandbox::start::pivot::ViewPlan;

/// `RLIMIT_MSGQUEUE`: the bytes of POSIX message queues the code's user may hold.
const MSGQUEUE_BYTES: u64 = 1 << 20;

/// Everything the child's set-up needs, made before the fork (after it, nothing may allocate).
#[derive(Debug)]
pub(in crate::sandbox) struct ChildSetup {
    policy: SandboxPolicy,
    /// `(uid, gid)` to switch to.
    switch_to: Option<(u32, u32)>,
    /// The fallback's namespaces are attempted, and its view where a mount namespace is made.
    fallback: Option<Fallback>,
    /// Descriptors the child keeps open (bubblewrap's pipes); every other one but 0, 1, 2 closes.
    keep: Vec<i32>,
    /// The `cgroup.procs` of the sandbox's cgroup, joined first (while the path is still there).
    cgroup: Option<std::ffi::CString>,
    /// The harness's pid, to notice it died before the parent-death signal was armed.
    parent: libc::pid_t,
}

/// What the fallback's child attempts: namespaces, the limits of its IPC namespace, its view.
#[derive(Debug)]
pub(in crate::sandbox) struct Fallback {
    /// A network namespace too.
    pub network: bool,
    /// Written inside its new IPC namespace.
    pub ipc: IpcLimits,
    /// Made in its new mount namespace.
    pub view: ViewPlan,
}

impl ChildSetup {
    /// The set-up of a child under `policy`, switching to `switch_to`, with the fallback's
    /// namespaces when `fallback`, keeping `keep` open, joining the cgroup whose `cgroup.procs`
    /// is `cgroup`.
    pub(in crate::sandbox) fn new(
        policy: &SandboxPolicy,
        switch_to: Option<(u32, u32)>,
        fallback: Option<Fallback>,
        keep: Vec<i32>,
        cgroup: Option<std::ffi::CString>,
    ) -> ChildSetup {
        ChildSetup {
            policy: policy.clone(),
            switch_to,
            fallback,
            keep,
            cgroup,
            parent: std::process::id() as libc::pid_t,
        }
    }

    /// Sets the child up: a new session, every inherited descriptor but 0, 1, 2 (and those kept)
    /// closed on exec, the fallback's namespaces, the limits, the identity, `SIGKILL` when the
    /// harness dies.
    ///
    /// # Safety
    /// Only in the child between `fork` and `exec` (`pre_exec`): it makes only
    /// async-signal-safe system calls (setsid, open, write, close, unshare, mount,
    /// mount_setattr, pivot_root, chdir, setrlimit, setgroups, setgid, setuid, prctl, getppid,
    /// fcntl, close_range) and allocates nothing.
    pub(in crate::sandbox) unsafe fn run(&self) -> std::io::Result<()> {
        // SAFETY: the caller's contract; each call is a plain system call on owned data.
        unsafe {
            if libc::setsid() < 0 {
                return Err(std::io::Error::last_os_error());
            }
            if let Some(procs) = &self.cgroup {
                // Best effort: the facts say whether the code was seen in it.
                let fd = libc::open(procs.as_ptr(), libc::O_WRONLY | libc::O_CLOEXEC);
                if fd >= 0 {
                    libc::write(fd, b"0".as_ptr().cast(), 1);
                    libc::close(fd);
                }
            }
            // Every inherited descriptor but 0, 1, 2 (and bubblewrap's pipes) closes on exec: a
            // descriptor the harness inherited must not reach the code.
            libc::syscall(
                libc::SYS_close_range,
                3u32,
                u32::MAX,
                libc::CLOSE_RANGE_CLOEXEC,
            );
            for &fd in &self.keep {
                libc::fcntl(fd, libc::F_SETFD, 0);
            }
            #[cfg(target_os = "linux")]
            if let Some(fallback) = &self.fallback {
                fallback.apply()?;
            }
            self.set_limits();
            if let Some((uid, gid)) = self.switch_to {
                limit(libc::RLIMIT_NPROC, self.policy.processes);
                if libc::setgroups(0, std::ptr::null()) != 0
                    || libc::setgid(gid) != 0
                    || libc::setuid(uid) != 0
                {
                    return Err(std::io::Error::last_os_error());
                }
            }
            // After the user change, which clears it.
            #[cfg(target_os = "linux")]
            {
                libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL as libc::c_ulong);
                if libc::getppid() != self.parent {
                    // The harness died before the signal was armed.
                    libc::_exit(137);
                }
            }
        }
        Ok(())
    }

    /// CPU time, address space, open files, file size, no core files.
    fn set_limits(&self) {
        let p = &self.policy;
        limit(libc::RLIMIT_CPU, p.cpu_seconds);
        limit(libc::RLIMIT_AS, p.memory_bytes);
        limit(libc::RLIMIT_NOFILE, p.open_files);
        limit(libc::RLIMIT_FSIZE, p.file_size_bytes);
        limit(libc::RLIMIT_CORE, 0);
        limit(libc::RLIMIT_MSGQUEUE, MSGQUEUE_BYTES);
    }
}

impl Fallback {
    /// The fallback's namespaces, each best effort and verified by the facts: a network
    /// namespace (when asked), an IPC namespace (System V objects die with it) with its limits
    /// written, and a mount namespace whose mounts never reach the host's (made private first)
    /// holding the sandbox's own view. Once a mount namespace is made, its view must be made
    /// whole, or the code does not run.
    ///
    /// # Safety
    /// As [`ChildSetup::run`].
    #[cfg(target_os = "linux")]
    unsafe fn apply(&self) -> std::io::Result<()> {
        // SAFETY: the caller's contract; each call is a plain system call on owned data.
        unsafe {
            if self.network {
                // Fails without CAP_SYS_ADMIN, which the facts show.
                let _ = libc::unshare(libc::CLONE_NEWNET);
            }
            if libc::unshare(libc::CLONE_NEWIPC) == 0 {
                // Written before the mounts (which make `/proc` read-only); the watchdog counts
                // what a namespace whose limits could not be written holds.
                let _ = self.ipc.write_in_child();
            }
            let null = std::ptr::null::<libc::c_char>();
            if libc::unshare(libc::CLONE_NEWNS) != 0 {
                return Ok(());
            }
            if libc::mount(
                null,
                c"/".as_ptr(),
                null,
                libc::MS_REC | libc::MS_PRIVATE,
                std::ptr::null(),
            ) != 0
            {
                return Err(std::io::Error::last_os_error());
            }
            self.view.apply()
        }
    }
}

/// Sets both the soft and the hard limit of `resource` (a plain system call: safe after fork).
fn limit(resource: libc::__rlimit_resource_t, value: u64) {
    let rl = libc::rlimit {
        rlim_cur: value as libc::rlim_t,
        rlim_max: value as libc::rlim_t,
    };
    // SAFETY: a plain system call with a valid pointer.
    unsafe {
        libc::setrlimit(resource, &rl);
    }
}
