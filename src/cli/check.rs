use std::process::ExitCode;

/// `rtoracle check` (to be written).
#[derive(Debug, clap::Args)]
pub struct Args {}

pub fn run(_args: Args) -> anyhow::Result<ExitCode> {
    anyhow::bail!("'check' is not implemented yet")
}
