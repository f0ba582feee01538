//! Eight coherent rays at once (a pixel tile's primary rays), for `tracelab bench --packets`:
//! with AVX one traversal for the packet, each ray still getting its single-ray t bit for bit.

use glam::Vec3A;

#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::*;

#[cfg(target_arch = "x86_64")]
use super::avx::{self, load_row, load8, slab_tail, store8};
#[cfg(target_arch = "x86_64")]
use super::traverse::nearest_first;
#[cfg(target_arch = "x86_64")]
use super::{SLAB_WIDEN, has_avx};
use super::{TriangleBvh, TriangleHit};
use crate::accel::wide::WIDTH;
#[cfg(target_arch = "x86_64")]
use crate::accel::wide::{self, Child, Node8, RayStack};

/// A sparse packet whose first `INCOHERENT_AFTER_LEAVES` leaves are each entered by fewer
/// than `INCOHERENT_RAYS_PER_LEAF` of its rays on average is incoherent (rays far apart on a
/// fine mesh: the dragon's coarse passes) and goes one ray at a time: its box tests, over
/// bounds of all its rays, enter far more of the tree than any one ray would.
#[cfg(target_arch = "x86_64")]
const INCOHERENT_RAYS_PER_LEAF: u32 = 2;
#[cfg(target_arch = "x86_64")]
const INCOHERENT_AFTER_LEAVES: u32 = 16;

#[cfg(test)]
thread_local! {
    /// Sparse packets sent one ray at a time on this thread (for the tests).
    pub(super) static GAVE_UP: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

impl TriangleBvh {
    /// Closest hits of a packet of eight rays (`o[i]`, `d[i]`) in (t_min, t_max[i]), for the
    /// rays whose bit is set in `active`; a ray that hits has its `t_max` lowered to the hit.
    /// Each ray gets the t `closest_hit` gives it, bit for bit (the triangle may differ only
    /// where two are hit at the very same t). Made for coherent rays (a pixel tile's primary
    /// rays): with AVX, one traversal for the packet, which falls back to single rays when
    /// the active rays' directions differ in sign on some axis (or one is axis-parallel).
    #[inline]
    pub fn closest_hit8(
        &self,
        o: &[Vec3A; WIDTH],
        d: &[Vec3A; WIDTH],
        active: u8,
        t_min: f32,
        t_max: &mut [f32; WIDTH],
    ) -> [Option<TriangleHit>; WIDTH] {
        self.closest_hit8_with(o, d, active, t_min, t_max, false)
    }

    /// `closest_hit8`; with `sparse` (rays that may lie far apart, as a coarse pass's
    /// samples), a packet whose first leaves are entered by few of its rays is traced again
    /// one ray at a time, giving exactly the single rays' hits.
    #[inline(always)]
    pub fn closest_hit8_with(
        &self,
        o: &[Vec3A; WIDTH],
        d: &[Vec3A; WIDTH],
        active: u8,
        t_min: f32,
        t_max: &mut [f32; WIDTH],
        sparse: bool,
    ) -> [Option<TriangleHit>; WIDTH] {
        #[cfg(target_arch = "x86_64")]
        if has_avx() {
            #[allow(unsafe_code)]
            // SAFETY: the CPU has AVX, checked just above.
            return unsafe { self.packet_avx(o, d, active, t_min, t_max, sparse) };
        }
        let _ = sparse;
        self.singles8(o, d, active, t_min, t_max)
    }

    /// `closest_hit8` one ray at a time.
    pub(super) fn singles8(
        &self,
        o: &[Vec3A; WIDTH],
        d: &[Vec3A; WIDTH],
        active: u8,
        t_min: f32,
        t_max: &mut [f32; WIDTH],
    ) -> [Option<TriangleHit>; WIDTH] {
        let mut out = [None; WIDTH];
        for i in 0..WIDTH {
            if active & (1 << i) != 0 {
                out[i] = self.closest_hit(o[i], d[i], t_min, t_max[i]);
                if let Some(h) = out[i] {
                    t_max[i] = h.t;
                }
            }
        }
        out
    }

    /// The packet traversal. Each node's eight boxes are tested once for the whole packet,
    /// with bounds over its rays (interval arithmetic on origin and reciprocal direction,
    /// exact under rounding, see `PacketBounds`), so a box is entered whenever any ray's own
    /// slab test would enter it; at a leaf, each ray whose own slab test (the single-ray
    /// one, bit for bit) enters the leaf's box runs the AVX leaf test with its own t_best.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    fn packet_avx(
        &self,
        o: &[Vec3A; WIDTH],
        d: &[Vec3A; WIDTH],
        active: u8,
        t_min: f32,
        t_max: &mut [f32; WIDTH],
        sparse: bool,
    ) -> [Option<TriangleHit>; WIDTH] {
        let mut out = [None; WIDTH];
        if self.is_empty() || active == 0 {
            return out;
        }
        let Some((p, live)) = PacketBounds::new(o, d, active, self, t_min, t_max) else {
            return self.singles8(o, d, active, t_min, t_max);
        };
        if live == 0 {
            return out;
        }
        // Lanes of rays not traced hold -inf, so the packet's farthest t_best is a plain max.
        let mut t_best = [f32::NEG_INFINITY; WIDTH];
        for i in 0..WIDTH {
            if live & (1 << i) != 0 {
                t_best[i] = t_max[i];
            }
        }
        let mut t_far = t_best.iter().copied().fold(f32::NEG_INFINITY, f32::max);
        let mut best = [usize::MAX; WIDTH];
        let mut stack: RayStack<(Child, f32, u32)> = RayStack::new();
        let mut t_enter = [0.0f32; WIDTH];
        // Where cur's box is stored (node * 8 + slot); none (u32::MAX) for the root and for
        // a flat mesh's leaves, whose box is the root's, or a one-slot root's leaf.
        let mut cur: Child = self.start(&mut stack, |c| (c, t_min, u32::MAX));
        let mut cur_box = u32::MAX;
        let (mut leaves, mut leaf_rays) = (0u32, 0u32);
        loop {
            if wide::is_leaf(cur) {
                let (first, count) = wide::leaf_range(cur);
                // Only the rays whose own slab test enters the leaf's box: testing every
                // live ray instead is slower on the larger meshes (`docs/perf.md`).
                let mut rays = if cur_box == u32::MAX {
                    live
                } else {
                    let n = &self.nodes[(cur_box / 8) as usize];
                    p.rays_entering(n, (cur_box % 8) as usize, t_min, &t_best) & live
                };
                if sparse {
                    leaves += 1;
                    leaf_rays += rays.count_ones();
                    // t_max still holds the callers' bounds: nothing is written until the end.
                    if leaves == INCOHERENT_AFTER_LEAVES
                        && leaf_rays < INCOHERENT_RAYS_PER_LEAF * leaves
                    {
                        #[cfg(test)]
                        GAVE_UP.with(|g| g.set(g.get() + 1));
                        return self.singles8(o, d, active, t_min, t_max);
                    }
                }
                let mut hit = false;
                while rays != 0 {
                    let i = rays.trailing_zeros() as usize;
                    rays &= rays - 1;
                    if let Some((t, k)) = avx::leaf8::<_, { avx::caller::PACKET }>(
                        self,
                        &(o[i], d[i]),
                        first,
                        count,
                        t_min,
                        t_best[i],
                    ) {
                        t_best[i] = t;
                        best[i] = k;
                        hit = true;
                    }
                }
                if hit {
                    t_far = t_best.iter().copied().fold(f32::NEG_INFINITY, f32::max);
                }
            } else {
                let n = self.node(cur);
                let mask = p.slab8(n, t_min, t_far, &mut t_enter);
                // The slot's node by index (a node's unit offset times 8 could overflow).
                let at = cur / wide::NODE_UNITS * 8;
                let entry = |s: usize| (n.child[s], t_enter[s], at + s as u32);
                if let Some((c, _, b)) = nearest_first(mask, &t_enter, &mut stack, entry) {
                    cur = c;
                    cur_box = b;
                    continue;
                }
            }
            // The nearest child some ray may still need.
            match stack.pop_within(t_far) {
                Some((c, _, b)) => {
                    cur = c;
                    cur_box = b;
                }
                None => {
                    for i in 0..WIDTH {
                        if best[i] != usize::MAX {
                            t_max[i] = t_best[i];
                            out[i] = Some(TriangleHit {
                                t: t_best[i],
                                triangle: self.ids[best[i]],
                            });
                        }
                    }
                    return out;
                }
            }
        }
    }
}

/// Eight vectors' x, y and z components, each in one register (lane i = `v[i]`): a
/// transpose in eleven shuffles. Built lane by lane (`_mm256_setr_ps` of 24 components) it
/// was 48 inserts per packet, most of the packet's set-up.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
#[inline]
fn columns(v: &[Vec3A; WIDTH]) -> [__m256; 3] {
    let row = |k: usize| __m128::from(v[k]);
    // Lanes 0-3 hold v[k], lanes 4-7 v[k + 4] (x, y, z, and glam's unused fourth).
    let pair = |k: usize| _mm256_insertf128_ps::<1>(_mm256_castps128_ps256(row(k)), row(k + 4));
    let (a0, a1, a2, a3) = (pair(0), pair(1), pair(2), pair(3));
    let xy01 = _mm256_unpacklo_ps(a0, a1); // x0 x1 y0 y1 | x4 x5 y4 y5
    let zw01 = _mm256_unpackhi_ps(a0, a1); // z0 z1 w0 w1 | z4 z5 w4 w5
    let xy23 = _mm256_unpacklo_ps(a2, a3); // x2 x3 y2 y3 | x6 x7 y6 y7
    let zw23 = _mm256_unpackhi_ps(a2, a3);
    [
        _mm256_shuffle_ps::<0b01_00_01_00>(xy01, xy23),
        _mm256_shuffle_ps::<0b11_10_11_10>(xy01, xy23),
        _mm256_shuffle_ps::<0b01_00_01_00>(zw01, zw23),
    ]
}

/// A packet's bounds for the 8-box test, and its rays' own constants lane by lane.
///
/// Every traced ray runs the same sign on each axis, so the near plane of an axis is the
/// same for all (lo for +, hi for -). Ray i's entry distance on an axis is
/// fl(fl(plane - o_i) * inv_i); rounding is monotone in each operand and both factors lie
/// in intervals [plane - o_max, plane - o_min] and [inv_min, inv_max], so the product at
/// the right corner bounds every ray's value, bit-exactly rather than approximately: for the
/// near plane the lower bound is (plane - o_far) * (inv_min where that difference is >= 0,
/// else inv_max), with o_far = o_max on a + axis and o_min on a - axis; the far plane's
/// upper bound mirrors it. Finite, nonzero reciprocals (checked in `new`) keep NaN out.
#[cfg(target_arch = "x86_64")]
pub(super) struct PacketBounds {
    /// Per axis: do the rays run toward -axis?
    toward_neg: [bool; 3],
    /// Per axis: the origin bound the near (far) plane's difference takes.
    o_near: [f32; 3],
    o_far: [f32; 3],
    inv_min: [f32; 3],
    inv_max: [f32; 3],
    /// Per axis, lane i = ray i's origin and reciprocal direction.
    o: [__m256; 3],
    inv: [__m256; 3],
}

#[cfg(target_arch = "x86_64")]
impl PacketBounds {
    /// The packet's constants and the rays of `active` that meet the root's box (tested as
    /// `SlabRay::enters` tests it). None when an active ray has a zero (or non-finite)
    /// direction component or a non-finite origin, or when the rays meeting the root differ
    /// in direction sign on some axis: those go one by one. Built in registers, eight rays
    /// per instruction (one division per axis instead of a reciprocal per ray).
    #[target_feature(enable = "avx")]
    #[inline]
    pub(super) fn new(
        o: &[Vec3A; WIDTH],
        d: &[Vec3A; WIDTH],
        active: u8,
        bvh: &TriangleBvh,
        t_min: f32,
        t_max: &[f32; WIDTH],
    ) -> Option<(PacketBounds, u8)> {
        let (set, sub, mul) = (_mm256_set1_ps, _mm256_sub_ps, _mm256_mul_ps);
        let ov = columns(o);
        // IEEE division, lane by lane the value of `Vec3A::recip`.
        let iv = columns(d).map(|c| _mm256_div_ps(set(1.0), c));
        let bits = |m: __m256| _mm256_movemask_ps(m) as u8;
        let abs = |v: __m256| _mm256_andnot_ps(set(-0.0), v);
        let inf = set(f32::INFINITY);
        let mut finite = 0xff;
        for a in 0..3 {
            finite &= bits(_mm256_cmp_ps::<_CMP_LT_OQ>(abs(ov[a]), inf));
            finite &= bits(_mm256_cmp_ps::<_CMP_LT_OQ>(abs(iv[a]), inf));
            finite &= bits(_mm256_cmp_ps::<_CMP_NEQ_OQ>(iv[a], _mm256_setzero_ps()));
        }
        if finite & active != active {
            return None;
        }
        // The root's box per ray, `SlabRay::enters`'s operations (no NaN can arise here:
        // every reciprocal is finite and nonzero).
        let (mut near, mut far) = (set(t_min), load8(t_max));
        for a in 0..3 {
            let t0 = mul(sub(set(bvh.root_lo[a]), ov[a]), iv[a]);
            let t1 = mul(sub(set(bvh.root_hi[a]), ov[a]), iv[a]);
            near = _mm256_max_ps(near, _mm256_min_ps(t0, t1));
            far = _mm256_min_ps(far, _mm256_max_ps(t0, t1));
        }
        let live = bits(_mm256_cmp_ps::<_CMP_LE_OQ>(near, mul(far, set(SLAB_WIDEN)))) & active;
        let mut p = PacketBounds {
            toward_neg: [false; 3],
            o_near: [0.0; 3],
            o_far: [0.0; 3],
            inv_min: [0.0; 3],
            inv_max: [0.0; 3],
            o: ov,
            inv: iv,
        };
        if live == 0 {
            return Some((p, 0));
        }
        // Lanes of the live rays as a mask, for the bounds over them.
        let sel = |lo: i32| _mm_setr_epi32(lo, lo << 1, lo << 2, lo << 3);
        let b = _mm_set1_epi32(live as i32);
        let lane = |s: __m128i| _mm_cmpeq_epi32(_mm_and_si128(b, s), s);
        let lanes = _mm256_castsi256_ps(_mm256_set_m128i(lane(sel(16)), lane(sel(1))));
        // Horizontal min and max of the eight lanes.
        let hmin = |v: __m256| {
            let v = _mm256_min_ps(v, _mm256_permute2f128_ps::<1>(v, v));
            let v = _mm256_min_ps(v, _mm256_permute_ps::<0b01_00_11_10>(v));
            _mm256_cvtss_f32(_mm256_min_ps(v, _mm256_permute_ps::<0b10_11_00_01>(v)))
        };
        let hmax = |v: __m256| {
            let v = _mm256_max_ps(v, _mm256_permute2f128_ps::<1>(v, v));
            let v = _mm256_max_ps(v, _mm256_permute_ps::<0b01_00_11_10>(v));
            _mm256_cvtss_f32(_mm256_max_ps(v, _mm256_permute_ps::<0b10_11_00_01>(v)))
        };
        let neg_inf = set(f32::NEG_INFINITY);
        for a in 0..3 {
            let neg = bits(_mm256_cmp_ps::<_CMP_LT_OQ>(iv[a], _mm256_setzero_ps())) & live;
            if neg != 0 && neg != live {
                return None;
            }
            p.toward_neg[a] = neg != 0;
            let o_min = hmin(_mm256_blendv_ps(inf, ov[a], lanes));
            let o_max = hmax(_mm256_blendv_ps(neg_inf, ov[a], lanes));
            p.inv_min[a] = hmin(_mm256_blendv_ps(inf, iv[a], lanes));
            p.inv_max[a] = hmax(_mm256_blendv_ps(neg_inf, iv[a], lanes));
            (p.o_near[a], p.o_far[a]) = if p.toward_neg[a] {
                (o_min, o_max)
            } else {
                (o_max, o_min)
            };
        }
        Some((p, live))
    }

    /// The packet against a node's eight boxes: bit i set when some ray of the packet may
    /// enter slot i within [t_min, t_far] (never unset where a ray's own `slab8` sets it);
    /// `t_enter` gets lower bounds of the rays' entry distances.
    #[target_feature(enable = "avx")]
    #[inline]
    fn slab8(&self, n: &Node8, t_min: f32, t_far: f32, t_enter: &mut [f32; WIDTH]) -> u32 {
        let (sub, mul, blend, set) = (
            _mm256_sub_ps,
            _mm256_mul_ps,
            _mm256_blendv_ps,
            _mm256_set1_ps,
        );
        let side = |a: usize| {
            let (entry, exit) = n.entry_exit(a, self.toward_neg[a]);
            let (lo, hi) = (set(self.inv_min[a]), set(self.inv_max[a]));
            // blendv takes its second operand where the difference is negative.
            let x = sub(load_row(entry), set(self.o_near[a]));
            let y = sub(load_row(exit), set(self.o_far[a]));
            (mul(x, blend(lo, hi, x)), mul(y, blend(hi, lo, y)))
        };
        let (nx, fx) = side(0);
        let (ny, fy) = side(1);
        let (nz, fz) = side(2);
        let (near, mask) = slab_tail([nx, ny, nz], [fx, fy, fz], set(t_min), set(t_far));
        store8(t_enter, near);
        mask
    }

    /// Bit i set when ray i's own slab test (`avx::slab8`'s operations in its order, lane i)
    /// enters slot `s` of `n` within [t_min, t_best[i]].
    #[target_feature(enable = "avx")]
    #[inline]
    fn rays_entering(&self, n: &Node8, s: usize, t_min: f32, t_best: &[f32; WIDTH]) -> u8 {
        let (sub, mul, set) = (_mm256_sub_ps, _mm256_mul_ps, _mm256_set1_ps);
        let (h, l) = (s / 4, s % 4);
        let slab = |a: usize| {
            let (entry, exit) = n.entry_exit(a, self.toward_neg[a]);
            let (o, inv) = (self.o[a], self.inv[a]);
            (
                mul(sub(set(entry[h][l]), o), inv),
                mul(sub(set(exit[h][l]), o), inv),
            )
        };
        let (nx, fx) = slab(0);
        let (ny, fy) = slab(1);
        let (nz, fz) = slab(2);
        let (_, mask) = slab_tail([nx, ny, nz], [fx, fy, fz], set(t_min), load8(t_best));
        mask as u8
    }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::*;

    #[test]
    fn columns_put_each_vectors_components_in_its_own_lane() {
        if !has_avx() {
            return; // nothing to test without AVX: the packet path is not taken
        }
        let v: [Vec3A; WIDTH] =
            std::array::from_fn(|i| Vec3A::new(i as f32, 10.0 + i as f32, -(i as f32) - 0.5));
        #[allow(unsafe_code)]
        // SAFETY: the CPU has AVX, checked above.
        let cols = unsafe { columns(&v) };
        for (a, c) in cols.iter().enumerate() {
            let mut lanes = [0.0f32; WIDTH];
            #[allow(unsafe_code)]
            // SAFETY: as above.
            unsafe {
                store8(&mut lanes, *c)
            };
            let want: [f32; WIDTH] = std::array::from_fn(|i| v[i][a]);
            assert_eq!(lanes, want, "component {a}");
        }
    }
}
