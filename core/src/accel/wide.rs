//! 8-wide BVH nodes, collapsed from the binary SAH tree: each node holds up to eight child
//! boxes stored axis by axis, so one ray meets all eight in a handful of vector instructions.
//! `collapse` builds them with f32 bounds (`Node8`); the mesh's tree keeps them quantised
//! (`QNode8`, 160 bytes instead of 224), decoded to f32 planes before the slab test.

use std::mem::MaybeUninit;

use glam::{Vec3, Vec4};

use crate::geometry::Aabb;

use super::sah::{self, MAX_DEPTH, MAX_LEAF};

pub const WIDTH: usize = 8;

/// A child reference: an inner node index, or (top bit set) a leaf of triangles
/// `first..first + count` with count - 1 in bits 28..31 and first in bits 0..28.
pub type Child = u32;
const LEAF_BIT: u32 = 1 << 31;
const FIRST_BITS: u32 = 28;
/// Meshes up to 2^28 triangles (≈ 10 GB of geometry) are addressable in a leaf.
pub const MAX_TRIANGLES: usize = 1 << FIRST_BITS;

#[inline]
pub fn is_leaf(c: Child) -> bool {
    c & LEAF_BIT != 0
}

/// (first, count) of a leaf child.
#[inline]
pub fn leaf_range(c: Child) -> (usize, usize) {
    (
        (c & ((1 << FIRST_BITS) - 1)) as usize,
        (((c >> FIRST_BITS) & 0x7) + 1) as usize,
    )
}

fn leaf(first: u32, count: u32) -> Child {
    debug_assert!(count >= 1 && count as usize <= MAX_LEAF && (first as usize) < MAX_TRIANGLES);
    LEAF_BIT | ((count - 1) << FIRST_BITS) | first
}

/// 224 bytes; unused slots hold an empty box (min = +inf, max = -inf). What `collapse` builds;
/// the mesh's tree stores each as a `QNode8`.
#[derive(Clone, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct Node8 {
    /// Indexed [axis][half][lane]: slot i is lane i % 4 of half i / 4. Four-wide vectors, so
    /// the slab test is two SSE passes wherever the crate is built (AVX2 measured no faster).
    pub lo: [[Vec4; 2]; 3],
    pub hi: [[Vec4; 2]; 3],
    pub child: [Child; WIDTH],
}

impl Node8 {
    const EMPTY: Node8 = Node8 {
        lo: [[Vec4::INFINITY; 2]; 3],
        hi: [[Vec4::NEG_INFINITY; 2]; 3],
        child: [0; WIDTH],
    };

    fn get(v: &[[Vec4; 2]; 3], i: usize) -> Vec3 {
        Vec3::new(v[0][i / 4][i % 4], v[1][i / 4][i % 4], v[2][i / 4][i % 4])
    }

    pub fn slot_bounds(&self, i: usize) -> Aabb {
        Aabb::new(Self::get(&self.lo, i), Self::get(&self.hi, i))
    }

    pub fn slot_is_empty(&self, i: usize) -> bool {
        self.slot_bounds(i).is_empty()
    }

    /// The union of the used slots' boxes.
    pub fn bounds(&self) -> Aabb {
        (0..WIDTH)
            .filter(|&i| !self.slot_is_empty(i))
            .fold(Aabb::EMPTY, |b, i| b.union(self.slot_bounds(i)))
    }

    fn set(&mut self, i: usize, b: Aabb, c: Child) {
        for a in 0..3 {
            self.lo[a][i / 4][i % 4] = b.min[a];
            self.hi[a][i / 4][i % 4] = b.max[a];
        }
        self.child[i] = c;
    }
}

/// A grid index: 16 bits (8 bits cost the dragon's single rays ~8% in looser boxes alone).
pub type Q = u16;
const Q_MAX: f32 = Q::MAX as f32;

/// The largest grid exponent: 65535 * 2^112 < f32::MAX, so q * step never overflows and is
/// exact for every q (a 16-bit integer times a power of two, subnormal or not).
const MAX_EXP: i32 = 112;

/// A `Node8` in 160 bytes (224 as f32): per axis a
/// grid of origin + q * step with step a power of two, and each child's bounds as 16-bit grid
/// indices, lo rounded down and hi up, so every decoded box contains the child's box.
///
/// Decoding is `origin + q * step` in f32: the product is exact, so the one rounding is the
/// sum's, the same with or without FMA, on every path. `quantise` picks each index by
/// evaluating that very expression, so the containment holds for the decoded floats
/// themselves, and the slab tests run on them as on any f32 box (`SLAB_WIDEN`'s bound is
/// unchanged). An axis whose bounds no grid covers (non-finite, or spanning more than
/// 65535 * 2^112) has a NaN origin: every plane decodes to NaN, which the slab tests' max/min
/// drop (the NaN rule they already rely on), so that axis culls nothing in this node.
#[derive(Clone, Debug)]
#[repr(C, align(32))]
pub struct QNode8 {
    pub origin: [f32; 3],
    pub step: [f32; 3],
    /// Indexed [axis][slot].
    pub lo: [[Q; WIDTH]; 3],
    pub hi: [[Q; WIDTH]; 3],
    pub child: [Child; WIDTH],
    /// Bit i set when slot i holds a child: the slab tests' masks are cut to it, since a
    /// quantised box cannot be empty for every ray as +inf..-inf is.
    pub used: u8,
}

const _: () = assert!(std::mem::size_of::<QNode8>() == 160);

/// Bitwise, so two trees with the same NaN origin compare equal.
impl PartialEq for QNode8 {
    fn eq(&self, o: &Self) -> bool {
        let bits = |v: &[f32; 3]| v.map(f32::to_bits);
        bits(&self.origin) == bits(&o.origin)
            && bits(&self.step) == bits(&o.step)
            && (self.lo, self.hi, self.child, self.used) == (o.lo, o.hi, o.child, o.used)
    }
}

impl QNode8 {
    /// Grid index `q` on axis `a` as a plane: the value every slab test computes.
    #[inline(always)]
    pub fn decode(&self, a: usize, q: Q) -> f32 {
        self.origin[a] + f32::from(q) * self.step[a]
    }

    /// Slot i's decoded box, a NaN axis as -inf..inf (what the slab tests make of it).
    pub fn slot_bounds(&self, i: usize) -> Aabb {
        let f = |q: &[[Q; WIDTH]; 3], none: f32| {
            Vec3::from_array([0, 1, 2].map(|a| {
                let v = self.decode(a, q[a][i]);
                if v.is_nan() { none } else { v }
            }))
        };
        Aabb::new(f(&self.lo, f32::NEG_INFINITY), f(&self.hi, f32::INFINITY))
    }

    pub fn slot_is_empty(&self, i: usize) -> bool {
        self.used & (1 << i) == 0
    }

    /// Axis `a`'s (entry, exit) index rows for a ray whose direction's sign on that axis is
    /// negative when `toward_neg`: such a ray enters through the max plane.
    #[inline(always)]
    pub fn entry_exit(&self, a: usize, toward_neg: bool) -> (&[Q; WIDTH], &[Q; WIDTH]) {
        if toward_neg {
            (&self.hi[a], &self.lo[a])
        } else {
            (&self.lo[a], &self.hi[a])
        }
    }

    /// A row decoded in two four-lane halves (the SSE slab test's form).
    #[inline(always)]
    pub fn decode_row(&self, a: usize, q: &[Q; WIDTH]) -> [Vec4; 2] {
        let half = |h: usize| {
            let v = Vec4::from_array([0, 1, 2, 3].map(|l| f32::from(q[4 * h + l])));
            Vec4::splat(self.origin[a]) + v * Vec4::splat(self.step[a])
        };
        [half(0), half(1)]
    }

    /// Quantises `n`'s used slots (those with a non-empty box).
    pub fn quantise(n: &Node8) -> QNode8 {
        let mut q = QNode8 {
            origin: [0.0; 3],
            step: [1.0; 3],
            lo: [[Q::MAX; WIDTH]; 3],
            hi: [[0; WIDTH]; 3],
            child: n.child,
            used: 0,
        };
        let used: Vec<usize> = (0..WIDTH).filter(|&i| !n.slot_is_empty(i)).collect();
        for &i in &used {
            q.used |= 1 << i;
        }
        for a in 0..3 {
            let lo = |i: usize| n.lo[a][i / 4][i % 4];
            let hi = |i: usize| n.hi[a][i / 4][i % 4];
            let lo_min = used.iter().map(|&i| lo(i)).fold(f32::INFINITY, f32::min);
            let hi_max = used
                .iter()
                .map(|&i| hi(i))
                .fold(f32::NEG_INFINITY, f32::max);
            let Some((origin, step)) = grid(lo_min, hi_max) else {
                q.origin[a] = f32::NAN;
                continue;
            };
            (q.origin[a], q.step[a]) = (origin, step);
            let dec = |k: Q| origin + f32::from(k) * step;
            let guess = |v: f32| {
                ((f64::from(v) - f64::from(origin)) / f64::from(step)).clamp(0.0, f64::from(Q_MAX))
            };
            for &i in &used {
                // The f64 guess is within one of the answer; the loops settle it on the
                // decoded f32 values: the largest index at or below lo, the smallest at or
                // above hi (index 0 decodes to origin <= lo, Q::MAX to at least hi_max).
                let mut l = guess(lo(i)).floor() as Q;
                while l > 0 && dec(l) > lo(i) {
                    l -= 1;
                }
                while l < Q::MAX && dec(l + 1) <= lo(i) {
                    l += 1;
                }
                let mut h = guess(hi(i)).ceil() as Q;
                while h < Q::MAX && dec(h) < hi(i) {
                    h += 1;
                }
                while h > 0 && dec(h - 1) >= hi(i) {
                    h -= 1;
                }
                (q.lo[a][i], q.hi[a][i]) = (l, h);
            }
        }
        q
    }
}

/// (origin, step) of the finest grid whose 65536 planes from `lo_min` reach `hi_max`, decoded
/// as `QNode8::decode` does; None when no power of two up to 2^MAX_EXP does (or a bound is
/// not finite).
fn grid(lo_min: f32, hi_max: f32) -> Option<(f32, f32)> {
    if !lo_min.is_finite() || !hi_max.is_finite() {
        return None;
    }
    let span = f64::from(hi_max) - f64::from(lo_min);
    let mut e = if span > 0.0 {
        (span / f64::from(Q_MAX)).log2().ceil() as i32
    } else {
        -149
    };
    // One step down first: the f64 estimate may overshoot by one.
    e = (e - 1).max(-149);
    while e <= MAX_EXP {
        // 2^e as f32, exact for -149..=127 (subnormal below -126).
        let step = 2f64.powi(e) as f32;
        if lo_min + Q_MAX * step >= hi_max {
            return Some((lo_min, step));
        }
        e += 1;
    }
    None
}

/// Collapses the binary tree into 8-wide nodes, depth first; node 0 is the root (a root leaf
/// becomes a node with one slot).
pub fn collapse(root: &sah::Node) -> Vec<Node8> {
    let mut nodes = Vec::new();
    emit(root, &mut nodes);
    nodes
}

fn emit(node: &sah::Node, nodes: &mut Vec<Node8>) -> u32 {
    let me = nodes.len();
    nodes.push(Node8::EMPTY);
    // Open the largest inner child until eight slots are used: the classic collapse, which
    // keeps the boxes a ray is most likely to enter near the top.
    let mut kids: Vec<&sah::Node> = match node {
        sah::Node::Inner { children, .. } => vec![&children[0], &children[1]],
        sah::Node::Leaf { .. } => vec![node],
    };
    while kids.len() < WIDTH {
        let pick = kids
            .iter()
            .enumerate()
            .filter(|(_, k)| matches!(k, sah::Node::Inner { .. }))
            .max_by(|a, b| {
                a.1.bounds()
                    .surface_area()
                    .total_cmp(&b.1.bounds().surface_area())
            })
            .map(|(i, _)| i);
        let Some(i) = pick else { break };
        if let sah::Node::Inner { children, .. } = kids[i] {
            kids[i] = &children[0];
            kids.push(&children[1]);
        }
    }
    for (slot, k) in kids.into_iter().enumerate() {
        let c = match k {
            sah::Node::Leaf { first, count, .. } => leaf(*first, *count),
            sah::Node::Inner { .. } => emit(k, nodes),
        };
        nodes[me].set(slot, k.bounds(), c);
    }
    me as u32
}

/// Entries a traversal stack can hold: a node pushes at most WIDTH children after popping
/// itself, and no path is longer than the binary tree's depth cap.
pub const STACK: usize = WIDTH * (MAX_DEPTH + 1);

/// What a traversal stack holds: a child and the distance it is entered at (the key the
/// stack sorts by), and for packets also where its box is stored.
pub trait StackEntry: Copy {
    fn dist(&self) -> f32;
}

impl StackEntry for (Child, f32) {
    #[inline(always)]
    fn dist(&self) -> f32 {
        self.1
    }
}

/// (child, entry distance, node index * 8 + slot of the child's box).
impl StackEntry for (Child, f32, u32) {
    #[inline(always)]
    fn dist(&self) -> f32 {
        self.1
    }
}

/// A fixed, uninitialised stack of (child, entry distance) for one traversal.
///
/// Uninitialised because zeroing its 4 KiB on every ray cost a fifth of the throughput
/// (`docs/perf.md`).
pub struct RayStack<E: StackEntry = (Child, f32)> {
    items: [MaybeUninit<E>; STACK],
    len: usize,
}

impl<E: StackEntry> RayStack<E> {
    #[inline]
    pub fn new() -> Self {
        RayStack {
            items: [const { MaybeUninit::uninit() }; STACK],
            len: 0,
        }
    }
    #[inline]
    pub fn push(&mut self, e: E) {
        // The depth cap bounds the size; the check keeps a broken tree from writing out of
        // bounds (it then loses children instead).
        if let Some(slot) = self.items.get_mut(self.len) {
            *slot = MaybeUninit::new(e);
            self.len += 1;
        }
    }
    #[inline]
    pub fn pop(&mut self) -> Option<E> {
        if self.len == 0 {
            return None;
        }
        self.len -= 1;
        #[allow(unsafe_code)]
        // SAFETY: every index below `len` was written by `push`, and `len` only shrinks here.
        Some(unsafe { self.items[self.len].assume_init() })
    }
    /// Pops entries until one is entered no later than `t`: the nearest child not ruled out
    /// by a hit found since it was pushed.
    #[inline(always)]
    pub fn pop_within(&mut self, t: f32) -> Option<E> {
        while let Some(e) = self.pop() {
            if e.dist() <= t {
                return Some(e);
            }
        }
        None
    }
    /// Sorts the top `k` entries so the nearest is on top (popped first).
    #[inline]
    pub fn sort_top(&mut self, k: usize) {
        let base = self.len.saturating_sub(k);
        for i in base + 1..self.len {
            let mut j = i;
            #[allow(unsafe_code)]
            // SAFETY: indices base..len were all written by `push`.
            let x = unsafe { self.items[i].assume_init() };
            while j > base {
                #[allow(unsafe_code)]
                // SAFETY: as above, j - 1 >= base.
                let y = unsafe { self.items[j - 1].assume_init() };
                if y.dist() >= x.dist() {
                    break;
                }
                self.items[j] = MaybeUninit::new(y);
                j -= 1;
            }
            self.items[j] = MaybeUninit::new(x);
        }
    }
}

impl<E: StackEntry> Default for RayStack<E> {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A node of `boxes` (at most eight), as `collapse` fills one.
    fn node(boxes: &[Aabb]) -> Node8 {
        let mut n = Node8::EMPTY;
        for (i, b) in boxes.iter().enumerate() {
            n.set(i, *b, i as Child);
        }
        n
    }

    /// Every used slot's decoded box contains its box, and each index is the tightest on its
    /// side: one step in would cut the box. The grid is the finest that reaches hi_max.
    fn assert_tight(boxes: &[Aabb]) -> QNode8 {
        let q = QNode8::quantise(&node(boxes));
        assert_eq!(q.used as usize, (1 << boxes.len()) - 1);
        for a in 0..3 {
            if q.origin[a].is_nan() {
                continue;
            }
            let hi_max = boxes.iter().map(|b| b.max[a]).fold(f32::MIN, f32::max);
            if q.step[a] > f32::from_bits(1) {
                let coarse = q.origin[a] + Q_MAX * (q.step[a] * 0.5);
                assert!(coarse < hi_max, "axis {a}: a finer grid reaches {hi_max}");
            }
            for (i, b) in boxes.iter().enumerate() {
                let (l, h) = (q.lo[a][i], q.hi[a][i]);
                assert!(q.decode(a, l) <= b.min[a] && q.decode(a, h) >= b.max[a]);
                assert!(
                    l == Q::MAX || q.decode(a, l + 1) > b.min[a],
                    "slot {i} axis {a} lo"
                );
                assert!(
                    h == 0 || q.decode(a, h - 1) < b.max[a],
                    "slot {i} axis {a} hi"
                );
            }
        }
        q
    }

    #[test]
    fn quantised_boxes_contain_their_boxes_tightly() {
        let mut seed = 7u32;
        let mut f = move || {
            seed ^= seed << 13;
            seed ^= seed >> 17;
            seed ^= seed << 5;
            seed as f32 / u32::MAX as f32
        };
        for scale in [1e-40, 1e-30, 1e-3, 1.0, 7.0, 1e6, 1e30, 1e37] {
            for _ in 0..200 {
                let offset = (f() - 0.5) * scale * 1e3;
                let k = 1 + (f() * 7.99) as usize;
                let boxes: Vec<Aabb> = (0..k)
                    .map(|_| {
                        let p = Vec3::new(f(), f(), f()) * scale + offset;
                        Aabb::new(p, p + Vec3::new(f(), f(), f()) * scale)
                    })
                    .collect();
                assert_tight(&boxes);
            }
        }
        // A flat axis, and one box of a single point.
        assert_tight(&[Aabb::new(
            Vec3::new(0.0, 1.0, 2.0),
            Vec3::new(1.0, 1.0, 5.0),
        )]);
        assert_tight(&[Aabb::new(Vec3::splat(3.5), Vec3::splat(3.5))]);
    }

    /// Bounds no grid of 2^112 steps spans, or infinite ones: that axis decodes to NaN, shown
    /// as unbounded, and the other axes are still quantised.
    #[test]
    fn unquantisable_axes_decode_to_nan() {
        let b = [
            Aabb::new(Vec3::new(-3e38, 0.0, 0.0), Vec3::new(-1e38, 1.0, 1.0)),
            Aabb::new(
                Vec3::new(2e38, 0.0, 0.0),
                Vec3::new(3e38, 2.0, f32::INFINITY),
            ),
        ];
        let q = assert_tight(&b);
        assert!(q.origin[0].is_nan() && q.origin[2].is_nan() && !q.origin[1].is_nan());
        let s = q.slot_bounds(0);
        assert_eq!((s.min.x, s.max.x), (f32::NEG_INFINITY, f32::INFINITY));
        assert!(s.min.y <= 0.0 && s.max.y >= 1.0 && s.max.y < 1.1);
        // Within 65535 * 2^112 it is quantised.
        let q = assert_tight(&[Aabb::new(Vec3::splat(-1e38), Vec3::splat(1.5e38))]);
        assert!(!q.origin[0].is_nan());
    }
}
