//! What a sandbox did, told truthfully: the isolation used, the namespaces seen made (never
//! assumed), the uid, for the report ([`SandboxFacts`]) and once on stderr ([`announce`]).

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use serde::{Deserialize, Serialize};

use super::identity::running_as_root;
use super::lifecycle::Sandbox;
use super::policy::{Isolation, SandboxPolicy};
use super::start::bwrap;

/// What the sandbox did, for the report.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SandboxFacts {
    /// The policy.
    pub policy: SandboxPolicy,
    /// Which isolation was used.
    pub isolation: Isolation,
    /// The namespaces the candidate was seen in that differ from the harness's (`user`, `pid`,
    /// `net`, `ipc`, `mount`, `uts`), as verified after it started; empty when not looked at. In
    /// the fallback, `mount` is listed only when its `/proc` was also seen mounted `hidepid`.
    #[serde(default)]
    pub namespaces: Vec<String>,
    /// The user id the code ran as, seen from outside any user namespace.
    pub uid: u32,
    /// A remark for the reader (why this isolation and not a stronger one).
    pub note: Option<String>,
    /// Whether the candidate was seen in a network namespace of its own (`None`: not verified).
    pub network_isolated: Option<bool>,
    /// The code's cgroup v2 and its limits, where cgroups are delegated and the code was seen
    /// in it (absent otherwise: the other limits hold alone).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cgroup: Option<String>,
    /// Files of the submission not copied into the sandbox, each named (control characters
    /// escaped) with why: links, FIFOs, devices, files over the size caps.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub skipped_files: Vec<String>,
}

impl SandboxFacts {
    /// One line for stderr: `bubblewrap (user, pid, net, ... namespaces), uid N`.
    pub fn summary(&self) -> String {
        let ns = if self.namespaces.is_empty() {
            "no namespaces verified".to_string()
        } else {
            format!("{} namespaces", self.namespaces.join(", "))
        };
        let mut line = match self.isolation {
            Isolation::Bubblewrap => format!("bubblewrap ({ns}), uid {}", self.uid),
            Isolation::FallbackUid => {
                let mut parts = vec!["limits".to_string(), "own session".to_string()];
                if self.network_isolated != Some(true) {
                    parts.push("network NOT isolated".into());
                }
                if !self.namespaces.is_empty() {
                    parts.push(format!("{} namespaces", self.namespaces.join(", ")));
                }
                if self.namespaces.iter().any(|n| n == "mount") {
                    parts.push("/proc shows only its processes".into());
                    parts.push("read-only but its folder and /tmp".into());
                }
                format!("fallback-uid ({}), uid {}", parts.join(", "), self.uid)
            }
            Isolation::CurrentUser => format!(
                "current-user (limits, own session, no namespaces), uid {}",
                self.uid
            ),
            Isolation::Unsandboxed => format!(
                "UNSANDBOXED by request (--unsandboxed): limits only, uid {}",
                self.uid
            ),
        };
        if let Some(note) = self
            .note
            .as_ref()
            .filter(|_| self.isolation != Isolation::Unsandboxed)
        {
            line.push_str("; ");
            line.push_str(note);
        }
        line
    }
}

static ANNOUNCE: AtomicBool = AtomicBool::new(false);
static ANNOUNCED: AtomicBool = AtomicBool::new(false);

/// Makes the first sandbox of this process that starts a candidate say which isolation it
/// used, once, on stderr (the binary calls this; a library user stays quiet).
pub fn announce_on_stderr() {
    ANNOUNCE.store(true, Ordering::SeqCst);
}

/// Prints `line` (already escaped) on stderr when [`announce_on_stderr`] was called.
pub fn say(line: &str) {
    if ANNOUNCE.load(Ordering::SeqCst) {
        crate::output::stderr_line(line);
    }
}

/// Prints `facts` once per process when [`announce_on_stderr`] was called.
pub fn announce(facts: &SandboxFacts) {
    if ANNOUNCE.load(Ordering::SeqCst) && !ANNOUNCED.swap(true, Ordering::SeqCst) {
        let per = if facts.isolation != Isolation::Unsandboxed && running_as_root() {
            " (a uid of its own per candidate)"
        } else {
            ""
        };
        crate::output::stderr_line(&format!(
            "rtoracle: sandbox: {}{per}",
            crate::escape::terminal_line(&facts.summary())
        ));
    }
}

impl Sandbox {
    /// The facts of a run, given the id of a child spawned from [`Sandbox::command`]: under
    /// bubblewrap, the namespaces it reports (waiting up to 2 s for its `--info-fd`); in the
    /// fallback, whether the child is in a network namespace of its own.
    pub fn facts(&self, child: Option<u32>) -> SandboxFacts {
        let own_net = std::fs::read_link("/proc/self/ns/net").ok();
        let mut namespaces = Vec::new();
        let mut network_isolated = None;
        match (self.isolation, child) {
            (Isolation::Bubblewrap, Some(_)) => {
                let slot = self.info.lock().unwrap_or_else(|e| e.into_inner()).take();
                if let Some(slot) = slot {
                    let text = slot.wait(Duration::from_secs(2));
                    namespaces = bwrap::made_namespaces(&text).0;
                    network_isolated = Some(namespaces.iter().any(|n| n == "net"));
                }
            }
            (_, Some(pid)) => {
                let theirs = std::fs::read_link(format!("/proc/{pid}/ns/net")).ok();
                if let (Some(mine), Some(theirs)) = (own_net, theirs) {
                    network_isolated = Some(mine != theirs);
                    if mine != theirs {
                        namespaces.push("net".into());
                    }
                }
                if self.isolation == Isolation::FallbackUid {
                    namespaces.extend(fallback_namespaces(pid));
                }
            }
            _ => {}
        }
        let note = match self.isolation {
            Isolation::Unsandboxed => Some(format!(
                "unsandboxed by request (--unsandboxed): the candidate ran as uid {} with limits only",
                self.uid()
            )),
            _ => self.note.clone(),
        };
        let cgroup = match (&self.cgroup, child) {
            (Some(group), Some(pid)) if group.holds(pid) => Some(format!(
                "{} (memory.max {}, cpu.weight {})",
                group.path().display(),
                std::fs::read_to_string(group.path().join("memory.max"))
                    .unwrap_or_default()
                    .trim(),
                super::bounds::cgroup::CPU_WEIGHT
            )),
            _ => None,
        };
        SandboxFacts {
            cgroup,
            policy: self.policy.clone(),
            isolation: self.isolation,
            namespaces,
            uid: self.uid(),
            note,
            network_isolated,
            skipped_files: self.skipped.clone(),
        }
    }
}

/// The IPC and mount namespaces a fallback's process `pid` was seen in, when they differ from
/// the harness's: `mount` only when its `/proc` is also seen mounted with `hidepid` and its `/`
/// read-only (what the mount namespace is for).
fn fallback_namespaces(pid: u32) -> Vec<String> {
    let differs = |ns: &str| {
        let mine = std::fs::read_link(format!("/proc/self/ns/{ns}")).ok();
        let theirs = std::fs::read_link(format!("/proc/{pid}/ns/{ns}")).ok();
        mine.is_some() && theirs.is_some() && mine != theirs
    };
    let mut made = Vec::new();
    if differs("ipc") {
        made.push("ipc".to_string());
    }
    let mountinfo = std::fs::read_to_string(format!("/proc/{pid}/mountinfo")).unwrap_or_default();
    // The last mount at a point is the one seen there; field 5 is the point, 6 its options.
    let at = |point: &str| {
        mountinfo
            .lines()
            .rfind(|l| l.split(' ').nth(4) == Some(point))
            .unwrap_or_default()
            .to_string()
    };
    let proc_line = at("/proc");
    let hidden = proc_line.contains(" - proc ") && proc_line.contains("hidepid=");
    let read_only = at("/")
        .split(' ')
        .nth(5)
        .is_some_and(|o| o.split(',').any(|w| w == "ro"));
    if differs("mnt") && hidden && read_only {
        made.push("mount".to_string());
    }
    made
}
