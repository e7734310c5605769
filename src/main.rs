//! The `rtoracle` command: parses the command line and hands each subcommand to the library.
//! Exit codes: 0 success or a passing verdict, 1 a failing verdict, 2 bad input or a harness error.

mod cli;

use std::process::ExitCode;

fn main() -> ExitCode {
    if let Err(err) = rtoracle::interrupt::install() {
        eprintln!("rtoracle: cannot install the signal handlers: {err}");
        return ExitCode::from(2);
    }
    match cli::run() {
        Ok(code) => code,
        Err(err) => {
            // One line: the whole chain of causes, joined by ": ".
            eprintln!("rtoracle: {err:#}");
            ExitCode::from(2)
        }
    }
}
