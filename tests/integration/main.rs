//! One integration-test binary with a module per area (as ripgrep does).

mod architecture;
mod assignment;
mod check;
mod cli;
mod common;
mod compare;
mod compare_report;
mod course_code;
mod course_weeks;
mod feedback;
mod functions;
mod golden;
mod grade;
mod grade_weeks;
mod oracle;
mod oracle_props;
mod protocol;
mod readme;
mod render;
mod render_weeks;
mod renders;
mod reports;
mod sandbox;
mod shards;
