//! A world-from-object transform with its inverse and normal matrix, computed once.

use glam::{DMat4, Mat3, Mat4, Vec3};

use super::Aabb;

/// A transform with everything rays and normals need, computed once.
#[derive(Clone, Copy, Debug)]
pub struct Transform {
    pub world_from_object: Mat4,
    pub object_from_world: Mat4,
    /// (M⁻¹)ᵀ for normals: M itself skews them under non-uniform scale and shear.
    pub normal_from_object: Mat3,
}

impl Transform {
    /// Inverts once, here, so no ray ever pays for it.
    pub fn new(world_from_object: Mat4) -> Transform {
        Self::from_pair(world_from_object, world_from_object.inverse())
    }

    /// From a matrix composed in f64: inverted there, so tiny and huge scales keep their
    /// digits in the f32 pair.
    pub fn from_f64(world_from_object: DMat4) -> Transform {
        Self::from_pair(
            world_from_object.as_mat4(),
            world_from_object.inverse().as_mat4(),
        )
    }

    fn from_pair(world_from_object: Mat4, inv: Mat4) -> Transform {
        Transform {
            world_from_object,
            object_from_world: inv,
            normal_from_object: Mat3::from_mat4(inv).transpose(),
        }
    }

    /// An object-space normal in world space by (M⁻¹)ᵀ, normalised: perpendicular to the
    /// surface under any affine M. (`n` itself if that is degenerate.)
    #[inline]
    pub fn normal_by_inverse_transpose(&self, n: Vec3) -> Vec3 {
        (self.normal_from_object * n).normalize_or(n)
    }

    /// The lecture's incorrect rule, M·n normalised: right only for similitudes.
    #[inline]
    pub fn normal_by_m(&self, n: Vec3) -> Vec3 {
        self.world_from_object.transform_vector3(n).normalize_or(n)
    }

    /// The world box around an object-space box; an unbounded one (a plane) stays as it is.
    pub fn world_bounds(&self, local: Aabb) -> Aabb {
        if local.is_finite() {
            local.transformed(&self.world_from_object)
        } else {
            local
        }
    }
}
