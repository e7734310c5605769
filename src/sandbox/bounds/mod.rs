//! Keeping the code within its bounds while it runs: what it may write where and how that is
//! measured ([`scratch`]), its processes and what they hold ([`held`]), its IPC ([`ipc`]), its
//! cgroup where the host delegates one ([`cgroup`]), the watchdog that measures all of it every
//! tick ([`watchdog`]), and the reaper that ends what it started (`reaper`).

pub mod cgroup;
pub mod ipc;
pub mod held;
pub mod reaper;
pub mod scratch;
pub mod watchdog;
