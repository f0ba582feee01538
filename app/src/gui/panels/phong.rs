//! A material's fields beyond its diffuse colour (assignments 3–4): the course's Phong
//! fields, each with its value or the course default and a box saying whether the file
//! gives it, and any other field, listed as read. Edits are whole materials
//! (`Edit::SetMaterial`), so the rules, the refusal beside the field and undo work as for
//! the diffuse colour.

use glam::Vec3;
use tracelab_core::scene::{PHONG_FIELDS, Phong, PhongField, phong_field};
use tracelab_core::{Field, Material};

use super::fields::{color_values, name_widget, refusal_note};
use crate::gui::widgets::number;

/// The Phong fields of material `m`; returns the edited material when one changed.
pub(super) fn fields(ui: &mut egui::Ui, m: &Material) -> Option<Material> {
    let defaults = Phong::default();
    let mut edited = None;
    for f in PHONG_FIELDS {
        let given = m.field(f.name).filter(|v| v.len() == f.numbers);
        // A field with the wrong count (refused by the rules) shows as the default.
        let mut values = given.map_or_else(|| default_of(&defaults, f), <[f32]>::to_vec);
        let mut present = m.field(f.name).is_some();
        let mut changed = false;
        ui.horizontal(|ui| {
            let hint = format!(
                "Ticked: the file gives {}. Unticked: the course default, {}.",
                f.name,
                numbers(&default_of(&defaults, f))
            );
            changed |= ui
                .checkbox(&mut present, f.name)
                .on_hover_text(hint)
                .changed();
            if m.field(f.name).is_none() {
                ui.weak("(course default)");
            }
        });
        ui.horizontal(|ui| {
            ui.add_space(18.0);
            if changed_values(ui, f, &mut values) {
                // Editing a default's value writes the field.
                present = true;
                changed = true;
            }
        });
        refusal_note(ui, &Field::Material(f.name.to_string()));
        if changed {
            let mut next = edited.take().unwrap_or_else(|| m.clone());
            if present {
                next.set_field(f.name, values);
            } else {
                next.remove_field(f.name);
            }
            edited = Some(next);
        }
    }
    let unknown: Vec<&(String, Vec<f32>)> = m
        .extra
        .iter()
        .filter(|(n, _)| phong_field(n).is_none())
        .collect();
    if !unknown.is_empty() {
        ui.add(
            egui::Label::new(
                egui::RichText::new(
                    "Other fields, kept when saving; tracelab does not render them:",
                )
                .small(),
            )
            .wrap(),
        );
        for (name, v) in unknown {
            ui.add(egui::Label::new(format!("{name} {}", numbers(v))).wrap());
        }
    }
    edited
}

/// The value widgets of one field: a colour's swatch and numbers, or one number.
fn changed_values(ui: &mut egui::Ui, f: PhongField, values: &mut [f32]) -> bool {
    match values {
        [x, y, z] => {
            let mut c = Vec3::new(*x, *y, *z);
            let changed = color_values(ui, f.name, &mut c);
            [*x, *y, *z] = c.to_array();
            changed
        }
        [v] => {
            // No range: a refused value (a negative exponent) is shown refused with its reason.
            let speed = if f.name == "exponent" { 0.5 } else { 0.01 };
            let r = number(ui, v, |d| d.speed(speed).max_decimals(4));
            name_widget(&r, f.name.to_string(), f64::from(*v));
            r.changed()
        }
        _ => false,
    }
}

fn default_of(p: &Phong, f: PhongField) -> Vec<f32> {
    match f.name {
        "specularColor" => p.specular.to_array().to_vec(),
        "exponent" => vec![p.exponent],
        "reflectiveColor" => p.reflective.to_array().to_vec(),
        "transparentColor" => p.transparent.to_array().to_vec(),
        "indexOfRefraction" => vec![p.index_of_refraction],
        _ => vec![0.0; f.numbers],
    }
}

fn numbers(v: &[f32]) -> String {
    v.iter().map(f32::to_string).collect::<Vec<_>>().join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_phong_field_has_its_course_default() {
        let d = Phong::default();
        for f in PHONG_FIELDS {
            assert_eq!(default_of(&d, f).len(), f.numbers, "{}", f.name);
        }
        let idx = phong_field("indexOfRefraction").expect("a field");
        assert_eq!(default_of(&d, idx), vec![1.0]);
    }
}
