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
    #[arg(long, value_name = "N", value_parser = super::num::spp)]
    spp: Option<u32>,
    /// Seed of the per-pixel random streams.
    #[arg(long, value_name = "S", default_value_t = 0, value_parser = super::num::seed)]
    seed: u64,
    /// Image width in pixels (the height follows the scene's aspect ratio).
    #[arg(long, value_name = "W", value_parser = super::num::width)]
    width: Option<usize>,
    /// Worker threads (default: all cores). The image is the same for any count.
    #[arg(long, value_name = "T", value_parser = super::num::threads)]
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
    let spp = args.spp.unwrap_or(description.image.samples_per_pixel);
    let width = args.width;
    let option = if args.output.is_some() {
        "-o"
    } else {
        "the default -o"
    };
    let output = args
        .output
        .unwrap_or_else(|| PathBuf::from(format!("{name}.png")));
    rtoracle::output::check_output_file(&output, option)?;
    let format = OutputFormat::of(&output, option)?;

    let camera = description.camera(width);
    if camera.width.saturating_mul(camera.height) > MAX_PIXELS {
        let what = match width {
            Some(w) => format!("--width {w}"),
            None => name.clone(),
        };
        anyhow::bail!(
            "{what}: a {}x{} image is too large (at most {MAX_PIXELS} pixels)",
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
    errln!(
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
    fn of(path: &std::path::Path, option: &str) -> anyhow::Result<Self> {
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("png") => Ok(OutputFormat::Png),
            Some("exr") => Ok(OutputFormat::Exr),
            _ if name.starts_with('.') && !name[1..].contains('.') => anyhow::bail!(
                "{option} {}: the name has no extension ('{name}' is a hidden file's whole name); \
                 give a name such as out.png or out.exr",
                path.display()
            ),
            _ => anyhow::bail!(
                "{option} {}: cannot write this kind of image; use a .png or .exr name",
                path.display()
            ),
        }
    }
}
