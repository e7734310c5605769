use std::process::ExitCode;

/// `rtoracle fuzz` (to be written).
#[derive(Debug, clap::Args)]
pub struct Args {}

pub fn run(_args: Args) -> anyhow::Result<ExitCode> {
    anyhow::bail!("'fuzz' is not implemented yet")
}
