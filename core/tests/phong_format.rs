//! Assignments 3–4 in the format: PhongMaterial's fields and PointLight read with the
//! course's defaults, located errors for each new field, exact round trips, and every
//! assignment 3–4 course scene read without a warning.

mod common;

use glam::Vec3;
use tracelab_core::scene::{LightKind, Phong};
use tracelab_core::{MeshCache, ParseOutcome, Scene, parse_scene, write_scene};

fn parse(text: &str) -> ParseOutcome {
    parse_scene(
        text.as_bytes(),
        "scene.txt",
        Some(std::path::Path::new(env!("CARGO_MANIFEST_DIR"))),
        &mut MeshCache::new(),
    )
}

fn parse_ok(text: &str) -> Scene {
    let (scene, warnings) = parse(text).into_result().unwrap_or_else(|d| panic!("{d}"));
    assert!(warnings.is_empty(), "{warnings}");
    scene
}

/// `line:col: message` of each error, or of each warning.
fn said(text: &str, errors: bool) -> Vec<String> {
    let o = parse(text);
    let list: Vec<_> = if errors {
        o.diagnostics.errors().collect()
    } else {
        o.diagnostics.warnings().collect()
    };
    list.iter()
        .map(|d| format!("{}:{}: {}", d.line, d.col, d.message))
        .collect()
}

fn scene_with(lights: &str, materials: &str) -> String {
    format!(
        "PerspectiveCamera {{ center 0 0 10 direction 0 0 -1 up 0 1 0 angle 30 }}\n\
         Lights {{\n{lights}}}\n\
         Background {{ color 0 0 0 ambientLight 0.1 0.1 0.1 }}\n\
         Materials {{\n{materials}}}\n\
         Group {{ numObjects 1 MaterialIndex 0 Sphere {{ center 0 0 0 radius 1 }} }}\n"
    )
}

const ONE_LIGHT: &str = "numLights 1\nDirectionalLight { direction 0 0 -1 color 1 1 1 }\n";
const ONE_MATERIAL: &str = "numMaterials 1\nMaterial { diffuseColor 1 0 0 }\n";

#[test]
fn phong_fields_read_in_any_order_with_the_course_defaults_for_the_rest() {
    let s = parse_ok(&scene_with(
        ONE_LIGHT,
        "numMaterials 3\n\
         PhongMaterial { exponent 32 diffuseColor 1 0 0 specularColor 0.5 0.5 0.5 }\n\
         PhongMaterial { diffuseColor 0.2 0.2 0.2 reflectiveColor 0.9 0.9 0.9 \
         transparentColor 0.1 0.2 0.3 indexOfRefraction 1.5 }\n\
         Material { diffuseColor 1 1 1 specularColor 1 1 1 }\n",
    ));
    let p = s.materials[0].phong();
    assert_eq!(s.materials[0].diffuse, Vec3::new(1.0, 0.0, 0.0));
    assert_eq!(
        p,
        Phong {
            specular: Vec3::splat(0.5),
            exponent: 32.0,
            ..Phong::default()
        }
    );
    let q = s.materials[1].phong();
    assert_eq!(q.reflective, Vec3::splat(0.9));
    assert_eq!(q.transparent, Vec3::new(0.1, 0.2, 0.3));
    assert_eq!(q.index_of_refraction, 1.5);
    assert_eq!(q.specular, Vec3::ZERO, "absent: the course's default");
    // `Material` is read the same way, as the course's parser does.
    assert_eq!(s.materials[2].phong().specular, Vec3::ONE);
}

#[test]
fn point_lights_read_with_and_without_attenuation_beside_directional_ones() {
    let s = parse_ok(&scene_with(
        "numLights 3\n\
         PointLight { position 1 2 3 color 1 0.5 0 attenuation 0 0 0.25 }\n\
         DirectionalLight { direction 0 -1 0 color 1 1 1 }\n\
         PointLight { color 1 1 1 position 0 5 0 }\n",
        ONE_MATERIAL,
    ));
    let l = s.lights();
    assert_eq!(
        l[0].kind,
        LightKind::Point {
            position: Vec3::new(1.0, 2.0, 3.0),
            attenuation: Some(Vec3::new(0.0, 0.0, 0.25))
        }
    );
    assert_eq!(l[0].color, Vec3::new(1.0, 0.5, 0.0));
    assert_eq!(l[1].direction(), Some(Vec3::NEG_Y));
    assert_eq!(
        l[2].kind,
        LightKind::Point {
            position: Vec3::new(0.0, 5.0, 0.0),
            attenuation: None
        },
        "a missing attenuation stays missing (the course's 1 0 0)"
    );
}

#[test]
fn phong_scenes_round_trip_exactly() {
    let text = scene_with(
        "numLights 2\n\
         PointLight { position 1 2 3 color 1 0.5 0 attenuation 1 0.5 0.25 }\n\
         PointLight { position -1 2 3 color 0.1 0.2 0.3 }\n",
        "numMaterials 2\n\
         PhongMaterial { diffuseColor 1 0 0 specularColor 0.5 0.5 0.5 exponent 32 \
         reflectiveColor 0.1 0.1 0.1 transparentColor 0.9 0.9 0.9 indexOfRefraction 2.413 }\n\
         Material { diffuseColor 0.1 0.2 0.3 exponent 7 }\n",
    );
    let s = parse_ok(&text);
    let written = write_scene(&s);
    let back = parse_ok(&written);
    assert_eq!(s.reads_back_as(&back), Ok(()));
    assert_eq!(write_scene(&back), written, "the writer is a fixed point");
    assert_eq!(back.materials[0].phong(), s.materials[0].phong());
    assert_eq!(back.lights(), s.lights());
}

#[test]
fn every_new_field_is_refused_at_its_own_line_and_column() {
    let m = |body: &str| scene_with(ONE_LIGHT, &format!("numMaterials 1\n{body}\n"));
    // Line 9 is the material's line in `scene_with` (a refused material also leaves the
    // MaterialIndex out of range: only the first error is the field's).
    let cases = [
        (
            m("PhongMaterial { diffuseColor 1 0 0 specularColor 1 1 }"),
            "9:36: \"specularColor\" takes 3 number(s), found 2",
        ),
        (
            m("PhongMaterial { diffuseColor 1 0 0 exponent 1 2 }"),
            "9:36: \"exponent\" takes 1 number(s), found 2",
        ),
        (
            m("PhongMaterial { diffuseColor 1 0 0 exponent -3 }"),
            "9:36: exponent must not be negative, found -3",
        ),
        (
            m("PhongMaterial { diffuseColor 1 0 0 indexOfRefraction 0 }"),
            "9:36: indexOfRefraction must be positive, found 0",
        ),
    ];
    for (text, want) in &cases {
        assert_eq!(said(text, true).first().map(String::as_str), Some(*want));
    }
    let l = |body: &str| scene_with(&format!("numLights 1\n{body}\n"), ONE_MATERIAL);
    let e = said(
        &l("PointLight { position 0 0 0 color 1 1 1 attenuation 0 0 0 }"),
        true,
    );
    assert_eq!(e.len(), 1, "{e:?}");
    assert!(e[0].starts_with("4:41: PointLight: attenuation"), "{e:?}");
    let e = said(&l("PointLight { color 1 1 1 }"), true);
    assert_eq!(e[0], "4:1: PointLight is missing \"position\"");
    let e = said(
        &l("PointLight { position 0 0 0 color 1 1 1 radius 2 }"),
        true,
    );
    assert_eq!(
        e,
        ["4:41: unknown field \"radius\" in PointLight (expected position, color, attenuation)"]
    );
    let e = said(&l("SpotLight { position 0 0 0 }"), true);
    assert!(
        e[0].starts_with("4:1: unknown keyword \"SpotLight\" in Lights"),
        "{e:?}"
    );
}

#[test]
fn a_material_field_tracelab_does_not_render_is_named_in_a_warning_never_ignored() {
    let text = scene_with(
        ONE_LIGHT,
        "numMaterials 1\nPhongMaterial { diffuseColor 1 0 0 shininess 3 }\n",
    );
    let w = said(&text, false);
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].starts_with("9:36: \"shininess\" is not a field tracelab renders"),
        "{w:?}"
    );
    // Kept and written back all the same.
    let (s, _) = parse(&text).into_result().expect("a warning only");
    assert!(write_scene(&s).contains("shininess 3"));
}

#[test]
#[ignore = "needs the course's assignment 3-7 files: TRACELAB_SEMESTER_DIR, default ../shared/mit6837-semester"]
fn every_assignment_3_and_4_scene_reads_without_a_warning_and_round_trips() {
    let dir = common::semester_dir().join("scenes");
    let mut read = 0;
    let mut names: Vec<_> = std::fs::read_dir(&dir)
        .expect("scenes")
        .map(|e| e.expect("entry").path())
        .filter(|p| {
            let n = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
            n.starts_with("scene3_") || n.starts_with("scene4_")
        })
        .collect();
    names.sort();
    for p in names {
        let bytes = std::fs::read(&p).expect("read");
        let o = parse_scene(
            &bytes,
            &p.display().to_string(),
            Some(&dir),
            &mut MeshCache::new(),
        );
        let (s, w) = o.into_result().unwrap_or_else(|d| panic!("{d}"));
        assert!(w.is_empty(), "{}: {w}", p.display());
        let written = write_scene(&s);
        let back = parse_scene(
            written.as_bytes(),
            "back",
            Some(&dir),
            &mut MeshCache::new(),
        )
        .into_result()
        .unwrap_or_else(|d| panic!("{}: {d}", p.display()))
        .0;
        assert_eq!(s.reads_back_as(&back), Ok(()), "{}", p.display());
        read += 1;
    }
    assert_eq!(read, 26, "12 assignment-3 and 14 assignment-4 scenes");
}
