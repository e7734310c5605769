use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use rtoracle::render::{RenderOptions, render};
use rtoracle::scene::SceneDescription;

/// `rtoracle render (NAME | FILE.toml) [-o OUT.png | OUT.exr] [--spp N] [--seed S] [--width W] [--threads T]`
#[derive(Debug, clap::Args)]
pub struct Args {
    /// A built-in scene name (see `rtoracle scenes`) or a TOML scene file.
    scene: String,
    /// Output image: `.png` (the course's 8-bit encoding) or `.exr` (linear f32 RGB).
    /// Default: `NAME.png` in the working directory.
    #[arg(short, long, value_name = "OUT")]
    output: Option<PathBuf>,
    /// Samples per pixel (default: the scene's, 20 for the course scenes).
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    spp: Option<i64>,
    /// Seed of the per-pixel random streams.
    #[arg(long, value_name = "S", default_value_t = 0)]
    seed: u64,
    /// Image width in pixels (the height follows the scene's aspect ratio).
    #[arg(long, value_name = "W", allow_negative_numbers = true)]
    width: Option<i64>,
    /// Worker threads (default: all cores). The image is the same for any count.
    #[arg(long, value_name = "T")]
    threads: Option<usize>,
}

/// The largest image `render` makes: 100 million pixels (2.4 GB of film).
const MAX_PIXELS: usize = 100_000_000;

/// Loads a built-in scene by name, or a scene file when the argument ends in `.toml` or names an
/// existing file.
pub fn load_scene(name: &str) -> anyhow::Result<(String, SceneDescription)> {
    let path = std::path::Path::new(name);
    if name.ends_with(".toml") || path.is_file() {
        let stem = path
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("scene")
            .to_string();
        Ok((stem, SceneDescription::from_file(path)?))
    } else {
        Ok((name.to_string(), rtoracle::scene::builtin(name)?))
    }
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let (name, description) = load_scene(&args.scene)?;
    let spp = match args.spp {
        Some(n) if n <= 0 => anyhow::bail!("--spp {n}: samples per pixel must be at least 1"),
        Some(n) => u32::try_from(n).map_err(|_| anyhow::anyhow!("--spp {n}: too large"))?,
        None => description.image.samples_per_pixel,
    };
    let width = match args.width {
        Some(w) if w <= 0 => anyhow::bail!("--width {w}: the width must be at least 1 pixel"),
        Some(w) => Some(usize::try_from(w).map_err(|_| anyhow::anyhow!("--width {w}: too large"))?),
        None => None,
    };
    if args.threads == Some(0) {
        anyhow::bail!("--threads 0: at least one thread is needed");
    }
    let output = args
        .output
        .unwrap_or_else(|| PathBuf::from(format!("{name}.png")));
    let format = OutputFormat::of(&output)?;
    rtoracle::image_io::check_writable(&output)?;

    let camera = description.camera(width);
    if camera.width.saturating_mul(camera.height) > MAX_PIXELS {
        anyhow::bail!(
            "{name}: a {}x{} image is too large (at most {MAX_PIXELS} pixels)",
            camera.width,
            camera.height
        );
    }
    let scene = description.scene();
    let options = RenderOptions {
        samples_per_pixel: spp,
        seed: args.seed,
        progress: true,
        ..Default::default()
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads.unwrap_or(0))
        .build()
        .context("cannot start the worker threads")?;
    let film = pool.install(|| render(&scene, &camera, &options))?;
    match format {
        OutputFormat::Png => rtoracle::image_io::write_png(
            &output,
            &rtoracle::image_io::Rgb8Image {
                width: film.width,
                height: film.height,
                data: film.to_course_rgb8(),
            },
        )?,
        OutputFormat::Exr => {
            let attributes = vec![
                ("rtoracle.scene".to_string(), name.clone()),
                ("rtoracle.spp".to_string(), spp.to_string()),
                ("rtoracle.seed".to_string(), args.seed.to_string()),
            ];
            rtoracle::image_io::write_exr(&output, &film, &attributes)?
        }
    }
    eprintln!(
        "rendered {name} ({}x{}, {spp} spp, seed {}) to {}",
        film.width,
        film.height,
        args.seed,
        output.display()
    );
    Ok(ExitCode::SUCCESS)
}

enum OutputFormat {
    Png,
    Exr,
}

impl OutputFormat {
    fn of(path: &std::path::Path) -> anyhow::Result<Self> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("png") => Ok(OutputFormat::Png),
            Some("exr") => Ok(OutputFormat::Exr),
            _ => anyhow::bail!(
                "{}: cannot write this kind of image; use a .png or .exr name",
                path.display()
            ),
        }
    }
}
