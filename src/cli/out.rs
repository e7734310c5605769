//! Standard output that a closed pipe cannot crash.
//!
//! `println!` panics when stdout is a pipe whose reader has gone (`rtoracle scenes | head -1`).
//! Every subcommand writes its stdout through [`print`] (or the [`out!`] and [`outln!`] macros)
//! instead: a closed pipe (`EPIPE`; Rust ignores `SIGPIPE`, so the write fails instead of
//! killing the process) marks stdout closed and later writes are skipped, so the subcommand
//! finishes its work, runs its cleanups and exits with its own code (0, or the verdict's), as
//! ripgrep does. Any other write error (a full disk behind a redirection) is returned, and the
//! command fails with exit 2 naming stdout.

use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};

static CLOSED: AtomicBool = AtomicBool::new(false);

/// Writes `text` to stdout and flushes it. A closed pipe is not an error (see the module docs).
pub fn print(text: &str) -> anyhow::Result<()> {
    rtoracle::interrupt::exit_if_interrupted();
    if CLOSED.load(Ordering::Relaxed) {
        return Ok(());
    }
    let mut stdout = std::io::stdout().lock();
    match stdout
        .write_all(text.as_bytes())
        .and_then(|()| stdout.flush())
    {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => {
            CLOSED.store(true, Ordering::Relaxed);
            Ok(())
        }
        Err(e) => Err(anyhow::anyhow!("cannot write to stdout: {e}")),
    }
}

/// `print!` through [`print`]: evaluates to `anyhow::Result<()>`.
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::cli::out::print(&format!($($arg)*))
    };
}

/// `println!` through [`print`]: evaluates to `anyhow::Result<()>`.
macro_rules! outln {
    () => {
        $crate::cli::out::print("\n")
    };
    ($($arg:tt)*) => {
        $crate::cli::out::print(&(format!($($arg)*) + "\n"))
    };
}

/// `eprintln!` that cannot panic: a closed stderr (`2>&1 | head -1`) loses the line quietly.
/// Neither it nor [`print`] writes once a signal has come (see `interrupt::exit_if_interrupted`).
macro_rules! errln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        rtoracle::interrupt::exit_if_interrupted();
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}
