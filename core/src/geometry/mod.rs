//! Rays, bounds and the ray–primitive intersection routines, in object space.

mod aabb;
mod primitives;
mod ray;

pub use aabb::Aabb;
pub use primitives::{intersect_plane, intersect_sphere, intersect_triangle, sphere_roots, triangle_normal};
pub use ray::Ray;

pub(crate) use primitives::moller_trumbore;
