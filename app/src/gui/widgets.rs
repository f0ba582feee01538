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
