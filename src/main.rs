//! The `rtoracle` command: parses the command line and hands each subcommand to the library.
//! Exit codes: 0 success or a passing verdict, 1 a failing verdict, 2 bad input or a harness error,
//! 130 / 143 interrupted by SIGINT / SIGTERM (after removing what was half-written). A closed
//! stdout or stderr never makes it panic (see `cli::out`).

#![deny(clippy::undocumented_unsafe_blocks)]

#[macro_use]
mod cli;

use std::process::ExitCode;

fn main() -> ExitCode {
    // A submission that found a copy of rtoracle must not use it as an oracle.
    if let Some(why) = rtoracle::sandbox::oracles::refusal() {
        errln!("rtoracle: {why}");
        return ExitCode::from(2);
    }
    if let Err(err) = rtoracle::interrupt::install() {
        errln!("rtoracle: cannot install the signal handlers: {err}");
        return ExitCode::from(2);
    }
    let outcome = cli::run();
    // A command cut short by a signal ends with the signal's code, whatever it returned.
    rtoracle::interrupt::exit_if_interrupted();
    match outcome {
        Ok(code) => code,
        Err(err) => {
            // One line: the whole chain of causes, joined by ": ".
            errln!("rtoracle: {err:#}");
            ExitCode::from(2)
        }
    }
}
