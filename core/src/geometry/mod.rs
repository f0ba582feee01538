//! Rays, bounds and the ray–primitive intersection routines, in object space.

mod aabb;
mod primitives;
mod ray;
mod transform;

pub use aabb::Aabb;
pub use primitives::{
    box_face_normal, box_span, intersect_plane, intersect_sphere, intersect_triangle,
    sphere_bounds, sphere_normal, sphere_roots, triangle_normal,
};
pub use ray::Ray;
pub use transform::Transform;

pub(crate) use primitives::moller_trumbore;
