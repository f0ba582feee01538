//! What a built tree looks like: its invariants, checked against the mesh (for tests), and
//! its shape (for `tracelab bench`).

use glam::Vec3;

use super::{FLAT_MAX, TriangleBvh, soa_len};
use crate::accel::sah;
use crate::accel::wide::{self, WIDTH};
use crate::geometry::Aabb;

impl TriangleBvh {
    /// Shape of the tree, for `tracelab bench`: nodes, mean children per node, leaves and
    /// mean triangles per leaf.
    pub fn shape(&self) -> String {
        if self.nodes.is_empty() && !self.is_empty() {
            return format!(
                "flat: no nodes, {} leaves, {} triangles",
                self.stride.div_ceil(WIDTH),
                self.stride
            );
        }
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
    /// inside the box its parent holds for it, each node reached once, depth within the cap;
    /// a flat mesh: at most `FLAT_MAX` triangles, each once, all in the root's box.
    pub fn check_invariants(
        &self,
        positions: &[Vec3],
        triangles: &[[u32; 3]],
    ) -> Result<(), crate::accel::InvariantViolation> {
        self.invariants(positions, triangles)
            .map_err(crate::accel::InvariantViolation)
    }

    fn invariants(&self, positions: &[Vec3], triangles: &[[u32; 3]]) -> Result<(), String> {
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
            || self.soa.len() != soa_len(self.stride)
            || self.ids.len() != triangles.len()
        {
            return Err(format!(
                "{} triangles stored for {}",
                self.ids.len(),
                triangles.len()
            ));
        }
        let mut seen = vec![0u32; triangles.len()];
        if self.nodes.is_empty() {
            // Flat: few triangles, all in the root's box (the walks test them all).
            if triangles.len() > FLAT_MAX {
                return Err(format!("no nodes over {} triangles", triangles.len()));
            }
            for &id in &self.ids {
                let t = triangles
                    .get(id as usize)
                    .ok_or(format!("bad triangle id {id}"))?;
                if !self.bounds().contains(&tri_box(t)) {
                    return Err(format!("the root box does not contain triangle {id}"));
                }
                seen[id as usize] += 1;
            }
        }
        let mut reached = vec![0u32; self.nodes.len()];
        // (node, the box its parent holds for it, depth); none in a flat mesh.
        let mut stack = if self.nodes.is_empty() {
            Vec::new()
        } else {
            vec![(0usize, None::<Aabb>, 0usize)]
        };
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
                    let k = wide::node_index(c).ok_or(format!(
                        "node {i} slot {s}: child {c} names no node's start"
                    ))?;
                    stack.push((k, Some(b), depth + 1));
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
}
