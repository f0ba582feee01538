//! How far dragging a number moves it. A fixed step per point was wrong at every scale but
//! one: 60 px moved a Translate under UniformScale 5 by 6 world units, out of a view 5.4
//! across. Lengths move by a share of what the camera sees, measured in the space the value
//! lives in; factors move by a share of their own size.

use tracelab_core::scene::{compose, walk};
use tracelab_core::{Camera, NodeId, NodeKind, Scene};

/// Points of drag that move a length across the whole view: about the width of the view
/// itself, so a dragged object roughly follows the pointer.
const POINTS_PER_VIEW: f32 = 500.0;

/// Drag speeds for one scene (the camera decides the scale).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DragSpeeds {
    /// World units per point of drag.
    world_per_point: f32,
}

impl DragSpeeds {
    pub fn for_scene(scene: &Scene) -> Self {
        Self::for_scene_camera(&scene.camera)
    }

    pub fn for_scene_camera(camera: &Camera) -> Self {
        DragSpeeds {
            world_per_point: view_extent(camera) / POINTS_PER_VIEW,
        }
    }

    /// For a length in a space where one unit is `world_per_unit` world units (a Translate,
    /// a centre, a radius, box corners, vertices).
    pub fn length(&self, world_per_unit: f32) -> f64 {
        let s = if world_per_unit.is_finite() && world_per_unit > 1e-9 {
            world_per_unit
        } else {
            1.0
        };
        f64::from(self.world_per_point / s)
    }

    /// For a scale factor: half a percent of its size per point, so 1 and 100 feel alike.
    pub fn factor(value: f32) -> f64 {
        let v = if value.is_finite() { value.abs() } else { 1.0 };
        f64::from(v.max(0.01) * 0.005)
    }
}

/// The width of the world the camera shows around what it looks at.
fn view_extent(camera: &Camera) -> f32 {
    let extent = match *camera {
        Camera::Orthographic { size, .. } => size,
        Camera::Perspective {
            center,
            direction,
            angle,
            ..
        } => {
            // How far away the scene is: the origin's depth along the view, or its distance
            // when the camera looks away from it.
            let d = direction.normalize_or_zero();
            let depth = (-center).dot(d);
            let distance = if depth > 1e-3 { depth } else { center.length() };
            2.0 * distance.max(1e-3) * (angle.to_radians() * 0.5).tan()
        }
    };
    if extent.is_finite() && extent > 1e-6 {
        extent.abs()
    } else {
        10.0
    }
}

/// World units per unit of the space `node`'s parameters live in (all Transforms above it),
/// or, for op `index` of a Transform node, the space that op acts in (the Transforms above
/// and the ops listed before it: M = op1 · op2 · …). The cube root of the volume scale:
/// one number for a possibly non-uniform scale.
pub fn world_per_unit(scene: &Scene, node: NodeId, op_index: Option<usize>) -> f32 {
    let g = &scene.graph;
    let Some(v) = walk::visit(g, node) else {
        return 1.0;
    };
    let mut m = v.world_from_parent.as_mat4();
    if let (Some(i), NodeKind::Transform(ops)) = (op_index, &v.node.kind) {
        m *= compose(ops.get(..i).unwrap_or(ops));
    }
    let s = m.determinant().abs().cbrt();
    if s.is_finite() && s > 1e-9 { s } else { 1.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(text: &str) -> Scene {
        let out = tracelab_core::parse_scene(
            text.as_bytes(),
            "t.txt",
            None,
            &mut tracelab_core::MeshCache::new(),
        );
        out.scene.expect("parses")
    }

    const SCALED: &str = "PerspectiveCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 angle 30 }
        Group { numObjects 1 Transform { UniformScale 5 Translate 1 0 0 Transform { Scale 1 2 4 Sphere { center 0 0 0 radius 1 } } } }";

    #[test]
    fn a_length_drags_by_a_share_of_the_view_in_its_own_space() {
        let s = scene(SCALED);
        let speeds = DragSpeeds::for_scene(&s);
        let extent = 2.0 * 10.0 * 15f32.to_radians().tan();
        assert!((speeds.length(1.0) - f64::from(extent / POINTS_PER_VIEW)).abs() < 1e-6);
        let outer = s
            .graph
            .iter()
            .find(|(_, n)| matches!(&n.kind, NodeKind::Transform(ops) if ops.len() == 2))
            .map(|(i, _)| i)
            .expect("outer");
        // The Translate comes after UniformScale 5: its units are 5 world units.
        assert!((world_per_unit(&s, outer, Some(1)) - 5.0).abs() < 1e-4);
        assert!((world_per_unit(&s, outer, Some(0)) - 1.0).abs() < 1e-4);
        // The sphere sits under both: 5 · cbrt(1·2·4) = 10.
        let sphere = s
            .graph
            .iter()
            .find(|(_, n)| matches!(n.kind, NodeKind::Sphere { .. }))
            .map(|(i, _)| i)
            .expect("sphere");
        assert!((world_per_unit(&s, sphere, None) - 10.0).abs() < 1e-3);
        // 60 points of drag move the Translate by a small share of the view, in world units.
        let moved = 60.0 * speeds.length(world_per_unit(&s, outer, Some(1))) * 5.0;
        assert!(moved < f64::from(extent) * 0.15, "{moved}");
    }

    #[test]
    fn factors_drag_by_their_own_size_and_degenerate_spaces_fall_back_to_one() {
        assert!((DragSpeeds::factor(100.0) / DragSpeeds::factor(1.0) - 100.0).abs() < 1e-3);
        assert!(DragSpeeds::factor(0.0) > 0.0 && DragSpeeds::factor(f32::NAN) > 0.0);
        let mut s = scene(
            "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 4 }
            Group { numObjects 1 Transform { Scale 1 1 1 Sphere { center 0 0 0 radius 1 } } }",
        );
        // Flattened by an edit (the parser refuses a singular transform, an edit may not yet).
        let t = s
            .graph
            .iter()
            .find(|(_, n)| matches!(n.kind, NodeKind::Transform(_)))
            .map(|(i, _)| i)
            .expect("transform");
        s.graph.node_mut(t).kind = NodeKind::Transform(vec![tracelab_core::TransformOp::Scale(
            glam::Vec3::new(1.0, 0.0, 1.0),
        )]);
        let sphere = s
            .graph
            .iter()
            .find(|(_, n)| matches!(n.kind, NodeKind::Sphere { .. }))
            .map(|(i, _)| i)
            .expect("sphere");
        assert_eq!(world_per_unit(&s, sphere, None), 1.0);
        assert!(
            (DragSpeeds::for_scene(&s).length(1.0) - f64::from(4.0 / POINTS_PER_VIEW)).abs() < 1e-6
        );
    }
}
