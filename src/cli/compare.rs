use std::process::ExitCode;

/// `rtoracle compare` (to be written).
#[derive(Debug, clap::Args)]
pub struct Args {}

pub fn run(_args: Args) -> anyhow::Result<ExitCode> {
    anyhow::bail!("'compare' is not implemented yet")
}
