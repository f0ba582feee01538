//! A binary BVH over boxes (the scene's objects), built by the shared binned-SAH builder
//! (depth-capped) and flattened depth-first into 32-byte nodes. It knows only boxes; callers
//! intersect their primitives in a leaf closure.

use glam::{Vec3, Vec3A};

use super::sah::{self, MAX_DEPTH, PrimRef};
use crate::geometry::Aabb;

/// Leaf when `count > 0` (primitives `first..first+count` of `Bvh::indices`); otherwise an
/// interior node whose left child is the next node and right child is `right_or_first`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct BvhNode {
    pub min: [f32; 3],
    pub right_or_first: u32,
    pub max: [f32; 3],
    pub count: u32,
}

impl BvhNode {
    /// Slab test: the entry distance if the ray meets the box within [t_min, t_max].
    #[inline(always)]
    fn hit(&self, o: Vec3A, inv: Vec3A, t_min: f32, t_max: f32) -> Option<f32> {
        let (lo, hi) = (Vec3A::from(self.min), Vec3A::from(self.max));
        let (near, far) = super::slab::span(lo, hi, o, inv, t_min, t_max);
        (near <= far).then_some(near)
    }

    pub fn bounds(&self) -> Aabb {
        Aabb::new(Vec3::from(self.min), Vec3::from(self.max))
    }
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct Bvh {
    pub nodes: Vec<BvhNode>,
    /// Primitive ids in leaf order.
    pub indices: Vec<u32>,
}

impl Bvh {
    /// Builds over `bounds` (one box per primitive; id = position in the slice).
    pub fn build(bounds: &[Aabb]) -> Bvh {
        let prims = bounds
            .iter()
            .enumerate()
            .map(|(i, b)| PrimRef::new(*b, i as u32))
            .collect();
        match Self::build_from(prims) {
            Ok(bvh) => bvh,
            Err(e) => crate::memory::fail_as_infallible(e),
        }
    }

    /// About what a build over `n` primitives takes at its peak: the primitive references,
    /// the builder's tree (up to 2n − 1 nodes, each its own allocation) and the flat nodes.
    pub fn build_bytes(n: usize) -> u64 {
        let per_prim = std::mem::size_of::<PrimRef>()
            + 2 * (std::mem::size_of::<sah::Node>() + 16)
            + 2 * std::mem::size_of::<BvhNode>()
            + std::mem::size_of::<u32>();
        (n as u64).saturating_mul(per_prim as u64)
    }

    /// [`Bvh::build`], or an error where it would not fit in memory: checked as a whole
    /// before starting, since the builder's tree is millions of small allocations.
    pub fn try_build(bounds: &[Aabb]) -> Result<Bvh, crate::memory::OutOfMemory> {
        // The builder allocates on every thread.
        crate::memory::check_available_threaded(
            Self::build_bytes(bounds.len()),
            "the scene's BVH",
        )?;
        let mut prims = crate::memory::try_with_capacity(bounds.len(), "the scene's BVH")?;
        prims.extend(
            bounds
                .iter()
                .enumerate()
                .map(|(i, b)| PrimRef::new(*b, i as u32)),
        );
        Self::build_from(prims)
    }

    fn build_from(mut prims: Vec<PrimRef>) -> Result<Bvh, crate::memory::OutOfMemory> {
        let Some(root) = sah::build(&mut prims, sah::LeafBlock(1)) else {
            return Ok(Bvh::default());
        };
        // A binary tree over n leaves has 2n − 1 nodes: no doubling slack.
        let mut nodes = crate::memory::try_with_capacity(2 * prims.len() - 1, "the scene's BVH")?;
        flatten(&root, &mut nodes);
        let mut indices = crate::memory::try_with_capacity(prims.len(), "the scene's BVH")?;
        indices.extend(prims.iter().map(|p| p.id));
        Ok(Bvh { nodes, indices })
    }

    pub fn bounds(&self) -> Aabb {
        self.nodes
            .first()
            .map(|n| n.bounds())
            .unwrap_or(Aabb::EMPTY)
    }

    /// Closest-hit traversal, near child first. `leaf(prim_id, t_max)` returns a closer t if
    /// that primitive is hit before `t_max`.
    #[inline]
    pub fn traverse(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_min: f32,
        mut t_max: f32,
        mut leaf: impl FnMut(u32, f32) -> Option<f32>,
    ) -> f32 {
        if self.nodes.is_empty() {
            return t_max;
        }
        // Packed (Vec3A) arithmetic: every ray pays for this on its critical path.
        let (o, inv) = (Vec3A::from(origin), Vec3A::from(dir).recip());
        let root = &self.nodes[0];
        if root.is_leaf() {
            // A scene of a few objects: no stack to set up.
            if root.hit(o, inv, t_min, t_max).is_some() {
                let first = root.right_or_first as usize;
                for &p in self
                    .indices
                    .get(first..first + root.count as usize)
                    .unwrap_or(&[])
                {
                    if let Some(t) = leaf(p, t_max) {
                        t_max = t;
                    }
                }
            }
            return t_max;
        }
        // One entry per level at most, and the builder keeps leaves above depth MAX_DEPTH.
        // Exactly 64 entries: an odd size turns the zeroing into a memset call on every ray
        // (`docs/perf.md`).
        let mut stack = [0u32; MAX_DEPTH];
        let mut sp = 0usize;
        let mut idx = 0u32;
        if self.nodes[0].hit(o, inv, t_min, t_max).is_none() {
            return t_max;
        }
        loop {
            let node = &self.nodes[idx as usize];
            if node.is_leaf() {
                let first = node.right_or_first as usize;
                for &p in &self.indices[first..first + node.count as usize] {
                    if let Some(t) = leaf(p, t_max) {
                        t_max = t;
                    }
                }
            } else {
                let l = idx + 1;
                let r = node.right_or_first;
                let tl = self.nodes[l as usize].hit(o, inv, t_min, t_max);
                let tr = self.nodes[r as usize].hit(o, inv, t_min, t_max);
                match (tl, tr) {
                    (Some(a), Some(b)) => {
                        let (near, far) = if a <= b { (l, r) } else { (r, l) };
                        if sp < stack.len() {
                            stack[sp] = far;
                            sp += 1;
                        }
                        idx = near;
                        continue;
                    }
                    (Some(_), None) => {
                        idx = l;
                        continue;
                    }
                    (None, Some(_)) => {
                        idx = r;
                        continue;
                    }
                    (None, None) => {}
                }
            }
            // Pop, skipping nodes the shrinking t_max has ruled out.
            loop {
                if sp == 0 {
                    return t_max;
                }
                sp -= 1;
                let n = stack[sp];
                if self.nodes[n as usize].hit(o, inv, t_min, t_max).is_some() {
                    idx = n;
                    break;
                }
            }
        }
    }

    /// Any-hit traversal: true as soon as `leaf(prim_id)` says true. It enters exactly the
    /// boxes `traverse` enters while its t_max has not shrunk (the same slab test against the
    /// same t_max), so it reaches every leaf `traverse` reaches before its first hit, and no
    /// other: a leaf test that answers "is there a hit before t_max" gives `traverse`'s
    /// "was anything hit" bit for bit.
    #[inline]
    pub fn any(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_min: f32,
        t_max: f32,
        mut leaf: impl FnMut(u32) -> bool,
    ) -> bool {
        let Some(root) = self.nodes.first() else {
            return false;
        };
        let (o, inv) = (Vec3A::from(origin), Vec3A::from(dir).recip());
        if root.hit(o, inv, t_min, t_max).is_none() {
            return false;
        }
        let mut stack = [0u32; MAX_DEPTH];
        let mut sp = 0usize;
        let mut idx = 0u32;
        loop {
            let node = &self.nodes[idx as usize];
            if node.is_leaf() {
                let first = node.right_or_first as usize;
                let prims = self.indices.get(first..first + node.count as usize);
                if prims.unwrap_or(&[]).iter().any(|&p| leaf(p)) {
                    return true;
                }
            } else {
                // Near child first, as `traverse`: the nearer objects are likelier blockers.
                let (l, r) = (idx + 1, node.right_or_first);
                let tl = self.nodes[l as usize].hit(o, inv, t_min, t_max);
                let tr = self.nodes[r as usize].hit(o, inv, t_min, t_max);
                let next = match (tl, tr) {
                    (Some(a), Some(b)) => {
                        let (near, far) = if a <= b { (l, r) } else { (r, l) };
                        // Dropped when full, as in `traverse` (the depth cap keeps it from
                        // filling).
                        if sp < stack.len() {
                            stack[sp] = far;
                            sp += 1;
                        }
                        Some(near)
                    }
                    (Some(_), None) => Some(l),
                    (None, Some(_)) => Some(r),
                    (None, None) => None,
                };
                if let Some(n) = next {
                    idx = n;
                    continue;
                }
            }
            // No re-test on pop: t_max never shrinks, so a pushed node still passes.
            if sp == 0 {
                return false;
            }
            sp -= 1;
            idx = stack[sp];
        }
    }

    /// `traverse` for eight rays together (lanes set in `active`), sharing one stack: each
    /// node's box is tested against every lane still in, near child first by the nearest
    /// lane's entry. `leaf(prim_id, lanes, t)` gets the lanes whose box test passed and the
    /// lanes' current closest t, which it lowers for those it hits; a node is entered, or
    /// left on the stack, only while some lane still meets it before its t. Every lane
    /// reaches every leaf its own `traverse` could reach with the same t, so a leaf test that
    /// does not depend on the order of leaves gives the same answer.
    pub fn traverse8(
        &self,
        origin: &[Vec3A; 8],
        dir: &[Vec3A; 8],
        active: u8,
        t_min: f32,
        t: &mut [f32; 8],
        mut leaf: impl FnMut(u32, u8, &mut [f32; 8]),
    ) {
        if self.nodes.is_empty() || active == 0 {
            return;
        }
        let inv: [Vec3A; 8] = std::array::from_fn(|k| dir[k].recip());
        // The lanes meeting node `n` before their t, and the nearest entry among them.
        let test = |n: u32, lanes: u8, t: &[f32; 8]| -> (u8, f32) {
            let node = &self.nodes[n as usize];
            let (lo, hi) = (Vec3A::from(node.min), Vec3A::from(node.max));
            let mut hit = 0u8;
            let mut nearest = f32::INFINITY;
            for k in 0..8 {
                if lanes & (1 << k) != 0 {
                    let (near, far) = super::slab::span(lo, hi, origin[k], inv[k], t_min, t[k]);
                    if near <= far {
                        hit |= 1 << k;
                        nearest = nearest.min(near);
                    }
                }
            }
            (hit, nearest)
        };
        let mut stack = [(0u32, 0u8); MAX_DEPTH];
        let mut sp = 0usize;
        let (mut lanes, _) = test(0, active, t);
        let mut idx = 0u32;
        loop {
            if lanes != 0 {
                let node = &self.nodes[idx as usize];
                if node.is_leaf() {
                    let first = node.right_or_first as usize;
                    for &p in self
                        .indices
                        .get(first..first + node.count as usize)
                        .unwrap_or(&[])
                    {
                        leaf(p, lanes, t);
                    }
                } else {
                    let (l, r) = (idx + 1, node.right_or_first);
                    let (ml, nl) = test(l, lanes, t);
                    let (mr, nr) = test(r, lanes, t);
                    let ((near, mn), (far, mf)) = if nl <= nr {
                        ((l, ml), (r, mr))
                    } else {
                        ((r, mr), (l, ml))
                    };
                    if mn != 0 && mf != 0 && sp < stack.len() {
                        stack[sp] = (far, mf);
                        sp += 1;
                    }
                    (idx, lanes) = if mn != 0 { (near, mn) } else { (far, mf) };
                    continue;
                }
            }
            // Pop, keeping only the lanes that still meet the node with their shrunk t.
            loop {
                if sp == 0 {
                    return;
                }
                sp -= 1;
                let (n, m) = stack[sp];
                let (still, _) = test(n, m, t);
                if still != 0 {
                    (idx, lanes) = (n, still);
                    break;
                }
            }
        }
    }

    /// Checks the structural invariants: every primitive in exactly one leaf, no node deeper
    /// than the traversal stack, children inside their parents' bounds, leaves holding the
    /// boxes of their primitives. For tests.
    pub fn check_invariants(&self, bounds: &[Aabb]) -> Result<(), super::InvariantViolation> {
        self.invariants(bounds).map_err(super::InvariantViolation)
    }

    fn invariants(&self, bounds: &[Aabb]) -> Result<(), String> {
        if bounds.is_empty() {
            return if self.nodes.is_empty() {
                Ok(())
            } else {
                Err("nodes for no primitives".into())
            };
        }
        let mut seen = vec![0u32; bounds.len()];
        let mut stack = vec![(0usize, 0usize)];
        while let Some((i, depth)) = stack.pop() {
            if depth >= MAX_DEPTH {
                return Err(format!(
                    "node {i} at depth {depth}: the traversal stack cannot hold it"
                ));
            }
            let n = self.nodes.get(i).ok_or(format!("node {i} out of range"))?;
            let nb = n.bounds();
            if n.is_leaf() {
                let first = n.right_or_first as usize;
                let ids = self
                    .indices
                    .get(first..first + n.count as usize)
                    .ok_or(format!("leaf {i} range out of bounds"))?;
                for &p in ids {
                    let b = bounds
                        .get(p as usize)
                        .ok_or(format!("bad primitive id {p}"))?;
                    if !nb.contains(b) {
                        return Err(format!("leaf {i} does not contain primitive {p}"));
                    }
                    seen[p as usize] += 1;
                }
            } else {
                for c in [i + 1, n.right_or_first as usize] {
                    let cn = self.nodes.get(c).ok_or(format!("child {c} out of range"))?;
                    if !nb.contains(&cn.bounds()) {
                        return Err(format!("child {c} escapes parent {i}"));
                    }
                    stack.push((c, depth + 1));
                }
            }
        }
        if let Some(p) = seen.iter().position(|&s| s != 1) {
            return Err(format!("primitive {p} appears in {} leaves", seen[p]));
        }
        Ok(())
    }
}

fn flatten(root: &sah::Node, out: &mut Vec<BvhNode>) {
    // Iterative, so the (bounded but deep) tree never recurses here.
    let mut stack: Vec<(&sah::Node, Option<usize>)> = vec![(root, None)];
    while let Some((node, patch_parent)) = stack.pop() {
        let me = out.len();
        if let Some(p) = patch_parent {
            out[p].right_or_first = me as u32;
        }
        let b = node.bounds();
        match node {
            sah::Node::Leaf { first, count, .. } => out.push(BvhNode {
                min: b.min.into(),
                right_or_first: *first,
                max: b.max.into(),
                count: *count,
            }),
            sah::Node::Inner { children, .. } => {
                out.push(BvhNode {
                    min: b.min.into(),
                    right_or_first: 0,
                    max: b.max.into(),
                    count: 0,
                });
                // Right is flattened after the whole left subtree and patches our pointer.
                stack.push((&children[1], Some(me)));
                stack.push((&children[0], None));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn boxes(n: usize) -> Vec<Aabb> {
        // Deterministic pseudo-random boxes.
        let mut s = 0x1234_5678u32;
        let mut rnd = || {
            s ^= s << 13;
            s ^= s >> 17;
            s ^= s << 5;
            (s as f32 / u32::MAX as f32) * 10.0
        };
        (0..n)
            .map(|_| {
                let c = Vec3::new(rnd(), rnd(), rnd());
                Aabb::new(c, c + Vec3::splat(0.1 + rnd() * 0.05))
            })
            .collect()
    }

    #[test]
    fn invariants_hold_for_various_sizes() {
        for n in [0, 1, 2, 5, 17, 1000, 10_000] {
            let b = boxes(n);
            let bvh = Bvh::build(&b);
            bvh.check_invariants(&b)
                .unwrap_or_else(|e| panic!("n={n}: {e}"));
        }
    }

    #[test]
    fn exponentially_spaced_boxes_stay_within_the_stack() {
        // Boxes at 2^-100 .. 2^119: SAH peels a couple off per level, far deeper than the
        // traversal stack unless the builder caps the depth. Every box must stay reachable.
        let b: Vec<Aabb> = (-100..120)
            .map(|i| {
                let x = 2f32.powi(i);
                Aabb::new(Vec3::new(x, 0.0, 0.0), Vec3::new(x * 1.01, 1.0, 1.0))
            })
            .collect();
        let bvh = Bvh::build(&b);
        bvh.check_invariants(&b).expect("invariants");
        let mut seen = Vec::new();
        bvh.traverse(
            Vec3::new(-1.0, 0.5, 0.5),
            Vec3::X,
            0.0,
            f32::INFINITY,
            |p, _| {
                seen.push(p);
                None
            },
        );
        seen.sort_unstable();
        assert_eq!(seen, (0..b.len() as u32).collect::<Vec<u32>>());
    }

    #[test]
    fn traverse8_gives_each_lane_what_traverse_gives_it() {
        // The boxes themselves as primitives, hit at their entry distance: each lane's final t
        // must be its single traversal's, whatever subset of lanes is active.
        let b = boxes(3000);
        let bvh = Bvh::build(&b);
        let entry = |p: u32, o: Vec3A, d: Vec3A, t_max: f32| {
            let (near, far) = crate::accel::slab::span(
                b[p as usize].min.into(),
                b[p as usize].max.into(),
                o,
                d.recip(),
                1e-3,
                t_max,
            );
            (near <= far && near < t_max).then_some(near)
        };
        let mut s = 0x2545_f491u32;
        let mut rnd = move || {
            s ^= s << 13;
            s ^= s >> 17;
            s ^= s << 5;
            s as f32 / u32::MAX as f32
        };
        let mut hits = 0;
        for packet in 0..300 {
            // Coherent packets from one eye, and scattered ones.
            let eye = Vec3A::new(rnd() * 10.0, rnd() * 10.0, -5.0);
            let spread = if packet % 3 == 0 { 2.0 } else { 0.05 };
            let base = Vec3A::new(rnd() - 0.5, rnd() - 0.5, 1.0);
            let o = [eye; 8];
            let d: [Vec3A; 8] = std::array::from_fn(|_| {
                base + Vec3A::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5) * spread
            });
            let active = [0xffu8, 0x5a, 0x81, 0x01][packet % 4];
            let mut t = [f32::INFINITY; 8];
            bvh.traverse8(&o, &d, active, 1e-3, &mut t, |p, lanes, t| {
                for k in 0..8 {
                    if lanes & (1 << k) != 0 {
                        assert!(active & (1 << k) != 0, "inactive lane {k} offered a leaf");
                        if let Some(h) = entry(p, o[k], d[k], t[k]) {
                            t[k] = h;
                        }
                    }
                }
            });
            for k in 0..8 {
                let want = if active & (1 << k) != 0 {
                    bvh.traverse(o[k].into(), d[k].into(), 1e-3, f32::INFINITY, |p, t_max| {
                        entry(p, o[k], d[k], t_max)
                    })
                } else {
                    f32::INFINITY
                };
                assert_eq!(t[k].to_bits(), want.to_bits(), "packet {packet} lane {k}");
                hits += want.is_finite() as u32;
            }
        }
        assert!(hits > 300, "{hits} hits");
    }

    #[test]
    fn any_finds_a_hit_exactly_when_traverse_does() {
        // The boxes as primitives, hit at their entry distance: for many rays and t ranges
        // (cut at the closest hit and one ulp either side), `any` says whether `traverse`
        // found anything, and visits no primitive `traverse` would not.
        let b = boxes(3000);
        let bvh = Bvh::build(&b);
        let entry = |p: u32, o: Vec3, d: Vec3, t_min: f32, t_max: f32| {
            let (near, far) = crate::accel::slab::span(
                b[p as usize].min.into(),
                b[p as usize].max.into(),
                o.into(),
                Vec3A::from(d).recip(),
                t_min,
                t_max,
            );
            (near <= far && near < t_max).then_some(near)
        };
        let mut s = 0x9e37_79b9u32;
        let mut rnd = move || {
            s ^= s << 13;
            s ^= s >> 17;
            s ^= s << 5;
            s as f32 / u32::MAX as f32
        };
        let (mut compared, mut hits) = (0, 0);
        for _ in 0..2000 {
            let o = Vec3::new(rnd() * 12.0 - 1.0, rnd() * 12.0 - 1.0, rnd() * 12.0 - 1.0);
            let d = Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5);
            let closest = |t_min: f32, t_max: f32| {
                let t = bvh.traverse(o, d, t_min, t_max, |p, t| entry(p, o, d, t_min, t));
                (t < t_max).then_some(t)
            };
            let first = closest(1e-3, f32::INFINITY);
            let mut ranges = vec![(1e-3, f32::INFINITY)];
            if let Some(t) = first {
                ranges.extend([(1e-3, t), (1e-3, t.next_up()), (1e-3, t.next_down())]);
                ranges.extend([(t, f32::INFINITY), (1e-3, t * 0.5)]);
            }
            for (lo, hi) in ranges {
                let want = closest(lo, hi).is_some();
                let got = bvh.any(o, d, lo, hi, |p| entry(p, o, d, lo, hi).is_some());
                assert_eq!(got, want, "ray {o} {d} ({lo}, {hi})");
                compared += 1;
                hits += want as u32;
            }
        }
        assert!(hits > 1000 && hits < compared, "{hits} of {compared}");
    }

    #[test]
    fn identical_boxes_still_split() {
        let b = vec![Aabb::new(Vec3::ZERO, Vec3::ONE); 100];
        let bvh = Bvh::build(&b);
        bvh.check_invariants(&b).expect("invariants");
    }
}
