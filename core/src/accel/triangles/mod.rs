//! A BVH over a mesh's triangles: binned SAH on three axes, built in parallel, collapsed into
//! 8-wide nodes by least SAH cost (`wide::collapse`), with the triangles stored in leaf order
//! as (v0, e1, e2) so a leaf test reads contiguous memory and skips two subtractions per
//! triangle.
//!
//! - `build`: the tree and the triangles' copies in leaf order.
//! - `check`: the invariants (for tests) and the tree's shape (for `tracelab bench`).
//! - `traverse`: one ray: the closest hit, with SSE anywhere and AVX where the CPU has it,
//!   whether there is any hit (the same walk, stopped at its first hit: shadow rays), and
//!   every hit (for CSG).
//! - `avx`: the AVX kernels (a ray against eight boxes, against a leaf's eight triangles);
//!   their `unsafe` is only in `load8`, `store8` and `load_row`.
//! - `avx512`: the leaf test with AVX-512 mask registers, for the single-ray traversal
//!   compiled for AVX-512 (`walk_avx512`).
//! - `packet`: eight coherent rays at once (`closest_hit8`, for `tracelab bench --packets`).

use glam::{Vec3, Vec3A};

use super::wide::{self, Child, NODE_UNIT, NODE_UNITS, Node8, RayStack, StackEntry, WIDTH};
use crate::geometry::{Aabb, moller_trumbore};

#[cfg(target_arch = "x86_64")]
mod avx;
#[cfg(target_arch = "x86_64")]
mod avx512;
mod build;
mod check;
mod packet;
#[cfg(test)]
mod tests;
mod traverse;

/// Meshes of at most this many triangles are flat: no nodes, their triangles tested after
/// the root box as leaves of up to eight (two tests at most), in mesh order. For the
/// 12-triangle cube the one node was 224 of 972 bytes (81 bytes a triangle, over issue 32's
/// 68); without it single rays trace as fast, packets 5% slower (`docs/perf.md`).
const FLAT_MAX: usize = 2 * WIDTH;

/// What a box's exit distance is multiplied by before the `near <= far` test, so rounding
/// never culls a box the ray touches: 1 + 2γ₃ (Ize, "Robust BVH Ray Traversal", 2013), where
/// γ₃ = 3u/(1 − 3u) with u = 2⁻²⁴ bounds the relative error of three roundings (the
/// subtraction, the reciprocal, the product) in each of near and far. In f32 that is
/// 1 + 3 ulps of 1 (`1.0 + 3.0 * f32::EPSILON`, checked by a test).
const SLAB_WIDEN: f32 = 1.000_000_4;

#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleBvh {
    /// Node 0 is the root. None for an empty mesh, and none for a flat one (at most
    /// `FLAT_MAX` triangles), whose leaves a walk starts from (`start`).
    nodes: Vec<Node8>,
    /// Triangles in leaf order, one array per component (v0.x, v0.y, v0.z, e1.x, ... e2.z,
    /// each `stride` = triangle count long), so a leaf's up to eight triangles load as one
    /// 8-lane vector per component; lanes past the leaf (the next component's values, or 7
    /// zeros at the very end) are masked off. `ids[i]` is the mesh's index of triangle i.
    soa: Vec<f32>,
    stride: usize,
    ids: Vec<u32>,
    /// The root's box, tested alone before the traversal sets up: most rays of a scene's
    /// frame miss the mesh, and one box is far cheaper than the root's eight.
    root_lo: Vec3A,
    root_hi: Vec3A,
}

impl TriangleBvh {
    /// The node an inner child names (`wide::inner`): the walks' step from a child to its
    /// node, one scaled load (`Child`). Panics on a child past the last node or not on a
    /// multiple of 32 bytes.
    #[inline(always)]
    fn node(&self, c: Child) -> &Node8 {
        let units = c as usize;
        assert!(
            units + NODE_UNITS as usize <= self.nodes.len() * NODE_UNITS as usize
                && (units * NODE_UNIT).is_multiple_of(align_of::<Node8>())
        );
        #[allow(unsafe_code)]
        // SAFETY: the node's bytes lie inside `nodes` and start aligned for Node8 (the
        // assert). A child that is no node's start (none is: `check` tests it) would read
        // parts of two neighbours, initialised `f32`s and `u32`s, for which any bits are
        // valid (Node8 has no padding).
        unsafe {
            &*self
                .nodes
                .as_ptr()
                .cast::<u8>()
                .add(units * NODE_UNIT)
                .cast::<Node8>()
        }
    }
}

impl TriangleBvh {
    /// Where every walk of a non-empty mesh starts: the root node, or a flat mesh's first
    /// leaf, with its other leaves pushed (as `entry(leaf)`, entered at the walk's t_min) so
    /// that they pop in order after it.
    #[inline(always)]
    fn start<E: StackEntry>(&self, stack: &mut RayStack<E>, entry: impl Fn(Child) -> E) -> Child {
        if !self.nodes.is_empty() {
            return 0;
        }
        let n = self.stride;
        let leaf = |k: usize| wide::leaf(k as u32, (n - k).min(WIDTH) as u32);
        let mut k = n.saturating_sub(1) / WIDTH * WIDTH;
        while k > 0 {
            stack.push(entry(leaf(k)));
            k -= WIDTH;
        }
        leaf(0)
    }

    /// Whether the mesh has no triangles.
    #[inline(always)]
    fn is_empty(&self) -> bool {
        self.stride == 0
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    pub t: f32,
    /// Index of the triangle in the mesh's own order.
    pub triangle: u32,
}

/// A stored triangle: a vertex and the two edges from it.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Tri {
    v0: Vec3,
    e1: Vec3,
    e2: Vec3,
}

impl Tri {
    /// The ray parameter of a hit, if any (two-sided, not range-checked): the triangle
    /// primitive's test, which the AVX leaf test repeats bit for bit.
    #[inline(always)]
    fn hit(&self, o: Vec3, d: Vec3) -> Option<f32> {
        moller_trumbore(o, d, self.v0, self.e1, self.e2).map(|(t, _, _)| t)
    }
}

impl TriangleBvh {
    pub fn bounds(&self) -> Aabb {
        if self.is_empty() {
            return Aabb::EMPTY;
        }
        Aabb::new(self.root_lo.into(), self.root_hi.into())
    }

    /// Bytes held by the nodes and the triangle copies.
    pub fn memory_bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<Node8>() + self.soa.len() * 4 + self.ids.len() * 4
    }

    /// Triangle `i` (leaf order) from the component arrays; zeros past the end.
    #[inline(always)]
    fn tri(&self, i: usize) -> Tri {
        let c = |k: usize| self.soa.get(k * self.stride + i).copied().unwrap_or(0.0);
        Tri {
            v0: Vec3::new(c(0), c(1), c(2)),
            e1: Vec3::new(c(3), c(4), c(5)),
            e2: Vec3::new(c(6), c(7), c(8)),
        }
    }
}

/// Whether a ray can be traversed: with finite origin and direction an empty slot's box
/// (+inf..-inf) gives an infinite, never NaN, slab on every axis, so it is never entered.
#[inline(always)]
fn finite_ray(o: Vec3A, d: Vec3A) -> bool {
    o.is_finite() && d.is_finite()
}

/// Whether the AVX traversal and leaf test run here (`crate::simd`: the CPU has AVX and
/// `TRACELAB_SIMD` does not ask for SSE).
#[inline(always)]
fn has_avx() -> bool {
    crate::simd::level() >= crate::simd::Level::Avx
}

/// Whether the AVX-512 kernels run here (the CPU has AVX-512 F and VL, and `TRACELAB_SIMD`
/// does not ask for less).
#[inline(always)]
fn has_avx512() -> bool {
    crate::simd::level() >= crate::simd::Level::Avx512
}

/// Nine component arrays of this length hold `n` triangles, padded so an 8-lane load at the
/// last triangle stays in bounds.
const fn soa_len(n: usize) -> usize {
    9 * n + WIDTH - 1
}
