use std::process::ExitCode;

/// `rtoracle vectors` (to be written).
#[derive(Debug, clap::Args)]
pub struct Args {}

pub fn run(_args: Args) -> anyhow::Result<ExitCode> {
    anyhow::bail!("'vectors' is not implemented yet")
}
