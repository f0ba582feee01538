//! Every keyword of the assignment 1–2 grammar reads into the expected scene.

use glam::{Mat4, Vec3};
use tracelab_core::{
    Camera, MaterialKeyword, MeshCache, NodeKind, Scene, TransformOp, parse_scene,
};

fn parse_ok(text: &str) -> Scene {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes");
    let (scene, warnings) =
        parse_scene(text.as_bytes(), "t.txt", Some(&dir), &mut MeshCache::new())
            .into_result()
            .unwrap_or_else(|d| panic!("{d}"));
    assert!(warnings.is_empty(), "{warnings}");
    scene
}

const FULL: &str = "
PerspectiveCamera { center 0 1 5 direction 0 0 -1 up 0 1 0 angle 30 }
Lights { numLights 2
  DirectionalLight { direction 0 -1 0 color 1 1 1 }
  DirectionalLight { direction 1 0 0 color 0.5 0.5 0.5 } }
Background { color 0.1 0.2 0.3 }
Materials { numMaterials 2
  PhongMaterial { diffuseColor 1 0 0 specularColor 1 1 1 exponent 20 }
  Material { diffuseColor 0 1 0 } }
Group { numObjects 5
  MaterialIndex 0
  Sphere { center 1 2 3 radius 4 }
  Plane { normal 0 1 0 offset -2 }
  MaterialIndex 1
  Triangle { vertex0 0 0 0 vertex1 1 0 0 vertex2 0 1 0 }
  TriangleMesh { obj_file ../assets/cube.obj }
  Transform {
    Scale 1 2 3 UniformScale 2 Translate 1 0 0 XRotate 10 YRotate 20 ZRotate 30
    Rotate { 0 0 1 45 }
    Matrix { 1 0 0 5  0 1 0 6  0 0 1 7  0 0 0 1 }
    Group { numObjects 0 }
  }
}
";

#[test]
fn every_keyword_reads_into_the_scene() {
    let s = parse_ok(FULL);
    assert_eq!(
        s.camera,
        Camera::Perspective {
            center: Vec3::new(0.0, 1.0, 5.0),
            direction: Vec3::NEG_Z,
            up: Vec3::Y,
            angle: 30.0
        }
    );
    assert_eq!(s.lights().len(), 2);
    assert_eq!(s.lights()[1].color, Vec3::splat(0.5));
    assert_eq!(s.background.color, Some(Vec3::new(0.1, 0.2, 0.3)));
    assert_eq!(
        s.background.ambient, None,
        "a missing ambientLight stays missing"
    );
    assert_eq!(s.materials[0].keyword, MaterialKeyword::PhongMaterial);
    assert_eq!(
        s.materials[0].extra,
        vec![
            ("specularColor".to_string(), vec![1.0, 1.0, 1.0]),
            ("exponent".to_string(), vec![20.0])
        ]
    );
    assert_eq!(s.materials[1].keyword, MaterialKeyword::Material);

    let g = &s.graph;
    let kids = &g.node(g.root()).children;
    assert_eq!(kids.len(), 5);
    let kinds: Vec<&str> = kids.iter().map(|&c| g.node(c).kind.name()).collect();
    assert_eq!(
        kinds,
        ["Sphere", "Plane", "Triangle", "TriangleMesh", "Transform"]
    );
    let mats: Vec<Option<u32>> = g.effective_materials().to_vec();
    assert_eq!(
        kids.iter().map(|c| mats[c.index()]).collect::<Vec<_>>(),
        [Some(0), Some(0), Some(1), Some(1), Some(1)]
    );
    match &g.node(kids[3]).kind {
        NodeKind::TriangleMesh { mesh, .. } => {
            assert_eq!(mesh.mesh().map(|m| m.triangle_count()), Some(12))
        }
        other => panic!("{other:?}"),
    }
    let NodeKind::Transform(ops) = &g.node(kids[4]).kind else {
        panic!("not a transform")
    };
    let names: Vec<&str> = ops.iter().map(|o| o.name()).collect();
    assert_eq!(
        names,
        [
            "Scale",
            "UniformScale",
            "Translate",
            "XRotate",
            "YRotate",
            "ZRotate",
            "Rotate",
            "Matrix"
        ]
    );
    // Matrix is read row by row: translation in the fourth column.
    let TransformOp::Matrix(m) = &ops[7] else {
        panic!()
    };
    assert_eq!(*m, Mat4::from_translation(Vec3::new(5.0, 6.0, 7.0)));
}

#[test]
fn orthographic_camera_and_missing_lights_give_flat_shading() {
    let s = parse_ok(
        "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 5 }\n\
        Materials { numMaterials 1 Material { diffuseColor 1 0 0 } }\n\
        Group { numObjects 1 MaterialIndex 0 Sphere { center 0 0 0 radius 1 } }\n",
    );
    assert!(matches!(s.camera, Camera::Orthographic { size, .. } if size == 5.0));
    assert!(s.lights.is_none());
    assert_eq!(s.effective_ambient(), Vec3::ONE);
}

#[test]
fn material_index_applies_inside_nested_objects_until_changed() {
    let s = parse_ok(
        "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 5 }\n\
        Materials { numMaterials 2 Material { diffuseColor 1 0 0 } Material { diffuseColor 0 1 0 } }\n\
        Group { numObjects 2 MaterialIndex 1\n\
          Transform { Translate 1 0 0 Group { numObjects 2 Sphere { center 0 0 0 radius 1 } MaterialIndex 0 Sphere { center 0 0 0 radius 1 } } }\n\
          Sphere { center 0 0 0 radius 1 } }\n",
    );
    let eff = s.graph.effective_materials();
    let spheres: Vec<Option<u32>> = s
        .graph
        .iter()
        .filter(|(_, n)| matches!(n.kind, NodeKind::Sphere { .. }))
        .map(|(id, _)| eff[id.index()])
        .collect();
    assert_eq!(spheres, [Some(1), Some(0), Some(1)]);
}
