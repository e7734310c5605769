//! One integration-test binary with a module per area (as ripgrep does).

mod common;
mod oracle;
mod oracle_props;
mod render;
