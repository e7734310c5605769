use std::process::ExitCode;

/// `rtoracle golden` (to be written).
#[derive(Debug, clap::Args)]
pub struct Args {}

pub fn run(_args: Args) -> anyhow::Result<ExitCode> {
    anyhow::bail!("'golden' is not implemented yet")
}
