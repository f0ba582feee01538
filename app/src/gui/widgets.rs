//! Small widgets the panels share.

/// A linear [0, 1] colour as the renderer writes it (quantised, no gamma), for swatches.
pub fn color32(c: glam::Vec3) -> egui::Color32 {
    let q = |x: f32| (x * 255.0).clamp(0.0, 255.0) as u8;
    egui::Color32::from_rgb(q(c.x), q(c.y), q(c.z))
}

/// egui's default fonts have no superscripts: M⁻¹ is drawn as M^-1, (M⁻¹)ᵀ as (M^-1)^T.
pub fn ascii_math(s: &str) -> String {
    s.replace("⁻¹", "^-1").replace('ᵀ', "^T")
}

/// A number field whose typed text is applied on Enter or when the field loses focus: one
/// edit (one undo step) per typed value, none for half-typed ones, and Esc leaves the value
/// as it was before the field got the keyboard. Dragging still applies as it goes. `style`
/// sets speed, range, decimals.
pub fn number<Num: egui::emath::Numeric>(
    ui: &mut egui::Ui,
    value: &mut Num,
    style: impl FnOnce(egui::DragValue<'_>) -> egui::DragValue<'_>,
) -> egui::Response {
    let before = *value;
    let mut r = ui.add(style(
        egui::DragValue::new(value).update_while_editing(false),
    ));
    // egui 0.37 counts a field as having lost focus for two frames and skips the text only
    // in the first (the one with the Esc key), so it applies the abandoned text one frame
    // later. Remember the Esc and undo that.
    let escaped = r.id.with("tracelab-escaped");
    let now = ui.ctx().cumulative_pass_nr();
    if ui.input(|i| i.key_pressed(egui::Key::Escape)) && r.lost_focus() {
        ui.data_mut(|d| d.insert_temp(escaped, now));
    } else if let Some(at) = ui.data_mut(|d| d.remove_temp::<u64>(escaped))
        && now <= at + 2
        && r.changed()
    {
        *value = before;
        r.flags.remove(egui::response::Flags::CHANGED);
    }
    r
}

/// The renderer writes a colour's numbers straight into the image's bytes, which the screen
/// shows as sRGB; egui's colour button takes linear values. These two map between them so
/// the swatch shows the colour as the render does (0.2 is drawn as 51, not 124).
pub fn swatch_from_render(c: [f32; 3]) -> [f32; 3] {
    c.map(egui::ecolor::linear_from_gamma)
}

pub fn render_from_swatch(c: [f32; 3]) -> [f32; 3] {
    c.map(egui::ecolor::gamma_from_linear)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_swatch_shows_a_colour_as_the_render_writes_it() {
        let c = [0.2, 0.45, 0.9];
        let [r, g, b] = swatch_from_render(c);
        let shown = egui::Color32::from(egui::Rgba::from_rgb(r, g, b));
        // The render's bytes for the same colour (`color32`), within rounding.
        let render = color32(glam::Vec3::from_array(c));
        for (s, w) in shown.to_array().iter().zip(render.to_array()) {
            assert!(s.abs_diff(w) <= 1, "{shown:?} vs {render:?}");
        }
        // Linear, as before the fix, the swatch was lighter: 0.2 shown as 124.
        let linear = egui::Color32::from(egui::Rgba::from_rgb(0.2, 0.45, 0.9));
        assert!(linear.r() > 100, "{linear:?}");
        let back = render_from_swatch(swatch_from_render(c));
        for (a, b) in back.iter().zip(c) {
            assert!((a - b).abs() < 1e-5);
        }
    }
}
