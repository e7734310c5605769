//! One integration-test binary with a module per area (as ripgrep does).

mod check;
mod common;
mod compare;
mod golden;
mod grade;
mod oracle;
mod oracle_props;
mod readme;
mod render;
mod sandbox;
