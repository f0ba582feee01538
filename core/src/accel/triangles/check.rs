//! What a built tree looks like: its invariants, checked against the mesh (for tests), and
//! its shape (for `tracelab bench`).

use glam::Vec3;

use super::{TriangleBvh, soa_len};
use crate::accel::sah;
use crate::accel::wide::{self, WIDTH};
use crate::geometry::Aabb;

impl TriangleBvh {
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
    /// triangle in exactly one leaf, every decoded (quantised) box around all the triangles
    /// below it, each node reached once, depth within the cap.
    ///
    /// Boxes are checked against the triangles, not against their parent's box: each
    /// quantised box rounds outward on its own node's grid, so a child node's boxes may
    /// poke out of the box its parent decodes for it, which costs a ray nothing.
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
        let mut reached = vec![0u32; self.nodes.len()];
        let all = self.subtree(0, 0, triangles, &vert, &mut seen, &mut reached)?;
        if !self.bounds().contains(&all) {
            return Err("the root box does not contain the mesh".into());
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

    /// Checks node `i` at `depth` and everything below it; returns the box of the triangles
    /// under it.
    fn subtree(
        &self,
        i: usize,
        depth: usize,
        triangles: &[[u32; 3]],
        vert: &impl Fn(u32) -> Vec3,
        seen: &mut [u32],
        reached: &mut [u32],
    ) -> Result<Aabb, String> {
        let n = self.nodes.get(i).ok_or(format!("node {i} out of range"))?;
        reached[i] += 1;
        if reached[i] > 1 {
            return Err(format!("node {i} reached twice"));
        }
        if depth > sah::MAX_DEPTH {
            return Err(format!("node {i} at depth {depth}, past the cap"));
        }
        if n.used == 0 {
            return Err(format!("node {i} has no children"));
        }
        let mut all = Aabb::EMPTY;
        for s in (0..WIDTH).filter(|&s| !n.slot_is_empty(s)) {
            let c = n.child[s];
            let below = if wide::is_leaf(c) {
                let (first, count) = wide::leaf_range(c);
                let ids = self
                    .ids
                    .get(first..first + count)
                    .ok_or(format!("leaf range {first}+{count} out of bounds"))?;
                let mut b = Aabb::EMPTY;
                for &id in ids {
                    let t = triangles
                        .get(id as usize)
                        .ok_or(format!("bad triangle id {id}"))?;
                    b = b.union(Aabb::from_points(&[vert(t[0]), vert(t[1]), vert(t[2])]));
                    seen[id as usize] += 1;
                }
                b
            } else {
                self.subtree(c as usize, depth + 1, triangles, vert, seen, reached)?
            };
            if !n.slot_bounds(s).contains(&below) {
                return Err(format!(
                    "node {i} slot {s}'s box does not contain the triangles below it"
                ));
            }
            all = all.union(below);
        }
        Ok(all)
    }
}
