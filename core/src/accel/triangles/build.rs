//! Building: binned SAH over the triangles' boxes, collapsed into 8-wide nodes, then the
//! triangles copied into leaf order, component by component; a mesh of at most `FLAT_MAX`
//! triangles gets no nodes.

use glam::Vec3;
use rayon::prelude::*;

use super::{FLAT_MAX, Tri, TriangleBvh, has_avx, soa_len};
use crate::accel::sah::{self, PrimRef};
use crate::accel::wide::{self, Node8, WIDTH};
use crate::geometry::Aabb;

impl TriangleBvh {
    /// Builds over the mesh. Vertex indices out of range read as the origin (the loaders
    /// reject them); triangles beyond `wide::MAX_TRIANGLES` (2^26) are left out (the OBJ
    /// loader refuses such meshes).
    pub fn build(positions: &[Vec3], triangles: &[[u32; 3]]) -> TriangleBvh {
        // Leaves sized for the leaf test this CPU runs: eight triangles cost one AVX test,
        // but eight scalar tests where there is no AVX.
        let block = if has_avx() { WIDTH as u32 } else { 1 };
        Self::build_with(positions, triangles, sah::LeafBlock(block))
    }

    pub(super) fn build_with(
        positions: &[Vec3],
        triangles: &[[u32; 3]],
        block: sah::LeafBlock,
    ) -> TriangleBvh {
        let triangles = &triangles[..triangles.len().min(wide::MAX_TRIANGLES)];
        if triangles.is_empty() {
            return TriangleBvh::default();
        }
        let vert = |i: u32| positions.get(i as usize).copied().unwrap_or(Vec3::ZERO);
        let tri = |t: [u32; 3]| {
            let (a, b, c) = (vert(t[0]), vert(t[1]), vert(t[2]));
            Tri {
                v0: a,
                e1: b - a,
                e2: c - a,
            }
        };
        let (nodes, tris, ids, root) = if triangles.len() <= FLAT_MAX {
            // Flat: no nodes, the triangles in mesh order (`FLAT_MAX`).
            let root = triangles.iter().fold(Aabb::EMPTY, |b, t| {
                b.union(Aabb::from_points(&[vert(t[0]), vert(t[1]), vert(t[2])]))
            });
            let tris = triangles.iter().map(|&t| tri(t)).collect();
            (
                Vec::new(),
                tris,
                (0..triangles.len() as u32).collect(),
                root,
            )
        } else {
            Self::tree(triangles, &vert, &tri, block)
        };
        let stride = tris.len();
        let mut soa = vec![0.0f32; soa_len(stride)];
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

    /// The nodes over `triangles` (more than `FLAT_MAX`), and the triangles, their mesh
    /// indices and the root's box in leaf order.
    fn tree(
        triangles: &[[u32; 3]],
        vert: &(impl Fn(u32) -> Vec3 + Sync),
        tri: &(impl Fn([u32; 3]) -> Tri + Sync),
        block: sah::LeafBlock,
    ) -> (Vec<Node8>, Vec<Tri>, Vec<u32>, Aabb) {
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
            return (Vec::new(), Vec::new(), Vec::new(), Aabb::EMPTY);
        };
        let nodes = wide::collapse(&root, block);
        // The temporary tree is freed on another thread while the triangles are copied.
        let ((tris, ids), ()): ((Vec<Tri>, Vec<u32>), ()) = rayon::join(
            || {
                prims
                    .par_iter()
                    .with_min_len(4096)
                    .map(|p| (tri(triangles[p.id as usize]), p.id))
                    .unzip()
            },
            move || drop(root),
        );
        let root = nodes.first().map_or(Aabb::EMPTY, Node8::bounds);
        (nodes, tris, ids, root)
    }
}
