//! No shadow acne: a scaled, moved sphere alone under a light cannot shadow itself where it
//! faces the light, so every pixel of it lit from the front must render lit. The positive
//! control is the mistake catalogue's `shadow-acne` (shadow rays from t_min 0, no lift off
//! the surface), which must speckle the same sphere, so the test sees acne where there is.

use glam::Vec3;
use tracelab_core::render::mistakes::{Mistake, Variant, render_variant};
use tracelab_core::render::{Secondary, render_frame};
use tracelab_core::{CompiledScene, MeshCache, RenderSettings, parse_scene};

const SCENE: &str = "PerspectiveCamera { center 0 3 12 direction 0 -0.25 -1 up 0 1 0 angle 30 }
Lights { numLights 2
  DirectionalLight { direction -0.4 -1 -0.6 color 0.6 0.6 0.6 }
  PointLight { position 2 4 4 color 6 6 5 attenuation 1 0 0.15 } }
Background { color 0 0 0 ambientLight 0.15 0.15 0.15 }
Materials { numMaterials 1 PhongMaterial { diffuseColor 0.2 0.6 0.25 } }
Group { numObjects 1 MaterialIndex 0
  Transform { Translate 2.6 -0.4 -2.5 Scale 0.6 0.6 0.6 Sphere { center 0 0 0 radius 1 } } }
";

/// Pixels of the sphere rendered at no more than the ambient term although a light faces
/// them (N·L > 0.02 for some light): with nothing else in the scene, only the sphere itself
/// can have blocked the light there.
fn dark_lit_pixels(variant: Option<Variant>) -> (usize, usize) {
    let (scene, _) = parse_scene(SCENE.as_bytes(), "acne.txt", None, &mut MeshCache::new())
        .into_result()
        .expect("parses");
    let c = CompiledScene::new(&scene);
    let s = RenderSettings {
        variant,
        secondary: Secondary {
            shadows: true,
            ..Secondary::default()
        },
        ..RenderSettings::new(480, 480)
    };
    let frame = match variant {
        Some(_) => render_variant(&c, &s),
        None => render_frame(&c, &s),
    };
    let center = Vec3::new(2.6, -0.4, -2.5);
    let lights = [
        Vec3::new(0.4, 1.0, 0.6).normalize(),
        Vec3::new(2.0, 4.0, 4.0),
    ];
    let ambient = 0.15 * 0.6 * 255.0;
    let (mut lit, mut dark) = (0, 0);
    for row in 0..s.height {
        for x in 0..s.width {
            let ray = c.camera.pixel_ray(x, row, s.width, s.height);
            let Some(hit) = c.intersect(&ray, c.camera.t_min(), f32::INFINITY) else {
                continue;
            };
            let p = ray.at(hit.t);
            let n = (p - center).normalize();
            let faces = n.dot(lights[0]) > 0.02 || n.dot((lights[1] - p).normalize()) > 0.02;
            if !faces {
                continue;
            }
            lit += 1;
            let g = frame.samples[(row * s.width + x) as usize].color[1];
            if f32::from(g) <= ambient + 1.0 {
                dark += 1;
            }
        }
    }
    (lit, dark)
}

#[test]
fn a_sphere_alone_never_shadows_its_own_lit_side() {
    let (lit, dark) = dark_lit_pixels(None);
    assert!(lit > 3000, "{lit} lit pixels: the sphere is in view");
    assert_eq!(
        dark, 0,
        "{dark} of {lit} lit pixels shadowed by the sphere itself"
    );
    // The control: no epsilon at all speckles the same pixels.
    let (lit_m, dark_m) = dark_lit_pixels(Some(Variant::one(Mistake::ShadowAcne)));
    assert_eq!(lit_m, lit);
    assert!(dark_m > 20, "{dark_m}: the mistake's acne is not seen");
}
