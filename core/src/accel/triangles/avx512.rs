//! The AVX-512 kernel: two rays of a packet against a leaf's up to eight triangles in one
//! 16-lane register (ray i in lanes 0..8, ray j in lanes 8..16), with mask registers for the
//! tests. Each lane runs `avx::leaf8`'s operations in its order (no FMA), so each ray gets
//! `leaf8`'s answer bit for bit. Every `unsafe` it needs is in `load8x2`.

use std::arch::x86_64::*;

use glam::Vec3A;

use super::TriangleBvh;
use super::avx;
use super::packet::PacketBounds;
use crate::accel::wide::WIDTH;

/// Eight floats, in both halves of one 16-lane register.
#[target_feature(enable = "avx512f,avx512vl")]
#[inline]
fn load8x2(v: &[f32; WIDTH]) -> __m512 {
    #[allow(unsafe_code)]
    // SAFETY: `v` is 8 contiguous f32, what an unaligned 256-bit load reads.
    let x = _mm512_castps256_ps512(unsafe { _mm256_loadu_ps(v.as_ptr()) });
    _mm512_shuffle_f32x4::<0b01_00_01_00>(x, x)
}

/// The rays of `rays` through the leaf first..first+count, two at a time in `leaf8x2`, each
/// lowering its t_best and setting its best on a hit, exactly as `avx::leaf8` one ray at a
/// time would. Returns whether any hit, and the odd ray left over (0 or one bit), for the
/// caller's `leaf8` (called here too, `leaf8` was no longer inlined into the caller).
#[allow(clippy::too_many_arguments)]
#[target_feature(enable = "avx512f,avx512vl")]
pub(super) fn leaf_rays(
    bvh: &TriangleBvh,
    (o, d): (&[Vec3A; WIDTH], &[Vec3A; WIDTH]),
    p: &PacketBounds,
    mut rays: u8,
    (first, count): (usize, usize),
    t_min: f32,
    t_best: &mut [f32; WIDTH],
    best: &mut [usize; WIDTH],
) -> (bool, u8) {
    // The rays' directions as columns, for the pairs' broadcasts.
    let col = |a: usize| {
        _mm256_setr_ps(
            d[0][a], d[1][a], d[2][a], d[3][a], d[4][a], d[5][a], d[6][a], d[7][a],
        )
    };
    let dc = [col(0), col(1), col(2)];
    let mut hit = false;
    while rays & (rays - 1) != 0 {
        let i = rays.trailing_zeros() as usize;
        rays &= rays - 1;
        let j = rays.trailing_zeros() as usize;
        rays &= rays - 1;
        let got = leaf8x2(
            bvh,
            (&p.o, &dc),
            (o, d),
            (i, j),
            first,
            count,
            t_min,
            t_best,
        );
        for (r, g) in [(i, got[0]), (j, got[1])] {
            if let Some((t, k)) = g {
                t_best[r] = t;
                best[r] = k;
                hit = true;
            }
        }
    }
    (hit, rays)
}

/// Per axis, lane k = ray k's component (a packet's columns, as `PacketBounds` keeps them).
pub(super) type Columns = [__m256; 3];

/// `avx::leaf8` for rays `i` and `j` of a packet at once: the nearest hit of each in
/// (t_min, t_best[ray]) among triangles first..first+count, as (t, index in leaf order).
/// `o`, `d` are the packet's rays as columns (for the vector part) and as vectors (for the
/// scalar redo of overflowing determinants, as in `leaf8`).
#[allow(clippy::too_many_arguments)]
#[target_feature(enable = "avx512f,avx512vl")]
#[inline]
pub(super) fn leaf8x2(
    bvh: &TriangleBvh,
    (oc, dc): (&Columns, &Columns),
    (o, d): (&[Vec3A; WIDTH], &[Vec3A; WIDTH]),
    (i, j): (usize, usize),
    first: usize,
    count: usize,
    t_min: f32,
    t_best: &[f32; WIDTH],
) -> [Option<(f32, usize)>; 2] {
    // Lanes 0..8 take ray i's value, lanes 8..16 ray j's.
    let idx = _mm512_mask_blend_epi32(
        0xff00,
        _mm512_set1_epi32(i as i32),
        _mm512_set1_epi32(j as i32),
    );
    let pair = |c: __m256| _mm512_permutexvar_ps(idx, _mm512_castps256_ps512(c));
    let ld = |k: usize| {
        let at = k * bvh.stride + first;
        match bvh.soa.get(at..at + WIDTH).and_then(|s| s.try_into().ok()) {
            Some(s) => load8x2(s),
            None => _mm512_setzero_ps(),
        }
    };
    let (v0x, v0y, v0z) = (ld(0), ld(1), ld(2));
    let (e1x, e1y, e1z) = (ld(3), ld(4), ld(5));
    let (e2x, e2y, e2z) = (ld(6), ld(7), ld(8));
    let (dx, dy, dz) = (pair(dc[0]), pair(dc[1]), pair(dc[2]));
    let (mul, sub, add) = (_mm512_mul_ps, _mm512_sub_ps, _mm512_add_ps);
    // glam's Vec3::cross and dot, lane-wise, in their operation order (as `leaf8`).
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
    let inv_det = _mm512_div_ps(_mm512_set1_ps(1.0), det);
    let sx = sub(pair(oc[0]), v0x);
    let sy = sub(pair(oc[1]), v0y);
    let sz = sub(pair(oc[2]), v0z);
    let u = mul(dot(sx, sy, sz, px, py, pz), inv_det);
    let (zero, one) = (_mm512_setzero_ps(), _mm512_set1_ps(1.0));
    let leaf = (1u32 << count) - 1;
    let lanes = (leaf | leaf << 8) as u16;
    // An overflowed determinant (det − det is NaN): redone in scalar code below, as in leaf8.
    let overflow = sub(det, det);
    let slow = _mm512_cmp_ps_mask::<_CMP_UNORD_Q>(overflow, overflow) & lanes;
    // Ordered compares are false for NaN, as the scalar tests are; each masked compare is
    // the AND of its mask and its own test.
    let ok = _mm512_cmp_ps_mask::<_CMP_NEQ_OQ>(det, zero);
    let ok = _mm512_mask_cmp_ps_mask::<_CMP_GE_OQ>(ok, u, zero);
    let ok = _mm512_mask_cmp_ps_mask::<_CMP_LE_OQ>(ok, u, one) & lanes & !slow;
    // Most leaves a ray enters hold no triangle it crosses: stop before the second half.
    if ok == 0 && slow == 0 {
        return [None, None];
    }
    let (qx, qy, qz) = cross(sx, sy, sz, e1x, e1y, e1z);
    let v = mul(dot(dx, dy, dz, qx, qy, qz), inv_det);
    let t = mul(dot(e2x, e2y, e2z, qx, qy, qz), inv_det);
    // leaf8 rejects v < 0 or u + v > 1 (so a NaN v passes, as in the scalar test).
    let reject = _mm512_cmp_ps_mask::<_CMP_LT_OQ>(v, zero)
        | _mm512_cmp_ps_mask::<_CMP_GT_OQ>(add(u, v), one);
    let in_range = _mm512_mask_cmp_ps_mask::<_CMP_GT_OQ>(ok, t, _mm512_set1_ps(t_min));
    let in_range = _mm512_mask_cmp_ps_mask::<_CMP_LT_OQ>(in_range, t, pair(avx::load8(t_best)));
    let mask = in_range & !reject;
    let mut ts = [0.0f32; 2 * WIDTH];
    store16(&mut ts, t);
    let tb = [t_best[i], t_best[j]];
    let rays = [i, j];
    let mut out = [None, None];
    for h in 0..2 {
        let mut m = ((mask >> (8 * h)) & 0xff) as u32;
        let mut rest = ((slow >> (8 * h)) & 0xff) as u32;
        let ts = &mut ts[8 * h..8 * h + 8];
        while rest != 0 {
            let k = rest.trailing_zeros() as usize;
            rest &= rest - 1;
            let r = rays[h];
            if let Some(t) = bvh.tri(first + k).hit(o[r].into(), d[r].into())
                && t > t_min
                && t < tb[h]
            {
                ts[k] = t;
                m |= 1 << k;
            }
        }
        // Lowest lane first, strictly closer replaces: leaf8's choice among equal t.
        let mut best = (f32::INFINITY, usize::MAX);
        while m != 0 {
            let k = m.trailing_zeros() as usize;
            m &= m - 1;
            if best.1 == usize::MAX || ts[k] < best.0 {
                best = (ts[k], first + k);
            }
        }
        if best.1 != usize::MAX {
            out[h] = Some(best);
        }
    }
    out
}

/// One register into sixteen floats.
#[target_feature(enable = "avx512f,avx512vl")]
#[inline]
fn store16(v: &mut [f32; 2 * WIDTH], x: __m512) {
    #[allow(unsafe_code)]
    // SAFETY: `v` is 16 contiguous f32, what an unaligned 512-bit store writes.
    unsafe {
        _mm512_storeu_ps(v.as_mut_ptr(), x)
    }
}

/// `avx::leaf8` with AVX-512VL mask registers: the same eight lanes, the same operations in
/// the same order (no FMA), the tests' results in mask registers instead of blends, so t is
/// bit for bit `leaf8`'s.
#[target_feature(enable = "avx512f,avx512vl")]
#[inline]
pub(super) fn leaf8<L: avx::LeafRay>(
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
    let inv_det = _mm256_div_ps(_mm256_set1_ps(1.0), det);
    let sx = sub(_mm256_set1_ps(o.x), v0x);
    let sy = sub(_mm256_set1_ps(o.y), v0y);
    let sz = sub(_mm256_set1_ps(o.z), v0z);
    let u = mul(dot(sx, sy, sz, px, py, pz), inv_det);
    let (zero, one) = (_mm256_setzero_ps(), _mm256_set1_ps(1.0));
    let lanes = ((1u32 << count) - 1) as u8;
    let overflow = sub(det, det);
    let slow = _mm256_cmp_ps_mask::<_CMP_UNORD_Q>(overflow, overflow) & lanes;
    let ok = _mm256_mask_cmp_ps_mask::<_CMP_NEQ_OQ>(lanes & !slow, det, zero);
    let ok = _mm256_mask_cmp_ps_mask::<_CMP_GE_OQ>(ok, u, zero);
    let ok = _mm256_mask_cmp_ps_mask::<_CMP_LE_OQ>(ok, u, one);
    if ok == 0 && slow == 0 {
        return None;
    }
    let (qx, qy, qz) = cross(sx, sy, sz, e1x, e1y, e1z);
    let v = mul(dot(dx, dy, dz, qx, qy, qz), inv_det);
    let t = mul(dot(e2x, e2y, e2z, qx, qy, qz), inv_det);
    let reject = _mm256_cmp_ps_mask::<_CMP_LT_OQ>(v, zero)
        | _mm256_cmp_ps_mask::<_CMP_GT_OQ>(add(u, v), one);
    let in_range = _mm256_mask_cmp_ps_mask::<_CMP_GT_OQ>(ok & !reject, t, _mm256_set1_ps(t_min));
    let mut mask =
        _mm256_mask_cmp_ps_mask::<_CMP_LT_OQ>(in_range, t, _mm256_set1_ps(t_best)) as u32;
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
