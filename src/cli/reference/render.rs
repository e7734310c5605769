use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use rtoracle::render::{RenderOptions, render};
use rtoracle::scene::{Profile, SceneDescription, TextureSource};

/// `rtoracle render (NAME | FILE.toml) [-o OUT.png | OUT.exr] [--spp N] [--seed S] [--width W]
/// [--threads T] [--profile P] [--textures DIR]`
#[derive(Debug, clap::Args)]
pub struct Args {
    /// A built-in scene name (see `rtoracle scenes`) or a TOML scene file.
    scene: String,
    /// Output image: `.png` (the course's 8-bit encoding) or `.exr` (linear f32 RGB).
    /// Default: `NAME.png` in the working directory.
    #[arg(short, long, value_name = "OUT")]
    output: Option<PathBuf>,
    /// Samples per pixel (default: the scene's, 20 for the course scenes).
    #[arg(long, value_name = "N", value_parser = crate::cli::args::spp)]
    spp: Option<u32>,
    /// Seed of the per-pixel random streams.
    #[arg(long, value_name = "S", default_value_t = 0, value_parser = crate::cli::args::seed)]
    seed: u64,
    /// Image width in pixels (the height follows the scene's aspect ratio).
    #[arg(long, value_name = "W", value_parser = crate::cli::args::width)]
    width: Option<usize>,
    /// Worker threads (default: all cores). The image is the same for any count.
    #[arg(long, value_name = "T", value_parser = crate::cli::args::threads)]
    threads: Option<usize>,
    /// Render by these rules instead of the scene's own: `course` (what the course's code of
    /// the scene's week computes) or `physical` (as Ray Tracing in One Weekend computes it).
    #[arg(long, value_name = "P", value_parser = parse_profile)]
    profile: Option<Profile>,
    /// A built-in scene's image textures from the course's files in DIR (earthmap.png,
    /// pepsi.jpg, ...) instead of the pictures rtoracle generates.
    #[arg(long, value_name = "DIR")]
    textures: Option<PathBuf>,
    /// With an .exr output: also write the per-sample variance and deviation layers (what
    /// `compare A B` reads to compare two renders with no golden).
    #[arg(long)]
    variance: bool,
}

/// `--profile`'s value.
pub fn parse_profile(text: &str) -> Result<Profile, String> {
    Profile::from_name(text)
        .ok_or_else(|| format!("'{text}' is not a profile: the profiles are course and physical"))
}

/// The largest image `render` makes: 100 million pixels (2.4 GB of film).
const MAX_PIXELS: usize = 100_000_000;

/// Loads a built-in scene by name, or a scene file when the argument ends in `.toml` or names an
/// existing file; a built-in scene's image textures come from the course's files in `textures`
/// (refused for a scene file, whose textures are its own).
pub fn load_scene_with(
    name: &str,
    textures: Option<&std::path::Path>,
) -> anyhow::Result<(String, SceneDescription)> {
    let path = std::path::Path::new(name);
    if name.ends_with(".toml") || path.is_file() {
        if textures.is_some() {
            anyhow::bail!(
                "--textures: {name} is a scene file, which names its own texture files \
                 (--textures is for the built-in scenes)"
            );
        }
        let stem = path
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("scene")
            .to_string();
        Ok((stem, SceneDescription::from_file(path)?))
    } else {
        let source = match textures {
            Some(dir) if !dir.is_dir() => {
                anyhow::bail!("--textures {}: no such folder", dir.display())
            }
            Some(dir) => TextureSource::Folder(dir.to_path_buf()),
            None => TextureSource::Generated,
        };
        Ok((
            name.to_string(),
            rtoracle::scene::builtin_with_textures(name, &source)?,
        ))
    }
}

/// `description` under `profile` (its own when `None`), checked again for that profile.
pub fn with_profile(
    name: &str,
    mut description: SceneDescription,
    profile: Option<Profile>,
) -> anyhow::Result<SceneDescription> {
    if let Some(profile) = profile {
        if profile != description.profile {
            description.profile = profile;
            description
                .validate(name)
                .with_context(|| format!("--profile {profile}"))?;
        }
    }
    Ok(description)
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let (name, description) = load_scene_with(&args.scene, args.textures.as_deref())?;
    let description = with_profile(&args.scene, description, args.profile)?;
    let profile = description.profile;
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
    if args.variance && !matches!(format, OutputFormat::Exr) {
        anyhow::bail!(
            "--variance: {} is not an .exr output (only an EXR holds the variance layers)",
            output.display()
        );
    }

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
        variance: args.variance,
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
                data: film.to_rgb8(profile),
            },
        )?,
        OutputFormat::Exr => {
            let attributes = vec![
                ("rtoracle.scene".to_string(), name.clone()),
                (
                    "rtoracle.spp".to_string(),
                    film.samples_per_pixel.to_string(),
                ),
                ("rtoracle.profile".to_string(), profile.name().to_string()),
                ("rtoracle.seed".to_string(), args.seed.to_string()),
            ];
            rtoracle::image_io::write_exr(&output, &film, &attributes)?
        }
    }
    let samples = if film.samples_per_pixel == spp {
        format!("{spp} spp")
    } else {
        format!(
            "{spp} spp: {} jittered samples a pixel",
            film.samples_per_pixel
        )
    };
    errln!(
        "rendered {name} ({}x{}, {samples}, seed {}, profile {profile}) to {}",
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
