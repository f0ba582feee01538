//! The inspector's field widgets: numbers, vectors and colours labelled for screen readers
//! and tests, and the refused edit's reason shown beside the field it names.

use glam::Vec3;
use tracelab_core::{Field, Place};

use crate::document::Document;
use crate::document::edit::Refusal;
use crate::gui::widgets::{number, render_from_swatch, swatch_from_render};

/// Three drag values labelled for screen readers and tests (e.g. "Translate x"); a refusal
/// about `field` shows under them.
pub(super) fn vec3(ui: &mut egui::Ui, name: &str, field: Field, v: &mut Vec3, speed: f64) -> bool {
    let mut changed = false;
    ui.horizontal(|ui| {
        ui.label(name);
        for (axis, c) in [("x", &mut v.x), ("y", &mut v.y), ("z", &mut v.z)] {
            let r = number(ui, &mut *c, |d| d.speed(speed).max_decimals(4));
            name_widget(&r, format!("{name} {axis}"), f64::from(*c));
            changed |= r.changed();
        }
    });
    // Under the row, not beside it: the row's width is taken, and a wrapped reason one word
    // a line is hard to read.
    refusal_note(ui, &field);
    changed
}

/// Gives a drag value an accessible name (screen readers, and tests that find it by label).
pub(super) fn name_widget(r: &egui::Response, name: String, value: f64) {
    r.widget_info(|| egui::WidgetInfo {
        label: Some(name.clone()),
        ..egui::WidgetInfo::drag_value(true, value)
    });
}

pub(super) fn scalar(ui: &mut egui::Ui, name: &str, field: Field, v: &mut f32, speed: f64) -> bool {
    let changed = ui
        .horizontal(|ui| {
            ui.label(name);
            let r = number(ui, &mut *v, |d| d.speed(speed).max_decimals(4));
            name_widget(&r, name.to_string(), f64::from(*v));
            r.changed()
        })
        .inner;
    refusal_note(ui, &field);
    changed
}

/// What the last refused edit said, while the inspector draws the place it was about. In
/// egui's memory for the frame, so `vec3`, `scalar` and `color` show it beside the field it
/// names without a parameter each.
#[derive(Clone)]
struct Note {
    field: Field,
    op: Option<usize>,
    reason: String,
}

fn note_id() -> egui::Id {
    egui::Id::unique("tracelab-refusal-note")
}

/// The op being drawn, so a refusal for op 2 shows beside op 2's fields only.
pub(super) fn op_id() -> egui::Id {
    egui::Id::unique("tracelab-refusal-op")
}

pub(super) fn show_refusal_for(ui: &egui::Ui, doc: &Document, place: Option<Place>) {
    let note = doc
        .refusal
        .as_ref()
        .filter(|r: &&Refusal| r.place.is_some() && r.place == place)
        .and_then(|r| {
            Some(Note {
                field: r.field.clone()?,
                op: r.op,
                reason: r.reason.clone(),
            })
        });
    ui.data_mut(|d| {
        d.insert_temp(note_id(), note);
        d.insert_temp(op_id(), None::<usize>);
    });
}

/// The refusal's reason under the widget that edits `field`, if the refusal names it (and,
/// inside a Transform's op, that op).
pub(super) fn refusal_note(ui: &mut egui::Ui, field: &Field) {
    let (note, op) = ui.data(|d| {
        (
            d.get_temp::<Option<Note>>(note_id()).flatten(),
            d.get_temp::<Option<usize>>(op_id()).flatten(),
        )
    });
    if let Some(n) = note.filter(|n| n.op == op && n.field == *field) {
        // Wrapped to the panel: a long reason must not widen it.
        ui.add(
            egui::Label::new(egui::RichText::new(n.reason).color(ui.visuals().error_fg_color))
                .wrap(),
        );
    }
}

pub(super) fn color(ui: &mut egui::Ui, name: &str, field: Field, c: &mut Vec3) -> bool {
    let changed = ui
        .horizontal(|ui| {
            ui.label(name);
            color_values(ui, name, c)
        })
        .inner;
    refusal_note(ui, &field);
    changed
}

/// A colour's swatch and its three numbers (named "`name` r", "… g", "… b"), in a row the
/// caller lays out.
pub(super) fn color_values(ui: &mut egui::Ui, name: &str, c: &mut Vec3) -> bool {
    let mut rgb = c.to_array();
    // The swatch in the render's colour space (see `swatch_from_render`).
    let mut swatch = swatch_from_render(rgb);
    let mut changed = ui.color_edit_button_rgb(&mut swatch).changed();
    if changed {
        rgb = render_from_swatch(swatch);
    }
    for (v, channel) in rgb.iter_mut().zip(["r", "g", "b"]) {
        // No range of its own: the file's rules (a finite number) are the only limit.
        let r = number(ui, v, |d| d.speed(0.005).max_decimals(3));
        name_widget(&r, format!("{name} {channel}"), f64::from(*v));
        changed |= r.changed();
    }
    *c = Vec3::from_array(rgb);
    changed
}
