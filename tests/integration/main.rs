//! One integration-test binary with a module per area (as ripgrep does), each area a folder:
//! render (the reference, goldens, Mitsuba), oracle, check (the protocol, the weekly and physics
//! checks), compare, course (the course's real code), grade, attacks (hostile submissions and the
//! sandbox) and cli (every subcommand's principles, the docs' examples).

mod architecture;
mod attacks;
mod check;
mod cli;
mod common;
mod compare;
mod course;
mod grade;
mod oracle;
mod render;
