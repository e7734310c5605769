//! Arithmetic that can be trusted to decide a sign: outward-rounded intervals ([`Iv`]), exact
//! dyadic rationals ([`Dyadic`]), what both provide ([`Num`]), and the decisions of a ray against
//! a sphere, a quad or a triangle written once over both ([`sphere_decide`], [`plane_decide`]).
//!
//! This is the bottom of the house: it imports nothing else of the crate, so the reference's
//! watertight triangle (in [`crate::geometry`]) and the intersection oracle (in
//! [`crate::oracle`]) decide their hard cases with the same code.

mod dyadic;
mod interval;
mod num;
mod predicates;

pub use dyadic::Dyadic;
pub use interval::{Iv, next_down, next_up};
pub use num::{Num, V3};
pub use predicates::{Decision, Line, PlaneKind, PlaneSigns, Root, plane_decide, sphere_decide};
