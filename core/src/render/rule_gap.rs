//! The largest angle between the two normal rules, (M⁻¹)ᵀ·n and M·n, over an image's
//! pixels: the one number that says whether the incorrect rule shows anywhere on screen.

use std::sync::atomic::{AtomicBool, Ordering};

use glam::Mat3;
use rayon::prelude::*;

use super::NormalTransform;
use super::RenderSettings;
use super::compile::{CompiledScene, Hit, Object, Shape};
use super::plan::Cancelled;
use super::similitude::similitude_within;
use crate::geometry::Transform;

/// f32 matrices carry about seven digits: closer than this to a similitude is one.
const F32_TOLERANCE: f64 = 1e-6;

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NormalGap {
    /// Degrees; exactly 0 when every transform hit is a similitude.
    pub degrees: f32,
    /// Where it is largest (x, row from the top); `None` when no pixel disagrees.
    pub pixel: Option<(u32, u32)>,
}

/// Traces every pixel of a `settings`-sized image (with its depth rule) and returns the
/// largest angle between the two world normals. For a hit under a similitude the angle is 0
/// by the theorem, (M⁻¹)ᵀ = λM, rather than the rounding of two f32 products.
///
/// Stops within a row once `cancel` is set (the editor computes it after each render).
pub fn normal_rule_gap(
    scene: &CompiledScene,
    settings: &RenderSettings,
    cancel: &AtomicBool,
) -> Result<NormalGap, Cancelled> {
    let (w, h) = (settings.width, settings.height);
    let rays = scene.camera.pixel_rays(w, h);
    let similar: Vec<bool> = scene.objects.iter().map(object_is_similitude).collect();
    (0..h)
        .into_par_iter()
        .map(|row| {
            if cancel.load(Ordering::Relaxed) {
                return Err(Cancelled);
            }
            let row_rays = rays.row(row);
            let mut best = NormalGap::default();
            for x in 0..w {
                let ray = row_rays.ray(x);
                let Some(hit) = scene.intersect_with(
                    &ray,
                    scene.camera.t_min(),
                    f32::INFINITY,
                    settings.object_rays,
                ) else {
                    continue;
                };
                if hit_is_similitude(scene, &similar, &hit) {
                    continue;
                }
                let at = scene.ray_for_hit_point(&ray, &hit, settings.object_rays);
                let a = scene.world_normal(&at, &hit, NormalTransform::Correct);
                let b = scene.world_normal(&at, &hit, NormalTransform::Incorrect);
                let deg = a.cross(b).length().atan2(a.dot(b)).to_degrees();
                if deg > best.degrees {
                    best = NormalGap {
                        degrees: deg,
                        pixel: Some((x, row)),
                    };
                }
            }
            Ok(best)
        })
        .try_reduce(NormalGap::default, |a, b| {
            Ok(if b.degrees > a.degrees { b } else { a })
        })
}

fn xf_is_similitude(xf: Option<&Transform>) -> bool {
    xf.is_none_or(|xf| {
        let m = Mat3::from_mat4(xf.world_from_object).as_dmat3();
        similitude_within(m, F32_TOLERANCE).is_similitude()
    })
}

/// For a CSG object, whether every operand's transform is one (decided per hit below).
fn object_is_similitude(o: &Object) -> bool {
    match &o.shape {
        Shape::Csg(tree) => tree.leaves.iter().all(|l| xf_is_similitude(l.xf.as_ref())),
        _ => xf_is_similitude(o.xf.as_ref()),
    }
}

fn hit_is_similitude(scene: &CompiledScene, similar: &[bool], hit: &Hit) -> bool {
    if similar.get(hit.object as usize).copied().unwrap_or(false) {
        return true;
    }
    match scene.objects.get(hit.object as usize).map(|o| &o.shape) {
        Some(Shape::Csg(tree)) => tree
            .leaf(hit.prim)
            .is_some_and(|l| xf_is_similitude(l.xf.as_ref())),
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::format::obj::MeshCache;
    use crate::format::parse_scene;
    use crate::render::inspect_pixel;
    use crate::scene::Scene;

    fn scene(ops: &str) -> Scene {
        let text = format!(
            "OrthographicCamera {{ center 0 0 10 direction 0 0 -1 up 0 1 0 size 4 }}
Lights {{ numLights 1 DirectionalLight {{ direction -0.3 -0.5 -1 color 0.8 0.8 0.8 }} }}
Background {{ color 0 0 0 ambientLight 0.1 0.1 0.1 }}
Materials {{ numMaterials 1 Material {{ diffuseColor 0.9 0.5 0.2 }} }}
Group {{ numObjects 2 MaterialIndex 0
  Transform {{ {ops} Sphere {{ center 0 0 0 radius 1 }} }}
  Transform {{ Translate 0 -1.5 0 XRotate 30 UniformScale 0.5 Box {{ min -1 -1 -1 max 1 1 1 }} }} }}"
        );
        parse_scene(text.as_bytes(), "t.txt", None, &mut MeshCache::new())
            .into_result()
            .expect("parses")
            .0
    }

    #[test]
    fn only_similitudes_on_screen_give_exactly_zero() {
        let s = scene("ZRotate 20 UniformScale 1.3 XRotate 70 Scale -1 1 1");
        let c = CompiledScene::new(&s);
        let gap = normal_rule_gap(&c, &RenderSettings::new(32, 32), &AtomicBool::new(false))
            .expect("not cancelled");
        assert_eq!(
            gap,
            NormalGap {
                degrees: 0.0,
                pixel: None
            }
        );
    }

    #[test]
    fn a_squashed_sphere_gives_the_largest_of_the_inspectors_angles() {
        let s = scene("ZRotate 20 Scale 1.5 0.5 1");
        let c = CompiledScene::new(&s);
        let settings = RenderSettings::new(32, 32);
        let gap = normal_rule_gap(&c, &settings, &AtomicBool::new(false)).expect("not cancelled");
        assert_eq!(
            normal_rule_gap(&c, &settings, &AtomicBool::new(true)),
            Err(Cancelled)
        );
        // Independently: the pixel inspector's angle at every pixel.
        let mut best = 0.0f32;
        for row in 0..32 {
            for x in 0..32 {
                if let Some(h) = inspect_pixel(&s, &c, &settings, x, row).hit {
                    best = best.max(h.normal_angle_degrees);
                }
            }
        }
        assert!(gap.degrees > 10.0, "{gap:?}");
        assert!((gap.degrees - best).abs() < 1e-3, "{gap:?} vs {best}");
        let (x, row) = gap.pixel.expect("where");
        let h = inspect_pixel(&s, &c, &settings, x, row)
            .hit
            .expect("hit there");
        assert!((h.normal_angle_degrees - gap.degrees).abs() < 1e-3);
    }
}
