//! A binary BVH over primitive boxes by binned SAH on all three axes, built in parallel
//! (subtrees and, near the root, the binning itself). It is an intermediate form: the
//! triangle BVH collapses it into 8-wide nodes. Primitives end up permuted into leaf order.

use glam::{Vec3, Vec3A};
use rayon::prelude::*;

use crate::geometry::Aabb;

/// Bins per axis: 32 traced no faster and built slower (`docs/perf.md`).
const BINS: usize = 16;
/// Most primitives in a leaf; the 8-wide node packs a leaf's count in 3 bits.
pub const MAX_LEAF: usize = 8;
/// No leaf deeper than this: below `MAX_DEPTH - log2(n / MAX_LEAF)` the builder stops trusting
/// SAH and splits in the middle, so adversarial input cannot make the tree a long chain. The
/// traversal's fixed stack is sized from it.
pub const MAX_DEPTH: usize = 64;
/// Below this many primitives a subtree is built on the current thread.
const PARALLEL_SUBTREE: usize = 4096;
/// Above this many primitives a node's binning pass is itself split across threads.
const PARALLEL_BINNING: usize = 1 << 16;
/// Cost of one node visit relative to one leaf test, in the SAH.
const TRAVERSAL_COST: f32 = 1.0;

/// How many primitives a leaf tests at once: the SAH charges a leaf by the block, so with
/// blocks of 8 (the mesh BVH's AVX leaf test) a leaf of 7 costs what a leaf of 1 does, and
/// leaves fill up (fewer, fuller leaves trace faster and take less memory: `docs/perf.md`).
#[derive(Clone, Copy, Debug)]
pub struct LeafBlock(pub u32);

impl LeafBlock {
    #[inline]
    pub(super) fn cost(self, n: u32) -> f32 {
        n.div_ceil(self.0.max(1)) as f32
    }
}

/// A primitive's box and its index in the caller's order (32 bytes).
#[derive(Clone, Copy, Debug)]
pub struct PrimRef {
    pub lo: Vec3,
    pub id: u32,
    pub hi: Vec3,
}

impl PrimRef {
    pub fn new(b: Aabb, id: u32) -> Self {
        PrimRef {
            lo: b.min,
            id,
            hi: b.max,
        }
    }
    /// The box's corners as 16-byte vectors. Binning uses their sum, twice the centroid: it
    /// only needs the centroids up to a common scale.
    #[inline(always)]
    fn corners(&self) -> (Vec3A, Vec3A) {
        (self.lo.into(), self.hi.into())
    }
}

pub enum Node {
    /// Primitives `first..first + count` of the (permuted) primitive array.
    Leaf {
        bounds: Aabb,
        first: u32,
        count: u32,
    },
    Inner {
        bounds: Aabb,
        children: Box<[Node; 2]>,
    },
}

impl Node {
    pub fn bounds(&self) -> Aabb {
        match self {
            Node::Leaf { bounds, .. } | Node::Inner { bounds, .. } => *bounds,
        }
    }
}

/// Builds over `prims`, reordering them so every leaf is a contiguous range. `None` when empty.
pub fn build(prims: &mut [PrimRef], block: LeafBlock) -> Option<Node> {
    if prims.is_empty() {
        return None;
    }
    let (bounds, centroid_box) = extents(prims);
    Some(build_rec(prims, 0, bounds, centroid_box, 0, block))
}

/// (union of boxes, box of the doubled centroids).
fn extents(prims: &[PrimRef]) -> (Aabb, Aabb) {
    let fold = |acc: (Box3, Box3), p: &PrimRef| {
        let (lo, hi) = p.corners();
        (acc.0.grow(lo, hi), acc.1.grow(lo + hi, lo + hi))
    };
    let merge = |a: (Box3, Box3), b: (Box3, Box3)| (a.0.union(b.0), a.1.union(b.1));
    let (b, c) = if prims.len() > PARALLEL_BINNING {
        prims
            .par_chunks(PARALLEL_BINNING / 4)
            .map(|c| c.iter().fold((Box3::EMPTY, Box3::EMPTY), fold))
            .reduce(|| (Box3::EMPTY, Box3::EMPTY), merge)
    } else {
        prims.iter().fold((Box3::EMPTY, Box3::EMPTY), fold)
    };
    (b.aabb(), c.aabb())
}

/// A box as two 16-byte vectors: a union is two SSE instructions where `Aabb`'s `Vec3`s take
/// six scalar ones (binning is most of a build). Bit for bit `Aabb`'s results on x86-64, NaN
/// included: SSE's min and max pick as glam's scalar `Vec3` does (the first operand only if
/// it is smaller, or larger), and the operands are in `Aabb`'s order, so the trees are the
/// same. (Elsewhere glam's `Vec3A` may order a NaN differently: only boxes with NaN corners,
/// which the loaders refuse, would build other trees.)
#[derive(Clone, Copy, Debug)]
struct Box3 {
    lo: Vec3A,
    hi: Vec3A,
}

impl Box3 {
    const EMPTY: Box3 = Box3 {
        lo: Vec3A::splat(f32::INFINITY),
        hi: Vec3A::splat(f32::NEG_INFINITY),
    };
    #[inline(always)]
    fn grow(self, lo: Vec3A, hi: Vec3A) -> Box3 {
        Box3 {
            lo: self.lo.min(lo),
            hi: self.hi.max(hi),
        }
    }
    #[inline(always)]
    fn union(self, o: Box3) -> Box3 {
        self.grow(o.lo, o.hi)
    }
    /// `Aabb::surface_area`, operation for operation (a NaN corner is not empty there).
    #[inline(always)]
    fn surface_area(&self) -> f32 {
        if self.lo.cmpgt(self.hi).any() {
            return 0.0;
        }
        let e = self.hi - self.lo;
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }
    fn aabb(&self) -> Aabb {
        Aabb::new(self.lo.into(), self.hi.into())
    }
}

#[derive(Clone, Copy)]
struct Bins {
    boxes: [[Box3; BINS]; 3],
    counts: [[u32; BINS]; 3],
}

impl Bins {
    fn new() -> Self {
        Bins {
            boxes: [[Box3::EMPTY; BINS]; 3],
            counts: [[0; BINS]; 3],
        }
    }
    fn merge(mut self, o: Self) -> Self {
        for a in 0..3 {
            for i in 0..BINS {
                self.boxes[a][i] = self.boxes[a][i].union(o.boxes[a][i]);
                self.counts[a][i] += o.counts[a][i];
            }
        }
        self
    }
}

/// Maps doubled centroids to bins along each axis.
#[derive(Clone, Copy)]
struct Binner {
    lo: Vec3,
    scale: Vec3,
    /// Bins in use: fewer for small nodes, whose fixed cost per bin would dominate the build.
    count: usize,
}

impl Binner {
    fn new(centroid_box: &Aabb, n: usize) -> Self {
        let ext = centroid_box.extent();
        let count = (n / 2).clamp(8, BINS);
        // Slightly under count / extent so the largest centroid lands in the last bin.
        let scale = Vec3::select(
            ext.cmpgt(Vec3::ZERO),
            (count as f32 * 0.9999) / ext,
            Vec3::ZERO,
        );
        Binner {
            lo: centroid_box.min,
            scale,
            count,
        }
    }
    /// The bin of `p` on `axis`: ((lo + hi − self.lo) · scale) truncated, NaN and negatives
    /// in bin 0, past the last bin in the last (`as usize` saturates), so no input can index
    /// out. `fill` computes it for three axes at once (`bins3`), the partition only compares
    /// (`left_of`); the tests check both against this.
    #[cfg(test)]
    fn bin(&self, p: &PrimRef, axis: usize) -> usize {
        (((p.lo[axis] + p.hi[axis] - self.lo[axis]) * self.scale[axis]) as usize)
            .min(self.count - 1)
    }
    /// Whether `p` is in bin `split` or before on `axis`: `bin(..) <= split` without the
    /// saturating cast. For x ≥ 0, trunc(x) ≤ split exactly when x < split + 1; negatives
    /// and NaN (bin 0) answer true, +∞ (the last bin, past any split) false.
    #[inline(always)]
    #[allow(clippy::neg_cmp_op_on_partial_ord)] // NaN must answer true: `!(x >= ..)` does.
    fn left_of(&self, p: &PrimRef, axis: usize, split: usize) -> bool {
        let x = (p.lo[axis] + p.hi[axis] - self.lo[axis]) * self.scale[axis];
        !(x >= (split + 1) as f32)
    }
    fn fill(&self, prims: &[PrimRef], bins: &mut Bins) {
        for p in prims {
            let (lo, hi) = p.corners();
            // `bin`'s arithmetic, three lanes at once.
            let f = (lo + hi - Vec3A::from(self.lo)) * Vec3A::from(self.scale);
            let k = bins3(f, (self.count - 1) as f32);
            for (a, k) in k.into_iter().enumerate() {
                bins.boxes[a][k] = bins.boxes[a][k].grow(lo, hi);
                bins.counts[a][k] += 1;
            }
        }
    }
}

/// `(f[a] as usize).min(last)` for the three lanes at once (Rust's saturating casts, one
/// by one, were an eighth of a build): NaN and negatives to 0, then truncation.
#[inline(always)]
fn bins3(f: Vec3A, last: f32) -> [usize; 3] {
    // SSE's max returns its second operand where either is NaN, so NaN clamps to 0.
    let c = f.max(Vec3A::ZERO).min(Vec3A::splat(last));
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_cvtsi128_si32, _mm_cvttps_epi32, _mm_srli_si128};
        #[allow(unsafe_code)]
        // SAFETY: SSE2 intrinsics, and every x86-64 CPU has SSE2.
        unsafe {
            let i = _mm_cvttps_epi32(c.into());
            [
                _mm_cvtsi128_si32(i) as usize,
                _mm_cvtsi128_si32(_mm_srli_si128::<4>(i)) as usize,
                _mm_cvtsi128_si32(_mm_srli_si128::<8>(i)) as usize,
            ]
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        [c.x as usize, c.y as usize, c.z as usize]
    }
}

fn build_rec(
    prims: &mut [PrimRef],
    first: usize,
    bounds: Aabb,
    centroid_box: Aabb,
    depth: usize,
    block: LeafBlock,
) -> Node {
    let n = prims.len();
    let leaf = Node::Leaf {
        bounds,
        first: first as u32,
        count: n as u32,
    };
    if n <= 1 {
        return leaf;
    }
    // Levels a middle split still needs to reach leaves of MAX_LEAF.
    let levels_needed = (n.div_ceil(MAX_LEAF)).next_power_of_two().trailing_zeros() as usize;
    let ext = centroid_box.extent();
    // No positive extent (all centroids equal, or NaN): SAH has nothing to split on.
    let flat = ext.max_element().partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater);
    let mid = if depth + levels_needed + 1 >= MAX_DEPTH || flat {
        if n <= MAX_LEAF {
            return leaf;
        }
        n / 2
    } else {
        let binner = Binner::new(&centroid_box, n);
        let bins = if n > PARALLEL_BINNING {
            prims
                .par_chunks(PARALLEL_BINNING / 4)
                .map(|c| {
                    let mut b = Bins::new();
                    binner.fill(c, &mut b);
                    b
                })
                .reduce(Bins::new, Bins::merge)
        } else {
            let mut b = Bins::new();
            binner.fill(prims, &mut b);
            b
        };
        let Some((cost, axis, split)) = best_split(&bins, binner.count, &ext, block) else {
            return if n <= MAX_LEAF {
                leaf
            } else {
                split_middle(prims, first, bounds, depth, block)
            };
        };
        let area = bounds.surface_area();
        if n <= MAX_LEAF && cost + TRAVERSAL_COST * area >= block.cost(n as u32) * area {
            return leaf;
        }
        partition(prims, |p| binner.left_of(p, axis, split))
    };
    let mid = if mid == 0 || mid == n { n / 2 } else { mid };
    children(prims, first, bounds, mid, depth, block)
}

fn split_middle(
    prims: &mut [PrimRef],
    first: usize,
    bounds: Aabb,
    depth: usize,
    block: LeafBlock,
) -> Node {
    let mid = prims.len() / 2;
    children(prims, first, bounds, mid, depth, block)
}

fn children(
    prims: &mut [PrimRef],
    first: usize,
    bounds: Aabb,
    mid: usize,
    depth: usize,
    block: LeafBlock,
) -> Node {
    let n = prims.len();
    let (l, r) = prims.split_at_mut(mid);
    let sub = |s: &mut [PrimRef], f: usize| {
        let (b, c) = extents(s);
        build_rec(s, f, b, c, depth + 1, block)
    };
    let (left, right) = if n > PARALLEL_SUBTREE {
        rayon::join(|| sub(l, first), || sub(r, first + mid))
    } else {
        (sub(l, first), sub(r, first + mid))
    };
    Node::Inner {
        bounds,
        children: Box::new([left, right]),
    }
}

/// The cheapest split over all axes: (SAH cost, axis, last bin on the left).
fn best_split(bins: &Bins, nb: usize, ext: &Vec3, block: LeafBlock) -> Option<(f32, usize, usize)> {
    let mut best: Option<(f32, usize, usize)> = None;
    for a in 0..3 {
        if ext[a].partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            continue;
        }
        let mut right_cost = [0.0f32; BINS];
        let mut right_count = [0u32; BINS];
        let (mut acc, mut cnt) = (Box3::EMPTY, 0u32);
        for i in (1..nb).rev() {
            acc = acc.union(bins.boxes[a][i]);
            cnt += bins.counts[a][i];
            right_cost[i] = acc.surface_area() * block.cost(cnt);
            right_count[i] = cnt;
        }
        let (mut acc, mut cnt) = (Box3::EMPTY, 0u32);
        for i in 0..nb - 1 {
            acc = acc.union(bins.boxes[a][i]);
            cnt += bins.counts[a][i];
            if cnt == 0 || right_count[i + 1] == 0 {
                continue;
            }
            let cost = acc.surface_area() * block.cost(cnt) + right_cost[i + 1];
            if best.is_none_or(|b| cost < b.0) {
                best = Some((cost, a, i));
            }
        }
    }
    best
}

fn partition(prims: &mut [PrimRef], left: impl Fn(&PrimRef) -> bool) -> usize {
    let mut i = 0;
    let mut j = prims.len();
    loop {
        while i < j && left(&prims[i]) {
            i += 1;
        }
        while i < j && !left(&prims[j - 1]) {
            j -= 1;
        }
        if i >= j {
            return i;
        }
        prims.swap(i, j - 1);
        i += 1;
        j -= 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Coordinates that probe the casts and comparisons: NaN, infinities, negatives, the
    /// bins' edges and the floats on each side of them, huge values.
    fn awkward() -> Vec<f32> {
        let mut v = vec![
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            -0.0,
            0.0,
            -1.0,
            1e30,
            -1e30,
        ];
        for k in 0..=17 {
            let x = k as f32 * 0.0625;
            v.extend([x, x.next_up(), x.next_down()]);
        }
        v.extend((0..64).map(|i| ((i * 7919) % 1000) as f32 / 997.0 - 0.01));
        v
    }

    #[test]
    fn binning_three_axes_at_once_and_the_partition_agree_with_the_bin() {
        // Centroids (doubled) over [0, 2] in 16 bins, and a degenerate axis (scale 0).
        let binner = Binner {
            lo: Vec3::ZERO,
            scale: Vec3::new(16.0 * 0.9999 / 2.0, 8.0 / 2.0, 0.0),
            count: 16,
        };
        let xs = awkward();
        let mut seen = 0;
        for (i, &x) in xs.iter().enumerate() {
            let (y, z) = (xs[(i * 5 + 3) % xs.len()], xs[(i * 11 + 1) % xs.len()]);
            let p = PrimRef::new(Aabb::new(Vec3::new(x, y, z), Vec3::new(x, y, z)), 0);
            let (lo, hi) = p.corners();
            let f = (lo + hi - Vec3A::from(binner.lo)) * Vec3A::from(binner.scale);
            let k = bins3(f, (binner.count - 1) as f32);
            for (a, &got) in k.iter().enumerate() {
                let want = binner.bin(&p, a);
                assert_eq!(got, want, "bins3 at {:?}, axis {a}", (x, y, z));
                for split in 0..binner.count - 1 {
                    assert_eq!(
                        binner.left_of(&p, a, split),
                        want <= split,
                        "{x} {a} {split}"
                    );
                }
                seen |= 1 << want;
            }
        }
        assert_eq!(seen, 0xffff, "every bin reached");
    }

    #[test]
    #[cfg_attr(
        not(target_arch = "x86_64"),
        ignore = "NaN order of glam's Vec3A min and max is SSE's only on x86-64"
    )]
    fn box3_is_aabb_bit_for_bit_nan_included() {
        let xs = awkward();
        let mut a = Aabb::EMPTY;
        let mut b = Box3::EMPTY;
        for (i, &x) in xs.iter().enumerate() {
            let y = xs[(i * 3 + 1) % xs.len()];
            let p = Vec3::new(x, y, xs[(i * 13 + 2) % xs.len()]);
            let q = Vec3::new(y, x, xs[(i * 17 + 5) % xs.len()]);
            let (pa, pb) = (
                Aabb::new(p, q),
                Box3 {
                    lo: p.into(),
                    hi: q.into(),
                },
            );
            a = a.union(pa);
            b = b.union(pb);
            let bits = |v: Vec3| v.to_array().map(f32::to_bits);
            assert_eq!(bits(b.aabb().min), bits(a.min), "min after {i}");
            assert_eq!(bits(b.aabb().max), bits(a.max), "max after {i}");
            assert_eq!(
                pb.surface_area().to_bits(),
                pa.surface_area().to_bits(),
                "{pa:?}"
            );
            assert_eq!(
                b.surface_area().to_bits(),
                a.surface_area().to_bits(),
                "{a:?}"
            );
        }
    }
}
