//! The fallback's own view of the file system, made by its child in a mount namespace of its
//! own (a root harness without bubblewrap): the same view as bubblewrap's ([`crate::sandbox::view`]), on
//! a new root that replaces the host's (`pivot_root`).
//!
//! Promises:
//! - Everything is prepared before the fork ([`ViewPlan::new`]: every path, option and step);
//!   [`ViewPlan::apply`], in the child, makes only system calls (mkdir, open, mount,
//!   mount_setattr, symlink, pivot_root, umount2, chdir) and allocates nothing.
//! - The new root is a small tmpfs mounted on an empty folder of the harness
//!   ([`ViewPlan::new`]'s `root`), read-only once made. It holds the system view and the exposed
//!   paths (read-only, recursively), a minimal `/dev` (`null`, `zero`, `full`, `random`,
//!   `urandom`, `tty`; no `/dev/shm`), a `/proc` mounted `hidepid=2` (the code sees only its own
//!   processes), a `/tmp` that is a tmpfs of bounded size, the sandbox folder at its own path
//!   (writable), and every rtoracle binary of the view covered with `/dev/null`.
//! - A step that hides or makes read-only is required: when it fails, [`ViewPlan::apply`]
//!   fails and the code does not run (fail closed). A missing optional path (an `/etc` file, an
//!   exposed path that went away) is left out.

use std::ffi::CString;
use std::os::unix::ffi::OsStrExt;
use std::path::{Path, PathBuf};

use crate::sandbox::view::{SystemEntry, View, system};

/// The device nodes of the minimal `/dev`.
const DEVICES: [&str; 6] = ["null", "zero", "full", "random", "urandom", "tty"];

/// The links of the minimal `/dev`.
const DEV_LINKS: [(&str, &str); 4] = [
    ("fd", "/proc/self/fd"),
    ("stdin", "/proc/self/fd/0"),
    ("stdout", "/proc/self/fd/1"),
    ("stderr", "/proc/self/fd/2"),
];

/// One step of the view, every string made before the fork.
#[derive(Debug)]
enum Step {
    /// A folder (an error other than "exists" fails it).
    Mkdir(CString),
    /// An empty file to mount a file on.
    Touch(CString),
    /// A symbolic link at the second path to the first.
    Link(CString, CString),
    /// A file system of `kind` (`tmpfs`, `proc`) with `options` at `target`.
    Mount {
        kind: &'static std::ffi::CStr,
        target: CString,
        options: CString,
        flags: libc::c_ulong,
    },
    /// `source` shown at `target`, with what is mounted below it.
    Bind {
        source: CString,
        target: CString,
        mode: BindMode,
    },
    /// `target` and what is mounted below it made read-only.
    ReadOnly(CString),
}

/// What a bind becomes once made.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum BindMode {
    /// Read-only with what is below it: a failure to make it so fails the view, required or
    /// not (a bind must not stay writable).
    ReadOnly,
    /// Writable, without set-user-id programs or devices (the sandbox folder).
    Writable,
    /// As the source is (a device node; `/dev/null` over a binary).
    AsIs,
}

/// How a step went.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Outcome {
    Done,
    /// Not made; harmless where the step is optional.
    NotMade,
    /// Made but not made safe: fails the view.
    Unsafe,
}

/// A step and whether its failure fails the view.
#[derive(Debug)]
struct Planned {
    step: Step,
    required: bool,
}

/// The whole view, ready to be applied in a child.
#[derive(Debug)]
pub(in crate::sandbox) struct ViewPlan {
    root: CString,
    steps: Vec<Planned>,
    /// The sandbox folder, the working directory once the root is swapped.
    dir: CString,
}

/// `path` as a C string (paths never hold a NUL byte; one that did would be skipped).
fn c(path: &Path) -> CString {
    CString::new(path.as_os_str().as_bytes()).unwrap_or_default()
}

/// `root` joined with the absolute `path`.
fn under(root: &Path, path: &Path) -> PathBuf {
    root.join(path.strip_prefix("/").unwrap_or(path))
}

/// Builds the steps, making each target's missing folders first.
struct Planner {
    root: PathBuf,
    made: std::collections::HashSet<PathBuf>,
    steps: Vec<Planned>,
}

impl Planner {
    fn push(&mut self, step: Step, required: bool) {
        self.steps.push(Planned { step, required });
    }

    /// The folders from the root down to `path` (inside the new root), each once.
    fn folders(&mut self, path: &Path, required: bool) {
        let mut missing = Vec::new();
        let mut p = path.to_path_buf();
        while p != self.root && p.starts_with(&self.root) && !self.made.contains(&p) {
            missing.push(p.clone());
            if !p.pop() {
                break;
            }
        }
        for p in missing.into_iter().rev() {
            self.push(Step::Mkdir(c(&p)), required);
            self.made.insert(p);
        }
    }

    /// `source` shown at its own path; a folder or a file (followed, as `mount` does).
    fn show(&mut self, source: &Path, mode: BindMode, required: bool) {
        let target = under(&self.root, source);
        if source.is_dir() {
            self.folders(&target, required);
        } else if source.exists() {
            if let Some(parent) = target.parent() {
                self.folders(parent, required);
            }
            self.push(Step::Touch(c(&target)), required);
        } else {
            return;
        }
        self.push(
            Step::Bind {
                source: c(source),
                target: c(&target),
                mode,
            },
            required,
        );
    }

    fn tmpfs(&mut self, at: &Path, options: String) {
        let target = under(&self.root, at);
        self.folders(&target, true);
        self.push(
            Step::Mount {
                kind: c"tmpfs",
                target: c(&target),
                options: CString::new(options).unwrap_or_default(),
                flags: libc::MS_NOSUID | libc::MS_NODEV,
            },
            true,
        );
    }
}

impl ViewPlan {
    /// The plan of `view` on a new root mounted on `root` (an empty folder), with the sandbox
    /// folder `dir` writable and a `/tmp` of `tmp_bytes`.
    pub(in crate::sandbox) fn new(
        view: &View,
        dir: &Path,
        root: &Path,
        tmp_bytes: u64,
    ) -> ViewPlan {
        let mut p = Planner {
            root: root.to_path_buf(),
            made: Default::default(),
            steps: Vec::new(),
        };
        p.push(
            Step::Mount {
                kind: c"tmpfs",
                target: c(root),
                options: c"size=4m,mode=0755".to_owned(),
                flags: libc::MS_NOSUID | libc::MS_NODEV,
            },
            true,
        );
        p.made.insert(root.to_path_buf());
        for entry in system() {
            match entry {
                SystemEntry::Link(at, to) => {
                    let to = CString::new(to.as_bytes()).unwrap_or_default();
                    p.push(Step::Link(to, c(&under(root, &at))), false);
                }
                SystemEntry::Shown(path) => {
                    let required = path == Path::new("/usr");
                    p.show(&path, BindMode::ReadOnly, required);
                }
            }
        }
        p.tmpfs(Path::new("/dev"), "size=64k,mode=0755".into());
        for d in DEVICES {
            p.show(&Path::new("/dev").join(d), BindMode::AsIs, false);
        }
        for (name, to) in DEV_LINKS {
            let at = under(root, &Path::new("/dev").join(name));
            p.push(
                Step::Link(CString::new(to).unwrap_or_default(), c(&at)),
                false,
            );
        }
        // `/dev/shm`: made before `/dev` is read-only, mounted after (a tmpfs of its own, so it
        // stays writable), as bubblewrap's.
        p.folders(&under(root, Path::new("/dev/shm")), true);
        p.push(Step::ReadOnly(c(&under(root, Path::new("/dev")))), true);
        p.tmpfs(
            Path::new("/dev/shm"),
            format!("size={},mode=1777", crate::sandbox::start::bwrap::SHM_BYTES),
        );
        let proc_dir = under(root, Path::new("/proc"));
        p.folders(&proc_dir, true);
        p.push(
            Step::Mount {
                kind: c"proc",
                target: c(&proc_dir),
                options: c"hidepid=2".to_owned(),
                flags: libc::MS_NOSUID | libc::MS_NODEV | libc::MS_NOEXEC,
            },
            true,
        );
        p.tmpfs(Path::new("/tmp"), format!("size={tmp_bytes},mode=1777"));
        for e in &view.exposed {
            p.show(e, BindMode::ReadOnly, false);
        }
        p.show(dir, BindMode::Writable, true);
        for h in &view.hidden {
            p.push(
                Step::Bind {
                    source: c"/dev/null".to_owned(),
                    target: c(&under(root, h)),
                    mode: BindMode::AsIs,
                },
                true,
            );
        }
        ViewPlan {
            root: c(root),
            steps: p.steps,
            dir: c(dir),
        }
    }

    /// Makes the view and moves the process into it: the new root replaces `/`, read-only,
    /// and the working directory is the sandbox folder. `Err` when a required step failed.
    ///
    /// # Safety
    /// Only in a child between `fork` and `exec`, in a mount namespace of its own whose mounts
    /// are private: it makes only system calls and allocates nothing.
    pub(in crate::sandbox) unsafe fn apply(&self) -> std::io::Result<()> {
        for planned in &self.steps {
            // SAFETY: the caller's contract.
            match unsafe { run(&planned.step) } {
                Outcome::Done => {}
                Outcome::NotMade if !planned.required => {}
                Outcome::NotMade | Outcome::Unsafe => {
                    return Err(std::io::Error::last_os_error());
                }
            }
        }
        // SAFETY: the caller's contract; plain system calls on strings made before the fork.
        unsafe {
            if libc::chdir(self.root.as_ptr()) != 0
                || libc::mkdir(c".old".as_ptr(), 0o700) != 0
                || libc::syscall(libc::SYS_pivot_root, c".".as_ptr(), c".old".as_ptr()) != 0
                || libc::chdir(c"/".as_ptr()) != 0
                || libc::umount2(c"/.old".as_ptr(), libc::MNT_DETACH) != 0
                || libc::rmdir(c"/.old".as_ptr()) != 0
                || !read_only(c"/", false)
                || libc::chdir(self.dir.as_ptr()) != 0
            {
                return Err(std::io::Error::last_os_error());
            }
        }
        Ok(())
    }
}

/// Makes `target` (and, when `recursive`, what is mounted below it) read-only
/// (`mount_setattr`, Linux 5.12).
///
/// # Safety
/// A plain system call; safe after fork.
unsafe fn read_only(target: &std::ffi::CStr, recursive: bool) -> bool {
    const MOUNT_ATTR_RDONLY: u64 = 1;
    let attr: [u64; 4] = [MOUNT_ATTR_RDONLY, 0, 0, 0];
    let flags = if recursive { libc::AT_RECURSIVE } else { 0 };
    // SAFETY: a valid path and attribute struct of the size given.
    unsafe {
        libc::syscall(
            libc::SYS_mount_setattr,
            libc::AT_FDCWD,
            target.as_ptr(),
            flags as libc::c_uint,
            attr.as_ptr(),
            std::mem::size_of_val(&attr),
        ) == 0
    }
}

/// Runs one step.
///
/// # Safety
/// As [`ViewPlan::apply`].
unsafe fn run(step: &Step) -> Outcome {
    let null = std::ptr::null::<libc::c_char>();
    let made = |ok: bool| if ok { Outcome::Done } else { Outcome::NotMade };
    // SAFETY: the caller's contract; plain system calls on strings made before the fork.
    unsafe {
        match step {
            Step::Mkdir(p) => made(
                libc::mkdir(p.as_ptr(), 0o755) == 0 || *libc::__errno_location() == libc::EEXIST,
            ),
            Step::Touch(p) => {
                let fd = libc::open(
                    p.as_ptr(),
                    libc::O_WRONLY | libc::O_CREAT | libc::O_CLOEXEC,
                    0o644,
                );
                made(fd >= 0 && libc::close(fd) == 0)
            }
            Step::Link(to, at) => made(libc::symlink(to.as_ptr(), at.as_ptr()) == 0),
            Step::Mount {
                kind,
                target,
                options,
                flags,
            } => made(
                libc::mount(
                    kind.as_ptr(),
                    target.as_ptr(),
                    kind.as_ptr(),
                    *flags,
                    options.as_ptr().cast(),
                ) == 0,
            ),
            Step::Bind {
                source,
                target,
                mode,
            } => {
                let bound = libc::mount(
                    source.as_ptr(),
                    target.as_ptr(),
                    null,
                    libc::MS_BIND | libc::MS_REC,
                    std::ptr::null(),
                ) == 0;
                let safe = match mode {
                    _ if !bound => true,
                    BindMode::ReadOnly => read_only(target, true),
                    BindMode::Writable => {
                        libc::mount(
                            null,
                            target.as_ptr(),
                            null,
                            libc::MS_REMOUNT | libc::MS_BIND | libc::MS_NOSUID | libc::MS_NODEV,
                            std::ptr::null(),
                        ) == 0
                    }
                    BindMode::AsIs => true,
                };
                match (bound, safe) {
                    (true, true) => Outcome::Done,
                    (true, false) => Outcome::Unsafe,
                    (false, _) => Outcome::NotMade,
                }
            }
            Step::ReadOnly(p) => {
                if read_only(p, true) {
                    Outcome::Done
                } else {
                    Outcome::Unsafe
                }
            }
        }
    }
}
