//! Acceleration structures: a binned-SAH BVH over boxes, and a triangle BVH for meshes.

mod bvh;
mod triangles;

pub use bvh::{Bvh, BvhNode};
pub use triangles::{TriangleBvh, TriangleHit};
