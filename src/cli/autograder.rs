use std::process::ExitCode;

/// `rtoracle autograder` (to be written).
#[derive(Debug, clap::Args)]
pub struct Args {}

pub fn run(_args: Args) -> anyhow::Result<ExitCode> {
    anyhow::bail!("'autograder' is not implemented yet")
}
