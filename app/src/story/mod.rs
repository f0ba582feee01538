//! One pixel's story as plain data: what `tracelab inspect` prints (as text or, through
//! serde, as the JSON schema of docs/inspect-json.md) and what the editor's pixel inspector
//! and Ray panel show. Built from core's `RayStory`, with the tree's node labels, each
//! Transform's M, M⁻¹ and (M⁻¹)ᵀ, and the similitude test.

use glam::{DMat3, DMat4, Vec3};
use serde::Serialize;
use tracelab_core::render::{
    Breaks, Cut, HitStory, RayKind, RayNode, RayStory, SimilitudeTest, depth_shade, quantize,
    similitude,
};
use tracelab_core::{NormalTransform, ObjectRays, RenderSettings, Scene};

use crate::node_label::node_label;

mod text;
pub use text::{images_line, one_line, ray_tree_lines, report_text, transform_lines};

/// Bumped when a field changes meaning or goes away (adding one keeps it).
pub const SCHEMA: &str = "tracelab-inspect/1";

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PixelReport {
    pub schema: &'static str,
    pub size: [u32; 2],
    /// Column from the left and row from the top, as images store them.
    pub pixel: PixelAt,
    pub settings: SettingsReport,
    pub world_ray: RayReport,
    /// `None` (JSON null) when the ray misses everything.
    pub hit: Option<HitReport>,
    pub background: [f32; 3],
    /// The colour before quantisation: the shading's sum, or the background.
    pub color: [f32; 3],
    /// The image's bytes for that colour: ⌊c·255⌋ clamped, as the course's Image writes.
    pub rgb8: [u8; 3],
    /// The bytes each of the course's images holds at this pixel.
    pub images: ImageBytes,
    /// Assignments 3–4: the eye ray's tree of shadow, reflected and refracted rays; `None`
    /// (JSON null) where the scene and settings need only the lecture's diffuse shading.
    pub ray_tree: Option<RayTreeReport>,
}

/// One ray of a pixel's ray tree (`tracelab_core::render::RayNode`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RayTreeReport {
    /// "eye", "reflected" or "refracted".
    pub kind: &'static str,
    pub ray: RayReport,
    /// The product of the colours this ray is seen through, as a length (1 for the eye ray).
    pub weight: f32,
    /// The material colour what it brings back is multiplied by (reflective or transparent).
    pub factor: [f32; 3],
    /// `None` (null) for a miss: the ray brings back the background.
    pub hit: Option<TreeHitReport>,
    /// c_ambient·k_d.
    pub ambient: [f32; 3],
    /// Each light's diffuse + specular share (zero in shadow or from behind).
    pub lights: Vec<LightShareReport>,
    pub shadow_rays: Vec<ShadowReport>,
    /// Secondary rays not traced: "bounces" (-bounces used up), "weight" (below -weight)
    /// or "total internal reflection".
    pub not_traced: Vec<CutReport>,
    pub children: Vec<RayTreeReport>,
    /// What the ray brings back, before `factor`.
    pub color: [f32; 3],
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TreeHitReport {
    pub t: f32,
    pub node: Option<u32>,
    pub point: [f32; 3],
    pub normal: [f32; 3],
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LightShareReport {
    pub light: usize,
    pub color: [f32; 3],
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ShadowReport {
    pub light: usize,
    pub ray: RayReport,
    /// Distance to the light; null for a directional light.
    pub distance: Option<f32>,
    pub blocked: bool,
    /// The nearest blocker's t along the shadow ray and its node.
    pub blocker_t: Option<f32>,
    pub blocker_node: Option<u32>,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CutReport {
    pub kind: &'static str,
    pub why: &'static str,
    /// For "weight": the weight it would have had.
    pub weight: Option<f32>,
}

fn ray_kind_name(k: RayKind) -> &'static str {
    match k {
        RayKind::Eye => "eye",
        RayKind::Reflected => "reflected",
        RayKind::Refracted => "refracted",
    }
}

/// The report of one ray of the tree and everything below it.
pub fn ray_tree_report(n: &RayNode) -> RayTreeReport {
    RayTreeReport {
        kind: ray_kind_name(n.kind),
        ray: ray(&n.ray),
        weight: n.weight,
        factor: a3(n.factor),
        hit: n.hit.map(|(t, node, point, normal)| TreeHitReport {
            t,
            node: node.map(|id| id.0),
            point: a3(point),
            normal: a3(normal),
        }),
        ambient: a3(n.ambient),
        lights: n
            .lights
            .iter()
            .map(|l| LightShareReport {
                light: l.light,
                color: a3(l.color),
            })
            .collect(),
        shadow_rays: n
            .shadows
            .iter()
            .map(|s| ShadowReport {
                light: s.light,
                ray: ray(&s.ray),
                distance: s.distance.is_finite().then_some(s.distance),
                blocked: s.blocker.is_some(),
                blocker_t: s.blocker.map(|b| b.0),
                blocker_node: s.blocker.and_then(|b| b.1).map(|id| id.0),
            })
            .collect(),
        not_traced: n
            .cuts
            .iter()
            .map(|&(kind, why)| CutReport {
                kind: ray_kind_name(kind),
                why: match why {
                    Cut::Bounces => "bounces",
                    Cut::Weight { .. } => "weight",
                    Cut::TotalInternalReflection => "total internal reflection",
                },
                weight: match why {
                    Cut::Weight { weight } => Some(weight),
                    _ => None,
                },
            })
            .collect(),
        children: n.children.iter().map(ray_tree_report).collect(),
        color: a3(n.color),
    }
}

/// What the `-output`, `-normals` and `-depth` images hold at the pixel, so a student need
/// not turn a normal or a t into bytes by hand.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ImageBytes {
    /// The colour image: the same as `rgb8`.
    pub color: [u8; 3],
    /// The normal image: ⌊|n|·255⌋ of the world normal by the rule (before any shade-back
    /// flip); black for a miss.
    pub normals: [u8; 3],
    /// The depth image for the range given (`--depth MIN MAX`, a course line's `-depth`);
    /// `None` (JSON null) without one.
    pub depth: Option<DepthBytes>,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DepthBytes {
    pub min: f32,
    pub max: f32,
    /// The shade (max − t)/(max − min) clamped to [0, 1], of the t the renderer kept.
    pub shade: f32,
    /// ⌊shade·255⌋ in each channel; black for a miss.
    pub bytes: [u8; 3],
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct PixelAt {
    pub x: u32,
    pub row: u32,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SettingsReport {
    pub object_rays: &'static str,
    pub normal_transform: &'static str,
    pub shade_back: bool,
    pub shadows: bool,
    pub bounces: u32,
    pub weight: f32,
    pub specular_fix: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct RayReport {
    pub origin: [f32; 3],
    pub direction: [f32; 3],
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NodeReport {
    pub id: u32,
    pub kind: &'static str,
    /// As the scene tree shows it, e.g. `Transform: Scale(1.5, 0.5, 1)`.
    pub label: String,
}

/// A 4×4 affine matrix as its 3×3 linear part (rows) and its translation.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AffineReport {
    pub linear: [[f64; 3]; 3],
    pub translation: [f64; 3],
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TransformReport {
    #[serde(rename = "M")]
    pub m: AffineReport,
    #[serde(rename = "M_inverse")]
    pub m_inverse: AffineReport,
    /// (M⁻¹)ᵀ's 3×3: normals see no translation.
    #[serde(rename = "M_inverse_transpose")]
    pub m_inverse_transpose: [[f64; 3]; 3],
    pub similitude: SimilitudeReport,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SimilitudeReport {
    pub is_similitude: bool,
    /// (M⁻¹)ᵀ = λ·M for a similitude; null otherwise.
    pub lambda: Option<f64>,
    pub reflects: bool,
    /// |M·x̂|, |M·ŷ|, |M·ẑ|.
    pub axis_scales: [f64; 3],
    /// Degrees between the images of the axis pairs (x,y), (y,z), (z,x).
    pub axis_angles_degrees: [f64; 3],
    /// What breaks it: `{"kind": "non_uniform_scale", "min", "max"}` or
    /// `{"kind": "shear", "angle_degrees"}`.
    pub breaks: Vec<BreakReport>,
    pub summary: String,
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum BreakReport {
    NonUniformScale { min: f64, max: f64 },
    Shear { angle_degrees: f64 },
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StepReport {
    pub node: NodeReport,
    /// The node's own matrix, for a Transform; null for others.
    pub transform: Option<TransformReport>,
    /// The world ray in the space this node's children live in (direction not renormalised).
    pub ray: RayReport,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TReport {
    /// The world ray parameter of the point hit (the same along every step's ray).
    pub world: f32,
    /// t along the object-space ray as the renderer traced it.
    pub object: f32,
    /// The t the renderer kept for depth and occlusion.
    pub used: f32,
    /// "world" or "object": which of the two `used` is.
    pub used_is: &'static str,
    /// |M⁻¹d|: how much longer the object-space direction is before any normalising.
    pub object_direction_length: f32,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NormalReport {
    pub object: [f32; 3],
    /// (M⁻¹)ᵀ·n, normalised.
    pub world_correct: [f32; 3],
    /// M·n, normalised.
    pub world_incorrect: [f32; 3],
    pub angle_degrees: f32,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LightReport {
    /// Toward the light, normalised.
    pub direction: [f32; 3],
    pub l_dot_n: f32,
    /// max(L·N, 0)·c_light·k_d.
    pub contribution: [f32; 3],
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ShadingReport {
    /// "correct" or "incorrect": the rule the colour was shaded with.
    pub normal_rule: &'static str,
    /// The normal shaded with (flipped toward the eye under shade-back).
    pub normal: [f32; 3],
    pub back_facing: bool,
    pub diffuse: [f32; 3],
    /// c_ambient·k_d.
    pub ambient: [f32; 3],
    pub lights: Vec<LightReport>,
    /// ambient + Σ lights.
    pub color: [f32; 3],
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct HitReport {
    pub node: NodeReport,
    /// Root first; the last step is the object hit.
    pub path: Vec<StepReport>,
    /// The composed world-from-object matrix, with its similitude test.
    pub world_from_object: TransformReport,
    pub t: TReport,
    /// The object-space ray the intersection routine saw.
    pub traced_ray: RayReport,
    pub point_world: [f32; 3],
    pub point_object: [f32; 3],
    pub normal: NormalReport,
    pub shading: ShadingReport,
}

fn a3(v: Vec3) -> [f32; 3] {
    v.to_array()
}

fn ray(r: &tracelab_core::geometry::Ray) -> RayReport {
    RayReport {
        origin: a3(r.origin),
        direction: a3(r.direction),
    }
}

fn rows3(m: DMat3) -> [[f64; 3]; 3] {
    [
        m.row(0).to_array(),
        m.row(1).to_array(),
        m.row(2).to_array(),
    ]
}

fn affine(m: DMat4) -> AffineReport {
    AffineReport {
        linear: rows3(DMat3::from_mat4(m)),
        translation: m.w_axis.truncate().to_array(),
    }
}

pub fn similitude_report(t: &SimilitudeTest) -> SimilitudeReport {
    SimilitudeReport {
        is_similitude: t.is_similitude(),
        lambda: t.lambda,
        reflects: t.reflects,
        axis_scales: t.axis_scales,
        axis_angles_degrees: t.axis_angles,
        breaks: t
            .breaks
            .iter()
            .map(|b| match *b {
                Breaks::NonUniformScale { min, max } => BreakReport::NonUniformScale { min, max },
                Breaks::Shear { angle_degrees } => BreakReport::Shear { angle_degrees },
            })
            .collect(),
        summary: t.summary(),
    }
}

/// M, M⁻¹, (M⁻¹)ᵀ and the similitude test of one matrix (inverted in f64, as the renderer).
pub fn transform_report(m: DMat4) -> TransformReport {
    let inv = m.inverse();
    let linear = DMat3::from_mat4(m);
    TransformReport {
        m: affine(m),
        m_inverse: affine(inv),
        m_inverse_transpose: rows3(DMat3::from_mat4(inv).transpose()),
        similitude: similitude_report(&similitude(linear)),
    }
}

pub fn object_rays_name(r: ObjectRays) -> &'static str {
    r.name()
}

pub fn normal_rule_name(n: NormalTransform) -> &'static str {
    match n {
        NormalTransform::Correct => "correct",
        NormalTransform::Incorrect => "incorrect",
    }
}

fn node(scene: &Scene, id: tracelab_core::NodeId) -> NodeReport {
    let n = scene.graph.get(id);
    NodeReport {
        id: id.0,
        kind: n.map_or("?", |n| n.kind.name()),
        label: n.map_or_else(|| "?".into(), |n| node_label(&n.kind, n.children.len())),
    }
}

/// The hit part of the report (what the editor's panels draw).
pub fn hit_report(scene: &Scene, h: &HitStory, normal_rule: NormalTransform) -> HitReport {
    let mut world_from_object = DMat4::IDENTITY;
    let path = h
        .path
        .iter()
        .map(|s| {
            if let Some(m) = s.transform {
                world_from_object *= m;
            }
            StepReport {
                node: node(scene, s.node),
                transform: s.transform.map(transform_report),
                ray: ray(&s.ray),
            }
        })
        .collect();
    let object_direction_length = h.object_ray.direction.length();
    HitReport {
        node: node(scene, h.node),
        path,
        world_from_object: transform_report(world_from_object),
        t: TReport {
            world: h.t,
            object: h.t_object,
            used: h.t_used,
            used_is: if h.object_rays == ObjectRays::NormalizedNoRescale && h.t_used != h.t {
                "object"
            } else {
                "world"
            },
            object_direction_length,
        },
        traced_ray: ray(&h.traced_ray),
        point_world: a3(h.world_point),
        point_object: a3(h.object_point),
        normal: NormalReport {
            object: a3(h.object_normal),
            world_correct: a3(h.normal_correct),
            world_incorrect: a3(h.normal_incorrect),
            angle_degrees: h.normal_angle_degrees,
        },
        shading: ShadingReport {
            normal_rule: normal_rule_name(normal_rule),
            normal: a3(h.shade.shading_normal),
            back_facing: h.shade.back_facing,
            diffuse: a3(h.shade.diffuse),
            ambient: a3(h.shade.ambient_term),
            lights: h
                .shade
                .lights
                .iter()
                .map(|l| LightReport {
                    direction: a3(l.l),
                    l_dot_n: l.l_dot_n,
                    contribution: a3(l.contribution),
                })
                .collect(),
            color: a3(h.shade.color),
        },
    }
}

fn quantize3(v: Vec3) -> [u8; 3] {
    [quantize(v.x), quantize(v.y), quantize(v.z)]
}

impl PixelReport {
    /// The depth image's bytes for the range `min`..`max`, as `Frame::rgb8` makes them.
    pub fn with_depth_range(mut self, min: f32, max: f32) -> Self {
        let shade = self
            .hit
            .as_ref()
            .map_or(0.0, |h| depth_shade(h.t.used, min, max));
        let g = if self.hit.is_some() {
            quantize(shade)
        } else {
            0
        };
        self.images.depth = Some(DepthBytes {
            min,
            max,
            shade,
            bytes: [g; 3],
        });
        self
    }
}

/// The report of a story traced with `settings` in `scene`.
pub fn pixel_report(scene: &Scene, story: &RayStory, settings: &RenderSettings) -> PixelReport {
    let color = story.color();
    PixelReport {
        schema: SCHEMA,
        size: [settings.width, settings.height],
        pixel: PixelAt {
            x: story.x,
            row: story.row,
        },
        settings: SettingsReport {
            object_rays: object_rays_name(settings.object_rays),
            normal_transform: normal_rule_name(settings.normal_transform),
            shade_back: settings.shade_back,
            shadows: settings.secondary.shadows,
            bounces: settings.secondary.bounces,
            weight: settings.secondary.weight,
            specular_fix: settings.secondary.specular_fix,
        },
        world_ray: ray(&story.world_ray),
        hit: story
            .hit
            .as_ref()
            .map(|h| hit_report(scene, h, story.normal_transform)),
        background: a3(story.background),
        color: a3(color),
        rgb8: quantize3(color),
        images: ImageBytes {
            color: quantize3(color),
            normals: story
                .hit
                .as_ref()
                .map_or([0; 3], |h| quantize3(h.shade.normal.abs())),
            depth: None,
        },
        ray_tree: story.ray_tree.as_ref().map(ray_tree_report),
    }
}

/// For a node of the scene: its own similitude test when it is a Transform, and that of the
/// world-from-object chain down to it (every Transform above it, and itself), in f64.
pub fn node_similitudes(
    scene: &Scene,
    id: tracelab_core::NodeId,
) -> (Option<SimilitudeTest>, SimilitudeTest) {
    use tracelab_core::NodeKind;
    use tracelab_core::scene::compose_f64;
    let g = &scene.graph;
    let chain =
        tracelab_core::scene::walk::visit(g, id).map_or(DMat4::IDENTITY, |v| v.world_from_object);
    let own = match g.get(id).map(|n| &n.kind) {
        Some(NodeKind::Transform(ops)) => Some(similitude(DMat3::from_mat4(compose_f64(ops)))),
        _ => None,
    };
    (own, similitude(DMat3::from_mat4(chain)))
}
