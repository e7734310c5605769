//! `bench render`'s comparison with Mitsuba 3: the scenes whose physics both renderers share,
//! exported with `scenes --export mitsuba` (`--profile physical`), rendered at the same size and
//! sample count by rtoracle (in this process, on pools of one thread and of every core) and by
//! Mitsuba (through `benches/mitsuba_timer.py`, embedded, in a Python that imports `mitsuba`),
//! the two taking turns within each run, each keeping its best. The goal: ahead of Mitsuba's
//! `scalar_rgb` variant on every scene; its `llvm_ad_rgb` variant (which needs Debian's
//! `libllvm19` named by `DRJIT_LIBLLVM_PATH`: without it Dr.Jit picks an older LLVM that cannot
//! compile its kernels and aborts) is measured where it can run, and has no goal.
//!
//! Mitsuba's scene loading and its first render (the LLVM variant compiles its kernels there)
//! are outside its times, as rtoracle's scene building is outside its own.

use std::io::{BufRead, BufReader, Write};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{Receiver, RecvTimeoutError, channel};
use std::time::{Duration, Instant};

use anyhow::Context;
use rtoracle::render::{RenderOptions, render};
use rtoracle::scene::{Camera, Profile, World};

use super::{process_cpu_time, spawn_killed_on_interrupt};

/// The scenes timed: diffuse quads under the sky, and under an area light (docs/benchmarks.md
/// says why these two: where the two renderers' images agree).
const SCENES: [&str; 2] = ["week05-quad", "week05-quad-light"];
/// The timer Mitsuba runs in.
const TIMER: &str = include_str!("../../../benches/mitsuba_timer.py");
/// The longest one command of the timer may take (a load with its untimed render, or a timed
/// render) before the timer is stopped and the comparison reported as failed.
const ANSWER_DEADLINE: Duration = Duration::from_secs(600);
/// Where Debian's libllvm19 is, for the hint printed when the LLVM variant is not measured.
const LIBLLVM_HINT: &str = "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1";

/// What the comparison runs with.
pub struct Options<'a> {
    /// The Python interpreter that imports `mitsuba`.
    pub python: &'a str,
    /// Samples per pixel of every render.
    pub spp: u32,
    /// Runs of each timing; the best is kept.
    pub runs: u32,
    /// The pools: one thread, and every core (when there is more than one).
    pub pools: &'a [(usize, rayon::ThreadPool)],
}

/// A scene as rtoracle renders it and as Mitsuba reads it.
struct Shared {
    name: &'static str,
    world: World,
    camera: Camera,
    xml: String,
}

/// The Mitsuba timer: a Python process answering one line per command.
struct Timer {
    child: Child,
    stdin: Option<ChildStdin>,
    lines: Receiver<String>,
    _kill: rtoracle::interrupt::CleanupGuard,
}

impl Timer {
    /// Starts the timer; returns it and Mitsuba's version, or why it cannot run.
    fn start(python: &str) -> anyhow::Result<Result<(Timer, String), String>> {
        let mut command = Command::new(python);
        command
            .args(["-c", TIMER])
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::null());
        let (mut child, kill) = match spawn_killed_on_interrupt(&mut command) {
            Ok(started) => started,
            Err(e) => return Ok(Err(format!("{e:#}"))),
        };
        let stdout = child.stdout.take().context("the timer's stdout")?;
        let (send, lines) = channel();
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                if send.send(line).is_err() {
                    break;
                }
            }
        });
        let mut timer = Timer {
            stdin: child.stdin.take(),
            child,
            lines,
            _kill: kill,
        };
        Ok(match timer.answer() {
            Ok(words) if words.first().map(String::as_str) == Some("ready") => {
                Ok((timer, words.get(1).cloned().unwrap_or_default()))
            }
            Ok(words) => Err(words.join(" ")),
            Err(why) => Err(why),
        })
    }

    /// Sends `command` and reads the answer's words.
    fn ask(&mut self, command: &str) -> Result<Vec<String>, String> {
        let stdin = self.stdin.as_mut().ok_or("the Mitsuba timer has ended")?;
        writeln!(stdin, "{command}")
            .and_then(|()| stdin.flush())
            .map_err(|e| format!("the Mitsuba timer has ended ({e})"))?;
        let words = self.answer()?;
        match words.first().map(String::as_str) {
            Some("error") => Err(words[1..].join(" ")),
            _ => Ok(words),
        }
    }

    fn answer(&mut self) -> Result<Vec<String>, String> {
        match self.lines.recv_timeout(ANSWER_DEADLINE) {
            Ok(line) => Ok(line.split_whitespace().map(str::to_string).collect()),
            Err(RecvTimeoutError::Timeout) => {
                let _ = self.child.kill();
                Err(format!(
                    "Mitsuba did not answer within {} s",
                    ANSWER_DEADLINE.as_secs()
                ))
            }
            Err(RecvTimeoutError::Disconnected) => {
                let status = self.child.wait().map(|s| s.to_string()).unwrap_or_default();
                Err(format!("the Mitsuba process ended ({status})"))
            }
        }
    }

    /// One timed render on `threads` threads: (CPU time, wall clock).
    fn time(&mut self, threads: usize) -> Result<(Duration, Duration), String> {
        let words = self.ask(&format!("time {threads}"))?;
        let secs = |k: usize| {
            words
                .get(k)
                .and_then(|w| w.parse::<f64>().ok())
                .filter(|s| s.is_finite() && *s > 0.0)
                .map(Duration::from_secs_f64)
                .ok_or_else(|| format!("the timer answered '{}'", words.join(" ")))
        };
        Ok((secs(1)?, secs(2)?))
    }
}

impl Drop for Timer {
    fn drop(&mut self) {
        drop(self.stdin.take());
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The best times of one scene on one variant: rtoracle and Mitsuba, one thread (CPU time) and
/// all threads (wall clock).
#[derive(Clone, Copy)]
struct Best {
    ours_one: Duration,
    theirs_one: Duration,
    ours_all: Duration,
    theirs_all: Duration,
}

/// Prints the comparison (or why it was skipped). Errors only for what breaks rtoracle itself.
pub fn compare(options: &Options) -> anyhow::Result<()> {
    let scenes = prepare()?;
    let mut variants = vec!["scalar_rgb"];
    let llvm = std::env::var_os("DRJIT_LIBLLVM_PATH").is_some();
    if llvm {
        variants.push("llvm_ad_rgb");
    }
    let (dir, _dir_guard) = rtoracle::interrupt::create_temporary(tempfile::tempdir, |d| d.path())
        .context("cannot make a temporary folder")?;
    let mut header = false;
    let mut least: Option<(f64, &str)> = None;
    let mut complete = true;
    for variant in &variants {
        let (mut timer, version) = match Timer::start(options.python)? {
            Ok(started) => started,
            Err(why) => {
                outln!(
                    "against Mitsuba 3 ({variant}): skipped, {} cannot run it: {why} (pip install mitsuba)",
                    options.python
                )?;
                complete &= *variant != "scalar_rgb";
                continue;
            }
        };
        if !header {
            header = true;
            print_header(&version, options)?;
        }
        for scene in &scenes {
            let path = dir.path().join(format!("{}.xml", scene.name));
            std::fs::write(&path, &scene.xml)
                .with_context(|| format!("cannot write {}", path.display()))?;
            match time_scene(&mut timer, variant, scene, &path, options)? {
                Ok(best) => {
                    let ratios = print_row(scene, variant, best, options)?;
                    if *variant == "scalar_rgb" {
                        for r in ratios {
                            if least.is_none_or(|(l, _)| r < l) {
                                least = Some((r, scene.name));
                            }
                        }
                    }
                }
                Err(why) => {
                    outln!("  {:<18} {variant:<12} skipped: {why}", scene.name)?;
                    complete &= *variant != "scalar_rgb";
                }
            }
        }
    }
    match least {
        Some((ratio, name)) if complete => outln!(
            "  goal: ahead of Mitsuba's scalar_rgb on every scene, on one core and on all: {} (the least ahead: {name}, {ratio:.2}x)",
            if ratio > 1.0 { "met" } else { "NOT met" }
        )?,
        _ => outln!("  goal: ahead of Mitsuba's scalar_rgb: not measured")?,
    }
    if !llvm {
        outln!(
            "  llvm_ad_rgb: not measured (set DRJIT_LIBLLVM_PATH to Debian's libllvm19, {LIBLLVM_HINT})"
        )?;
    }
    Ok(())
}

/// The shared scenes under the physical profile, with their Mitsuba scene files.
fn prepare() -> anyhow::Result<Vec<Shared>> {
    SCENES
        .iter()
        .map(|&name| {
            let description = rtoracle::scene::builtin(name)?;
            let description = crate::cli::reference::render::with_profile(
                name,
                description,
                Some(Profile::Physical),
            )?;
            let xml = rtoracle::scene::to_mitsuba_xml(&description)
                .with_context(|| format!("cannot export {name} for Mitsuba"))?;
            Ok(Shared {
                name,
                world: description.scene(),
                camera: description.camera(None),
                xml,
            })
        })
        .collect()
}

fn print_header(version: &str, options: &Options) -> anyhow::Result<()> {
    let cores = options.pools.last().map_or(1, |(n, _)| *n);
    outln!(
        "against Mitsuba {version}, the scenes both render alike (--profile physical, {} spp, best of {} runs; samples per second):",
        options.spp,
        options.runs
    )?;
    outln!(
        "  {:<18} {:<12} {:<42} all {cores} threads (wall clock)",
        "scene",
        "variant",
        "one thread (CPU time)"
    )?;
    Ok(())
}

/// Loads `scene` in `variant` and times it; the inner error says why Mitsuba could not.
fn time_scene(
    timer: &mut Timer,
    variant: &str,
    scene: &Shared,
    path: &std::path::Path,
    options: &Options,
) -> anyhow::Result<Result<Best, String>> {
    let loaded = timer.ask(&format!(
        "load {variant} {} {}",
        options.spp,
        path.display()
    ));
    let size = match loaded {
        Ok(words) => (
            words.get(1).and_then(|w| w.parse::<usize>().ok()),
            words.get(2).and_then(|w| w.parse::<usize>().ok()),
        ),
        Err(why) => return Ok(Err(why)),
    };
    if size != (Some(scene.camera.width), Some(scene.camera.height)) {
        return Ok(Err(format!(
            "Mitsuba's film is {size:?}, not {}x{}",
            scene.camera.width, scene.camera.height
        )));
    }
    let render_options = RenderOptions {
        samples_per_pixel: options.spp,
        ..Default::default()
    };
    let mut best = Best {
        ours_one: Duration::MAX,
        theirs_one: Duration::MAX,
        ours_all: Duration::MAX,
        theirs_all: Duration::MAX,
    };
    for _ in 0..options.runs {
        for (k, (threads, pool)) in options.pools.iter().enumerate() {
            let (cpu, wall) = (process_cpu_time(), Instant::now());
            pool.install(|| render(&scene.world, &scene.camera, &render_options))?;
            let (cpu, wall) = (process_cpu_time().saturating_sub(cpu), wall.elapsed());
            let theirs = match timer.time(*threads) {
                Ok(t) => t,
                Err(why) => return Ok(Err(why)),
            };
            if k == 0 {
                best.ours_one = best.ours_one.min(cpu);
                best.theirs_one = best.theirs_one.min(theirs.0);
            }
            if k + 1 == options.pools.len() {
                best.ours_all = best.ours_all.min(wall);
                best.theirs_all = best.theirs_all.min(theirs.1);
            }
        }
    }
    Ok(Ok(best))
}

/// Prints one scene's row; returns rtoracle's ratios over Mitsuba (one thread, all threads).
fn print_row(
    scene: &Shared,
    variant: &str,
    best: Best,
    options: &Options,
) -> anyhow::Result<[f64; 2]> {
    let samples = (scene.camera.width * scene.camera.height) as f64 * f64::from(options.spp);
    let rate = |t: Duration| samples / t.as_secs_f64() / 1e6;
    let one = rate(best.ours_one) / rate(best.theirs_one);
    let all = rate(best.ours_all) / rate(best.theirs_all);
    outln!(
        "  {:<18} {variant:<12} rtoracle {:>6.2}M Mitsuba {:>6.2}M {:>5.2}x    rtoracle {:>6.2}M Mitsuba {:>6.2}M {:>5.2}x",
        scene.name,
        rate(best.ours_one),
        rate(best.theirs_one),
        one,
        rate(best.ours_all),
        rate(best.theirs_all),
        all
    )?;
    Ok([one, all])
}
