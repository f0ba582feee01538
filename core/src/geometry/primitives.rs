//! Closest-hit routines for the analytic primitives. Each returns the smallest t in
//! (t_min, t_max) and leaves normals to the caller, who builds them once for the closest hit.

use glam::Vec3;

use super::Ray;

/// Both roots of |o + t d − c|² = r², the smaller first. Works for unnormalised d. CSG
/// takes both (entry and exit); `intersect_sphere` the first in range, so a CSG sphere and a
/// plain one meet a ray at the same t to the last bit.
#[inline]
pub fn sphere_roots(ray: &Ray, center: Vec3, radius: f32) -> Option<(f32, f32)> {
    let oc = ray.origin - center;
    let a = ray.direction.length_squared();
    let half_b = oc.dot(ray.direction);
    let c = oc.length_squared() - radius * radius;
    let disc = half_b * half_b - a * c;
    // Under a strong scale (a radius-1e10 sphere inside ten UniformScale 0.1) the squares
    // leave f32's range: solve those rare rays in f64 instead of missing them.
    if !(disc.is_finite() && a.is_normal() && (half_b * half_b).is_finite()) {
        return sphere_roots_f64(ray, center, radius);
    }
    if disc < 0.0 {
        return None;
    }
    let sq = disc.sqrt();
    // Numerically stable pair of roots.
    let q = -half_b - sq.copysign(half_b);
    let (t0, t1) = if q != 0.0 {
        (q / a, c / q)
    } else {
        (-half_b / a, -half_b / a)
    };
    Some(if t0 > t1 { (t1, t0) } else { (t0, t1) })
}

#[cold]
fn sphere_roots_f64(ray: &Ray, center: Vec3, radius: f32) -> Option<(f32, f32)> {
    let oc = (ray.origin - center).as_dvec3();
    let d = ray.direction.as_dvec3();
    let a = d.length_squared();
    let half_b = oc.dot(d);
    let c = oc.length_squared() - f64::from(radius) * f64::from(radius);
    let disc = half_b * half_b - a * c;
    if !(disc >= 0.0 && a > 0.0 && disc.is_finite()) {
        return None;
    }
    let q = -half_b - disc.sqrt().copysign(half_b);
    let (t0, t1) = if q != 0.0 {
        (q / a, c / q)
    } else {
        (-half_b / a, -half_b / a)
    };
    let (t0, t1) = if t0 > t1 { (t1, t0) } else { (t0, t1) };
    Some((t0 as f32, t1 as f32))
}

/// Smallest root of |o + t d − c|² = r² in (t_min, t_max).
#[inline]
pub fn intersect_sphere(
    ray: &Ray,
    center: Vec3,
    radius: f32,
    t_min: f32,
    t_max: f32,
) -> Option<f32> {
    let (t0, t1) = sphere_roots(ray, center, radius)?;
    if t0 > t_min && t0 < t_max {
        Some(t0)
    } else if t1 > t_min && t1 < t_max {
        Some(t1)
    } else {
        None
    }
}

/// The plane {p : n·p = offset}. A ray parallel to it never hits.
#[inline]
pub fn intersect_plane(
    ray: &Ray,
    normal: Vec3,
    offset: f32,
    t_min: f32,
    t_max: f32,
) -> Option<f32> {
    let denom = normal.dot(ray.direction);
    if denom == 0.0 {
        return None;
    }
    let t = (offset - normal.dot(ray.origin)) / denom;
    (t > t_min && t < t_max).then_some(t)
}

/// Möller–Trumbore, two-sided. Returns (t, u, v).
#[inline]
pub fn intersect_triangle(
    ray: &Ray,
    a: Vec3,
    b: Vec3,
    c: Vec3,
    t_min: f32,
    t_max: f32,
) -> Option<(f32, f32, f32)> {
    let (t, u, v) = moller_trumbore(ray.origin, ray.direction, a, b - a, c - a)?;
    (t > t_min && t < t_max).then_some((t, u, v))
}

/// Two-sided Möller–Trumbore against the triangle `v0 + u e1 + v e2`: (t, u, v) where the ray
/// `o + t d` crosses it, t not range-checked. The one scalar copy of the test: the mesh BVH's
/// AVX leaf repeats these operations lane by lane, so every path gives the same t bit for bit.
///
/// The inside test compares the undivided barycentrics with the determinant (0 ≤ u·det ≤ det,
/// v·det ≥ 0, (u + v)·det ≤ det, signs taken from det), as Möller and Trumbore's paper and the
/// course's programs do; only t, u and v of a hit are divided. A ray exactly on an edge then
/// falls on the side those programs put it: dividing first rounds u + v past 1 for some of
/// them (scene7_01's 3×3 uniform samples on the edge x + y = 0 at 12×12 differed on 8 pixels).
///
/// When the determinant overflows f32 (edges of ~1.8e19 and more seen by a unit ray) the
/// test is done again in f64, which holds every product of f32 numbers: the triangle is
/// still found where its edges are f32 numbers. The AVX leaf sends those lanes here too.
#[inline(always)]
pub(crate) fn moller_trumbore(
    o: Vec3,
    d: Vec3,
    v0: Vec3,
    e1: Vec3,
    e2: Vec3,
) -> Option<(f32, f32, f32)> {
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 {
        return None;
    }
    if !det.is_finite() {
        return moller_trumbore_f64(o, d, v0, e1, e2);
    }
    // Negating both sides of a comparison is exact: compare in det's sign.
    let sign = if det < 0.0 { -1.0 } else { 1.0 };
    let abs_det = det * sign;
    let s = o - v0;
    let u_det = s.dot(p);
    if !(0.0..=abs_det).contains(&(u_det * sign)) {
        return None;
    }
    let q = s.cross(e1);
    let v_det = d.dot(q);
    // A NaN v passes, as it always has (the AVX leaves repeat this).
    if v_det * sign < 0.0 || (u_det + v_det) * sign > abs_det {
        return None;
    }
    let inv_det = 1.0 / det;
    Some((e2.dot(q) * inv_det, u_det * inv_det, v_det * inv_det))
}

/// `moller_trumbore` in f64, for the triangles whose determinant overflows f32. A t past
/// f32's range comes back infinite, and so out of any range tested.
#[cold]
#[inline(never)]
pub(crate) fn moller_trumbore_f64(
    o: Vec3,
    d: Vec3,
    v0: Vec3,
    e1: Vec3,
    e2: Vec3,
) -> Option<(f32, f32, f32)> {
    let (o, d, v0, e1, e2) = (
        o.as_dvec3(),
        d.as_dvec3(),
        v0.as_dvec3(),
        e1.as_dvec3(),
        e2.as_dvec3(),
    );
    let p = d.cross(e2);
    let det = e1.dot(p);
    // Infinite or NaN only when an edge is: an edge past f32::MAX was never a number here.
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    // The f32 test's comparisons, undivided, in det's sign.
    let sign = if det < 0.0 { -1.0 } else { 1.0 };
    let abs_det = det * sign;
    let s = o - v0;
    let u_det = s.dot(p);
    if !(0.0..=abs_det).contains(&(u_det * sign)) {
        return None;
    }
    let q = s.cross(e1);
    let v_det = d.dot(q);
    if v_det * sign < 0.0 || (u_det + v_det) * sign > abs_det {
        return None;
    }
    let inv_det = 1.0 / det;
    Some((
        (e2.dot(q) * inv_det) as f32,
        (u_det * inv_det) as f32,
        (v_det * inv_det) as f32,
    ))
}

/// The face normal (b − a) × (c − a), normalised: counter-clockwise vertices face the viewer.
/// In f32 where that is exact enough (every triangle of ordinary size, so renders stay what
/// they were); where f32 fails (edges past ~4e9 overflow the squared length, past ~1.8e19 the
/// cross product, past f32::MAX the edges themselves; tiny triangles underflow) in f64,
/// whose range holds every product of f32 coordinates. Zero only for a degenerate triangle.
#[inline]
pub fn triangle_normal(a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    let n = (b - a).cross(c - a);
    // `normalize_or_zero`'s own test: 1/|n| finite and positive.
    let rcp = n.length_recip();
    if rcp.is_finite() && rcp > 0.0 {
        n * rcp
    } else {
        triangle_normal_f64(a, b, c)
    }
}

/// `triangle_normal` for the triangles f32 cannot take. The packet shader calls it for the
/// same lanes, so both paths give the same bits.
#[cold]
pub(crate) fn triangle_normal_f64(a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    let (a, b, c) = (a.as_dvec3(), b.as_dvec3(), c.as_dvec3());
    (b - a).cross(c - a).normalize_or_zero().as_vec3()
}

/// A box face: axis · 2 + 1 for the max side. Its outward normal is `box_face_normal`.
pub fn box_face_normal(face: u32) -> Vec3 {
    let axis = (face / 2).min(2) as usize;
    let mut n = Vec3::ZERO;
    n[axis] = if face % 2 == 1 { 1.0 } else { -1.0 };
    n
}

/// Where a ray is inside an axis-aligned box, by slabs, over the whole line:
/// (t_enter, entry face, t_exit, exit face), or None if it misses (or only grazes an edge).
pub fn box_span(ray: &Ray, min: Vec3, max: Vec3) -> Option<(f32, u32, f32, u32)> {
    let (o, d) = (ray.origin, ray.direction);
    let (mut near, mut near_face) = (f32::NEG_INFINITY, 0u32);
    let (mut far, mut far_face) = (f32::INFINITY, 0u32);
    for axis in 0..3 {
        if d[axis] == 0.0 {
            // Parallel to this slab: inside it everywhere or nowhere.
            if o[axis] < min[axis] || o[axis] > max[axis] {
                return None;
            }
            continue;
        }
        let inv = 1.0 / d[axis];
        let (t_lo, t_hi) = ((min[axis] - o[axis]) * inv, (max[axis] - o[axis]) * inv);
        let a = axis as u32 * 2;
        // Moving toward +axis the ray enters through the min face and leaves through the max.
        let (t_in, f_in, t_out, f_out) = if d[axis] > 0.0 {
            (t_lo, a, t_hi, a + 1)
        } else {
            (t_hi, a + 1, t_lo, a)
        };
        if t_in > near {
            near = t_in;
            near_face = f_in;
        }
        if t_out < far {
            far = t_out;
            far_face = f_out;
        }
    }
    (near < far).then_some((near, near_face, far, far_face))
}

/// The box around a sphere (a negative radius is a sphere of its absolute size).
pub fn sphere_bounds(center: Vec3, radius: f32) -> super::Aabb {
    super::Aabb::new(
        center - Vec3::splat(radius.abs()),
        center + Vec3::splat(radius.abs()),
    )
}

/// A sphere's outward normal at `p` (Z where `p` is its centre).
#[inline]
pub fn sphere_normal(center: Vec3, p: Vec3) -> Vec3 {
    (p - center).normalize_or(Vec3::Z)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_hit_from_outside_gives_near_root() {
        let r = Ray::new(Vec3::new(0.0, 0.0, 10.0), Vec3::NEG_Z);
        let t = intersect_sphere(&r, Vec3::ZERO, 1.0, 0.0, f32::INFINITY);
        assert_eq!(t, Some(9.0));
    }

    #[test]
    fn sphere_hit_from_inside_gives_far_root() {
        let r = Ray::new(Vec3::ZERO, Vec3::X);
        assert_eq!(
            intersect_sphere(&r, Vec3::ZERO, 2.0, 0.0, f32::INFINITY),
            Some(2.0)
        );
    }

    #[test]
    fn sphere_with_unnormalised_direction_keeps_parameter_meaning() {
        let r = Ray::new(Vec3::new(0.0, 0.0, 10.0), Vec3::new(0.0, 0.0, -2.0));
        assert_eq!(
            intersect_sphere(&r, Vec3::ZERO, 1.0, 0.0, f32::INFINITY),
            Some(4.5)
        );
    }

    #[test]
    fn sphere_miss_and_negative_tmin_behaviour() {
        let r = Ray::new(Vec3::new(0.0, 5.0, 10.0), Vec3::NEG_Z);
        assert_eq!(
            intersect_sphere(&r, Vec3::ZERO, 1.0, 0.0, f32::INFINITY),
            None
        );
        // Sphere behind the origin is found only with t_min = -inf (orthographic cameras).
        let r = Ray::new(Vec3::new(0.0, 0.0, -10.0), Vec3::NEG_Z);
        assert_eq!(
            intersect_sphere(&r, Vec3::ZERO, 1.0, 0.0, f32::INFINITY),
            None
        );
        assert_eq!(
            intersect_sphere(&r, Vec3::ZERO, 1.0, f32::NEG_INFINITY, f32::INFINITY),
            Some(-11.0)
        );
    }

    #[test]
    fn plane_hit_matches_offset() {
        let r = Ray::new(Vec3::new(0.0, 5.0, 0.0), Vec3::NEG_Y);
        assert_eq!(
            intersect_plane(&r, Vec3::Y, -2.0, 0.0, f32::INFINITY),
            Some(7.0)
        );
        let parallel = Ray::new(Vec3::new(0.0, 5.0, 0.0), Vec3::X);
        assert_eq!(
            intersect_plane(&parallel, Vec3::Y, -2.0, 0.0, f32::INFINITY),
            None
        );
    }

    #[test]
    fn triangle_hit_inside_and_miss_outside() {
        let (a, b, c) = (Vec3::ZERO, Vec3::X, Vec3::Y);
        let r = Ray::new(Vec3::new(0.25, 0.25, 3.0), Vec3::NEG_Z);
        let (t, u, v) = intersect_triangle(&r, a, b, c, 0.0, f32::INFINITY).expect("hit");
        assert!((t - 3.0).abs() < 1e-6 && (u - 0.25).abs() < 1e-6 && (v - 0.25).abs() < 1e-6);
        let r = Ray::new(Vec3::new(0.75, 0.75, 3.0), Vec3::NEG_Z);
        assert!(intersect_triangle(&r, a, b, c, 0.0, f32::INFINITY).is_none());
        // Two-sided: hit from behind too.
        let r = Ray::new(Vec3::new(0.25, 0.25, -3.0), Vec3::Z);
        assert!(intersect_triangle(&r, a, b, c, 0.0, f32::INFINITY).is_some());
        assert_eq!(triangle_normal(a, b, c), Vec3::Z);
    }

    /// Edges of 1e10 overflow the f32 squared length, 1e19 the cross product, 3e38 (corners
    /// at ±3e38) the edges themselves: the normal is still the plane's, in every case and
    /// both windings; tiny triangles whose squared length underflows too.
    #[test]
    fn triangle_normals_survive_any_f32_size() {
        for s in [1e10f32, 1e19, 3e38, 1e-20] {
            let (a, b, c) = (
                Vec3::new(-s, -s, 0.0),
                Vec3::new(s, -s, 0.0),
                Vec3::new(0.0, s, 0.0),
            );
            assert_eq!(triangle_normal(a, b, c), Vec3::Z, "{s:e}");
            assert_eq!(triangle_normal(a, c, b), Vec3::NEG_Z, "{s:e}");
            let tilted = triangle_normal(a, b, Vec3::new(0.0, s, s));
            assert!(
                (tilted - Vec3::new(0.0, -1.0, 2.0).normalize()).length() < 1e-6,
                "{s:e}"
            );
        }
        // Ordinary triangles keep their f32 normal bit for bit.
        let (a, b, c) = (Vec3::new(0.1, 0.2, 0.3), Vec3::new(1.7, -0.4, 2.0), Vec3::Y);
        assert_eq!(triangle_normal(a, b, c), (b - a).cross(c - a).normalize());
        assert_eq!(
            triangle_normal(Vec3::ZERO, Vec3::X, Vec3::X * 2.0),
            Vec3::ZERO
        );
    }

    /// A determinant that overflows f32 (edges of 1e19 and up) is redone in f64: the hit is
    /// found at the right t; edges past f32::MAX cannot be, as b − a is no f32 number.
    #[test]
    fn huge_triangles_are_hit_where_their_edges_are_f32_numbers() {
        let r = Ray::new(Vec3::new(0.25, 0.25, 3.0), Vec3::NEG_Z);
        for s in [1e10f32, 1e19, 1.5e38] {
            let (a, b, c) = (
                Vec3::new(-s, -s, 0.0),
                Vec3::new(s, -s, 0.0),
                Vec3::new(0.0, s, 0.0),
            );
            let hit = intersect_triangle(&r, a, b, c, 0.0, f32::INFINITY);
            assert_eq!(hit.map(|h| h.0), Some(3.0), "{s:e}");
        }
        let (a, b, c) = (
            Vec3::new(-3e38, -3e38, 0.0),
            Vec3::new(3e38, -3e38, 0.0),
            Vec3::new(0.0, 3e38, 0.0),
        );
        assert!(intersect_triangle(&r, a, b, c, 0.0, f32::INFINITY).is_none());
    }

    /// scene7_01's triangle and two of output7_01d_low_res's uniform samples that lie exactly
    /// on its edge x + y = 0 (x = −y to the bit): inside, as the course's programs find them
    /// (their undivided comparison u·det + v·det ≤ det). The control: dividing by det first,
    /// as this test did before, rounds u + v past 1 and leaves them out.
    #[test]
    fn a_ray_exactly_on_an_edge_is_inside_as_the_course_programs_find_it() {
        let (a, b, c) = (
            Vec3::new(-2.0, -2.0, 0.0),
            Vec3::new(1.8, -1.8, 0.0),
            Vec3::new(-1.95, 1.95, 0.0),
        );
        for bits in [0x3f97_1c72_u32, 0x3ef8_e38c] {
            let x = f32::from_bits(bits);
            let r = Ray::new(Vec3::new(x, -x, 10.0), Vec3::NEG_Z);
            let (t, u, v) = intersect_triangle(&r, a, b, c, 0.0, f32::INFINITY).expect("inside");
            assert!(
                (t - 10.0).abs() < 1e-5 && (u + v - 1.0).abs() < 1e-6,
                "{t} {u} {v}"
            );
            // Control: the divided form rejects this very ray.
            let (e1, e2) = (b - a, c - a);
            let p = r.direction.cross(e2);
            let inv = 1.0 / e1.dot(p);
            let s = r.origin - a;
            let (u, v) = (s.dot(p) * inv, r.direction.dot(s.cross(e1)) * inv);
            assert!(u + v > 1.0, "not a tie the divided test loses: {x}");
        }
    }

    #[test]
    fn degenerate_triangle_never_hits() {
        let r = Ray::new(Vec3::new(0.5, 0.0, 3.0), Vec3::NEG_Z);
        assert!(
            intersect_triangle(&r, Vec3::ZERO, Vec3::X, Vec3::X * 2.0, 0.0, f32::INFINITY)
                .is_none()
        );
    }

    #[test]
    fn box_span_names_entry_and_exit_faces() {
        let r = Ray::new(Vec3::new(-5.0, 0.0, 0.0), Vec3::X);
        let (t0, f0, t1, f1) = box_span(&r, Vec3::splat(-1.0), Vec3::splat(1.0)).expect("hit");
        assert_eq!((t0, t1), (4.0, 6.0));
        assert_eq!(
            (box_face_normal(f0), box_face_normal(f1)),
            (Vec3::NEG_X, Vec3::X)
        );
        let miss = Ray::new(Vec3::new(-5.0, 2.0, 0.0), Vec3::X);
        assert!(box_span(&miss, Vec3::splat(-1.0), Vec3::splat(1.0)).is_none());
    }
}
