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
        Mesh { positions, triangles, accel }
    }

    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    pub fn bounds(&self) -> Aabb {
        self.accel.bounds()
    }

    pub fn triangle(&self, i: u32) -> [Vec3; 3] {
        let t = self.triangles.get(i as usize).copied().unwrap_or([0; 3]);
        t.map(|v| self.positions.get(v as usize).copied().unwrap_or(Vec3::ZERO))
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

/// A TriangleMesh node's geometry: loaded, or the reason it could not be.
#[derive(Clone, Debug)]
pub enum MeshSlot {
    Loaded(Arc<Mesh>),
    /// Not loaded (missing or broken file); the node renders nothing and shows this message.
    Failed(String),
}

impl PartialEq for MeshSlot {
    fn eq(&self, other: &Self) -> bool {
        match (self, other) {
            (MeshSlot::Loaded(a), MeshSlot::Loaded(b)) => Arc::ptr_eq(a, b) || a == b,
            (MeshSlot::Failed(a), MeshSlot::Failed(b)) => a == b,
            _ => false,
        }
    }
}

impl MeshSlot {
    pub fn mesh(&self) -> Option<&Arc<Mesh>> {
        match self {
            MeshSlot::Loaded(m) => Some(m),
            MeshSlot::Failed(_) => None,
        }
    }
}
