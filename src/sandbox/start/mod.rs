//! Starting the code: the command that runs a program inside a sandbox (`command`), under
//! bubblewrap ([`bwrap`]) or the fallback, whose child sets everything up between `fork` and
//! `exec` (`child`), what the code sees of the host ([`view`](crate::sandbox::view), and `pivot` for
//! the fallback's own root), and letting a bubblewrap sandbox's first process start
//! (`admission`).

pub(super) mod admission;
pub mod bwrap;
pub(super) mod pivot;
pub(super) mod child;
pub mod command;
