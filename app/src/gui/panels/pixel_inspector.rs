//! The pixel inspector: the story of one pixel's ray, from the core's `inspect_pixel`. The
//! pixel stays chosen while the scene and the view change: each new render traces it again,
//! so the story always describes the image on screen (it once kept showing a deleted box).

use std::sync::Arc;

use glam::Vec3;
use tracelab_core::render::{RayStory, inspect_pixel};
use tracelab_core::{NodeKind, NormalTransform, RenderSettings, Scene};

use crate::render_worker::Published;

/// The pixel being inspected, and the render its story was traced in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Inspected {
    /// Which image: 0, or 1 for the Incorrect rule in compare mode.
    pub frame: usize,
    pub x: u32,
    pub row: u32,
    /// The image size the pixel was picked in, to find the same place after a resize.
    pub size: (u32, u32),
    /// The render request the story belongs to.
    pub request: u64,
}

/// Traces pixel (`x`, `row`) of image `frame` of a published render.
pub fn trace(p: &Published, frame: usize, x: u32, row: u32) -> Option<(Inspected, RayStory, Arc<Scene>)> {
    let mode = *p.job.modes.get(frame)?;
    let settings = RenderSettings { normal_transform: mode, ..p.job.settings };
    let at = Inspected {
        frame,
        x: x.min(settings.width.saturating_sub(1)),
        row: row.min(settings.height.saturating_sub(1)),
        size: (settings.width, settings.height),
        request: p.job.request,
    };
    let story = inspect_pixel(&p.job.scene, &p.compiled, &settings, at.x, at.row);
    Some((at, story, p.job.scene.clone()))
}

/// The same pixel traced in a newer render: the same place in the image when its size
/// changed, and the first image when the one it was in is gone (compare mode turned off).
/// `None` when `p` is the render `at` was traced in.
pub fn follow(p: &Published, at: &Inspected) -> Option<(Inspected, RayStory, Arc<Scene>)> {
    if p.job.request == at.request {
        return None;
    }
    let (w, h) = (p.job.settings.width, p.job.settings.height);
    let scale = |v: u32, old: u32, new: u32| ((f64::from(v) + 0.5) * f64::from(new) / f64::from(old.max(1))) as u32;
    let frame = if at.frame < p.job.modes.len() { at.frame } else { 0 };
    trace(p, frame, scale(at.x, at.size.0, w), scale(at.row, at.size.1, h))
}

fn v(v: Vec3) -> String {
    format!("({:.4}, {:.4}, {:.4})", v.x, v.y, v.z)
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
    } = story;
    ui.label(format!("Pixel ({x}, {row}), rows from the top"));
    ui.label(format!(
        "World ray: origin {} direction {}",
        v(world_ray.origin),
        v(world_ray.direction)
    ));
    let Some(h) = hit else {
        ui.label(format!(
            "Missed every object: background {}",
            v(*background)
        ));
        return;
    };
    ui.separator();
    ui.strong(format!(
        "Hit {} (node #{}) at t = {:.5}",
        scene.graph.get(h.node).map_or("?", |n| n.kind.name()),
        h.node.0,
        h.t
    ));
    ui.label("Path, with the ray in each space (t is the same in every one):");
    egui::Grid::new("path").striped(true).show(ui, |ui| {
        for step in &h.path {
            let what = match scene.graph.get(step.node).map(|n| &n.kind) {
                Some(NodeKind::Transform(ops)) => {
                    format!(
                        "Transform: {}",
                        ops.iter()
                            .map(|o| o.summary())
                            .collect::<Vec<_>>()
                            .join(" · ")
                    )
                }
                _ => step.kind.to_string(),
            };
            ui.label(what);
            ui.label(format!(
                "o {}  d {}",
                v(step.ray.origin),
                v(step.ray.direction)
            ));
            ui.end_row();
        }
    });
    ui.separator();
    egui::Grid::new("hit").show(ui, |ui| {
        let mut row = |a: &str, b: String| {
            ui.label(a);
            ui.label(b);
            ui.end_row();
        };
        row("hit point (object)", v(h.object_point));
        row("hit point (world)", v(h.world_point));
        row("normal (object)", v(h.object_normal));
        row("world normal by (M^-1)^T", v(h.normal_correct));
        row("world normal by M", v(h.normal_incorrect));
        row(
            "angle between them",
            format!("{:.3}°", h.normal_angle_degrees),
        );
        let rule = match normal_transform {
            NormalTransform::Correct => "(M^-1)^T",
            NormalTransform::Incorrect => "M",
        };
        row(
            "shading uses",
            format!(
                "{rule}{}",
                if h.shade.back_facing {
                    ", back-facing"
                } else {
                    ""
                }
            ),
        );
        row("diffuse k_d", v(h.shade.diffuse));
        row("ambient · k_d", v(h.shade.ambient_term));
        for (i, l) in h.shade.lights.iter().enumerate() {
            row(&format!("light {i}: L·N"), format!("{:.4}", l.l_dot_n));
            row(&format!("light {i}: max(L·N,0)·c·k_d"), v(l.contribution));
        }
        row("colour (sum)", v(h.shade.color));
    });
}
