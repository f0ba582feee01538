//! The format extensions (Box, Union, Intersection, Subtraction) and the slides' shorthand:
//! how they read, how they are written back, and the errors they give with their location.

mod common;
use common::{Rng, mutate};
use std::path::Path;

use glam::Vec3;
use tracelab_core::format::uses_only_course_grammar;
use tracelab_core::{CsgOp, MeshCache, NodeKind, ParseOutcome, Scene, parse_scene, write_scene};

const HEAD: &str = "OrthographicCamera {\n    center 0 0 10\n    direction 0 0 -1\n    up 0 1 0\n    size 5\n}\n\
Materials {\n    numMaterials 2\n    Material { diffuseColor 1 0 0 }\n    Material { diffuseColor 0 0 1 }\n}\n";
/// Lines in HEAD; the first line of a body appended after it is line HEAD_LINES + 1.
const HEAD_LINES: u32 = 11;

fn parse_in(text: &str, dir: &Path) -> ParseOutcome {
    parse_scene(
        text.as_bytes(),
        "scene.txt",
        Some(dir),
        &mut MeshCache::new(),
    )
}

fn parse(text: &str) -> ParseOutcome {
    parse_in(
        text,
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes"),
    )
}

fn parse_ok(text: &str) -> Scene {
    let (scene, warnings) = parse(text).into_result().unwrap_or_else(|d| panic!("{d}"));
    assert!(warnings.is_empty(), "{warnings}");
    scene
}

/// The errors as `line:col: message`, lines counted from the body's first line.
fn errors(objects: &str) -> Vec<String> {
    parse(&format!("{HEAD}{objects}"))
        .diagnostics
        .errors()
        .map(|d| format!("{}:{}: {}", d.line - HEAD_LINES, d.col, d.message))
        .collect()
}

fn round_trip(scene: &Scene) -> (String, Scene) {
    let text = write_scene(scene);
    let back = parse_ok(&text);
    (text, back)
}

#[test]
fn box_and_csg_nodes_read_into_the_graph_with_their_operands_materials() {
    let s = parse_ok(&format!(
        "{HEAD}Group {{\n numObjects 1\n Subtraction {{\n  MaterialIndex 0\n  Box {{ min -1 -2 -3 max 1 2 3 }}\n  MaterialIndex 1\n  Sphere {{ center 0 0 0 radius 1 }}\n }}\n}}\n"
    ));
    let g = &s.graph;
    let csg = g.node(g.root()).children[0];
    assert_eq!(g.node(csg).kind, NodeKind::Csg(CsgOp::Subtraction));
    let ops = &g.node(csg).children;
    assert_eq!(ops.len(), 2);
    assert_eq!(
        g.node(ops[0]).kind,
        NodeKind::Box {
            min: Vec3::new(-1.0, -2.0, -3.0),
            max: Vec3::new(1.0, 2.0, 3.0)
        }
    );
    assert_eq!(
        (g.node(ops[0]).material, g.node(ops[1]).material),
        (Some(0), Some(1))
    );
    assert_eq!(g.node(csg).kind.name(), "Subtraction");
    assert!(g.node(csg).kind.is_container());
}

#[test]
fn every_operand_kind_reads_and_the_scene_round_trips() {
    let s = parse_ok(&format!(
        "{HEAD}Group {{\n numObjects 2\n MaterialIndex 0\n\
         Union {{\n  Intersection {{\n   Plane {{ normal 0 1 0 offset 0 }}\n   TriangleMesh {{ obj_file ../assets/cube.obj }}\n  }}\n\
           Transform {{\n   Translate 1 0 0\n   Subtraction {{ Sphere {{ center 0 0 0 radius 1 }} Box {{ min 0 0 0 max 1 1 1 }} }}\n  }}\n }}\n\
         Box {{ min 0 0 0 max 0.5 0.5 0.5 }}\n}}\n"
    ));
    assert!(!uses_only_course_grammar(&s));
    let (text, back) = round_trip(&s);
    assert_eq!(back, s, "read → write → read changed the scene:\n{text}");
    for word in [
        "Union {",
        "Intersection {",
        "Subtraction {",
        "Box {",
        "min 0 0 0",
        "max 0.5 0.5 0.5",
    ] {
        assert!(text.contains(word), "written text lacks {word:?}:\n{text}");
    }
    // A CSG block has no numObjects (it always holds two).
    let union_block = &text[text.find("Union {").expect("Union")..];
    let first_line_inside = union_block.lines().nth(1).unwrap_or("");
    assert!(!first_line_inside.contains("numObjects"), "{text}");
    assert_eq!(write_scene(&back), text, "writing is canonical");
}

#[test]
fn extensions_are_written_only_when_used() {
    let s = parse_ok(&format!(
        "{HEAD}Group {{\n numObjects 1\n MaterialIndex 0\n Sphere {{ center 0 0 0 radius 1 }}\n}}\n"
    ));
    assert!(uses_only_course_grammar(&s));
    let text = write_scene(&s);
    for word in ["Box", "Union", "Intersection", "Subtraction"] {
        assert!(
            !text.contains(word),
            "{word} written for a course-only scene:\n{text}"
        );
    }
    let with_box = parse_ok(&format!(
        "{HEAD}Group {{\n numObjects 1\n MaterialIndex 0\n Box {{ min 0 0 0 max 1 1 1 }}\n}}\n"
    ));
    assert!(!uses_only_course_grammar(&with_box));
}

#[test]
fn slide_shorthand_reads_and_is_written_back_in_the_course_form() {
    // As the slides write it: Material directly in a Group, Groups without numObjects.
    let slide = "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 5 }\n\
Group {\n  Material { diffuseColor 0 0 1 }\n  Group {\n    Sphere { center 0 0 0 radius 1 }\n    Sphere { center 2 0 0 radius 1 }\n  }\n\
  Group {\n    Material { diffuseColor 0.5 0.3 0.1 }\n    Sphere { center 4 0 0 radius 1 }\n  }\n  Material { diffuseColor 1 0 0 }\n  Plane { normal 0 1 0 offset -1 }\n}\n";
    let s = parse_ok(slide);
    let diffuse: Vec<Vec3> = s.materials.iter().map(|m| m.diffuse).collect();
    assert_eq!(
        diffuse,
        [
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(0.5, 0.3, 0.1),
            Vec3::new(1.0, 0.0, 0.0)
        ]
    );
    // Each object renders with the material placed before it, at whatever level.
    let eff = s.graph.effective_materials();
    let leaves: Vec<Option<u32>> = s
        .graph
        .iter()
        .filter(|(_, n)| !n.kind.is_container())
        .map(|(id, _)| eff[id.index()])
        .collect();
    assert_eq!(leaves, [Some(0), Some(0), Some(1), Some(2)]);
    assert!(
        uses_only_course_grammar(&s),
        "the shorthand is not an extension of what is written"
    );

    let (text, back) = round_trip(&s);
    assert_eq!(back, s, "{text}");
    assert!(text.contains("Materials {\n    numMaterials 3\n"), "{text}");
    // Every Material sits in the Materials block; Groups count their objects.
    let materials_block_end = text.find("\n}\n\nGroup").expect("Materials then Group");
    assert!(
        !text[materials_block_end..].contains("Material {"),
        "{text}"
    );
    assert_eq!(text.matches("numObjects").count(), 3, "{text}");
    assert!(
        text.contains("numObjects 3\n    MaterialIndex 0\n"),
        "{text}"
    );
    assert!(text.contains("MaterialIndex 2\n    Plane"), "{text}");
}

#[test]
fn csg_with_other_than_two_operands_is_an_error_at_its_keyword() {
    let e = errors(
        "Group {\n numObjects 1\n MaterialIndex 0\n Union {\n  Sphere { center 0 0 0 radius 1 }\n }\n}\n",
    );
    assert_eq!(
        e,
        ["4:2: Union needs exactly two operand objects (nest them for more), found 1"]
    );
    let e = errors(
        "Group {\n numObjects 1\n MaterialIndex 0\n Intersection {\n  Sphere { center 0 0 0 radius 1 }\n  Sphere { center 1 0 0 radius 1 }\n  Sphere { center 2 0 0 radius 1 }\n }\n}\n",
    );
    assert_eq!(
        e,
        ["4:2: Intersection needs exactly two operand objects (nest them for more), found 3"]
    );
}

#[test]
fn a_lone_triangle_or_a_group_operand_is_an_error_at_the_operand() {
    let e = errors(
        "Group {\n numObjects 1\n MaterialIndex 0\n Subtraction {\n  Sphere { center 0 0 0 radius 1 }\n  Transform {\n   Translate 1 0 0\n   Triangle { vertex0 0 0 0 vertex1 1 0 0 vertex2 0 1 0 }\n  }\n }\n}\n",
    );
    assert_eq!(
        e,
        [
            "8:4: a lone Triangle is not a solid, so it cannot be an operand of Subtraction (use a closed TriangleMesh)"
        ]
    );
    let e = errors(
        "Group {\n numObjects 1\n MaterialIndex 0\n Union {\n  Group { numObjects 0 }\n  Sphere { center 0 0 0 radius 1 }\n }\n}\n",
    );
    assert_eq!(e.len(), 1, "{e:?}");
    assert!(
        e[0].starts_with("5:3: a Group cannot be an operand of Union"),
        "{e:?}"
    );
}

#[test]
fn an_open_mesh_operand_is_an_error_naming_the_open_edge_and_a_closed_one_is_not() {
    let dir = std::env::temp_dir().join(format!("tracelab-open-mesh-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    // A cube without its top: the rim edges belong to one triangle each.
    std::fs::write(
        dir.join("open_box.obj"),
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
         f 1 4 3 2\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n",
    )
    .expect("write");
    let body = "Group {\n numObjects 1\n MaterialIndex 0\n Union {\n  Sphere { center 0 0 0 radius 1 }\n  TriangleMesh { obj_file open_box.obj }\n }\n}\n";
    let out = parse_in(&format!("{HEAD}{body}"), &dir);
    let e: Vec<_> = out.diagnostics.errors().collect();
    assert_eq!(e.len(), 1, "{:?}", out.diagnostics);
    assert_eq!((e[0].line, e[0].col), (HEAD_LINES + 6, 3));
    assert!(
        e[0].message.starts_with("TriangleMesh \"open_box.obj\" is not a closed solid, so it cannot be an operand of Union: the edge between vertices"),
        "{}",
        e[0]
    );
    assert!(
        e[0].message.ends_with("belongs to 1 triangle(s), not 2"),
        "{}",
        e[0]
    );
    // The same open mesh outside CSG is fine: it is a surface, not a solid.
    let plain =
        "Group {\n numObjects 1\n MaterialIndex 0\n TriangleMesh { obj_file open_box.obj }\n}\n";
    assert!(
        !parse_in(&format!("{HEAD}{plain}"), &dir)
            .diagnostics
            .has_errors()
    );
    let _ = std::fs::remove_dir_all(&dir);
    // The course cube (quads split into triangles) is closed.
    let closed = "Group {\n numObjects 1\n MaterialIndex 0\n Union {\n  Sphere { center 0 0 0 radius 1 }\n  TriangleMesh { obj_file ../assets/cube.obj }\n }\n}\n";
    assert_eq!(errors(closed), Vec::<String>::new());
}

#[test]
fn box_errors_have_locations() {
    let e = errors("Group {\n numObjects 1\n MaterialIndex 0\n Box { min 1 0 0 max 0 1 1 }\n}\n");
    assert_eq!(e, ["4:2: Box: min must not exceed max on any axis"]);
    let e = errors("Group {\n numObjects 1\n MaterialIndex 0\n Box { min 0 0 0 }\n}\n");
    assert_eq!(e, ["4:2: Box is missing \"max\""]);
    let e = errors("Group {\n numObjects 1\n MaterialIndex 0\n Box { min 0 0 0 max 1 1 }\n}\n");
    assert_eq!(e, ["4:26: expected 3 numbers after \"max\", found \"}\""]);
}

/// A flat box (min = max on an axis) used to be accepted and render as nothing: no ray
/// enters a slab of width zero. It is refused where it stands, by the one rule set (so the
/// editor refuses the same edit, and the writer will not write one).
#[test]
fn a_flat_box_is_refused_with_its_location() {
    let e = errors("Group {\n numObjects 1\n MaterialIndex 0\n Box { min 0 2 0 max 1 2 1 }\n}\n");
    assert_eq!(
        e,
        [
            "4:2: Box: min and max are equal on y (2), so the box is flat and would not be seen; give it a thickness"
        ]
    );
    let e = errors("Group {\n numObjects 1\n MaterialIndex 0\n Box { min 0 0 0 max 0 0 0 }\n}\n");
    assert_eq!(e.len(), 1, "{e:?}");
    assert!(
        e[0].starts_with("4:2: Box: min and max are equal on x (0)"),
        "{e:?}"
    );
    // The checked writer (the editor's Save) refuses a box flattened after parsing.
    let mut scene = parse_ok(&format!(
        "{HEAD}Group {{ numObjects 1 MaterialIndex 0 Box {{ min 0 0 0 max 1 1 1 }} }}\n"
    ));
    let id = scene
        .graph
        .iter()
        .find(|(_, n)| matches!(n.kind, NodeKind::Box { .. }))
        .map(|(id, _)| id)
        .expect("a box");
    if let Some(NodeKind::Box { max, .. }) = scene.graph.get_mut(id).map(|n| &mut n.kind) {
        max.z = 0.0;
    }
    let problems = tracelab_core::try_write_scene(&scene).expect_err("a flat box");
    assert!(problems[0].message.contains("equal on z"), "{problems:?}");
}

#[test]
fn unknown_keyword_and_unterminated_csg_are_reported() {
    let e = errors(
        "Group {\n numObjects 1\n MaterialIndex 0\n Union {\n  Sphere { center 0 0 0 radius 1 }\n  Sphre { center 0 0 0 radius 1 }\n }\n}\n",
    );
    assert_eq!(e.len(), 1, "{e:?}");
    assert!(
        e[0].starts_with("6:3: unknown keyword \"Sphre\" in Union"),
        "{e:?}"
    );
    let e = errors(
        "Group {\n numObjects 1\n MaterialIndex 0\n Union {\n  Sphere { center 0 0 0 radius 1 }\n",
    );
    assert_eq!(
        e,
        ["4:8: unterminated Union block: expected \"}\" before the end of the file"]
    );
}

#[test]
fn deeply_nested_csg_neither_overflows_nor_fails() {
    let depth = 20_000;
    let mut text = format!("{HEAD}Group {{\n numObjects 1\n MaterialIndex 0\n");
    for i in 0..depth {
        text.push_str(&format!(
            "Union {{ Sphere {{ center {} 0 0 radius 1 }}\n",
            i % 7
        ));
    }
    text.push_str("Box { min 0 0 0 max 1 1 1 }\n");
    for _ in 0..depth {
        text.push_str("}\n");
    }
    text.push_str("}\n");
    let s = parse_ok(&text);
    let (_, back) = round_trip(&s);
    assert_eq!(back.graph.compacted(), s.graph.compacted());
    // Compiling and tracing the 20 001-leaf tree is iterative too.
    let scene = tracelab_core::compile(&s);
    let ray = tracelab_core::geometry::Ray::new(Vec3::new(0.0, 0.0, 10.0), Vec3::NEG_Z);
    let hit = scene
        .intersect(&ray, 0.0, f32::INFINITY)
        .expect("the union is hit");
    assert!((hit.t - 9.0).abs() < 1e-5, "{}", hit.t);
}

#[test]
fn transform_ops_in_braces_read_as_on_the_slides_and_are_written_bare() {
    let braced = parse_ok(&format!(
        "{HEAD}Group {{\n numObjects 1\n MaterialIndex 0\n Transform {{\n  ZRotate {{ 45 }}\n  Translate {{ -2 0 0 }}\n  Scale {{ 1 2 3 }}\n  Sphere {{ center 0 0 0 radius 1 }}\n }}\n}}\n"
    ));
    let bare = parse_ok(&format!(
        "{HEAD}Group {{\n numObjects 1\n MaterialIndex 0\n Transform {{\n  ZRotate 45\n  Translate -2 0 0\n  Scale 1 2 3\n  Sphere {{ center 0 0 0 radius 1 }}\n }}\n}}\n"
    ));
    assert_eq!(braced, bare);
    let text = write_scene(&braced);
    assert!(
        text.contains("ZRotate 45\n") && text.contains("Translate -2 0 0\n"),
        "{text}"
    );
    let e = errors(
        "Group {\n numObjects 1\n MaterialIndex 0\n Transform {\n  Translate { -2 0 }\n  Sphere { center 0 0 0 radius 1 }\n }\n}\n",
    );
    assert_eq!(
        e,
        ["5:20: expected 3 numbers after \"Translate\", found \"}\""]
    );
    let e = errors(
        "Group {\n numObjects 1\n MaterialIndex 0\n Transform {\n  ZRotate { 45 1 }\n  Sphere { center 0 0 0 radius 1 }\n }\n}\n",
    );
    assert_eq!(
        e,
        ["5:16: expected \"}\" to close ZRotate after 1 number(s), found \"1\""]
    );
}

/// Deterministic xorshift, so failures reproduce.

#[test]
fn no_mutated_csg_scene_panics_and_clean_ones_round_trip() {
    let seed = format!(
        "{HEAD}Group {{ Material {{ diffuseColor 0 1 0 }} Subtraction {{ MaterialIndex 0 Intersection {{ Box {{ min -1 -1 -1 max 1 1 1 }} \
         Sphere {{ center 0 0 0 radius 1.3 }} }} MaterialIndex 1 Transform {{ ZRotate {{ 30 }} Union {{ Plane {{ normal 0 1 0 offset 2 }} \
         TriangleMesh {{ obj_file ../assets/cube.obj }} }} }} }} Box {{ min 0 0 0 max 1 1 1 }} }}\n"
    );
    let words: Vec<&str> = seed.split_whitespace().collect();
    let extra = [
        "{",
        "}",
        "Union",
        "Subtraction",
        "Box",
        "min",
        "max",
        "Triangle",
        "Group",
        "MaterialIndex",
        "Material",
        "1",
    ];
    let mut rng = Rng(0x2545_f491_4f6c_dd1d);
    let mut clean = 0;
    for _ in 0..2000 {
        let text = mutate(&words, &extra, 2, &mut rng);
        let out = parse(&text);
        let Some(scene) = out.scene else {
            assert!(
                out.diagnostics.has_errors(),
                "no scene and no error for {text}"
            );
            continue;
        };
        let c = tracelab_core::compile(&scene);
        let _ = tracelab_core::render_frame(&c, &tracelab_core::RenderSettings::new(6, 6));
        if !out.diagnostics.has_errors() {
            clean += 1;
            let (written, back) = round_trip(&scene);
            assert_eq!(back, scene, "round trip changed\n{text}\ninto\n{written}");
        }
    }
    assert!(
        clean >= 50,
        "only {clean} mutated scenes were clean: the test exercises too little"
    );
}
