//! The parser on broken input: every kind of error comes back as a value with its exact
//! line:column, several errors are reported from one pass, and no input panics.

mod common;
use common::{Rng, mutate};
use tracelab_core::{
    MeshCache, MeshSlot, NodeKind, ParseOutcome, Severity, parse_scene, parse_scene_unresolved,
    resolve_meshes,
};

const HEAD: &str = "OrthographicCamera {\n    center 0 0 10\n    direction 0 0 -1\n    up 0 1 0\n    size 5\n}\n\
Materials {\n    numMaterials 1\n    Material { diffuseColor 1 0 0 }\n}\n";
/// Lines in HEAD; the first line of a body appended after it is line HEAD_LINES + 1.
const HEAD_LINES: u32 = 10;

fn parse(text: &str) -> ParseOutcome {
    parse_scene(
        text.as_bytes(),
        "scene.txt",
        Some(std::path::Path::new(env!("CARGO_MANIFEST_DIR"))),
        &mut MeshCache::new(),
    )
}

/// The errors as `line:col: message` (file name left out).
fn errors(text: &str) -> Vec<String> {
    parse(text)
        .diagnostics
        .errors()
        .map(|d| format!("{}:{}: {}", d.line, d.col, d.message))
        .collect()
}

fn body(objects: &str) -> String {
    format!("{HEAD}{objects}")
}

fn at(line_in_body: u32, col: u32) -> String {
    format!("{}:{col}:", HEAD_LINES + line_in_body)
}

#[test]
fn parser_reports_missing_radius_with_location() {
    let e = errors(&body(
        "Group {\n    numObjects 1\n    MaterialIndex 0\n    Sphere { center 0 0 0 radius }\n}\n",
    ));
    assert_eq!(
        e,
        [format!(
            "{} expected a number after \"radius\", found \"}}\"",
            at(4, 34)
        )]
    );
}

#[test]
fn a_short_vector_is_one_error_not_also_a_missing_next_field() {
    let e = errors(&body(
        "Group {\n    numObjects 1\n    MaterialIndex 0\n    Sphere { center 0 0 radius 1 }\n}\n",
    ));
    assert_eq!(
        e,
        [format!(
            "{} expected 3 numbers after \"center\", found \"radius\"",
            at(4, 25)
        )]
    );
    // An unknown word in the same place is still reported once, as the found word.
    let e = errors(&body(
        "Group {\n    numObjects 1\n    MaterialIndex 0\n    Sphere { center 0 0 rad 1 radius 1 }\n}\n",
    ));
    assert_eq!(
        e,
        [format!(
            "{} expected 3 numbers after \"center\", found \"rad\"",
            at(4, 25)
        )]
    );
}

#[test]
fn diagnostics_display_as_file_line_col() {
    let out = parse(&body(
        "Group {\n    numObjects 1\n    MaterialIndex 0\n    Sphere { center 0 0 0 radius }\n}\n",
    ));
    let d = out.diagnostics.errors().next().expect("an error");
    assert_eq!(
        d.to_string(),
        "scene.txt:14:34: expected a number after \"radius\", found \"}\""
    );
    assert!(out.scene.is_none());
}

#[test]
fn wrong_object_count_points_at_num_objects() {
    let e = errors(&body(
        "Group {\n    numObjects 3\n    MaterialIndex 0\n    Sphere { center 0 0 0 radius 1 }\n    Sphere { center 1 0 0 radius 1 }\n}\n",
    ));
    assert_eq!(
        e,
        [format!(
            "{} numObjects says 3 but the Group holds 2 object(s)",
            at(2, 16)
        )]
    );
}

#[test]
fn wrong_light_and_material_counts_are_reported() {
    let text = "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 5 }\n\
Lights {\n numLights 2\n DirectionalLight { direction 0 0 -1 color 1 1 1 }\n}\n\
Materials {\n numMaterials 2\n Material { diffuseColor 1 0 0 }\n}\n\
Group { numObjects 0 }\n";
    assert_eq!(
        errors(text),
        [
            "3:12: numLights says 2 but the block holds 1 light(s)",
            "7:15: numMaterials says 2 but the block holds 1 material(s)"
        ]
    );
}

#[test]
fn unknown_keyword_is_reported_and_parsing_continues() {
    let e = errors(&body(
        "Group {\n    numObjects 2\n    MaterialIndex 0\n    Sphre { center 0 0 0 radius 1 }\n    Sphere { center 0 0 0 radius x }\n}\n",
    ));
    assert_eq!(e.len(), 2, "{e:?}");
    assert!(
        e[0].starts_with(&format!("{} unknown keyword \"Sphre\" in Group", at(4, 5))),
        "{e:?}"
    );
    assert_eq!(
        e[1],
        format!(
            "{} expected a number after \"radius\", found \"x\"",
            at(5, 34)
        )
    );
}

#[test]
fn unknown_field_names_the_expected_ones() {
    let e = errors(&body(
        "Group {\n numObjects 1\n MaterialIndex 0\n Sphere { center 0 0 0 radus 1 }\n}\n",
    ));
    assert_eq!(e.len(), 2, "{e:?}");
    assert_eq!(e[0], format!("{} Sphere is missing \"radius\"", at(4, 2)));
    assert_eq!(
        e[1],
        format!(
            "{} unknown field \"radus\" in Sphere (expected center, radius)",
            at(4, 24)
        )
    );
}

#[test]
fn unterminated_block_points_at_its_opening_brace() {
    let e = errors(&body(
        "Group {\n    numObjects 1\n    MaterialIndex 0\n    Sphere { center 0 0 0 radius 1 }\n",
    ));
    assert_eq!(
        e,
        [format!(
            "{} unterminated Group block: expected \"}}\" before the end of the file",
            at(1, 7)
        )]
    );
    let e = errors(&body(
        "Group {\n numObjects 1\n MaterialIndex 0\n Sphere { center 0 0 0 radius 1\n",
    ));
    assert_eq!(
        e[0],
        format!(
            "{} unterminated Sphere block: expected \"}}\" before the end of the file",
            at(4, 9)
        )
    );
}

#[test]
fn bad_and_non_finite_numbers_are_errors() {
    let e = errors(&body(
        "Group {\n numObjects 1\n MaterialIndex 0\n Sphere { center 0 1.2.3 0 radius 1 }\n}\n",
    ));
    assert_eq!(
        e,
        [format!(
            "{} expected a number after \"center\", found \"1.2.3\"",
            at(4, 20)
        )]
    );
    for (bad, col) in [("nan", 31), ("inf", 31), ("1e40", 31), ("-infinity", 31)] {
        let e = errors(&body(&format!(
            "Group {{\n numObjects 1\n MaterialIndex 0\n Sphere {{ center 0 0 0 radius {bad} }}\n}}\n"
        )));
        assert_eq!(
            e,
            [format!(
                "{} \"{bad}\" after \"radius\" is not a finite number",
                at(4, col)
            )],
            "{bad}"
        );
    }
}

#[test]
fn material_index_out_of_range_is_an_error() {
    let e = errors(&body(
        "Group {\n numObjects 1\n MaterialIndex 4\n Sphere { center 0 0 0 radius 1 }\n}\n",
    ));
    assert_eq!(
        e,
        [format!(
            "{} MaterialIndex 4 is out of range: valid indices are 0 to 0",
            at(3, 16)
        )]
    );
}

#[test]
fn object_before_any_material_index_gets_a_warning_not_an_error() {
    let out = parse(&body(
        "Group {\n numObjects 1\n Sphere { center 0 0 0 radius 1 }\n}\n",
    ));
    assert!(out.scene.is_some());
    assert!(!out.diagnostics.has_errors());
    let w: Vec<_> = out.diagnostics.warnings().collect();
    assert_eq!(w.len(), 1);
    assert_eq!((w[0].line, w[0].col), (HEAD_LINES + 3, 2));
}

#[test]
fn singular_transform_names_the_flattening_op() {
    let e = errors(&body(
        "Group {\n numObjects 1\n MaterialIndex 0\n Transform {\n  Translate 1 0 0\n  Scale 0 1 1\n  Sphere { center 0 0 0 radius 1 }\n }\n}\n",
    ));
    assert_eq!(
        e,
        [format!(
            "{} singular transform: Scale(0, 1, 1) flattens space, so rays cannot be moved into object space",
            at(6, 3)
        )]
    );
}

#[test]
fn a_transform_s_first_broken_op_is_reported_at_its_place() {
    // The rules judge a Transform's ops with its node: the first op at fault, where it stands.
    let e = errors(&body(
        "Group {\n numObjects 1\n MaterialIndex 0\n Transform {\n  Translate 1 0 0\n  Scale 1 0 1\n  Rotate { 0 0 0 30 }\n  Sphere { center 0 0 0 radius 1 }\n }\n}\n",
    ));
    assert_eq!(
        e,
        [format!(
            "{} singular transform: Scale(1, 0, 1) flattens space, so rays cannot be moved into object space",
            at(6, 3)
        )]
    );
}

#[test]
fn transform_with_two_objects_or_none_is_an_error() {
    let e = errors(&body(
        "Group {\n numObjects 1\n MaterialIndex 0\n Transform {\n  Sphere { center 0 0 0 radius 1 }\n  Sphere { center 0 0 0 radius 1 }\n }\n}\n",
    ));
    assert_eq!(e.len(), 1, "{e:?}");
    assert!(
        e[0].starts_with(&format!(
            "{} a Transform holds exactly one object",
            at(6, 3)
        )),
        "{e:?}"
    );
    let e = errors(&body(
        "Group {\n numObjects 1\n MaterialIndex 0\n Transform {\n  Translate 1 0 0\n }\n}\n",
    ));
    assert_eq!(
        e,
        [format!(
            "{} Transform needs one object after its operations",
            at(4, 2)
        )]
    );
}

#[test]
fn missing_obj_is_an_error_on_that_node_and_the_scene_survives() {
    let out = parse(&body(
        "Group {\n numObjects 1\n MaterialIndex 0\n TriangleMesh { obj_file no_such_mesh.obj }\n}\n",
    ));
    let e: Vec<_> = out.diagnostics.errors().collect();
    assert_eq!(e.len(), 1);
    assert_eq!((e[0].line, e[0].col), (HEAD_LINES + 4, 26));
    assert!(
        e[0].message
            .starts_with("cannot load OBJ file \"no_such_mesh.obj\": file not found"),
        "{}",
        e[0]
    );
    // Structure is intact: the editor can open it and show the error on the node.
    assert!(out.scene.is_some());
}

/// Parsing opens no file: the mesh is listed with its location and loaded by a step of its
/// own, which reports the same error the one-call `parse_scene` does.
#[test]
fn parsing_alone_leaves_meshes_unresolved_and_resolving_reports_the_missing_file() {
    let text = body(
        "Group {\n numObjects 1\n MaterialIndex 0\n TriangleMesh { obj_file no_such_mesh.obj }\n}\n",
    );
    let mut out = parse_scene_unresolved(text.as_bytes(), "t.txt");
    assert!(!out.diagnostics.has_errors(), "{}", out.diagnostics);
    let scene = out.scene.as_ref().expect("parses");
    let mesh = scene
        .graph
        .preorder()
        .into_iter()
        .find_map(|id| match &scene.graph.node(id).kind {
            NodeKind::TriangleMesh { mesh, .. } => Some(mesh.clone()),
            _ => None,
        });
    assert_eq!(mesh, Some(MeshSlot::Unresolved));
    assert_eq!(out.meshes.len(), 1);
    assert_eq!(
        (
            out.meshes[0].obj_file.as_str(),
            out.meshes[0].at.line,
            out.meshes[0].at.col
        ),
        ("no_such_mesh.obj", HEAD_LINES + 4, 26)
    );
    resolve_meshes(&mut out, None, &mut MeshCache::new());
    let e: Vec<_> = out.diagnostics.errors().collect();
    assert_eq!(e.len(), 1, "{}", out.diagnostics);
    assert_eq!((e[0].line, e[0].col), (HEAD_LINES + 4, 26));
    assert!(
        e[0].message
            .starts_with("cannot load OBJ file \"no_such_mesh.obj\": file not found"),
        "{}",
        e[0]
    );
    assert!(out.meshes.is_empty(), "resolved once");
    let scene = out.scene.expect("still usable");
    assert!(scene.graph.preorder().into_iter().any(|id| matches!(
        &scene.graph.node(id).kind,
        NodeKind::TriangleMesh {
            mesh: MeshSlot::Failed(_),
            ..
        }
    )));
}

/// A million missing meshes are reported as a screenful, as the parser's own errors are.
#[test]
fn many_missing_meshes_are_capped_like_parse_errors() {
    let n = 500;
    let objects: String = (0..n)
        .map(|i| format!(" TriangleMesh {{ obj_file missing_{i}.obj }}\n"))
        .collect();
    let out = parse(&body(&format!(
        "Group {{\n numObjects {n}\n MaterialIndex 0\n{objects}}}\n"
    )));
    let e: Vec<_> = out.diagnostics.errors().collect();
    assert_eq!(e.len(), 21, "20 shown and a summary");
    assert_eq!(e[20].message, format!("… and {} more errors", n - 20));
    assert!(e[20].message.len() < 40);
}

/// The parser's errors and the meshes' share one cap: 20 shown in all, one "… and N more".
#[test]
fn parse_errors_and_missing_meshes_share_one_cap() {
    let spheres: String = (0..25)
        .map(|i| format!(" Sphere {{ center {i} 0 0 }}\n"))
        .collect();
    let meshes: String = (0..5)
        .map(|i| format!(" TriangleMesh {{ obj_file gone_{i}.obj }}\n"))
        .collect();
    let text = body(&format!(
        "Group {{\n numObjects 30\n MaterialIndex 0\n{spheres}{meshes}}}\n"
    ));
    let more = |d: &tracelab_core::Diagnostics| -> usize {
        d.errors()
            .find_map(|e| {
                e.message
                    .strip_prefix("… and ")?
                    .strip_suffix(" more errors")?
                    .parse()
                    .ok()
            })
            .unwrap_or(0)
    };
    let parsed = parse_scene_unresolved(text.as_bytes(), "t.txt");
    let parse_errors = parsed.diagnostics.errors().count() - 1 + more(&parsed.diagnostics);
    assert!(parse_errors >= 25, "{}", parsed.diagnostics);
    let out = parse(&text);
    let e: Vec<_> = out.diagnostics.errors().collect();
    assert_eq!(e.len(), 21, "{}", out.diagnostics);
    assert_eq!(
        more(&out.diagnostics),
        parse_errors + 5 - 20,
        "{}",
        out.diagnostics
    );
    assert!(
        e[20].message.starts_with("… and "),
        "the summary stays last: {}",
        out.diagnostics
    );
}

#[test]
fn broken_obj_reports_the_obj_line() {
    let dir = std::env::temp_dir().join(format!("tracelab-broken-obj-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    std::fs::write(
        dir.join("broken.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 one 0\nf 1 2 3\n",
    )
    .expect("write");
    let text = body(
        "Group {\n numObjects 1\n MaterialIndex 0\n TriangleMesh { obj_file broken.obj }\n}\n",
    );
    let out = parse_scene(
        text.as_bytes(),
        "scene.txt",
        Some(&dir),
        &mut MeshCache::new(),
    );
    let e: Vec<_> = out.diagnostics.errors().collect();
    assert_eq!(e.len(), 1);
    assert!(e[0].message.contains("broken.obj:4:"), "{}", e[0]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_file_that_is_not_text_is_reported_with_its_location() {
    let mut bytes = b"OrthographicCamera {\n center 0 0".to_vec();
    bytes.extend_from_slice(&[0xff, 0xfe, 0x00, 0x01]);
    let out = parse_scene(&bytes, "scene.txt", None, &mut MeshCache::new());
    let e: Vec<_> = out.diagnostics.errors().collect();
    assert_eq!(e.len(), 1);
    assert_eq!((e[0].line, e[0].col), (2, 12));
    assert!(e[0].message.contains("not a text scene file"), "{}", e[0]);
    let out = parse_scene(b"Group {\0}", "scene.txt", None, &mut MeshCache::new());
    assert!(
        out.diagnostics
            .errors()
            .next()
            .is_some_and(|d| d.message.contains("NUL"))
    );
}

#[test]
fn one_pass_reports_several_errors() {
    let text = "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size x }\n\
Materials { numMaterials 1 Material { diffuseColor 1 0 } }\n\
Group {\n numObjects 2\n MaterialIndex 7\n Sphere { center 0 0 0 radius 1 }\n Plane { normal 0 1 0 offset nan }\n}\n";
    let e = errors(text);
    assert_eq!(e.len(), 4, "{e:?}");
    assert!(
        e[0].starts_with("1:67: expected a number after \"size\""),
        "{e:?}"
    );
    assert!(
        e[1].starts_with("2:56: expected 3 numbers after \"diffuseColor\""),
        "{e:?}"
    );
    assert!(e[2].starts_with("7:30: \"nan\" after \"offset\""), "{e:?}");
    assert!(
        e[3].starts_with("5:16: MaterialIndex 7 is out of range"),
        "{e:?}"
    );
}

#[test]
fn missing_camera_and_group_are_errors() {
    let e = errors("Materials { numMaterials 0 }\n");
    assert_eq!(e.len(), 2);
    assert!(e[0].contains("no camera"));
    assert!(e[1].contains("no Group"));
}

#[test]
fn deep_nesting_parses_renders_writes_and_drops_without_overflow() {
    const DEPTH: usize = 50_000;
    let mut text = String::from(HEAD);
    for _ in 0..DEPTH {
        text.push_str("Group {\nnumObjects 1\n");
    }
    text.push_str("MaterialIndex 0\nSphere { center 0 0 0 radius 1 }\n");
    for _ in 0..DEPTH {
        text.push_str("}\n");
    }
    let start = std::time::Instant::now();
    let (scene, _) = parse(&text).into_result().expect("parses");
    let compiled = tracelab_core::compile(&scene);
    let frame = tracelab_core::render_frame(&compiled, &tracelab_core::RenderSettings::new(8, 8));
    assert!(frame.samples.iter().any(|s| s.is_hit()));
    let written = tracelab_core::write_scene(&scene);
    let again = parse(&written).into_result().expect("reparses").0;
    assert_eq!(again, scene);
    let copy = scene.clone();
    drop(scene);
    drop(copy);
    // Not a timing test: a generous bound that only an accidental quadratic walk would break.
    assert!(start.elapsed().as_secs() < 60);
}

/// Deterministic xorshift, so failures reproduce.

#[test]
fn no_input_panics_the_parser() {
    let seed_text = body(
        "Group {\n numObjects 3\n MaterialIndex 0\n Sphere { center 0 0 0 radius 1 }\n Transform {\n  Scale 1 2 1\n  Rotate { 0 0 1 30 }\n  Matrix { 1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1 }\n  Plane { normal 0 1 0 offset -1 }\n }\n Triangle { vertex0 0 0 0 vertex1 1 0 0 vertex2 0 1 0 }\n}\n",
    );
    let words: Vec<&str> = seed_text.split_whitespace().collect();
    let extra = [
        "{",
        "}",
        "-",
        "1e999",
        "nan",
        "Group",
        "Transform",
        "numObjects",
        "MaterialIndex",
        "0",
        "é",
        "\u{0}",
        "TriangleMesh",
        "obj_file",
    ];
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for _ in 0..3000 {
        let text = mutate(&words, &extra, 6, &mut rng);
        let out = parse(&text);
        // Whatever came back must be usable: render and write it if it parsed.
        if let Some(scene) = out.scene {
            let c = tracelab_core::compile(&scene);
            let _ = tracelab_core::render_frame(&c, &tracelab_core::RenderSettings::new(4, 4));
            let _ = tracelab_core::write_scene(&scene);
        } else {
            assert!(
                out.diagnostics
                    .0
                    .iter()
                    .any(|d| d.severity == Severity::Error),
                "no scene and no error for {text}"
            );
        }
    }
}

// Issue 11, "renders that are silently wrong": each is now an error with its location, or
// (strong scales, huge vectors) accepted and rendered right (tests/validity_render.rs).

fn one_object(object: &str) -> String {
    body(&format!(
        "Group {{\n numObjects 1\n MaterialIndex 0\n{object}}}\n"
    ))
}

#[test]
fn a_projective_matrix_is_an_error_not_the_identity() {
    let e = errors(&one_object(
        " Transform {\n  Matrix { 1 0 0 0  0 1 0 0  0 0 1 0  0.5 0 0 1 }\n  Sphere { center 0 0 0 radius 1 }\n }\n",
    ));
    assert_eq!(
        e,
        [format!(
            "{} Matrix: the last row must be 0 0 0 1 (a projective matrix cannot move rays), found 0.5 0 0 1",
            at(5, 3)
        )]
    );
}

#[test]
fn a_zero_rotate_axis_is_an_error_not_the_identity() {
    let e = errors(&one_object(
        " Transform {\n  Rotate { 0 0 0 45 }\n  Sphere { center 0 0 0 radius 1 }\n }\n",
    ));
    assert_eq!(
        e,
        [format!("{} Rotate: the axis must not be zero", at(5, 3))]
    );
}

#[test]
fn a_negative_or_zero_radius_is_an_error_not_its_absolute_value() {
    let e = errors(&one_object(" Sphere { center 0 0 0 radius -1 }\n"));
    assert_eq!(
        e,
        [format!(
            "{} Sphere: radius must be positive, found -1",
            at(4, 2)
        )]
    );
    let e = errors(&one_object(" Sphere { center 0 0 0 radius 0 }\n"));
    assert_eq!(
        e,
        [format!(
            "{} Sphere: radius must be positive, found 0",
            at(4, 2)
        )]
    );
}

#[test]
fn tiny_and_huge_uniform_scales_are_accepted_and_nested_ones_judged_together() {
    for s in ["0.0001", "1e13"] {
        let out = parse(&one_object(&format!(
            " Transform {{\n  UniformScale {s}\n  Sphere {{ center 0 0 0 radius 1 }}\n }}\n"
        )));
        assert!(!out.diagnostics.has_errors(), "{s}: {}", out.diagnostics);
    }
    // Each squashes y by 1e-4, fine alone; together 1e-8 leaves f32 no digits.
    let e = errors(&one_object(
        " Transform {\n  Scale 1 0.0001 1\n  Transform {\n   Scale 1 0.0001 1\n   Sphere { center 0 0 0 radius 1 }\n  }\n }\n",
    ));
    assert_eq!(
        e,
        [format!(
            "{} singular transform: the combined transforms down to here squashes one direction so much more than another that rays lose all precision",
            at(6, 3)
        )]
    );
    // Three 1e13 scales (1e39) leave f32's range: reported once, at the Transform that does.
    let mut nested = "Sphere { center 0 0 0 radius 1 }".to_string();
    for _ in 0..4 {
        nested = format!("Transform {{ UniformScale 1e13 {nested} }}");
    }
    let e = errors(&one_object(&format!(" {nested}\n")));
    assert_eq!(
        e,
        [format!(
            "{} singular transform: the combined transforms down to here overflows",
            at(4, 62)
        )]
    );
}

#[test]
fn overflowing_vector_lengths_are_accepted_as_directions() {
    let src = "OrthographicCamera { center 0 0 10 direction 0 0 -3e38 up 0 1 0 size 5 }\n\
               Lights { numLights 1 DirectionalLight { direction 0 -1e20 -1e20 color 1 1 1 } }\n\
               Materials { numMaterials 1 Material { diffuseColor 1 0 0 } }\n\
               Group { numObjects 1 MaterialIndex 0 Plane { normal 0 0 1e20 offset 0 } }\n";
    let out = parse(src);
    assert!(!out.diagnostics.has_errors(), "{}", out.diagnostics);
    // A camera direction really parallel to up is still one, however long.
    let e = errors(&src.replace("0 0 -3e38 up", "0 3e38 0 up"));
    assert_eq!(
        e,
        ["1:1: OrthographicCamera: up must not be zero or parallel to direction"]
    );
}
