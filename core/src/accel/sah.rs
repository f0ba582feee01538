//! A binary BVH over primitive boxes by binned SAH on all three axes, built in parallel
//! (subtrees and, near the root, the binning itself). It is an intermediate form: the
//! triangle BVH collapses it into 8-wide nodes. Primitives end up permuted into leaf order.

use glam::Vec3;
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
    /// Twice the centroid: binning only needs it up to a common scale.
    #[inline]
    fn doubled_centroid(&self) -> Vec3 {
        self.lo + self.hi
    }
    fn bounds(&self) -> Aabb {
        Aabb::new(self.lo, self.hi)
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
    let fold = |acc: (Aabb, Aabb), p: &PrimRef| {
        (acc.0.union(p.bounds()), acc.1.grow(p.doubled_centroid()))
    };
    let merge = |a: (Aabb, Aabb), b: (Aabb, Aabb)| (a.0.union(b.0), a.1.union(b.1));
    if prims.len() > PARALLEL_BINNING {
        prims
            .par_chunks(PARALLEL_BINNING / 4)
            .map(|c| c.iter().fold((Aabb::EMPTY, Aabb::EMPTY), fold))
            .reduce(|| (Aabb::EMPTY, Aabb::EMPTY), merge)
    } else {
        prims.iter().fold((Aabb::EMPTY, Aabb::EMPTY), fold)
    }
}

#[derive(Clone, Copy)]
struct Bins {
    boxes: [[Aabb; BINS]; 3],
    counts: [[u32; BINS]; 3],
}

impl Bins {
    fn new() -> Self {
        Bins {
            boxes: [[Aabb::EMPTY; BINS]; 3],
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
    #[inline]
    fn bin(&self, doubled_centroid: Vec3, axis: usize) -> usize {
        // `as usize` saturates (NaN to 0), and min keeps it in range: no input can index out.
        (((doubled_centroid[axis] - self.lo[axis]) * self.scale[axis]) as usize).min(self.count - 1)
    }
    fn fill(&self, prims: &[PrimRef], bins: &mut Bins) {
        for p in prims {
            let c = p.doubled_centroid();
            let b = p.bounds();
            for a in 0..3 {
                let k = self.bin(c, a);
                bins.boxes[a][k] = bins.boxes[a][k].union(b);
                bins.counts[a][k] += 1;
            }
        }
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
        partition(prims, |p| binner.bin(p.doubled_centroid(), axis) <= split)
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
        let (mut acc, mut cnt) = (Aabb::EMPTY, 0u32);
        for i in (1..nb).rev() {
            acc = acc.union(bins.boxes[a][i]);
            cnt += bins.counts[a][i];
            right_cost[i] = acc.surface_area() * block.cost(cnt);
            right_count[i] = cnt;
        }
        let (mut acc, mut cnt) = (Aabb::EMPTY, 0u32);
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
