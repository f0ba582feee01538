//! Writes a scene back in the 6.837 format, canonically indented. Numbers use Rust's
//! shortest round-trip formatting, so every f32 reads back to the same value. Comments go
//! back on lines of their own where the parser attaches them again: before their item's
//! keyword, before the field or op they preceded, or before the closing `}`.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use glam::Vec3;

use super::MAX_SCENE_BYTES;
use crate::scene::{
    Anchor, Camera, Comments, Graph, LightKind, MaterialKeyword, NodeId, NodeKind, Problem, Scene,
    SolidTexture, TransformOp, check_scene,
};

const IND: &str = "    ";
/// Indentation stops growing past this depth, so a file with tens of thousands of nested
/// Groups is written in linear, not quadratic, space.
const MAX_INDENT_DEPTH: usize = 32;

fn indent(depth: usize) -> String {
    IND.repeat(depth.min(MAX_INDENT_DEPTH))
}

fn num(x: f32) -> String {
    // `{}` on f32 prints the shortest text that parses back to the same value, "-0" included:
    // the sign of a zero changes renders (1/-0 is -inf in a ray's slab test).
    format!("{x}")
}

fn v3(v: Vec3) -> String {
    format!("{} {} {}", num(v.x), num(v.y), num(v.z))
}

/// True when the scene can be written in the course's own grammar: it uses none of
/// tracelab's extensions (Box, Union, Intersection, Subtraction), which are written only
/// when used. (The slides' Material-in-Group shorthand is always written back canonically;
/// `#` comments are written back only where the file read had them.)
pub fn uses_only_course_grammar(scene: &Scene) -> bool {
    !scene.graph.iter().any(|(_, n)| n.kind.is_extension())
}

fn comment_lines(out: &mut String, ind: &str, lines: &[String]) {
    for l in lines {
        let _ = writeln!(out, "{ind}#{l}");
    }
}

/// An item's inner comments, each written once before its line; whatever no line took (a
/// field since removed by an edit) is written before the closing `}` rather than dropped.
struct Inner<'a>(BTreeMap<&'a Anchor, &'a Vec<String>>);

impl<'a> Inner<'a> {
    fn new(c: &'a Comments) -> Self {
        Inner(c.inner.iter().collect())
    }

    fn at(&mut self, out: &mut String, ind: &str, anchor: &Anchor) {
        if let Some(lines) = self.0.remove(anchor) {
            comment_lines(out, ind, lines);
        }
    }

    fn field(&mut self, out: &mut String, ind: &str, name: &str) {
        if !self.0.is_empty() {
            self.at(out, ind, &Anchor::Field(name.to_string()));
        }
    }

    /// The leftovers and the end comments, at the block's inner indentation.
    fn finish(self, out: &mut String, ind: &str, end: &[String]) {
        for lines in self.0.into_values() {
            comment_lines(out, ind, lines);
        }
        comment_lines(out, ind, end);
    }
}

/// Scene text longer than the reader takes ([`MAX_SCENE_BYTES`]): written, it could not be
/// opened again. Deep nesting makes the canonical text larger than the file it came from
/// (each level is a line of its own, indented up to `MAX_INDENT_DEPTH`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "its text would be {} MiB, more than the {} MiB tracelab reads as a scene, so it could not be opened again",
    .bytes.div_ceil(1 << 20),
    MAX_SCENE_BYTES >> 20
)]
pub struct TooLargeToReadBack {
    pub bytes: usize,
}

/// Whether scene text is short enough to be read back: what every writer of a scene file
/// checks before writing.
pub fn check_reads_back(text: &str) -> Result<(), TooLargeToReadBack> {
    if text.len() > MAX_SCENE_BYTES {
        Err(TooLargeToReadBack { bytes: text.len() })
    } else {
        Ok(())
    }
}

/// The scene's text, if it passes every validity rule ([`crate::scene::check_scene`]);
/// otherwise what must be fixed first, and nothing is written.
pub fn try_write_scene(scene: &Scene) -> Result<String, Vec<Problem>> {
    let problems = check_scene(scene);
    if problems.is_empty() {
        Ok(write_scene(scene))
    } else {
        Err(problems)
    }
}

/// The scene's text, unchecked: a scene that breaks a rule gives text the parser rejects.
pub fn write_scene(scene: &Scene) -> String {
    let mut out = String::new();
    let sc = &scene.comments;
    write_camera(&mut out, &scene.camera, &sc.camera);
    if let Some(lights) = &scene.lights {
        out.push('\n');
        comment_lines(&mut out, "", &sc.lights.before);
        out.push_str("Lights {\n");
        let mut inner = Inner::new(&sc.lights);
        inner.field(&mut out, IND, "numLights");
        let _ = writeln!(out, "{IND}numLights {}", lights.len());
        let in2 = format!("{IND}{IND}");
        for l in lights {
            comment_lines(&mut out, IND, &l.comments.before);
            let _ = writeln!(out, "{IND}{} {{", l.keyword());
            let mut li = Inner::new(&l.comments);
            match l.kind {
                LightKind::Directional { direction } => {
                    li.field(&mut out, &in2, "direction");
                    let _ = writeln!(out, "{in2}direction {}", v3(direction));
                    li.field(&mut out, &in2, "color");
                    let _ = writeln!(out, "{in2}color {}", v3(l.color));
                }
                LightKind::Point {
                    position,
                    attenuation,
                } => {
                    li.field(&mut out, &in2, "position");
                    let _ = writeln!(out, "{in2}position {}", v3(position));
                    li.field(&mut out, &in2, "color");
                    let _ = writeln!(out, "{in2}color {}", v3(l.color));
                    if let Some(a) = attenuation {
                        li.field(&mut out, &in2, "attenuation");
                        let _ = writeln!(out, "{in2}attenuation {}", v3(a));
                    }
                }
            }
            li.finish(&mut out, &in2, &l.comments.end);
            let _ = writeln!(out, "{IND}}}");
        }
        inner.finish(&mut out, IND, &sc.lights.end);
        out.push_str("}\n");
    } else if !sc.lights.is_empty() {
        // No Lights block to hold them (writing one would light the scene): keep them here.
        out.push('\n');
        comment_lines(
            &mut out,
            "",
            &sc.lights.lines().cloned().collect::<Vec<_>>(),
        );
    }
    let bg = &scene.background;
    if bg.color.is_some() || bg.ambient.is_some() || !sc.background.is_empty() {
        out.push('\n');
        comment_lines(&mut out, "", &sc.background.before);
        out.push_str("Background {\n");
        let mut inner = Inner::new(&sc.background);
        if let Some(c) = bg.color {
            inner.field(&mut out, IND, "color");
            let _ = writeln!(out, "{IND}color {}", v3(c));
        }
        if let Some(a) = bg.ambient {
            inner.field(&mut out, IND, "ambientLight");
            let _ = writeln!(out, "{IND}ambientLight {}", v3(a));
        }
        inner.finish(&mut out, IND, &sc.background.end);
        out.push_str("}\n");
    }
    out.push('\n');
    comment_lines(&mut out, "", &sc.materials.before);
    out.push_str("Materials {\n");
    let mut inner = Inner::new(&sc.materials);
    inner.field(&mut out, IND, "numMaterials");
    let _ = writeln!(out, "{IND}numMaterials {}", scene.materials.len());
    let in2 = format!("{IND}{IND}");
    for m in &scene.materials {
        if let Some(t) = &m.texture {
            write_texture(&mut out, t, &m.comments);
            continue;
        }
        let kw = match m.keyword {
            MaterialKeyword::Material => "Material",
            MaterialKeyword::PhongMaterial => "PhongMaterial",
        };
        comment_lines(&mut out, IND, &m.comments.before);
        let _ = writeln!(out, "{IND}{kw} {{");
        let mut mi = Inner::new(&m.comments);
        mi.field(&mut out, &in2, "diffuseColor");
        let _ = writeln!(out, "{in2}diffuseColor {}", v3(m.diffuse));
        for (name, values) in &m.extra {
            let vals: Vec<String> = values.iter().map(|&v| num(v)).collect();
            mi.field(&mut out, &in2, name);
            let _ = writeln!(out, "{in2}{name} {}", vals.join(" "));
        }
        mi.finish(&mut out, &in2, &m.comments.end);
        let _ = writeln!(out, "{IND}}}");
    }
    inner.finish(&mut out, IND, &sc.materials.end);
    out.push_str("}\n\n");
    write_graph(&mut out, &scene.graph);
    comment_lines(&mut out, "", &sc.end);
    out
}

/// A solid texture in the Materials block (`Material::texture`), its own fields only.
fn write_texture(out: &mut String, t: &SolidTexture, comments: &Comments) {
    let in2 = format!("{IND}{IND}");
    comment_lines(out, IND, &comments.before);
    let _ = writeln!(out, "{IND}{} {{", t.kind.name());
    let mut inner = Inner::new(comments);
    if let Some(ops) = &t.transform {
        inner.field(out, &in2, "Transform");
        let _ = writeln!(out, "{in2}Transform {{");
        let in3 = format!("{in2}{IND}");
        for (i, op) in ops.iter().enumerate() {
            inner.at(out, &in3, &Anchor::Op(i));
            write_op(out, &in3, op);
        }
        let _ = writeln!(out, "{in2}}}");
    }
    for (field, m) in ["materialIndex", "materialIndex#2"].iter().zip(t.materials) {
        inner.field(out, &in2, field);
        let _ = writeln!(out, "{in2}materialIndex {m}");
    }
    if t.kind.has_octaves() {
        inner.field(out, &in2, "octaves");
        let _ = writeln!(out, "{in2}octaves {}", t.octaves);
    }
    if t.kind.has_waves() {
        for (name, v) in [("frequency", t.frequency), ("amplitude", t.amplitude)] {
            inner.field(out, &in2, name);
            let _ = writeln!(out, "{in2}{name} {}", num(v));
        }
    }
    inner.finish(out, &in2, &comments.end);
    let _ = writeln!(out, "{IND}}}");
}

fn write_camera(out: &mut String, cam: &Camera, comments: &Comments) {
    let (kw, last, value) = match cam {
        Camera::Orthographic { size, .. } => ("OrthographicCamera", "size", *size),
        Camera::Perspective { angle, .. } => ("PerspectiveCamera", "angle", *angle),
    };
    comment_lines(out, "", &comments.before);
    let _ = writeln!(out, "{kw} {{");
    let mut inner = Inner::new(comments);
    for (name, v) in [
        ("center", cam.center()),
        ("direction", cam.direction()),
        ("up", cam.up()),
    ] {
        inner.field(out, IND, name);
        let _ = writeln!(out, "{IND}{name} {}", v3(v));
    }
    inner.field(out, IND, last);
    let _ = writeln!(out, "{IND}{last} {}", num(value));
    inner.finish(out, IND, &comments.end);
    out.push_str("}\n");
}

fn write_op(out: &mut String, ind: &str, op: &TransformOp) {
    let _ = match op {
        TransformOp::Scale(s) => writeln!(out, "{ind}Scale {}", v3(*s)),
        TransformOp::UniformScale(s) => writeln!(out, "{ind}UniformScale {}", num(*s)),
        TransformOp::Translate(t) => writeln!(out, "{ind}Translate {}", v3(*t)),
        TransformOp::XRotate(d) => writeln!(out, "{ind}XRotate {}", num(*d)),
        TransformOp::YRotate(d) => writeln!(out, "{ind}YRotate {}", num(*d)),
        TransformOp::ZRotate(d) => writeln!(out, "{ind}ZRotate {}", num(*d)),
        TransformOp::Rotate { axis, degrees } => {
            writeln!(out, "{ind}Rotate {{ {} {} }}", v3(*axis), num(*degrees))
        }
        TransformOp::Matrix(m) => {
            let _ = writeln!(out, "{ind}Matrix {{");
            for r in 0..4 {
                let row = m.row(r);
                let _ = writeln!(
                    out,
                    "{ind}{IND}{} {} {} {}",
                    num(row.x),
                    num(row.y),
                    num(row.z),
                    num(row.w)
                );
            }
            writeln!(out, "{ind}}}")
        }
    };
}

enum Work {
    /// `before_written`: the node's leading comments are already out (in a Group they go
    /// above the MaterialIndex written for the node, where the parser takes them back).
    Open {
        id: NodeId,
        depth: usize,
        in_group: bool,
        before_written: bool,
    },
    Text(String),
}

/// Depth-first with an explicit stack, so deep trees cannot overflow the call stack.
fn write_graph(out: &mut String, graph: &Graph) {
    let mut stack = vec![Work::Open {
        id: graph.root(),
        depth: 0,
        in_group: false,
        before_written: false,
    }];
    while let Some(w) = stack.pop() {
        let (id, depth, in_group, before_written) = match w {
            Work::Text(t) => {
                out.push_str(&t);
                continue;
            }
            Work::Open {
                id,
                depth,
                in_group,
                before_written,
            } => (id, depth, in_group, before_written),
        };
        let Some(node) = graph.get(id) else { continue };
        let mut depth = depth;
        let mut closers = Vec::new();
        // A material set on a node outside a Group's list cannot be written as MaterialIndex
        // there; wrap the node in a one-object Group that sets it.
        if !in_group
            && id != graph.root()
            && let Some(m) = node.material
        {
            let ind = indent(depth);
            let _ = writeln!(
                out,
                "{ind}Group {{\n{ind}{IND}numObjects 1\n{ind}{IND}MaterialIndex {m}"
            );
            closers.push(format!("{ind}}}\n"));
            depth += 1;
        }
        let ind = indent(depth);
        let inner = format!("{ind}{IND}");
        if !before_written {
            comment_lines(out, &ind, &node.comments.before);
        }
        let mut ic = Inner::new(&node.comments);
        // The node's own `}`, after its leftover and end comments.
        let own_closer = |ic: Inner| {
            let mut s = String::new();
            ic.finish(&mut s, &inner, &node.comments.end);
            let _ = writeln!(s, "{ind}}}");
            s
        };
        let _ = writeln!(out, "{ind}{} {{", node.kind.name());
        match &node.kind {
            NodeKind::Group | NodeKind::Csg(_) => {
                if node.kind == NodeKind::Group {
                    ic.field(out, &inner, "numObjects");
                    let _ = writeln!(out, "{inner}numObjects {}", node.children.len());
                }
                // Emit MaterialIndex where a child's own material changes. A block starts
                // with none set (what the reader does), so a child that sets the material it
                // also inherits keeps its MaterialIndex.
                let mut current = None;
                let mut work = Vec::new();
                for &c in &node.children {
                    let child = graph.get(c);
                    if let Some(before) =
                        child.map(|n| &n.comments.before).filter(|b| !b.is_empty())
                    {
                        let mut t = String::new();
                        comment_lines(&mut t, &inner, before);
                        work.push(Work::Text(t));
                    }
                    let want = child.and_then(|n| n.material);
                    if let Some(m) = want
                        && current != Some(m)
                    {
                        work.push(Work::Text(format!("{inner}MaterialIndex {m}\n")));
                        current = Some(m);
                    }
                    work.push(Work::Open {
                        id: c,
                        depth: depth + 1,
                        in_group: true,
                        before_written: true,
                    });
                }
                closers.insert(0, own_closer(ic));
                for c in closers.into_iter().rev() {
                    stack.push(Work::Text(c));
                }
                stack.extend(work.into_iter().rev());
                continue;
            }
            NodeKind::Transform(ops) => {
                for (i, op) in ops.iter().enumerate() {
                    ic.at(out, &inner, &Anchor::Op(i));
                    write_op(out, &inner, op);
                }
                closers.insert(0, own_closer(ic));
                for c in closers.into_iter().rev() {
                    stack.push(Work::Text(c));
                }
                for &c in node.children.iter().rev() {
                    stack.push(Work::Open {
                        id: c,
                        depth: depth + 1,
                        in_group: false,
                        before_written: false,
                    });
                }
                continue;
            }
            NodeKind::Sphere { center, radius } => {
                ic.field(out, &inner, "center");
                let _ = writeln!(out, "{inner}center {}", v3(*center));
                ic.field(out, &inner, "radius");
                let _ = writeln!(out, "{inner}radius {}", num(*radius));
            }
            NodeKind::Plane { normal, offset } => {
                ic.field(out, &inner, "normal");
                let _ = writeln!(out, "{inner}normal {}", v3(*normal));
                ic.field(out, &inner, "offset");
                let _ = writeln!(out, "{inner}offset {}", num(*offset));
            }
            NodeKind::Triangle { vertices } => {
                for (i, v) in vertices.iter().enumerate() {
                    let name = format!("vertex{i}");
                    ic.field(out, &inner, &name);
                    let _ = writeln!(out, "{inner}{name} {}", v3(*v));
                }
            }
            NodeKind::TriangleMesh { obj_file, .. } => {
                ic.field(out, &inner, "obj_file");
                let _ = writeln!(out, "{inner}obj_file {obj_file}");
            }
            NodeKind::Box { min, max } => {
                ic.field(out, &inner, "min");
                let _ = writeln!(out, "{inner}min {}", v3(*min));
                ic.field(out, &inner, "max");
                let _ = writeln!(out, "{inner}max {}", v3(*max));
            }
        }
        out.push_str(&own_closer(ic));
        for c in closers {
            out.push_str(&c);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::format::parse_scene;
    use crate::{MeshCache, RenderSettings, compile, render_frame};

    #[test]
    fn numbers_are_written_so_they_read_back_bit_for_bit() {
        for x in [-0.0f32, 0.0, 1e-45, -3.4028235e38, 0.1, 1.0 / 3.0] {
            assert_eq!(
                num(x).parse::<f32>().map(f32::to_bits),
                Ok(x.to_bits()),
                "{x}"
            );
        }
    }

    #[test]
    fn a_negative_zero_survives_the_round_trip_and_renders_the_same() {
        // Found by the fuzz harness: "center -0 0 0" was written as 0 and moved pixels.
        let text = "PerspectiveCamera { center -0 0 0 direction 0 0 -1 up 0 1 0 angle 90 }\n\
                    Materials { numMaterials 1 Material { diffuseColor 1 1 1 } }\n\
                    Group { numObjects 1 MaterialIndex 0 Sphere { center 0 0 0 radius 5 } }\n";
        let read =
            |t: &str| parse_scene(t.as_bytes(), "t.txt", None, &mut MeshCache::new()).into_result();
        let scene = read(text).expect("parses").0;
        let back = read(&write_scene(&scene)).expect("reparses").0;
        assert_eq!(back.camera.center().x.to_bits(), (-0.0f32).to_bits());
        let render = |s| render_frame(&compile(s), &RenderSettings::new(4, 4));
        let (a, b) = (render(&scene), render(&back));
        assert!(
            a.samples
                .iter()
                .zip(&b.samples)
                .all(|(x, y)| x.color == y.color && x.t.to_bits() == y.t.to_bits())
        );
    }

    const TWO: &str = "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 5 }\n\
                       Lights { numLights 1 DirectionalLight { direction 0 0 -1 color 1 1 1 } }\n\
                       Materials { numMaterials 2 Material { diffuseColor 1 0 0 } Material { diffuseColor 0 1 0 } }\n\
                       Group { numObjects 2 MaterialIndex 1 Sphere { center -1 0 0 radius 1 } Sphere { center 1 0 0 radius 1 } }\n";

    fn two() -> Scene {
        parse_scene(TWO.as_bytes(), "t.txt", None, &mut MeshCache::new())
            .into_result()
            .expect("parses")
            .0
    }

    #[test]
    fn the_checked_writer_writes_nothing_for_a_scene_that_breaks_a_rule() {
        let scene = two();
        assert_eq!(try_write_scene(&scene), Ok(write_scene(&scene)));
        let mut bad = scene.clone();
        if let Some(l) = bad.lights.as_mut().and_then(|l| l.first_mut()) {
            l.kind = LightKind::Directional {
                direction: Vec3::ZERO,
            };
        }
        let p = try_write_scene(&bad).expect_err("a zero light direction");
        assert_eq!(p.len(), 1);
        assert_eq!(
            (p[0].place, &p[0].field),
            (
                crate::scene::Place::Light(0),
                &crate::scene::Field::Direction
            )
        );
        assert_eq!(
            p[0].message,
            "light 0: DirectionalLight: direction must not be zero"
        );
        // An incomplete node (a mesh with no file yet) is never written either.
        let mut incomplete = scene;
        let root = incomplete.graph.root();
        let mesh = incomplete
            .graph
            .add(crate::scene::Node::new(NodeKind::TriangleMesh {
                obj_file: String::new(),
                mesh: crate::scene::MeshSlot::Failed(String::new()),
            }));
        incomplete.graph.push_child(root, mesh);
        let p = try_write_scene(&incomplete).expect_err("no OBJ file");
        assert!(
            p.len() == 1 && p[0].incomplete && p[0].node() == Some(mesh),
            "{p:?}"
        );
    }

    #[test]
    fn an_object_without_its_own_material_continues_its_list_as_the_file_says() {
        // The parser spells the continued material out; an edit can leave it unset. The file
        // has no way to say "not the one before me", so the graph means what the text means.
        let mut scene = two();
        let root = scene.graph.root();
        let second = scene.graph.node(root).children[1];
        scene.graph.node_mut(second).material = None;
        assert_eq!(scene.graph.effective_materials()[second.index()], Some(1));
        let text = write_scene(&scene);
        let back = parse_scene(text.as_bytes(), "t.txt", None, &mut MeshCache::new())
            .into_result()
            .expect("reparses")
            .0;
        assert_eq!(back.graph, scene.graph.with_listed_materials());
        let render = |s| render_frame(&compile(s), &RenderSettings::new(8, 8));
        let (a, b) = (render(&scene), render(&back));
        assert!(
            a.samples
                .iter()
                .zip(&b.samples)
                .all(|(x, y)| x.color == y.color),
            "same colours before and after"
        );
    }
}
