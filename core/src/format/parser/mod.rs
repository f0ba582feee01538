//! Recursive-descent reader for the 6.837 scene format. The object tree is parsed with an
//! explicit stack (no recursion), so nesting depth is limited only by memory. Errors are
//! collected, not thrown: after an error the parser skips to the end of the enclosing block
//! and carries on, so one pass reports as many problems as it can.
//!
//! In parts: `reader.rs` (tokens, comments and messages), `fields.rs` (a flat block's
//! `name value…` lines), `blocks.rs` (the top level: camera, lights, background,
//! materials), `texture.rs` (the solid textures in Materials), `objects.rs` (the object
//! tree and Transform ops); this file holds the
//! parser's state, its entry points and the checks once the whole file is read.

mod blocks;
mod fields;
mod objects;
mod reader;
mod texture;

use std::collections::{HashMap, HashSet};
use std::path::Path;

use super::diagnostic::{Diagnostic, Diagnostics, Severity, SourceFile};
use super::token_stream::TokenStream;

use crate::scene::{
    Background, Camera, CsgOp, Field, Graph, Light, Material, NodeId, NodeKind, Place, Problem,
    Scene, SceneComments, validate,
};

/// What one read of a scene file gave. `scene` is `Some` when the file's structure was read
/// completely; it may still come with errors that concern single nodes (an OBJ file that
/// could not be loaded), which `diagnostics.has_errors()` reports.
///
/// Parsing never touches the file system: TriangleMesh nodes come back
/// [`MeshSlot::Unresolved`], listed in `meshes`, until [`super::resolve_meshes`] loads them.
#[derive(Debug)]
pub struct ParseOutcome {
    pub scene: Option<Scene>,
    pub diagnostics: Diagnostics,
    /// Comments that stand where the scene cannot keep them (between a keyword and its
    /// value): writing the scene drops them. Each is also among `diagnostics` as a warning;
    /// kept apart so a save can repeat them (see [`ParseOutcome::lost_comments`]).
    pub lost_comments: Vec<Diagnostic>,
    /// Each TriangleMesh node still to be loaded, with where its file name stands.
    pub meshes: Vec<MeshRef>,
    /// The diagnostics counted but not shown (the last `summaries` of `diagnostics` say so),
    /// for the resolve step to go on counting within the same cap.
    pub(crate) unshown: UnshownSummary,
}

/// Errors and warnings left out after the first [`MAX_SHOWN`] of each, and where the first
/// of them stands.
#[derive(Clone, Debug, Default)]
pub(crate) struct UnshownSummary {
    pub errors: (usize, Option<Located>),
    pub warnings: (usize, Option<Located>),
    /// How many "… and N more" lines end `diagnostics`.
    pub summaries: usize,
}

impl ParseOutcome {
    /// The scene if there was no error at all, else every diagnostic.
    pub fn into_result(self) -> Result<(Scene, Diagnostics), Diagnostics> {
        match self.scene {
            Some(s) if !self.diagnostics.has_errors() => Ok((s, self.diagnostics)),
            _ => Err(self.diagnostics),
        }
    }

    /// Comments that writing the scene would drop, as warnings with file:line:col.
    pub fn lost_comments(&self) -> &[Diagnostic] {
        &self.lost_comments
    }
}

/// The largest scene file read. Scenes are hand-written or generated text (meshes live in OBJ
/// files); the cap keeps a device, a FIFO or a mistaken huge file from filling memory.
pub const MAX_SCENE_BYTES: usize = 64 << 20;

/// Reads and parses a scene file without loading its meshes (what `tracelab fmt` needs: it
/// works when an OBJ file is missing).
pub fn load_scene_unresolved(path: &Path) -> ParseOutcome {
    let name = path.display().to_string();
    let whole_file_error = |message: String| ParseOutcome {
        scene: None,
        diagnostics: Diagnostics(vec![Diagnostic {
            severity: Severity::Error,
            file: name.clone(),
            line: 0,
            col: 0,
            message,
        }]),
        lost_comments: Vec::new(),
        meshes: Vec::new(),
        unshown: UnshownSummary::default(),
    };
    match read_capped(path, MAX_SCENE_BYTES) {
        Ok(Some(bytes)) => parse_scene_unresolved(&bytes, &name),
        Ok(None) => whole_file_error(format!(
            "the file is larger than {} MiB, the most tracelab reads as a scene",
            MAX_SCENE_BYTES >> 20
        )),
        Err(e) => whole_file_error(format!("cannot read scene file: {e}")),
    }
}

/// The file's bytes, or None when it holds more than `cap`. Reads at most `cap + 1` bytes, so
/// a character device or a FIFO that never ends cannot be read forever.
pub(crate) fn read_capped(path: &Path, cap: usize) -> std::io::Result<Option<Vec<u8>>> {
    use std::io::Read as _;
    let file = std::fs::File::open(path)?;
    let hint = file.metadata().map_or(0, |m| m.len()).min(cap as u64 + 1) as usize;
    let mut bytes = Vec::with_capacity(hint);
    file.take(cap as u64 + 1).read_to_end(&mut bytes)?;
    Ok((bytes.len() <= cap).then_some(bytes))
}

/// Parses scene text only: no file is opened, meshes stay [`MeshSlot::Unresolved`].
pub fn parse_scene_unresolved(bytes: &[u8], name: &str) -> ParseOutcome {
    let text = match std::str::from_utf8(bytes) {
        Ok(t) if !t.contains('\0') => t,
        other => {
            let (valid_up_to, what) = match other {
                Ok(t) => (t.find('\0').unwrap_or(0), "a NUL byte".to_string()),
                Err(e) => {
                    let b = bytes.get(e.valid_up_to()).copied().unwrap_or(0);
                    (
                        e.valid_up_to(),
                        format!("byte 0x{b:02x}, which is not UTF-8 text"),
                    )
                }
            };
            let prefix = std::str::from_utf8(&bytes[..valid_up_to]).unwrap_or("");
            let src = SourceFile::new(name, prefix);
            let d = src.diagnostic(
                Severity::Error,
                valid_up_to,
                format!("this is not a text scene file: found {what}"),
            );
            return ParseOutcome {
                scene: None,
                diagnostics: Diagnostics(vec![d]),
                lost_comments: Vec::new(),
                meshes: Vec::new(),
                unshown: UnshownSummary::default(),
            };
        }
    };
    let mut p = Parser {
        src: SourceFile::new(name, text),
        toks: TokenStream::new(text),
        next_comment: 0,
        pending_comments: Vec::new(),
        lost_comments: Vec::new(),
        scene_comments: SceneComments::default(),
        pos: 0,
        diags: Vec::new(),
        unshown: Unshown::default(),
        fatal: false,
        out_of_memory: false,
        camera: None,
        camera_seen: false,
        group_seen: false,
        lights: None,
        background: None,
        materials: Vec::new(),
        graph: None,
        material_refs: Vec::new(),
        texture_refs: Vec::new(),
        leaf_offsets: Vec::new(),
        spans: Vec::new(),
        op_offsets: Vec::new(),
        lost_objects: HashSet::new(),
        mesh_name_offsets: Vec::new(),
        last_obj_name: 0,
    };
    p.parse_file();
    p.finish()
}

struct Parser<'a> {
    src: SourceFile<'a>,
    /// Tokens and comments, lexed as the parser reaches them; comments before
    /// `next_comment` have been attached or lost.
    toks: TokenStream<'a>,
    next_comment: usize,
    /// Comments before a MaterialIndex, waiting for the object it applies to.
    pending_comments: Vec<String>,
    lost_comments: Vec<Diagnostic>,
    scene_comments: SceneComments,
    pos: usize,
    diags: Vec<Diagnostic>,
    unshown: Unshown,
    /// Set by any error that leaves the scene incomplete.
    fatal: bool,
    /// The scene's objects outgrew the memory there is: the parse stops there.
    out_of_memory: bool,
    camera: Option<Camera>,
    /// A camera or object Group block was present (even if broken): do not also report it missing.
    camera_seen: bool,
    group_seen: bool,
    lights: Option<Vec<Light>>,
    background: Option<Background>,
    materials: Vec<Material>,
    graph: Option<Graph>,
    /// (index as written, offset) of each MaterialIndex, checked once all materials are
    /// known.
    material_refs: Vec<(u64, usize)>,
    /// Where each texture's materialIndex lines stand, checked once all materials are known.
    texture_refs: Vec<TextureRefs>,
    /// (node, offset) of each primitive, for warnings that need the final tree.
    leaf_offsets: Vec<(NodeId, usize)>,
    /// Where each node stands, indexed by node id: the rules' verdicts on the graph are
    /// placed with it.
    spans: Vec<NodeSpan>,
    /// Where each Transform op stands, the ops of one Transform one after another.
    op_offsets: Vec<usize>,
    /// Transform and CSG nodes that lost an object the file gives them (misspelt or
    /// unreadable, reported where it stands): their count of objects is not reported too.
    lost_objects: HashSet<NodeId>,
    /// (node, offset of its file name) of each TriangleMesh, for the resolve step.
    mesh_name_offsets: Vec<(NodeId, usize)>,
    /// Offset of the last TriangleMesh's file name, read by `start_object`.
    last_obj_name: usize,
}

/// Where a node stands in the file: its keyword, and the MaterialIndex that applies to it.
#[derive(Clone, Copy, Debug, Default)]
struct NodeSpan {
    keyword: usize,
    material: Option<usize>,
    /// For a Transform: where its first op stands in `Parser::op_offsets`.
    first_op: usize,
}

/// Where a texture's lines stand, for errors found once every material is read.
#[derive(Clone, Copy, Debug)]
struct TextureRefs {
    /// The texture's index in the Materials block.
    material: usize,
    /// The value of each `materialIndex` line.
    at: [usize; 2],
}

/// Where something stands in a scene file (1-based line and column).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Located {
    pub file: String,
    pub line: u32,
    pub col: u32,
}

/// A TriangleMesh node as the parser left it: the file to load, where its name stands, and
/// the CSG operations it is an operand of (each with the operand's location).
#[derive(Clone, Debug, PartialEq)]
pub struct MeshRef {
    pub node: NodeId,
    pub obj_file: String,
    pub at: Located,
    pub operand_of: Vec<(CsgOp, Located)>,
}

/// Errors (and, separately, warnings) past this many are counted, not shown: a file of a
/// million stray braces must not print a million lines.
pub(super) const MAX_SHOWN: usize = 20;

/// Diagnostics beyond the first `MAX_SHOWN` of their severity: how many, and where the first
/// of them is.
#[derive(Default)]
struct Unshown {
    shown_errors: usize,
    shown_warnings: usize,
    errors: (usize, usize),
    warnings: (usize, usize),
}

/// (The rule is the scene's: a name must not read as a number; the reader follows it.)
pub(crate) use crate::scene::words::is_numberlike;

impl Parser<'_> {
    // ---------------------------------------------------------------- completion

    fn finish(mut self) -> ParseOutcome {
        let end = self.src.text.len();
        self.scene_comments.end = self.comments_before(self.toks.len());
        let n = self.materials.len();
        // Each line once, also one that applies to no object; the objects after it are
        // not reported again (`judge_graph`).
        let mut placed = HashSet::new();
        for (i, at) in std::mem::take(&mut self.material_refs) {
            if let Err(e) = validate::check_material_index(i, n) {
                self.error(at, e.message);
                placed.insert((at, e.field));
            }
        }
        for (i, slot, reason) in validate::check_texture_refs(&self.materials) {
            let at = self.texture_refs.iter().find(|r| r.material == i);
            let off = at.map_or(end, |r| r.at[slot.min(1)]);
            self.error(off, reason);
        }
        if self.camera.is_none() && !self.camera_seen {
            self.error(
                end,
                "the scene has no camera (OrthographicCamera or PerspectiveCamera)",
            );
        }
        if self.graph.is_none() && !self.group_seen {
            self.error(end, "the scene has no Group of objects");
        }
        if let Some(graph) = self.graph.take() {
            self.judge_graph(&graph, n, placed);
            self.graph = Some(graph);
        }
        if let Some(graph) = &self.graph {
            let eff = graph.effective_materials();
            let missing: Vec<usize> = self
                .leaf_offsets
                .iter()
                .filter(|(id, _)| eff.get(id.index()).copied().flatten().is_none())
                .map(|(_, at)| *at)
                .collect();
            for (k, at) in missing.iter().enumerate() {
                if k == 5 {
                    self.warn(
                        *at,
                        format!("{} more objects have no material", missing.len() - 5),
                    );
                    break;
                }
                self.warn(
                    *at,
                    "no MaterialIndex applies to this object; it uses the default grey material",
                );
            }
        }
        let unshown = self.summarise_unshown();
        let scene = if self.fatal {
            None
        } else {
            Some(Scene {
                camera: self.camera.take().unwrap_or_default(),
                lights: self.lights.take(),
                background: self.background.take().unwrap_or_default(),
                materials: std::mem::take(&mut self.materials),
                graph: self.graph.take().unwrap_or_default(),
                comments: std::mem::take(&mut self.scene_comments),
            })
        };
        let meshes = self.mesh_refs(scene.as_ref());
        ParseOutcome {
            scene,
            diagnostics: Diagnostics(self.diags),
            lost_comments: self.lost_comments,
            meshes,
            unshown,
        }
    }

    /// The graph rules of `validate`, once over the whole tree (chains of Transforms
    /// composed, so nested scales are judged together), each verdict placed where its node,
    /// child or MaterialIndex stands.
    /// `placed`: what was reported already, by place and field (each MaterialIndex line).
    fn judge_graph(
        &mut self,
        graph: &Graph,
        n_materials: usize,
        mut placed: HashSet<(usize, Field)>,
    ) {
        for p in validate::check_graph(graph, n_materials) {
            let Some(at) = self.place_of(&p) else {
                continue;
            };
            // One verdict per place and field: a MaterialIndex line once, not once per
            // object after it.
            if placed.insert((at, p.field.clone())) {
                self.error(at, p.reason);
            }
        }
    }

    /// Where a verdict on the graph stands, or None when the file already says why (a
    /// count of objects in a block that lost one).
    fn place_of(&self, p: &Problem) -> Option<usize> {
        let Place::Node(id) = p.place else {
            return Some(0);
        };
        let span = |id: NodeId| self.spans.get(id.index()).copied().unwrap_or_default();
        match &p.field {
            Field::Children if self.lost_objects.contains(&id) => None,
            Field::Child(c) => Some(span(*c).keyword),
            Field::MaterialIndex => Some(span(id).material.unwrap_or(span(id).keyword)),
            _ => Some(match p.op {
                Some(i) => self
                    .op_offsets
                    .get(span(id).first_op + i)
                    .copied()
                    .unwrap_or(span(id).keyword),
                None => span(id).keyword,
            }),
        }
    }

    /// Each TriangleMesh that is a CSG operand (through Transforms), with its operation
    /// and where it stands: the resolve step checks that it is closed.
    fn mesh_operands(&self, graph: &Graph) -> Vec<(NodeId, CsgOp, usize)> {
        let mut out = Vec::new();
        for (_, node) in graph.iter() {
            let NodeKind::Csg(op) = node.kind else {
                continue;
            };
            for &c in &node.children {
                let mut cur = c;
                while let Some(NodeKind::Transform(_)) = graph.get(cur).map(|n| &n.kind) {
                    match graph.node(cur).children.first() {
                        Some(&next) => cur = next,
                        None => break,
                    }
                }
                if let Some(NodeKind::TriangleMesh { .. }) = graph.get(cur).map(|n| &n.kind) {
                    let at = self.spans.get(cur.index()).map_or(0, |s| s.keyword);
                    out.push((cur, op, at));
                }
            }
        }
        out
    }

    /// The TriangleMesh nodes with their file names and locations (also for a scene too
    /// broken to keep, so that a missing OBJ file is reported with the other errors).
    fn mesh_refs(&self, scene: Option<&Scene>) -> Vec<MeshRef> {
        let graph = scene.map(|s| &s.graph).or(self.graph.as_ref());
        let place = |off: usize| {
            let d = self.src.diagnostic(Severity::Error, off, "");
            Located {
                file: d.file,
                line: d.line,
                col: d.col,
            }
        };
        let mut refs: Vec<MeshRef> = self
            .mesh_name_offsets
            .iter()
            .filter_map(|&(node, off)| {
                let obj_file = match graph.and_then(|g| g.get(node)).map(|n| &n.kind) {
                    Some(NodeKind::TriangleMesh { obj_file, .. }) => obj_file.clone(),
                    _ => return None,
                };
                Some(MeshRef {
                    node,
                    obj_file,
                    at: place(off),
                    operand_of: Vec::new(),
                })
            })
            .collect();
        let index: HashMap<NodeId, usize> =
            refs.iter().enumerate().map(|(i, r)| (r.node, i)).collect();
        for (node, op, off) in graph.map(|g| self.mesh_operands(g)).unwrap_or_default() {
            if let Some(&i) = index.get(&node) {
                refs[i].operand_of.push((op, place(off)));
            }
        }
        refs
    }
}
