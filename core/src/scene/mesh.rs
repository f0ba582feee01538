//! Triangle meshes loaded from OBJ files, with their BVH built once at load time.

use std::sync::Arc;

use glam::Vec3;

use crate::accel::TriangleBvh;
use crate::geometry::{Aabb, triangle_normal};

#[derive(Debug)]
pub struct Mesh {
    pub positions: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
    pub accel: TriangleBvh,
}

impl PartialEq for Mesh {
    /// Meshes are equal when their geometry is; the BVH is derived data.
    fn eq(&self, other: &Self) -> bool {
        self.positions == other.positions && self.triangles == other.triangles
    }
}

impl Mesh {
    /// Builds the BVH. Triangle indices must be in range (the loaders check).
    pub fn new(positions: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Mesh {
        let accel = TriangleBvh::build(&positions, &triangles);
        Mesh {
            positions,
            triangles,
            accel,
        }
    }

    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    pub fn bounds(&self) -> Aabb {
        self.accel.bounds()
    }

    pub fn triangle(&self, i: u32) -> [Vec3; 3] {
        let t = self.triangles.get(i as usize).copied().unwrap_or([0; 3]);
        t.map(|v| {
            self.positions
                .get(v as usize)
                .copied()
                .unwrap_or(Vec3::ZERO)
        })
    }

    pub fn face_normal(&self, i: u32) -> Vec3 {
        let [a, b, c] = self.triangle(i);
        triangle_normal(a, b, c)
    }

    /// Bytes of geometry plus acceleration structure.
    pub fn memory_bytes(&self) -> usize {
        self.positions.len() * 12 + self.triangles.len() * 12 + self.accel.memory_bytes()
    }
}

/// A TriangleMesh node's geometry: not looked for yet, loaded, or the reason it could not be.
#[derive(Clone, Debug)]
pub enum MeshSlot {
    /// As the parser leaves it: the OBJ file has not been opened
    /// ([`crate::format::resolve_meshes`] loads it). Renders nothing.
    Unresolved,
    Loaded(Arc<Mesh>),
    /// Not loaded (missing or broken file); the node renders nothing and shows this message.
    Failed(String),
}

impl PartialEq for MeshSlot {
    fn eq(&self, other: &Self) -> bool {
        match (self, other) {
            (MeshSlot::Loaded(a), MeshSlot::Loaded(b)) => Arc::ptr_eq(a, b) || a == b,
            (MeshSlot::Failed(a), MeshSlot::Failed(b)) => a == b,
            (MeshSlot::Unresolved, MeshSlot::Unresolved) => true,
            _ => false,
        }
    }
}

impl MeshSlot {
    pub fn mesh(&self) -> Option<&Arc<Mesh>> {
        match self {
            MeshSlot::Loaded(m) => Some(m),
            MeshSlot::Failed(_) | MeshSlot::Unresolved => None,
        }
    }
}

/// Why a mesh does not bound a solid.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum NotClosed {
    #[error("it has no triangles")]
    Empty,
    /// An edge (1-based vertex numbers, as in the OBJ file) on `count` triangles, not 2.
    #[error("the edge between vertices {a} and {b} belongs to {count} triangle(s), not 2")]
    OpenEdge { a: u32, b: u32, count: usize },
}

/// Checks that a mesh bounds a solid: every edge is shared by exactly two triangles, so a
/// ray's crossings alternate between entering and leaving. CSG needs that; an open mesh
/// would give a wrong picture rather than an error.
pub fn check_closed(mesh: &Mesh) -> Result<(), NotClosed> {
    if mesh.triangles.is_empty() {
        return Err(NotClosed::Empty);
    }
    let mut edges: Vec<(u32, u32)> = Vec::with_capacity(mesh.triangles.len() * 3);
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            edges.push((a.min(b), a.max(b)));
        }
    }
    edges.sort_unstable();
    let mut i = 0;
    while i < edges.len() {
        let mut j = i;
        while j < edges.len() && edges[j] == edges[i] {
            j += 1;
        }
        if j - i != 2 {
            let (a, b) = edges[i];
            return Err(NotClosed::OpenEdge {
                a: a + 1,
                b: b + 1,
                count: j - i,
            });
        }
        i = j;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tetra(faces: Vec<[u32; 3]>) -> Mesh {
        Mesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z], faces)
    }

    #[test]
    fn tetrahedron_is_closed_and_missing_face_is_not() {
        let all = vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
        assert_eq!(check_closed(&tetra(all.clone())), Ok(()));
        let open = check_closed(&tetra(all[..3].to_vec())).expect_err("open");
        assert!(
            matches!(open, NotClosed::OpenEdge { count: 1, .. }),
            "{open}"
        );
    }
}
