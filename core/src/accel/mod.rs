//! Acceleration structures: a binned-SAH BVH over boxes (the scene's objects), and an 8-wide
//! BVH over a mesh's triangles.

mod bvh;
mod sah;
mod slab;
mod triangles;
mod wide;

pub use bvh::{Bvh, BvhNode};
pub use triangles::{TriangleBvh, TriangleHit};
