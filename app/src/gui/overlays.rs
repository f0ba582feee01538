//! What the render view draws over the image besides the gizmo: the selected object's
//! outline (from the per-pixel object ids that picking uses), a world-axes triad, the
//! directional lights' directions and a marker at each point light. The triad and the
//! light directions are badges sized to the image and put in corners that show no object
//! (`place_badges`), so in small views they keep off what the user looks at.

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

/// Below this many points on its shorter side, an image gets no badges (triad, light
/// directions): in "All three" and lecture figures they covered the object.
pub const MIN_BADGE_VIEW: f32 = 120.0;
/// The badges' largest radius, in views of 370 points and more.
const BADGE_RADIUS: f32 = 26.0;

/// A corner of the image, for a badge.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Corner {
    BottomLeft,
    TopLeft,
    TopRight,
    BottomRight,
}

/// Where the badges go in an image drawn in `rect`: the triad's centre and the directional
/// lights' centres (one per light, a row), all of radius `radius`.
#[derive(Clone, Debug, PartialEq)]
pub struct Badges {
    pub radius: f32,
    pub triad: Option<egui::Pos2>,
    pub lights: Vec<egui::Pos2>,
}

impl Badges {
    /// Every badge's square on screen.
    pub fn rects(&self) -> Vec<egui::Rect> {
        let side = egui::Vec2::splat(self.radius * 2.0);
        self.triad
            .iter()
            .chain(&self.lights)
            .map(|c| egui::Rect::from_center_size(*c, side))
            .collect()
    }
}

/// The badges for an image in `rect` with `lights` directional lights: scaled to the image
/// (none below [`MIN_BADGE_VIEW`]), each in the first corner where `shows_object` says no
/// object is under it (the triad prefers the bottom left, the lights the top right), else,
/// in a view big enough to spare the room, its own corner; in a small one, none.
pub fn place_badges(
    rect: egui::Rect,
    lights: usize,
    shows_object: &dyn Fn(egui::Rect) -> bool,
) -> Badges {
    let side = rect.width().min(rect.height());
    let none = Badges {
        radius: 0.0,
        triad: None,
        lights: Vec::new(),
    };
    if side < MIN_BADGE_VIEW {
        return none;
    }
    let r = (side * 0.07).clamp(10.0, BADGE_RADIUS);
    let margin = 4.0;
    let step = 2.0 * r + margin;
    // A row of `n` badges starting at `corner`, going inward along the edge.
    let row = |corner: Corner, n: usize| -> Vec<egui::Pos2> {
        let (start, dir) = match corner {
            Corner::BottomLeft => (
                rect.left_bottom() + egui::vec2(r + margin, -r - margin),
                1.0,
            ),
            Corner::TopLeft => (rect.left_top() + egui::vec2(r + margin, r + margin), 1.0),
            Corner::TopRight => (rect.right_top() + egui::vec2(-r - margin, r + margin), -1.0),
            Corner::BottomRight => (
                rect.right_bottom() + egui::vec2(-r - margin, -r - margin),
                -1.0,
            ),
        };
        (0..n)
            .map(|i| start + egui::vec2(dir * step * i as f32, 0.0))
            .collect()
    };
    let square = |c: egui::Pos2| egui::Rect::from_center_size(c, egui::Vec2::splat(2.0 * r));
    let fits = |centres: &[egui::Pos2], taken: &[egui::Rect]| {
        centres.iter().all(|c| {
            let sq = square(*c);
            rect.contains_rect(sq) && !taken.iter().any(|t| t.intersects(sq)) && !shows_object(sq)
        })
    };
    let big = side >= 3.0 * MIN_BADGE_VIEW;
    use Corner::*;
    let triad_row = [BottomLeft, TopLeft, BottomRight, TopRight]
        .into_iter()
        .map(|c| row(c, 1))
        .find(|r| fits(r, &[]))
        .or_else(|| big.then(|| row(BottomLeft, 1)));
    let taken: Vec<egui::Rect> = triad_row.iter().flatten().map(|c| square(*c)).collect();
    let light_row = if lights == 0 {
        None
    } else {
        [TopRight, TopLeft, BottomRight, BottomLeft]
            .into_iter()
            .map(|c| row(c, lights))
            .find(|r| fits(r, &taken))
            .or_else(|| {
                let r = row(TopRight, lights);
                (big && r.iter().all(|c| rect.contains_rect(square(*c)))).then_some(r)
            })
    };
    Badges {
        radius: r,
        triad: triad_row.and_then(|r| r.first().copied()),
        lights: light_row.unwrap_or_default(),
    }
}

/// The world axes in a badge of radius `r` centred at `o`.
pub fn triad(painter: &egui::Painter, basis: &ViewBasis, o: egui::Pos2, r: f32) {
    painter.circle_filled(o, r, egui::Color32::from_black_alpha(90));
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
    let len = r * 0.77;
    for (d, name, c) in order {
        let v = on_screen(basis, *d) * len;
        painter.line_segment([o, o + v], egui::Stroke::new(2.0, *c));
        painter.text(
            o + v * 1.2,
            egui::Align2::CENTER_CENTER,
            *name,
            egui::FontId::monospace((r * 0.42).clamp(8.0, 11.0)),
            *c,
        );
    }
}

/// Each directional light's direction (from the light into the scene), in the light's
/// colour, in the badges at `centres` (one per directional light, in order).
pub fn lights(
    painter: &egui::Painter,
    basis: &ViewBasis,
    centres: &[egui::Pos2],
    r: f32,
    scene: &Scene,
) {
    let directional = scene
        .lights()
        .iter()
        .enumerate()
        .filter_map(|(i, l)| Some((i, l, l.direction().and_then(tracelab_core::scene::unit)?)));
    for ((i, l, d), &o) in directional.zip(centres) {
        // A point light has no one direction (its place is for the gizmo to show).
        let colour = light_colour(l.color);
        painter.circle_filled(o, r, egui::Color32::from_black_alpha(90));
        let v = on_screen(basis, d) * (r * 0.77);
        // Into the screen: a cross; out of it: a dot (the light is behind the viewer).
        if v.length() < r * 0.15 {
            // Drawn, not typed: the UI's fonts have no ⊗ or ⊙.
            let stroke = egui::Stroke::new(2.0, colour);
            let k = r * 0.27;
            painter.circle_stroke(o, k * 1.4, stroke);
            if d.dot(basis.rays.direction) > 0.0 {
                painter.line_segment([o + egui::vec2(-k, -k), o + egui::vec2(k, k)], stroke);
                painter.line_segment([o + egui::vec2(-k, k), o + egui::vec2(k, -k)], stroke);
            } else {
                painter.circle_filled(o, 2.5, colour);
            }
        } else {
            painter.arrow(o - v * 0.5, v, egui::Stroke::new(2.0, colour));
        }
        painter.text(
            o + egui::vec2(0.0, r * 0.7),
            egui::Align2::CENTER_TOP,
            format!("light {i}"),
            egui::FontId::proportional((r * 0.38).clamp(8.0, 10.0)),
            colour,
        );
    }
}

/// How many lights [`lights`] draws: the directional ones.
pub fn directional_lights(scene: &Scene) -> usize {
    scene
        .lights()
        .iter()
        .filter(|l| l.direction().and_then(tracelab_core::scene::unit).is_some())
        .count()
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
