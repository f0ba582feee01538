//! A BVH over a mesh's triangles: binned SAH on three axes, built in parallel, collapsed into
//! 8-wide nodes, with the triangles stored in leaf order as (v0, e1, e2) so a leaf test reads
//! contiguous memory and skips two subtractions per triangle.

use glam::{Vec3, Vec3A, Vec4};
use rayon::prelude::*;

use super::sah::{self, PrimRef};
use super::wide::{self, Child, Node8, RayStack, WIDTH};
use crate::geometry::{Aabb, Ray, moller_trumbore};

#[derive(Clone, Copy, Debug, PartialEq)]
struct Tri {
    v0: Vec3,
    e1: Vec3,
    e2: Vec3,
}

impl Tri {
    /// The ray parameter of a hit, if any (two-sided, not range-checked). Without the
    /// infinite-determinant test, as the AVX leaf test, which must agree bit for bit.
    #[inline(always)]
    fn hit(&self, o: Vec3, d: Vec3) -> Option<f32> {
        moller_trumbore::<false>(o, d, self.v0, self.e1, self.e2).map(|(t, _, _)| t)
    }
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleBvh {
    nodes: Vec<Node8>,
    /// Triangles in leaf order, one array per component (v0.x, v0.y, v0.z, e1.x, ... e2.z,
    /// each `stride` = triangle count long), so a leaf's up to eight triangles load as one
    /// 8-lane vector per component; lanes past the leaf (the next component's values, or 7
    /// zeros at the very end) are masked off. `ids[i]` is the mesh's index of triangle i.
    soa: Vec<f32>,
    stride: usize,
    ids: Vec<u32>,
    /// The root's box, tested alone before the traversal sets up: most rays of a scene's
    /// frame miss the mesh, and one box is far cheaper than the root's eight.
    root_lo: Vec3A,
    root_hi: Vec3A,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    pub t: f32,
    /// Index of the triangle in the mesh's own order.
    pub triangle: u32,
}

/// Per-ray constants for the 8-wide slab test.
///
/// 16-byte `Vec3A`s, not `Vec3`s: the tests below broadcast single components, and with
/// 12-byte fields LLVM loaded them as 16 bytes spanning two earlier stores, a failed store
/// forward on every ray (perf put ~20% of the Stanford bunny's traversal samples on the two
/// loads). With `Vec3A`: Stanford bunny 11.5 -> 12.1 Mrays/s, dragon 10.4 -> 10.8, cube 29 ->
/// 45 (1 thread, medians of 7, alternating runs).
struct RayPre {
    o: Vec3A,
    d: Vec3A,
    inv: Vec3A,
    /// Per axis: does the ray run toward -axis (so it enters through the max plane)?
    neg: [bool; 3],
}

impl RayPre {
    /// Whether the ray meets the box [lo, hi] within [t_min, t_max], widened as `slab8`
    /// widens so it never culls a box the traversal would enter.
    #[inline(always)]
    fn enters(&self, lo: Vec3A, hi: Vec3A, t_min: f32, t_max: f32) -> bool {
        let (o, inv) = (self.o, self.inv);
        let (t0, t1) = ((lo - o) * inv, (hi - o) * inv);
        // maxps/minps return the second operand for a NaN lane (0 * inf): that axis drops out.
        let near = t0.min(t1).max(Vec3A::splat(t_min)).max_element();
        let far = t0.max(t1).min(Vec3A::splat(t_max)).min_element();
        near <= far * 1.000_000_4
    }

    #[inline(always)]
    fn new(o: Vec3A, d: Vec3A) -> Self {
        // One packed division rather than three scalar ones on every ray's critical path.
        let inv = d.recip();
        RayPre {
            o,
            d,
            inv,
            neg: [inv.x < 0.0, inv.y < 0.0, inv.z < 0.0],
        }
    }

    /// Entry distances of all eight slots into `tn`; bit i of the result is set when slot i
    /// is entered within [t_min, t_max].
    #[inline(always)]
    fn slab8(&self, n: &Node8, t_min: f32, t_max: f32, tn: &mut [f32; WIDTH]) -> u32 {
        let pick = |a: usize| {
            if self.neg[a] {
                (&n.hi[a], &n.lo[a])
            } else {
                (&n.lo[a], &n.hi[a])
            }
        };
        let (nx, fx) = pick(0);
        let (ny, fy) = pick(1);
        let (nz, fz) = pick(2);
        let (o, inv) = (self.o, self.inv);
        let (ox, oy, oz) = (Vec4::splat(o.x), Vec4::splat(o.y), Vec4::splat(o.z));
        let (ix, iy, iz) = (Vec4::splat(inv.x), Vec4::splat(inv.y), Vec4::splat(inv.z));
        let (t0, t1) = (Vec4::splat(t_min), Vec4::splat(t_max));
        let mut mask = 0u32;
        let mut near = [Vec4::ZERO; 2];
        for h in 0..2 {
            // maxps/minps return the second operand when the first is NaN (0 * inf on an
            // axis-parallel ray), so that axis drops out instead of poisoning the result.
            let a = ((nx[h] - ox) * ix)
                .max((ny[h] - oy) * iy)
                .max(((nz[h] - oz) * iz).max(t0));
            let b = ((fx[h] - ox) * ix)
                .min((fy[h] - oy) * iy)
                .min(((fz[h] - oz) * iz).min(t1));
            // Widened by a few ulps so rounding never loses a box the ray grazes.
            mask |= a.cmple(b * 1.000_000_4).bitmask() << (4 * h);
            near[h] = a;
        }
        let (lo, hi) = tn.split_at_mut(4);
        lo.copy_from_slice(&near[0].to_array());
        hi.copy_from_slice(&near[1].to_array());
        mask
    }
}

/// The closest-hit traversal, expanded once per slab test so each copy is compiled for the
/// instruction set its function enables.
macro_rules! closest_hit {
    ($self:ident, $o:expr, $d:expr, $t_min:expr, $t_max:expr, $slab:expr, $leaf:expr) => {{
        let (t_min, t_max) = ($t_min, $t_max);
        if $self.nodes.is_empty() {
            return None;
        }
        let r = RayPre::new($o, $d);
        if !r.enters($self.root_lo, $self.root_hi, t_min, t_max) {
            return None;
        }
        let mut t_best = t_max;
        let mut best = usize::MAX;
        let mut stack = RayStack::new();
        let mut tn = [0.0f32; WIDTH];
        let mut cur: Child = 0;
        loop {
            if wide::is_leaf(cur) {
                let (first, count) = wide::leaf_range(cur);
                if let Some((t, k)) = $leaf($self, &r, first, count, t_min, t_best) {
                    t_best = t;
                    best = k;
                }
            } else {
                let n = &$self.nodes[cur as usize];
                let mask = $slab(&r, n, t_min, t_best, &mut tn);
                if mask != 0 {
                    let i = mask.trailing_zeros() as usize;
                    let rest = mask & (mask - 1);
                    if rest == 0 {
                        cur = n.child[i];
                        continue;
                    }
                    if rest & (rest - 1) == 0 {
                        // Two children, the common case below the top: no sort needed.
                        let j = rest.trailing_zeros() as usize;
                        let (near, far) = if tn[i] <= tn[j] { (i, j) } else { (j, i) };
                        stack.push((n.child[far], tn[far]));
                        cur = n.child[near];
                        continue;
                    }
                    // Several children: push them all, nearest on top, and take the nearest.
                    let mut m = mask;
                    let mut k = 0;
                    while m != 0 {
                        let j = m.trailing_zeros() as usize;
                        m &= m - 1;
                        stack.push((n.child[j], tn[j]));
                        k += 1;
                    }
                    stack.sort_top(k);
                    if let Some((c, _)) = stack.pop() {
                        cur = c;
                        continue;
                    }
                }
            }
            // Pop the nearest child not ruled out by a closer hit found since it was pushed.
            loop {
                match stack.pop() {
                    None => {
                        return (best != usize::MAX).then(|| TriangleHit {
                            t: t_best,
                            triangle: $self.ids[best],
                        });
                    }
                    Some((c, t)) if t <= t_best => {
                        cur = c;
                        break;
                    }
                    Some(_) => {}
                }
            }
        }
    }};
}

impl TriangleBvh {
    /// Builds over the mesh. Vertex indices out of range read as the origin (the loaders
    /// reject them); triangles beyond 2^28 are left out.
    pub fn build(positions: &[Vec3], triangles: &[[u32; 3]]) -> TriangleBvh {
        // Leaves sized for the leaf test this CPU runs: eight triangles cost one AVX test,
        // but eight scalar tests where there is no AVX.
        let block = if has_avx() { WIDTH as u32 } else { 1 };
        Self::build_with(positions, triangles, sah::LeafBlock(block))
    }

    fn build_with(
        positions: &[Vec3],
        triangles: &[[u32; 3]],
        block: sah::LeafBlock,
    ) -> TriangleBvh {
        let triangles = &triangles[..triangles.len().min(wide::MAX_TRIANGLES)];
        let vert = |i: u32| positions.get(i as usize).copied().unwrap_or(Vec3::ZERO);
        let mut prims: Vec<PrimRef> = triangles
            .par_iter()
            .enumerate()
            .with_min_len(4096)
            .map(|(i, t)| {
                let (a, b, c) = (vert(t[0]), vert(t[1]), vert(t[2]));
                PrimRef::new(Aabb::new(a.min(b).min(c), a.max(b).max(c)), i as u32)
            })
            .collect();
        let Some(root) = sah::build(&mut prims, block) else {
            return TriangleBvh::default();
        };
        let nodes = wide::collapse(&root);
        // The temporary tree is freed on another thread while the triangles are copied.
        let ((tris, ids), ()): ((Vec<Tri>, Vec<u32>), ()) = rayon::join(
            || {
                prims
                    .par_iter()
                    .with_min_len(4096)
                    .map(|p| {
                        let t = triangles[p.id as usize];
                        let (a, b, c) = (vert(t[0]), vert(t[1]), vert(t[2]));
                        (
                            Tri {
                                v0: a,
                                e1: b - a,
                                e2: c - a,
                            },
                            p.id,
                        )
                    })
                    .unzip()
            },
            move || drop(root),
        );
        let root = nodes.first().map_or(Aabb::EMPTY, |r| {
            (0..WIDTH)
                .filter(|&i| !r.slot_is_empty(i))
                .fold(Aabb::EMPTY, |b, i| b.union(r.slot_bounds(i)))
        });
        let stride = tris.len();
        let mut soa = vec![0.0f32; 9 * stride + WIDTH - 1];
        for (i, t) in tris.iter().enumerate() {
            for (k, v) in [t.v0, t.e1, t.e2].iter().enumerate() {
                soa[(3 * k) * stride + i] = v.x;
                soa[(3 * k + 1) * stride + i] = v.y;
                soa[(3 * k + 2) * stride + i] = v.z;
            }
        }
        TriangleBvh {
            nodes,
            soa,
            stride,
            ids,
            root_lo: root.min.into(),
            root_hi: root.max.into(),
        }
    }

    pub fn bounds(&self) -> Aabb {
        let Some(root) = self.nodes.first() else {
            return Aabb::EMPTY;
        };
        (0..WIDTH)
            .filter(|&i| !root.slot_is_empty(i))
            .fold(Aabb::EMPTY, |b, i| b.union(root.slot_bounds(i)))
    }

    /// Bytes held by the nodes and the triangle copies.
    pub fn memory_bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<Node8>() + self.soa.len() * 4 + self.ids.len() * 4
    }

    /// Shape of the tree, for `tracelab bench`: nodes, mean children per node, leaves and
    /// mean triangles per leaf.
    pub fn shape(&self) -> String {
        let (mut slots, mut leaves) = (0usize, 0usize);
        for n in &self.nodes {
            for s in 0..WIDTH {
                if !n.slot_is_empty(s) {
                    slots += 1;
                    leaves += wide::is_leaf(n.child[s]) as usize;
                }
            }
        }
        let per = |a: usize, b: usize| a as f64 / b.max(1) as f64;
        format!(
            "{} nodes, {:.2} children/node, {} leaves, {:.2} triangles/leaf",
            self.nodes.len(),
            per(slots, self.nodes.len()),
            leaves,
            per(self.ids.len(), leaves)
        )
    }

    /// Checks the BVH invariants against the mesh it was built from (for tests): every
    /// triangle in exactly one leaf, every leaf box around its triangles, every node's boxes
    /// inside the box its parent holds for it, each node reached once, depth within the cap.
    pub fn check_invariants(
        &self,
        positions: &[Vec3],
        triangles: &[[u32; 3]],
    ) -> Result<(), String> {
        let vert = |i: u32| positions.get(i as usize).copied().unwrap_or(Vec3::ZERO);
        let tri_box = |t: &[u32; 3]| Aabb::from_points(&[vert(t[0]), vert(t[1]), vert(t[2])]);
        if triangles.is_empty() {
            return if self.nodes.is_empty() && self.ids.is_empty() {
                Ok(())
            } else {
                Err("nodes or triangles for an empty mesh".into())
            };
        }
        if self.stride != triangles.len()
            || self.soa.len() != 9 * self.stride + WIDTH - 1
            || self.ids.len() != triangles.len()
        {
            return Err(format!(
                "{} triangles stored for {}",
                self.ids.len(),
                triangles.len()
            ));
        }
        let mut seen = vec![0u32; triangles.len()];
        let mut reached = vec![0u32; self.nodes.len()];
        // (node, the box its parent holds for it, depth)
        let mut stack = vec![(0usize, None::<Aabb>, 0usize)];
        while let Some((i, parent_box, depth)) = stack.pop() {
            let n = self.nodes.get(i).ok_or(format!("node {i} out of range"))?;
            reached[i] += 1;
            if depth > sah::MAX_DEPTH {
                return Err(format!("node {i} at depth {depth}, past the cap"));
            }
            let mut used = 0;
            for s in 0..WIDTH {
                if n.slot_is_empty(s) {
                    continue;
                }
                used += 1;
                let b = n.slot_bounds(s);
                if let Some(pb) = parent_box
                    && !pb.contains(&b)
                {
                    return Err(format!("node {i} slot {s} escapes its parent's box"));
                }
                let c = n.child[s];
                if wide::is_leaf(c) {
                    let (first, count) = wide::leaf_range(c);
                    let ids = self
                        .ids
                        .get(first..first + count)
                        .ok_or(format!("leaf range {first}+{count} out of bounds"))?;
                    for &id in ids {
                        let t = triangles
                            .get(id as usize)
                            .ok_or(format!("bad triangle id {id}"))?;
                        if !b.contains(&tri_box(t)) {
                            return Err(format!(
                                "leaf box in node {i} does not contain triangle {id}"
                            ));
                        }
                        seen[id as usize] += 1;
                    }
                } else {
                    stack.push((c as usize, Some(b), depth + 1));
                }
            }
            if used == 0 {
                return Err(format!("node {i} has no children"));
            }
        }
        if let Some(p) = seen.iter().position(|&s| s != 1) {
            return Err(format!("triangle {p} appears in {} leaves", seen[p]));
        }
        if let Some(p) = reached.iter().position(|&r| r != 1) {
            return Err(format!("node {p} reached {} times", reached[p]));
        }
        // The stored copies must be the mesh's triangles, in leaf order.
        for (k, &id) in self.ids.iter().enumerate() {
            let tri = self.tri(k);
            let t = triangles[id as usize];
            if tri.v0 != vert(t[0]) || tri.v0 + tri.e1 != vert(t[0]) + (vert(t[1]) - vert(t[0])) {
                return Err(format!("stored triangle {k} is not mesh triangle {id}"));
            }
        }
        Ok(())
    }

    /// Every hit with t in (t_min, t_max), in no particular order, appended to `out`. CSG
    /// needs all crossings of a closed mesh along a ray, not just the nearest.
    pub fn intersect_all(&self, ray: &Ray, t_min: f32, t_max: f32, out: &mut Vec<TriangleHit>) {
        if self.nodes.is_empty() {
            return;
        }
        if !finite_ray(ray.origin.into(), ray.direction.into()) {
            return; // as in `closest_hit`
        }
        let r = RayPre::new(ray.origin.into(), ray.direction.into());
        let mut stack = RayStack::new();
        let mut tn = [0.0f32; WIDTH];
        stack.push((0, t_min));
        while let Some((c, _)) = stack.pop() {
            if wide::is_leaf(c) {
                let (first, count) = wide::leaf_range(c);
                for k in first..first + count {
                    if let Some(t) = self.tri(k).hit(r.o.into(), r.d.into())
                        && t > t_min
                        && t < t_max
                    {
                        out.push(TriangleHit {
                            t,
                            triangle: self.ids[k],
                        });
                    }
                }
                continue;
            }
            let n = &self.nodes[c as usize];
            let mut mask = r.slab8(n, t_min, t_max, &mut tn);
            while mask != 0 {
                let i = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                stack.push((n.child[i], tn[i]));
            }
        }
    }

    /// Closest hit in (t_min, t_max). Two-sided Möller–Trumbore.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_min: f32, t_max: f32) -> Option<TriangleHit> {
        self.closest_hit(ray.origin.into(), ray.direction.into(), t_min, t_max)
    }

    /// `intersect` for a ray given as 16-byte vectors, the form the traversal keeps. Callers
    /// that build the ray just before (the renderer's object-space transform) should use it:
    /// loading a `Ray`'s 12-byte fields as vectors right after they were stored defeated the
    /// store forward (Stanford bunny 12.1 -> 12.6 Mrays/s, medians of 7, same minute).
    #[inline]
    pub fn closest_hit(&self, o: Vec3A, d: Vec3A, t_min: f32, t_max: f32) -> Option<TriangleHit> {
        // A NaN or infinite ray (an overflowing object-space transform) makes every slab
        // test NaN, which would enter the empty slots, whose child is the root: endless.
        if !finite_ray(o, d) {
            return None;
        }
        #[cfg(target_arch = "x86_64")]
        if has_avx() {
            #[allow(unsafe_code)]
            // SAFETY: the CPU has AVX, checked just above (std caches the answer).
            return unsafe { self.intersect_avx(o, d, t_min, t_max) };
        }
        self.intersect_portable(o, d, t_min, t_max)
    }

    /// Closest hits of a packet of eight rays (`o[i]`, `d[i]`) in (t_min, t_max[i]), for the
    /// rays whose bit is set in `active`; a ray that hits has its `t_max` lowered to the hit.
    /// Each ray gets the t `closest_hit` gives it, bit for bit (the triangle may differ only
    /// where two are hit at the very same t). Made for coherent rays (a pixel tile's primary
    /// rays): with AVX, one traversal for the packet, which falls back to single rays when
    /// the active rays' directions differ in sign on some axis (or one is axis-parallel).
    pub fn closest_hit8(
        &self,
        o: &[Vec3A; WIDTH],
        d: &[Vec3A; WIDTH],
        active: u8,
        t_min: f32,
        t_max: &mut [f32; WIDTH],
    ) -> [Option<TriangleHit>; WIDTH] {
        #[cfg(target_arch = "x86_64")]
        if has_avx() {
            #[allow(unsafe_code)]
            // SAFETY: the CPU has AVX, checked just above.
            return unsafe { self.packet_avx(o, d, active, t_min, t_max) };
        }
        self.singles8(o, d, active, t_min, t_max)
    }

    /// `closest_hit8` one ray at a time.
    fn singles8(
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
    /// exact under rounding, see `PacketPre`), so a box is entered whenever any ray's own
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
    ) -> [Option<TriangleHit>; WIDTH] {
        let mut out = [None; WIDTH];
        if self.nodes.is_empty() || active == 0 {
            return out;
        }
        let Some((p, live)) = PacketPre::new(o, d, active, self, t_min, t_max) else {
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
        let mut tn = [0.0f32; WIDTH];
        let mut cur: Child = 0;
        // Where cur's box is stored (node * 8 + slot); unused for the root, never a leaf
        // except in a one-slot root, whose box is the root's box.
        let mut cur_box = u32::MAX;
        loop {
            if wide::is_leaf(cur) {
                let (first, count) = wide::leaf_range(cur);
                // Only the rays whose own slab test enters the leaf's box: testing every
                // live ray instead cost the Stanford bunny 28.0 -> 25.6 Mrays/s (bunny_1k
                // 43.4 vs 43.8, a wash; 1 thread, medians of 9, alternating runs).
                let mut rays = if cur_box == u32::MAX {
                    live
                } else {
                    let n = &self.nodes[(cur_box / 8) as usize];
                    p.rays_entering(n, (cur_box % 8) as usize, t_min, &t_best) & live
                };
                let mut hit = false;
                while rays != 0 {
                    let i = rays.trailing_zeros() as usize;
                    rays &= rays - 1;
                    if let Some((t, k)) =
                        leaf8_avx(self, &(o[i], d[i]), first, count, t_min, t_best[i])
                    {
                        t_best[i] = t;
                        best[i] = k;
                        hit = true;
                    }
                }
                if hit {
                    t_far = t_best.iter().copied().fold(f32::NEG_INFINITY, f32::max);
                }
            } else {
                let n = &self.nodes[cur as usize];
                let mask = p.slab8(n, t_min, t_far, &mut tn);
                let at = cur * 8;
                if mask != 0 {
                    let i = mask.trailing_zeros() as usize;
                    let rest = mask & (mask - 1);
                    if rest == 0 {
                        cur = n.child[i];
                        cur_box = at + i as u32;
                        continue;
                    }
                    if rest & (rest - 1) == 0 {
                        let j = rest.trailing_zeros() as usize;
                        let (near, far) = if tn[i] <= tn[j] { (i, j) } else { (j, i) };
                        stack.push((n.child[far], tn[far], at + far as u32));
                        cur = n.child[near];
                        cur_box = at + near as u32;
                        continue;
                    }
                    let mut m = mask;
                    let mut k = 0;
                    while m != 0 {
                        let j = m.trailing_zeros() as usize;
                        m &= m - 1;
                        stack.push((n.child[j], tn[j], at + j as u32));
                        k += 1;
                    }
                    stack.sort_top(k);
                    if let Some((c, _, b)) = stack.pop() {
                        cur = c;
                        cur_box = b;
                        continue;
                    }
                }
            }
            // The nearest child some ray may still need.
            loop {
                match stack.pop() {
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
                    Some((c, t, b)) if t <= t_far => {
                        cur = c;
                        cur_box = b;
                        break;
                    }
                    Some(_) => {}
                }
            }
        }
    }

    /// The closest hit with SSE only (any x86-64, and the fallback elsewhere).
    #[inline(always)]
    fn intersect_portable(
        &self,
        o: Vec3A,
        d: Vec3A,
        t_min: f32,
        t_max: f32,
    ) -> Option<TriangleHit> {
        closest_hit!(
            self,
            o,
            d,
            t_min,
            t_max,
            RayPre::slab8,
            TriangleBvh::leaf_scalar
        )
    }

    /// Triangle `i` (leaf order) from the component arrays; zeros past the end.
    #[inline(always)]
    fn tri(&self, i: usize) -> Tri {
        let c = |k: usize| self.soa.get(k * self.stride + i).copied().unwrap_or(0.0);
        Tri {
            v0: Vec3::new(c(0), c(1), c(2)),
            e1: Vec3::new(c(3), c(4), c(5)),
            e2: Vec3::new(c(6), c(7), c(8)),
        }
    }

    /// The nearest hit in (t_min, t_best) among triangles first..first+count, one at a time:
    /// (t, index in leaf order). The first of equal t wins.
    #[inline(always)]
    fn leaf_scalar(
        &self,
        r: &RayPre,
        first: usize,
        count: usize,
        t_min: f32,
        t_best: f32,
    ) -> Option<(f32, usize)> {
        let mut best = None;
        let mut t_best = t_best;
        for k in first..first + count {
            if let Some(t) = self.tri(k).hit(r.o.into(), r.d.into())
                && t > t_min
                && t < t_best
            {
                t_best = t;
                best = Some((t, k));
            }
        }
        best
    }

    /// The 8 slots in one 256-bit register. Measured (best of 20 frames, 800x800, 1 thread):
    /// bunny69k 8.77 -> 8.93 Mrays/s, dragon 7.55 -> 7.88, bunny_1k unchanged.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    fn intersect_avx(&self, o: Vec3A, d: Vec3A, t_min: f32, t_max: f32) -> Option<TriangleHit> {
        closest_hit!(self, o, d, t_min, t_max, slab8_avx, leaf8_avx)
    }
}

/// Whether a ray can be traversed: with finite origin and direction an empty slot's box
/// (+inf..-inf) gives an infinite, never NaN, slab on every axis, so it is never entered.
#[inline(always)]
fn finite_ray(o: Vec3A, d: Vec3A) -> bool {
    o.is_finite() && d.is_finite()
}

/// Whether the AVX traversal and leaf test run here.
#[inline(always)]
fn has_avx() -> bool {
    #[cfg(target_arch = "x86_64")]
    return std::arch::is_x86_feature_detected!("avx");
    #[cfg(not(target_arch = "x86_64"))]
    false
}

/// A ray as the leaf test reads it: the single-ray traversal's `RayPre`, or a packet's
/// (origin, direction). Generic rather than one function taking (o, d) that both call: with
/// two callers LLVM stopped inlining the leaf test into the single-ray traversal, which cost
/// single rays 4-5% (bunny_1k 29.2 -> 27.8 Mrays/s, Stanford bunny 15.5 -> 14.9, dragon
/// 13.2 -> 12.8; 1 thread, medians of 9, alternating runs).
trait LeafRay {
    fn origin(&self) -> Vec3A;
    fn direction(&self) -> Vec3A;
}

impl LeafRay for RayPre {
    #[inline(always)]
    fn origin(&self) -> Vec3A {
        self.o
    }
    #[inline(always)]
    fn direction(&self) -> Vec3A {
        self.d
    }
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

/// `TriangleBvh::leaf_scalar` for a whole leaf at once: the same Möller–Trumbore steps in
/// the same order on eight lanes (no FMA), so t is bit for bit the scalar (and brute-force)
/// value. Measured against the scalar loop over (v0, e1, e2) records (medians of 9 frames,
/// 800x800, 1 thread, interleaved runs): Stanford bunny 10.7 -> 11.1 Mrays/s, dragon 8.7 ->
/// 9.3; but bunny_1k 19.4 -> 17.7 and cube 41 -> 30, whose rays meet few, small leaves
/// (one 8-lane chain is longer than a few scalar tests that overlap).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
#[inline]
fn leaf8_avx<L: LeafRay>(
    bvh: &TriangleBvh,
    ray: &L,
    first: usize,
    count: usize,
    t_min: f32,
    t_best: f32,
) -> Option<(f32, usize)> {
    use std::arch::x86_64::*;
    let (o, d) = (ray.origin(), ray.direction());
    let ld = |k: usize| {
        let at = k * bvh.stride + first;
        match bvh.soa.get(at..at + WIDTH) {
            #[allow(unsafe_code)]
            // SAFETY: the slice holds exactly 8 f32, one unaligned 256-bit load.
            Some(s) => unsafe { _mm256_loadu_ps(s.as_ptr()) },
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
    let inv_det = _mm256_div_ps(_mm256_set1_ps(1.0), det);
    let sx = sub(_mm256_set1_ps(o.x), v0x);
    let sy = sub(_mm256_set1_ps(o.y), v0y);
    let sz = sub(_mm256_set1_ps(o.z), v0z);
    let u = mul(dot(sx, sy, sz, px, py, pz), inv_det);
    let (zero, one) = (_mm256_setzero_ps(), _mm256_set1_ps(1.0));
    // Ordered compares are false for NaN, as the scalar tests are.
    let ok = _mm256_and_ps(
        _mm256_cmp_ps::<_CMP_NEQ_OQ>(det, zero),
        _mm256_and_ps(
            _mm256_cmp_ps::<_CMP_GE_OQ>(u, zero),
            _mm256_cmp_ps::<_CMP_LE_OQ>(u, one),
        ),
    );
    let lanes = (1u32 << count) - 1;
    // Most leaves a ray enters hold no triangle it crosses: stop before the second half.
    if _mm256_movemask_ps(ok) as u32 & lanes == 0 {
        return None;
    }
    let (qx, qy, qz) = cross(sx, sy, sz, e1x, e1y, e1z);
    let v = mul(dot(dx, dy, dz, qx, qy, qz), inv_det);
    let t = mul(dot(e2x, e2y, e2z, qx, qy, qz), inv_det);
    // The scalar test rejects when v < 0 or u + v > 1 (so a NaN v passes here, as there).
    let reject = _mm256_or_ps(
        _mm256_cmp_ps::<_CMP_LT_OQ>(v, zero),
        _mm256_cmp_ps::<_CMP_GT_OQ>(add(u, v), one),
    );
    let in_range = _mm256_and_ps(
        _mm256_cmp_ps::<_CMP_GT_OQ>(t, _mm256_set1_ps(t_min)),
        _mm256_cmp_ps::<_CMP_LT_OQ>(t, _mm256_set1_ps(t_best)),
    );
    let mut mask =
        (_mm256_movemask_ps(_mm256_andnot_ps(reject, _mm256_and_ps(ok, in_range))) as u32) & lanes;
    if mask == 0 {
        return None;
    }
    let mut ts = [0.0f32; WIDTH];
    #[allow(unsafe_code)]
    // SAFETY: `ts` is 8 f32, exactly one unaligned 256-bit store.
    unsafe {
        _mm256_storeu_ps(ts.as_mut_ptr(), t)
    };
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

/// `RayPre::slab8` with AVX.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
#[inline]
fn slab8_avx(r: &RayPre, n: &Node8, t_min: f32, t_max: f32, tn: &mut [f32; WIDTH]) -> u32 {
    use std::arch::x86_64::*;
    #[allow(unsafe_code)]
    // SAFETY: an axis row [Vec4; 2] is 8 contiguous f32 (Vec4 is a 16-byte __m128);
    // unaligned loads ask nothing more.
    let ld = |v: &[Vec4; 2]| unsafe { _mm256_loadu_ps(v.as_ptr().cast::<f32>()) };
    let pick = |a: usize| {
        if r.neg[a] {
            (&n.hi[a], &n.lo[a])
        } else {
            (&n.lo[a], &n.hi[a])
        }
    };
    let (nx, fx) = pick(0);
    let (ny, fy) = pick(1);
    let (nz, fz) = pick(2);
    let (ox, oy, oz) = (
        _mm256_set1_ps(r.o.x),
        _mm256_set1_ps(r.o.y),
        _mm256_set1_ps(r.o.z),
    );
    let (ix, iy, iz) = (
        _mm256_set1_ps(r.inv.x),
        _mm256_set1_ps(r.inv.y),
        _mm256_set1_ps(r.inv.z),
    );
    let slab = |p: &[Vec4; 2], o: __m256, i: __m256| _mm256_mul_ps(_mm256_sub_ps(ld(p), o), i);
    // Operand order as in the SSE version: NaN in the first operand yields the second.
    let near = _mm256_max_ps(
        _mm256_max_ps(slab(nx, ox, ix), slab(ny, oy, iy)),
        _mm256_max_ps(slab(nz, oz, iz), _mm256_set1_ps(t_min)),
    );
    let far = _mm256_min_ps(
        _mm256_min_ps(slab(fx, ox, ix), slab(fy, oy, iy)),
        _mm256_min_ps(slab(fz, oz, iz), _mm256_set1_ps(t_max)),
    );
    let far = _mm256_mul_ps(far, _mm256_set1_ps(1.000_000_4));
    #[allow(unsafe_code)]
    // SAFETY: `tn` is 8 f32, exactly one unaligned 256-bit store.
    unsafe {
        _mm256_storeu_ps(tn.as_mut_ptr(), near)
    };
    _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(near, far)) as u32
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
struct PacketPre {
    neg: [bool; 3],
    /// Per axis: the origin bound the near (far) plane's difference takes.
    o_near: [f32; 3],
    o_far: [f32; 3],
    inv_min: [f32; 3],
    inv_max: [f32; 3],
    /// Per axis, lane i = ray i's origin and reciprocal direction.
    o: [std::arch::x86_64::__m256; 3],
    inv: [std::arch::x86_64::__m256; 3],
}

#[cfg(target_arch = "x86_64")]
impl PacketPre {
    /// The packet's constants and the rays of `active` that meet the root's box (tested as
    /// `RayPre::enters` tests it). None when an active ray has a zero (or non-finite)
    /// direction component or a non-finite origin, or when the rays meeting the root differ
    /// in direction sign on some axis: those go one by one. Built in registers, eight rays
    /// per instruction (one division per axis instead of a reciprocal per ray).
    #[target_feature(enable = "avx")]
    #[inline]
    fn new(
        o: &[Vec3A; WIDTH],
        d: &[Vec3A; WIDTH],
        active: u8,
        bvh: &TriangleBvh,
        t_min: f32,
        t_max: &[f32; WIDTH],
    ) -> Option<(PacketPre, u8)> {
        use std::arch::x86_64::*;
        let col = |v: &[Vec3A; WIDTH], a: usize| {
            _mm256_setr_ps(
                v[0][a], v[1][a], v[2][a], v[3][a], v[4][a], v[5][a], v[6][a], v[7][a],
            )
        };
        let (set, sub, mul) = (_mm256_set1_ps, _mm256_sub_ps, _mm256_mul_ps);
        let ov = [col(o, 0), col(o, 1), col(o, 2)];
        // IEEE division, lane by lane the value of `Vec3A::recip`.
        let iv = [0, 1, 2].map(|a| _mm256_div_ps(set(1.0), col(d, a)));
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
        // The root's box per ray, `RayPre::enters`'s operations (no NaN can arise here: every
        // reciprocal is finite and nonzero).
        #[allow(unsafe_code)]
        // SAFETY: `t_max` is 8 f32, one unaligned 256-bit load.
        let tmax = unsafe { _mm256_loadu_ps(t_max.as_ptr()) };
        let (mut near, mut far) = (set(t_min), tmax);
        for a in 0..3 {
            let t0 = mul(sub(set(bvh.root_lo[a]), ov[a]), iv[a]);
            let t1 = mul(sub(set(bvh.root_hi[a]), ov[a]), iv[a]);
            near = _mm256_max_ps(near, _mm256_min_ps(t0, t1));
            far = _mm256_min_ps(far, _mm256_max_ps(t0, t1));
        }
        let live = bits(_mm256_cmp_ps::<_CMP_LE_OQ>(
            near,
            mul(far, set(1.000_000_4)),
        )) & active;
        let mut p = PacketPre {
            neg: [false; 3],
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
            p.neg[a] = neg != 0;
            let o_min = hmin(_mm256_blendv_ps(inf, ov[a], lanes));
            let o_max = hmax(_mm256_blendv_ps(neg_inf, ov[a], lanes));
            p.inv_min[a] = hmin(_mm256_blendv_ps(inf, iv[a], lanes));
            p.inv_max[a] = hmax(_mm256_blendv_ps(neg_inf, iv[a], lanes));
            (p.o_near[a], p.o_far[a]) = if p.neg[a] {
                (o_min, o_max)
            } else {
                (o_max, o_min)
            };
        }
        Some((p, live))
    }

    /// The packet against a node's eight boxes: bit i set when some ray of the packet may
    /// enter slot i within [t_min, t_far] (never unset where a ray's own `slab8` sets it);
    /// `tn` gets lower bounds of the rays' entry distances.
    #[target_feature(enable = "avx")]
    #[inline]
    fn slab8(&self, n: &Node8, t_min: f32, t_far: f32, tn: &mut [f32; WIDTH]) -> u32 {
        use std::arch::x86_64::*;
        #[allow(unsafe_code)]
        // SAFETY: an axis row [Vec4; 2] is 8 contiguous f32; unaligned loads ask nothing more.
        let ld = |v: &[Vec4; 2]| unsafe { _mm256_loadu_ps(v.as_ptr().cast::<f32>()) };
        let (sub, mul, blend, set) = (
            _mm256_sub_ps,
            _mm256_mul_ps,
            _mm256_blendv_ps,
            _mm256_set1_ps,
        );
        let side = |a: usize| {
            let (np, fp) = if self.neg[a] {
                (&n.hi[a], &n.lo[a])
            } else {
                (&n.lo[a], &n.hi[a])
            };
            let (lo, hi) = (set(self.inv_min[a]), set(self.inv_max[a]));
            // blendv takes its second operand where the difference is negative.
            let x = sub(ld(np), set(self.o_near[a]));
            let y = sub(ld(fp), set(self.o_far[a]));
            (mul(x, blend(lo, hi, x)), mul(y, blend(hi, lo, y)))
        };
        let (nx, fx) = side(0);
        let (ny, fy) = side(1);
        let (nz, fz) = side(2);
        let near = _mm256_max_ps(_mm256_max_ps(nx, ny), _mm256_max_ps(nz, set(t_min)));
        let far = _mm256_min_ps(_mm256_min_ps(fx, fy), _mm256_min_ps(fz, set(t_far)));
        let far = mul(far, set(1.000_000_4));
        #[allow(unsafe_code)]
        // SAFETY: `tn` is 8 f32, exactly one unaligned 256-bit store.
        unsafe {
            _mm256_storeu_ps(tn.as_mut_ptr(), near)
        };
        _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(near, far)) as u32
    }

    /// Bit i set when ray i's own slab test (`slab8_avx`'s operations in its order, lane i)
    /// enters slot `s` of `n` within [t_min, t_best[i]].
    #[target_feature(enable = "avx")]
    #[inline]
    fn rays_entering(&self, n: &Node8, s: usize, t_min: f32, t_best: &[f32; WIDTH]) -> u8 {
        use std::arch::x86_64::*;
        #[allow(unsafe_code)]
        // SAFETY: each row is 8 f32, one unaligned 256-bit load.
        let ld = |v: &[f32; WIDTH]| unsafe { _mm256_loadu_ps(v.as_ptr()) };
        let (sub, mul, set) = (_mm256_sub_ps, _mm256_mul_ps, _mm256_set1_ps);
        let (h, l) = (s / 4, s % 4);
        let slab = |a: usize| {
            let (np, fp) = if self.neg[a] {
                (n.hi[a][h][l], n.lo[a][h][l])
            } else {
                (n.lo[a][h][l], n.hi[a][h][l])
            };
            let (o, inv) = (self.o[a], self.inv[a]);
            (mul(sub(set(np), o), inv), mul(sub(set(fp), o), inv))
        };
        let (nx, fx) = slab(0);
        let (ny, fy) = slab(1);
        let (nz, fz) = slab(2);
        let near = _mm256_max_ps(_mm256_max_ps(nx, ny), _mm256_max_ps(nz, set(t_min)));
        let far = _mm256_min_ps(_mm256_min_ps(fx, fy), _mm256_min_ps(fz, ld(t_best)));
        let far = mul(far, set(1.000_000_4));
        _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(near, far)) as u8
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::intersect_triangle;

    /// xorshift32: repeatable runs.
    struct Rng(u32);
    impl Rng {
        fn f(&mut self) -> f32 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 17;
            self.0 ^= self.0 << 5;
            self.0 as f32 / u32::MAX as f32
        }
        fn v(&mut self) -> Vec3 {
            Vec3::new(self.f(), self.f(), self.f())
        }
    }

    fn random_mesh(n: usize, seed: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let mut r = Rng(seed.max(1));
        let mut pos = Vec::new();
        let mut tris = Vec::new();
        for i in 0..n {
            let c = r.v() * 4.0 - 2.0;
            for _ in 0..3 {
                pos.push(c + (r.v() - 0.5) * 0.6);
            }
            let b = (3 * i) as u32;
            tris.push([b, b + 1, b + 2]);
        }
        // Degenerate triangles too: a point and a sliver along a line.
        pos.extend([Vec3::ZERO, Vec3::X, Vec3::X * 2.0]);
        let z = (pos.len() - 3) as u32;
        tris.push([z, z, z]);
        tris.push([z, z + 1, z + 2]);
        (pos, tris)
    }

    fn build_checked(pos: &[Vec3], tris: &[[u32; 3]]) -> TriangleBvh {
        let bvh = TriangleBvh::build(pos, tris);
        bvh.check_invariants(pos, tris)
            .unwrap_or_else(|e| panic!("{} triangles: {e}", tris.len()));
        bvh
    }

    fn brute(pos: &[Vec3], tris: &[[u32; 3]], ray: &Ray, t_min: f32) -> Option<TriangleHit> {
        let mut best: Option<TriangleHit> = None;
        for (i, t) in tris.iter().enumerate() {
            let lim = best.map_or(f32::INFINITY, |b| b.t);
            let [a, b, c] = t.map(|v| pos[v as usize]);
            if let Some((th, _, _)) = intersect_triangle(ray, a, b, c, t_min, lim) {
                best = Some(TriangleHit {
                    t: th,
                    triangle: i as u32,
                });
            }
        }
        best
    }

    /// Closest hits agree with the brute-force loop: same t, and the same triangle unless
    /// two triangles are hit at that very t.
    fn assert_agrees(pos: &[Vec3], tris: &[[u32; 3]], bvh: &TriangleBvh, rays: &[Ray]) {
        for (k, ray) in rays.iter().enumerate() {
            let a = bvh.intersect(ray, 0.0, f32::INFINITY);
            // Whichever instruction set `intersect` picked, the portable path must agree.
            assert_eq!(
                a,
                bvh.intersect_portable(ray.origin.into(), ray.direction.into(), 0.0, f32::INFINITY),
                "ray {k}"
            );
            let b = brute(pos, tris, ray, 0.0);
            match (a, b) {
                (None, None) => {}
                (Some(a), Some(b)) => {
                    assert!(
                        (a.t - b.t).abs() <= 1e-6 * b.t.abs().max(1.0),
                        "ray {k}: t {a:?} vs {b:?}"
                    );
                    if a.triangle != b.triangle {
                        let [p, q, r] = tris[a.triangle as usize].map(|v| pos[v as usize]);
                        let again =
                            intersect_triangle(ray, p, q, r, 0.0, f32::INFINITY).map(|h| h.0);
                        assert_eq!(
                            again,
                            Some(a.t),
                            "ray {k}: triangle {} is not hit at {}",
                            a.triangle,
                            a.t
                        );
                    }
                }
                _ => panic!("ray {k}: bvh {a:?} vs brute {b:?}"),
            }
        }
    }

    fn rays_toward(center: Vec3, radius: f32, n: usize, seed: u32) -> Vec<Ray> {
        let mut r = Rng(seed);
        (0..n)
            .map(|_| {
                let o = center + (r.v() * 2.0 - 1.0) * radius * 2.5;
                let target = center + (r.v() * 2.0 - 1.0) * radius * 0.8;
                Ray::new(o, target - o)
            })
            .collect()
    }

    #[test]
    fn random_rays_agree_with_brute_force_on_random_meshes() {
        for (n, seed) in [(1, 7), (3, 3), (9, 1), (50, 11), (2000, 13), (20_000, 17)] {
            let (pos, tris) = random_mesh(n, seed);
            let bvh = build_checked(&pos, &tris);
            assert_agrees(
                &pos,
                &tris,
                &bvh,
                &rays_toward(Vec3::ZERO, 2.0, 2000, 99 + seed),
            );
        }
    }

    /// Both leaf sizings (the AVX one and the one for CPUs without it) build valid trees that
    /// find the brute-force hits; the AVX sizing makes leaves of several triangles.
    #[test]
    fn both_leaf_sizings_build_valid_trees() {
        let (pos, tris) = random_mesh(5000, 23);
        let mut per_leaf = Vec::new();
        for block in [1, WIDTH as u32] {
            let bvh = TriangleBvh::build_with(&pos, &tris, sah::LeafBlock(block));
            bvh.check_invariants(&pos, &tris)
                .unwrap_or_else(|e| panic!("block {block}: {e}"));
            assert_agrees(&pos, &tris, &bvh, &rays_toward(Vec3::ZERO, 2.0, 2000, 5));
            let leaves: usize = bvh
                .nodes
                .iter()
                .flat_map(|n| {
                    n.child
                        .iter()
                        .enumerate()
                        .filter(|&(s, c)| !n.slot_is_empty(s) && wide::is_leaf(*c))
                })
                .count();
            per_leaf.push(tris.len() as f64 / leaves as f64);
        }
        assert!(
            per_leaf[1] > 1.5 * per_leaf[0],
            "triangles per leaf {per_leaf:?}"
        );
    }

    #[test]
    fn a_ray_from_inside_the_mesh_and_axis_parallel_rays_agree() {
        let (pos, tris) = random_mesh(3000, 23);
        let bvh = build_checked(&pos, &tris);
        let mut rays = Vec::new();
        let mut r = Rng(5);
        for _ in 0..500 {
            let o = r.v() * 3.0 - 1.5;
            for d in [
                Vec3::X,
                Vec3::NEG_X,
                Vec3::Y,
                Vec3::NEG_Y,
                Vec3::Z,
                Vec3::NEG_Z,
                r.v() - 0.5,
            ] {
                rays.push(Ray::new(o, d));
            }
        }
        assert_agrees(&pos, &tris, &bvh, &rays);
    }

    #[test]
    fn t_range_is_respected() {
        let (pos, tris) = random_mesh(500, 29);
        let bvh = build_checked(&pos, &tris);
        for ray in rays_toward(Vec3::ZERO, 2.0, 500, 3) {
            let Some(first) = bvh.intersect(&ray, 0.0, f32::INFINITY) else {
                continue;
            };
            // Nothing strictly before the first hit; past it, the brute force's next hit.
            assert!(bvh.intersect(&ray, 0.0, first.t).is_none());
            let next = bvh.intersect(&ray, first.t, f32::INFINITY).map(|h| h.t);
            let want = brute(&pos, &tris, &ray, first.t).map(|h| h.t);
            assert_eq!(next, want);
        }
    }

    #[test]
    fn identical_and_degenerate_triangles_build_and_never_hit_edge_on() {
        // Many copies of one triangle: no split can separate them; leaves must still be small.
        let pos = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
        let tris = vec![[0, 1, 2]; 1000];
        let bvh = build_checked(&pos, &tris);
        let hit = bvh.intersect(
            &Ray::new(Vec3::new(0.2, 0.2, 1.0), Vec3::NEG_Z),
            0.0,
            f32::INFINITY,
        );
        assert_eq!(hit.map(|h| h.t), Some(1.0));
        // Zero-area triangles only.
        let pos = vec![Vec3::ZERO, Vec3::X, Vec3::X * 2.0];
        let tris = vec![[0, 0, 0], [0, 1, 2], [1, 1, 2]];
        let bvh = build_checked(&pos, &tris);
        for ray in rays_toward(Vec3::X, 1.0, 200, 8) {
            assert!(bvh.intersect(&ray, 0.0, f32::INFINITY).is_none());
        }
    }

    #[test]
    fn adversarial_sizes_stay_within_the_depth_cap() {
        // Triangles at exponentially growing distances make SAH peel one at a time.
        let mut pos = Vec::new();
        let mut tris = Vec::new();
        for i in 0..3000u32 {
            let x = 1.02f32.powi(i as i32);
            pos.extend([
                Vec3::new(x, 0.0, 0.0),
                Vec3::new(x, 1.0, 0.0),
                Vec3::new(x, 0.0, 1.0),
            ]);
            tris.push([3 * i, 3 * i + 1, 3 * i + 2]);
        }
        let bvh = build_checked(&pos, &tris);
        let ray = Ray::new(Vec3::new(-1.0, 0.2, 0.2), Vec3::X);
        assert_eq!(
            bvh.intersect(&ray, 0.0, f32::INFINITY).map(|h| h.triangle),
            Some(0)
        );
        let mut all = Vec::new();
        bvh.intersect_all(&ray, 0.0, f32::INFINITY, &mut all);
        assert_eq!(all.len(), 3000);
    }

    #[test]
    fn one_triangle_mesh() {
        let pos = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
        let bvh = build_checked(&pos, &[[0, 1, 2]]);
        let ray = Ray::new(Vec3::new(0.25, 0.25, -2.0), Vec3::Z);
        assert_eq!(
            bvh.intersect(&ray, 0.0, f32::INFINITY),
            Some(TriangleHit {
                t: 2.0,
                triangle: 0
            })
        );
        assert!(
            bvh.intersect(
                &Ray::new(Vec3::new(0.8, 0.8, -2.0), Vec3::Z),
                0.0,
                f32::INFINITY
            )
            .is_none()
        );
        assert_eq!(
            bvh.bounds(),
            Aabb::new(Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0))
        );
    }

    #[test]
    fn empty_mesh_never_hits() {
        let bvh = build_checked(&[], &[]);
        assert!(
            bvh.intersect(&Ray::new(Vec3::ZERO, Vec3::X), 0.0, f32::INFINITY)
                .is_none()
        );
        let mut out = Vec::new();
        bvh.intersect_all(&Ray::new(Vec3::ZERO, Vec3::X), 0.0, f32::INFINITY, &mut out);
        assert!(out.is_empty());
        assert!(bvh.bounds().is_empty());
    }

    #[test]
    fn broken_trees_fail_the_invariant_check() {
        let (pos, tris) = random_mesh(300, 31);
        let good = build_checked(&pos, &tris);
        let mut shrunk = good.clone();
        shrunk.nodes[0].hi[0][0][0] -= 0.5;
        assert!(shrunk.check_invariants(&pos, &tris).is_err());
        let mut dup = good.clone();
        dup.ids[1] = dup.ids[0];
        assert!(dup.check_invariants(&pos, &tris).is_err());
        assert!(good.check_invariants(&pos, &tris[1..]).is_err());
    }

    #[test]
    fn intersect_all_finds_every_crossing() {
        let (pos, tris) = random_mesh(500, 5);
        let bvh = build_checked(&pos, &tris);
        let mut out = Vec::new();
        for k in 0..200 {
            let o = Vec3::new(
                -5.0,
                (k as f32 * 0.37).sin() * 1.5,
                (k as f32 * 0.11).cos() * 1.5,
            );
            let ray = Ray::new(o, Vec3::new(1.0, 0.01 * k as f32 - 1.0, 0.3));
            out.clear();
            bvh.intersect_all(&ray, 0.0, f32::INFINITY, &mut out);
            let mut got: Vec<u32> = out.iter().map(|h| h.triangle).collect();
            got.sort_unstable();
            let want: Vec<u32> = (0..tris.len() as u32)
                .filter(|&i| {
                    let [a, b, c] = tris[i as usize].map(|v| pos[v as usize]);
                    intersect_triangle(&ray, a, b, c, 0.0, f32::INFINITY).is_some()
                })
                .collect();
            assert_eq!(got, want, "ray {k}");
        }
    }

    /// Rays with NaN or infinite parts (an overflowing transform) used to loop forever: the
    /// NaN slab entered the empty slots, whose child is the root. Run on a thread so a
    /// regression fails instead of hanging the test run.
    #[test]
    fn non_finite_rays_miss_and_return() {
        let (pos, tris) = random_mesh(300, 9);
        let bvh = build_checked(&pos, &tris);
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let (n, i) = (f32::NAN, f32::INFINITY);
            let rays = [
                (Vec3::new(n, 0.0, -5.0), Vec3::Z),
                (Vec3::new(0.0, 0.0, -5.0), Vec3::new(n, n, n)),
                (Vec3::new(0.0, 0.0, -5.0), Vec3::new(i, i, i)),
                (Vec3::new(i, -i, i), Vec3::new(0.0, 0.0, 1.0)),
            ];
            let mut all = Vec::new();
            let mut hits = 0;
            for (o, d) in rays {
                hits += bvh.intersect(&Ray::new(o, d), 0.0, f32::INFINITY).is_some() as usize;
                bvh.intersect_all(&Ray::new(o, d), 0.0, f32::INFINITY, &mut all);
            }
            let _ = tx.send((hits, all.len()));
        });
        let got = rx.recv_timeout(std::time::Duration::from_secs(10));
        assert_eq!(got, Ok((0, 0)), "non-finite rays must miss, and return");
    }

    /// Packets of the eight rays `rays[k..k + 8]` under every `active` mask in `masks`: each
    /// traced ray gets the single-ray t bit for bit (and a triangle hit at that t), its
    /// t_max lowered to it; rays left out get nothing and keep their t_max. Returns how
    /// many rays were compared.
    fn assert_packets_agree(bvh: &TriangleBvh, rays: &[Ray], t_min: f32, masks: &[u8]) -> usize {
        let mut compared = 0;
        for (p, chunk) in rays.chunks_exact(WIDTH).enumerate() {
            let o: [Vec3A; WIDTH] = std::array::from_fn(|i| chunk[i].origin.into());
            let d: [Vec3A; WIDTH] = std::array::from_fn(|i| chunk[i].direction.into());
            for &active in masks {
                let mut limits = [f32::INFINITY; WIDTH];
                limits[3] = 7.5; // one ray with a finite limit
                let mut t_packet = limits;
                let got = bvh.closest_hit8(&o, &d, active, t_min, &mut t_packet);
                for i in 0..WIDTH {
                    let want = if active & (1 << i) != 0 {
                        bvh.closest_hit(o[i], d[i], t_min, limits[i])
                    } else {
                        None
                    };
                    match (got[i], want) {
                        (None, None) => {}
                        (Some(g), Some(w)) => {
                            assert_eq!(
                                g.t.to_bits(),
                                w.t.to_bits(),
                                "packet {p} ray {i} mask {active:#x}"
                            );
                            if g.triangle != w.triangle {
                                // A tie: the other triangle must be hit at that very t.
                                let k = bvh
                                    .ids
                                    .iter()
                                    .position(|&id| id == g.triangle)
                                    .expect("a stored id");
                                assert_eq!(
                                    bvh.tri(k).hit(chunk[i].origin, chunk[i].direction),
                                    Some(g.t),
                                    "packet {p} ray {i}: triangle {} not hit at {}",
                                    g.triangle,
                                    g.t
                                );
                            }
                        }
                        _ => panic!(
                            "packet {p} ray {i} mask {active:#x}: {:?} vs single {want:?}",
                            got[i]
                        ),
                    }
                    let want_t = want.map_or(limits[i], |h| h.t);
                    assert_eq!(
                        t_packet[i].to_bits(),
                        want_t.to_bits(),
                        "packet {p} ray {i}: t_max"
                    );
                }
                // The portable fallback (single rays) agrees too.
                let mut t_singles = limits;
                let singles = bvh.singles8(&o, &d, active, t_min, &mut t_singles);
                assert_eq!(
                    t_singles.map(f32::to_bits),
                    t_packet.map(f32::to_bits),
                    "packet {p}"
                );
                assert_eq!(
                    singles.map(|h| h.map(|h| h.t)),
                    got.map(|h| h.map(|h| h.t)),
                    "packet {p}"
                );
                compared += active.count_ones() as usize;
            }
        }
        compared
    }

    /// Primary rays of a pinhole camera at `eye` looking at `at`, in 4x2 pixel tiles (the
    /// bench's packets): `n` x `n` pixels, n a multiple of 4, spanning `fov` radians.
    fn pinhole_tiles(eye: Vec3, at: Vec3, n: usize, fov: f32) -> Vec<Ray> {
        camera_tiles(eye, at, n, fov, 0.0)
    }

    /// `pinhole_tiles` with origins spread over the screen too (`spread` = 1: a screen as
    /// wide as the view at distance 1), so a packet's origins differ.
    fn camera_tiles(eye: Vec3, at: Vec3, n: usize, fov: f32, spread: f32) -> Vec<Ray> {
        let f = (at - eye).normalize();
        let r = f.cross(Vec3::Y).normalize();
        let u = r.cross(f);
        let h = (fov * 0.5).tan();
        let mut rays = Vec::new();
        for ty in (0..n).step_by(2) {
            for tx in (0..n).step_by(4) {
                for k in 0..WIDTH {
                    let (i, j) = (tx + (k & 3), ty + (k >> 2));
                    let x = (2.0 * (i as f32 + 0.5) / n as f32 - 1.0) * h;
                    let y = (1.0 - 2.0 * (j as f32 + 0.5) / n as f32) * h;
                    let o = eye + (x * r + y * u) * spread;
                    rays.push(Ray::new(o, (f + x * r + y * u).normalize()));
                }
            }
        }
        rays
    }

    const MASKS: [u8; 5] = [0xff, 0x01, 0x80, 0x5a, 0x00];

    #[test]
    fn packets_agree_with_single_rays_on_random_meshes() {
        for (n, seed) in [(1, 7), (9, 1), (2000, 13), (20_000, 17)] {
            let (pos, tris) = random_mesh(n, seed);
            let bvh = build_checked(&pos, &tris);
            let mut compared = 0;
            // Coherent tiles from pinholes on every side (all eight sign octants).
            for eye in [
                Vec3::new(0.3, 0.4, 6.0),
                Vec3::new(-5.0, -4.0, -3.0),
                Vec3::new(4.0, -5.0, 2.0),
                Vec3::new(-0.2, 6.0, -4.0),
            ] {
                let rays = pinhole_tiles(eye, Vec3::new(0.1, -0.2, 0.05), 32, 0.9);
                compared += assert_packets_agree(&bvh, &rays, 0.0, &MASKS);
                // Origins differing within a packet (the origin bounds matter), and nearly
                // parallel rays (the reciprocal bounds collapse).
                for (fov, spread) in [(0.9, 2.0), (0.01, 400.0)] {
                    let rays = camera_tiles(eye, Vec3::new(-0.1, 0.2, 0.0), 32, fov, spread);
                    compared += assert_packets_agree(&bvh, &rays, 0.0, &MASKS);
                }
                // A camera inside the mesh's box, with t_min > 0.
                let inside = pinhole_tiles(eye * 0.05, Vec3::ZERO, 16, 1.2);
                compared += assert_packets_agree(&bvh, &inside, 0.3, &MASKS);
            }
            // Incoherent packets: random origins and directions, mixed signs.
            let rays = rays_toward(Vec3::ZERO, 2.0, 1024, 77 + seed);
            compared += assert_packets_agree(&bvh, &rays, 0.0, &MASKS);
            // Axis-parallel rays (zero direction components) amid coherent ones.
            let mut mixed = pinhole_tiles(Vec3::new(0.0, 0.0, 6.0), Vec3::ZERO, 8, 0.6);
            for (k, r) in mixed.iter_mut().enumerate().step_by(5) {
                *r = Ray::new(r.origin + Vec3::new(0.01 * k as f32, 0.0, 0.0), Vec3::NEG_Z);
            }
            compared += assert_packets_agree(&bvh, &mixed, 0.0, &MASKS);
            assert!(compared > 1000, "{compared} rays compared");
        }
    }

    /// Pins the guard the result tests cannot see (without it, loose bounds only slow the
    /// traversal down): a packet whose rays meeting the mesh differ in direction sign on an
    /// axis, or have a zero direction component, is not traced as a packet.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn packets_with_mixed_signs_or_zero_components_go_one_by_one() {
        if !has_avx() {
            crate::test_support::skip_note("no AVX here: packets always go one by one");
            return;
        }
        let (pos, tris) = random_mesh(200, 3);
        let bvh = build_checked(&pos, &tris);
        let eye = Vec3::new(0.0, 0.0, 6.0);
        // Eight rays toward points near (0.5, 0.5, 0): every one meets the mesh's box.
        let toward = |k: usize| Vec3::new(0.5 + 0.01 * k as f32, 0.5 - 0.01 * k as f32, 0.0);
        let packet = |dirs: [Vec3; WIDTH]| {
            let o = [Vec3A::from(eye); WIDTH];
            let d: [Vec3A; WIDTH] = dirs.map(Vec3A::from);
            #[allow(unsafe_code)]
            // SAFETY: the CPU has AVX, checked above.
            unsafe { PacketPre::new(&o, &d, 0xff, &bvh, 0.0, &[f32::INFINITY; WIDTH]) }
                .map(|(_, live)| live)
        };
        let coherent: [Vec3; WIDTH] = std::array::from_fn(|k| toward(k) - eye);
        assert_eq!(packet(coherent), Some(0xff), "a coherent tile is a packet");
        let mut mixed = coherent;
        mixed[3].x = -mixed[3].x;
        assert_eq!(packet(mixed), None, "one ray runs toward -x");
        let mut zero = coherent;
        zero[5].y = 0.0;
        assert_eq!(packet(zero), None, "one ray is parallel to the xz plane");
    }

    #[test]
    fn packets_on_empty_and_one_triangle_meshes() {
        let rays = pinhole_tiles(Vec3::new(0.2, 0.3, 3.0), Vec3::new(0.3, 0.3, 0.0), 8, 0.8);
        let empty = build_checked(&[], &[]);
        let o: [Vec3A; WIDTH] = std::array::from_fn(|i| rays[i].origin.into());
        let d: [Vec3A; WIDTH] = std::array::from_fn(|i| rays[i].direction.into());
        let mut t_max = [f32::INFINITY; WIDTH];
        assert_eq!(
            empty.closest_hit8(&o, &d, 0xff, 0.0, &mut t_max),
            [None; WIDTH]
        );
        assert_eq!(t_max, [f32::INFINITY; WIDTH]);
        let pos = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
        let one = build_checked(&pos, &[[0, 1, 2]]);
        assert_packets_agree(&one, &rays, 0.0, &MASKS);
        // The middle rays of the tiles do hit the triangle.
        let hits: usize = rays
            .chunks_exact(WIDTH)
            .map(|c| {
                let o: [Vec3A; WIDTH] = std::array::from_fn(|i| c[i].origin.into());
                let d: [Vec3A; WIDTH] = std::array::from_fn(|i| c[i].direction.into());
                let mut t = [f32::INFINITY; WIDTH];
                one.closest_hit8(&o, &d, 0xff, 0.0, &mut t)
                    .iter()
                    .flatten()
                    .count()
            })
            .sum();
        assert!(hits > 0 && hits < rays.len(), "{hits} hits");
    }

    #[test]
    fn shared_meshes_agree_with_brute_force() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/meshes");
        if !dir.is_dir() {
            assert!(
                std::env::var_os("TRACELAB_REQUIRE_SHARED").is_none(),
                "{} is required here",
                dir.display()
            );
            crate::test_support::skip_note(&format!(
                "SKIPPED: {} not found; shared meshes not checked",
                dir.display()
            ));
            return;
        }
        // The dragon is left to the benchmark's checksums: brute force over 871k triangles
        // per ray is too slow for a unit test.
        for (name, rays) in [
            ("cube.obj", 2000),
            ("bunny_1k.obj", 2000),
            ("stanford-bunny.obj", 150),
        ] {
            let mesh = crate::format::obj::load_obj(&dir.join(name))
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            let bvh = build_checked(&mesh.positions, &mesh.triangles);
            let b = bvh.bounds();
            let radius = b.extent().max_element() * 0.5;
            assert_agrees(
                &mesh.positions,
                &mesh.triangles,
                &bvh,
                &rays_toward(b.center(), radius, rays, 41),
            );
            // Packets: pinhole tiles from two sides, and the incoherent rays.
            for eye in [Vec3::new(0.3, 0.5, 3.0), Vec3::new(-2.0, -1.5, -2.5)] {
                let tiles = pinhole_tiles(b.center() + eye * radius, b.center(), 64, 0.8);
                assert_packets_agree(&bvh, &tiles, 0.0, &MASKS);
            }
            let mixed = rays_toward(b.center(), radius, 512, 43);
            assert_packets_agree(&bvh, &mixed, 0.0, &MASKS);
        }
    }
}
