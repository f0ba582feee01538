//! 8-wide BVH nodes, collapsed from the binary SAH tree: each node holds up to eight child
//! boxes stored axis by axis ([f32; 8] per bound), so one ray meets all eight in a handful of
//! vector instructions.

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

/// 224 bytes; unused slots hold an empty box (min = +inf, max = -inf) that no ray enters.
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

    /// Axis `a`'s (entry, exit) rows for a ray whose direction's sign on that axis is
    /// negative when `toward_neg`: such a ray enters through the max plane.
    #[inline(always)]
    pub fn entry_exit(&self, a: usize, toward_neg: bool) -> (&[Vec4; 2], &[Vec4; 2]) {
        if toward_neg {
            (&self.hi[a], &self.lo[a])
        } else {
            (&self.lo[a], &self.hi[a])
        }
    }

    fn set(&mut self, i: usize, b: Aabb, c: Child) {
        for a in 0..3 {
            self.lo[a][i / 4][i % 4] = b.min[a];
            self.hi[a][i / 4][i % 4] = b.max[a];
        }
        self.child[i] = c;
    }
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
