use std::process::ExitCode;

use rtoracle::scene::{BUILTIN_SCENES, builtin};

/// `rtoracle scenes [--dump NAME]`
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Print the built-in scene NAME as a TOML scene file instead of listing the scenes.
    #[arg(long, value_name = "NAME")]
    dump: Option<String>,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    match args.dump {
        Some(name) => out!("{}", builtin(&name)?.to_toml())?,
        None => {
            let width = BUILTIN_SCENES
                .iter()
                .map(|s| s.name.len())
                .max()
                .unwrap_or(0);
            for s in BUILTIN_SCENES {
                outln!("{:width$}  {}", s.name, s.summary)?;
            }
        }
    }
    Ok(ExitCode::SUCCESS)
}
