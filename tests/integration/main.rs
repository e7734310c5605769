//! One integration-test binary with a module per area (as ripgrep does).

mod architecture;
mod assignment;
mod check;
mod cli;
mod common;
mod compare;
mod course_weeks;
mod golden;
mod grade;
mod oracle;
mod oracle_props;
mod protocol;
mod readme;
mod render;
mod reports;
mod sandbox;
