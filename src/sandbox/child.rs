//! What a sandbox's child does between `fork` and `exec`, before any untrusted code runs: its
//! own session, no inherited descriptors, the fallback's namespaces and read-only view, the
//! limits, the identity, and death with the harness.

use std::ffi::CString;
use std::path::Path;

use super::policy::SandboxPolicy;
use super::scratch;

/// Everything the child's set-up needs, made before the fork (after it, nothing may allocate).
#[derive(Debug)]
pub(super) struct ChildSetup {
    policy: SandboxPolicy,
    /// `(uid, gid)` to switch to.
    switch_to: Option<(u32, u32)>,
    /// The fallback's namespaces and view are attempted.
    fallback: bool,
    /// A network namespace is attempted.
    unshare_net: bool,
    /// Descriptors the child keeps open (bubblewrap's pipes); every other one but 0, 1, 2 closes.
    keep: Vec<i32>,
    /// The grader's binary, covered with `/dev/null` in the fallback's mount namespace.
    hide_exe: Option<CString>,
    /// The mounts made writable again in the fallback's read-only view.
    writable: Vec<CString>,
    /// The sandbox folder (the working directory).
    own_dir: Option<CString>,
    /// The harness's pid, to notice it died before the parent-death signal was armed.
    parent: libc::pid_t,
}

impl ChildSetup {
    /// The set-up of a child of the sandbox whose folder is `dir`: under `policy`, switching to
    /// `switch_to`, with the fallback's namespaces when `fallback`, keeping `keep` open.
    pub(super) fn new(
        policy: &SandboxPolicy,
        switch_to: Option<(u32, u32)>,
        fallback: bool,
        dir: &Path,
        keep: Vec<i32>,
    ) -> ChildSetup {
        // The fallback's own view where a mount namespace can be made: a `/proc` that shows
        // only the code's processes (`hidepid=2`), and the grader's binary as an empty file.
        let hide_exe = std::env::current_exe()
            .ok()
            .and_then(|p| CString::new(p.into_os_string().into_encoded_bytes()).ok());
        // ... and the host read-only but the sandbox folder and the shared folders (`/tmp`, ...:
        // where the watchdog measures and the sweep cleans what the uid writes).
        let mut writable: Vec<CString> = scratch::SHARED_ROOTS
            .iter()
            .filter(|r| Path::new(r).is_dir())
            .filter_map(|r| CString::new(*r).ok())
            .collect();
        let own_dir = CString::new(dir.as_os_str().as_encoded_bytes()).ok();
        if let Some(d) = &own_dir
            && !scratch::SHARED_ROOTS.iter().any(|r| dir.starts_with(r))
        {
            writable.push(d.clone());
        }
        ChildSetup {
            policy: policy.clone(),
            switch_to,
            fallback,
            unshare_net: fallback && policy.isolate_network,
            keep,
            hide_exe,
            writable,
            own_dir,
            parent: std::process::id() as libc::pid_t,
        }
    }

    /// Sets the child up: a new session, every inherited descriptor but 0, 1, 2 (and those kept)
    /// closed on exec, the fallback's namespaces, the limits, the identity, `SIGKILL` when the
    /// harness dies.
    ///
    /// # Safety
    /// Only in the child between `fork` and `exec` (`pre_exec`): it makes only
    /// async-signal-safe system calls (setsid, unshare, mount, mount_setattr, chdir,
    /// setrlimit, setgroups, setgid, setuid, prctl, getppid, fcntl, close_range) and
    /// allocates nothing.
    pub(super) unsafe fn run(&self) -> std::io::Result<()> {
        // SAFETY: the caller's contract; each call is a plain system call on owned data.
        unsafe {
            if libc::setsid() < 0 {
                return Err(std::io::Error::last_os_error());
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
            if self.unshare_net {
                // Best effort: fails without CAP_SYS_ADMIN, which the facts show.
                let _ = libc::unshare(libc::CLONE_NEWNET);
            }
            #[cfg(target_os = "linux")]
            if self.fallback {
                self.fallback_view();
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

    /// The fallback's namespaces, each best effort and verified by the facts: an IPC namespace
    /// (System V objects die with it), and a mount namespace whose mounts never reach the
    /// host's (made private first, or nothing is mounted), with a `/proc` mounted `hidepid=2`,
    /// the grader's binary covered, every mount read-only (`mount_setattr`, Linux 5.12) but the
    /// folder and the shared folders, made writable again at their own paths, and the working
    /// directory moved onto those mounts.
    ///
    /// # Safety
    /// As [`ChildSetup::run`].
    #[cfg(target_os = "linux")]
    unsafe fn fallback_view(&self) {
        // SAFETY: the caller's contract; each call is a plain system call on owned data.
        unsafe {
            let _ = libc::unshare(libc::CLONE_NEWIPC);
            let null = std::ptr::null::<libc::c_char>();
            if libc::unshare(libc::CLONE_NEWNS) != 0
                || libc::mount(
                    null,
                    c"/".as_ptr(),
                    null,
                    libc::MS_REC | libc::MS_PRIVATE,
                    std::ptr::null(),
                ) != 0
            {
                return;
            }
            libc::mount(
                c"proc".as_ptr(),
                c"/proc".as_ptr(),
                c"proc".as_ptr(),
                libc::MS_NOSUID | libc::MS_NODEV | libc::MS_NOEXEC,
                c"hidepid=2".as_ptr().cast(),
            );
            if let Some(exe) = &self.hide_exe {
                libc::mount(
                    c"/dev/null".as_ptr(),
                    exe.as_ptr(),
                    null,
                    libc::MS_BIND,
                    std::ptr::null(),
                );
            }
            let Some(dir) = &self.own_dir else {
                return;
            };
            const MOUNT_ATTR_RDONLY: u64 = 1;
            let attr: [u64; 4] = [MOUNT_ATTR_RDONLY, 0, 0, 0];
            if libc::syscall(
                libc::SYS_mount_setattr,
                libc::AT_FDCWD,
                c"/".as_ptr(),
                libc::AT_RECURSIVE as libc::c_uint,
                attr.as_ptr(),
                std::mem::size_of_val(&attr),
            ) != 0
            {
                return;
            }
            for path in &self.writable {
                let p = path.as_ptr();
                if libc::mount(p, p, null, libc::MS_BIND | libc::MS_REC, std::ptr::null()) == 0 {
                    libc::mount(
                        null,
                        p,
                        null,
                        libc::MS_REMOUNT | libc::MS_BIND | libc::MS_NOSUID | libc::MS_NODEV,
                        std::ptr::null(),
                    );
                }
            }
            libc::chdir(dir.as_ptr());
        }
    }

    /// CPU time, address space, open files, file size, no core files.
    fn set_limits(&self) {
        let p = &self.policy;
        limit(libc::RLIMIT_CPU, p.cpu_seconds);
        limit(libc::RLIMIT_AS, p.memory_bytes);
        limit(libc::RLIMIT_NOFILE, p.open_files);
        limit(libc::RLIMIT_FSIZE, p.file_size_bytes);
        limit(libc::RLIMIT_CORE, 0);
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
