//! Writes a scene back in the 6.837 format, canonically indented. Numbers use Rust's
//! shortest round-trip formatting, so every f32 reads back to the same value.

use std::fmt::Write as _;

use glam::Vec3;

use crate::scene::{Camera, Graph, MaterialKeyword, NodeId, NodeKind, Scene, TransformOp};

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
/// when used. (The slides' Material-in-Group shorthand is always written back canonically.)
pub fn uses_only_course_grammar(scene: &Scene) -> bool {
    !scene.graph.iter().any(|(_, n)| n.kind.is_extension())
}

pub fn write_scene(scene: &Scene) -> String {
    let mut out = String::new();
    write_camera(&mut out, &scene.camera);
    if let Some(lights) = &scene.lights {
        out.push_str("\nLights {\n");
        let _ = writeln!(out, "{IND}numLights {}", lights.len());
        for l in lights {
            let _ = writeln!(out, "{IND}DirectionalLight {{");
            let _ = writeln!(out, "{IND}{IND}direction {}", v3(l.direction));
            let _ = writeln!(out, "{IND}{IND}color {}", v3(l.color));
            let _ = writeln!(out, "{IND}}}");
        }
        out.push_str("}\n");
    }
    let bg = &scene.background;
    if bg.color.is_some() || bg.ambient.is_some() {
        out.push_str("\nBackground {\n");
        if let Some(c) = bg.color {
            let _ = writeln!(out, "{IND}color {}", v3(c));
        }
        if let Some(a) = bg.ambient {
            let _ = writeln!(out, "{IND}ambientLight {}", v3(a));
        }
        out.push_str("}\n");
    }
    out.push_str("\nMaterials {\n");
    let _ = writeln!(out, "{IND}numMaterials {}", scene.materials.len());
    for m in &scene.materials {
        let kw = match m.keyword {
            MaterialKeyword::Material => "Material",
            MaterialKeyword::PhongMaterial => "PhongMaterial",
        };
        let _ = writeln!(out, "{IND}{kw} {{");
        let _ = writeln!(out, "{IND}{IND}diffuseColor {}", v3(m.diffuse));
        for (name, values) in &m.extra {
            let vals: Vec<String> = values.iter().map(|&v| num(v)).collect();
            let _ = writeln!(out, "{IND}{IND}{name} {}", vals.join(" "));
        }
        let _ = writeln!(out, "{IND}}}");
    }
    out.push_str("}\n\n");
    write_graph(&mut out, &scene.graph);
    out
}

fn write_camera(out: &mut String, cam: &Camera) {
    let (kw, last, value) = match cam {
        Camera::Orthographic { size, .. } => ("OrthographicCamera", "size", *size),
        Camera::Perspective { angle, .. } => ("PerspectiveCamera", "angle", *angle),
    };
    let _ = writeln!(out, "{kw} {{");
    let _ = writeln!(out, "{IND}center {}", v3(cam.center()));
    let _ = writeln!(out, "{IND}direction {}", v3(cam.direction()));
    let _ = writeln!(out, "{IND}up {}", v3(cam.up()));
    let _ = writeln!(out, "{IND}{last} {}", num(value));
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
                let _ = writeln!(out, "{ind}{IND}{} {} {} {}", num(row.x), num(row.y), num(row.z), num(row.w));
            }
            writeln!(out, "{ind}}}")
        }
    };
}

enum Work {
    Open { id: NodeId, depth: usize, in_group: bool },
    Text(String),
}

/// Depth-first with an explicit stack, so deep trees cannot overflow the call stack.
fn write_graph(out: &mut String, graph: &Graph) {
    let mut stack = vec![Work::Open { id: graph.root(), depth: 0, in_group: false }];
    while let Some(w) = stack.pop() {
        let (id, depth, in_group) = match w {
            Work::Text(t) => {
                out.push_str(&t);
                continue;
            }
            Work::Open { id, depth, in_group } => (id, depth, in_group),
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
            let _ = writeln!(out, "{ind}Group {{\n{ind}{IND}numObjects 1\n{ind}{IND}MaterialIndex {m}");
            closers.push(format!("{ind}}}\n"));
            depth += 1;
        }
        let ind = indent(depth);
        let inner = format!("{ind}{IND}");
        let _ = writeln!(out, "{ind}{} {{", node.kind.name());
        match &node.kind {
            NodeKind::Group | NodeKind::Csg(_) => {
                if node.kind == NodeKind::Group {
                    let _ = writeln!(out, "{inner}numObjects {}", node.children.len());
                }
                // Emit MaterialIndex where a child's own material changes. A block starts
                // with none set (what the reader does), so a child that sets the material it
                // also inherits keeps its MaterialIndex.
                let mut current = None;
                let mut work = Vec::new();
                for &c in &node.children {
                    let want = graph.get(c).and_then(|n| n.material);
                    if let Some(m) = want
                        && current != Some(m)
                    {
                        work.push(Work::Text(format!("{inner}MaterialIndex {m}\n")));
                        current = Some(m);
                    }
                    work.push(Work::Open { id: c, depth: depth + 1, in_group: true });
                }
                closers.insert(0, format!("{ind}}}\n"));
                for c in closers.into_iter().rev() {
                    stack.push(Work::Text(c));
                }
                stack.extend(work.into_iter().rev());
                continue;
            }
            NodeKind::Transform(ops) => {
                for op in ops {
                    write_op(out, &inner, op);
                }
                closers.insert(0, format!("{ind}}}\n"));
                for c in closers.into_iter().rev() {
                    stack.push(Work::Text(c));
                }
                for &c in node.children.iter().rev() {
                    stack.push(Work::Open { id: c, depth: depth + 1, in_group: false });
                }
                continue;
            }
            NodeKind::Sphere { center, radius } => {
                let _ = writeln!(out, "{inner}center {}\n{inner}radius {}", v3(*center), num(*radius));
            }
            NodeKind::Plane { normal, offset } => {
                let _ = writeln!(out, "{inner}normal {}\n{inner}offset {}", v3(*normal), num(*offset));
            }
            NodeKind::Triangle { vertices } => {
                for (i, v) in vertices.iter().enumerate() {
                    let _ = writeln!(out, "{inner}vertex{i} {}", v3(*v));
                }
            }
            NodeKind::TriangleMesh { obj_file, .. } => {
                let _ = writeln!(out, "{inner}obj_file {obj_file}");
            }
            NodeKind::Box { min, max } => {
                let _ = writeln!(out, "{inner}min {}\n{inner}max {}", v3(*min), v3(*max));
            }
        }
        let _ = writeln!(out, "{ind}}}");
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
            assert_eq!(num(x).parse::<f32>().map(f32::to_bits), Ok(x.to_bits()), "{x}");
        }
    }

    #[test]
    fn a_negative_zero_survives_the_round_trip_and_renders_the_same() {
        // Found by the fuzz harness: "center -0 0 0" was written as 0 and moved pixels.
        let text = "PerspectiveCamera { center -0 0 0 direction 0 0 -1 up 0 1 0 angle 90 }\n\
                    Materials { numMaterials 1 Material { diffuseColor 1 1 1 } }\n\
                    Group { numObjects 1 MaterialIndex 0 Sphere { center 0 0 0 radius 5 } }\n";
        let read = |t: &str| parse_scene(t.as_bytes(), "t.txt", None, &mut MeshCache::new()).into_result();
        let scene = read(text).expect("parses").0;
        let back = read(&write_scene(&scene)).expect("reparses").0;
        assert_eq!(back.camera.center().x.to_bits(), (-0.0f32).to_bits());
        let render = |s| render_frame(&compile(s), &RenderSettings::new(4, 4));
        let (a, b) = (render(&scene), render(&back));
        assert!(a.samples.iter().zip(&b.samples).all(|(x, y)| x.color == y.color && x.t.to_bits() == y.t.to_bits()));
    }
}
