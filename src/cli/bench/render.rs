//! `rtoracle bench render`: the reference tracer's speed and memory.
//!
//! Renders the course's two week-4 scenes at 20 spp (5.0M primary rays) on one thread and on all
//! threads, and times a plain C loop doing the same work (`bench/baseline.c`, compiled here with
//! `cc -O3`) in the same run; then measures the peak memory of a large `rtoracle render`.

use std::path::Path;
use std::process::{Command, ExitCode, Stdio};
use std::time::{Duration, Instant};

use anyhow::Context;
use rtoracle::render::{Film, RenderOptions, render};

use super::{load_average, process_cpu_time, run_measuring_peak_rss};

/// The scenes timed, as the course renders them.
const SCENES: [&str; 2] = ["week04-sphere", "week04-quad"];
/// Samples per pixel, as the course renders them.
const SPP: u32 = 20;
/// The goal for one core, in primary rays per second.
const GOAL_RAYS_PER_SECOND: f64 = 27e6;
/// The goal for the speedup on two threads.
const GOAL_SPEEDUP: f64 = 1.8;
/// The memory budget: bytes per pixel, plus a fixed allowance.
const BUDGET_BYTES_PER_PIXEL: u64 = 64;
const BUDGET_FIXED_BYTES: u64 = 50_000_000;
/// The C baseline's source, built into the binary so the benchmark runs anywhere.
const BASELINE_C: &str = include_str!("../../../bench/baseline.c");

/// `rtoracle bench render [--runs N] [--memory-width W] [--cc CC]`
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Runs of each timing; the fastest is reported.
    #[arg(long, value_name = "N", default_value_t = 5, value_parser = crate::cli::num::runs)]
    runs: u32,
    /// Width of the render whose peak memory is measured (the square quad scene, 1 spp; at most
    /// 10000, as `render` makes at most 100 million pixels).
    #[arg(long, value_name = "W", default_value_t = 4000, value_parser = crate::cli::num::memory_width)]
    memory_width: u32,
    /// The C compiler that builds the baseline.
    #[arg(long, value_name = "CC", default_value = "cc")]
    cc: String,
}

/// The best of several runs of one scene.
struct Timing {
    name: &'static str,
    width: usize,
    height: usize,
    cpu: Duration,
    wall: Duration,
    checksum: u64,
}

impl Timing {
    fn rays(&self) -> f64 {
        (self.width * self.height) as f64 * SPP as f64
    }
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    if args.runs == 0 {
        anyhow::bail!("--runs 0: at least one run is needed");
    }
    if args.memory_width == 0 {
        anyhow::bail!("--memory-width 0: the width must be at least 1 pixel");
    }
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    outln!(
        "rtoracle bench render: the course's week-4 scenes at {SPP} spp, seed 0, best of {} runs",
        args.runs
    )?;
    let vector = rtoracle::render::vector_instructions();
    match load_average() {
        Some(load) => {
            outln!("machine: {cores} cores, load average {load:.2}, vector instructions {vector}")?
        }
        None => outln!("machine: {cores} cores, vector instructions {vector}")?,
    }

    outln!()?;
    outln!("one thread (CPU time of the process):")?;
    let counts: Vec<usize> = if cores > 1 { vec![1, cores] } else { vec![1] };
    let mut timings = time_scenes(&counts, args.runs)?.into_iter();
    let one = timings.next().expect("one thread timed");
    for t in &one {
        print_row(t.name, Some((t.width, t.height)), t.rays(), t.cpu)?;
    }
    let (rays, cpu1, wall1) = totals(&one);
    let rate1 = rays / cpu1.as_secs_f64();
    print_row("both", None, rays, cpu1)?;
    outln!(
        "  goal: at least {:.1}M primary rays/s on one core: {}",
        GOAL_RAYS_PER_SECOND / 1e6,
        verdict(rate1 >= GOAL_RAYS_PER_SECOND)
    )?;

    outln!()?;
    match c_baseline(&args.cc, args.runs) {
        Ok(c) => {
            outln!(
                "baseline: bench/baseline.c, a plain C loop doing the same work ({} -O3):",
                args.cc
            )?;
            let mut c_cpu = Duration::ZERO;
            let mut same = true;
            for (name, seconds, checksum) in &c {
                let ours = one.iter().find(|t| t.name == name);
                let rays = ours.map_or(0.0, Timing::rays);
                let cpu = Duration::from_secs_f64(*seconds);
                print_row(name, None, rays, cpu)?;
                c_cpu += cpu;
                same &= ours.is_some_and(|t| t.checksum == *checksum);
            }
            print_row("both", None, rays, c_cpu)?;
            outln!(
                "  same film, bit for bit: {}",
                if same && c.len() == SCENES.len() {
                    "yes (checksums equal)"
                } else {
                    "NO: the baseline does not do the same work"
                }
            )?;
            outln!(
                "  rtoracle / C: {:.2}x the baseline's primary rays per second",
                c_cpu.as_secs_f64() / cpu1.as_secs_f64()
            )?;
        }
        Err(why) => outln!("baseline: skipped: {why}")?,
    }

    outln!()?;
    if cores > 1 {
        outln!("all {cores} threads (wall clock):")?;
        let all = timings.next().expect("all threads timed");
        let (_, _, wall_all) = totals(&all);
        print_row("both", None, rays, wall_all)?;
        let speedup = wall1.as_secs_f64() / wall_all.as_secs_f64();
        outln!(
            "  speedup over one thread ({:.4} s wall): {speedup:.2}x; goal at least {GOAL_SPEEDUP}x on 2 threads: {}",
            wall1.as_secs_f64(),
            verdict(speedup >= GOAL_SPEEDUP)
        )?;
        let (_, cpu_all, _) = totals(&all);
        outln!(
            "  CPU time on {cores} threads: {:.4} s, {:.2}x one thread's (the extra work of running in parallel)",
            cpu_all.as_secs_f64(),
            cpu_all.as_secs_f64() / cpu1.as_secs_f64()
        )?;
        if let Some(load) = load_average().filter(|&l| l > 0.5) {
            if load > cores as f64 - 1.0 {
                outln!(
                    "  note: the machine is busy (load average {load:.2} on {cores} cores): the wall-clock speedup measures the other programs too"
                )?;
            }
        }
        let identical = all.iter().zip(&one).all(|(a, b)| a.checksum == b.checksum);
        outln!(
            "  same film as on one thread: {}",
            if identical { "yes" } else { "NO" }
        )?;
    } else {
        outln!("all threads: skipped, this machine has one core")?;
    }

    outln!()?;
    memory(args.memory_width)?;
    Ok(ExitCode::SUCCESS)
}

fn verdict(met: bool) -> &'static str {
    if met { "met" } else { "NOT met" }
}

fn print_row(
    name: &str,
    size: Option<(usize, usize)>,
    rays: f64,
    time: Duration,
) -> anyhow::Result<()> {
    let size = size.map_or(String::new(), |(w, h)| format!("{w}x{h}"));
    outln!(
        "  {name:<14} {size:>8} {:>6.2}M rays {:>8.4} s {:>7.2}M rays/s",
        rays / 1e6,
        time.as_secs_f64(),
        rays / time.as_secs_f64() / 1e6
    )
}

/// Total rays and the sums of the best CPU and wall times.
fn totals(timings: &[Timing]) -> (f64, Duration, Duration) {
    (
        timings.iter().map(Timing::rays).sum(),
        timings.iter().map(|t| t.cpu).sum(),
        timings.iter().map(|t| t.wall).sum(),
    )
}

/// Renders each scene `runs` times on a pool of each of the `threads` counts and keeps the best
/// times per count. The counts take turns within each run, so a burst of load elsewhere on the
/// machine hits them alike.
fn time_scenes(threads: &[usize], runs: u32) -> anyhow::Result<Vec<Vec<Timing>>> {
    let pools = threads
        .iter()
        .map(|&n| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .context("cannot start the worker threads")
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let mut prepared = Vec::new();
    for name in SCENES {
        let description = rtoracle::scene::builtin(name)?;
        prepared.push((name, description.camera(None), description.scene()));
    }
    let options = RenderOptions {
        samples_per_pixel: SPP,
        ..Default::default()
    };
    let mut timings: Vec<Vec<Timing>> = threads
        .iter()
        .map(|_| {
            prepared
                .iter()
                .map(|(name, camera, _)| Timing {
                    name,
                    width: camera.width,
                    height: camera.height,
                    cpu: Duration::MAX,
                    wall: Duration::MAX,
                    checksum: 0,
                })
                .collect()
        })
        .collect();
    for _ in 0..runs {
        for (pool, per_scene) in pools.iter().zip(&mut timings) {
            for ((_, camera, scene), timing) in prepared.iter().zip(per_scene.iter_mut()) {
                let (cpu, wall) = (process_cpu_time(), Instant::now());
                let film = pool.install(|| render(scene, camera, &options))?;
                timing.wall = timing.wall.min(wall.elapsed());
                timing.cpu = timing.cpu.min(process_cpu_time().saturating_sub(cpu));
                timing.checksum = checksum(&film);
            }
        }
    }
    Ok(timings)
}

/// FNV-1a over the little-endian bits of every channel of every pixel's mean, row-major: the
/// checksum `bench/baseline.c` prints.
fn checksum(film: &Film) -> u64 {
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    for channel in film.mean.iter().flat_map(|c| c.to_array()) {
        for byte in channel.to_bits().to_le_bytes() {
            hash ^= u64::from(byte);
            hash = hash.wrapping_mul(0x0100_0000_01b3);
        }
    }
    hash
}

/// Builds and runs the C baseline: per scene, its name, best CPU seconds and film checksum.
/// `Err` says why it was skipped.
fn c_baseline(cc: &str, runs: u32) -> Result<Vec<(String, f64, u64)>, String> {
    let dir = tempfile::tempdir().map_err(|e| format!("cannot make a temporary folder: {e}"))?;
    let source = dir.path().join("baseline.c");
    let binary = dir.path().join("baseline");
    std::fs::write(&source, BASELINE_C).map_err(|e| format!("cannot write the source: {e}"))?;
    let compiled = Command::new(cc)
        .args(["-O3", "-ffp-contract=off", "-o"])
        .arg(&binary)
        .arg(&source)
        .arg("-lm")
        .output()
        .map_err(|e| format!("no C compiler '{cc}' ({e})"))?;
    if !compiled.status.success() {
        let stderr = String::from_utf8_lossy(&compiled.stderr);
        return Err(format!(
            "'{cc}' could not build it: {}",
            stderr.lines().next().unwrap_or("no message")
        ));
    }
    run_baseline(&binary, runs)
}

fn run_baseline(binary: &Path, runs: u32) -> Result<Vec<(String, f64, u64)>, String> {
    let out = Command::new(binary)
        .arg(runs.to_string())
        .stderr(Stdio::inherit())
        .output()
        .map_err(|e| format!("cannot run it: {e}"))?;
    if !out.status.success() {
        return Err(format!("it failed ({})", out.status));
    }
    let text = String::from_utf8_lossy(&out.stdout);
    let mut rows = Vec::new();
    for line in text.lines() {
        let fields: Vec<&str> = line.split_whitespace().collect();
        let parsed = match fields.as_slice() {
            [name, _width, _height, seconds, checksum] => seconds
                .parse::<f64>()
                .ok()
                .zip(u64::from_str_radix(checksum, 16).ok())
                .map(|(s, c)| (name.to_string(), s, c)),
            _ => None,
        };
        rows.push(parsed.ok_or_else(|| format!("unexpected output line '{line}'"))?);
    }
    Ok(rows)
}

/// Peak memory of `rtoracle render` of the quad scene at `width` x `width` (1 spp: memory does
/// not depend on the sample count), against the budget; and of a tiny render, for the fixed part.
fn memory(width: u32) -> anyhow::Result<()> {
    let exe = std::env::current_exe().context("cannot find the rtoracle executable")?;
    let dir = tempfile::tempdir().context("cannot make a temporary folder")?;
    let measure = |w: u32| -> anyhow::Result<u64> {
        let out = dir.path().join(format!("memory-{w}.png"));
        let mut command = Command::new(&exe);
        command
            .args([
                "render",
                "week04-quad",
                "--spp",
                "1",
                "--width",
                &w.to_string(),
            ])
            .arg("-o")
            .arg(&out)
            .stdout(Stdio::null())
            .stderr(Stdio::null());
        let (status, peak) = run_measuring_peak_rss(&mut command)?;
        if !status.success() {
            anyhow::bail!("the memory render at width {w} failed ({status})");
        }
        Ok(peak)
    };
    let pixels = u64::from(width) * u64::from(width);
    let small = measure(16)?;
    let peak = measure(width)?;
    let budget = BUDGET_BYTES_PER_PIXEL * pixels + BUDGET_FIXED_BYTES;
    let mb = |b: u64| b as f64 / 1e6;
    outln!(
        "memory: peak RSS of `rtoracle render week04-quad --width {width} --spp 1` ({:.1}M pixels):",
        pixels as f64 / 1e6
    )?;
    outln!(
        "  {:.1} MB = {:.1} B/px overall; {:.1} B/px above a 16x16 render's {:.1} MB",
        mb(peak),
        peak as f64 / pixels as f64,
        peak.saturating_sub(small) as f64 / pixels as f64,
        mb(small)
    )?;
    outln!(
        "  budget {BUDGET_BYTES_PER_PIXEL} B/px + 50 MB = {:.1} MB: {}",
        mb(budget),
        verdict(peak <= budget)
    )?;
    Ok(())
}
