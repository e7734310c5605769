use std::process::ExitCode;

/// `rtoracle grade` (to be written).
#[derive(Debug, clap::Args)]
pub struct Args {}

pub fn run(_args: Args) -> anyhow::Result<ExitCode> {
    anyhow::bail!("'grade' is not implemented yet")
}
