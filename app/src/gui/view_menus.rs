//! The View menu's settings submenus: Rays (assignments 3–4) and Supersampling (7). Each
//! takes the current setting and edits a copy; the caller turns a change into a command.

/// The course's `-shadows`, `-bounces` and `-weight`, and assignment 3's optional fix: off,
/// 0 and 0 as the course's `raytracer` starts. The coarse passes trace what the full pass
/// traces (the same bounces), so a preview never shows a different image.
pub fn rays(ui: &mut egui::Ui, s: &mut tracelab_core::render::Secondary) {
    ui.checkbox(&mut s.shadows, "Shadows (-shadows)");
    ui.add(egui::Slider::new(&mut s.bounces, 0..=10).text("bounces (-bounces)"));
    ui.add(
        egui::Slider::new(&mut s.weight, 0.0..=1.0)
            .text("weight cut-off (-weight)")
            .step_by(0.01),
    );
    ui.checkbox(&mut s.specular_fix, "Specular fix (optional, assignment 3)")
        .on_hover_text("The highlight fades with max(N·L, 0) instead of stopping where N·L ≤ 0");
}

/// View › Supersampling: samples a pixel, where they lie and the filter, as the course's
/// flags set them; the render refines toward it after its one-ray pass. The seed is the
/// command line's default, so the editor shows what `tracelab -input … -jittered_samples 9`
/// writes.
pub fn supersampling(
    ui: &mut egui::Ui,
    current: Option<tracelab_core::render::Supersampling>,
) -> Option<tracelab_core::render::Supersampling> {
    use tracelab_core::render::{DEFAULT_SEED, Filter, Sampler, SamplerKind, Supersampling};
    let (mut kind, mut count, mut filter) = current
        .map_or((SamplerKind::Jittered, 1, Filter::default()), |s| {
            (s.sampler.kind(), s.sampler.count(), s.filter)
        });
    ui.label("Samples a pixel");
    for n in [1u32, 4, 9, 16, 36] {
        let text = if n == 1 {
            "1 (one ray, at the pixel's centre)".to_string()
        } else {
            format!("{n}")
        };
        ui.radio_value(&mut count, n, text);
    }
    ui.separator();
    ui.label("Where they lie");
    for (k, text) in [
        (SamplerKind::Uniform, "Uniform grid (-uniform_samples)"),
        (SamplerKind::Random, "Random (-random_samples)"),
        (SamplerKind::Jittered, "Jittered (-jittered_samples)"),
    ] {
        ui.radio_value(&mut kind, k, text);
    }
    ui.separator();
    ui.label("Filter");
    let filters = [
        (Filter::default(), "Box 0.5: each pixel its own samples"),
        (Filter::Box { radius: 1.0 }, "Box 1 (-box_filter 1)"),
        (Filter::Tent { radius: 1.5 }, "Tent 1.5 (-tent_filter 1.5)"),
        (
            Filter::Gaussian { sigma: 0.5 },
            "Gaussian σ 0.5 (-gaussian_filter 0.5)",
        ),
    ];
    for (f, text) in filters {
        ui.radio_value(&mut filter, f, text);
    }
    if count == 1 && filter == Filter::default() {
        return None;
    }
    // One sample is the pixel's centre whatever the sampler (the handout's default); the menu
    // offers squares of 1 to 36 only, so every choice is a valid sampler.
    let sampler = if count == 1 {
        Sampler::default()
    } else {
        Sampler::new(kind, count, DEFAULT_SEED).ok()?
    };
    Some(Supersampling { sampler, filter })
}
