//! Where things are in the world, from the document's scene (not a render): the matrix
//! above a node and the world box of a node's objects, for framing and for the gizmo.

use glam::{Mat4, Vec3};
use tracelab_core::scene::walk;
use tracelab_core::{NodeId, Scene};

/// World from the space `node` itself sits in: the product of every Transform above it
/// (not its own ops). `None` when the node is not in the scene.
pub fn world_from_parent(scene: &Scene, node: NodeId) -> Option<Mat4> {
    walk::visit(&scene.graph, node).map(|v| v.world_from_parent.as_mat4())
}

/// The world box (min, max) of everything with finite bounds under `node` (planes have
/// none): core's [`walk::world_bounds`]. `None` when there is nothing to bound.
pub fn world_bounds(scene: &Scene, node: NodeId) -> Option<(Vec3, Vec3)> {
    walk::world_bounds(&scene.graph, node).map(|b| (b.min, b.max))
}

/// The centre of `node`'s world box: where the gizmo stands. Under any affine transform the
/// box of a primitive's transformed box is centred on the transformed centre, so a
/// translation moves this point by exactly the translation.
pub fn world_centre(scene: &Scene, node: NodeId) -> Option<Vec3> {
    world_bounds(scene, node).map(|(a, b)| (a + b) * 0.5)
}

#[cfg(test)]
mod tests {
    use super::*;
    use tracelab_core::{MeshCache, NodeKind, parse_scene};

    #[test]
    fn a_sphere_under_scale_and_translate_has_the_transformed_box() {
        let text = "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 5 }\n\
            Group { numObjects 2 Transform { UniformScale 2 Transform { Translate 1 0 0 Sphere { center 0 0 0 radius 0.5 } } } \
            Plane { normal 0 1 0 offset -1 } }\n";
        let scene = parse_scene(text.as_bytes(), "t", None, &mut MeshCache::new())
            .scene
            .expect("parses");
        let root = scene.graph.root();
        let (lo, hi) = world_bounds(&scene, root).expect("bounded");
        assert!(
            (lo - Vec3::new(1.0, -1.0, -1.0)).length() < 1e-5
                && (hi - Vec3::new(3.0, 1.0, 1.0)).length() < 1e-5,
            "{lo} {hi}"
        );
        let sphere = scene
            .graph
            .preorder()
            .into_iter()
            .find(|&id| matches!(scene.graph.node(id).kind, NodeKind::Sphere { .. }))
            .expect("sphere");
        assert!(
            (world_centre(&scene, sphere).expect("c") - Vec3::new(2.0, 0.0, 0.0)).length() < 1e-5
        );
        let m = world_from_parent(&scene, sphere).expect("in scene");
        assert!((m.transform_point3(Vec3::ZERO) - Vec3::new(2.0, 0.0, 0.0)).length() < 1e-5);
    }
}
