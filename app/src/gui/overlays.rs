//! What the render view draws over the image besides the gizmo: the selected object's
//! outline (from the per-pixel object ids that picking uses), a world-axes triad, the
//! directional lights' directions and a marker at each point light.

use glam::Vec3;
use tracelab_core::{Frame, NodeId, Scene};

use crate::document::Selection;
use crate::gui::on_screen::OnScreen;
use crate::navigation::ViewBasis;

const OUTLINE: [u8; 4] = [255, 150, 20, 255];

/// The outline of the pixels showing the nodes marked in `nodes` (indexed by raw node id):
/// each such pixel with a neighbour that shows something else, as an RGBA image the size of
/// the frame (clear elsewhere). `None` when no pixel shows them.
pub fn outline(frame: &Frame, nodes: &[bool]) -> Option<egui::ColorImage> {
    let (w, h) = (frame.width as usize, frame.height as usize);
    if w == 0 || h == 0 || !nodes.contains(&true) {
        return None;
    }
    // A table, not a set: this runs over every pixel on the UI thread.
    let inside: Vec<bool> = frame
        .samples
        .iter()
        .map(|s| nodes.get(s.node as usize).copied().unwrap_or(false))
        .collect();
    let at = |x: usize, y: usize| inside.get(y * w + x).copied().unwrap_or(false);
    let mut rgba = vec![0u8; w * h * 4];
    let mut any = false;
    for y in 0..h {
        for x in 0..w {
            if !at(x, y) {
                continue;
            }
            let edge = x == 0
                || y == 0
                || x + 1 == w
                || y + 1 == h
                || !at(x - 1, y)
                || !at(x + 1, y)
                || !at(x, y - 1)
                || !at(x, y + 1);
            if edge {
                rgba[(y * w + x) * 4..][..4].copy_from_slice(&OUTLINE);
                any = true;
            }
        }
    }
    any.then(|| egui::ColorImage::from_rgba_unmultiplied([w, h], &rgba))
}

/// `node` and everything under it, marked by raw id: what its pixels may name.
pub fn subtree_ids(scene: &Scene, node: NodeId) -> Vec<bool> {
    let mut mask = vec![false; scene.graph.capacity_len()];
    for id in scene.graph.preorder_from(node) {
        if let Some(m) = mask.get_mut(id.index()) {
            *m = true;
        }
    }
    mask
}

/// A world direction as a screen vector (points, y down), as seen by the camera.
fn on_screen(basis: &ViewBasis, d: Vec3) -> egui::Vec2 {
    egui::vec2(d.dot(basis.rays.horizontal), -d.dot(basis.rays.up))
}

/// The world axes in the image's lower-left corner.
pub fn triad(painter: &egui::Painter, basis: &ViewBasis, rect: egui::Rect) {
    let o = rect.left_bottom() + egui::vec2(34.0, -34.0);
    painter.circle_filled(o, 26.0, egui::Color32::from_black_alpha(90));
    let axes = [
        (Vec3::X, "x", egui::Color32::from_rgb(230, 70, 70)),
        (Vec3::Y, "y", egui::Color32::from_rgb(90, 210, 90)),
        (Vec3::Z, "z", egui::Color32::from_rgb(90, 140, 255)),
    ];
    // Farthest first, so the nearer axes draw over it.
    let mut order: Vec<_> = axes.iter().collect();
    order.sort_by(|a, b| {
        b.0.dot(basis.rays.direction)
            .total_cmp(&a.0.dot(basis.rays.direction))
    });
    for (d, name, c) in order {
        let v = on_screen(basis, *d) * 20.0;
        painter.line_segment([o, o + v], egui::Stroke::new(2.0, *c));
        painter.text(
            o + v * 1.2,
            egui::Align2::CENTER_CENTER,
            *name,
            egui::FontId::monospace(11.0),
            *c,
        );
    }
}

/// Each directional light's direction (from the light into the scene) in the image's upper
/// right corner, in the light's colour.
pub fn lights(painter: &egui::Painter, basis: &ViewBasis, rect: egui::Rect, scene: &Scene) {
    for (i, l) in scene.lights().iter().enumerate() {
        // A point light has no one direction (its place is for the gizmo to show).
        let Some(d) = l.direction().and_then(tracelab_core::scene::unit) else {
            continue;
        };
        let colour = light_colour(l.color);
        let o = rect.right_top() + egui::vec2(-34.0 - 60.0 * i as f32, 34.0);
        painter.circle_filled(o, 26.0, egui::Color32::from_black_alpha(90));
        let v = on_screen(basis, d) * 20.0;
        // Into the screen: a cross; out of it: a dot (the light is behind the viewer).
        if v.length() < 4.0 {
            // Drawn, not typed: the UI's fonts have no ⊗ or ⊙.
            let stroke = egui::Stroke::new(2.0, colour);
            painter.circle_stroke(o, 7.0, stroke);
            if d.dot(basis.rays.direction) > 0.0 {
                painter.line_segment(
                    [o + egui::vec2(-5.0, -5.0), o + egui::vec2(5.0, 5.0)],
                    stroke,
                );
                painter.line_segment(
                    [o + egui::vec2(-5.0, 5.0), o + egui::vec2(5.0, -5.0)],
                    stroke,
                );
            } else {
                painter.circle_filled(o, 2.5, colour);
            }
        } else {
            painter.arrow(o - v * 0.5, v, egui::Stroke::new(2.0, colour));
        }
        painter.text(
            o + egui::vec2(0.0, 18.0),
            egui::Align2::CENTER_TOP,
            format!("light {i}"),
            egui::FontId::proportional(10.0),
            colour,
        );
    }
}

/// A small sun at each point light's position, in its colour, named; the selected one
/// ringed (its arrows are the gizmo's).
pub fn point_lights(
    painter: &egui::Painter,
    view: &OnScreen,
    scene: &Scene,
    selection: Option<Selection>,
) {
    for (i, l) in scene.lights().iter().enumerate() {
        let tracelab_core::scene::LightKind::Point { position, .. } = l.kind else {
            continue;
        };
        let Some(c) = view.project(position) else {
            continue;
        };
        let colour = light_colour(l.color);
        let stroke = egui::Stroke::new(1.5, colour);
        painter.circle_filled(c, 5.0, colour);
        painter.circle_stroke(c, 5.0, egui::Stroke::new(1.0, egui::Color32::BLACK));
        for k in 0..8 {
            let a = k as f32 * std::f32::consts::FRAC_PI_4;
            let d = egui::vec2(a.cos(), a.sin());
            painter.line_segment([c + d * 7.0, c + d * 11.0], stroke);
        }
        if selection == Some(Selection::Light(i)) {
            painter.circle_stroke(c, 14.0, egui::Stroke::new(1.5, egui::Color32::WHITE));
        }
        painter.text(
            c + egui::vec2(12.0, 10.0),
            egui::Align2::LEFT_TOP,
            format!("point light {i}"),
            egui::FontId::proportional(10.0),
            colour,
        );
    }
}

/// A light's colour for drawing: halved, and light grey where that would be too dark to see.
fn light_colour(color: Vec3) -> egui::Color32 {
    let c = color.clamp(Vec3::ZERO, Vec3::ONE) * 255.0;
    let colour = egui::Color32::from_rgb(c.x as u8, c.y as u8, c.z as u8)
        .gamma_multiply(0.5)
        .to_opaque();
    if colour.r().max(colour.g()).max(colour.b()) < 60 {
        egui::Color32::LIGHT_GRAY
    } else {
        colour
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tracelab_core::Sample;

    #[test]
    fn the_outline_is_the_border_of_the_selected_pixels() {
        let mut f = Frame::new(5, 5);
        for y in 1..4 {
            for x in 1..4 {
                f.samples[y * 5 + x] = Sample {
                    node: 7,
                    ..Sample::UNSET
                };
            }
        }
        let mut seven = vec![false; 9];
        seven[7] = true;
        let img = outline(&f, &seven).expect("drawn");
        let lit: Vec<usize> = img
            .pixels
            .iter()
            .enumerate()
            .filter(|(_, c)| c.a() > 0)
            .map(|(i, _)| i)
            .collect();
        // The 3×3 block's ring of 8, not its centre.
        assert_eq!(lit.len(), 8);
        assert!(!lit.contains(&12));
        let mut eight = vec![false; 9];
        eight[8] = true;
        assert!(outline(&f, &eight).is_none());
    }
}
