use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use rtoracle::escape::terminal_line;
use rtoracle::golden::SPP_VARIANTS;
use rtoracle::golden::{
    GOLDEN_SEED, GOLDEN_SPP, GoldenScene, Tolerance, cache_dir, compare_goldens, golden_file_name,
    golden_of, golden_spp, render_golden_bytes,
};
use rtoracle::image_io::{decode_exr, write_atomically};
use rtoracle::scene::builtin_names;

/// `rtoracle golden [--check] [--dir DIR] [--spp N] [--scenes a,b]`, or
/// `rtoracle golden FILE.toml -o FILE.exr [--spp N]` for a scene file.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// A scene file (TOML) to make the golden of, instead of the built-in scenes; a rubric's
    /// image group names it with `golden = "FILE.exr"`.
    #[arg(value_name = "FILE.toml", requires = "out", conflicts_with_all = ["check", "scenes", "dir"])]
    scene_file: Option<PathBuf>,
    /// Where to write the scene file's golden (EXR).
    #[arg(short, long, value_name = "FILE.exr", requires = "scene_file")]
    out: Option<PathBuf>,
    /// Verify instead of writing: regenerate each golden in memory and compare it with the file,
    /// pixel by pixel within a small tolerance. Exit 0 when all are equal, 1 when one differs,
    /// 2 when a file cannot be read.
    #[arg(long)]
    check: bool,
    /// The folder of the goldens (created when writing).
    #[arg(long, value_name = "DIR", default_value = "golden")]
    dir: PathBuf,
    /// Samples per pixel (default: 4096 for the built-in scenes; for a scene file, the golden
    /// its grading uses: max(4096, 100 x the scene's samples_per_pixel)).
    #[arg(long, value_name = "N", value_parser = crate::cli::args::spp)]
    spp: Option<u32>,
    /// Only these built-in scenes (comma-separated; default: all of them).
    #[arg(long, value_name = "A,B", value_delimiter = ',')]
    scenes: Vec<String>,
}

/// The committed goldens: each built-in scene's (`NAME`), then those of
/// [`SPP_VARIANTS`] (`NAME.sppN`), as (its name for `--scenes`, the scene at its samples).
fn committed() -> Vec<(String, GoldenScene)> {
    let mut out: Vec<(String, GoldenScene)> = builtin_names()
        .into_iter()
        .map(|n| {
            (
                n.to_string(),
                GoldenScene::builtin(n).expect("a built-in scene"),
            )
        })
        .collect();
    for (name, spp) in SPP_VARIANTS {
        let scene = GoldenScene::builtin_at_spp(name, *spp).expect("a built-in scene");
        out.push((format!("{name}.spp{spp}"), scene));
    }
    out
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    if let (Some(file), Some(out)) = (&args.scene_file, &args.out) {
        return write_scene_file(file, out, args.spp);
    }
    let spp = args.spp.unwrap_or(GOLDEN_SPP);
    let all = committed();
    let scenes: Vec<(String, GoldenScene)> = if args.scenes.is_empty() {
        all
    } else {
        let mut chosen = Vec::new();
        for name in &args.scenes {
            match all.iter().find(|(n, _)| n == name) {
                Some(found) => chosen.push(found.clone()),
                None => anyhow::bail!(
                    "--scenes {}: no such built-in scene (the committed goldens: {})",
                    terminal_line(name),
                    all.iter()
                        .map(|(n, _)| n.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            }
        }
        chosen
    };
    if args.check {
        if !args.dir.is_dir() {
            let what = if args.dir.exists() {
                "is a file, not a folder"
            } else {
                "does not exist"
            };
            anyhow::bail!("--dir {}: {what}", args.dir.display());
        }
    } else {
        rtoracle::output::check_output_dir(&args.dir, "--dir")?;
    }
    if args.check {
        check(&args.dir, &scenes, spp)
    } else {
        write(&args.dir, &scenes, spp)
    }
}

fn write_scene_file(file: &Path, out: &Path, spp: Option<u32>) -> anyhow::Result<ExitCode> {
    if !file.exists() {
        if let Some(name) = file
            .to_str()
            .filter(|n| rtoracle::scene::builtin(n).is_ok())
        {
            anyhow::bail!(
                "{name}: no such file; it names a built-in scene, whose golden `rtoracle golden --scenes {name} --dir DIR` writes (as DIR/{name}.exr)"
            );
        }
    }
    let scene = GoldenScene::from_file(file)?;
    // The grader's golden of this scene, from (or into) the same cache, so that grading it later
    // renders nothing.
    let spp = spp.unwrap_or_else(|| golden_spp(scene.description.image.samples_per_pixel));
    if out.extension().and_then(|e| e.to_str()) != Some("exr") {
        anyhow::bail!("-o {}: the golden must be an .exr file", out.display());
    }
    rtoracle::output::check_output_file(out, "-o")?;
    let start = Instant::now();
    let bytes = golden_of(&scene, spp, cache_dir().as_deref(), true)?.bytes;
    write_atomically(out, &bytes)?;
    outln!(
        "wrote {} ({spp} spp, seed {GOLDEN_SEED}, {} bytes) in {:.1} s",
        out.display(),
        bytes.len(),
        start.elapsed().as_secs_f64()
    )?;
    Ok(ExitCode::SUCCESS)
}

fn write(dir: &Path, scenes: &[(String, GoldenScene)], spp: u32) -> anyhow::Result<ExitCode> {
    // The folder is created with the first golden, and removed again on Ctrl-C if this run
    // created it, so an interrupted run leaves no empty or half-filled new folder.
    let mut created: Option<rtoracle::interrupt::CleanupGuard> = None;
    for (name, scene) in scenes {
        let path = dir.join(golden_file_name(name));
        let start = Instant::now();
        let bytes = render_golden_bytes(scene, spp, true)?;
        if created.is_none() && !dir.is_dir() {
            // Made and registered in one step, so a signal's cleanups cannot miss it.
            let made = || std::fs::create_dir(dir).map(|()| dir.to_path_buf());
            let (_, guard) =
                rtoracle::interrupt::create_temporary(made, |p| p.as_path()).map_err(|e| {
                    anyhow::anyhow!("--dir {}: cannot create the folder: {e}", dir.display())
                })?;
            created = Some(guard);
        }
        write_atomically(&path, &bytes)?;
        outln!(
            "wrote {} ({spp} spp, seed {GOLDEN_SEED}, {} bytes) in {:.1} s",
            path.display(),
            bytes.len(),
            start.elapsed().as_secs_f64()
        )?;
    }
    drop(created);
    Ok(ExitCode::SUCCESS)
}

fn check(dir: &Path, scenes: &[(String, GoldenScene)], spp: u32) -> anyhow::Result<ExitCode> {
    // Read every file before the long renders, so an unreadable one fails at once.
    let mut committed = Vec::with_capacity(scenes.len());
    for (name, _) in scenes {
        let path = dir.join(golden_file_name(name));
        let bytes = std::fs::read(&path)
            .map_err(|e| anyhow::anyhow!("{}: cannot read: {e}", path.display()))?;
        let image = decode_exr(&bytes, &path)?;
        committed.push((path, bytes, image));
    }
    let mut all_equal = true;
    for ((_, scene), (path, bytes, on_disk)) in scenes.iter().zip(committed) {
        let fresh = render_golden_bytes(scene, spp, true)?;
        if fresh == bytes {
            outln!("{}: identical bytes", path.display())?;
            continue;
        }
        // The file is what is checked ("is"); the fresh render is what is expected.
        let expected = decode_exr(&fresh, &path)?;
        let diff = compare_goldens(&expected, &on_disk, &Tolerance::default());
        let pixels = on_disk.width * on_disk.height;
        if diff.is_match() {
            outln!(
                "{}: equal within tolerance (the bytes differ)",
                path.display()
            )?;
        } else {
            all_equal = false;
            outln!(
                "{}: differs from a fresh render: {}",
                path.display(),
                diff.summary(pixels)
            )?;
        }
    }
    Ok(if all_equal {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(crate::cli::FAILED)
    })
}
