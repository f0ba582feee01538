//! The pixel inspector: the story of one pixel's ray, from the core's `inspect_pixel`. The
//! pixel stays chosen while the scene and the view change: each new render traces it again,
//! so the story always describes the image on screen (it once kept showing a deleted box).

use std::sync::Arc;

use glam::{Vec2, Vec3};
use tracelab_core::render::{RayStory, inspect_pixel};
use tracelab_core::{Camera, NormalTransform, ObjectRays, RenderSettings, Scene};

use crate::gui::widgets::ascii_math;
use crate::navigation::ViewBasis;
use crate::render_worker::Published;
use crate::story::{HitReport, TransformReport, hit_report, transform_lines};

/// The pixel being inspected, and the render its story was traced in.
#[derive(Clone, Debug, PartialEq)]
pub struct Inspected {
    /// Which image: 0, or 1 for the Incorrect rule in compare mode.
    pub frame: usize,
    pub x: u32,
    pub row: u32,
    /// The image size the pixel was picked in, to find the same place after a resize.
    pub size: (u32, u32),
    /// The render request the story belongs to.
    pub request: u64,
    /// The camera it was picked with: while it stays, a resized image (the dock opening)
    /// follows the same ray, not the same fraction of the image.
    pub camera: Camera,
}

/// Traces pixel (`x`, `row`) of image `frame` of a published render.
pub fn trace(
    p: &Published,
    frame: usize,
    x: u32,
    row: u32,
) -> Option<(Inspected, RayStory, Arc<Scene>)> {
    let mode = *p.job.modes.get(frame)?;
    let settings = RenderSettings {
        normal_transform: mode,
        ..p.job.settings
    };
    let at = Inspected {
        frame,
        x: x.min(settings.width.saturating_sub(1)),
        row: row.min(settings.height.saturating_sub(1)),
        size: (settings.width, settings.height),
        request: p.job.request,
        camera: p.job.scene.camera.clone(),
    };
    let story = inspect_pixel(&p.job.scene, &p.compiled, &settings, at.x, at.row);
    Some((at, story, p.job.scene.clone()))
}

/// The same pixel traced in a newer render: the pixel the same ray goes through when only
/// the image's size changed (so a pick describes what was under the pointer, even after the
/// view shrinks), else the same place in the image; and the first image when the one it was
/// in is gone (compare mode turned off). `None` when `p` is the render `at` was traced in,
/// or when the picked ray is no longer in the image (the story from before stays).
pub fn follow(p: &Published, at: &Inspected) -> Option<(Inspected, RayStory, Arc<Scene>)> {
    if p.job.request == at.request {
        return None;
    }
    let (w, h) = (p.job.settings.width, p.job.settings.height);
    let scale = |v: u32, old: u32, new: u32| {
        ((f64::from(v) + 0.5) * f64::from(new) / f64::from(old.max(1))) as u32
    };
    let frame = if at.frame < p.job.modes.len() {
        at.frame
    } else {
        0
    };
    let (x, row) = if p.job.scene.camera == at.camera {
        same_ray(at, w, h)?
    } else {
        (scale(at.x, at.size.0, w), scale(at.row, at.size.1, h))
    };
    trace(p, frame, x, row)
}

/// The pixel of a `w`×`h` image, same camera, that `at`'s ray goes through.
fn same_ray(at: &Inspected, w: u32, h: u32) -> Option<(u32, u32)> {
    let old = ViewBasis::new(&at.camera, at.size.0, at.size.1);
    let (origin, dir) = old.ray(Vec2::new(at.x as f32 + 0.5, at.row as f32 + 0.5));
    let px = ViewBasis::new(&at.camera, w, h).project(origin + dir)?;
    let inside = px.x >= 0.0 && px.y >= 0.0 && px.x < w as f32 && px.y < h as f32;
    inside.then_some((px.x as u32, px.y as u32))
}

fn v(v: Vec3) -> String {
    format!("({:.4}, {:.4}, {:.4})", v.x, v.y, v.z)
}

fn a(xyz: [f32; 3]) -> String {
    v(Vec3::from_array(xyz))
}

/// M, M⁻¹, (M⁻¹)ᵀ and the similitude line of one Transform, in a monospace block.
pub fn matrices_ui(ui: &mut egui::Ui, t: &TransformReport) {
    let text = transform_lines("", t)
        .iter()
        .map(|l| ascii_math(l))
        .collect::<Vec<_>>()
        .join("\n");
    ui.label(egui::RichText::new(text).monospace().small());
}

/// Which t the renderer kept, in words.
pub fn t_line(h: &HitReport, rule: ObjectRays) -> String {
    format!(
        "t: world {:.5}, object {:.5} (|M^-1 d| = {:.4}); rule {}: kept the {} t, {:.5}",
        h.t.world,
        h.t.object,
        h.t.object_direction_length,
        rule.name(),
        h.t.used_is,
        h.t.used
    )
}

/// Draws the story. `scene` is the snapshot the story was traced in.
pub fn ui(ui: &mut egui::Ui, story: &RayStory, scene: &Scene) {
    let RayStory {
        x,
        row,
        world_ray,
        hit,
        background,
        normal_transform,
        ray_tree,
    } = story;
    ui.label(format!("Pixel ({x}, {row}), rows from the top"));
    ui.label(format!(
        "World ray: origin {} direction {}",
        v(world_ray.origin),
        v(world_ray.direction)
    ));
    let Some(story_hit) = hit else {
        ui.label(format!(
            "Missed every object: background {}",
            v(*background)
        ));
        return;
    };
    let h = hit_report(scene, story_hit, *normal_transform);
    ui.separator();
    ui.strong(format!("Hit {} at t = {:.5}", h.node.label, h.t.world));
    ui.label(t_line(&h, story_hit.object_rays));
    ui.label("Path, with the ray in each space (direction not renormalised: t is the same in every one):");
    // One block per node, label then ray then matrices: a two-column grid squeezed the ray
    // into one number a line beside the Ray panel.
    for step in &h.path {
        ui.label(egui::RichText::new(&step.node.label).strong());
        ui.indent(("step", step.node.id), |ui| {
            ui.label(format!(
                "origin {}  direction {}",
                a(step.ray.origin),
                a(step.ray.direction)
            ));
            if let Some(t) = &step.transform {
                matrices_ui(ui, t);
            }
        });
    }
    ui.label(format!(
        "World from object: {}",
        ascii_math(&h.world_from_object.similitude.summary)
    ));
    ui.separator();
    egui::Grid::new("hit").show(ui, |ui| {
        let mut row = |key: &str, value: String| {
            ui.label(key);
            ui.label(value);
            ui.end_row();
        };
        row("hit point (object)", a(h.point_object));
        row("hit point (world)", a(h.point_world));
        row("normal (object)", a(h.normal.object));
        row("world normal by (M^-1)^T", a(h.normal.world_correct));
        row("world normal by M", a(h.normal.world_incorrect));
        row(
            "angle between them",
            format!("{:.3}°", h.normal.angle_degrees),
        );
        let rule = match normal_transform {
            NormalTransform::Correct => "(M^-1)^T",
            NormalTransform::Incorrect => "M",
        };
        row(
            "shading uses",
            format!(
                "{rule}{}",
                if h.shading.back_facing {
                    ", back-facing"
                } else {
                    ""
                }
            ),
        );
        row("diffuse k_d", a(h.shading.diffuse));
        row("ambient · k_d", a(h.shading.ambient));
        for (i, l) in h.shading.lights.iter().enumerate() {
            row(&format!("light {i}: L·N"), format!("{:.4}", l.l_dot_n));
            row(&format!("light {i}: max(L·N,0)·c·k_d"), a(l.contribution));
        }
        row("colour (sum)", a(h.shading.color));
    });
    if let Some(tree) = ray_tree {
        ray_tree_ui(ui, tree);
    }
}

/// Assignments 3–4: the pixel's ray tree, one ray a block, indented by level.
fn ray_tree_ui(ui: &mut egui::Ui, tree: &tracelab_core::render::RayNode) {
    ui.separator();
    ui.strong(format!("Ray tree ({} rays)", tree.count()));
    let mut lines = Vec::new();
    crate::story::ray_tree_lines(&crate::story::ray_tree_report(tree), 0, &mut lines);
    for l in lines {
        ui.label(egui::RichText::new(l).monospace());
    }
}
