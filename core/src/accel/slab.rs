//! The slab test of one box, shared by the top-level BVH and the mesh BVH's root box.

use glam::Vec3A;

/// (near, far): where the ray `o + t d` (`inv` = 1 / d) enters and leaves the box [lo, hi],
/// clamped to [t_min, t_max]; it meets the box when near <= far.
#[inline(always)]
pub fn span(lo: Vec3A, hi: Vec3A, o: Vec3A, inv: Vec3A, t_min: f32, t_max: f32) -> (f32, f32) {
    let (t0, t1) = ((lo - o) * inv, (hi - o) * inv);
    // Packed clamps: maxps/minps return the second operand for a NaN lane (0 * inf), so that
    // axis drops out, without the scalar NaN checks of f32::max.
    let near = t0.min(t1).max(Vec3A::splat(t_min)).max_element();
    let far = t0.max(t1).min(Vec3A::splat(t_max)).min_element();
    (near, far)
}
