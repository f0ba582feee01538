//! `CompiledScene::intersect8` against `intersect`, ray by ray: a one-mesh scene under a
//! rotation and non-uniform scale (the packet path, in object space) and a scene of several
//! objects (one walk of the top-level BVH for the eight), over 4x2 pixel tiles as `tracelab bench --packets` traces them.

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
fn several_objects_agree_with_single_rays() {
    let c = compiled(
        "Sphere { center 0 0 0 radius 0.7 } \
         Transform { YRotate 20 TriangleMesh { obj_file ../assets/icosphere.obj } } \
         Plane { normal 0 1 0 offset -1 }",
        3,
    );
    let hits = assert_tiles_agree(&c, 36, 20);
    assert!(hits > 500, "{hits} hits");
}

/// Deterministic pseudo-random numbers in [0, 1).
fn rng(mut s: u32) -> impl FnMut() -> f32 {
    move || {
        s ^= s << 13;
        s ^= s >> 17;
        s ^= s << 5;
        (s >> 8) as f32 / (1u32 << 24) as f32
    }
}

#[test]
fn many_instances_share_one_walk_of_the_top_level_bvh() {
    // Transformed mesh instances (some scaled non-uniformly), spheres and boxes, overlapping:
    // a top-level BVH many levels deep, whose leaves the eight rays reach in differing sets.
    let mut r = rng(0x9e37_79b9);
    let mut objs = String::new();
    let n = 120;
    for i in 0..n {
        let (x, y, z) = (r() * 4.0 - 2.0, r() * 3.0 - 1.5, r() * 4.0 - 2.0);
        let shape = match i % 3 {
            0 => "TriangleMesh { obj_file ../assets/icosphere.obj }".to_string(),
            1 => "Sphere { center 0 0 0 radius 1 }".to_string(),
            _ => "Box { min -1 -1 -1 max 1 1 1 }".to_string(),
        };
        let (sx, sy) = (
            0.15 + r() * 0.3,
            if i % 2 == 0 { 0.15 + r() * 0.3 } else { 0.0 },
        );
        let scale = if sy > 0.0 {
            format!("Scale {sx} {sy} {sx}")
        } else {
            format!("UniformScale {sx}")
        };
        objs += &format!(
            "Transform {{ Translate {x} {y} {z} YRotate {} {scale} {shape} }} ",
            r() * 360.0
        );
    }
    let c = compiled(&objs, n);
    let hits = assert_tiles_agree(&c, 48, 40);
    assert!(hits > 2000, "{hits} hits");
}

#[test]
fn exact_ties_go_to_the_first_object_in_file_order() {
    // Surfaces that coincide, so many rays hit two objects at the very same t. The course's
    // Group loop keeps the first object; so must single rays and packets, whatever order the
    // BVH visits them in (a box sharing its front face with a deeper one, whose centroid puts
    // it first in the tree; a plane, tested before every bounded object; copies).
    let a = "Box { min -1 -1 -1 max 1 1 1 }";
    let b = "Box { min -0.5 -1.5 -3 max 1.5 0.5 1 }";
    let plane = "Plane { normal 0 0 1 offset 1 }";
    let sphere = "Sphere { center 0.3 0 0 radius 1 }";
    let mesh =
        "Transform { YRotate 20 Scale 1 0.6 1 TriangleMesh { obj_file ../assets/icosphere.obj } }";
    for objs in [
        vec![a, b],
        vec![b, a],
        vec![a, plane],
        vec![plane, b, a],
        vec![sphere; 4],
        vec![mesh, sphere, mesh],
    ] {
        let c = compiled(&objs.join(" "), objs.len());
        assert_tiles_agree(&c, 24, 16);
        let (t_min, rays) = (c.camera.t_min(), c.camera.pixel_rays(24, 16));
        let mut ties = 0;
        for y in 0..16 {
            for x in 0..24 {
                let ray = rays.row(y).ray(x);
                // The course's loop: objects in file order, a hit kept only if strictly nearer.
                let mut want: Option<(f32, u32)> = None;
                for i in 0..objs.len() as u32 {
                    if let Some((t, _)) =
                        c.intersect_object(i, &ray, t_min, want.map_or(f32::INFINITY, |w| w.0))
                    {
                        want = Some((t, i));
                    }
                }
                let got = c
                    .intersect(&ray, t_min, f32::INFINITY)
                    .map(|h| (h.t, h.object));
                assert_eq!(got, want, "{objs:?}: pixel ({x}, {y})");
                if let Some((t, i)) = want {
                    ties += (i + 1..objs.len() as u32).any(|j| {
                        c.intersect_object(j, &ray, t_min, t.next_up())
                            .is_some_and(|h| h.0 == t)
                    }) as u32;
                }
            }
        }
        assert!(ties > 20, "{objs:?}: only {ties} tied pixels");
    }
}
