//! How a candidate is run ([`RunOptions`]): per-case and hello time-outs, when a shape group
//! stops, the sandbox's limits and the session's time budget.

use std::time::Duration;

use crate::sandbox::policy::SandboxPolicy;

/// How a candidate is run.
#[derive(Clone, Debug, PartialEq)]
pub struct RunOptions {
    /// Time allowed for one case, counted from the answer to the previous one.
    pub timeout: Duration,
    /// Time allowed for starting and answering the hello (imports happen here).
    pub hello_timeout: Duration,
    /// After this many timeouts in a shape group the rest of the group is not run.
    pub max_timeouts_per_group: u32,
    /// After this many crashes in a shape group the rest of the group is not run.
    pub max_crashes_per_group: u32,
    /// The sandbox's limits and switches.
    pub limits: SandboxPolicy,
    /// Wall time allowed for the whole session (the hello and every case, restarts included):
    /// past it the cases not yet answered are `not_run` with the reason. `None`: no limit.
    pub budget: Option<Duration>,
}

impl Default for RunOptions {
    fn default() -> Self {
        RunOptions {
            timeout: Duration::from_secs(2),
            hello_timeout: Duration::from_secs(10),
            max_timeouts_per_group: 3,
            max_crashes_per_group: 50,
            limits: SandboxPolicy::default(),
            budget: None,
        }
    }
}
