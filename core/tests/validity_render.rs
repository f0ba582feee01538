//! Scenes that used to render silently wrong (issue 11): strong scales and vectors whose
//! squared length overflows f32 now render like their tame equivalents.

use tracelab_core::{MeshCache, RenderSettings, Scene, compile, parse_scene, render_frame};

fn scene(text: &str) -> Scene {
    let out = parse_scene(text.as_bytes(), "test.txt", None, &mut MeshCache::new());
    out.into_result()
        .unwrap_or_else(|d| panic!("{d}\n{text}"))
        .0
}

fn colors(s: &Scene) -> Vec<[u8; 3]> {
    render_frame(&compile(s), &RenderSettings::new(24, 24))
        .samples
        .iter()
        .map(|p| p.color)
        .collect()
}

fn with(camera_dir: &str, light_dir: &str, objects: &str) -> String {
    format!(
        "PerspectiveCamera {{ center 0 0 10 direction {camera_dir} up 0 1 0 angle 30 }}\n\
         Lights {{ numLights 1 DirectionalLight {{ direction {light_dir} color 1 1 1 }} }}\n\
         Background {{ color 0.1 0.2 0.3 ambientLight 0.1 0.1 0.1 }}\n\
         Materials {{ numMaterials 1 Material {{ diffuseColor 1 0 0 }} }}\n\
         Group {{ numObjects 1 MaterialIndex 0 {objects} }}\n"
    )
}

#[test]
fn ten_nested_tenth_scales_around_a_huge_sphere_render_a_unit_sphere() {
    let mut nested = "Sphere { center 0 0 0 radius 1e10 }".to_string();
    for _ in 0..10 {
        nested = format!("Transform {{ UniformScale 0.1 {nested} }}");
    }
    let plain = colors(&scene(&with(
        "0 0 -1",
        "-0.5 -1 -1",
        "Sphere { center 0 0 0 radius 1 }",
    )));
    let scaled = colors(&scene(&with("0 0 -1", "-0.5 -1 -1", &nested)));
    let hits = |c: &[[u8; 3]]| c.iter().filter(|p| p[0] > 40).count();
    assert!(hits(&plain) > 20);
    assert_eq!(
        hits(&scaled),
        hits(&plain),
        "the scaled sphere covers the same pixels"
    );
}

const PLANE: &str = "Plane { normal 0 0.6 0.8 offset -1 }";

fn tame() -> Vec<[u8; 3]> {
    colors(&scene(&with("0 0 -1", "-0.5 -1 -1", PLANE)))
}

#[test]
fn a_camera_direction_of_0_0_minus_3e38_is_just_minus_z() {
    assert_eq!(
        colors(&scene(&with("0 0 -3e38", "-0.5 -1 -1", PLANE))),
        tame()
    );
}

#[test]
fn a_light_direction_scaled_by_1e20_shades_like_the_unit_one() {
    assert_eq!(
        colors(&scene(&with("0 0 -1", "-0.5e20 -1e20 -1e20", PLANE))),
        tame()
    );
}

#[test]
fn a_plane_normal_scaled_by_1e20_is_the_same_plane() {
    let huge_normal = "Plane { normal 0 0.6e20 0.8e20 offset -1 }";
    assert_eq!(
        colors(&scene(&with("0 0 -1", "-0.5 -1 -1", huge_normal))),
        tame()
    );
}

/// Colours and normal-view bytes of every pixel.
fn views(s: &Scene) -> Vec<([u8; 3], [u8; 3])> {
    render_frame(&compile(s), &RenderSettings::new(24, 24))
        .samples
        .iter()
        .map(|p| (p.color, p.normal))
        .collect()
}

/// Equal pixel lists, or a failure naming the first pixel that differs (not all 576).
fn same_pixels(got: &[([u8; 3], [u8; 3])], want: &[([u8; 3], [u8; 3])], what: &str) {
    assert_eq!(got.len(), want.len(), "{what}");
    let wrong = got.iter().zip(want).filter(|(g, w)| g != w).count();
    if let Some(i) = got.iter().zip(want).position(|(g, w)| g != w) {
        panic!(
            "{what}: {wrong} pixels differ; pixel {i} is (colour, normal) {:?}, the plane's {:?}",
            got[i], want[i]
        );
    }
}

/// A triangle in the z = 0 plane around the whole view, its corners `s` from the axis;
/// `toward` is +1 for counter-clockwise as the camera sees it (facing the camera), -1 for
/// clockwise (a back face).
fn big_triangle(s: f32, toward: f32) -> String {
    format!(
        "Triangle {{ vertex0 {} {} 0 vertex1 {} {} 0 vertex2 0 {} 0 }}",
        -s * toward,
        -s,
        s * toward,
        -s,
        s
    )
}

/// Triangles whose edges overflow f32's squared length (1e10), its cross product and
/// determinant (1e19) or come near f32::MAX (1.5e38, edges of 3e38) used to get the normal
/// (0,0,0): unlit, black in the normal view and never a back face; from 1e19 on they were
/// not hit at all. Now each shades exactly as the plane it lies in, front and back.
///
/// What is not representable: a triangle whose edges themselves exceed f32::MAX (corners at
/// ±3e38) cannot be hit, as b − a is not an f32 number (its normal is still right: see
/// `geometry::primitives`' tests).
#[test]
fn huge_triangles_shade_as_the_plane_they_lie_in() {
    for (toward, plane) in [
        (1.0, "Plane { normal 0 0 1 offset 0 }"),
        (-1.0, "Plane { normal 0 0 -1 offset 0 }"),
    ] {
        let want = views(&scene(&with("0 0 -1", "-0.5 -1 -1", plane)));
        for s in [1e10f32, 1e19, 1.5e38] {
            let got = views(&scene(&with(
                "0 0 -1",
                "-0.5 -1 -1",
                &big_triangle(s, toward),
            )));
            same_pixels(
                &got,
                &want,
                &format!("triangle of size {s:e}, facing {toward}"),
            );
        }
    }
}

/// The same for a mesh (one triangle in an OBJ file): its face normal and its hits go
/// through the mesh BVH and the packet shader, which must agree with the triangle.
#[test]
fn huge_mesh_triangles_shade_as_the_plane_they_lie_in() {
    let dir = std::env::temp_dir().join(format!("tracelab-huge-mesh-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    for (toward, plane) in [
        (1.0f32, "Plane { normal 0 0 1 offset 0 }"),
        (-1.0, "Plane { normal 0 0 -1 offset 0 }"),
    ] {
        let want = views(&scene(&with("0 0 -1", "-0.5 -1 -1", plane)));
        for s in [1e10f32, 1e19, 1.5e38] {
            let obj = dir.join("big.obj");
            std::fs::write(
                &obj,
                format!(
                    "v {} {} 0\nv {} {} 0\nv 0 {} 0\nf 1 2 3\n",
                    -s * toward,
                    -s,
                    s * toward,
                    -s,
                    s
                ),
            )
            .expect("write obj");
            let text = with("0 0 -1", "-0.5 -1 -1", "TriangleMesh { obj_file big.obj }");
            let out = parse_scene(text.as_bytes(), "t.txt", Some(&dir), &mut MeshCache::new());
            let s_ = out.into_result().unwrap_or_else(|d| panic!("{d}")).0;
            let what = format!("mesh triangle of size {s:e}, facing {toward}");
            same_pixels(&views(&s_), &want, &what);
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
