//! How untrusted code is started: the one place that spawns a candidate or a student's
//! submission (`check --python-course`, `check --adapter`, `fuzz` and `grade` all come here,
//! through [`Session`](crate::candidate::process::session::Session)). What it does, for a reader who
//! runs it: `docs/sandbox.md`.
//!
//! # What it promises
//! - **Never as root.** Untrusted code never runs as uid 0. A root harness gives every
//!   [`Sandbox`](lifecycle::Sandbox) an unprivileged uid and gid of its own ([`identity`]: `2^30 + ...`, no `passwd`
//!   entry needed), so no submission can signal, trace or read another's files; a harness that is
//!   not root runs the code as its own (unprivileged) user. When no unprivileged identity can be
//!   used, [`Sandbox::new`](lifecycle::Sandbox::new) fails ([`SandboxError::Unavailable`](policy::SandboxError::Unavailable)): `grade` exits 2, and so do
//!   `check` and `fuzz` unless `--unsandboxed` asks to run one's own code without a sandbox
//!   ([`Isolation::Unsandboxed`](policy::Isolation::Unsandboxed), which the facts and the output then say).
//! - **A real sandbox where one can be made: bubblewrap** ([`Isolation::Bubblewrap`](policy::Isolation::Bubblewrap)). bubblewrap
//!   is probed once per process (it fails in containers that refuse user namespaces). The code
//!   runs in new user, PID, mount, IPC, network, UTS (and cgroup, where allowed) namespaces, with
//!   `--die-with-parent`, `--new-session`, `--disable-userns`, `--cap-drop ALL`, a cleared
//!   environment and a view of its own ([`view`], [`start::bwrap`]): the system's `/usr` and `/lib*`,
//!   the loader's `/etc` files, a read-only `/dev` (but a 4 MiB tmpfs at `/dev/shm`, for
//!   `multiprocessing`), a `/tmp` that is a tmpfs of bounded size, the
//!   sandbox folder at `/sandbox`, and the paths exposed read-only (an interpreter and its
//!   library tree; for an `--adapter` its program's and its files' folders, and those
//!   `--expose` names). Its root is read-only. Nothing of the grader is visible: not its binary,
//!   the rubric, the vectors, the reports, the batch folder, another submission, `/root` or
//!   `/home`. bubblewrap itself runs as the submission's uid (the switch happens before it is
//!   executed), so even outside its user namespace the code is that uid.
//! - **A fallback where bubblewrap cannot run** ([`Isolation::FallbackUid`](policy::Isolation::FallbackUid), root only): the
//!   limits, its own session, the per-submission uid and gid, with the sandbox folder owned by
//!   that uid, mode `0700`, and, each where the kernel allows it (attempted, verified from
//!   `/proc/<pid>/ns`, never assumed): a network namespace, an IPC namespace with its limits
//!   ([`bounds::ipc`]; System V objects die with it, and are swept by owner where it cannot be made),
//!   and a mount namespace in which the child builds the same view as bubblewrap's on a new root
//!   (`pivot_root`, `pivot`), with a `/proc` mounted `hidepid=2` (the code sees only its own
//!   processes: not the grader's command line, which names its binary, rubric and folders).
//!   Where no namespace can be made (`RTORACLE_SANDBOX=uid-bare`) the code sees the host's
//!   world-readable files and processes: what it must not read is made unreadable by others
//!   while `grade` runs ([`keep_from_sandboxes`](originals::keep_from_sandboxes)), and no rtoracle binary runs for it
//!   ([`oracles::refusal`]). [`Isolation::CurrentUser`](policy::Isolation::CurrentUser) is the fallback without the uid switch
//!   and the namespaces, for a harness that is not root.
//! - **Limits** in every mode, set with `setrlimit` between `fork` and `exec` (inherited through
//!   bubblewrap): CPU time, address space, open files, file size, POSIX message queues, no core
//!   files, and a process count (threads included) for a per-submission uid. Under bubblewrap
//!   the count holds for any harness: bubblewrap's first process waits (`--block-fd`) until the
//!   harness has set `RLIMIT_NPROC` on it, which inside its own user namespace counts the
//!   sandbox's processes alone (a harness that is not root gave a fork bomb no limit: 1527 forks
//!   in 2 s); where it cannot be set, that process is killed. File descriptors other than the
//!   standard three are closed.
//! - **Every byte it holds bounded and counted, nothing left** ([`bounds::watchdog`], [`bounds::held`],
//!   [`bounds::scratch`], [`bounds::ipc`]): a watchdog ends the code once its files (its folder, its `/tmp`
//!   tmpfs, what a per-submission uid owns in the host's world-writable folders, the unlinked
//!   files and memfds its processes hold open) pass the policy's `disk_bytes`, or the resident
//!   memory of all its processes and its System V shared memory together pass `memory_bytes`;
//!   the tmpfs's size and the IPC namespace's `shmall` bound them between two ticks, and
//!   cgroups v2 where the host delegates them ([`bounds::cgroup`]). What a uid left in the host's
//!   folders and IPC namespace is swept when the sandbox goes.
//! - **No rtoracle binary reachable** ([`oracles`]): every rtoracle binary the view would show
//!   is covered with an empty file, found by inode or content, never by name.
//! - **Nothing outlives it.** [`Sandbox::reaper`](lifecycle::Sandbox::reaper) ends every process the code started: the PID
//!   namespace dies with bubblewrap (killed with its process group), a per-submission uid is
//!   swept with [`identity::kill_all`] (double-forked `setsid` sleepers included), and a cgroup
//!   is killed whole. Dropping the sandbox does all that and removes its folder; while it
//!   exists, the same cleanup is registered with [`crate::interrupt::on_interrupt`], so Ctrl-C
//!   and SIGTERM leave nothing behind.
//! - **Truthful facts** ([`SandboxFacts`](facts::SandboxFacts)): which isolation was used, the namespaces that were
//!   seen made (bubblewrap's `--info-fd` compared with the harness's own namespaces), the uid,
//!   the cgroup only when the code was seen in it, and `network_isolated` only when verified.
//!   [`announce_on_stderr`](facts::announce_on_stderr) makes the first session of a run say it once on stderr, e.g.
//!   `rtoracle: sandbox: bubblewrap (user, pid, net, ipc, mount, uts namespaces), uid
//!   1073741824 (one per submission)`.
//!
//! `RTORACLE_SANDBOX` forces a mode ([`Mode`](policy::Mode)): `bubblewrap` (an error where it does not work),
//! `uid` (the fallback even where bubblewrap works), `uid-bare` (the fallback without any
//! namespace, as in a container that refuses them), `none` (as on a host where neither works: a
//! root harness then refuses to run untrusted code), `auto` (the default).
//!
//! # Why bubblewrap
//! It is the established tool for this (Flatpak's sandbox; Debian package `bubblewrap`), small
//! and audited, needs no daemon, no configuration file and no setuid bit (it uses unprivileged
//! user namespaces), and it works as root and as an ordinary user on these machines. The
//! alternatives: nsjail (stronger seccomp policies, but not packaged in Debian 12 and configured
//! through protobuf files), firejail (setuid-root with a large attack surface and a history of
//! privilege escalations), the `landlock` crate (filesystem rules only: no PID or network
//! isolation, and kernel >= 5.13), `hakoniwa` (a young crate re-implementing what bubblewrap
//! does, with far fewer users).
//!
//! # Where each part lives
//! The rooms below, bottom floor first (each uses only those above it in this list):
//! [`identity`] (uids, the processes a uid has); [`bounds`] (what the code may write where, what
//! its processes hold, its IPC, its cgroup, the watchdog that enforces the limits while it runs,
//! and the [`Reaper`](bounds::reaper::Reaper)); [`oracles`] (rtoracle binaries); [`view`] (what
//! the code sees of the host, and its paths told in the user's terms); [`policy`] (limits,
//! modes, isolations); [`lifecycle`] (a [`Sandbox`](lifecycle::Sandbox): its folder, identity,
//! watchdog and cleanup); `probe` (trusted helpers run inside); [`start`] (the command that runs
//! a program inside, [`Sandbox::command`](lifecycle::Sandbox::command): bubblewrap's command
//! line, the child between fork and exec, the fallback's view made in the child, and
//! bubblewrap's first process limited before it goes on); [`detect`] (which isolation works
//! here, and [`Sandbox::new`](lifecycle::Sandbox::new)); [`facts`]
//! ([`SandboxFacts`](facts::SandboxFacts)); [`originals`]
//! ([`keep_from_sandboxes`](originals::keep_from_sandboxes)).

pub mod identity;
pub mod bounds;
pub mod oracles;
pub mod view;
pub mod policy;
pub mod lifecycle;
mod probe;
pub mod start;
pub mod detect;
pub mod facts;
pub mod originals;

#[cfg(test)]
mod tests;
