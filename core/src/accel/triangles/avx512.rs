//! The AVX-512 kernel: `avx::leaf8` with the tests' results in mask registers, for the
//! single-ray traversal compiled for AVX-512 (F and VL). It needs no `unsafe` of its own
//! (its loads and stores are `avx::load8` and `avx::store8`).
//!
//! Tried and dropped (`docs/perf.md`): a packet's rays two at a time against a leaf in one
//! 16-lane register: bit-exact, but no faster than `leaf8` one ray at a time on Zen 5.

use std::arch::x86_64::*;

use super::TriangleBvh;
use super::avx;
use crate::accel::wide::WIDTH;

/// `avx::leaf8` with AVX-512VL mask registers: the same eight lanes, the same operations in
/// the same order (no FMA), the tests' results in mask registers instead of blends, so t is
/// bit for bit `leaf8`'s. `CALLER`: one copy per call site, as for `avx::leaf8`.
#[target_feature(enable = "avx512f,avx512vl")]
#[inline]
pub(super) fn leaf8<L: avx::LeafRay, const CALLER: u8>(
    bvh: &TriangleBvh,
    ray: &L,
    first: usize,
    count: usize,
    t_min: f32,
    t_best: f32,
) -> Option<(f32, usize)> {
    let (o, d) = (ray.origin(), ray.direction());
    let ld = |k: usize| {
        let at = k * bvh.stride + first;
        match bvh.soa.get(at..at + WIDTH).and_then(|s| s.try_into().ok()) {
            Some(s) => avx::load8(s),
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
    let sign = _mm256_and_ps(det, _mm256_set1_ps(-0.0));
    let abs_det = _mm256_xor_ps(det, sign);
    let u = _mm256_xor_ps(dot(sx, sy, sz, px, py, pz), sign);
    let zero = _mm256_setzero_ps();
    let lanes = ((1u32 << count) - 1) as u8;
    let overflow = sub(det, det);
    let slow = _mm256_cmp_ps_mask::<_CMP_UNORD_Q>(overflow, overflow) & lanes;
    let ok = _mm256_mask_cmp_ps_mask::<_CMP_NEQ_OQ>(lanes & !slow, det, zero);
    let ok = _mm256_mask_cmp_ps_mask::<_CMP_GE_OQ>(ok, u, zero);
    let ok = _mm256_mask_cmp_ps_mask::<_CMP_LE_OQ>(ok, u, abs_det);
    // No early return here, as in `avx::leaf8`.
    let (qx, qy, qz) = cross(sx, sy, sz, e1x, e1y, e1z);
    let v = _mm256_xor_ps(dot(dx, dy, dz, qx, qy, qz), sign);
    let inv_det = _mm256_div_ps(_mm256_set1_ps(1.0), det);
    let t = mul(dot(e2x, e2y, e2z, qx, qy, qz), inv_det);
    let reject = _mm256_cmp_ps_mask::<_CMP_LT_OQ>(v, zero)
        | _mm256_cmp_ps_mask::<_CMP_GT_OQ>(add(u, v), abs_det);
    let in_range = _mm256_mask_cmp_ps_mask::<_CMP_GT_OQ>(ok & !reject, t, _mm256_set1_ps(t_min));
    let mut mask =
        _mm256_mask_cmp_ps_mask::<_CMP_LT_OQ>(in_range, t, _mm256_set1_ps(t_best)) as u32;
    if slow == 0 {
        if mask == 0 {
            return None;
        }
        // The nearest hit in registers (`avx::nearest`).
        let (t_near, at) = nearest(t, mask as u8);
        if let Some(t_near) = t_near {
            return Some((t_near, first + at));
        }
    }
    let mut ts = [0.0f32; WIDTH];
    avx::store8(&mut ts, t);
    let mut rest = slow as u32;
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

/// `avx::nearest` with the lanes as a mask register.
#[target_feature(enable = "avx512f,avx512vl")]
#[inline]
fn nearest(t: __m256, hit: u8) -> (Option<f32>, usize) {
    let tm = _mm256_mask_blend_ps(hit, _mm256_set1_ps(f32::INFINITY), t);
    let m = _mm256_min_ps(tm, _mm256_permute2f128_ps::<1>(tm, tm));
    let m = _mm256_min_ps(m, _mm256_permute_ps::<0b0100_1110>(m));
    let m = _mm256_min_ps(m, _mm256_permute_ps::<0b1011_0001>(m));
    let t_near = _mm256_cvtss_f32(m);
    let at = _mm256_mask_cmp_ps_mask::<_CMP_EQ_OQ>(hit, t, m);
    (
        (t_near != 0.0).then_some(t_near),
        at.trailing_zeros() as usize,
    )
}
