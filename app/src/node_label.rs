//! A node's one-line summary, as the scene tree and the pixel's story (`inspect`, `diff`,
//! the pixel inspector) show it.

use glam::Vec3;
use tracelab_core::{CsgOp, MeshSlot, NodeKind, TransformOp};

/// A short summary of a node (its tree row, its step in a pixel's story).
pub fn node_label(kind: &NodeKind, children: usize) -> String {
    let v = |v: Vec3| format!("{}, {}, {}", v.x, v.y, v.z);
    match kind {
        NodeKind::Group => format!("Group ({children})"),
        NodeKind::Transform(ops) if ops.is_empty() => "Transform: identity".into(),
        NodeKind::Transform(ops) => {
            format!(
                "Transform: {}",
                ops.iter()
                    .map(TransformOp::summary)
                    .collect::<Vec<_>>()
                    .join(" · ")
            )
        }
        NodeKind::Sphere { center, radius } => format!("Sphere: ({}) r {radius}", v(*center)),
        NodeKind::Plane { normal, offset } => format!("Plane: n ({}) d {offset}", v(*normal)),
        NodeKind::Triangle { .. } => "Triangle".into(),
        NodeKind::TriangleMesh { obj_file, mesh } => match mesh {
            MeshSlot::Loaded(m) => {
                format!("TriangleMesh: {obj_file} ({} tris)", m.triangle_count())
            }
            MeshSlot::Failed(_) | MeshSlot::Unresolved => {
                format!("TriangleMesh: {obj_file} (not loaded)")
            }
        },
        NodeKind::Box { min, max } => format!("Box: ({}) to ({})", v(*min), v(*max)),
        NodeKind::Csg(op) => {
            // Words, not ∪ ∩ −: egui's default fonts have no glyphs for them.
            let what = match op {
                CsgOp::Union => "A or B",
                CsgOp::Intersection => "A and B",
                CsgOp::Subtraction => "A minus B",
            };
            format!("{}: {what}", op.name())
        }
    }
}
