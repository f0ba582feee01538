//! The inspector's scene-wide items: the camera, a light, the background.

use glam::Vec3;
use tracelab_core::scene::{DEFAULT_ATTENUATION, LightKind};
use tracelab_core::{Background, Camera, Field, Place};

use crate::document::Document;
use crate::document::edit::Edit;
use crate::gui::drag_speed::DragSpeeds;

use super::super::fields::{color, scalar, show_refusal_for, vec3};

pub(super) fn camera(ui: &mut egui::Ui, cam: &Camera, edits: &mut Vec<Edit>) {
    let speeds = DragSpeeds::for_scene_camera(cam);
    ui.heading("Camera");
    let mut c = cam.clone();
    let mut changed = false;
    ui.horizontal(|ui| {
        let ortho = matches!(c, Camera::Orthographic { .. });
        if ui.selectable_label(ortho, "Orthographic").clicked() && !ortho {
            c = Camera::Orthographic {
                center: c.center(),
                direction: c.direction(),
                up: c.up(),
                size: 5.0,
            };
            changed = true;
        }
        if ui.selectable_label(!ortho, "Perspective").clicked() && ortho {
            c = Camera::Perspective {
                center: c.center(),
                direction: c.direction(),
                up: c.up(),
                angle: 30.0,
            };
            changed = true;
        }
    });
    match &mut c {
        Camera::Orthographic {
            center,
            direction,
            up,
            size,
        } => {
            changed |= vec3(ui, "center", Field::Center, center, speeds.length(1.0));
            changed |= vec3(ui, "direction", Field::Direction, direction, 0.01);
            changed |= vec3(ui, "up", Field::Up, up, 0.01);
            changed |= scalar(ui, "size", Field::Size, size, DragSpeeds::factor(*size));
        }
        Camera::Perspective {
            center,
            direction,
            up,
            angle,
        } => {
            changed |= vec3(ui, "center", Field::Center, center, speeds.length(1.0));
            changed |= vec3(ui, "direction", Field::Direction, direction, 0.01);
            changed |= vec3(ui, "up", Field::Up, up, 0.01);
            // No clamp of its own: an angle out of (0, 180) is refused by the rules, beside
            // the field.
            changed |= scalar(ui, "angle (degrees)", Field::Angle, angle, 0.1);
        }
    }
    if changed {
        edits.push(Edit::SetCamera(c));
    }
}

pub(super) fn light(ui: &mut egui::Ui, doc: &Document, i: usize, edits: &mut Vec<Edit>) {
    let Some(l) = doc.scene.lights().get(i) else {
        return;
    };
    let mut l = l.clone();
    show_refusal_for(ui, doc, Some(Place::Light(i)));
    let mut changed = match &mut l.kind {
        LightKind::Directional { direction } => {
            ui.strong(format!("Light {i} (directional)"));
            vec3(ui, "direction", Field::Direction, direction, 0.01)
        }
        LightKind::Point {
            position,
            attenuation,
        } => {
            ui.strong(format!("Light {i} (point)"));
            let mut changed = vec3(ui, "position", Field::Position, position, 0.01);
            // Absent means the course's 1 0 0, and stays absent until given.
            let mut on = attenuation.is_some();
            if ui
                .checkbox(&mut on, "attenuation (constant, linear, quadratic)")
                .changed()
            {
                *attenuation = on.then_some(DEFAULT_ATTENUATION);
                changed = true;
            }
            if let Some(a) = attenuation {
                changed |= vec3(ui, "attenuation", Field::Attenuation, a, 0.01);
            }
            changed
        }
    };
    changed |= color(ui, "colour", Field::Color, &mut l.color);
    if changed {
        edits.push(Edit::SetLight { index: i, light: l });
    }
    if ui.button(format!("Remove light {i}")).clicked() {
        edits.push(Edit::RemoveLight { index: i });
    }
}

pub(super) fn background(ui: &mut egui::Ui, bg: &Background, edits: &mut Vec<Edit>) {
    ui.heading("Background");
    let mut b = bg.clone();
    let mut changed = false;
    for (name, field, value) in [
        ("colour", Field::Color, &mut b.color),
        ("ambient light", Field::AmbientLight, &mut b.ambient),
    ] {
        let mut on = value.is_some();
        ui.horizontal(|ui| {
            if ui.checkbox(&mut on, "").changed() {
                *value = on.then_some(Vec3::ZERO);
                changed = true;
            }
            if let Some(c) = value {
                changed |= color(ui, name, field.clone(), c);
            } else {
                ui.label(format!("{name} (not set: black)"));
            }
        });
    }
    if changed {
        edits.push(Edit::SetBackground(b));
    }
}
