//! `rtoracle bench <area>`: speed and memory figures, each against a baseline measured in the
//! same run.
//!
//! Each area has its own module under `src/cli/bench/` with a clap `Args` and a `run`, one
//! variant in [`Area`] and one arm in [`run`]. The helpers below (CPU time, a child's peak
//! memory, the machine's load) are shared by all of them.

mod baseline;
mod mitsuba;
mod render;

use std::process::{Command, ExitCode};
use std::time::Duration;

use anyhow::Context;

/// `rtoracle bench <AREA>`
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    area: Area,
}

/// What to measure.
#[derive(Debug, clap::Subcommand)]
enum Area {
    /// The reference tracer: primary rays per second on one thread against a plain C loop
    /// doing the same work, the speedup on all threads, and peak memory per pixel.
    Render(render::Args),
    /// The intersection oracle: reference against exact decisions on random cases across scales
    /// and distances, the naive course formula beside it, classification rate, suite generation.
    Oracle {
        /// Random sphere cases (planes get a fifth as many).
        #[arg(long, value_name = "N", default_value_t = 1_000_000, value_parser = crate::cli::args::count)]
        cases: usize,
    },
    /// Checking candidates: vectors per second through the Python adapter against the in-process
    /// reference and an echo adapter.
    Candidate {
        /// A run of a few seconds (1000 cases, no suites) that shows the benchmark works; not a
        /// measurement.
        #[arg(long)]
        quick: bool,
    },
    /// The image comparison: one 400x400 comparison and the whole command, against a plain
    /// per-pixel difference.
    Compare,
    /// Grading: one submission and a batch of 30 against starting Python once.
    Grade,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    match args.area {
        Area::Render(args) => render::run(args),
        Area::Oracle { cases } => {
            let mut opts = rtoracle::bench::oracle::Options::default();
            if cases != opts.sphere_cases {
                opts.sphere_cases = cases;
                opts.plane_cases = cases / 5;
                opts.silhouette_cases = (cases / 10).max(1000);
            }
            out!("{}", rtoracle::bench::oracle::run(opts))?;
            Ok(ExitCode::SUCCESS)
        }
        Area::Candidate { quick } => {
            let options = if quick {
                rtoracle::bench::harness::Options::quick()
            } else {
                rtoracle::bench::harness::Options::default()
            };
            out!("{}", rtoracle::bench::harness::run(options)?)?;
            Ok(ExitCode::SUCCESS)
        }
        Area::Compare => {
            out!("{}", rtoracle::bench::compare::run())?;
            Ok(ExitCode::SUCCESS)
        }
        Area::Grade => {
            out!("{}", rtoracle::bench::grade::run())?;
            Ok(ExitCode::SUCCESS)
        }
    }
}

/// CPU time used so far by this process, all threads together. Unlike the wall clock it does
/// not count the time other programs hold the cores, so it stays steady on a busy machine.
pub(crate) fn process_cpu_time() -> Duration {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec; the clock id is a constant Linux and the BSDs
    // define.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut ts) };
    if rc != 0 {
        return Duration::ZERO;
    }
    Duration::new(ts.tv_sec as u64, ts.tv_nsec as u32)
}

/// The one-minute load average, when the system says (`/proc/loadavg`).
pub(crate) fn load_average() -> Option<f64> {
    std::fs::read_to_string("/proc/loadavg")
        .ok()?
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

/// Starts `command` so that an interruption (Ctrl-C, SIGTERM) kills it, and whatever it
/// started, before the cleanups remove what it writes into: in a process group of its own,
/// under the spawn gate, with the kill registered before the gate opens. The guard unregisters
/// the kill; keep it until the child has been waited for.
pub(crate) fn spawn_killed_on_interrupt(
    command: &mut Command,
) -> anyhow::Result<(std::process::Child, rtoracle::interrupt::CleanupGuard)> {
    use std::os::unix::process::CommandExt;
    let gate = rtoracle::interrupt::spawn_gate().context("interrupted")?;
    // A group of its own, so the kill reaches what it starts too (a compiler's cc1 and as).
    let child = command
        .process_group(0)
        .spawn()
        .with_context(|| format!("cannot start {}", command.get_program().to_string_lossy()))?;
    let pid = child.id() as libc::pid_t;
    let kill = rtoracle::interrupt::on_interrupt(move || {
        // SAFETY: kill(2) on our own child's process group; at worst the child has exited
        // and not been reaped, which keeps the group's id from being reused.
        unsafe {
            libc::kill(-pid, libc::SIGKILL);
        }
    });
    drop(gate);
    Ok((child, kill))
}

/// Runs `command` to completion and returns its exit status and its peak resident set size in
/// bytes, from `wait4`'s resource usage of that one child (`ru_maxrss`, kilobytes on Linux).
pub(crate) fn run_measuring_peak_rss(
    command: &mut Command,
) -> anyhow::Result<(std::process::ExitStatus, u64)> {
    let (child, _kill) = spawn_killed_on_interrupt(command)?;
    let pid = child.id() as libc::pid_t;
    let mut status: libc::c_int = 0;
    // SAFETY: zeroed memory is a valid `rusage` (plain integers and timevals).
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: `pid` is our own child, not yet waited for; `status` and `usage` are valid and
    // writable. `wait4` reaps it, so `child` is not waited for again (dropping it does not wait).
    let rc = unsafe { libc::wait4(pid, &mut status, 0, &mut usage) };
    if rc != pid {
        anyhow::bail!(
            "cannot wait for {command:?}: {}",
            std::io::Error::last_os_error()
        );
    }
    drop(child);
    use std::os::unix::process::ExitStatusExt;
    let kib = u64::try_from(usage.ru_maxrss).unwrap_or(0);
    // Linux reports kilobytes; macOS reports bytes.
    let bytes = if cfg!(target_os = "macos") {
        kib
    } else {
        kib * 1024
    };
    Ok((std::process::ExitStatus::from_raw(status), bytes))
}
