//! Recursive-descent reader for the 6.837 scene format. The object tree is parsed with an
//! explicit stack (no recursion), so nesting depth is limited only by memory. Errors are
//! collected, not thrown: after an error the parser skips to the end of the enclosing block
//! and carries on, so one pass reports as many problems as it can.

use std::collections::HashMap;
use std::path::Path;

use glam::{Mat4, Vec3};

use super::diagnostic::{Diagnostic, Diagnostics, Severity, SourceFile};
use super::lexer::{TokKind, Token};
use super::token_stream::TokenStream;

use crate::scene::{
    Anchor, Background, Camera, Comments, CsgOp, Graph, Light, Material, MaterialKeyword, MeshSlot,
    Node, NodeId, NodeKind, Scene, SceneComments, TransformOp, validate,
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
        leaf_offsets: Vec::new(),
        node_offsets: Vec::new(),
        mesh_name_offsets: Vec::new(),
        mesh_operands: Vec::new(),
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
    /// (index, offset) of each MaterialIndex, checked once all materials are known.
    material_refs: Vec<(u32, usize)>,
    /// (node, offset) of each primitive, for warnings that need the final tree.
    leaf_offsets: Vec<(NodeId, usize)>,
    /// Offset of each object's keyword, indexed by node id (for errors about operands).
    node_offsets: Vec<usize>,
    /// (node, offset of its file name) of each TriangleMesh, for the resolve step.
    mesh_name_offsets: Vec<(NodeId, usize)>,
    /// (mesh node, operation, offset) of each TriangleMesh that is a CSG operand: the
    /// resolve step checks that it is closed.
    mesh_operands: Vec<(NodeId, CsgOp, usize)>,
    /// Offset of the last TriangleMesh's file name, read by `start_object`.
    last_obj_name: usize,
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

/// Numbers one field may hold: far above the grammar's largest (Matrix, 16), and small
/// enough that a field of millions of numbers is refused rather than held.
const MAX_FIELD_NUMBERS: usize = 1024;

/// One `name value…` line inside a flat block.
struct Field {
    name: String,
    name_off: usize,
    values: Vec<(f32, usize)>,
    word: Option<(String, usize)>,
    /// Text and offset of the token after the values, for "found …" in messages.
    after: (String, usize),
    used: bool,
    /// Named as the "found …" of a field short of numbers: never reported as unknown, but
    /// still taken if it is a real field (`center 0 0 radius 1` must not also say radius
    /// is missing).
    swallowed: bool,
    /// Comments before the field's name.
    comments: Vec<String>,
}

enum OpenBlock {
    Group {
        node: NodeId,
        open: usize,
        declared: Option<(usize, usize)>,
        count: usize,
        material: Option<u32>,
    },
    Transform {
        node: NodeId,
        keyword: usize,
        open: usize,
        ops: Vec<TransformOp>,
        has_child: bool,
    },
    /// Union, Intersection or Subtraction: operands, with MaterialIndex as in a Group.
    Csg {
        node: NodeId,
        op: CsgOp,
        keyword: usize,
        open: usize,
        count: usize,
        material: Option<u32>,
    },
}

const OBJECT_KEYWORDS: &[&str] = &[
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

/// An item's comments: those before its keyword, before each field, and before its `}`.
fn block_comments(before: Vec<String>, fields: &mut [Field], end: Vec<String>) -> Comments {
    let mut c = Comments {
        before,
        end,
        ..Comments::default()
    };
    for f in fields.iter_mut().filter(|f| !f.comments.is_empty()) {
        c.inner
            .entry(Anchor::Field(f.name.clone()))
            .or_default()
            .append(&mut f.comments);
    }
    c
}

/// Whether the reader takes this word as a number (a bad one is an error, never a name).
pub(crate) fn is_numberlike(s: &str) -> bool {
    let first = s.as_bytes().first().copied().unwrap_or(b'a');
    first.is_ascii_digit()
        || matches!(first, b'-' | b'+' | b'.')
        || ["nan", "inf", "infinity"]
            .iter()
            .any(|k| s.eq_ignore_ascii_case(k))
}

impl<'a> Parser<'a> {
    // ---------------------------------------------------------------- tokens and messages

    fn peek(&self) -> Option<Token> {
        // Out of memory, the parse stops: the rest of the file is not read.
        if self.out_of_memory {
            return None;
        }
        self.toks.get(self.pos)
    }

    fn next(&mut self) -> Option<Token> {
        let t = self.peek();
        if t.is_some() {
            self.pos += 1;
        }
        t
    }

    /// Takes the comments that stand before token `tok`, which starts something the scene
    /// keeps comments for (a keyword, a field, a closing brace). Earlier comments nobody
    /// took stood inside something (between a keyword and its value) and are lost.
    fn comments_before(&mut self, tok: usize) -> Vec<String> {
        let mut out = std::mem::take(&mut self.pending_comments);
        while let Some(c) = self.toks.comment(self.next_comment) {
            if c.next_token > tok {
                break;
            }
            self.next_comment += 1;
            let text: &'a str = self.src.text;
            if c.next_token == tok {
                out.push(text[c.start..c.end].to_string());
            } else {
                let d = self.src.diagnostic(
                    Severity::Warning,
                    c.start.saturating_sub(1),
                    "this comment stands inside a value (between a keyword and what it takes), where it cannot be kept: saving the scene drops it",
                );
                self.lost_comments.push(d.clone());
                self.diags.push(d);
            }
        }
        out
    }

    /// Comments before the token just read (`self.pos - 1`).
    fn comments_here(&mut self) -> Vec<String> {
        self.comments_before(self.pos.saturating_sub(1))
    }

    /// Comments before the token just read belong to what comes next (a MaterialIndex's to
    /// the object it applies to).
    fn defer_comments(&mut self) {
        self.pending_comments = self.comments_here();
    }

    fn text(&self, t: Token) -> &'a str {
        let text: &'a str = self.src.text;
        &text[t.start..t.end]
    }

    /// The word that starts at `offset`, as written (for quoting numbers in messages).
    fn word_at(&self, offset: usize) -> &'a str {
        let text: &'a str = self.src.text;
        let rest = text.get(offset..).unwrap_or("");
        let end = rest
            .find(|c: char| c.is_ascii_whitespace() || matches!(c, '{' | '}' | '#'))
            .unwrap_or(rest.len());
        &rest[..end]
    }

    /// How a token reads in a "found …" message.
    fn describe(&self, t: Option<Token>) -> (String, usize) {
        match t {
            Some(t) => (format!("\"{}\"", self.text(t)), t.start),
            None => ("the end of the file".to_string(), self.src.text.len()),
        }
    }

    fn error(&mut self, offset: usize, msg: impl Into<String>) {
        self.fatal = true;
        self.report(Severity::Error, offset, msg);
    }

    fn warn(&mut self, offset: usize, msg: impl Into<String>) {
        self.report(Severity::Warning, offset, msg);
    }

    fn report(&mut self, severity: Severity, offset: usize, msg: impl Into<String>) {
        let u = &mut self.unshown;
        let (shown, unshown) = match severity {
            Severity::Error => (&mut u.shown_errors, &mut u.errors),
            Severity::Warning => (&mut u.shown_warnings, &mut u.warnings),
        };
        if *shown < MAX_SHOWN {
            *shown += 1;
            let d = self.src.diagnostic(severity, offset, msg);
            self.diags.push(d);
        } else {
            if unshown.0 == 0 {
                unshown.1 = offset;
            }
            unshown.0 += 1;
        }
    }

    /// "… and N more", located at the first diagnostic left out.
    fn summarise_unshown(&mut self) -> UnshownSummary {
        let u = &self.unshown;
        let mut out = UnshownSummary::default();
        for (severity, (n, at), what) in [
            (Severity::Error, u.errors, "error"),
            (Severity::Warning, u.warnings, "warning"),
        ] {
            if n > 0 {
                let s = if n == 1 { "" } else { "s" };
                let d = self
                    .src
                    .diagnostic(severity, at, format!("… and {n} more {what}{s}"));
                let place = Some(Located {
                    file: d.file.clone(),
                    line: d.line,
                    col: d.col,
                });
                match severity {
                    Severity::Error => out.errors = (n, place),
                    Severity::Warning => out.warnings = (n, place),
                }
                out.summaries += 1;
                self.diags.push(d);
            }
        }
        out
    }

    /// Skips to just past the `}` that closes a block whose `{` was already read.
    fn skip_block(&mut self) {
        let mut depth = 1usize;
        while let Some(t) = self.next() {
            match t.kind {
                TokKind::Open => depth += 1,
                TokKind::Close => {
                    depth -= 1;
                    if depth == 0 {
                        return;
                    }
                }
                TokKind::Word => {}
            }
        }
    }

    /// Reads the `{` after a keyword; on failure reports it and returns None.
    fn expect_open(&mut self, keyword: &str) -> Option<usize> {
        match self.peek() {
            Some(t) if t.kind == TokKind::Open => {
                self.pos += 1;
                Some(t.start)
            }
            other => {
                let (found, off) = self.describe(other);
                self.error(
                    off,
                    format!("expected \"{{\" after \"{keyword}\", found {found}"),
                );
                None
            }
        }
    }

    /// A whole number after `keyword` (numObjects, MaterialIndex, …).
    fn expect_count(&mut self, keyword: &str) -> Option<(usize, usize)> {
        let t = self.peek();
        if let Some(t) = t.filter(|t| t.kind == TokKind::Word) {
            if let Ok(n) = self.text(t).parse::<usize>() {
                self.pos += 1;
                return Some((n, t.start));
            }
            if is_numberlike(self.text(t)) {
                self.pos += 1;
                let msg = format!(
                    "expected a whole number after \"{keyword}\", found \"{}\"",
                    self.text(t)
                );
                self.error(t.start, msg);
                return None;
            }
        }
        let (found, off) = self.describe(t);
        self.error(
            off,
            format!("expected a whole number after \"{keyword}\", found {found}"),
        );
        None
    }

    /// Reads one number token; reports bad and non-finite numbers.
    fn number_token(&mut self, t: Token, after: &str) -> Option<f32> {
        let s = self.text(t);
        match s.parse::<f32>() {
            Ok(v) if v.is_finite() => Some(v),
            Ok(_) => {
                self.error(
                    t.start,
                    format!("\"{s}\" after \"{after}\" is not a finite number"),
                );
                None
            }
            Err(_) => {
                self.error(
                    t.start,
                    format!("expected a number after \"{after}\", found \"{s}\""),
                );
                None
            }
        }
    }

    /// Exactly `n` numbers after `keyword` (for transform ops).
    fn expect_numbers(&mut self, keyword: &str, n: usize) -> Option<Vec<f32>> {
        let mut out = Vec::with_capacity(n);
        for _ in 0..n {
            let t = self.peek();
            match t {
                Some(t) if t.kind == TokKind::Word && is_numberlike(self.text(t)) => {
                    self.pos += 1;
                    out.push(self.number_token(t, keyword)?);
                }
                other => {
                    let (found, off) = self.describe(other);
                    let what = if n == 1 {
                        "a number".to_string()
                    } else {
                        format!("{n} numbers")
                    };
                    self.error(
                        off,
                        format!("expected {what} after \"{keyword}\", found {found}"),
                    );
                    return None;
                }
            }
        }
        Some(out)
    }

    // ---------------------------------------------------------------- flat blocks

    /// Reads `name numbers…` lines up to the closing `}` of a block whose `{` was read.
    /// Returns None (having reported why) if the block is malformed.
    fn read_fields(&mut self, block: &str, open: usize) -> Option<(Vec<Field>, Vec<String>)> {
        let mut fields: Vec<Field> = Vec::new();
        let mut ok = true;
        let end_comments;
        loop {
            let Some(t) = self.next() else {
                self.error(
                    open,
                    format!(
                        "unterminated {block} block: expected \"}}\" before the end of the file"
                    ),
                );
                return None;
            };
            match t.kind {
                TokKind::Close => {
                    end_comments = self.comments_here();
                    break;
                }
                TokKind::Open => {
                    self.error(t.start, format!("unexpected \"{{\" inside {block}"));
                    self.skip_block();
                    ok = false;
                }
                TokKind::Word => {
                    let name = self.text(t);
                    if is_numberlike(name) {
                        if ok {
                            let msg = match fields.last() {
                                Some(f) if f.values.is_empty() && f.word.is_none() => {
                                    format!(
                                        "expected a number after \"{}\", found \"{name}\"",
                                        f.name
                                    )
                                }
                                _ => format!("unexpected number \"{name}\" in {block}"),
                            };
                            self.error(t.start, msg);
                        }
                        ok = false;
                        continue;
                    }
                    let comments = self.comments_here();
                    let mut field = Field {
                        comments,
                        name: name.to_string(),
                        name_off: t.start,
                        values: Vec::new(),
                        word: None,
                        after: (String::new(), 0),
                        used: false,
                        swallowed: false,
                    };
                    if name == "obj_file" {
                        match self.peek() {
                            Some(w) if w.kind == TokKind::Word => {
                                self.pos += 1;
                                field.word = Some((self.text(w).to_string(), w.start));
                            }
                            other => {
                                let (found, off) = self.describe(other);
                                self.error(
                                    off,
                                    format!(
                                        "expected a file name after \"obj_file\", found {found}"
                                    ),
                                );
                                ok = false;
                            }
                        }
                    } else {
                        let mut too_many = None;
                        while let Some(v) = self.peek().filter(|v| v.kind == TokKind::Word) {
                            if !is_numberlike(self.text(v)) {
                                break;
                            }
                            self.pos += 1;
                            if field.values.len() == MAX_FIELD_NUMBERS {
                                // Skipped, not kept: memory stays bounded by what a scene keeps.
                                too_many.get_or_insert(v.start);
                                continue;
                            }
                            match self.number_token(v, name) {
                                Some(x) => field.values.push((x, v.start)),
                                None => ok = false,
                            }
                        }
                        if let Some(off) = too_many {
                            self.error(
                                off,
                                format!("\"{name}\" takes at most {MAX_FIELD_NUMBERS} numbers"),
                            );
                            ok = false;
                        }
                    }
                    field.after = self.describe(self.peek());
                    fields.push(field);
                }
            }
        }
        ok.then_some((fields, end_comments))
    }

    /// Takes field `name` with exactly `n` numbers; reports what is wrong otherwise.
    fn take(
        &mut self,
        fields: &mut [Field],
        block: &str,
        block_off: usize,
        name: &str,
        n: usize,
    ) -> Option<Vec<f32>> {
        let Some(i) = fields
            .iter()
            .position(|f| f.name == name && (!f.used || f.swallowed))
        else {
            self.error(block_off, format!("{block} is missing \"{name}\""));
            return None;
        };
        fields[i].used = true;
        fields[i].swallowed = false;
        let f = &fields[i];
        if f.values.len() < n {
            let what = if n == 1 {
                "a number".to_string()
            } else {
                format!("{n} numbers")
            };
            let (found, off) = f.after.clone();
            // The word found instead of a number is not a field of its own: do not report
            // it again as unknown.
            if let Some(next) = fields.get_mut(i + 1).filter(|g| g.name_off == off) {
                next.used = true;
                next.swallowed = true;
            }
            self.error(
                off,
                format!("expected {what} after \"{name}\", found {found}"),
            );
            return None;
        }
        if f.values.len() > n {
            let off = f.values[n].1;
            let extra = self.word_at(off);
            self.error(
                off,
                format!("\"{name}\" takes {n} number(s); found an extra \"{extra}\""),
            );
            return None;
        }
        Some(f.values.iter().map(|v| v.0).collect())
    }

    fn take_vec3(
        &mut self,
        fields: &mut [Field],
        block: &str,
        off: usize,
        name: &str,
    ) -> Option<Vec3> {
        self.take(fields, block, off, name, 3)
            .map(|v| Vec3::new(v[0], v[1], v[2]))
    }

    fn take_f32(
        &mut self,
        fields: &mut [Field],
        block: &str,
        off: usize,
        name: &str,
    ) -> Option<f32> {
        self.take(fields, block, off, name, 1).map(|v| v[0])
    }

    /// Reports fields nobody took (unknown or repeated names).
    fn reject_unused(&mut self, fields: &[Field], block: &str, expected: &str) -> bool {
        let mut ok = true;
        for f in fields.iter().filter(|f| !f.used) {
            let repeated = fields.iter().any(|g| g.used && g.name == f.name);
            let msg = if repeated {
                format!("\"{}\" is given twice in {block}", f.name)
            } else {
                format!(
                    "unknown field \"{}\" in {block} (expected {expected})",
                    f.name
                )
            };
            self.error(f.name_off, msg);
            ok = false;
        }
        ok
    }

    // ---------------------------------------------------------------- top level

    fn parse_file(&mut self) {
        while let Some(t) = self.next() {
            match t.kind {
                TokKind::Open => {
                    self.error(t.start, "unexpected \"{\" outside any block");
                    self.skip_block();
                }
                TokKind::Close => self.error(t.start, "unexpected \"}\" outside any block"),
                TokKind::Word => {
                    let kw = self.text(t);
                    match kw {
                        "OrthographicCamera" | "PerspectiveCamera" => {
                            self.camera_seen = true;
                            self.parse_camera(kw, t.start)
                        }
                        "Lights" => self.parse_lights(t.start),
                        "Background" => self.parse_background(t.start),
                        "Materials" => self.parse_materials(t.start),
                        "Group" => {
                            self.group_seen = true;
                            self.parse_object_tree(t.start)
                        }
                        _ => {
                            let hint = if OBJECT_KEYWORDS.contains(&kw) {
                                " (objects belong inside the top-level Group)"
                            } else {
                                " (expected OrthographicCamera, PerspectiveCamera, Lights, Background, Materials or Group)"
                            };
                            self.error(t.start, format!("unknown keyword \"{kw}\"{hint}"));
                            if self.peek().is_some_and(|n| n.kind == TokKind::Open) {
                                self.pos += 1;
                                self.skip_block();
                            }
                        }
                    }
                }
            }
        }
    }

    fn parse_camera(&mut self, kw: &str, off: usize) {
        let before = self.comments_here();
        let Some(open) = self.expect_open(kw) else {
            return;
        };
        let Some((mut f, end)) = self.read_fields(kw, open) else {
            return;
        };
        self.scene_comments.camera = block_comments(before, &mut f, end);
        if self.camera.is_some() {
            self.error(off, "a scene has one camera; this is a second");
        }
        let center = self.take_vec3(&mut f, kw, off, "center");
        let direction = self.take_vec3(&mut f, kw, off, "direction");
        let up = self.take_vec3(&mut f, kw, off, "up");
        let perspective = kw == "PerspectiveCamera";
        let last = if perspective { "angle" } else { "size" };
        let extent = self.take_f32(&mut f, kw, off, last);
        self.reject_unused(&f, kw, &format!("center, direction, up, {last}"));
        let (Some(center), Some(direction), Some(up), Some(extent)) =
            (center, direction, up, extent)
        else {
            return;
        };
        let camera = if perspective {
            Camera::Perspective {
                center,
                direction,
                up,
                angle: extent,
            }
        } else {
            Camera::Orthographic {
                center,
                direction,
                up,
                size: extent,
            }
        };
        if let Err(e) = validate::check_camera(&camera) {
            self.error(off, e.message);
            return;
        }
        self.camera = Some(camera);
    }

    fn parse_background(&mut self, off: usize) {
        let before = self.comments_here();
        let Some(open) = self.expect_open("Background") else {
            return;
        };
        let Some((mut f, end)) = self.read_fields("Background", open) else {
            return;
        };
        self.scene_comments.background = block_comments(before, &mut f, end);
        let mut bg = Background::default();
        if f.iter().any(|x| x.name == "color") {
            bg.color = self.take_vec3(&mut f, "Background", off, "color");
        }
        if f.iter().any(|x| x.name == "ambientLight") {
            bg.ambient = self.take_vec3(&mut f, "Background", off, "ambientLight");
        }
        self.reject_unused(&f, "Background", "color, ambientLight");
        if self.background.is_some() {
            self.error(off, "a scene has one Background; this is a second");
        }
        self.background = Some(bg);
    }

    fn parse_lights(&mut self, off: usize) {
        let mut comments = Comments {
            before: self.comments_here(),
            ..Comments::default()
        };
        let Some(open) = self.expect_open("Lights") else {
            return;
        };
        if self.lights.is_some() {
            self.error(off, "a scene has one Lights block; this is a second");
        }
        let mut lights = Vec::new();
        let mut declared = None;
        loop {
            let Some(t) = self.next() else {
                self.error(
                    open,
                    "unterminated Lights block: expected \"}\" before the end of the file",
                );
                return;
            };
            match (t.kind, self.text(t)) {
                (TokKind::Close, _) => {
                    comments.end = self.comments_here();
                    break;
                }
                (TokKind::Word, "numLights") => {
                    let c = self.comments_here();
                    if !c.is_empty() {
                        comments
                            .inner
                            .entry(Anchor::Field("numLights".into()))
                            .or_default()
                            .extend(c);
                    }
                    declared = self.expect_count("numLights")
                }
                (TokKind::Word, "DirectionalLight") => {
                    let before = self.comments_here();
                    let Some(o) = self.expect_open("DirectionalLight") else {
                        continue;
                    };
                    let Some((mut f, end)) = self.read_fields("DirectionalLight", o) else {
                        continue;
                    };
                    let light_comments = block_comments(before, &mut f, end);
                    let d = self.take_vec3(&mut f, "DirectionalLight", t.start, "direction");
                    let c = self.take_vec3(&mut f, "DirectionalLight", t.start, "color");
                    self.reject_unused(&f, "DirectionalLight", "direction, color");
                    if let (Some(direction), Some(color)) = (d, c) {
                        let light = Light {
                            direction,
                            color,
                            comments: light_comments,
                        };
                        if let Err(e) = validate::check_light(&light) {
                            self.error(t.start, e.message);
                        }
                        lights.push(light);
                    }
                }
                (_, w) => {
                    self.error(t.start, format!("unknown keyword \"{w}\" in Lights (expected numLights or DirectionalLight)"));
                    if t.kind == TokKind::Open
                        || self.peek().is_some_and(|n| n.kind == TokKind::Open)
                    {
                        if t.kind != TokKind::Open {
                            self.pos += 1;
                        }
                        self.skip_block();
                    }
                }
            }
        }
        match declared {
            Some((n, at)) if n != lights.len() => self.error(
                at,
                format!(
                    "numLights says {n} but the block holds {} light(s)",
                    lights.len()
                ),
            ),
            None => self.warn(off, "Lights has no numLights; counting the lights instead"),
            _ => {}
        }
        self.scene_comments.lights = comments;
        self.lights = Some(lights);
    }

    fn parse_material_block(&mut self, kw: &str, off: usize) -> Option<Material> {
        let before = self.comments_here();
        let open = self.expect_open(kw)?;
        let (mut f, end) = self.read_fields(kw, open)?;
        let diffuse = self.take_vec3(&mut f, kw, off, "diffuseColor")?;
        let mut ok = true;
        for (i, x) in f.iter().enumerate() {
            let msg = if x.word.is_some() {
                format!(
                    "\"{}\" belongs in TriangleMesh, not in {kw} (material fields take numbers)",
                    x.name
                )
            } else if f[..i].iter().any(|y| y.name == x.name) {
                format!("\"{}\" is given twice in {kw}", x.name)
            } else {
                continue;
            };
            self.error(x.name_off, msg);
            ok = false;
        }
        if !ok {
            return None;
        }
        let keyword = if kw == "PhongMaterial" {
            MaterialKeyword::PhongMaterial
        } else {
            MaterialKeyword::Material
        };
        // Other fields (specularColor, exponent, …) are kept, not shaded with.
        let extra = f
            .iter()
            .filter(|x| !x.used)
            .map(|x| (x.name.clone(), x.values.iter().map(|v| v.0).collect()))
            .collect();
        let comments = block_comments(before, &mut f, end);
        Some(Material {
            diffuse,
            keyword,
            extra,
            comments,
        })
    }

    fn parse_materials(&mut self, off: usize) {
        let mut comments = Comments {
            before: self.comments_here(),
            ..Comments::default()
        };
        let Some(open) = self.expect_open("Materials") else {
            return;
        };
        let mut declared = None;
        let mut count = 0;
        loop {
            let Some(t) = self.next() else {
                self.error(
                    open,
                    "unterminated Materials block: expected \"}\" before the end of the file",
                );
                return;
            };
            match (t.kind, self.text(t)) {
                (TokKind::Close, _) => {
                    comments.end = self.comments_here();
                    break;
                }
                (TokKind::Word, "numMaterials") => {
                    let c = self.comments_here();
                    if !c.is_empty() {
                        comments
                            .inner
                            .entry(Anchor::Field("numMaterials".into()))
                            .or_default()
                            .extend(c);
                    }
                    declared = self.expect_count("numMaterials")
                }
                (TokKind::Word, kw @ ("Material" | "PhongMaterial")) => {
                    count += 1;
                    if let Some(m) = self.parse_material_block(kw, t.start) {
                        self.materials.push(m);
                    }
                }
                (_, w) => {
                    self.error(
                        t.start,
                        format!("unknown keyword \"{w}\" in Materials (expected numMaterials, Material or PhongMaterial)"),
                    );
                    if t.kind == TokKind::Open
                        || self.peek().is_some_and(|n| n.kind == TokKind::Open)
                    {
                        if t.kind != TokKind::Open {
                            self.pos += 1;
                        }
                        self.skip_block();
                    }
                }
            }
        }
        match declared {
            Some((n, at)) if n != count => self.error(
                at,
                format!("numMaterials says {n} but the block holds {count} material(s)"),
            ),
            None => self.warn(
                off,
                "Materials has no numMaterials; counting the materials instead",
            ),
            _ => {}
        }
        self.scene_comments.materials = comments;
    }

    // ---------------------------------------------------------------- the object tree

    fn parse_object_tree(&mut self, off: usize) {
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
        let mut stack = vec![OpenBlock::Group {
            node: root,
            open,
            declared: None,
            count: 0,
            material: None,
        }];
        while !stack.is_empty() && !self.out_of_memory {
            let Some(t) = self.next() else {
                let (kind, open) = match stack.last() {
                    Some(OpenBlock::Group { open, .. }) => ("Group", *open),
                    Some(OpenBlock::Transform { open, .. }) => ("Transform", *open),
                    Some(OpenBlock::Csg { op, open, .. }) => (op.name(), *open),
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
                        let node = match &frame {
                            OpenBlock::Group { node, .. }
                            | OpenBlock::Transform { node, .. }
                            | OpenBlock::Csg { node, .. } => *node,
                        };
                        graph.node_mut(node).comments.end = self.comments_here();
                        self.close_frame(frame, &mut graph);
                    }
                }
                TokKind::Open => {
                    self.error(t.start, "unexpected \"{\"");
                    self.skip_block();
                }
                TokKind::Word => {
                    let w = self.text(t);
                    if let Some(frame) = stack.last_mut() {
                        match frame {
                            OpenBlock::Group {
                                node,
                                declared,
                                count,
                                material,
                                ..
                            } => {
                                let parent = *node;
                                match w {
                                    "numObjects" => {
                                        let c = self.comments_here();
                                        if !c.is_empty() {
                                            graph
                                                .node_mut(parent)
                                                .comments
                                                .inner
                                                .entry(Anchor::Field("numObjects".into()))
                                                .or_default()
                                                .extend(c);
                                        }
                                        if declared.is_some() {
                                            self.error(
                                                t.start,
                                                "numObjects is given twice in this Group",
                                            );
                                        }
                                        let d = self.expect_count("numObjects");
                                        if let Some(OpenBlock::Group { declared, .. }) =
                                            stack.last_mut()
                                        {
                                            *declared = d.or(*declared);
                                        }
                                    }
                                    "MaterialIndex" => {
                                        self.defer_comments();
                                        if let Some((i, at)) = self.expect_count("MaterialIndex") {
                                            let i = u32::try_from(i).unwrap_or(u32::MAX);
                                            self.material_refs.push((i, at));
                                            *material = Some(i);
                                        }
                                    }
                                    // The lecture's shorthand: a Material placed in a Group adds
                                    // it and applies it to what follows.
                                    "Material" => {
                                        if let Some(m) =
                                            self.parse_material_block("Material", t.start)
                                        {
                                            self.materials.push(m);
                                            let idx = (self.materials.len() - 1) as u32;
                                            if let Some(OpenBlock::Group { material, .. }) =
                                                stack.last_mut()
                                            {
                                                *material = Some(idx);
                                            }
                                        }
                                    }
                                    _ if OBJECT_KEYWORDS.contains(&w) => {
                                        *count += 1;
                                        let mat = *material;
                                        if let Some(f) =
                                            self.start_object(w, t.start, parent, mat, &mut graph)
                                        {
                                            stack.push(f);
                                        }
                                    }
                                    _ => {
                                        // A misspelt object still counts toward numObjects,
                                        // so one typo gives one error.
                                        if self.peek().is_some_and(|n| n.kind == TokKind::Open) {
                                            *count += 1;
                                        }
                                        self.error(
                                            t.start,
                                            format!(
                                                "unknown keyword \"{w}\" in Group (expected numObjects, MaterialIndex or an object: {})",
                                                OBJECT_KEYWORDS.join(", ")
                                            ),
                                        );
                                        self.skip_following_block();
                                    }
                                }
                            }
                            OpenBlock::Transform {
                                node, has_child, ..
                            } => {
                                let parent = *node;
                                if OBJECT_KEYWORDS.contains(&w) {
                                    if *has_child {
                                        self.error(t.start, "a Transform holds exactly one object; this is a second (wrap them in a Group)");
                                    }
                                    *has_child = true;
                                    if let Some(f) =
                                        self.start_object(w, t.start, parent, None, &mut graph)
                                    {
                                        stack.push(f);
                                    }
                                } else {
                                    let c = self.comments_here();
                                    let Some(op) = self.parse_op(w, t.start) else {
                                        continue;
                                    };
                                    match stack.last_mut() {
                                        Some(OpenBlock::Transform { ops, has_child: false, .. }) => {
                                            if !c.is_empty() {
                                                graph.node_mut(parent).comments.inner.entry(Anchor::Op(ops.len())).or_default().extend(c);
                                            }
                                            ops.push(op)
                                        }
                                        _ => self.error(t.start, "transform operations must come before the Transform's object"),
                                    }
                                }
                            }
                            OpenBlock::Csg {
                                node,
                                op,
                                count,
                                material,
                                ..
                            } => {
                                let (parent, op) = (*node, *op);
                                if w == "MaterialIndex" {
                                    self.defer_comments();
                                    if let Some((i, at)) = self.expect_count("MaterialIndex") {
                                        let i = u32::try_from(i).unwrap_or(u32::MAX);
                                        self.material_refs.push((i, at));
                                        if let Some(OpenBlock::Csg { material, .. }) =
                                            stack.last_mut()
                                        {
                                            *material = Some(i);
                                        }
                                    }
                                } else if OBJECT_KEYWORDS.contains(&w) {
                                    *count += 1;
                                    let mat = *material;
                                    if let Some(f) =
                                        self.start_object(w, t.start, parent, mat, &mut graph)
                                    {
                                        stack.push(f);
                                    }
                                } else {
                                    if self.peek().is_some_and(|n| n.kind == TokKind::Open) {
                                        *count += 1;
                                    }
                                    self.error(
                                        t.start,
                                        format!(
                                            "unknown keyword \"{w}\" in {} (expected MaterialIndex or an operand: {})",
                                            op.name(),
                                            OBJECT_KEYWORDS[2..].join(", ")
                                        ),
                                    );
                                    self.skip_following_block();
                                }
                            }
                        }
                    }
                }
            }
        }
        self.graph = Some(graph);
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
                        format!("expected \"}}\" to close {w} after {n} number(s), found {found}"),
                    );
                }
                self.skip_block();
                None
            }
        }
    }

    /// Parses a transform op after its keyword. Reports and returns None on failure
    /// (including an unknown keyword).
    fn parse_op(&mut self, w: &str, off: usize) -> Option<TransformOp> {
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
            "Rotate" | "Matrix" => {
                self.expect_open(w)?;
                let n = if w == "Rotate" { 4 } else { 16 };
                let v = self.expect_numbers(w, n);
                match self.peek() {
                    Some(c) if c.kind == TokKind::Close && v.is_some() => self.pos += 1,
                    other => {
                        if v.is_some() {
                            let (found, at) = self.describe(other);
                            self.error(
                                at,
                                format!(
                                    "expected \"}}\" to close {w} after {n} numbers, found {found}"
                                ),
                            );
                        }
                        // Resynchronise at the end of this block.
                        self.skip_block();
                        return None;
                    }
                }
                let v = v?;
                if w == "Rotate" {
                    TransformOp::Rotate {
                        axis: Vec3::new(v[0], v[1], v[2]),
                        degrees: v[3],
                    }
                } else {
                    let mut a = [0.0f32; 16];
                    a.copy_from_slice(&v);
                    // Written row by row; glam stores columns.
                    TransformOp::Matrix(Mat4::from_cols_array(&a).transpose())
                }
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
        material: Option<u32>,
        graph: &mut Graph,
    ) -> Option<OpenBlock> {
        let before = self.comments_here();
        let open = self.expect_open(w)?;
        let attach = |this: &mut Self, graph: &mut Graph, kind: NodeKind, comments: Comments| {
            // The arrays that grow with every object, fallibly: a scene too big for the
            // memory there is ends the parse with a message, not an abort.
            let id = crate::memory::fallibly(|| {
                this.node_offsets
                    .try_reserve(1)
                    .and_then(|()| this.leaf_offsets.try_reserve(1))
            })
            .map_err(|_| crate::memory::OutOfMemory {
                what: "the scene's objects",
                bytes: (this.node_offsets.len() * 24) as u64,
            })
            .and_then(|()| {
                graph.try_add(Node {
                    kind,
                    material,
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
            this.record_offset(id, off);
            Some(id)
        };
        if let Some(op) = CsgOp::from_name(w) {
            let node = attach(
                self,
                graph,
                NodeKind::Csg(op),
                Comments {
                    before,
                    ..Comments::default()
                },
            )?;
            return Some(OpenBlock::Csg {
                node,
                op,
                keyword: off,
                open,
                count: 0,
                material: None,
            });
        }
        match w {
            "Group" => {
                let node = attach(
                    self,
                    graph,
                    NodeKind::Group,
                    Comments {
                        before,
                        ..Comments::default()
                    },
                )?;
                Some(OpenBlock::Group {
                    node,
                    open,
                    declared: None,
                    count: 0,
                    material: None,
                })
            }
            "Transform" => {
                let node = attach(
                    self,
                    graph,
                    NodeKind::Transform(Vec::new()),
                    Comments {
                        before,
                        ..Comments::default()
                    },
                )?;
                Some(OpenBlock::Transform {
                    node,
                    keyword: off,
                    open,
                    ops: Vec::new(),
                    has_child: false,
                })
            }
            _ => {
                let (kind, mut comments) = self.parse_primitive(w, off, open)?;
                comments.before = before;
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
        if let Err(e) = validate::check_kind(&kind) {
            self.error(off, e.message);
            return None;
        }
        Some((kind, comments))
    }

    fn close_frame(&mut self, frame: OpenBlock, graph: &mut Graph) {
        match frame {
            OpenBlock::Csg {
                node,
                op,
                keyword,
                count,
                ..
            } => {
                if count != 2 {
                    self.error(
                        keyword,
                        format!("{} needs exactly two operand objects (nest them for more), found {count}", op.name()),
                    );
                }
                let operands = graph.node(node).children.clone();
                for c in operands {
                    self.check_operand(graph, c, op);
                }
            }
            OpenBlock::Group {
                declared: Some((n, at)),
                count,
                ..
            } if n != count => {
                self.error(
                    at,
                    format!("numObjects says {n} but the Group holds {count} object(s)"),
                );
            }
            OpenBlock::Group { .. } => {}
            OpenBlock::Transform {
                node,
                keyword,
                ops,
                has_child,
                ..
            } => {
                if !has_child {
                    self.error(keyword, "Transform needs one object after its operations");
                }
                // Ops were checked one by one as read; their product is checked with the
                // whole chain above it once the tree is complete.
                graph.node_mut(node).kind = NodeKind::Transform(ops);
            }
        }
    }

    fn record_offset(&mut self, id: NodeId, off: usize) {
        if self.node_offsets.len() <= id.index() {
            self.node_offsets.resize(id.index() + 1, 0);
        }
        self.node_offsets[id.index()] = off;
    }

    /// An operand must bound a solid: follow Transforms down to the object they move.
    fn check_operand(&mut self, graph: &Graph, id: NodeId, op: CsgOp) {
        let mut cur = id;
        while let Some(NodeKind::Transform(_)) = graph.get(cur).map(|n| &n.kind) {
            match graph.node(cur).children.first() {
                Some(&c) => cur = c,
                // An empty Transform was reported when it closed.
                None => return,
            }
        }
        let at = self.node_offsets.get(cur.index()).copied().unwrap_or(0);
        let Some(node) = graph.get(cur) else { return };
        let name = op.name();
        match &node.kind {
            NodeKind::Sphere { .. } | NodeKind::Box { .. } | NodeKind::Plane { .. } | NodeKind::Csg(_) => {}
            NodeKind::Triangle { .. } => self.error(
                at,
                format!("a lone Triangle is not a solid, so it cannot be an operand of {name} (use a closed TriangleMesh)"),
            ),
            NodeKind::Group => self.error(
                at,
                format!("a Group cannot be an operand of {name}: operands are solids (Sphere, Box, Plane, closed TriangleMesh, a Transform of one, or Union, Intersection, Subtraction); combine several with Union"),
            ),
            // Whether it is closed is known once it is loaded (the resolve step).
            NodeKind::TriangleMesh { .. } => self.mesh_operands.push((cur, op, at)),
            NodeKind::Transform(_) => {}
        }
    }

    // ---------------------------------------------------------------- completion

    fn finish(mut self) -> ParseOutcome {
        let end = self.src.text.len();
        self.scene_comments.end = self.comments_before(self.toks.len());
        let n = self.materials.len();
        for (i, at) in std::mem::take(&mut self.material_refs) {
            if i as usize >= n {
                let range = if n == 0 {
                    "the scene has no materials".to_string()
                } else {
                    format!("valid indices are 0 to {}", n - 1)
                };
                let written = self.word_at(at);
                self.error(
                    at,
                    format!("MaterialIndex {written} is out of range: {range}"),
                );
            }
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
        if let Some(graph) = &self.graph {
            // Composed through each chain, so nested scales are judged together.
            for p in validate::check_world_chain(graph) {
                let at = p
                    .node()
                    .and_then(|id| self.node_offsets.get(id.index()).copied())
                    .unwrap_or(0);
                self.error(at, p.message);
            }
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
        for &(node, op, off) in &self.mesh_operands {
            if let Some(&i) = index.get(&node) {
                refs[i].operand_of.push((op, place(off)));
            }
        }
        refs
    }
}
