//! The Ray panel: the picked pixel's ray drawn twice, as the lecture's "World Space / Object
//! Space" figure — in world space with the hit object, both normals, the tangent plane and
//! the lights; in the hit primitive's own space with M⁻¹o, M⁻¹d at its own length and the
//! object normal. Drag in either diagram to orbit it. With shadows or bounces on, the world
//! diagram also draws the pixel's ray tree: reflected and refracted rays and the shadow
//! rays, with a legend.

use egui::{Color32, Pos2, Stroke};
use glam::{Vec2, Vec3};
use tracelab_core::Scene;
use tracelab_core::render::RayStory;

use crate::gui::grid_view::GridPick;
use crate::gui::ray_diagram::{Diagram, Orbit, Role, Shape, diagrams};

fn color(role: Role) -> Color32 {
    match role {
        Role::Eye => Color32::from_rgb(200, 200, 200),
        Role::Ray => Color32::from_rgb(240, 240, 120),
        Role::Outline => Color32::from_rgb(110, 140, 200),
        Role::Hit => Color32::WHITE,
        Role::NormalCorrect => Color32::from_rgb(90, 220, 90),
        Role::NormalIncorrect => Color32::from_rgb(240, 80, 80),
        Role::Tangent => Color32::from_rgba_unmultiplied(90, 220, 90, 90),
        Role::Light => Color32::from_rgb(255, 190, 60),
        Role::Direction => Color32::from_rgb(255, 140, 255),
        Role::Reflected => Color32::from_rgb(80, 200, 255),
        Role::Refracted => Color32::from_rgb(200, 120, 255),
        Role::Shadow => Color32::from_rgb(170, 170, 140),
        Role::ShadowBlocked => Color32::from_rgb(255, 70, 70),
        Role::GridCell => Color32::from_rgba_unmultiplied(120, 130, 150, 45),
        Role::GridWalk => Color32::from_rgb(255, 150, 40),
    }
}

/// A line of the diagram: shadow rays thin and dashed, the others solid.
fn line(painter: &egui::Painter, role: Role, pts: Vec<Pos2>) {
    let c = color(role);
    match role {
        Role::Shadow | Role::ShadowBlocked => {
            painter.extend(egui::Shape::dashed_line(
                &pts,
                Stroke::new(1.0, c),
                5.0,
                3.0,
            ));
        }
        Role::Ray | Role::Reflected | Role::Refracted | Role::GridWalk => {
            painter.line(pts, Stroke::new(2.0, c));
        }
        _ => {
            painter.line(pts, Stroke::new(1.0, c));
        }
    }
}

/// The ray tree's colours, top left, for the roles the diagram holds; returns where it is.
fn legend(painter: &egui::Painter, rect: egui::Rect, d: &Diagram) -> egui::Rect {
    let mut at = rect.left_top() + egui::vec2(8.0, 8.0);
    let mut drawn = egui::Rect::NOTHING;
    let shown: Vec<(Role, &str)> = std::iter::once((Role::Ray, "eye ray"))
        .chain(Role::TREE)
        .filter(|(r, _)| d.find(*r).next().is_some())
        .collect();
    if shown.len() < 2 {
        return drawn;
    }
    for (role, name) in shown {
        line(
            painter,
            role,
            vec![at + egui::vec2(0.0, 6.0), at + egui::vec2(22.0, 6.0)],
        );
        let text = painter.text(
            at + egui::vec2(28.0, 0.0),
            egui::Align2::LEFT_TOP,
            name,
            egui::FontId::proportional(11.0),
            color(role),
        );
        drawn = drawn
            .union(text)
            .union(egui::Rect::from_min_size(at, egui::vec2(22.0, 12.0)));
        at.y += 14.0;
    }
    drawn
}

/// One diagram in `rect`; a drag on it turns `orbit`.
fn draw(
    ui: &mut egui::Ui,
    id: &str,
    title: &str,
    d: &Diagram,
    orbit: &mut Orbit,
    size: egui::Vec2,
) {
    ui.vertical(|ui| {
        ui.strong(title);
        let (rect, response) = ui.allocate_exact_size(size, egui::Sense::drag());
        if response.dragged() {
            let delta = response.drag_delta();
            orbit.drag(Vec2::new(delta.x, delta.y));
        }
        if response.hovered() {
            let scroll = ui.input(|i| i.smooth_scroll_delta.y);
            if scroll != 0.0 {
                orbit.scroll(scroll);
            }
        }
        let painter = ui.painter_at(rect);
        let mut labels: Vec<(Pos2, &str, Color32)> = Vec::new();
        painter.rect_filled(rect, 4.0, Color32::from_gray(24));
        let (center, radius) = d.bounds();
        let half = rect.width().min(rect.height()) * 0.5 - 14.0;
        let sc = Vec2::new(rect.center().x, rect.center().y);
        let proj = |p: Vec3| {
            let q = orbit.project(p, center, radius, sc, half.max(10.0));
            Pos2::new(q.x, q.y)
        };
        for item in &d.items {
            let c = color(item.role);
            let at = match &item.shape {
                Shape::Point(p) => {
                    painter.circle_filled(proj(*p), 3.5, c);
                    proj(*p)
                }
                Shape::Line(ps) => {
                    line(&painter, item.role, ps.iter().map(|p| proj(*p)).collect());
                    let end = ps.last().map_or(Pos2::ZERO, |p| proj(*p));
                    if item.role == Role::ShadowBlocked {
                        // A cross where the blocker stopped it.
                        let s = Stroke::new(1.5, c);
                        painter.line_segment(
                            [end - egui::vec2(4.0, 4.0), end + egui::vec2(4.0, 4.0)],
                            s,
                        );
                        painter.line_segment(
                            [end - egui::vec2(4.0, -4.0), end + egui::vec2(4.0, -4.0)],
                            s,
                        );
                    }
                    end
                }
                Shape::Arrow(a, b) => {
                    let (pa, pb) = (proj(*a), proj(*b));
                    painter.arrow(pa, pb - pa, Stroke::new(2.0, c));
                    pb
                }
            };
            if let Some(l) = &item.label {
                labels.push((at, l.as_str(), c));
            }
        }
        let mut taken = vec![legend(&painter, rect, d)];
        // Say where the origin is when it lies outside the view.
        if let Some(o) = d.items.iter().find(|i| i.role == Role::Eye)
            && let Shape::Point(p) = o.shape
            && !rect.contains(proj(p))
        {
            taken.push(painter.text(
                rect.left_bottom() + egui::vec2(6.0, -6.0),
                egui::Align2::LEFT_BOTTOM,
                format!(
                    "ray origin ({:.2}, {:.2}, {:.2}) off view: scroll to zoom out",
                    p.x, p.y, p.z
                ),
                egui::FontId::proportional(11.0),
                color(Role::Eye),
            ));
        }
        // Labels where they overlap nothing drawn before them (text, legend), each as a
        // label widget, so the tests and screen readers find them.
        let sizes: Vec<egui::Vec2> = labels
            .iter()
            .map(|(_, t, _)| {
                painter
                    .layout_no_wrap(t.to_string(), label_font(), Color32::WHITE)
                    .size()
            })
            .collect();
        let anchors: Vec<Pos2> = labels.iter().map(|(a, _, _)| *a).collect();
        let placed = place_labels(&anchors, &sizes, rect.shrink(2.0), &taken);
        for ((anchor, text, c), at) in labels.into_iter().zip(placed) {
            if anchor.distance(anchor.clamp(at.min, at.max)) > 10.0 {
                // Moved away from its point: a thin line says whose it is.
                painter.line_segment(
                    [anchor, anchor.clamp(at.min, at.max)],
                    Stroke::new(0.5, c.gamma_multiply(0.6)),
                );
            }
            ui.put(
                at,
                egui::Label::new(egui::RichText::new(text).font(label_font()).color(c))
                    .selectable(false)
                    .extend(),
            );
        }
        response
            .accessible_name(format!("{title} diagram"))
            .on_hover_text(format!("{id}: drag to orbit, scroll to zoom"));
    });
}

fn label_font() -> egui::FontId {
    egui::FontId::proportional(11.0)
}

/// Where to put labels of `sizes` near their `anchors` inside `bounds`, overlapping neither
/// each other nor `taken`: the first free spot on rings of growing distance around the
/// anchor (right and above first, the old place); if none is free, the first free row of a
/// list down the right edge; and last, the spot that overlaps least.
pub fn place_labels(
    anchors: &[Pos2],
    sizes: &[egui::Vec2],
    bounds: egui::Rect,
    taken: &[egui::Rect],
) -> Vec<egui::Rect> {
    let mut placed: Vec<egui::Rect> = Vec::with_capacity(anchors.len());
    let overlap = |r: &egui::Rect, placed: &[egui::Rect]| -> f32 {
        placed
            .iter()
            .chain(taken)
            .map(|o| {
                let i = r.intersect(*o);
                if i.is_positive() { i.area() } else { 0.0 }
            })
            .sum()
    };
    for (&a, &size) in anchors.iter().zip(sizes) {
        let mut candidates = Vec::new();
        for ring in [4.0f32, 14.0, 26.0, 40.0, 56.0] {
            for (dx, dy) in [
                (1.0, -1.0),
                (1.0, 1.0),
                (-1.0, -1.0),
                (-1.0, 1.0),
                (1.0, 0.0),
                (-1.0, 0.0),
                (0.0, -1.0),
                (0.0, 1.0),
            ] {
                // The rectangle's corner (or edge middle) nearest the anchor sits `ring` away.
                let min = egui::pos2(
                    a.x + dx * ring
                        - if dx < 0.0 {
                            size.x
                        } else if dx == 0.0 {
                            size.x * 0.5
                        } else {
                            0.0
                        },
                    a.y + dy * ring
                        - if dy < 0.0 {
                            size.y
                        } else if dy == 0.0 {
                            size.y * 0.5
                        } else {
                            0.0
                        },
                );
                candidates.push(egui::Rect::from_min_size(min, size));
            }
        }
        // The list beside: rows down the right edge.
        let mut y = bounds.top();
        while y + size.y <= bounds.bottom() {
            candidates.push(egui::Rect::from_min_size(
                egui::pos2(bounds.right() - size.x, y),
                size,
            ));
            y += size.y + 1.0;
        }
        let inside: Vec<egui::Rect> = candidates
            .iter()
            .copied()
            .filter(|r| bounds.contains_rect(*r))
            .collect();
        let chosen = inside
            .iter()
            .find(|r| overlap(r, &placed) == 0.0)
            .or_else(|| {
                inside
                    .iter()
                    .min_by(|x, y| overlap(x, &placed).total_cmp(&overlap(y, &placed)))
            })
            .copied()
            .unwrap_or(candidates[0]);
        placed.push(chosen);
    }
    placed
}

/// Both diagrams side by side, or a line saying why there are none. With a uniform grid in
/// use, the world diagram also draws its occupied cells and the cells the ray walks.
pub fn ui(
    ui: &mut egui::Ui,
    story: Option<(&RayStory, &Scene)>,
    orbits: &mut [Orbit; 2],
    grid: Option<&GridPick>,
) {
    let Some((story, scene)) = story else {
        ui.label("Click a pixel in the render view to draw its ray.");
        return;
    };
    let Some((mut world, object)) = diagrams(scene, story) else {
        if let Some(g) = grid {
            // No hit, but a walk through the grid to draw.
            ui.label(egui::RichText::new(g.summary()).small());
            let avail = ui.available_size();
            let side = egui::vec2(avail.x.max(120.0), (avail.y - 24.0).max(120.0));
            draw(
                ui,
                "world",
                "World space",
                &g.miss_diagram(),
                &mut orbits[0],
                side,
            );
            return;
        }
        ui.label("The ray misses every object: nothing to draw.");
        return;
    };
    if let Some(g) = grid {
        ui.label(egui::RichText::new(g.summary()).small());
        world.items.extend(g.items.iter().cloned());
    }
    let avail = ui.available_size();
    let side = egui::vec2(
        ((avail.x - 16.0) / 2.0).max(120.0),
        (avail.y - 24.0).max(120.0),
    );
    let [w, o] = orbits;
    ui.horizontal(|ui| {
        draw(ui, "world", "World space", &world, w, side);
        draw(
            ui,
            "object",
            "Object space (of the primitive hit)",
            &object,
            o,
            side,
        );
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_at_one_point_are_placed_apart_inside_the_diagram() {
        let bounds = egui::Rect::from_min_size(Pos2::ZERO, egui::vec2(200.0, 150.0));
        let legend = egui::Rect::from_min_size(Pos2::new(0.0, 0.0), egui::vec2(80.0, 40.0));
        // The ray's t, the hit and M^-1 d all end at the hit point.
        let anchors = [Pos2::new(60.0, 30.0); 3];
        let sizes = [
            egui::vec2(50.0, 13.0),
            egui::vec2(20.0, 13.0),
            egui::vec2(90.0, 13.0),
        ];
        let placed = place_labels(&anchors, &sizes, bounds, &[legend]);
        for (i, a) in placed.iter().enumerate() {
            assert!(bounds.contains_rect(*a), "{a:?}");
            assert!(!a.intersects(legend), "{a:?}");
            for b in &placed[i + 1..] {
                assert!(!a.intersects(*b), "{a:?} {b:?}");
            }
            // Near its point, not thrown across the diagram.
            assert!(a.distance_to_pos(anchors[0]) < 60.0, "{a:?}");
        }
        // Control: where they used to go (right of and above the point), they overlap.
        let old =
            |s: egui::Vec2| egui::Rect::from_min_size(anchors[0] + egui::vec2(4.0, -4.0 - s.y), s);
        assert!(old(sizes[0]).intersects(old(sizes[1])));
    }
}
