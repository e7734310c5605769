//! Ends what a sandbox's code started: its process groups, every process of its uid, and
//! everything in its cgroup.

use std::path::PathBuf;
use std::process::Child;
use std::sync::{Arc, Mutex};

use crate::sandbox::identity;

/// Ends what a sandbox's code started: its process groups and, for a per-submission uid, every
/// process of that uid. Cheap to clone; usable after the sandbox is gone.
#[derive(Clone, Debug)]
pub struct Reaper {
    pub(in crate::sandbox) uid: Option<u32>,
    pub(in crate::sandbox) groups: Arc<Mutex<Vec<i32>>>,
    /// The sandbox's cgroup, whose `cgroup.kill` ends every process in it.
    pub(in crate::sandbox) cgroup: Option<PathBuf>,
}

impl Reaper {
    /// Kills every process group spawned so far and every process of the uid.
    pub fn reap(&self) {
        let groups = self.groups.lock().map(|g| g.clone()).unwrap_or_default();
        for pgid in groups {
            // SAFETY: plain system call; a group that is gone gives ESRCH.
            unsafe {
                libc::killpg(pgid, libc::SIGKILL);
            }
        }
        if let Some(cgroup) = &self.cgroup {
            let _ = std::fs::write(cgroup.join("cgroup.kill"), "1");
        }
        if let Some(uid) = self.uid {
            identity::kill_all(uid);
        }
    }

    /// Records a spawned child (the leader of its own process group).
    pub fn track(&self, pid: u32) {
        if let Ok(mut g) = self.groups.lock() {
            g.push(pid as i32);
        }
    }

    /// Forgets a child once it is reaped (its pid may be reused: never signal it again).
    pub fn untrack(&self, pid: u32) {
        if let Ok(mut g) = self.groups.lock() {
            g.retain(|&p| p != pid as i32);
        }
    }
}

/// Kills a child spawned from [`Sandbox::command`](crate::sandbox::lifecycle::Sandbox::command) and everything in its process group, and
/// reaps it.
pub fn kill_group(child: &mut Child) {
    // SAFETY: the child leads its own process group (setsid) and is not reaped yet, so its pid
    // is still that group's id.
    unsafe {
        libc::killpg(child.id() as libc::pid_t, libc::SIGKILL);
    }
    let _ = child.kill();
    let _ = child.wait();
}
