//! The rules about the object graph as a whole: child counts, CSG operands that are
//! solids, MaterialIndex in range and in place, and every Transform's chain.

use glam::DMat4;

use super::super::field::Field;
use super::super::walk::Walk;
use super::super::{Graph, NodeId, NodeKind};
use super::{Invalid, Place, Problem, check_kind, check_world_from_object, fits_f32};

/// Whether `id` bounds a solid (a CSG operand): Transforms are followed to what they move.
pub fn is_solid(graph: &Graph, id: NodeId) -> bool {
    not_a_solid(graph, id).is_none() && !ends_in_empty_transform(graph, id)
}

/// The object at the end of `id`'s Transforms, when it is not a solid: a Triangle or a
/// Group. A Transform holding nothing is judged by its own rule, not here.
fn not_a_solid(graph: &Graph, id: NodeId) -> Option<NodeId> {
    let mut cur = id;
    loop {
        let node = graph.get(cur)?;
        match &node.kind {
            NodeKind::Transform(_) => cur = *node.children.first()?,
            NodeKind::Triangle { .. } | NodeKind::Group => return Some(cur),
            _ => return None,
        }
    }
}

fn ends_in_empty_transform(graph: &Graph, id: NodeId) -> bool {
    let mut cur = id;
    while let Some(n) = graph.get(cur) {
        match (&n.kind, n.children.first()) {
            (NodeKind::Transform(_), Some(&c)) => cur = c,
            (NodeKind::Transform(_), None) => return true,
            _ => return false,
        }
    }
    true
}

/// A MaterialIndex (as written: a file may give one past `u32`) against the scene's
/// materials.
pub fn check_material_index(index: u64, n_materials: usize) -> Result<(), Invalid> {
    if index < n_materials as u64 {
        return Ok(());
    }
    let range = if n_materials == 0 {
        "the scene has no materials".to_string()
    } else {
        format!("valid indices are 0 to {}", n_materials - 1)
    };
    Err(Invalid::new(
        Field::MaterialIndex,
        format!("MaterialIndex {index} is out of range: {range}"),
    ))
}

/// Rules about the object graph: each node's parameters, Transform and CSG child counts,
/// CSG operands that are solids, materials in range and placed where the file can say
/// them, and every Transform's world-from-object matrix composed through its whole chain
/// (not below a node whose own parameters are already at fault).
pub fn check_graph(graph: &Graph, n_materials: usize) -> Vec<Problem> {
    let mut out = Vec::new();
    // Nodes whose own parameters break a rule: their chain says the same thing again.
    let mut own = std::collections::HashSet::new();
    // Every Transform's world-from-object matrix, composed in f64 through its whole chain
    // of ancestors, in the same walk; only the outermost failing Transform of a chain is
    // reported (`below`: its depth, while the walk is inside it).
    let mut chain = Vec::new();
    let mut below: Option<usize> = None;
    for v in Walk::new(graph) {
        let (id, node, parent) = (v.id, v.node, v.parent);
        let own_verdict = check_kind(&node.kind);
        // A Transform right under the world whose own ops pass: its chain is those ops,
        // already judged singular or not, so only f32's range is left (the load of a
        // scene of many placed objects does not pay for the same test twice).
        let chain_is_own = own_verdict.is_ok() && v.world_from_parent == DMat4::IDENTITY;
        if below.is_some_and(|d| v.depth > d) {
            // Inside a chain already reported.
        } else if let NodeKind::Transform(_) = &node.kind
            && let Err(e) = if chain_is_own {
                fits_f32(&v.world_from_object)
            } else {
                check_world_from_object(&v.world_from_object)
            }
        {
            let message = e.to_string();
            chain.push(Problem {
                place: Place::Node(id),
                field: Field::Ops,
                op: None,
                reason: message.clone(),
                message,
                incomplete: false,
            });
            below = Some(v.depth);
        } else {
            below = None;
        }
        let name = node.kind.name();
        let mut push = |field: Field, op: Option<usize>, reason: String, incomplete: bool| {
            // "Sphere (node #4): radius …", not "Sphere (node #4): Sphere: radius …".
            let rest = reason
                .strip_prefix(name)
                .and_then(|r| r.strip_prefix(": "))
                .unwrap_or(&reason);
            out.push(Problem {
                place: Place::Node(id),
                field,
                op,
                message: format!("{name} (node #{}): {rest}", id.0),
                reason: reason.clone(),
                incomplete,
            })
        };
        if let Err(e) = own_verdict {
            own.insert(Place::Node(id));
            push(e.field, e.op, e.message, e.incomplete);
        }
        if let Some(m) = node.material {
            let parent_kind = parent.and_then(|p| graph.get(p)).map(|p| &p.kind);
            if !matches!(parent_kind, Some(NodeKind::Group | NodeKind::Csg(_))) {
                let m = format!(
                    "MaterialIndex {m} can only be set on an object listed in a Group or CSG node"
                );
                push(Field::MaterialIndex, None, m, false);
            }
            if let Err(e) = check_material_index(u64::from(m), n_materials) {
                push(e.field, None, e.message, false);
            }
        }
        match &node.kind {
            NodeKind::Transform(_) if node.children.is_empty() => {
                let m = "Transform needs one object after its operations".to_string();
                push(Field::Children, None, m, false);
            }
            NodeKind::Transform(_) => {
                for &c in &node.children[1..] {
                    let m = "a Transform holds exactly one object; this is a second (wrap them \
                             in a Group)";
                    push(Field::Child(c), None, m.into(), false);
                }
            }
            NodeKind::Csg(op) => {
                let op = op.name();
                let n = node.children.len();
                if n != 2 {
                    let m = format!(
                        "{op} needs exactly two operand objects (nest them for more), found {n}"
                    );
                    push(Field::Children, None, m, false);
                }
                for &c in &node.children {
                    let Some(at) = not_a_solid(graph, c) else {
                        continue;
                    };
                    let m = match graph.get(at).map(|n| &n.kind) {
                        Some(NodeKind::Group) => format!(
                            "a Group cannot be an operand of {op}: operands are solids (Sphere, \
                             Box, Plane, closed TriangleMesh, a Transform of one, or Union, \
                             Intersection, Subtraction); combine several with Union"
                        ),
                        _ => format!(
                            "a lone Triangle is not a solid, so it cannot be an operand of {op} \
                             (use a closed TriangleMesh)"
                        ),
                    };
                    push(Field::Child(at), None, m, false);
                }
            }
            _ => {}
        }
    }
    out.extend(
        chain
            .into_iter()
            .filter(|p| !own.contains(&p.place))
            .map(|p| Problem {
                message: format!(
                    "Transform (node #{}): {}",
                    p.node().map_or(0, |n| n.0),
                    p.message
                ),
                ..p
            }),
    );
    out
}
