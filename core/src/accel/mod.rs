//! Acceleration structures: a binned-SAH BVH over boxes (the scene's objects), an 8-wide
//! BVH over a mesh's triangles, and the course's uniform grid (`grid.rs`, `-grid`).

mod bvh;
mod grid;
mod sah;
mod slab;
mod triangles;
mod wide;

pub use bvh::{Bvh, BvhNode};
pub use grid::{CellVisit, MAX_CELLS, MAX_ENTRIES, UniformGrid};
pub use wide::MAX_TRIANGLES;

/// A broken structural invariant of a BVH, found by `check_invariants` (a tracelab bug, not
/// a user error): what is wrong, naming the node or primitive.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("BVH invariant broken: {0}")]
pub struct InvariantViolation(pub String);
pub use triangles::{TriangleBvh, TriangleHit};
