//! The comparison's benchmark: the time of one comparison of a 400x400 image once the golden is
//! loaded, and of the whole command's work (read the PNG and the cached golden, compare, write
//! the JSON), against a plain per-pixel absolute-difference pass over the same images.

use std::fmt::Write as _;
use std::time::{Duration, Instant};

use crate::compare::diagnose::mistakes::{Mistake, render_with_mistake};
use crate::compare::{
    CompareOptions, candidate::CandidateImage, compare_file, compare_image, noise_model::Golden,
};

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

fn time<T>(runs: usize, mut f: impl FnMut() -> T) -> Duration {
    median(
        (0..runs)
            .map(|_| {
                let t = Instant::now();
                std::hint::black_box(f());
                t.elapsed()
            })
            .collect(),
    )
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// Runs the benchmark on the week-4 quad scene (400x400) and returns its report.
pub fn run() -> String {
    let mut out = String::new();
    let scene = "week04-quad";
    let description = crate::scene::builtin(scene).expect("a built-in scene");
    let golden_spp = 1024;
    let t = Instant::now();
    let bytes = crate::golden::render_golden_bytes(
        &crate::golden::GoldenScene::builtin(scene).expect("a built-in scene"),
        golden_spp,
        false,
    )
    .expect("renders");
    let render_time = t.elapsed();
    let dir = tempfile::tempdir().expect("a temporary folder");
    let golden_path = dir.path().join("golden.exr");
    std::fs::write(&golden_path, &bytes).expect("writes");
    let golden = Golden::from_exr(&golden_path).expect("decodes");
    let honest_path = dir.path().join("honest.png");
    let shifted_path = dir.path().join("jitter01.png");
    crate::image_io::write_png(
        &honest_path,
        &render_with_mistake(&description, Mistake::Honest, 20, 1),
    )
    .expect("writes");
    crate::image_io::write_png(
        &shifted_path,
        &render_with_mistake(&description, Mistake::JitterZeroOne, 20, 1),
    )
    .expect("writes");
    let honest = CandidateImage::load(&honest_path).expect("reads");
    let shifted = CandidateImage::load(&shifted_path).expect("reads");
    let options = CompareOptions::default();
    let golden_codes: Vec<u8> = golden
        .mean
        .iter()
        .flat_map(|p| p.map(|x| options.encoding.encode(x)))
        .collect();
    let runs = 15;

    let baseline = time(runs, || {
        let CandidateImage::Rgb8 { data, .. } = &honest else {
            unreachable!()
        };
        data.iter()
            .zip(&golden_codes)
            .map(|(a, b)| (*a as i32 - *b as i32).unsigned_abs() as u64)
            .sum::<u64>()
    });
    let compare = time(runs, || {
        compare_image(&honest, &golden, &options).expect("compares")
    });
    let failing = time(5, || {
        compare_image(&shifted, &golden, &options).expect("compares")
    });
    let load_golden = time(runs, || Golden::from_exr(&golden_path).expect("decodes"));
    let whole = time(runs, || {
        let g = Golden::from_exr(&golden_path).expect("decodes");
        let c = compare_file(&honest_path, &g, &options).expect("compares");
        crate::compare::report::to_json(&c)
    });
    let baseline_whole = time(runs, || {
        let g = std::fs::read(&golden_path).expect("reads");
        let img = crate::image_io::read_png(&honest_path).expect("reads");
        let n = img.data.len().min(g.len());
        img.data[..n]
            .iter()
            .zip(&golden_codes)
            .map(|(a, b)| (*a as i32 - *b as i32).unsigned_abs() as u64)
            .sum::<u64>()
    });
    let verdict = compare_image(&honest, &golden, &options).expect("compares");
    let fail = compare_image(&shifted, &golden, &options).expect("compares");

    let _ = writeln!(
        out,
        "compare benchmark: {scene} 400x400, candidate 20 spp, golden {golden_spp} spp (rendered in {:.1} s, not timed below); median of {runs} runs",
        render_time.as_secs_f64()
    );
    let _ = writeln!(
        out,
        "  baseline: per-pixel |difference| pass            {:8.2} ms",
        ms(baseline)
    );
    let _ = writeln!(
        out,
        "  comparison, golden loaded (honest, {})        {:8.2} ms  ({:.0}x baseline; target < 100 ms)",
        if verdict.passed() { "pass" } else { "FAIL" },
        ms(compare),
        ms(compare) / ms(baseline).max(1e-6)
    );
    let _ = writeln!(
        out,
        "  comparison + diagnosis (jitter [0,1), {})     {:8.2} ms  ({:.0}x baseline)",
        if fail.passed() { "PASS" } else { "fail" },
        ms(failing),
        ms(failing) / ms(baseline).max(1e-6)
    );
    let _ = writeln!(
        out,
        "  load the cached golden                           {:8.2} ms",
        ms(load_golden)
    );
    let _ = writeln!(
        out,
        "  baseline whole: read PNG + golden, |difference|  {:8.2} ms",
        ms(baseline_whole)
    );
    let _ = writeln!(
        out,
        "  whole: read PNG + golden, compare, JSON          {:8.2} ms  ({:.1}x baseline; target < 2000 ms)",
        ms(whole),
        ms(whole) / ms(baseline_whole).max(1e-6)
    );
    out
}
