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
