//! The view bar, under the menu and as wide as the window: two rows of labelled groups, each
//! label before its control. Row one, what the view shows: the view tabs with the depth
//! range beside them, the display toggles and the render size. Row two, the lecture's
//! rules: the normal transform with the largest angle between its two rules, the compare
//! mode and the depth-t rule. Narrower windows wrap a row's groups onto more rows.

use tracelab_core::render::{MAX_IMAGE_SIDE, NormalGap, check_image_size};
use tracelab_core::{NormalTransform, ObjectRays};

use crate::gui::gizmo::Axes;
use crate::gui::panels::view_settings::{Compare, SplitLine, Tab, ViewSettings, object_rays_label};
use crate::gui::widgets::number;

/// The bar. `gap` is the largest angle between the two normal rules over the pixels of the
/// image on screen, once computed.
pub fn ui(ui: &mut egui::Ui, s: &mut ViewSettings, gap: Option<NormalGap>) {
    ui.horizontal_wrapped(|ui| {
        view(ui, s);
        ui.separator();
        display(ui, s);
        ui.separator();
        size(ui, s);
    });
    ui.horizontal_wrapped(|ui| {
        normal_rule(ui, s, gap);
        ui.separator();
        compare(ui, s);
        ui.separator();
        depth_t(ui, s);
    });
}

/// One group: its controls kept on one row.
fn group<R>(ui: &mut egui::Ui, add: impl FnOnce(&mut egui::Ui) -> R) -> R {
    ui.horizontal(add).inner
}

fn view(ui: &mut egui::Ui, s: &mut ViewSettings) {
    group(ui, |ui| {
        ui.label("View:");
        for (tab, name) in [
            (Tab::Color, "Colour"),
            (Tab::Normals, "Normals"),
            (Tab::Depth, "Depth"),
            (Tab::All, "All three"),
        ] {
            ui.selectable_value(&mut s.tab, tab, name);
        }
    });
    group(ui, |ui| {
        ui.label("depth range")
            .on_hover_text("The Depth view's distances drawn white (near) and black (far)");
        number(ui, &mut s.depth.0, |d| d.speed(0.05)).accessible_name("depth min");
        ui.label("to");
        number(ui, &mut s.depth.1, |d| d.speed(0.05)).accessible_name("max");
    });
}

fn display(ui: &mut egui::Ui, s: &mut ViewSettings) {
    group(ui, |ui| {
        ui.checkbox(&mut s.shade_back, "shade back")
            .on_hover_text("Shade the back faces too (the course's -shade_back)");
        ui.checkbox(&mut s.overlays, "gizmo & overlays");
        ui.add_enabled_ui(s.overlays, |ui| {
            ui.selectable_value(&mut s.gizmo_axes, Axes::World, "world axes")
                .on_hover_text("The gizmo's arrows move along the world's x, y and z");
            ui.selectable_value(&mut s.gizmo_axes, Axes::Local, "local axes")
                .on_hover_text("The gizmo's arrows move along the Translate's own axes (its Transform's space)");
        });
    });
}

fn size(ui: &mut egui::Ui, s: &mut ViewSettings) {
    group(ui, |ui| {
        let mut fixed = s.fixed_size.is_some();
        if ui.checkbox(&mut fixed, "fixed size").changed() {
            s.fixed_size = fixed.then_some((200, 200));
        }
        let error_id = ui.make_persistent_id("fixed-size-refused");
        if let Some(size) = &mut s.fixed_size {
            let before = *size;
            // Whole numbers only: "nan" once parsed, was clamped and became 4096.
            let parse = |t: &str| t.trim().parse::<f64>().ok().filter(|v| v.is_finite());
            let side = 1..=MAX_IMAGE_SIDE;
            number(ui, &mut size.0, |d| {
                d.range(side.clone()).custom_parser(parse).suffix(" w")
            });
            number(ui, &mut size.1, |d| {
                d.range(side).custom_parser(parse).suffix(" h")
            });
            if *size != before {
                // The same limits as the command line: refuse, keep the last good size, say why.
                let refused = check_image_size(size.0, size.1)
                    .err()
                    .map(|e| e.to_string());
                if refused.is_some() {
                    *size = before;
                }
                ui.data_mut(|d| d.insert_temp(error_id, refused));
            }
            if let Some(e) = ui
                .data(|d| d.get_temp::<Option<String>>(error_id))
                .flatten()
            {
                ui.colored_label(ui.visuals().error_fg_color, e);
            }
        }
    });
}

fn normal_rule(ui: &mut egui::Ui, s: &mut ViewSettings, gap: Option<NormalGap>) {
    group(ui, |ui| {
        ui.label("Normal transform:");
        // Compare mode shows both rules, so the switch has nothing to choose there.
        ui.add_enabled_ui(s.compare == Compare::Off, |ui| {
            ui.selectable_value(
                &mut s.normal_transform,
                NormalTransform::Correct,
                "Correct (M^-1)^T",
            );
            ui.selectable_value(
                &mut s.normal_transform,
                NormalTransform::Incorrect,
                "Incorrect M",
            );
        });
        let gap_text = match gap {
            Some(g) if g.degrees == 0.0 => "0° apart: all similitudes".to_string(),
            Some(g) => format!("up to {:.2}° apart", g.degrees),
            None => "…".to_string(),
        };
        ui.add(egui::Label::new(gap_text).extend())
            .on_hover_text("The largest angle between (M^-1)^T·n and M·n over the visible pixels (0 exactly when every transform on screen is a similitude)");
    });
}

fn compare(ui: &mut egui::Ui, s: &mut ViewSettings) {
    group(ui, |ui| {
        ui.label("Compare:");
        egui::ComboBox::from_id_salt("compare")
            .selected_text(match s.compare {
                Compare::Off => "off",
                Compare::SideBySide => "side by side",
                Compare::Split => "split",
            })
            .show_ui(ui, |ui| {
                ui.selectable_value(&mut s.compare, Compare::Off, "off");
                ui.selectable_value(&mut s.compare, Compare::SideBySide, "side by side");
                ui.selectable_value(&mut s.compare, Compare::Split, "split");
            })
            .response
            .accessible_name("compare");
        if s.compare == Compare::Split {
            ui.selectable_value(&mut s.split_line, SplitLine::Vertical, "left | right")
                .on_hover_text("Correct left of the line, incorrect right of it");
            ui.selectable_value(&mut s.split_line, SplitLine::Horizontal, "above / below")
                .on_hover_text("Correct above the line, incorrect below it: objects side by side are each seen under both rules");
        }
    });
}

fn depth_t(ui: &mut egui::Ui, s: &mut ViewSettings) {
    group(ui, |ui| {
        // The lecture's "what to do about the depth t", for both images when comparing.
        ui.label("Depth t:");
        egui::ComboBox::from_id_salt("depth t")
            .selected_text(object_rays_label(s.object_rays))
            .show_ui(ui, |ui| {
                for r in ObjectRays::ALL {
                    ui.selectable_value(&mut s.object_rays, r, object_rays_label(r));
                }
            })
            .response
            .accessible_name("depth t");
    });
}
