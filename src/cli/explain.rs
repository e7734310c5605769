use std::process::ExitCode;

/// `rtoracle explain` (to be written).
#[derive(Debug, clap::Args)]
pub struct Args {}

pub fn run(_args: Args) -> anyhow::Result<ExitCode> {
    anyhow::bail!("'explain' is not implemented yet")
}
