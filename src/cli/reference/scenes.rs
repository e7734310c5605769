use std::path::PathBuf;
use std::process::ExitCode;

use rtoracle::scene::{BUILTIN_SCENES, TextureSource};

/// `rtoracle scenes [--dump NAME [--textures DIR] [--profile P] | --export mitsuba NAME [--profile P]]`
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Print the built-in scene NAME as a TOML scene file instead of listing the scenes.
    #[arg(long, value_name = "NAME")]
    dump: Option<String>,
    /// With --dump: the scene's image textures from the course's files in DIR (written as
    /// absolute paths) instead of the pictures rtoracle generates.
    #[arg(long, value_name = "DIR", requires = "dump")]
    textures: Option<PathBuf>,
    /// With --dump or --export: the scene under this profile (course or physical) instead of its
    /// own.
    #[arg(long, value_name = "P", value_parser = crate::cli::reference::render::parse_profile)]
    profile: Option<rtoracle::scene::Profile>,
    /// Print the scene NAME (built-in, or a .toml scene file) for another renderer instead:
    /// `mitsuba` (a Mitsuba 3 scene file, where the two share the physics;
    /// docs/scenes-and-rendering.md).
    #[arg(long, value_name = "FORMAT", requires = "name", conflicts_with_all = ["dump", "textures"], value_parser = ["mitsuba"])]
    export: Option<String>,
    /// With --export: the built-in scene or scene file (`.toml`) to write.
    #[arg(value_name = "NAME|FILE.toml", requires = "export")]
    name: Option<String>,
}

/// Where a built-in scene comes from, as `scenes` lists it.
fn origin(scene: &rtoracle::scene::BuiltinScene) -> String {
    match scene.week {
        Some(week) => format!("week {week}"),
        None if scene.name.starts_with("rtiow") => "book 1".to_string(),
        None => "rtoracle".to_string(),
    }
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    if args.profile.is_some() && args.dump.is_none() && args.export.is_none() {
        anyhow::bail!("--profile is for --dump NAME or --export FORMAT NAME");
    }
    if let Some(name) = &args.name {
        let (_, description) = crate::cli::reference::render::load_scene_with(name, None)?;
        let description =
            crate::cli::reference::render::with_profile(name, description, args.profile)?;
        let xml = rtoracle::scene::to_mitsuba_xml(&description)
            .map_err(|e| anyhow::anyhow!("{name}: {e}"))?;
        out!("{xml}")?;
        return Ok(ExitCode::SUCCESS);
    }
    match args.dump {
        Some(name) => {
            let source = match &args.textures {
                Some(dir) if !dir.is_dir() => {
                    anyhow::bail!("--textures {}: no such folder", dir.display())
                }
                Some(dir) => TextureSource::Folder(dir.clone()),
                None => TextureSource::Generated,
            };
            let description = rtoracle::scene::builtin_with_textures(&name, &source)?;
            let description =
                crate::cli::reference::render::with_profile(&name, description, args.profile)?;
            out!("{}", description.to_toml())?
        }
        None => {
            let width = BUILTIN_SCENES
                .iter()
                .map(|s| s.name.len())
                .max()
                .unwrap_or(0);
            let profiles = |s: &rtoracle::scene::BuiltinScene| {
                s.profiles
                    .iter()
                    .map(|p| p.name())
                    .collect::<Vec<_>>()
                    .join(",")
            };
            let profile_width = BUILTIN_SCENES
                .iter()
                .map(|s| profiles(s).len())
                .max()
                .unwrap_or(0);
            for s in BUILTIN_SCENES {
                outln!(
                    "{:width$}  {:8}  {:profile_width$}  {}",
                    s.name,
                    origin(s),
                    profiles(s),
                    s.summary
                )?;
            }
        }
    }
    Ok(ExitCode::SUCCESS)
}
