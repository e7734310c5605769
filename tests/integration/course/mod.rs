//! The course's own code and the fixtures made after it: each week's real skeleton and solution
//! checked function by function (`code`) and graded (`grades`), the hand-written week fixtures
//! (`weeks`), and the week-4 assignment's submissions (`assignment`).

mod assignment;
mod code;
mod grades;
mod weeks;
