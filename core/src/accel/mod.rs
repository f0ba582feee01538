//! Acceleration structures: a binned-SAH BVH over boxes (the scene's objects), and an 8-wide
//! BVH over a mesh's triangles.

mod bvh;
mod sah;
mod slab;
mod triangles;
mod wide;

pub use bvh::{Bvh, BvhNode};

/// A broken structural invariant of a BVH, found by `check_invariants` (a tracelab bug, not
/// a user error): what is wrong, naming the node or primitive.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("BVH invariant broken: {0}")]
pub struct InvariantViolation(pub String);
pub use triangles::{TriangleBvh, TriangleHit};
