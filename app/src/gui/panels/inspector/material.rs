//! The inspector's material: its diffuse colour and Phong fields, or a solid texture shown
//! read-only.

use tracelab_core::{Field, Material, Place};

use crate::document::Document;
use crate::document::edit::Edit;

use super::super::fields::{color, show_refusal_for};

pub(super) fn material(ui: &mut egui::Ui, doc: &Document, i: usize, edits: &mut Vec<Edit>) {
    let Some(m) = doc.scene.materials.get(i) else {
        return;
    };
    let mut m = m.clone();
    show_refusal_for(ui, doc, Some(Place::Material(i)));
    ui.push_id(("material", i), |ui| {
        if let Some(t) = &m.texture {
            // Shown, not yet editable: the file's text is the way to change one.
            texture_lines(ui, i, t);
        } else {
            color_and_phong(ui, i, &mut m, edits);
        }
        if ui
            .button("Remove")
            .on_hover_text(format!("Remove material {i}"))
            .clicked()
        {
            edits.push(Edit::RemoveMaterial { index: i });
        }
    });
}

/// A solid texture, read-only: its kind, materials, numbers and Transform ops.
fn texture_lines(ui: &mut egui::Ui, i: usize, t: &tracelab_core::SolidTexture) {
    let [a, b] = t.materials;
    ui.label(format!("{i}: {} of materials {a} and {b}", t.kind.name()));
    if t.kind.has_octaves() {
        ui.label(format!("octaves {}", t.octaves));
    }
    if t.kind.has_waves() {
        ui.label(format!(
            "frequency {}  amplitude {}",
            t.frequency, t.amplitude
        ));
    }
    for op in t.transform.iter().flatten() {
        ui.small(format!("Transform: {}", op.summary()));
    }
    ui.small("(a solid texture: edit it in the scene file)");
}

fn color_and_phong(ui: &mut egui::Ui, i: usize, m: &mut Material, edits: &mut Vec<Edit>) {
    {
        // Remove under the colour, not beside it: beside, the row was wider than the panel
        // and egui widened the inspector by 60 points, pushing the picture aside.
        let mut c = m.diffuse;
        if color(ui, &format!("{i}: diffuse"), Field::DiffuseColor, &mut c) {
            m.diffuse = c;
            edits.push(Edit::SetMaterial {
                index: i,
                material: m.clone(),
            });
        }
        if let Some(material) = super::super::phong::fields(ui, m) {
            edits.push(Edit::SetMaterial { index: i, material });
        }
    }
}
