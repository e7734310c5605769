//! What makes a world quick to query, beside the scene it holds: a bounding volume hierarchy
//! over many objects, the shapes gathered by kind into flat arrays, and their four-ray lanes.
//!
//! - `bvh`: the hierarchy, built when a scene has at least `BVH_MIN_OBJECTS` objects.
//! - `shape_set`: the shapes by kind in flat arrays, and the scalar loop over them.
//! - `shape_lanes`: the same shapes four rays at a time (AVX2 on x86_64, portable lanes
//!   elsewhere), with the same arithmetic as the reference primitives.

pub(super) mod bvh;
pub(super) mod shape_set;
pub(super) mod shape_lanes;
