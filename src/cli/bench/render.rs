//! `rtoracle bench render`: the reference tracer's speed and memory.
//!
//! Renders four of the course's scenes at their own sample counts on one thread and on all
//! threads: week 4's two (one colour per hit, 5.0M primary rays at 20 spp), week 6's dielectric
//! (a mirror, hollow glass and Lambertian spheres under the sky, paths of up to 7 bounces) and
//! week 8's Phong scene (the BRDF integrator, a point light and its shadow rays at every bounce,
//! a checker ground). In the same run it times a plain C loop doing the same work
//! ([`baseline`](super::baseline), `benches/baseline.c` built with `cc -O3`) and checks that it
//! renders the same film bit for bit; then it times the scenes whose physics Mitsuba 3 shares
//! against Mitsuba ([`mitsuba`](super::mitsuba)), and measures the peak memory of a large
//! `rtoracle render`.

use std::process::{Command, ExitCode, Stdio};
use std::time::{Duration, Instant};

use anyhow::Context;
use rtoracle::render::{Film, RenderOptions, render};
use rtoracle::scene::{Camera, World};

use super::baseline::{CBaseline, CScene, pixels_differing};
use super::{load_average, process_cpu_time, run_measuring_peak_rss};

/// The scenes timed, as the course renders them; the first two are week 4's.
const SCENES: [&str; 4] = [
    "week04-sphere",
    "week04-quad",
    "week06-dielectric",
    "week08-phong",
];
/// How many of [`SCENES`] are week 4's, whose rate has a goal of its own.
const WEEK4: usize = 2;
/// The goal for one core on week 4's scenes, in primary rays per second.
const GOAL_RAYS_PER_SECOND: f64 = 27e6;
/// The goal for the speedup on two threads.
const GOAL_SPEEDUP: f64 = 1.8;
/// The memory budget: bytes per pixel, plus a fixed allowance.
const BUDGET_BYTES_PER_PIXEL: u64 = 64;
const BUDGET_FIXED_BYTES: u64 = 50_000_000;

/// `rtoracle bench render [--runs N] [--memory-width W] [--cc CC] [--mitsuba-spp N] [--python PY]`
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Runs of each timing; the fastest is reported.
    #[arg(long, value_name = "N", default_value_t = 5, value_parser = crate::cli::args::runs)]
    runs: u32,
    /// Width of the render whose peak memory is measured (the square quad scene, 1 spp; at most
    /// 10000, as `render` makes at most 100 million pixels).
    #[arg(long, value_name = "W", default_value_t = 4000, value_parser = crate::cli::args::memory_width)]
    memory_width: u32,
    /// The C compiler that builds the baseline.
    #[arg(long, value_name = "CC", default_value = "cc")]
    cc: String,
    /// Samples per pixel of the renders timed against Mitsuba 3.
    #[arg(long, value_name = "N", default_value_t = 64, value_parser = crate::cli::args::spp)]
    mitsuba_spp: u32,
    /// The Python that imports Mitsuba 3 (`pip install mitsuba`); without it the comparison says
    /// it was skipped.
    #[arg(long, value_name = "PY", default_value = "python3")]
    python: String,
}

/// A scene ready to render both ways.
struct Prepared {
    name: &'static str,
    world: World,
    camera: Camera,
    spp: u32,
    /// The scene as the C loop reads it, or why it cannot.
    c: Result<CScene, String>,
}

impl Prepared {
    fn rays(&self) -> f64 {
        (self.camera.width * self.camera.height) as f64 * f64::from(self.spp)
    }
}

/// The best of several runs of one scene on one pool, and the film of the last.
struct Timing {
    cpu: Duration,
    wall: Duration,
    film: Option<Film>,
}

/// The C loop's best CPU time on a scene and how many pixels of its film differ from the
/// reference's, or why it was not run.
type CTiming = Result<(Duration, usize), String>;

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    if args.runs == 0 {
        anyhow::bail!("--runs 0: at least one run is needed");
    }
    if args.memory_width == 0 {
        anyhow::bail!("--memory-width 0: the width must be at least 1 pixel");
    }
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let scenes = prepare()?;
    outln!(
        "rtoracle bench render: four of the course's scenes at their own spp, seed 0, best of {} runs",
        args.runs
    )?;
    let vector = rtoracle::render::vector_instructions();
    match load_average() {
        Some(load) => {
            outln!("machine: {cores} cores, load average {load:.2}, vector instructions {vector}")?
        }
        None => outln!("machine: {cores} cores, vector instructions {vector}")?,
    }
    let counts: Vec<usize> = if cores > 1 { vec![1, cores] } else { vec![1] };
    let pools = counts
        .iter()
        .map(|&n| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .map(|pool| (n, pool))
                .context("cannot start the worker threads")
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let baseline = CBaseline::build(&args.cc);
    let (timings, c) = time_scenes(&scenes, &pools, args.runs, &baseline)?;
    let mut timings = timings.into_iter();
    let one = timings.next().expect("one thread timed");
    outln!()?;
    one_thread(&scenes, &one, &c, &args.cc)?;
    outln!()?;
    match timings.next() {
        Some(all) => all_threads(&scenes, &one, &all, cores)?,
        None => outln!("all threads: skipped, this machine has one core")?,
    }
    outln!()?;
    super::mitsuba::compare(&super::mitsuba::Options {
        python: &args.python,
        spp: args.mitsuba_spp,
        runs: args.runs,
        pools: &pools,
    })?;
    outln!()?;
    memory(args.memory_width)?;
    Ok(ExitCode::SUCCESS)
}

/// The scenes, each with its world, camera, sample count and C form.
fn prepare() -> anyhow::Result<Vec<Prepared>> {
    SCENES
        .iter()
        .map(|&name| {
            let description = rtoracle::scene::builtin(name)?;
            let (world, camera) = (description.scene(), description.camera(None));
            let c = CScene::of(&world, &camera);
            Ok(Prepared {
                name,
                world,
                camera,
                spp: description.image.samples_per_pixel,
                c,
            })
        })
        .collect()
}

/// The one-thread table: each scene by rtoracle and by the C loop, the ratio, whether the films
/// are the same; then the goals.
fn one_thread(scenes: &[Prepared], one: &[Timing], c: &[CTiming], cc: &str) -> anyhow::Result<()> {
    outln!(
        "one thread (CPU time of the process); C: benches/baseline.c, a plain C loop doing the same work ({cc} -O3):"
    )?;
    outln!(
        "  {:<18} {:>8} {:>4} {:>5} {:>7}  {:>20}  {:>20}  {:>10}  same film",
        "scene",
        "size",
        "spp",
        "depth",
        "rays",
        "rtoracle",
        "C loop",
        "rtoracle/C"
    )?;
    let mut slowest: Option<(f64, &str)> = None;
    let mut all_same = true;
    for ((scene, ours), theirs) in scenes.iter().zip(one).zip(c) {
        let rays = scene.rays();
        let (c_time, ratio, same) = match theirs {
            Ok((cpu, differing)) => {
                let ratio = cpu.as_secs_f64() / ours.cpu.as_secs_f64();
                if slowest.is_none_or(|(r, _)| ratio < r) {
                    slowest = Some((ratio, scene.name));
                }
                all_same &= *differing == 0;
                let same = if *differing == 0 {
                    "yes".to_string()
                } else {
                    format!(
                        "NO: {differing} of {} pixels differ",
                        scene.camera.width * scene.camera.height
                    )
                };
                (rate(rays, *cpu), format!("{ratio:.2}x"), same)
            }
            Err(why) => ("-".into(), "-".into(), format!("skipped: {why}")),
        };
        let s = &scene.world.settings;
        let depth = if s.integrator == rtoracle::scene::Integrator::Albedo {
            "1".to_string()
        } else {
            s.max_depth.to_string()
        };
        outln!(
            "  {:<18} {:>8} {:>4} {:>5} {:>6.2}M  {:>20}  {:>20}  {:>10}  {same}",
            scene.name,
            format!("{}x{}", scene.camera.width, scene.camera.height),
            scene.spp,
            depth,
            rays / 1e6,
            rate(rays, ours.cpu),
            c_time,
            ratio
        )?;
    }
    let rays4: f64 = scenes[..WEEK4].iter().map(Prepared::rays).sum();
    let cpu4: Duration = one[..WEEK4].iter().map(|t| t.cpu).sum();
    let rate4 = rays4 / cpu4.as_secs_f64();
    outln!(
        "  goal: at least {:.1}M primary rays/s on one core on week 4's scenes ({:.2}M): {}",
        GOAL_RAYS_PER_SECOND / 1e6,
        rate4 / 1e6,
        verdict(rate4 >= GOAL_RAYS_PER_SECOND)
    )?;
    match slowest {
        Some((ratio, name)) if c.iter().all(Result::is_ok) => outln!(
            "  goal: ahead of the C loop on one thread, on every scene, with the same film: {} (the least ahead: {name}, {ratio:.2}x)",
            verdict(ratio > 1.0 && all_same)
        ),
        _ => outln!(
            "  goal: ahead of the C loop on one thread: not measured (the C loop was skipped)"
        ),
    }
}

/// `time` for `rays`, and the rate: `0.0534 s 33.71M/s`.
fn rate(rays: f64, time: Duration) -> String {
    format!(
        "{:.4} s {:>6.2}M/s",
        time.as_secs_f64(),
        rays / time.as_secs_f64() / 1e6
    )
}

/// The all-threads lines: the speedup of the four scenes together over one thread, the extra
/// CPU time, and whether every film is the one-thread film.
fn all_threads(
    scenes: &[Prepared],
    one: &[Timing],
    all: &[Timing],
    cores: usize,
) -> anyhow::Result<()> {
    let rays: f64 = scenes.iter().map(Prepared::rays).sum();
    let sum = |t: &[Timing], f: fn(&Timing) -> Duration| t.iter().map(f).sum::<Duration>();
    let (wall1, wall_all) = (sum(one, |t| t.wall), sum(all, |t| t.wall));
    let (cpu1, cpu_all) = (sum(one, |t| t.cpu), sum(all, |t| t.cpu));
    outln!("all {cores} threads (wall clock), the four scenes together:")?;
    outln!("  {:.2}M rays {}", rays / 1e6, rate(rays, wall_all))?;
    let speedup = wall1.as_secs_f64() / wall_all.as_secs_f64();
    outln!(
        "  speedup over one thread ({:.4} s wall): {speedup:.2}x; goal at least {GOAL_SPEEDUP}x on 2 threads: {}",
        wall1.as_secs_f64(),
        verdict(speedup >= GOAL_SPEEDUP)
    )?;
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
    let identical = all
        .iter()
        .zip(one)
        .all(|(a, b)| same_means(a.film.as_ref(), b.film.as_ref()));
    outln!(
        "  same film as on one thread: {}",
        if identical { "yes" } else { "NO" }
    )
}

fn verdict(met: bool) -> &'static str {
    if met { "met" } else { "NOT met" }
}

/// Whether two films' means are the same bits.
fn same_means(a: Option<&Film>, b: Option<&Film>) -> bool {
    match (a, b) {
        (Some(a), Some(b)) => {
            a.mean.len() == b.mean.len()
                && a.mean.iter().zip(&b.mean).all(|(x, y)| {
                    x.to_array()
                        .iter()
                        .zip(y.to_array())
                        .all(|(p, q)| p.to_bits() == q.to_bits())
                })
        }
        _ => false,
    }
}

/// Renders each scene `runs` times on each of the `pools` (its thread count, the pool) and with the C
/// loop (on this thread, when it was built), and keeps the best times of each: per scene, its
/// renders take turns within each run, so a change in the machine's speed (a burst of load
/// elsewhere, a slower hour of a virtual machine) hits rtoracle and the C loop alike. The C
/// loop's result holds how many pixels of its film differ from the reference's one-thread film.
fn time_scenes(
    scenes: &[Prepared],
    pools: &[(usize, rayon::ThreadPool)],
    runs: u32,
    baseline: &Result<CBaseline, String>,
) -> anyhow::Result<(Vec<Vec<Timing>>, Vec<CTiming>)> {
    let mut timings: Vec<Vec<Timing>> = pools
        .iter()
        .map(|_| {
            scenes
                .iter()
                .map(|_| Timing {
                    cpu: Duration::MAX,
                    wall: Duration::MAX,
                    film: None,
                })
                .collect()
        })
        .collect();
    let mut c: Vec<CTiming> = scenes
        .iter()
        .map(|scene| {
            baseline.as_ref().map_err(Clone::clone)?;
            scene.c.as_ref().map_err(Clone::clone)?;
            Ok((Duration::MAX, 0))
        })
        .collect();
    for _ in 0..runs {
        for (k, scene) in scenes.iter().enumerate() {
            for ((_, pool), per_scene) in pools.iter().zip(&mut timings) {
                let timing = &mut per_scene[k];
                let options = RenderOptions {
                    samples_per_pixel: scene.spp,
                    ..Default::default()
                };
                let (cpu, wall) = (process_cpu_time(), Instant::now());
                let film = pool.install(|| render(&scene.world, &scene.camera, &options))?;
                timing.wall = timing.wall.min(wall.elapsed());
                timing.cpu = timing.cpu.min(process_cpu_time().saturating_sub(cpu));
                timing.film = Some(film);
            }
            if let (Ok(baseline), Ok(cscene), Ok((best, differing))) =
                (baseline, &scene.c, &mut c[k])
            {
                match baseline.render(cscene, scene.spp, 0) {
                    Ok((film, cpu)) => {
                        *best = (*best).min(cpu);
                        *differing = timings[0][k]
                            .film
                            .as_ref()
                            .map_or(usize::MAX, |f| pixels_differing(f, &film));
                    }
                    Err(why) => c[k] = Err(why),
                }
            }
        }
    }
    Ok((timings, c))
}

/// Peak memory of `rtoracle render` of the quad scene at `width` x `width` (1 spp: memory does
/// not depend on the sample count), against the budget; and of a tiny render, for the fixed part.
fn memory(width: u32) -> anyhow::Result<()> {
    let exe = std::env::current_exe().context("cannot find the rtoracle executable")?;
    let (dir, _dir_guard) = rtoracle::interrupt::create_temporary(tempfile::tempdir, |d| d.path())
        .context("cannot make a temporary folder")?;
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
