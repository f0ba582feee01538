//! The one walk down the object graph: each node with the world-from-object matrix composed
//! above it (in f64, as the renderer composes it), the material in effect there and its
//! depth. Compile, CSG, the pixel story, the rules and the editor all read the tree through
//! it, so the order of composition and the material a list continues are written once.
//!
//! The walk keeps one entry per open container (not one per pending child), so a Group of a
//! million spheres costs one matrix of memory, and deep nesting no call stack.

use glam::{DMat4, Vec3};

use super::{Graph, Node, NodeId, NodeKind, compose_f64};
use crate::geometry::{Aabb, sphere_bounds};

/// One node as the walk reaches it.
#[derive(Clone, Copy, Debug)]
pub struct Visit<'a> {
    pub id: NodeId,
    pub node: &'a Node,
    /// World from the space the node sits in: every Transform above it, not its own ops.
    pub world_from_parent: DMat4,
    /// World from the node's own space: `world_from_parent`, times its ops for a Transform.
    /// What its geometry (or its children) is written in.
    pub world_from_object: DMat4,
    /// The material in effect at the node (its own MaterialIndex or the one it inherits).
    pub material: Option<u32>,
    /// 0 for the walk's first node.
    pub depth: usize,
    /// The node's position among its parent's children (0 for the walk's first node).
    pub index: usize,
    /// The node it was reached from (`None` for the walk's first node).
    pub parent: Option<NodeId>,
}

impl<'a> Visit<'a> {
    fn new(
        graph: &'a Graph,
        id: NodeId,
        world_from_parent: DMat4,
        inherited: Option<u32>,
        depth: usize,
        index: usize,
        parent: Option<NodeId>,
    ) -> Option<Self> {
        let node = graph.get(id)?;
        let world_from_object = match &node.kind {
            NodeKind::Transform(ops) => world_from_parent * compose_f64(ops),
            _ => world_from_parent,
        };
        Some(Visit {
            id,
            node,
            world_from_parent,
            world_from_object,
            material: node.material.or(inherited),
            depth,
            index,
            parent,
        })
    }
}

/// An open container: which child comes next, and what it inherits.
struct Level<'a> {
    id: NodeId,
    node: &'a Node,
    next: usize,
    world: DMat4,
    /// The material the next child inherits when it sets none.
    running: Option<u32>,
    /// In a Group's or CSG node's list a child's MaterialIndex holds for the later ones too
    /// (see [`Graph::list_materials`]); a Transform's one child only inherits.
    listed: bool,
    depth: usize,
}

/// Parents before children, children in order (the order of [`Graph::preorder`]); ids that
/// are not in the graph are passed over.
pub struct Walk<'a> {
    graph: &'a Graph,
    stack: Vec<Level<'a>>,
    first: Option<Visit<'a>>,
    /// The last node yielded, whose children come next unless skipped.
    pending: Option<Visit<'a>>,
}

impl<'a> Walk<'a> {
    /// The whole graph from its root.
    pub fn new(graph: &'a Graph) -> Self {
        Self::from_node(graph, graph.root(), DMat4::IDENTITY, None)
    }

    /// The subtree under `start`, which sits in `world_from_parent` and inherits `material`.
    pub fn from_node(
        graph: &'a Graph,
        start: NodeId,
        world_from_parent: DMat4,
        material: Option<u32>,
    ) -> Self {
        Walk {
            graph,
            stack: Vec::new(),
            first: Visit::new(graph, start, world_from_parent, material, 0, 0, None),
            pending: None,
        }
    }

    /// Does not enter the children of the node last yielded.
    pub fn skip_children(&mut self) {
        self.pending = None;
    }
}

impl<'a> Iterator for Walk<'a> {
    type Item = Visit<'a>;

    fn next(&mut self) -> Option<Visit<'a>> {
        if let Some(v) = self.first.take() {
            self.pending = Some(v);
            return Some(v);
        }
        if let Some(p) = self.pending.take()
            && !p.node.children.is_empty()
        {
            self.stack.push(Level {
                id: p.id,
                node: p.node,
                next: 0,
                world: p.world_from_object,
                running: p.material,
                listed: matches!(p.node.kind, NodeKind::Group | NodeKind::Csg(_)),
                depth: p.depth + 1,
            });
        }
        loop {
            let level = self.stack.last_mut()?;
            let Some(&c) = level.node.children.get(level.next) else {
                self.stack.pop();
                continue;
            };
            let index = level.next;
            level.next += 1;
            let inherited = level.running;
            let parent = Some(level.id);
            let Some(v) = Visit::new(
                self.graph,
                c,
                level.world,
                inherited,
                level.depth,
                index,
                parent,
            ) else {
                continue;
            };
            if level.listed && v.node.material.is_some() {
                level.running = v.node.material;
            }
            self.pending = Some(v);
            return Some(v);
        }
    }
}

impl Graph {
    /// The material each reachable node renders with (`None`: the default material).
    /// (Here rather than in graph.rs: it is the walk's, and graph.rs does not import it.)
    pub fn effective_materials(&self) -> Vec<Option<u32>> {
        let mut out = vec![None; self.capacity_len()];
        for v in Walk::new(self) {
            out[v.id.index()] = v.material;
        }
        out
    }
}

/// The nodes from the root down to `target` (inclusive) as the walk reaches them, or `None`
/// when it is not reachable.
pub fn path<'a>(graph: &'a Graph, target: NodeId) -> Option<Vec<Visit<'a>>> {
    let ids = graph.path_to(target)?;
    let mut out: Vec<Visit<'a>> = Vec::with_capacity(ids.len());
    for (depth, &id) in ids.iter().enumerate() {
        let v = match out.last() {
            None => Visit::new(graph, id, DMat4::IDENTITY, None, 0, 0, None)?,
            Some(parent) => {
                let node = parent.node;
                let index = node.children.iter().position(|&c| c == id)?;
                let inherited = graph
                    .list_materials(node, parent.material)
                    .get(index)
                    .map_or(parent.material, |l| l.1);
                let m = parent.world_from_object;
                Visit::new(graph, id, m, inherited, depth, index, Some(parent.id))?
            }
        };
        out.push(v);
    }
    Some(out)
}

/// `target` as the walk from the root reaches it.
pub fn visit(graph: &Graph, target: NodeId) -> Option<Visit<'_>> {
    path(graph, target)?.pop()
}

/// The object-space box of a primitive: infinite for a plane, `None` for a container or a
/// mesh not loaded.
pub fn local_bounds(kind: &NodeKind) -> Option<Aabb> {
    Some(match kind {
        NodeKind::Sphere { center, radius } => sphere_bounds(*center, *radius),
        NodeKind::Plane { .. } => Aabb::new(Vec3::NEG_INFINITY, Vec3::INFINITY),
        NodeKind::Triangle { vertices } => Aabb::from_points(vertices),
        NodeKind::TriangleMesh { mesh, .. } => mesh.mesh()?.bounds(),
        NodeKind::Box { min, max } => Aabb::new(*min, *max),
        NodeKind::Group | NodeKind::Transform(_) | NodeKind::Csg(_) => return None,
    })
}

/// The world box of everything with finite bounds under `node` (planes have none): each
/// primitive's box through its world-from-object matrix, corner by corner. `None` when
/// there is nothing to bound or `node` is not in the scene.
pub fn world_bounds(graph: &Graph, node: NodeId) -> Option<Aabb> {
    let start = visit(graph, node)?;
    let mut acc = Aabb::EMPTY;
    for v in Walk::from_node(graph, node, start.world_from_parent, start.material) {
        let Some(local) = local_bounds(&v.node.kind) else {
            continue;
        };
        if !local.is_finite() || local.is_empty() {
            continue;
        }
        let m = v.world_from_object.as_mat4();
        // Corner by corner, so one corner that overflows drops out alone.
        for i in 0..8 {
            let corner = Vec3::new(
                if i & 1 == 0 { local.min.x } else { local.max.x },
                if i & 2 == 0 { local.min.y } else { local.max.y },
                if i & 4 == 0 { local.min.z } else { local.max.z },
            );
            let p = m.transform_point3(corner);
            if p.is_finite() {
                acc = acc.grow(p);
            }
        }
    }
    (!acc.is_empty()).then_some(acc)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::TransformOp;

    /// Root Group { MaterialIndex 1 Transform { Sphere } ; Sphere ; MaterialIndex 2 Box }.
    fn graph() -> (Graph, [NodeId; 4]) {
        let mut g = Graph::new();
        let mut t = Node::new(NodeKind::Transform(vec![TransformOp::Translate(Vec3::X)]));
        t.material = Some(1);
        let t = g.add(t);
        let s1 = g.add(Node::new(NodeKind::Sphere {
            center: Vec3::ZERO,
            radius: 1.0,
        }));
        g.push_child(t, s1);
        let s2 = g.add(Node::new(NodeKind::Sphere {
            center: Vec3::ZERO,
            radius: 1.0,
        }));
        let mut b = Node::new(NodeKind::Box {
            min: Vec3::ZERO,
            max: Vec3::ONE,
        });
        b.material = Some(2);
        let b = g.add(b);
        let root = g.root();
        g.push_child(root, t);
        g.push_child(root, s2);
        g.push_child(root, b);
        (g, [t, s1, s2, b])
    }

    #[test]
    fn the_walk_is_preorder_with_composed_matrices_and_listed_materials() {
        let (g, [t, s1, s2, b]) = graph();
        let seen: Vec<_> = Walk::new(&g).collect();
        let ids: Vec<_> = seen.iter().map(|v| v.id).collect();
        assert_eq!(ids, g.preorder());
        assert_eq!(ids, vec![g.root(), t, s1, s2, b]);
        let at = |id| seen.iter().find(|v| v.id == id).copied().expect("seen");
        assert_eq!(at(t).world_from_parent, DMat4::IDENTITY);
        assert_eq!(
            at(t).world_from_object,
            DMat4::from_translation(glam::DVec3::X)
        );
        assert_eq!(at(s1).world_from_object, at(t).world_from_object);
        assert_eq!(at(s2).world_from_object, DMat4::IDENTITY);
        // The list's MaterialIndex 1 holds for the later sphere; the box sets its own.
        let mats: Vec<_> = seen.iter().map(|v| v.material).collect();
        assert_eq!(mats, vec![None, Some(1), Some(1), Some(1), Some(2)]);
        assert_eq!(
            mats,
            ids.iter()
                .map(|id| g.effective_materials()[id.index()])
                .collect::<Vec<_>>()
        );
        assert_eq!(
            seen.iter().map(|v| v.depth).collect::<Vec<_>>(),
            [0, 1, 2, 1, 1]
        );
    }

    #[test]
    fn path_and_visit_agree_with_the_walk() {
        let (g, [_, s1, s2, _]) = graph();
        for v in Walk::new(&g) {
            let p = visit(&g, v.id).expect("reachable");
            assert_eq!(
                (p.world_from_object, p.material, p.depth, p.index, p.parent),
                (v.world_from_object, v.material, v.depth, v.index, v.parent)
            );
        }
        assert_eq!(path(&g, s1).expect("path").len(), 3);
        let detached = {
            let mut g = g.clone();
            let d = g.add(Node::new(NodeKind::Group));
            (visit(&g, d).is_none(), visit(&g, s2).is_some())
        };
        assert_eq!(detached, (true, true));
    }

    #[test]
    fn skipped_children_are_not_entered() {
        let (g, [t, _, s2, b]) = graph();
        let mut walk = Walk::new(&g);
        let mut ids = Vec::new();
        while let Some(v) = walk.next() {
            if v.id == t {
                walk.skip_children();
            }
            ids.push(v.id);
        }
        assert_eq!(ids, vec![g.root(), t, s2, b]);
    }

    #[test]
    fn world_bounds_cover_transformed_primitives_and_ignore_planes() {
        let (mut g, [t, ..]) = graph();
        let p = g.add(Node::new(NodeKind::Plane {
            normal: Vec3::Y,
            offset: 0.0,
        }));
        let root = g.root();
        g.push_child(root, p);
        let all = world_bounds(&g, root).expect("bounded");
        assert_eq!(
            (all.min, all.max),
            (Vec3::splat(-1.0), Vec3::new(2.0, 1.0, 1.0))
        );
        let one = world_bounds(&g, t).expect("bounded");
        assert_eq!(
            (one.min, one.max),
            (Vec3::new(0.0, -1.0, -1.0), Vec3::new(2.0, 1.0, 1.0))
        );
        assert_eq!(world_bounds(&g, p), None);
    }
}
