//! The pixel inspector's query: for one pixel, the whole story of its primary ray — what it
//! hit, the Groups and Transforms on the way, the ray in each space, both normal rules and
//! the shading terms. Slow and thorough on purpose: it runs for one pixel on a click.

use glam::{DMat4, Mat4, Vec3};

use super::compile::CompiledScene;
use super::shade::{ShadeInfo, shade_hit};
use super::{NormalTransform, ObjectRays, RenderSettings};
use crate::geometry::Ray;
use crate::scene::{NodeId, NodeKind, Scene, compose_f64, walk};

/// One node on the way from the root to the object hit.
#[derive(Clone, Debug, PartialEq)]
pub struct PathStep {
    pub node: NodeId,
    pub kind: &'static str,
    /// World-from-local of the space this node's children live in (identity for the root
    /// Group; a Transform multiplies its ops in).
    pub world_from_local: Mat4,
    /// A Transform's own matrix M (its ops composed in f64), from its children's space to
    /// its parent's; `None` for other nodes.
    pub transform: Option<DMat4>,
    /// The world ray expressed in that space: origin as a point, direction unnormalised, so
    /// the hit's t is the same here as in world space.
    pub ray: Ray,
}

#[derive(Clone, Debug, PartialEq)]
pub struct HitStory {
    pub node: NodeId,
    /// Root first; the last step is the object hit itself.
    pub path: Vec<PathStep>,
    /// The world ray parameter of the point hit: the same along every step's ray.
    pub t: f32,
    /// The ray in the object's own space (the last step's ray).
    pub object_ray: Ray,
    /// The rule the renderer used, and what it traced and kept: under a normalising rule
    /// `traced_ray` has a unit direction and `t_object` = t·|M⁻¹d|; `t_used` is the t kept
    /// for depth and occlusion (the object-space one under the bug).
    pub object_rays: ObjectRays,
    pub traced_ray: Ray,
    pub t_object: f32,
    pub t_used: f32,
    pub object_point: Vec3,
    pub world_point: Vec3,
    pub object_normal: Vec3,
    /// (M⁻¹)ᵀ · n, normalised.
    pub normal_correct: Vec3,
    /// M · n, normalised: the lecture's incorrect rule.
    pub normal_incorrect: Vec3,
    /// Angle between the two world normals.
    pub normal_angle_degrees: f32,
    /// Shading with the settings' normal rule: ambient and per-light terms summing to `color`.
    pub shade: ShadeInfo,
}

#[derive(Clone, Debug, PartialEq)]
pub struct RayStory {
    pub x: u32,
    pub row: u32,
    pub world_ray: Ray,
    /// `None` for a miss: the pixel shows the background.
    pub hit: Option<HitStory>,
    pub background: Vec3,
    pub normal_transform: NormalTransform,
    /// The eye ray's tree of shadow, reflected and refracted rays, where the scene or the
    /// settings need more than the lecture's diffuse shading (assignments 3–4).
    pub ray_tree: Option<super::whitted::RayNode>,
}

impl RayStory {
    /// The pixel's colour as shading computed it (before quantisation).
    pub fn color(&self) -> Vec3 {
        self.hit.as_ref().map_or(self.background, |h| h.shade.color)
    }
}

/// Traces pixel (x, row) (rows from the top) of a `settings`-sized image. `compiled` must be
/// compiled from `scene`.
pub fn inspect_pixel(
    scene: &Scene,
    compiled: &CompiledScene,
    settings: &RenderSettings,
    x: u32,
    row: u32,
) -> RayStory {
    let world_ray =
        compiled
            .camera
            .pixel_ray(x, row, settings.width.max(1), settings.height.max(1));
    let rule = settings.object_rays;
    let hit = compiled
        .intersect_with(&world_ray, compiled.camera.t_min(), f32::INFINITY, rule)
        .and_then(|hit| {
            // For a CSG hit, the operand whose surface it is (its path holds the CSG node).
            let node = compiled.hit_node(&hit)?;
            // Composed and inverted in f64, as the renderer does, so the story matches it.
            let path: Vec<PathStep> = walk::path(&scene.graph, node)?
                .into_iter()
                .map(|v| PathStep {
                    node: v.id,
                    kind: v.node.kind.name(),
                    world_from_local: v.world_from_object.as_mat4(),
                    transform: match &v.node.kind {
                        NodeKind::Transform(ops) => Some(compose_f64(ops)),
                        _ => None,
                    },
                    ray: world_ray.transformed(&v.world_from_object.inverse().as_mat4()),
                })
                .collect();
            let object_ray = path.last().map_or(world_ray, |s| s.ray);
            let ot = compiled.object_t(&world_ray, &hit, rule);
            // CSG operands carry their transforms inside the solid: they keep the plain rule.
            let own_xf = compiled
                .objects
                .get(hit.object as usize)
                .is_some_and(|o| o.xf.is_some());
            let traced_ray = if own_xf { ot.traced } else { object_ray };
            // The normal routines evaluate their ray at hit.t: give them one that lands on the
            // point really hit under every rule.
            let at_hit = compiled.ray_for_hit_point(&world_ray, &hit, rule);
            let object_normal = compiled.object_normal(&at_hit, &hit);
            let normal_correct = compiled.world_normal(&at_hit, &hit, NormalTransform::Correct);
            let normal_incorrect = compiled.world_normal(&at_hit, &hit, NormalTransform::Incorrect);
            // atan2 of sine and cosine: acos of a dot product near 1 turns rounding into
            // hundredths of a degree where the rules agree exactly.
            let angle = normal_correct
                .cross(normal_incorrect)
                .length()
                .atan2(normal_correct.dot(normal_incorrect));
            Some(HitStory {
                node,
                path,
                t: ot.t_world,
                object_ray,
                object_rays: rule,
                traced_ray,
                t_object: ot.t_object,
                t_used: ot.t_used,
                object_point: object_ray.at(ot.t_world),
                world_point: world_ray.at(ot.t_world),
                object_normal,
                normal_correct,
                normal_incorrect,
                normal_angle_degrees: angle.to_degrees(),
                shade: story_shade(compiled, &world_ray, &hit, settings),
            })
        });
    // Assignments 3–4: every shadow, reflected and refracted ray behind the pixel.
    let ray_tree = super::whitted::needs_whitted(compiled, settings)
        .then(|| super::whitted::ray_tree(compiled, &world_ray, settings));
    RayStory {
        x,
        row,
        world_ray,
        hit,
        background: compiled.background,
        normal_transform: settings.normal_transform,
        ray_tree,
    }
}

/// The shading as the renderer does it, with `ambient_term` = c_ambient·k_d as documented
/// even where the pixel is drawn black (a back face without shade-back): the student sees
/// the term they should have, and `color` stays what the image holds.
fn story_shade(
    compiled: &CompiledScene,
    ray: &Ray,
    hit: &super::compile::Hit,
    settings: &RenderSettings,
) -> ShadeInfo {
    let mut shade = shade_hit(compiled, ray, hit, settings);
    if shade.back_facing && !settings.shade_back {
        shade.ambient_term = compiled.ambient * shade.diffuse;
    }
    shade
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::format::obj::MeshCache;
    use crate::format::parse_scene;
    use crate::render::{quantize, render_frame};

    const SQUASHED: &str = "
OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 4 }
Lights { numLights 2
  DirectionalLight { direction -0.3 -0.5 -1 color 0.6 0.6 0.6 }
  DirectionalLight { direction 1 0 -0.2 color 0.2 0.3 0.4 } }
Background { color 0.1 0.2 0.3 ambientLight 0.1 0.1 0.1 }
Materials { numMaterials 1 Material { diffuseColor 0.9 0.5 0.2 } }
Group { numObjects 1
  MaterialIndex 0
  Transform { Translate 0.2 0 0
    Group { numObjects 1
      Transform { Scale 1.5 0.5 1 Sphere { center 0 0 0 radius 1 } } } } }
";

    fn scene(text: &str) -> Scene {
        let out = parse_scene(text.as_bytes(), "t.txt", None, &mut MeshCache::new());
        out.into_result().expect("test scene parses").0
    }

    #[test]
    fn story_follows_the_transform_path_with_one_t_in_every_space() {
        let s = scene(SQUASHED);
        let c = CompiledScene::new(&s);
        let settings = RenderSettings::new(40, 40);
        // A pixel above and right of the centre: on the squashed sphere's sloped side.
        let story = inspect_pixel(&s, &c, &settings, 26, 16);
        let h = story.hit.as_ref().expect("pixel hits the sphere");
        let kinds: Vec<_> = h.path.iter().map(|p| p.kind).collect();
        assert_eq!(
            kinds,
            ["Group", "Transform", "Group", "Transform", "Sphere"]
        );
        // The same t lands on the same point in every space.
        for step in &h.path {
            let p = step.world_from_local.transform_point3(step.ray.at(h.t));
            assert!((p - h.world_point).length() < 1e-4, "{:?}", step.kind);
        }
        // On the unit sphere in object space.
        assert!((h.object_point.length() - 1.0).abs() < 1e-4);
        assert!((h.object_normal - h.object_point).length() < 1e-4);
        // Correct normal is perpendicular to the world surface's tangents; M·n is not, so
        // the two disagree on a non-uniformly scaled sphere.
        assert!(h.normal_angle_degrees > 5.0, "{}", h.normal_angle_degrees);
    }

    #[test]
    fn shading_terms_sum_to_the_rendered_pixel() {
        let s = scene(SQUASHED);
        let c = CompiledScene::new(&s);
        for mode in [NormalTransform::Correct, NormalTransform::Incorrect] {
            let settings = RenderSettings {
                normal_transform: mode,
                ..RenderSettings::new(40, 40)
            };
            let frame = render_frame(&c, &settings);
            for (x, row) in [(26, 16), (20, 20), (14, 25), (1, 1)] {
                let story = inspect_pixel(&s, &c, &settings, x, row);
                let px = frame.get(x, row).expect("in frame");
                let expect = story.color();
                if let Some(h) = &story.hit {
                    let sum = h.shade.ambient_term
                        + h.shade.lights.iter().map(|l| l.contribution).sum::<Vec3>();
                    assert!((sum - h.shade.color).length() < 1e-5);
                    assert_eq!(px.node, h.node.0);
                } else {
                    assert!(!px.is_hit());
                }
                assert_eq!(
                    px.color,
                    [quantize(expect.x), quantize(expect.y), quantize(expect.z)],
                    "{mode:?} {x},{row}"
                );
            }
        }
    }

    #[test]
    fn a_back_face_without_shade_back_reports_its_ambient_and_is_black() {
        // The camera inside the sphere sees only back faces.
        let s = scene(
            "PerspectiveCamera { center 0 0 0 direction 0 0 -1 up 0 1 0 angle 30 }
Lights { numLights 1 DirectionalLight { direction 0 0 -1 color 0.5 0.5 0.5 } }
Background { color 0.1 0.2 0.3 ambientLight 0.2 0.4 0.5 }
Materials { numMaterials 1 Material { diffuseColor 0.5 1 0.8 } }
Group { numObjects 1 MaterialIndex 0 Sphere { center 0 0 0 radius 3 } }",
        );
        let c = CompiledScene::new(&s);
        for shade_back in [false, true] {
            let settings = RenderSettings {
                shade_back,
                ..RenderSettings::new(20, 20)
            };
            let frame = render_frame(&c, &settings);
            let story = inspect_pixel(&s, &c, &settings, 10, 10);
            let h = story
                .hit
                .as_ref()
                .expect("inside the sphere every ray hits");
            assert!(h.shade.back_facing);
            assert_eq!(h.shade.ambient_term, Vec3::new(0.1, 0.4, 0.4));
            let e = story.color();
            let px = frame.get(10, 10).expect("in frame").color;
            assert_eq!(px, [quantize(e.x), quantize(e.y), quantize(e.z)]);
            assert_eq!(px == [0, 0, 0], !shade_back, "{px:?}");
        }
    }

    #[test]
    fn rules_agree_without_non_uniform_scale() {
        let s = scene(&SQUASHED.replace("Scale 1.5 0.5 1", "UniformScale 1.2"));
        let c = CompiledScene::new(&s);
        let story = inspect_pixel(&s, &c, &RenderSettings::new(40, 40), 26, 16);
        let h = story.hit.expect("hits");
        assert!(h.normal_angle_degrees < 0.05, "{}", h.normal_angle_degrees);
    }

    #[test]
    fn a_csg_pixel_names_the_operand_and_matches_the_render() {
        // A red box minus a squashed blue sphere: the pit's floor is the sphere's surface,
        // flipped, and must be reported as the sphere (inside its Transform), in blue.
        let text = "
OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 4 }
Lights { numLights 1 DirectionalLight { direction -0.2 -0.3 -1 color 0.8 0.8 0.8 } }
Background { color 0 0 0 ambientLight 0.2 0.2 0.2 }
Materials { numMaterials 2 Material { diffuseColor 1 0 0 } Material { diffuseColor 0 0 1 } }
Group { numObjects 1
  Subtraction {
    MaterialIndex 0
    Box { min -1 -1 -1 max 1 1 1 }
    MaterialIndex 1
    Transform { Scale 1 1 0.5 Translate 0 0 2 Sphere { center 0 0 0 radius 1.2 } } } }
";
        let s = scene(text);
        let c = CompiledScene::new(&s);
        let settings = RenderSettings::new(40, 40);
        let frame = render_frame(&c, &settings);
        let story = inspect_pixel(&s, &c, &settings, 22, 18);
        let h = story.hit.as_ref().expect("the pit is hit");
        let kinds: Vec<_> = h.path.iter().map(|p| p.kind).collect();
        assert_eq!(kinds, ["Group", "Subtraction", "Transform", "Sphere"]);
        assert_eq!(frame.get(22, 18).expect("in frame").node, h.node.0);
        assert_eq!(h.shade.diffuse, Vec3::new(0.0, 0.0, 1.0));
        // The exposed inner surface faces the viewer; the object normal is the sphere's, in
        // its own (unscaled) space, flipped inward.
        assert!(h.normal_correct.z > 0.0, "{:?}", h.normal_correct);
        let radial = (h.object_point - Vec3::ZERO).normalize();
        assert!(
            (h.object_normal + radial).length() < 1e-4,
            "{:?} vs {radial:?}",
            h.object_normal
        );
        let px = frame.get(22, 18).expect("in frame");
        let e = story.color();
        assert_eq!(px.color, [quantize(e.x), quantize(e.y), quantize(e.z)]);
        // In a corner of the front face, beyond the pit, the surface is the Box itself.
        let edge = inspect_pixel(&s, &c, &settings, 10, 10);
        let eh = edge.hit.expect("box face");
        assert_eq!(eh.path.last().map(|p| p.kind), Some("Box"));
    }
}
