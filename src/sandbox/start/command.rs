//! The command that runs a program inside a sandbox: under bubblewrap (its options through a
//! pipe, its first process admitted only once limited) or directly, with the code's cleared
//! environment, its folder, and the child's set-up between fork and exec.

use std::ffi::OsString;
use std::os::fd::{AsRawFd, OwnedFd};
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Arc;

use crate::sandbox::bounds::ipc::Limits as IpcLimits;
use crate::sandbox::identity::running_as_root;
use crate::sandbox::lifecycle::InfoSlot;
use crate::sandbox::lifecycle::Sandbox;
use crate::sandbox::policy::Isolation;
use crate::sandbox::start::admission;
use crate::sandbox::start::bwrap;
use crate::sandbox::start::child::{ChildSetup, Fallback};
use crate::sandbox::start::pivot::ViewPlan;
use crate::sandbox::view::{self, View};

/// The `PATH` inside the sandbox (the harness's own `PATH` may lead to a root-only Python).
pub const SANDBOX_PATH: &str = "/usr/local/bin:/usr/bin:/bin";

/// Environment variables passed through when set (older OpenBLAS builds need them on some
/// processors, and numpy loads OpenBLAS).
const PASSED_THROUGH: [&str; 2] = ["OPENBLAS_CORETYPE", "OPENBLAS_L2_SIZE"];

impl Sandbox {
    /// The environment of the code.
    fn env(&self) -> Vec<(&'static str, OsString)> {
        let inside = self.inside_dir().into_os_string();
        let tmp: OsString = match self.isolation {
            Isolation::Bubblewrap => "/tmp".into(),
            _ => inside.clone(),
        };
        let path: OsString = match self.isolation {
            Isolation::Unsandboxed => {
                std::env::var_os("PATH").unwrap_or_else(|| SANDBOX_PATH.into())
            }
            _ => SANDBOX_PATH.into(),
        };
        let mut env = vec![
            ("PATH", path),
            ("HOME", inside),
            ("TMPDIR", tmp),
            ("LANG", "C.UTF-8".into()),
            ("LC_ALL", "C.UTF-8".into()),
            ("PYTHONDONTWRITEBYTECODE", "1".into()),
            ("PYTHONHASHSEED", "0".into()),
            ("PYTHONIOENCODING", "utf-8".into()),
            ("PYTHONNOUSERSITE", "1".into()),
            ("PYTHONUNBUFFERED", "1".into()),
        ];
        for k in PASSED_THROUGH {
            if let Some(v) = std::env::var_os(k) {
                env.push((k, v));
            }
        }
        env
    }

    /// What the code sees of the host where it has a view of its own: the exposed paths and
    /// `program`'s, with the rtoracle binaries among them covered.
    fn view_of(&self, program: &Path) -> View {
        let mut exposed = self.exposed.clone();
        exposed.extend(view::exposure(program));
        View::new(exposed)
    }

    /// A command for `program` that runs inside the sandbox: under bubblewrap (`bwrap ...
    /// program`) or directly, with the folder as working directory, a cleared environment, its
    /// own session and process group, the limits and the identity. A bare program name is looked
    /// up on [`SANDBOX_PATH`] (the harness's `PATH` when unsandboxed).
    pub fn command(&self, program: &Path) -> Command {
        let env = self.env();
        let (mut cmd, keep) = match self.isolation {
            Isolation::Bubblewrap => self.bubblewrap_command(program, &env),
            _ => {
                let mut cmd = Command::new(program);
                cmd.current_dir(self.dir()).env_clear();
                for (k, v) in &env {
                    cmd.env(k, v);
                }
                (cmd, Vec::new())
            }
        };
        let fallback = match (self.isolation, &self.view_root) {
            (Isolation::FallbackUid, Some(root)) => Some(Fallback {
                network: self.policy.isolate_network,
                ipc: IpcLimits::for_memory(self.policy.memory_bytes),
                view: ViewPlan::new(
                    &self.view_of(program),
                    self.dir(),
                    root.path(),
                    self.policy.tmp_bytes(),
                ),
            }),
            _ => None,
        };
        let cgroup = self.cgroup.as_ref().map(|g| g.procs_file().clone());
        let setup = ChildSetup::new(&self.policy, self.switch_to, fallback, keep, cgroup);
        // SAFETY: `run` is made for this place (see its contract): it only makes
        // async-signal-safe system calls and allocates nothing.
        unsafe {
            cmd.pre_exec(move || setup.run());
        }
        cmd
    }

    /// `bwrap OPTIONS program`, and the descriptors its child must keep open: bubblewrap reports
    /// on one pipe and waits on another until the admission thread has set the limits of its
    /// first process ([`admission`]); its options come through a third.
    fn bubblewrap_command(
        &self,
        program: &Path,
        env: &[(&'static str, OsString)],
    ) -> (Command, Vec<i32>) {
        let bwrap = bwrap::program().unwrap_or_else(|| PathBuf::from("/usr/bin/bwrap"));
        let mut cmd = Command::new(bwrap);
        let view = self.view_of(program);
        let (uid, gid) = self.switch_to.unwrap_or_else(|| {
            // SAFETY: getuid and getgid have no preconditions.
            unsafe { (libc::getuid(), libc::getgid()) }
        });
        let slot = Arc::new(InfoSlot::default());
        let limits = admission::Limits {
            processes: self.switch_to.is_none().then_some(self.policy.processes),
            ipc: running_as_root().then(|| IpcLimits::for_memory(self.policy.memory_bytes)),
        };
        let admission = admission::start(slot.clone(), limits, self.pid_namespaces.clone());
        if admission.is_some() {
            *self.info.lock().unwrap_or_else(|e| e.into_inner()) = Some(slot);
        }
        let words = bwrap::args(&bwrap::Args {
            dir: self.dir(),
            uid,
            gid,
            view: &view,
            tmp_bytes: self.policy.tmp_bytes(),
            env,
            info_fd: admission.as_ref().map(|a| a.info_fd),
            block_fd: admission.as_ref().map(|a| a.block_fd),
        });
        // The options go through a pipe (`--args FD`), so the sandbox's `/proc/1/cmdline` shows
        // none of the host's paths.
        let args_read = args_pipe(&words);
        match &args_read {
            Some(fd) => cmd.arg("--args").arg(fd.as_raw_fd().to_string()),
            None => cmd.args(&words),
        };
        let mut keep: Vec<i32> = admission
            .iter()
            .flat_map(|a| [a.info_fd, a.block_fd])
            .collect();
        keep.extend(args_read.as_ref().map(|fd| fd.as_raw_fd()));
        // The closure owns the parent's copies of the pipes' child ends, so they close when the
        // command is dropped after the spawn. Without the admission's pipes the processes could
        // not be limited: the command then fails (fail closed).
        // SAFETY: the closure makes no system call.
        unsafe {
            cmd.pre_exec(move || {
                let _ = &args_read;
                match &admission {
                    Some(_) => Ok(()),
                    None => Err(std::io::Error::other(
                        "no pipe to admit the sandbox's first process",
                    )),
                }
            });
        }
        cmd.arg(program);
        cmd.current_dir("/").env_clear().env("PATH", SANDBOX_PATH);
        (cmd, keep)
    }
}

/// A pipe holding `words` (each ended by a zero byte) for bubblewrap's `--args`: its read end,
/// or `None` when it cannot be made or the words would not fit its buffer.
fn args_pipe(words: &[OsString]) -> Option<OwnedFd> {
    let (read, write) = admission::cloexec_pipe().ok()?;
    let mut bytes = Vec::new();
    for w in words {
        bytes.extend_from_slice(w.as_encoded_bytes());
        bytes.push(0);
    }
    // Far below a pipe's 64 KiB buffer, so this never blocks.
    if bytes.len() >= 60_000 {
        return None;
    }
    let mut file = std::fs::File::from(write);
    std::io::Write::write_all(&mut file, &bytes).ok()?;
    Some(read)
}
