//! The object tree (Group, Transform, CSG and the primitives), read with an explicit stack,
//! and Transform ops.

use glam::{Mat4, Vec3};

use super::super::lexer::TokKind;
use super::fields::block_comments;
use super::{NodeSpan, Parser};
use crate::scene::{
    Anchor, Comments, CsgOp, Graph, MeshSlot, Node, NodeId, NodeKind, TransformOp, validate,
};

/// An object block still open on the parser's stack.
pub(super) enum OpenBlock {
    Container(ContainerFrame),
    Transform(TransformFrame),
}

/// A Group or a CSG operation: objects (operands), with MaterialIndex applying to those
/// after it.
pub(super) struct ContainerFrame {
    node: NodeId,
    kind: Container,
    open: usize,
    count: usize,
    /// The MaterialIndex in effect, with where its number (or the Material block) stands.
    material: Option<(u32, usize)>,
}

pub(super) struct TransformFrame {
    node: NodeId,
    open: usize,
    ops: Vec<TransformOp>,
    /// How many objects the file gives it (the rules judge how many were read).
    objects: usize,
}

/// What a container block is: a Group and a CSG operation read alike but for these.
#[derive(Clone, Copy)]
enum Container {
    /// `numObjects` as written, with its offset.
    Group {
        declared: Option<(usize, usize)>,
    },
    Csg(CsgOp),
}

impl Container {
    fn name(self) -> &'static str {
        match self {
            Container::Group { .. } => "Group",
            Container::Csg(op) => op.name(),
        }
    }
}

impl OpenBlock {
    fn node(&self) -> NodeId {
        match self {
            OpenBlock::Container(f) => f.node,
            OpenBlock::Transform(f) => f.node,
        }
    }
}

pub(super) const OBJECT_KEYWORDS: &[&str] = &[
    "Group",
    "Transform",
    "Sphere",
    "Plane",
    "Triangle",
    "TriangleMesh",
    "Box",
    "Union",
    "Intersection",
    "Subtraction",
];

impl Parser<'_> {
    pub(super) fn parse_object_tree(&mut self, off: usize) {
        let before = self.comments_here();
        let Some(open) = self.expect_open("Group") else {
            return;
        };
        if self.graph.is_some() {
            self.error(off, "a scene has one top-level Group; this is a second");
            self.skip_block();
            return;
        }
        let mut graph = Graph::new();
        let root = graph.root();
        graph.node_mut(root).comments.before = before;
        let mut stack = vec![OpenBlock::Container(ContainerFrame {
            node: root,
            kind: Container::Group { declared: None },
            open,
            count: 0,
            material: None,
        })];
        while !stack.is_empty() && !self.out_of_memory {
            let Some(t) = self.next() else {
                let (kind, open) = match stack.last() {
                    Some(OpenBlock::Container(f)) => (f.kind.name(), f.open),
                    Some(OpenBlock::Transform(f)) => ("Transform", f.open),
                    None => break,
                };
                self.error(
                    open,
                    format!(
                        "unterminated {kind} block: expected \"}}\" before the end of the file"
                    ),
                );
                break;
            };
            match t.kind {
                TokKind::Close => {
                    if let Some(frame) = stack.pop() {
                        graph.node_mut(frame.node()).comments.end = self.comments_here();
                        self.close_frame(frame, &mut graph);
                    }
                }
                TokKind::Open => {
                    self.error(t.start, "unexpected \"{\"");
                    self.skip_block();
                }
                TokKind::Word => {
                    let w = self.text(t);
                    let opened = match stack.last_mut() {
                        Some(OpenBlock::Container(f)) => {
                            self.container_word(w, t.start, f, &mut graph)
                        }
                        Some(OpenBlock::Transform(f)) => {
                            self.transform_word(w, t.start, f, &mut graph)
                        }
                        None => None,
                    };
                    stack.extend(opened);
                }
            }
        }
        // Blocks left open (the file ended): how many objects they hold is not known.
        self.lost_objects.extend(stack.iter().map(OpenBlock::node));
        self.graph = Some(graph);
    }

    /// A word inside a Group or a CSG operation; returns the block it opens, if any.
    fn container_word(
        &mut self,
        w: &str,
        at: usize,
        frame: &mut ContainerFrame,
        graph: &mut Graph,
    ) -> Option<OpenBlock> {
        match (w, &mut frame.kind) {
            ("numObjects", Container::Group { declared }) => {
                let c = self.comments_here();
                if !c.is_empty() {
                    graph
                        .node_mut(frame.node)
                        .comments
                        .inner
                        .entry(Anchor::Field("numObjects".into()))
                        .or_default()
                        .extend(c);
                }
                if declared.is_some() {
                    self.error(at, "numObjects is given twice in this Group");
                }
                let d = self.expect_count("numObjects");
                *declared = d.or(*declared);
            }
            ("MaterialIndex", _) => {
                self.defer_comments();
                if let Some((i, at)) = self.expect_count("MaterialIndex") {
                    self.material_refs.push((i as u64, at));
                    frame.material = Some((u32::try_from(i).unwrap_or(u32::MAX), at));
                }
            }
            // The lecture's shorthand: a Material placed in a Group adds it and applies it
            // to what follows.
            ("Material", Container::Group { .. }) => {
                if let Some(m) = self.parse_material_block("Material", at) {
                    self.materials.push(m);
                    frame.material = Some(((self.materials.len() - 1) as u32, at));
                }
            }
            _ if OBJECT_KEYWORDS.contains(&w) => {
                frame.count += 1;
                return self.start_object(w, at, frame.node, frame.material, graph);
            }
            (_, kind) => {
                // A misspelt object still counts toward numObjects (or the operands), so one
                // typo gives one error.
                if self.peek().is_some_and(|n| n.kind == TokKind::Open) {
                    frame.count += 1;
                }
                let msg = match kind {
                    Container::Group { .. } => format!(
                        "unknown keyword \"{w}\" in Group (expected numObjects, MaterialIndex or an object: {})",
                        OBJECT_KEYWORDS.join(", ")
                    ),
                    Container::Csg(op) => format!(
                        "unknown keyword \"{w}\" in {} (expected MaterialIndex or an operand: {})",
                        op.name(),
                        OBJECT_KEYWORDS[2..].join(", ")
                    ),
                };
                self.error(at, msg);
                self.skip_following_block();
            }
        }
        None
    }

    /// A word inside a Transform: an op, or its one object (whose block is returned).
    fn transform_word(
        &mut self,
        w: &str,
        at: usize,
        frame: &mut TransformFrame,
        graph: &mut Graph,
    ) -> Option<OpenBlock> {
        if OBJECT_KEYWORDS.contains(&w) {
            // A second one is the rules' to report (they know where it stands).
            frame.objects += 1;
            return self.start_object(w, at, frame.node, None, graph);
        }
        let c = self.comments_here();
        // Its numbers are judged with the whole graph (`Parser::finish`), placed here.
        let op = self.parse_op_numbers(w, at)?;
        if frame.objects > 0 {
            self.error(
                at,
                "transform operations must come before the Transform's object",
            );
            return None;
        }
        if !c.is_empty() {
            graph
                .node_mut(frame.node)
                .comments
                .inner
                .entry(Anchor::Op(frame.ops.len()))
                .or_default()
                .extend(c);
        }
        frame.ops.push(op);
        self.op_offsets.push(at);
        None
    }

    fn skip_following_block(&mut self) {
        if self.peek().is_some_and(|n| n.kind == TokKind::Open) {
            self.pos += 1;
            self.skip_block();
        }
    }

    /// An op's numbers, bare as the course writes them or in braces as the lecture's slides
    /// do (`ZRotate { 45 }`); the writer always writes them bare.
    fn op_numbers(&mut self, w: &str, n: usize) -> Option<Vec<f32>> {
        if !self.peek().is_some_and(|t| t.kind == TokKind::Open) {
            return self.expect_numbers(w, n);
        }
        self.pos += 1;
        self.numbers_then_close(w, n, "number(s)")
    }

    /// `n` numbers and the `}` closing the block whose `{` was read; on failure reports it
    /// and resynchronises at the end of that block. `numbers` is the message's unit.
    fn numbers_then_close(&mut self, w: &str, n: usize, numbers: &str) -> Option<Vec<f32>> {
        let v = self.expect_numbers(w, n);
        match self.peek() {
            Some(c) if c.kind == TokKind::Close && v.is_some() => {
                self.pos += 1;
                v
            }
            other => {
                if v.is_some() {
                    let (found, at) = self.describe(other);
                    self.error(
                        at,
                        format!("expected \"}}\" to close {w} after {n} {numbers}, found {found}"),
                    );
                }
                self.skip_block();
                None
            }
        }
    }

    /// Parses a transform op after its keyword and checks it alone (a texture's; an
    /// object's is judged with its node). Reports and returns None on failure (including
    /// an unknown keyword).
    pub(super) fn parse_op(&mut self, w: &str, off: usize) -> Option<TransformOp> {
        let op = self.parse_op_numbers(w, off)?;
        if let Err(e) = validate::check_op(&op) {
            self.error(off, e.message);
            return None;
        }
        Some(op)
    }

    fn parse_op_numbers(&mut self, w: &str, off: usize) -> Option<TransformOp> {
        let v3 = |v: Vec<f32>| Vec3::new(v[0], v[1], v[2]);
        Some(match w {
            "Scale" => TransformOp::Scale(v3(self.op_numbers(w, 3)?)),
            "UniformScale" => TransformOp::UniformScale(self.op_numbers(w, 1)?[0]),
            "Translate" => TransformOp::Translate(v3(self.op_numbers(w, 3)?)),
            "XRotate" => TransformOp::XRotate(self.op_numbers(w, 1)?[0]),
            "YRotate" => TransformOp::YRotate(self.op_numbers(w, 1)?[0]),
            "ZRotate" => TransformOp::ZRotate(self.op_numbers(w, 1)?[0]),
            "Rotate" => {
                self.expect_open(w)?;
                let v = self.numbers_then_close(w, 4, "numbers")?;
                TransformOp::Rotate {
                    axis: Vec3::new(v[0], v[1], v[2]),
                    degrees: v[3],
                }
            }
            "Matrix" => {
                self.expect_open(w)?;
                let v = self.numbers_then_close(w, 16, "numbers")?;
                let mut a = [0.0f32; 16];
                a.copy_from_slice(&v);
                // Written row by row; glam stores columns.
                TransformOp::Matrix(Mat4::from_cols_array(&a).transpose())
            }
            _ => {
                self.error(
                    off,
                    format!(
                        "unknown keyword \"{w}\" in Transform (expected Scale, UniformScale, Translate, XRotate, YRotate, ZRotate, Rotate, Matrix or one object)"
                    ),
                );
                self.skip_following_block();
                return None;
            }
        })
    }

    /// Starts an object after its keyword: containers return a frame to push; primitives
    /// are read whole and attached.
    fn start_object(
        &mut self,
        w: &str,
        off: usize,
        parent: NodeId,
        material: Option<(u32, usize)>,
        graph: &mut Graph,
    ) -> Option<OpenBlock> {
        let before = self.comments_here();
        let open = self.expect_open(w)?;
        let attach = |this: &mut Self, graph: &mut Graph, kind: NodeKind, comments: Comments| {
            // The arrays that grow with every object, fallibly: a scene too big for the
            // memory there is ends the parse with a message, not an abort.
            let id = crate::memory::fallibly(|| {
                this.spans
                    .try_reserve(1)
                    .and_then(|()| this.leaf_offsets.try_reserve(1))
            })
            .map_err(|_| crate::memory::OutOfMemory {
                what: "the scene's objects",
                bytes: (this.spans.len() * 32) as u64,
            })
            .and_then(|()| {
                graph.try_add(Node {
                    kind,
                    material: material.map(|(i, _)| i),
                    children: Vec::new(),
                    comments,
                })
            });
            let id = match id {
                Ok(id) => id,
                Err(e) => {
                    this.error(
                        off,
                        format!("{e}: the scene has more objects than fit in memory here"),
                    );
                    this.out_of_memory = true;
                    return None;
                }
            };
            graph.push_child(parent, id);
            this.record_span(id, off, material.map(|(_, at)| at));
            Some(id)
        };
        let only_comments_before = Comments {
            before,
            ..Comments::default()
        };
        let container = match w {
            "Group" => Some(Container::Group { declared: None }),
            _ => CsgOp::from_name(w).map(Container::Csg),
        };
        if let Some(kind) = container {
            let node_kind = match kind {
                Container::Group { .. } => NodeKind::Group,
                Container::Csg(op) => NodeKind::Csg(op),
            };
            let node = attach(self, graph, node_kind, only_comments_before)?;
            return Some(OpenBlock::Container(ContainerFrame {
                node,
                kind,
                open,
                count: 0,
                material: None,
            }));
        }
        match w {
            "Transform" => {
                let node = attach(
                    self,
                    graph,
                    NodeKind::Transform(Vec::new()),
                    only_comments_before,
                )?;
                Some(OpenBlock::Transform(TransformFrame {
                    node,
                    open,
                    ops: Vec::new(),
                    objects: 0,
                }))
            }
            _ => {
                let (kind, mut comments) = self.parse_primitive(w, off, open)?;
                comments.before = only_comments_before.before;
                let is_mesh = matches!(kind, NodeKind::TriangleMesh { .. });
                let id = attach(self, graph, kind, comments)?;
                self.leaf_offsets.push((id, off));
                if is_mesh {
                    self.mesh_name_offsets.push((id, self.last_obj_name));
                }
                None
            }
        }
    }

    /// The primitive and the comments inside its block.
    fn parse_primitive(
        &mut self,
        w: &str,
        off: usize,
        open: usize,
    ) -> Option<(NodeKind, Comments)> {
        let (mut f, end) = self.read_fields(w, open)?;
        let comments = block_comments(Vec::new(), &mut f, end);
        let kind = match w {
            "Sphere" => {
                let center = self.take_vec3(&mut f, w, off, "center");
                let radius = self.take_f32(&mut f, w, off, "radius");
                self.reject_unused(&f, w, "center, radius");
                NodeKind::Sphere {
                    center: center?,
                    radius: radius?,
                }
            }
            "Plane" => {
                let normal = self.take_vec3(&mut f, w, off, "normal");
                let offset = self.take_f32(&mut f, w, off, "offset");
                self.reject_unused(&f, w, "normal, offset");
                NodeKind::Plane {
                    normal: normal?,
                    offset: offset?,
                }
            }
            "Triangle" => {
                let a = self.take_vec3(&mut f, w, off, "vertex0");
                let b = self.take_vec3(&mut f, w, off, "vertex1");
                let c = self.take_vec3(&mut f, w, off, "vertex2");
                self.reject_unused(&f, w, "vertex0, vertex1, vertex2");
                NodeKind::Triangle {
                    vertices: [a?, b?, c?],
                }
            }
            "Box" => {
                let min = self.take_vec3(&mut f, w, off, "min");
                let max = self.take_vec3(&mut f, w, off, "max");
                self.reject_unused(&f, w, "min, max");
                NodeKind::Box {
                    min: min?,
                    max: max?,
                }
            }
            "TriangleMesh" => {
                let Some(i) = f.iter().position(|x| x.name == "obj_file") else {
                    self.error(off, "TriangleMesh is missing \"obj_file\"");
                    return None;
                };
                f[i].used = true;
                self.reject_unused(&f, w, "obj_file");
                let (name, name_off) = f[i].word.clone()?;
                self.last_obj_name = name_off;
                NodeKind::TriangleMesh {
                    obj_file: name,
                    mesh: MeshSlot::Unresolved,
                }
            }
            _ => return None,
        };
        // Its numbers are judged with the whole graph (`Parser::finish`).
        Some((kind, comments))
    }

    /// Closes a block. How many objects a Transform or CSG node holds and what they are
    /// are the rules' to judge once the tree is read; a block that lost an object it gives
    /// (misspelt, or unreadable) is marked, so that its count is not reported as well.
    fn close_frame(&mut self, frame: OpenBlock, graph: &mut Graph) {
        let (node, written) = match &frame {
            OpenBlock::Container(f) => (f.node, f.count),
            OpenBlock::Transform(f) => (f.node, f.objects),
        };
        if graph.node(node).children.len() != written {
            self.lost_objects.insert(node);
        }
        match frame {
            OpenBlock::Container(ContainerFrame {
                kind:
                    Container::Group {
                        declared: Some((n, at)),
                    },
                count,
                ..
            }) if n != count => {
                self.error(
                    at,
                    format!("numObjects says {n} but the Group holds {count} object(s)"),
                );
            }
            OpenBlock::Container(_) => {}
            OpenBlock::Transform(TransformFrame { node, ops, .. }) => {
                // Ops were checked one by one as read; their product is checked with the
                // whole chain above it once the tree is complete.
                graph.node_mut(node).kind = NodeKind::Transform(ops);
            }
        }
    }

    fn record_span(&mut self, id: NodeId, keyword: usize, material: Option<usize>) {
        if self.spans.len() <= id.index() {
            self.spans.resize(id.index() + 1, NodeSpan::default());
        }
        // A Transform's ops are read next, one after another: they start here.
        let first_op = self.op_offsets.len();
        self.spans[id.index()] = NodeSpan {
            keyword,
            material,
            first_op,
        };
    }
}
