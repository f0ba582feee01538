//! 8-wide BVH nodes, collapsed from the binary SAH tree: each node holds up to eight child
//! boxes stored axis by axis ([f32; 8] per bound), so one ray meets all eight in a handful of
//! vector instructions.

use std::mem::MaybeUninit;

use glam::{Vec3, Vec4};

use crate::geometry::Aabb;

use super::sah::{self, MAX_DEPTH, MAX_LEAF};

pub const WIDTH: usize = 8;

/// A child reference: an inner node, or (top bit set) a leaf of triangles
/// `first..first + count` with count - 1 in bits 28..31 and first in bits 0..28.
///
/// An inner node is named by its offset in the node array in 8-byte units (`inner`: its
/// index times 28), which the walk's load takes as its scaled index: an index needed a
/// multiply by 224, three cycles on the walk's critical path, node after node (single rays
/// +0.7-1.4%, `docs/perf.md`). 2^31 units hold 76.7 million nodes; a tree has no more nodes
/// than triangles (every node but a lone root has two children or more), and
/// `MAX_TRIANGLES` is 2^26.
pub type Child = u32;
/// Bytes in one `Child` unit.
pub const NODE_UNIT: usize = 8;
/// `Child` units in one node.
pub const NODE_UNITS: u32 = (size_of::<Node8>() / NODE_UNIT) as u32;
const _: () = assert!(
    size_of::<Node8>() == 224
        && size_of::<Node8>().is_multiple_of(NODE_UNIT)
        && MAX_TRIANGLES * (NODE_UNITS as usize) < LEAF_BIT as usize
);

/// The child that names inner node `index`.
#[inline]
pub fn inner(index: usize) -> Child {
    debug_assert!(index < MAX_TRIANGLES);
    (index * NODE_UNITS as usize) as Child
}

/// The index of the inner node `c` names, if it names the start of one.
pub fn node_index(c: Child) -> Option<usize> {
    (!is_leaf(c) && c.is_multiple_of(NODE_UNITS)).then_some((c / NODE_UNITS) as usize)
}
const LEAF_BIT: u32 = 1 << 31;
const FIRST_BITS: u32 = 28;
/// The most triangles a mesh may have: a leaf could address 2^28, but the nodes of a tree
/// over more than 2^26 might not all be named by a `Child`. 2^26 triangles take 4.3 GB as a
/// tree; the OBJ loader refuses meshes of more (`ObjError::TooManyTriangles`: a file under
/// its size limit can still hold them, a polygon of n corners being n - 2 triangles).
pub const MAX_TRIANGLES: usize = 1 << 26;
const _: () = assert!(MAX_TRIANGLES <= 1 << FIRST_BITS);

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

pub fn leaf(first: u32, count: u32) -> Child {
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

    /// Slot `s`'s child, as the single-ray walks read it to go down: a volatile read, so it
    /// stays one load from this node. With a plain read LLVM merged it with the pop's load of
    /// a stack entry into one load from an address chosen between the two, which put that
    /// choice's two instructions on the chain from one node to the next: single rays 1-2%
    /// slower on the Stanford bunny on Zen 5 (`docs/perf.md`). A volatile read of a valid
    /// reference is a plain load.
    #[inline(always)]
    pub fn child_at(&self, s: usize) -> Child {
        let c = &self.child[s];
        #[allow(unsafe_code)]
        // SAFETY: `c` refers to an initialised, aligned u32 inside `self`.
        unsafe {
            std::ptr::read_volatile(c)
        }
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

/// What one node visit costs relative to one leaf block test, in the collapse's SAH: a node
/// is eight box tests in a few vector instructions, a leaf eight triangle tests in as few
/// (the binary builder's `TRAVERSAL_COST` makes the same call). With the builder's leaves
/// kept whole only the node term varies, so this matters only where small subtrees could
/// merge into one leaf.
const NODE_COST: f32 = 1.0;

/// How a binary subtree is laid out in the wide tree when it may take up to some number of
/// slots (Ylitie, Karras, Laine, "Efficient Incoherent Ray Traversal on GPUs Through
/// Compressed Wide BVHs", HPG 2017, section 3).
#[derive(Clone, Copy, Debug, PartialEq)]
enum How {
    /// One slot: a leaf of all the subtree's triangles (at most `MAX_LEAF`, contiguous
    /// because the builder lays leaves out depth first).
    Leaf,
    /// One slot: a wide node whose eight slots the two children share, `left` to the left.
    Node { left: u8 },
    /// Several slots: the children's own layouts side by side, `left` slots to the left.
    Split { left: u8 },
}

/// A binary node's table, `cost[i]` and `how[i]` for a layout in at most i + 1 slots, with
/// all the emission needs from the node: it then reads these in order instead of chasing the
/// binary tree's pointers a second time.
struct Plan {
    cost: [f32; WIDTH],
    how: [How; WIDTH],
    /// Where the children's plans are (none for a leaf).
    kids: [u32; 2],
    bounds: Aabb,
    /// The subtree's triangles, `first..first + count`.
    first: u32,
    count: u32,
}

/// Collapses the binary tree into 8-wide nodes, depth first; node 0 is the root (a root leaf
/// becomes a node with one slot). The layout is the one with the least SAH cost, found by
/// dynamic programming over the binary tree: the greedy collapse (open the largest child until
/// eight slots are used) filled the bottom nodes with two or three leaves each.
pub fn collapse(root: &sah::Node, block: sah::LeafBlock) -> Vec<Node8> {
    let mut plans = Vec::new();
    let top = plan(root, block, &mut plans);
    let mut nodes = Vec::new();
    let p = &plans[top];
    if let How::Node { .. } = p.how[0] {
        emit(&plans, top, &mut nodes);
    } else {
        // The whole mesh is one leaf: a node with one slot.
        let mut n = Node8::EMPTY;
        n.set(0, p.bounds, leaf(p.first, p.count));
        nodes.push(n);
    }
    nodes
}

/// Fills in the plans of `node`'s subtree (children before parents) and returns where its
/// own is.
fn plan(node: &sah::Node, block: sah::LeafBlock, plans: &mut Vec<Plan>) -> usize {
    let bounds = node.bounds();
    let area = bounds.surface_area();
    let mut p = Plan {
        cost: [f32::INFINITY; WIDTH],
        how: [How::Leaf; WIDTH],
        kids: [u32::MAX; 2],
        bounds,
        first: 0,
        count: 0,
    };
    match node {
        sah::Node::Leaf { first, count, .. } => {
            (p.first, p.count) = (*first, *count);
            p.cost[0] = area * block.cost(p.count);
        }
        sah::Node::Inner { children, .. } => {
            let l = plan(&children[0], block, plans);
            let r = plan(&children[1], block, plans);
            inner_table(&mut p, &plans[l], &plans[r], area);
            p.kids = [l as u32, r as u32];
            // A small subtree may become one leaf.
            let as_leaf = area * block.cost(p.count);
            if p.count as usize <= MAX_LEAF && as_leaf <= p.cost[0] {
                (p.cost[0], p.how[0]) = (as_leaf, How::Leaf);
            }
        }
    }
    // A layout in fewer slots also fits in more.
    for i in 1..WIDTH {
        if p.cost[i - 1] <= p.cost[i] {
            (p.cost[i], p.how[i]) = (p.cost[i - 1], p.how[i - 1]);
        }
    }
    plans.push(p);
    plans.len() - 1
}

/// An inner node's table from its children's: as a node of its own (one visit, then all
/// eight slots shared by the children), or in two or more slots, the children side by side.
fn inner_table(p: &mut Plan, l: &Plan, r: &Plan, area: f32) {
    (p.first, p.count) = (l.first, l.count + r.count);
    let (c, left) = best_split(l, r, WIDTH);
    p.cost[0] = NODE_COST * area + c;
    p.how[0] = How::Node { left };
    for i in 1..WIDTH {
        let (c, left) = best_split(l, r, i + 1);
        (p.cost[i], p.how[i]) = (c, How::Split { left });
    }
}

/// The cheapest way for two children to share `slots` (2 or more) slots, each taking at
/// least one: (cost, slots to the left). Boxes too large for f32 give infinite or NaN costs;
/// the first way then stands, so the layout stays valid if not the best. (Bounding `j` by
/// the leaves each side has measured slower: the fixed loops unroll.)
fn best_split(l: &Plan, r: &Plan, slots: usize) -> (f32, u8) {
    let cost = |j: usize| (l.cost[j - 1] + r.cost[slots - j - 1], j as u8);
    (2..slots)
        .map(cost)
        .fold(cost(1), |a, b| if b.0 < a.0 { b } else { a })
}

/// Emits plan `at` (a `How::Node`) as a wide node and, depth first, the nodes below it.
fn emit(plans: &[Plan], at: usize, nodes: &mut Vec<Node8>) -> u32 {
    let me = nodes.len();
    nodes.push(Node8::EMPTY);
    let mut slots = [usize::MAX; WIDTH];
    let mut used = 0;
    let p = &plans[at];
    if let How::Node { left } = p.how[0] {
        let left = left as usize;
        gather(plans, p.kids[0] as usize, left, &mut slots, &mut used);
        gather(
            plans,
            p.kids[1] as usize,
            WIDTH - left,
            &mut slots,
            &mut used,
        );
    }
    for (slot, &k) in slots[..used].iter().enumerate() {
        let kp = &plans[k];
        let c = match kp.how[0] {
            How::Node { .. } => inner(emit(plans, k, nodes) as usize),
            _ => leaf(kp.first, kp.count),
        };
        nodes[me].set(slot, kp.bounds, c);
    }
    me as u32
}

/// Appends the plans that plan `at`'s layout in `slots` slots puts in them, left to right:
/// `at` itself where the layout takes one slot.
fn gather(plans: &[Plan], at: usize, slots: usize, out: &mut [usize; WIDTH], used: &mut usize) {
    let p = &plans[at];
    if let How::Split { left } = p.how[slots - 1] {
        let left = left as usize;
        gather(plans, p.kids[0] as usize, left, out, used);
        gather(plans, p.kids[1] as usize, slots - left, out, used);
    } else if let Some(o) = out.get_mut(*used) {
        // Never full: the layouts gathered for one node take at most its WIDTH slots.
        *o = at;
        *used += 1;
    }
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
    use std::collections::HashMap;

    use super::*;

    /// A leaf of `count` triangles from `first`, its box the cube of side `size` at x = `x`.
    fn leaf_at(first: u32, count: u32, x: f32, size: f32) -> sah::Node {
        sah::Node::Leaf {
            bounds: Aabb::new(Vec3::new(x, 0.0, 0.0), Vec3::new(x + size, size, size)),
            first,
            count,
        }
    }

    /// A balanced binary tree over `leaves` leaves of `per` triangles each, unit cubes side
    /// by side on x.
    fn balanced(first_leaf: u32, leaves: u32, per: u32) -> sah::Node {
        sized(first_leaf, leaves, per, 1.0)
    }

    /// `balanced` with cubes of side `size`.
    fn sized(first_leaf: u32, leaves: u32, per: u32, size: f32) -> sah::Node {
        if leaves == 1 {
            return leaf_at(first_leaf * per, per, first_leaf as f32 * size, size);
        }
        let half = leaves / 2;
        let (l, r) = (
            sized(first_leaf, half, per, size),
            sized(first_leaf + half, leaves - half, per, size),
        );
        sah::Node::Inner {
            bounds: l.bounds().union(r.bounds()),
            children: Box::new([l, r]),
        }
    }

    /// The range of triangles under `node`.
    fn span(node: &sah::Node) -> (u32, u32) {
        match node {
            sah::Node::Leaf { first, count, .. } => (*first, *count),
            sah::Node::Inner { children, .. } => {
                let (first, a) = span(&children[0]);
                let (_, b) = span(&children[1]);
                (first, a + b)
            }
        }
    }

    /// Every subtree that may become one leaf: (first, count) -> its box.
    fn leaf_candidates(n: &sah::Node, out: &mut HashMap<(usize, usize), Aabb>) -> (u32, u32) {
        let (first, count) = span(n);
        if let sah::Node::Inner { children, .. } = n {
            leaf_candidates(&children[0], out);
            leaf_candidates(&children[1], out);
        }
        if count as usize <= MAX_LEAF || matches!(n, sah::Node::Leaf { .. }) {
            out.insert((first as usize, count as usize), n.bounds());
        }
        (first, count)
    }

    /// That the wide tree holds the binary tree's triangles once each, every leaf being one
    /// of its subtrees with that subtree's box, every inner slot's box the union of the
    /// boxes in the node it points to, and every node reached once.
    fn check(root: &sah::Node, nodes: &[Node8]) -> Result<(), String> {
        let mut candidates = HashMap::new();
        let (_, total) = leaf_candidates(root, &mut candidates);
        if nodes.first().map(Node8::bounds) != Some(root.bounds()) {
            return Err("the root's box is not the tree's".into());
        }
        let (mut ranges, mut reached, mut stack) = (Vec::new(), vec![0; nodes.len()], vec![0]);
        while let Some(i) = stack.pop() {
            let n = nodes.get(i).ok_or(format!("node {i} out of range"))?;
            reached[i] += 1;
            for s in (0..WIDTH).filter(|&s| !n.slot_is_empty(s)) {
                let (b, c) = (n.slot_bounds(s), n.child[s]);
                if is_leaf(c) {
                    if candidates.get(&leaf_range(c)) != Some(&b) {
                        return Err(format!("node {i} slot {s} is no subtree's leaf"));
                    }
                    ranges.push(leaf_range(c));
                } else if let Some(k) = node_index(c)
                    && nodes.get(k).map(Node8::bounds) == Some(b)
                {
                    stack.push(k);
                } else {
                    return Err(format!("node {i} slot {s}'s box is not its node's"));
                }
            }
        }
        if reached.iter().any(|&r| r != 1) {
            return Err("a node is reached other than once".into());
        }
        ranges.sort();
        let end = ranges.iter().try_fold(0, |at, &(first, count)| {
            (first == at).then_some(first + count)
        });
        match end {
            Some(end) if end == total as usize => Ok(()),
            _ => Err(format!(
                "the leaves do not hold triangles 0..{total} once each"
            )),
        }
    }

    /// Panics with what `check` found wrong.
    fn assert_whole(root: &sah::Node, nodes: &[Node8]) {
        if let Err(e) = check(root, nodes) {
            panic!("{e}");
        }
    }

    fn used_slots(nodes: &[Node8]) -> usize {
        let used = |n: &Node8| (0..WIDTH).filter(|&s| !n.slot_is_empty(s)).count();
        nodes.iter().map(used).sum()
    }

    #[test]
    fn collapse_keeps_every_leaf_and_box_and_fills_the_nodes() {
        // 16 full leaves of equal size: the greedy collapse opened the root's children
        // evenly until it held eight pairs of leaves, so 9 nodes of 2.7 children. The least
        // SAH puts eight leaves in one node, six in the root's other slots and the last two
        // in a third node: 3 nodes of 6.
        let root = balanced(0, 16, 8);
        let nodes = collapse(&root, sah::LeafBlock(8));
        assert_whole(&root, &nodes);
        assert_eq!(nodes.len(), 3);
        assert_eq!(used_slots(&nodes), 16 + 2);
        // A larger tree, 200 leaves: still all there, and fuller than the greedy 2.7.
        let root = balanced(0, 200, 8);
        let nodes = collapse(&root, sah::LeafBlock(8));
        assert_whole(&root, &nodes);
        assert!(used_slots(&nodes) as f32 / nodes.len() as f32 > 5.0);
    }

    #[test]
    fn check_fails_when_the_collapse_drops_a_subtree_or_a_leaf() {
        let root = balanced(0, 16, 8);
        let nodes = collapse(&root, sah::LeafBlock(8));
        assert_whole(&root, &nodes);
        // The root's inner slot: a whole subtree gone.
        let inner = (0..WIDTH).find(|&s| !is_leaf(nodes[0].child[s]));
        let inner = inner.expect("the root has an inner slot");
        let mut dropped = nodes.clone();
        dropped[0].set(inner, Aabb::EMPTY, 0);
        assert!(check(&root, &dropped).is_err());
        // A leaf between two others in the node below: every box stays the same, only the
        // count of triangles can tell.
        let below = node_index(nodes[0].child[inner]).expect("an inner child names a node");
        let mut dropped = nodes.clone();
        dropped[below].set(3, Aabb::EMPTY, 0);
        assert_eq!(dropped[below].bounds(), nodes[below].bounds());
        let err = check(&root, &dropped).expect_err("a leaf dropped unnoticed");
        assert!(err.contains("once each"), "{err}");
    }

    #[test]
    fn small_subtrees_merge_into_one_leaf_where_a_leaf_test_costs_one_block() {
        // Two leaves of three side by side: one test of eight lanes tests all six.
        let root = balanced(0, 2, 3);
        let nodes = collapse(&root, sah::LeafBlock(8));
        assert_whole(&root, &nodes);
        assert_eq!(nodes.len(), 1);
        assert_eq!(nodes[0].child[0], leaf(0, 6));
        assert!((1..WIDTH).all(|s| nodes[0].slot_is_empty(s)));
        // Tested one by one, six triangles in the larger box cost more than two leaves.
        let nodes = collapse(&root, sah::LeafBlock(1));
        assert_whole(&root, &nodes);
        assert_eq!(used_slots(&nodes), 2);
    }

    #[test]
    fn a_single_leaf_becomes_a_node_with_one_slot() {
        let root = leaf_at(0, 5, 0.0, 1.0);
        let nodes = collapse(&root, sah::LeafBlock(8));
        assert_whole(&root, &nodes);
        assert_eq!(nodes.len(), 1);
        assert_eq!(nodes[0].child[0], leaf(0, 5));
    }

    #[test]
    fn boxes_too_large_for_f32_areas_still_collapse_whole() {
        // Every area infinite, so every cost too: any layout is as good, but it must hold
        // every leaf.
        for leaves in [2, 9, 16, 100] {
            let root = sized(0, leaves, 8, 1.0e38);
            assert_eq!(root.bounds().surface_area(), f32::INFINITY);
            assert_whole(&root, &collapse(&root, sah::LeafBlock(8)));
        }
    }
}
