use std::process::ExitCode;

/// `rtoracle bench` (to be written).
#[derive(Debug, clap::Args)]
pub struct Args {}

pub fn run(_args: Args) -> anyhow::Result<ExitCode> {
    anyhow::bail!("'bench' is not implemented yet")
}
