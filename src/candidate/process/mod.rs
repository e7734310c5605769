//! A candidate as a process: what it runs, the lines it speaks, and the session that runs it.
//!
//! - [`command`]: [`CandidateCommand`](command::CandidateCommand), an `--adapter` command line
//!   or the bundled course adapter on a submission folder, and the sandbox made for it; the
//!   adapter's Python sources, embedded.
//! - [`python`]: choosing the interpreter of the course adapter (the assignment's modules,
//!   runnable in the sandbox).
//! - [`protocol`]: request and answer lines, the hello (`docs/PROTOCOL.md`); [`lines`]: the
//!   strict reading of each line; [`pipe`]: the pipes, bounded and with deadlines.
//! - [`session`]: [`Session`](session::Session) runs a command in the
//!   [sandbox](crate::sandbox) with pipelined requests, per-case time-outs, restarts after
//!   crashes and the process group killed on drop; [`options`], [`error`] and [`outcome`] are
//!   its settings, its harness errors and what one case got.
//! - [`render_request`]: the `render` request, a scene rendered tile by tile with the
//!   candidate's own code, with bounds on what comes back.

pub mod error;
pub mod options;
pub mod protocol;
pub mod lines;
pub mod outcome;
pub mod pipe;
pub mod python;
pub mod command;
pub mod session;
pub mod render_request;
