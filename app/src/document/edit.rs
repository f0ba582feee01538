//! Edits as commands. Panels emit them; [`crate::document::Document::apply`] is the one place
//! that carries them out (through [`apply_to`]) and records undo.

use super::error::Misfit;
use super::op_target::{OpKind, op_target};
use glam::Vec3;
use tracelab_core::{
    Background, Camera, Field, Graph, Light, Material, Node, NodeId, NodeKind, Place, Problem,
    Scene, TransformOp, check_scene,
};

#[derive(Clone, Debug, PartialEq)]
pub enum Edit {
    SetTransformOp {
        node: NodeId,
        index: usize,
        op: TransformOp,
    },
    AddOp {
        node: NodeId,
        op: TransformOp,
    },
    RemoveOp {
        node: NodeId,
        index: usize,
    },
    /// Moves op `from` to position `to` in the list.
    MoveOp {
        node: NodeId,
        from: usize,
        to: usize,
    },
    /// Replaces a primitive's parameters (a container keeps its children).
    SetNodeKind {
        node: NodeId,
        kind: NodeKind,
    },
    /// The `MaterialIndex` in effect from this node on (`None`: none of its own, so it
    /// continues the one before it in its list, or inherits its Group's).
    SetNodeMaterial {
        node: NodeId,
        material: Option<u32>,
    },
    /// Appends a new node to a Group (or to the Group holding the selected node).
    AddNode {
        parent: NodeId,
        kind: NodeKind,
    },
    DeleteNode {
        node: NodeId,
    },
    DuplicateNode {
        node: NodeId,
    },
    /// Moves a node into another Group, at `index` among its children.
    MoveNode {
        node: NodeId,
        new_parent: NodeId,
        index: usize,
    },
    WrapInTransform {
        node: NodeId,
    },
    WrapInGroup {
        node: NodeId,
    },
    /// Swaps a CSG node's two operands (A − B becomes B − A).
    SwapOperands {
        node: NodeId,
    },
    SetMaterial {
        index: usize,
        material: Material,
    },
    AddMaterial(Material),
    /// Removes a material; nodes using it fall back to the material around them, and later
    /// indices shift down so every other node keeps its colour.
    RemoveMaterial {
        index: usize,
    },
    SetCamera(Camera),
    AddLight(Light),
    RemoveLight {
        index: usize,
    },
    SetLight {
        index: usize,
        light: Light,
    },
    SetBackground(Background),
    /// A gizmo drag: sets the op of `op`'s kind (Translate, Scale or ZRotate) of the
    /// Transform that moves `node`, adding the op, or a Transform around the node, first
    /// when there is none (see `op_target`). The first edit of a drag adds; the following
    /// ones find what it added, so the whole drag is one undo step.
    SetOpOfKind {
        node: NodeId,
        op: TransformOp,
    },
}

/// Edits with the same key that follow each other (one drag) make a single undo step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CoalesceKey {
    Op(NodeId, usize),
    Kind(NodeId),
    Material(usize),
    Camera,
    Light(usize),
    Background,
    OpOfKind(NodeId, OpKind),
}

impl Edit {
    pub fn coalesce_key(&self) -> Option<CoalesceKey> {
        match self {
            Edit::SetTransformOp { node, index, .. } => Some(CoalesceKey::Op(*node, *index)),
            Edit::SetNodeKind { node, .. } => Some(CoalesceKey::Kind(*node)),
            Edit::SetMaterial { index, .. } => Some(CoalesceKey::Material(*index)),
            Edit::SetCamera(_) => Some(CoalesceKey::Camera),
            Edit::SetLight { index, .. } => Some(CoalesceKey::Light(*index)),
            Edit::SetBackground(_) => Some(CoalesceKey::Background),
            Edit::SetOpOfKind { node, op } => {
                OpKind::of(op).map(|k| CoalesceKey::OpOfKind(*node, k))
            }
            _ => None,
        }
    }
}

/// Why an edit was refused: the place and field it would have broken, so the inspector can
/// show the reason beside the widget of that [`Field`], and the reason itself.
#[derive(Clone, Debug, PartialEq)]
pub struct Refusal {
    /// `None` for an edit that does not fit the scene's structure (a stale id, a move into
    /// its own subtree).
    pub place: Option<Place>,
    /// `None` with no place.
    pub field: Option<Field>,
    /// For a Transform: the op at fault.
    pub op: Option<usize>,
    pub reason: String,
}

impl Refusal {
    fn structural(reason: String) -> Self {
        Refusal {
            place: None,
            field: None,
            op: None,
            reason,
        }
    }

    fn broken(p: &Problem) -> Self {
        Refusal {
            place: Some(p.place),
            field: Some(p.field.clone()),
            op: p.op,
            reason: p.reason.clone(),
        }
    }
}

impl std::fmt::Display for Refusal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.reason)
    }
}

/// Applies an edit to a copy of `scene` and holds the result to the core's validity rules
/// (the ones the parser and the checked writer apply): an edit that breaks one is refused,
/// and `scene` stays as it was. Leaving a node incomplete (a new TriangleMesh with no file
/// yet) is allowed; those problems come back with the new scene. `known` are the problems
/// `scene` already has, which an edit does not answer for.
pub fn apply_checked(
    scene: &Scene,
    known: &[Problem],
    edit: Edit,
) -> Result<(Scene, After, Vec<Problem>), Refusal> {
    let mut next = scene.clone();
    let after = apply_to(&mut next, edit).map_err(|m| Refusal::structural(m.0))?;
    let problems = check_scene(&next);
    if let Some(p) = problems
        .iter()
        .find(|p| !p.incomplete && !known.contains(p))
    {
        return Err(Refusal::broken(p));
    }
    Ok((next, after, problems))
}

/// What an applied edit wants selected afterwards.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum After {
    Keep,
    SelectNode(NodeId),
    ClearSelection,
}

/// Applies one edit to a scene. Never panics: an edit that does not fit the scene (a stale
/// id, an index out of range, a move into its own subtree) is an error and changes nothing.
pub fn apply_to(scene: &mut Scene, edit: Edit) -> Result<After, Misfit> {
    let g = &mut scene.graph;
    // What every node rendered with, for edits that must keep their neighbours' colours.
    let before = g.effective_materials();
    let parents = g.parents();
    let parent_of = |id: NodeId| parents.get(id.index()).copied().flatten();
    let root = g.root();
    let reachable = |id: NodeId| id == root || parent_of(id).is_some();
    // A stale id (a node deleted since the panel drew it) edits nothing: its arena slot is
    // out of the scene, and a value stored there could not be checked or saved.
    let target = match &edit {
        Edit::SetTransformOp { node, .. }
        | Edit::AddOp { node, .. }
        | Edit::RemoveOp { node, .. }
        | Edit::MoveOp { node, .. }
        | Edit::SetNodeKind { node, .. }
        | Edit::SetNodeMaterial { node, .. }
        | Edit::SwapOperands { node }
        | Edit::SetOpOfKind { node, .. } => Some(*node),
        _ => None,
    };
    if target.is_some_and(|id| !reachable(id)) {
        return Err("no such node in the scene".into());
    }
    match edit {
        Edit::SetTransformOp { node, index, op } => {
            let slot = transform_ops(g, node)?.get_mut(index).ok_or("no such op")?;
            *slot = op;
        }
        Edit::AddOp { node, op } => transform_ops(g, node)?.push(op),
        Edit::RemoveOp { node, index } => {
            let ops = transform_ops(g, node)?;
            if index >= ops.len() {
                return Err("no such op".into());
            }
            ops.remove(index);
            g.node_mut(node).comments.remove_op(index);
        }
        Edit::MoveOp { node, from, to } => {
            let ops = transform_ops(g, node)?;
            if from >= ops.len() || to >= ops.len() {
                return Err("no such op".into());
            }
            let op = ops.remove(from);
            ops.insert(to, op);
            g.node_mut(node).comments.move_op(from, to);
        }
        Edit::SetNodeKind { node, kind } => {
            let n = g.get_mut(node).ok_or("no such node")?;
            let csg_op_change = matches!((&n.kind, &kind), (NodeKind::Csg(_), NodeKind::Csg(_)));
            if matches!(kind, NodeKind::Triangle { .. })
                && parent_of(node).is_some_and(|p| matches!(g.node(p).kind, NodeKind::Csg(_)))
            {
                return Err("a lone Triangle is not a solid, so it cannot be a CSG operand".into());
            }
            let n = g.get_mut(node).ok_or("no such node")?;
            if !csg_op_change && (n.kind.is_container() || kind.is_container()) {
                return Err(
                    "only a primitive's parameters (or a CSG node's operation) can be replaced"
                        .into(),
                );
            }
            n.kind = kind;
        }
        Edit::SwapOperands { node } => {
            let n = g.get_mut(node).ok_or("no such node")?;
            if !matches!(n.kind, NodeKind::Csg(_)) || n.children.len() != 2 {
                return Err("only a CSG node's operands can be swapped".into());
            }
            n.children.swap(0, 1);
        }
        Edit::SetNodeMaterial { node, material } => {
            if node == g.root() {
                return Err("the root Group has no MaterialIndex".into());
            }
            g.get_mut(node).ok_or("no such node")?.material = material;
            if let Some(list) = parent_of(node) {
                keep_list_colours(g, list, &before, Some(node));
            }
        }
        Edit::AddNode { parent, kind } => {
            if !reachable(parent) || !matches!(g.node(parent).kind, NodeKind::Group) {
                return Err("new objects go into a Group".into());
            }
            let id = match kind {
                NodeKind::Transform(_) => {
                    // A Transform always holds one object: give it a unit sphere to start with.
                    let child = g.add(Node::new(NodeKind::Sphere {
                        center: Vec3::ZERO,
                        radius: 1.0,
                    }));
                    let t = g.add(Node::new(kind));
                    g.push_child(t, child);
                    t
                }
                NodeKind::Csg(_) => {
                    // A CSG node always holds two solids: a cube and a sphere poking out of
                    // its faces show each operation clearly.
                    let a = g.add(Node::new(NodeKind::Box {
                        min: Vec3::splat(-1.0),
                        max: Vec3::splat(1.0),
                    }));
                    let b = g.add(Node::new(NodeKind::Sphere {
                        center: Vec3::ZERO,
                        radius: 1.3,
                    }));
                    let c = g.add(Node::new(kind));
                    g.push_child(c, a);
                    g.push_child(c, b);
                    c
                }
                kind => g.add(Node::new(kind)),
            };
            // In the file, a Group's MaterialIndex holds for every object after it; give the
            // new last object that material, so it renders now as it will after a save.
            let sticky = g
                .node(parent)
                .children
                .iter()
                .rev()
                .find_map(|&c| g.node(c).material);
            g.node_mut(id).material = sticky;
            g.push_child(parent, id);
            return Ok(After::SelectNode(id));
        }
        Edit::DeleteNode { node } => {
            // Deleting one operand of a CSG node leaves the other one in its place, which is
            // what "A ∪ B without B" means.
            if let Some(csg) =
                parent_of(node).filter(|&p| matches!(g.node(p).kind, NodeKind::Csg(_)))
            {
                let other = *g
                    .node(csg)
                    .children
                    .iter()
                    .find(|&&c| c != node)
                    .ok_or("a CSG node needs two operands")?;
                let slot_parent = parent_of(csg).ok_or("not in the scene")?;
                // The comments above the CSG node described the slot the survivor now fills.
                let mut comments = g.node(csg).comments.before.clone();
                let o = g.node_mut(other);
                comments.append(&mut o.comments.before);
                o.comments.before = comments;
                // It keeps the material it rendered with, which it may have continued from
                // the other operand.
                o.material = before.get(other.index()).copied().flatten();
                for c in &mut g.node_mut(slot_parent).children {
                    if *c == csg {
                        *c = other;
                    }
                }
                settle_material(g, other, &before)?;
                return Ok(After::SelectNode(other));
            }
            let slot = group_slot(node, root, &parent_of, g)?;
            let parent = parent_of(slot).ok_or("not in the scene")?;
            g.node_mut(parent).children.retain(|&c| c != slot);
            keep_list_colours(g, parent, &before, None);
            return Ok(After::ClearSelection);
        }
        Edit::DuplicateNode { node } => {
            let slot = group_slot(node, root, &parent_of, g)?;
            let parent = parent_of(slot).ok_or("not in the scene")?;
            let copy = copy_subtree(g, slot);
            let at = g
                .node(parent)
                .children
                .iter()
                .position(|&c| c == slot)
                .map_or(0, |i| i + 1);
            g.insert_child(parent, at, copy);
            return Ok(After::SelectNode(copy));
        }
        Edit::MoveNode {
            node,
            new_parent,
            index,
        } => {
            let slot = group_slot(node, root, &parent_of, g)?;
            if !reachable(new_parent) || !matches!(g.node(new_parent).kind, NodeKind::Group) {
                return Err("objects move into a Group".into());
            }
            if g.preorder_from(slot).contains(&new_parent) {
                return Err("cannot move a node into itself".into());
            }
            let old_parent = parent_of(slot).ok_or("not in the scene")?;
            let old_index = g
                .node(old_parent)
                .children
                .iter()
                .position(|&c| c == slot)
                .unwrap_or(0);
            g.node_mut(old_parent).children.retain(|&c| c != slot);
            // Moving down within the same Group: the removal shifted the target left.
            let index = if old_parent == new_parent && index > old_index {
                index - 1
            } else {
                index
            };
            g.insert_child(new_parent, index, slot);
            // Moved or left behind, objects look as they did.
            keep_list_colours(g, old_parent, &before, None);
            keep_list_colours(g, new_parent, &before, None);
            return Ok(After::SelectNode(node));
        }
        Edit::WrapInTransform { node } | Edit::WrapInGroup { node } => {
            if node == g.root() {
                return Err("the root Group cannot be wrapped".into());
            }
            let parent = parent_of(node).ok_or("not in the scene")?;
            if matches!(edit, Edit::WrapInGroup { .. })
                && matches!(g.node(parent).kind, NodeKind::Csg(_))
            {
                return Err("a CSG operand must be a solid, and a Group is not one".into());
            }
            let kind = match edit {
                Edit::WrapInTransform { .. } => NodeKind::Transform(Vec::new()),
                _ => NodeKind::Group,
            };
            let mut wrapper = Node::new(kind);
            // The MaterialIndex stays in front of whatever now sits in the parent.
            wrapper.material = g.node_mut(node).material.take();
            // So do the comments above it.
            wrapper.comments.before = std::mem::take(&mut g.node_mut(node).comments.before);
            wrapper.children.push(node);
            let w = g.add(wrapper);
            for c in &mut g.node_mut(parent).children {
                if *c == node {
                    *c = w;
                }
            }
            return Ok(After::SelectNode(w));
        }
        Edit::SetMaterial { index, material } => {
            *scene.materials.get_mut(index).ok_or("no such material")? = material;
        }
        Edit::AddMaterial(m) => scene.materials.push(m),
        Edit::RemoveMaterial { index } => {
            if index >= scene.materials.len() {
                return Err("no such material".into());
            }
            // A texture's two materials are part of it: removing one would change what the
            // texture shows, so the texture goes first.
            if let Some(t) = scene.materials.iter().position(|m| {
                m.texture
                    .as_ref()
                    .is_some_and(|t| t.materials.contains(&(index as u32)))
            }) {
                return Err(format!("material {t}, a texture, uses material {index}").into());
            }
            scene.materials.remove(index);
            let index = index as u32;
            for t in scene
                .materials
                .iter_mut()
                .filter_map(|m| m.texture.as_mut())
            {
                for m in &mut t.materials {
                    if *m > index {
                        *m -= 1;
                    }
                }
            }
            for id in g.preorder() {
                let n = g.node_mut(id);
                n.material = match n.material {
                    Some(m) if m == index => None,
                    Some(m) if m > index => Some(m - 1),
                    other => other,
                };
            }
        }
        Edit::SetCamera(c) => scene.camera = c,
        Edit::AddLight(l) => scene.lights.get_or_insert_with(Vec::new).push(l),
        Edit::RemoveLight { index } => {
            let lights = scene.lights.as_mut().ok_or("no lights")?;
            if index >= lights.len() {
                return Err("no such light".into());
            }
            lights.remove(index);
        }
        Edit::SetLight { index, light } => {
            *scene
                .lights
                .as_mut()
                .and_then(|l| l.get_mut(index))
                .ok_or("no such light")? = light;
        }
        Edit::SetBackground(b) => scene.background = b,
        Edit::SetOpOfKind { node, op } => {
            let kind = OpKind::of(&op).ok_or("the gizmo drags Translate, Scale or ZRotate")?;
            let target = op_target(g, node, kind)?;
            let t = match target.transform {
                Some(t) => t,
                None => {
                    apply_to(scene, Edit::WrapInTransform { node })?;
                    let g = &scene.graph;
                    g.parents()
                        .get(node.index())
                        .copied()
                        .flatten()
                        .ok_or("not in the scene")?
                }
            };
            let g = &mut scene.graph;
            let ops = transform_ops(g, t)?;
            if target.exists {
                *ops.get_mut(target.index).ok_or("no such op")? = op;
            } else {
                let at = target.index.min(ops.len());
                let last = ops.len();
                ops.insert(at, op);
                // Comments of the ops after it stay with them.
                g.node_mut(t).comments.move_op(last, at);
            }
        }
    }
    Ok(After::Keep)
}

/// A MaterialIndex holds for the later objects of its list (see
/// [`Graph::list_materials`]), so an edit in `list` can change what an object there that sets
/// none continues. Spell out what it rendered with before (`before`: effective materials by
/// node index), so the edit changes only what it meant to. (One that rendered with the
/// default material cannot be spelt out: the file has no MaterialIndex for it.)
fn keep_list_colours(g: &mut Graph, list: NodeId, before: &[Option<u32>], except: Option<NodeId>) {
    if !matches!(
        g.get(list).map(|n| &n.kind),
        Some(NodeKind::Group | NodeKind::Csg(_))
    ) {
        return;
    }
    let now = g.effective_materials();
    for c in g.node(list).children.clone() {
        let was = before.get(c.index()).copied().flatten();
        if Some(c) != except
            && g.node(c).material.is_none()
            && was.is_some()
            && now.get(c.index()).copied().flatten() != was
        {
            g.node_mut(c).material = was;
        }
    }
}

/// `node`, just put in a new place, sets its own material; if that place is inside a
/// Transform, where no MaterialIndex can stand, the material moves up to the Transform the
/// chain hangs from, the one listed in a Group or CSG node, whose other objects keep theirs.
fn settle_material(g: &mut Graph, node: NodeId, before: &[Option<u32>]) -> Result<(), Misfit> {
    let parents = g.parents();
    let parent_of = |id: NodeId| parents.get(id.index()).copied().flatten();
    let listed = |g: &Graph, id: NodeId| {
        matches!(
            g.get(id).map(|n| &n.kind),
            Some(NodeKind::Group | NodeKind::Csg(_))
        )
    };
    let mut slot = node;
    let list = loop {
        let p = parent_of(slot).ok_or("not in the scene")?;
        if listed(g, p) {
            break p;
        }
        slot = p;
    };
    if slot == node {
        keep_list_colours(g, list, before, Some(node));
        return Ok(());
    }
    let want = g.node_mut(node).material.take();
    if want.is_some() && g.effective_materials().get(node.index()).copied().flatten() != want {
        g.node_mut(slot).material = want;
        keep_list_colours(g, list, before, Some(slot));
    }
    Ok(())
}

fn transform_ops(
    g: &mut tracelab_core::Graph,
    node: NodeId,
) -> Result<&mut Vec<TransformOp>, Misfit> {
    match g.get_mut(node).map(|n| &mut n.kind) {
        Some(NodeKind::Transform(ops)) => Ok(ops),
        _ => Err("not a Transform".into()),
    }
}

/// The node that stands for `node` inside a Group: itself, or the outermost of the
/// non-Group containers holding it. A Transform holds exactly one object (and a CSG node
/// exactly two), so deleting or moving one of those objects means deleting or moving the
/// container.
fn group_slot(
    node: NodeId,
    root: NodeId,
    parent_of: &dyn Fn(NodeId) -> Option<NodeId>,
    g: &tracelab_core::Graph,
) -> Result<NodeId, Misfit> {
    if node == root {
        return Err("the root Group cannot be moved or deleted".into());
    }
    let mut slot = node;
    loop {
        let p = parent_of(slot).ok_or("not in the scene")?;
        match g.get(p).map(|n| &n.kind) {
            Some(k) if k.is_container() && !matches!(k, NodeKind::Group) && p != root => slot = p,
            _ => return Ok(slot),
        }
    }
}

/// Copies a subtree into new arena slots; returns the copy's root.
fn copy_subtree(g: &mut tracelab_core::Graph, src: NodeId) -> NodeId {
    let order = g.preorder_from(src);
    let mut map = std::collections::HashMap::new();
    for &id in &order {
        let n = g.node(id).clone();
        map.insert(
            id,
            g.add(Node {
                children: Vec::new(),
                ..n
            }),
        );
    }
    for &id in &order {
        let kids: Vec<NodeId> = g.node(id).children.iter().map(|c| map[c]).collect();
        g.node_mut(map[&id]).children = kids;
    }
    map[&src]
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCENE: &str = "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 5 }
Materials { numMaterials 1 Material { diffuseColor 1 0 0 } }
Group {
    numObjects 2
    # the keeper
    Sphere { center 0 0 0 radius 1 }
    # the doomed one
    Transform {
        # first op
        Translate 1 0 0
        # second op
        Scale 1 2 1
        Sphere {
            # inside the doomed one
            center 0 0 0 radius 1
        }
    }
}
";

    fn parsed() -> Scene {
        let out = tracelab_core::parse_scene(
            SCENE.as_bytes(),
            "s.txt",
            None,
            &mut tracelab_core::MeshCache::new(),
        );
        out.scene.expect("parses")
    }

    fn node_of(scene: &Scene, kind: &str, nth: usize) -> NodeId {
        scene
            .graph
            .iter()
            .filter(|(_, n)| n.kind.name() == kind)
            .nth(nth)
            .map(|(id, _)| id)
            .expect("node")
    }

    fn written(scene: &Scene) -> String {
        tracelab_core::write_scene(scene)
    }

    #[test]
    fn a_deleted_node_takes_its_comments_with_it() {
        let mut s = parsed();
        let inner = node_of(&s, "Sphere", 1);
        apply_to(&mut s, Edit::DeleteNode { node: inner }).expect("deletes");
        let text = written(&s);
        assert!(text.contains("# the keeper"), "{text}");
        for gone in ["the doomed one", "first op", "inside the doomed one"] {
            assert!(!text.contains(gone), "{gone} survived:\n{text}");
        }
    }

    #[test]
    fn a_wrapped_node_s_comments_stay_in_front_of_the_wrapper() {
        let mut s = parsed();
        let keeper = node_of(&s, "Sphere", 0);
        apply_to(&mut s, Edit::WrapInGroup { node: keeper }).expect("wraps");
        let text = written(&s);
        assert!(text.contains("    # the keeper\n    Group {\n"), "{text}");
        let mut d = parsed();
        apply_to(&mut d, Edit::DuplicateNode { node: keeper }).expect("duplicates");
        assert_eq!(
            written(&d).matches("# the keeper").count(),
            2,
            "a copy carries its comments"
        );
    }

    #[test]
    fn op_comments_follow_their_ops() {
        let mut s = parsed();
        let t = node_of(&s, "Transform", 0);
        apply_to(
            &mut s,
            Edit::MoveOp {
                node: t,
                from: 0,
                to: 1,
            },
        )
        .expect("moves");
        assert!(written(&s).contains("        # second op\n        Scale 1 2 1\n        # first op\n        Translate 1 0 0\n"), "{}", written(&s));
        apply_to(&mut s, Edit::RemoveOp { node: t, index: 0 }).expect("removes");
        let text = written(&s);
        assert!(
            !text.contains("second op")
                && text.contains("        # first op\n        Translate 1 0 0\n"),
            "{text}"
        );
    }

    #[test]
    fn a_material_a_texture_uses_is_not_removed_and_later_texture_indices_shift() {
        let text = "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 5 }
Materials { numMaterials 4 Material { diffuseColor 1 1 1 } Material { diffuseColor 1 0 0 } Material { diffuseColor 0 0 1 }
Checkerboard { materialIndex 1 materialIndex 2 } }
Group { numObjects 1 MaterialIndex 3 Plane { normal 0 1 0 offset 0 } }
";
        let mut s = tracelab_core::parse_scene(
            text.as_bytes(),
            "s.txt",
            None,
            &mut tracelab_core::MeshCache::new(),
        )
        .scene
        .expect("parses");
        let refused = apply_to(&mut s, Edit::RemoveMaterial { index: 2 });
        assert!(
            refused.is_err_and(|m| m.0 == "material 3, a texture, uses material 2"),
            "refused"
        );
        apply_to(&mut s, Edit::RemoveMaterial { index: 0 }).expect("removes");
        let t = s.materials[2].texture.as_ref().expect("still a texture");
        assert_eq!(t.materials, [0, 1]);
        assert!(tracelab_core::check_scene(&s).is_empty());
        assert!(
            written(&s)
                .contains("Checkerboard {\n        materialIndex 0\n        materialIndex 1\n")
        );
    }

    #[test]
    fn deleting_or_moving_a_node_keeps_the_colour_its_list_neighbour_continued() {
        let text = "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 5 }
Materials { numMaterials 3 Material { diffuseColor 1 0 0 } Material { diffuseColor 0 1 0 } Material { diffuseColor 0 0 1 } }
Group { numObjects 3 MaterialIndex 1 Sphere { center -2 0 0 radius 1 } MaterialIndex 2 Sphere { center 0 0 0 radius 1 } Sphere { center 2 0 0 radius 1 } }
";
        let mut s = tracelab_core::parse_scene(
            text.as_bytes(),
            "s.txt",
            None,
            &mut tracelab_core::MeshCache::new(),
        )
        .scene
        .expect("parses");
        let [_, d, b] = s.graph.node(s.graph.root()).children[..] else {
            panic!("three spheres")
        };
        // B sets none of its own: it continues D's Material 2.
        apply_to(
            &mut s,
            Edit::SetNodeMaterial {
                node: b,
                material: None,
            },
        )
        .expect("applies");
        assert_eq!(s.graph.effective_materials()[b.index()], Some(2));
        let mut moved = s.clone();
        apply_to(&mut s, Edit::DeleteNode { node: d }).expect("deletes");
        assert_eq!(
            s.graph.effective_materials()[b.index()],
            Some(2),
            "B would have continued Material 1"
        );
        let root = moved.graph.root();
        apply_to(
            &mut moved,
            Edit::MoveNode {
                node: d,
                new_parent: root,
                index: usize::MAX,
            },
        )
        .expect("moves");
        let m = moved.graph.effective_materials();
        assert_eq!((m[b.index()], m[d.index()]), (Some(2), Some(2)));
    }

    #[test]
    fn deleting_a_csg_operand_keeps_the_comments_above_the_csg_node() {
        let text = SCENE.replace("numObjects 2", "numObjects 3\n    # the union\n    Union { Sphere { center 0 0 0 radius 1 } Box { min 0 0 0 max 1 1 1 } }");
        let mut s = tracelab_core::parse_scene(
            text.as_bytes(),
            "s.txt",
            None,
            &mut tracelab_core::MeshCache::new(),
        )
        .scene
        .expect("parses");
        let b = node_of(&s, "Box", 0);
        apply_to(&mut s, Edit::DeleteNode { node: b }).expect("deletes");
        assert!(
            written(&s).contains("    # the union\n    Sphere {"),
            "{}",
            written(&s)
        );
    }
}
