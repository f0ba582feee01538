//! Which Transform op a handle in the render view edits: the op of that kind in the
//! Transform that moves the node (the node itself when it is a Transform, else its
//! Transform parent), added in the lecture's order (Translate · ZRotate · Scale, as T·R·S)
//! when the list has none, in a new Transform around the node when it has no Transform
//! parent.

use tracelab_core::{Graph, NodeId, NodeKind, TransformOp};

/// The kinds of op the gizmo drags: the lecture's Translate, Scale and ZRotate.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum OpKind {
    Translate,
    Scale,
    ZRotate,
}

impl OpKind {
    pub fn of(op: &TransformOp) -> Option<OpKind> {
        match op {
            TransformOp::Translate(_) => Some(OpKind::Translate),
            TransformOp::Scale(_) => Some(OpKind::Scale),
            TransformOp::ZRotate(_) => Some(OpKind::ZRotate),
            _ => None,
        }
    }

    /// The op that changes nothing, the value a drag starts from when there is none yet.
    pub fn identity(self) -> TransformOp {
        match self {
            OpKind::Translate => TransformOp::Translate(glam::Vec3::ZERO),
            OpKind::Scale => TransformOp::Scale(glam::Vec3::ONE),
            OpKind::ZRotate => TransformOp::ZRotate(0.0),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            OpKind::Translate => "Translate",
            OpKind::Scale => "Scale",
            OpKind::ZRotate => "ZRotate",
        }
    }
}

/// Where the op lives, or will.
#[derive(Clone, Debug, PartialEq)]
pub struct OpTarget {
    /// The Transform holding it; `None`: a new Transform around the node.
    pub transform: Option<NodeId>,
    /// Its index in that Transform's list (after inserting, if it is not there yet).
    pub index: usize,
    /// Whether the op is there already.
    pub exists: bool,
    /// The Transform's ops as they are now (empty for a new Transform).
    pub ops: Vec<TransformOp>,
}

impl OpTarget {
    /// What the status bar says when the drag adds something; `None` when nothing is added.
    pub fn added(&self, kind: OpKind, node_name: &str) -> Option<String> {
        match (self.transform, self.exists) {
            (_, true) => None,
            (None, _) => Some(format!(
                "wrapped the {node_name} in a new Transform with {}",
                kind.name()
            )),
            (Some(_), false) => Some(format!(
                "added {} as op {} of the Transform",
                kind.name(),
                self.index + 1
            )),
        }
    }

    /// The ops before the dragged one: they act after it, so they decide how its change
    /// moves the object (`world · before · op · after`).
    pub fn before(&self) -> &[TransformOp] {
        self.ops.get(..self.index).unwrap_or(&[])
    }
}

/// Finds the op `kind` for `node` in `g` (see the module comment).
pub fn op_target(g: &Graph, node: NodeId, kind: OpKind) -> Result<OpTarget, super::error::Misfit> {
    let parents = g.parents();
    if node != g.root() && parents.get(node.index()).copied().flatten().is_none() {
        return Err("no such node in the scene".into());
    }
    if node == g.root() {
        return Err("the root Group has no Transform to edit".into());
    }
    let parent = parents.get(node.index()).copied().flatten();
    let transform = match &g.node(node).kind {
        NodeKind::Transform(_) => Some(node),
        _ => parent.filter(|&p| matches!(g.node(p).kind, NodeKind::Transform(_))),
    };
    let ops = match transform.map(|t| &g.node(t).kind) {
        Some(NodeKind::Transform(ops)) => ops.clone(),
        _ => Vec::new(),
    };
    if let Some(i) = ops.iter().position(|o| OpKind::of(o) == Some(kind)) {
        return Ok(OpTarget {
            transform,
            index: i,
            exists: true,
            ops,
        });
    }
    // T · R · S: the translation outermost (first listed, applied last), in the space
    // around the Transform; the rotation after the leading translations; the scale last.
    let index = match kind {
        OpKind::Translate => 0,
        OpKind::ZRotate => ops
            .iter()
            .take_while(|o| matches!(o, TransformOp::Translate(_)))
            .count(),
        OpKind::Scale => ops.len(),
    };
    Ok(OpTarget {
        transform,
        index,
        exists: false,
        ops,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use tracelab_core::Node;

    fn chain(ops: Vec<TransformOp>) -> (Graph, NodeId, NodeId) {
        let mut g = Graph::new();
        let s = g.add(Node::new(NodeKind::Sphere {
            center: Vec3::ZERO,
            radius: 1.0,
        }));
        let t = g.add(Node::new(NodeKind::Transform(ops)));
        g.push_child(t, s);
        let root = g.root();
        g.push_child(root, t);
        (g, t, s)
    }

    #[test]
    fn missing_ops_go_in_t_r_s_order_and_existing_ones_are_found() {
        let (g, t, s) = chain(vec![
            TransformOp::Translate(Vec3::X),
            TransformOp::UniformScale(2.0),
        ]);
        let r = op_target(&g, s, OpKind::ZRotate).expect("target");
        assert_eq!((r.transform, r.index, r.exists), (Some(t), 1, false));
        let sc = op_target(&g, t, OpKind::Scale).expect("target");
        assert_eq!((sc.index, sc.exists), (2, false));
        let tr = op_target(&g, s, OpKind::Translate).expect("target");
        assert_eq!((tr.index, tr.exists), (0, true));
        let (g, _, s) = chain(vec![TransformOp::Scale(Vec3::ONE * 2.0)]);
        assert_eq!(
            op_target(&g, s, OpKind::Translate).expect("target").index,
            0
        );
    }

    #[test]
    fn a_node_without_a_transform_parent_gets_a_new_one() {
        let mut g = Graph::new();
        let s = g.add(Node::new(NodeKind::Sphere {
            center: Vec3::ZERO,
            radius: 1.0,
        }));
        let root = g.root();
        g.push_child(root, s);
        let r = op_target(&g, s, OpKind::Translate).expect("target");
        assert_eq!((r.transform, r.index, r.exists), (None, 0, false));
        assert!(
            r.added(OpKind::Translate, "Sphere")
                .expect("says")
                .contains("new Transform")
        );
        assert!(op_target(&g, root, OpKind::Translate).is_err());
    }
}
