//! `CompiledScene::intersect8` against `intersect`, ray by ray: a one-mesh scene under a
//! rotation and non-uniform scale (the packet path, in object space) and a scene of several
//! objects (single rays), over 4x2 pixel tiles as `tracelab bench --packets` traces them.

use tracelab_core::geometry::Ray;
use tracelab_core::{CompiledScene, MeshCache, parse_scene};

const HEAD: &str = "PerspectiveCamera { center 0.4 1.5 6 direction -0.1 -0.25 -1 up 0 1 0 angle 35 }\n\
Lights { numLights 1 DirectionalLight { direction -0.5 -0.6 -1 color 0.8 0.8 0.8 } }\n\
Background { color 0.1 0.1 0.1 ambientLight 0.2 0.2 0.2 }\n\
Materials { numMaterials 1 Material { diffuseColor 0.9 0.2 0.2 } }\n";

fn compiled(objects: &str, n: usize) -> CompiledScene {
    let text = format!("{HEAD}Group {{ numObjects {n} MaterialIndex 0 {objects} }}");
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes");
    let scene = parse_scene(text.as_bytes(), "t.txt", Some(&dir), &mut MeshCache::new())
        .into_result()
        .unwrap_or_else(|d| panic!("{d}\n{text}"))
        .0;
    CompiledScene::new(&scene)
}

/// Every tile of a w x h image, under a few activity masks; returns the hits seen.
fn assert_tiles_agree(c: &CompiledScene, w: u32, h: u32) -> usize {
    let rays = c.camera.pixel_rays(w, h);
    let t_min = c.camera.t_min();
    let mut hits = 0;
    for row in (0..h).step_by(2) {
        for x in (0..w).step_by(4) {
            let packet: [Ray; 8] = std::array::from_fn(|k| {
                let r = (row + (k as u32 >> 2)).min(h - 1);
                rays.row(r).ray((x + (k as u32 & 3)).min(w - 1))
            });
            for active in [0xffu8, 0x0f, 0xa5, 0x00] {
                let got = c.intersect8(&packet, active, t_min, f32::INFINITY);
                for k in 0..8 {
                    let want = if active & (1 << k) != 0 {
                        c.intersect(&packet[k], t_min, f32::INFINITY)
                    } else {
                        None
                    };
                    match (got[k], want) {
                        (None, None) => {}
                        (Some(g), Some(w)) => {
                            assert_eq!(g.t.to_bits(), w.t.to_bits(), "tile ({x}, {row}) ray {k}");
                            assert_eq!(g.object, w.object, "tile ({x}, {row}) ray {k}");
                            hits += 1;
                        }
                        _ => panic!("tile ({x}, {row}) ray {k}: {:?} vs {want:?}", got[k]),
                    }
                }
            }
        }
    }
    hits
}

#[test]
fn one_transformed_mesh_packets_agree_with_single_rays() {
    let c = compiled(
        "Transform { XRotate 25 YRotate -35 Scale 1.3 0.7 1.1 \
         TriangleMesh { obj_file ../scenes/../assets/torus.obj } }",
        1,
    );
    let hits = assert_tiles_agree(&c, 64, 46);
    assert!(hits > 500, "{hits} hits");
}

#[test]
fn several_objects_fall_back_to_single_rays() {
    let c = compiled(
        "Sphere { center 0 0 0 radius 0.7 } \
         Transform { YRotate 20 TriangleMesh { obj_file ../assets/icosphere.obj } } \
         Plane { normal 0 1 0 offset -1 }",
        3,
    );
    let hits = assert_tiles_agree(&c, 36, 20);
    assert!(hits > 500, "{hits} hits");
}
