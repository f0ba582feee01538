//! The AVX kernels: a ray against a node's eight boxes, and against a leaf's up to eight
//! triangles, plus the tail every 8-box test shares (the packet's tests in `packet` too).
//! Every `unsafe` they need is in `load8`, `store8` and `load_row`.

use std::arch::x86_64::*;

use glam::{Vec3A, Vec4};

use super::{SLAB_WIDEN, TriangleBvh};
use crate::accel::wide::{Node8, WIDTH};

/// Eight floats as one register.
#[target_feature(enable = "avx")]
#[inline]
pub(super) fn load8(v: &[f32; WIDTH]) -> __m256 {
    #[allow(unsafe_code)]
    // SAFETY: `v` is 8 contiguous f32, what an unaligned 256-bit load reads.
    unsafe {
        _mm256_loadu_ps(v.as_ptr())
    }
}

/// One register into eight floats.
#[target_feature(enable = "avx")]
#[inline]
pub(super) fn store8(v: &mut [f32; WIDTH], x: __m256) {
    #[allow(unsafe_code)]
    // SAFETY: `v` is 8 contiguous f32, what an unaligned 256-bit store writes.
    unsafe {
        _mm256_storeu_ps(v.as_mut_ptr(), x)
    }
}

const _: () = assert!(std::mem::size_of::<[Vec4; 2]>() == WIDTH * 4);

/// One axis row of a node's boxes (`Node8::lo[a]` or `hi[a]`), slot i in lane i.
#[target_feature(enable = "avx")]
#[inline]
pub(super) fn load_row(row: &[Vec4; 2]) -> __m256 {
    #[allow(unsafe_code)]
    // SAFETY: `[Vec4; 2]` is 8 contiguous f32 (`Vec4` is four f32 with no padding, the
    // assertion above); an unaligned 256-bit load reads exactly them.
    unsafe {
        _mm256_loadu_ps(row.as_ptr().cast::<f32>())
    }
}

/// The end of every 8-box slab test, from the per-axis entry and exit distances of the
/// eight boxes: near = the latest entry or t_min, far = the earliest exit or t_far, widened
/// by `SLAB_WIDEN`. Returns near and the mask of lanes with near <= far.
#[target_feature(enable = "avx")]
#[inline]
pub(super) fn slab_tail(
    entry: [__m256; 3],
    exit: [__m256; 3],
    t_min: __m256,
    t_far: __m256,
) -> (__m256, u32) {
    let (near, far) = near_far(entry, exit, t_min, t_far);
    (near, widened_mask(near, far))
}

/// (near, far) of `slab_tail`, before the widening.
///
/// Operand order matters: maxps/minps return the second operand where the first is NaN (an
/// axis-parallel ray's 0 * inf), so that axis drops out, as in the SSE test.
#[target_feature(enable = "avx")]
#[inline]
fn near_far(
    entry: [__m256; 3],
    exit: [__m256; 3],
    t_min: __m256,
    t_far: __m256,
) -> (__m256, __m256) {
    let near = _mm256_max_ps(
        _mm256_max_ps(entry[0], entry[1]),
        _mm256_max_ps(entry[2], t_min),
    );
    let far = _mm256_min_ps(
        _mm256_min_ps(exit[0], exit[1]),
        _mm256_min_ps(exit[2], t_far),
    );
    (near, far)
}

/// The lanes with near <= far * `SLAB_WIDEN`.
#[target_feature(enable = "avx")]
#[inline]
fn widened_mask(near: __m256, far: __m256) -> u32 {
    let far = _mm256_mul_ps(far, _mm256_set1_ps(SLAB_WIDEN));
    _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(near, far)) as u32
}

/// `SlabRay::slab8` in one register: the ray (origin `o`, reciprocal direction `inv`, and
/// per axis whether it runs toward -axis) against the node's eight boxes. Entry distances go
/// to `t_enter`; bit i is set when slot i is entered within [t_min, t_max].
#[target_feature(enable = "avx")]
#[inline]
pub(super) fn slab8(
    n: &Node8,
    o: Vec3A,
    inv: Vec3A,
    toward_neg: [bool; 3],
    t_min: f32,
    t_max: f32,
    t_enter: &mut [f32; WIDTH],
) -> u32 {
    let slab = |a: usize| {
        let (entry, exit) = n.entry_exit(a, toward_neg[a]);
        let (o, inv) = (_mm256_set1_ps(o[a]), _mm256_set1_ps(inv[a]));
        let dist = |row: &[Vec4; 2]| _mm256_mul_ps(_mm256_sub_ps(load_row(row), o), inv);
        (dist(entry), dist(exit))
    };
    let (nx, fx) = slab(0);
    let (ny, fy) = slab(1);
    let (nz, fz) = slab(2);
    let (t_min, t_max) = (_mm256_set1_ps(t_min), _mm256_set1_ps(t_max));
    let (near, far) = near_far([nx, ny, nz], [fx, fy, fz], t_min, t_max);
    store8(t_enter, near);
    // The mask returned is `slab_tail`'s, near <= far * SLAB_WIDEN. near <= far is the same
    // mask but for a box grazed within rounding, and known three cycles sooner (the
    // multiply), which the walk waits for node after node: it goes on with that mask while
    // the widened one checks it, a branch almost never taken. Single rays +2-3% (packets
    // gained nothing: `docs/perf.md`).
    let unwidened = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(near, far)) as u32;
    let mask = widened_mask(near, far);
    if unwidened != mask {
        return grazed(mask);
    }
    unwidened
}

/// `slab8`'s mask where the widening changed it: out of line, so the common path keeps the
/// unwidened mask and does not wait for the widening. Opaque (`black_box`): returning its
/// argument plainly, LLVM saw that both paths give the widened mask and kept only that one
/// when the compares went to mask registers (5% slower; `docs/perf.md`).
#[cold]
#[inline(never)]
fn grazed(mask: u32) -> u32 {
    std::hint::black_box(mask)
}

/// The call sites of the leaf tests (`leaf8`'s `CALLER`).
pub(super) mod caller {
    pub const CLOSEST: u8 = 0;
    pub const ANY: u8 = 1;
    pub const PACKET: u8 = 2;
}

/// A ray as the leaf test reads it: the single-ray traversal's `SlabRay`, or a packet's
/// (origin, direction). Generic rather than one (o, d) function for both callers: with two
/// callers LLVM stopped inlining the leaf test into the single-ray traversal (`docs/perf.md`).
pub(super) trait LeafRay {
    fn origin(&self) -> Vec3A;
    fn direction(&self) -> Vec3A;
}

impl LeafRay for (Vec3A, Vec3A) {
    #[inline(always)]
    fn origin(&self) -> Vec3A {
        self.0
    }
    #[inline(always)]
    fn direction(&self) -> Vec3A {
        self.1
    }
}

/// `TriangleBvh::leaf_scalar` for a whole leaf at once: the nearest hit in (t_min, t_best)
/// among triangles first..first+count, as (t, index in leaf order). The Möller–Trumbore
/// steps of `geometry::moller_trumbore` in the same order on eight lanes (no FMA), so t is
/// bit for bit the scalar (and brute-force) value; the first of equal t wins, as there.
///
/// `CALLER` (one of [`caller`]) gives each call site a copy of its own: LLVM inlines a
/// function called from one place, but left this one a call while two walks shared it, so
/// every leaf spilled the walk's vector registers around the call. One copy per caller:
/// single rays 4-5% faster on Zen 5 (`docs/perf.md`).
#[target_feature(enable = "avx")]
#[inline]
pub(super) fn leaf8<L: LeafRay, const CALLER: u8>(
    bvh: &TriangleBvh,
    ray: &L,
    first: usize,
    count: usize,
    t_min: f32,
    t_best: f32,
) -> Option<(f32, usize)> {
    let (o, d) = (ray.origin(), ray.direction());
    // Component k of the leaf's triangles; zeros past the arrays' end.
    let ld = |k: usize| {
        let at = k * bvh.stride + first;
        match bvh.soa.get(at..at + WIDTH).and_then(|s| s.try_into().ok()) {
            Some(s) => load8(s),
            None => _mm256_setzero_ps(),
        }
    };
    let (v0x, v0y, v0z) = (ld(0), ld(1), ld(2));
    let (e1x, e1y, e1z) = (ld(3), ld(4), ld(5));
    let (e2x, e2y, e2z) = (ld(6), ld(7), ld(8));
    let (dx, dy, dz) = (
        _mm256_set1_ps(d.x),
        _mm256_set1_ps(d.y),
        _mm256_set1_ps(d.z),
    );
    let (mul, sub, add) = (_mm256_mul_ps, _mm256_sub_ps, _mm256_add_ps);
    // glam's Vec3::cross and dot, lane-wise, in their operation order.
    let cross = |ax, ay, az, bx, by, bz| {
        (
            sub(mul(ay, bz), mul(by, az)),
            sub(mul(az, bx), mul(bz, ax)),
            sub(mul(ax, by), mul(bx, ay)),
        )
    };
    let dot = |ax, ay, az, bx, by, bz| add(add(mul(ax, bx), mul(ay, by)), mul(az, bz));
    let (px, py, pz) = cross(dx, dy, dz, e2x, e2y, e2z);
    let det = dot(e1x, e1y, e1z, px, py, pz);
    let sx = sub(_mm256_set1_ps(o.x), v0x);
    let sy = sub(_mm256_set1_ps(o.y), v0y);
    let sz = sub(_mm256_set1_ps(o.z), v0z);
    // The scalar test's undivided comparisons in det's sign: flipping the sign bit is its
    // exact negation.
    let sign = _mm256_and_ps(det, _mm256_set1_ps(-0.0));
    let abs_det = _mm256_xor_ps(det, sign);
    let u_det = dot(sx, sy, sz, px, py, pz);
    let u = _mm256_xor_ps(u_det, sign);
    let zero = _mm256_setzero_ps();
    let lanes = (1u32 << count) - 1;
    // A determinant that overflowed (det − det is NaN): the scalar test redoes those in
    // f64, so they are taken from it below (rare: edges of ~1.8e19 and more).
    let overflow = sub(det, det);
    let slow = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_UNORD_Q>(overflow, overflow)) as u32 & lanes;
    // Ordered compares are false for NaN, as the scalar tests are.
    let ok = _mm256_and_ps(
        _mm256_cmp_ps::<_CMP_NEQ_OQ>(det, zero),
        _mm256_and_ps(
            _mm256_cmp_ps::<_CMP_GE_OQ>(u, zero),
            _mm256_cmp_ps::<_CMP_LE_OQ>(u, abs_det),
        ),
    );
    // No early return when no lane passes the u test: a branch on the data, taken or not
    // leaf by leaf; always doing the second half was 2-3% faster (`docs/perf.md`).
    let (qx, qy, qz) = cross(sx, sy, sz, e1x, e1y, e1z);
    let v_det = dot(dx, dy, dz, qx, qy, qz);
    let v = _mm256_xor_ps(v_det, sign);
    let inv_det = _mm256_div_ps(_mm256_set1_ps(1.0), det);
    let t = mul(dot(e2x, e2y, e2z, qx, qy, qz), inv_det);
    // The scalar test rejects when v < 0 or u + v > det (so a NaN v passes here, as there).
    let reject = _mm256_or_ps(
        _mm256_cmp_ps::<_CMP_LT_OQ>(v, zero),
        _mm256_cmp_ps::<_CMP_GT_OQ>(add(u, v), abs_det),
    );
    let in_range = _mm256_and_ps(
        _mm256_cmp_ps::<_CMP_GT_OQ>(t, _mm256_set1_ps(t_min)),
        _mm256_cmp_ps::<_CMP_LT_OQ>(t, _mm256_set1_ps(t_best)),
    );
    let hit = _mm256_andnot_ps(reject, _mm256_and_ps(ok, in_range));
    let mut mask = (_mm256_movemask_ps(hit) as u32) & lanes & !slow;
    if slow == 0 {
        if mask == 0 {
            return None;
        }
        // Lanes past the leaf masked off as vectors too (lane index < count).
        let lane = _mm256_set_ps(7.0, 6.0, 5.0, 4.0, 3.0, 2.0, 1.0, 0.0);
        let used = _mm256_cmp_ps::<_CMP_LT_OQ>(lane, _mm256_set1_ps(count as f32));
        let (t_near, at) = nearest(t, _mm256_and_ps(hit, used));
        if let Some(t_near) = t_near {
            return Some((t_near, first + at));
        }
    }
    let mut ts = [0.0f32; WIDTH];
    store8(&mut ts, t);
    let mut rest = slow;
    while rest != 0 {
        let k = rest.trailing_zeros() as usize;
        rest &= rest - 1;
        if let Some(t) = bvh.tri(first + k).hit(o.into(), d.into())
            && t > t_min
            && t < t_best
        {
            ts[k] = t;
            mask |= 1 << k;
        }
    }
    if mask == 0 {
        return None;
    }
    // Lowest lane first, strictly closer replaces: the scalar loop's choice among equal t.
    let mut best = (f32::INFINITY, usize::MAX);
    while mask != 0 {
        let k = mask.trailing_zeros() as usize;
        mask &= mask - 1;
        if best.1 == usize::MAX || ts[k] < best.0 {
            best = (ts[k], first + k);
        }
    }
    Some(best)
}

/// The smallest t among the lanes set in `hit` (at least one), and the lowest such lane: the
/// scalar loop's choice (strictly closer replaces, so the first of equal t wins). In
/// registers, because the walk waits for t; the lane is off that path. None for a minimum
/// of ±0 (possible only with t_min < 0): equal there, they differ in bits, so the caller
/// takes its loop.
#[target_feature(enable = "avx")]
#[inline]
fn nearest(t: __m256, hit: __m256) -> (Option<f32>, usize) {
    let tm = _mm256_blendv_ps(_mm256_set1_ps(f32::INFINITY), t, hit);
    let m = _mm256_min_ps(tm, _mm256_permute2f128_ps::<1>(tm, tm));
    let m = _mm256_min_ps(m, _mm256_permute_ps::<0b0100_1110>(m));
    let m = _mm256_min_ps(m, _mm256_permute_ps::<0b1011_0001>(m));
    let t_near = _mm256_cvtss_f32(m);
    let at = _mm256_movemask_ps(_mm256_and_ps(hit, _mm256_cmp_ps::<_CMP_EQ_OQ>(t, m)));
    (
        (t_near != 0.0).then_some(t_near),
        at.trailing_zeros() as usize,
    )
}
