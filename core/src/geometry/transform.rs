//! A world-from-object transform with its inverse and normal matrix, computed once.

use glam::{Affine3A, DMat4, Mat3, Mat4, Vec3, Vec3A};

use super::Aabb;

/// A transform with everything rays and normals need, computed once.
#[derive(Clone, Copy, Debug)]
pub struct Transform {
    pub world_from_object: Mat4,
    pub object_from_world: Mat4,
    /// `object_from_world` without its last row, for `object_ray`.
    object_from_world_affine: Affine3A,
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
            object_from_world_affine: Affine3A::from_mat4(inv),
            normal_from_object: Mat3::from_mat4(inv).transpose(),
        }
    }

    /// An object-space normal in world space by (M⁻¹)ᵀ, normalised: perpendicular to the
    /// surface under any affine M. (`n` itself if that is degenerate.)
    #[inline]
    pub fn normal_by_inverse_transpose(&self, n: Vec3) -> Vec3 {
        (self.normal_from_object * n).normalize_or(n)
    }

    /// A world ray `origin + t direction` in object space, as the mesh traversals take it:
    /// the origin as a point, the direction as a vector, not renormalised (so t is the same
    /// in both spaces). `object_from_world.transform_point3` / `transform_vector3` bit for
    /// bit (the same products and sums in the same order, the last row ignored as they
    /// ignore it), in 16-byte lanes: fewer shuffles on every ray, bunny_1k's single rays
    /// 4.5% faster (`docs/perf.md`).
    #[inline]
    pub fn object_ray(&self, origin: Vec3, direction: Vec3) -> (Vec3A, Vec3A) {
        let m = &self.object_from_world_affine;
        (
            m.transform_point3a(origin.into()),
            m.transform_vector3a(direction.into()),
        )
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

#[cfg(test)]
mod tests {
    use glam::{DMat4, DQuat, DVec3, DVec4, Vec3};

    use super::Transform;

    /// `object_ray` gives `object_from_world`'s `transform_point3` and `transform_vector3`
    /// bit for bit, so the one-mesh fast path and every other path see the same object-space
    /// rays (fails if either changes its order of operations, or uses FMA).
    #[test]
    fn object_ray_is_the_matrix_transform_bit_for_bit() {
        let mut s = 0x2545_f491u32;
        let mut f = move || {
            s ^= s << 13;
            s ^= s >> 17;
            s ^= s << 5;
            s as f32 / u32::MAX as f32 * 2.0 - 1.0
        };
        let mut compared = 0;
        for k in 0..200 {
            let scale = DVec3::new(f() as f64, f() as f64, f() as f64) * 7.0 + 0.01;
            let turn = DQuat::from_euler(glam::EulerRot::XYZ, f() as f64, f() as f64, 3.0);
            let shift = DVec3::new(f() as f64, f() as f64, f() as f64) * 30.0;
            let shear = DMat4::from_cols(
                DVec4::new(1.0, f() as f64, 0.0, 0.0),
                DVec4::Y,
                DVec4::new(f() as f64, 0.0, 1.0, 0.0),
                DVec4::W,
            );
            let m = DMat4::from_scale_rotation_translation(scale, turn, shift) * shear;
            let xf = if k % 2 == 0 {
                Transform::from_f64(m)
            } else {
                Transform::new(m.as_mat4())
            };
            for _ in 0..50 {
                let o = Vec3::new(f(), f(), f()) * 100.0;
                let d = Vec3::new(f(), f(), f());
                let (lo, ld) = xf.object_ray(o, d);
                let want_o = xf.object_from_world.transform_point3(o);
                let want_d = xf.object_from_world.transform_vector3(d);
                assert_eq!(
                    Vec3::from(lo).to_array().map(f32::to_bits),
                    want_o.to_array().map(f32::to_bits)
                );
                assert_eq!(
                    Vec3::from(ld).to_array().map(f32::to_bits),
                    want_d.to_array().map(f32::to_bits)
                );
                compared += 1;
            }
        }
        assert_eq!(compared, 10_000);
    }
}
