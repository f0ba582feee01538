//! The object graph as an arena: nodes live in one `Vec` and refer to their children by id.
//! An arena keeps drop, clone, comparison and every walk iterative, so a file with tens of
//! thousands of nested Groups cannot overflow the stack, and ids give the GUI stable handles.

use glam::Vec3;

use super::{Comments, MeshSlot, TransformOp};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct NodeId(pub u32);

impl NodeId {
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum NodeKind {
    Group,
    /// Ops as listed in the file: M = op1 · op2 · … · opn, so the first listed is applied last.
    Transform(Vec<TransformOp>),
    Sphere {
        center: Vec3,
        radius: f32,
    },
    /// Points p with normal · p = offset.
    Plane {
        normal: Vec3,
        offset: f32,
    },
    Triangle {
        vertices: [Vec3; 3],
    },
    TriangleMesh {
        obj_file: String,
        mesh: MeshSlot,
    },
    /// An axis-aligned box in object space (an extension: it rotates and shears under a
    /// Transform).
    Box {
        min: Vec3,
        max: Vec3,
    },
    /// Constructive solid geometry over exactly two operand solids (an extension).
    Csg(CsgOp),
}

/// How a CSG node combines its two operands A and B.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CsgOp {
    Union,
    Intersection,
    /// A minus B.
    Subtraction,
}

impl CsgOp {
    pub const ALL: [CsgOp; 3] = [CsgOp::Union, CsgOp::Intersection, CsgOp::Subtraction];

    /// The keyword in scene files.
    pub fn name(self) -> &'static str {
        match self {
            CsgOp::Union => "Union",
            CsgOp::Intersection => "Intersection",
            CsgOp::Subtraction => "Subtraction",
        }
    }

    pub fn from_name(name: &str) -> Option<CsgOp> {
        CsgOp::ALL.into_iter().find(|op| op.name() == name)
    }

    /// Whether a point inside A (`a`) and/or B (`b`) is inside the result.
    pub fn combine(self, a: bool, b: bool) -> bool {
        match self {
            CsgOp::Union => a || b,
            CsgOp::Intersection => a && b,
            CsgOp::Subtraction => a && !b,
        }
    }
}

impl NodeKind {
    pub fn name(&self) -> &'static str {
        match self {
            NodeKind::Group => "Group",
            NodeKind::Transform(_) => "Transform",
            NodeKind::Sphere { .. } => "Sphere",
            NodeKind::Plane { .. } => "Plane",
            NodeKind::Triangle { .. } => "Triangle",
            NodeKind::TriangleMesh { .. } => "TriangleMesh",
            NodeKind::Box { .. } => "Box",
            NodeKind::Csg(op) => op.name(),
        }
    }

    /// Whether the node holds other objects (a Group any number, a Transform one, a CSG
    /// node exactly two).
    pub fn is_container(&self) -> bool {
        matches!(
            self,
            NodeKind::Group | NodeKind::Transform(_) | NodeKind::Csg(_)
        )
    }

    /// Whether the node is one of tracelab's extensions to the course grammar.
    pub fn is_extension(&self) -> bool {
        matches!(self, NodeKind::Box { .. } | NodeKind::Csg(_))
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Node {
    pub kind: NodeKind,
    /// The material set by a `MaterialIndex` before this node in its Group; `None` inherits
    /// the material in effect around it.
    pub material: Option<u32>,
    pub children: Vec<NodeId>,
    /// `#` comments written before, inside and at the end of this node's block; a deleted
    /// node takes them with it.
    pub comments: Comments,
}

impl Node {
    pub fn new(kind: NodeKind) -> Self {
        Node {
            kind,
            material: None,
            children: Vec::new(),
            comments: Comments::default(),
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Graph {
    nodes: Vec<Node>,
    root: NodeId,
}

impl Default for Graph {
    fn default() -> Self {
        Self::new()
    }
}

impl Graph {
    /// A graph holding one empty root Group.
    pub fn new() -> Self {
        Graph {
            nodes: vec![Node::new(NodeKind::Group)],
            root: NodeId(0),
        }
    }

    pub fn root(&self) -> NodeId {
        self.root
    }

    pub fn get(&self, id: NodeId) -> Option<&Node> {
        self.nodes.get(id.index())
    }

    pub fn get_mut(&mut self, id: NodeId) -> Option<&mut Node> {
        self.nodes.get_mut(id.index())
    }

    /// The node; panics on an id that did not come from this graph.
    pub fn node(&self, id: NodeId) -> &Node {
        &self.nodes[id.index()]
    }

    pub fn node_mut(&mut self, id: NodeId) -> &mut Node {
        &mut self.nodes[id.index()]
    }

    /// Adds a detached node; attach it with [`Graph::push_child`] or [`Graph::insert_child`].
    pub fn add(&mut self, node: Node) -> NodeId {
        let id = NodeId(u32::try_from(self.nodes.len()).unwrap_or(u32::MAX));
        self.nodes.push(node);
        id
    }

    /// [`Graph::add`], or an error where the arena cannot grow (a scene of millions of
    /// objects under a memory limit).
    pub fn try_add(&mut self, node: Node) -> Result<NodeId, crate::memory::OutOfMemory> {
        let more = self.nodes.len().max(1);
        crate::memory::fallibly(|| self.nodes.try_reserve(1)).map_err(|_| {
            crate::memory::OutOfMemory {
                what: "the scene's objects",
                bytes: (more * std::mem::size_of::<Node>()) as u64,
            }
        })?;
        Ok(self.add(node))
    }

    pub fn push_child(&mut self, parent: NodeId, child: NodeId) {
        self.nodes[parent.index()].children.push(child);
    }

    pub fn insert_child(&mut self, parent: NodeId, index: usize, child: NodeId) {
        let children = &mut self.nodes[parent.index()].children;
        let index = index.min(children.len());
        children.insert(index, child);
    }

    /// Number of slots in the arena, detached nodes included.
    pub fn capacity_len(&self) -> usize {
        self.nodes.len()
    }

    /// Nodes reachable from the root, parents before children, children in order.
    pub fn preorder(&self) -> Vec<NodeId> {
        self.preorder_from(self.root)
    }

    pub fn preorder_from(&self, start: NodeId) -> Vec<NodeId> {
        let mut out = Vec::new();
        let mut stack = vec![start];
        while let Some(id) = stack.pop() {
            out.push(id);
            if let Some(n) = self.get(id) {
                stack.extend(n.children.iter().rev().copied());
            }
        }
        out
    }

    /// Parent of every reachable node (the root has none).
    pub fn parents(&self) -> Vec<Option<NodeId>> {
        let mut parents = vec![None; self.nodes.len()];
        for id in self.preorder() {
            for &c in &self.node(id).children {
                if let Some(p) = parents.get_mut(c.index()) {
                    *p = Some(id);
                }
            }
        }
        parents
    }

    /// The ids from the root down to `target` (inclusive), or `None` if it is not reachable.
    pub fn path_to(&self, target: NodeId) -> Option<Vec<NodeId>> {
        let parents = self.parents();
        let mut path = vec![target];
        let mut cur = target;
        while cur != self.root {
            cur = (*parents.get(cur.index())?)?;
            path.push(cur);
        }
        path.reverse();
        Some(path)
    }

    /// What each child of `node` inherits when it sets no material, given the material `m`
    /// in effect at `node`. In the file (and in the course's parser) a MaterialIndex holds
    /// for every later object of its list, so in a Group's or CSG node's list a child
    /// without one continues the latest one before it, which is what the writer's text says.
    pub fn list_materials(&self, node: &Node, m: Option<u32>) -> Vec<(NodeId, Option<u32>)> {
        let listed = matches!(node.kind, NodeKind::Group | NodeKind::Csg(_));
        let mut running = m;
        node.children
            .iter()
            .map(|&c| {
                let inherited = running;
                if listed && let Some(own) = self.get(c).and_then(|n| n.material) {
                    running = Some(own);
                }
                (c, inherited)
            })
            .collect()
    }

    /// The same graph with every material a list continues spelt out, as the parser reads
    /// the written file: two graphs that differ only in that spelling render alike and
    /// normalise to equal values.
    pub fn with_listed_materials(&self) -> Graph {
        let mut g = self.clone();
        for id in self.preorder() {
            if matches!(self.node(id).kind, NodeKind::Group | NodeKind::Csg(_)) {
                let mut running = None;
                for &c in &self.node(id).children {
                    let n = g.node_mut(c);
                    running = n.material.or(running);
                    n.material = running;
                }
            }
        }
        g
    }

    /// A copy holding only the nodes reachable from the root, renumbered in preorder. Two
    /// graphs describing the same tree compact to equal values.
    pub fn compacted(&self) -> Graph {
        let order = self.preorder();
        let mut new_id = vec![u32::MAX; self.nodes.len()];
        for (i, id) in order.iter().enumerate() {
            new_id[id.index()] = i as u32;
        }
        let nodes = order
            .iter()
            .map(|&id| {
                let n = self.node(id);
                Node {
                    kind: n.kind.clone(),
                    material: n.material,
                    comments: n.comments.clone(),
                    children: n
                        .children
                        .iter()
                        .map(|c| NodeId(new_id[c.index()]))
                        .collect(),
                }
            })
            .collect();
        Graph {
            nodes,
            root: NodeId(0),
        }
    }

    /// Iterates over all reachable nodes with their ids.
    pub fn iter(&self) -> impl Iterator<Item = (NodeId, &Node)> {
        self.preorder()
            .into_iter()
            .map(move |id| (id, self.node(id)))
    }

    /// Counts of reachable objects and triangles, for status bars.
    pub fn stats(&self) -> GraphStats {
        let mut s = GraphStats::default();
        for (_, n) in self.iter() {
            s.nodes += 1;
            match &n.kind {
                NodeKind::Triangle { .. } => s.triangles += 1,
                NodeKind::TriangleMesh {
                    mesh: MeshSlot::Loaded(m),
                    ..
                } => s.triangles += m.triangle_count(),
                _ => {}
            }
            if !n.kind.is_container() {
                s.primitives += 1;
            }
        }
        s
    }
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GraphStats {
    pub nodes: usize,
    pub primitives: usize,
    pub triangles: usize,
}
