//! The strip that shows a scene being read in the background: what it is doing, a progress
//! bar, and Cancel.

use crate::loading::Loading;

/// Draws the strip; true when Cancel was clicked.
pub fn ui(ui: &mut egui::Ui, loading: &Loading) -> bool {
    ui.horizontal(|ui| {
        ui.add(egui::Spinner::new());
        ui.label(loading.describe());
        ui.add(egui::ProgressBar::new(loading.fraction()).desired_width(160.0).animate(true));
        ui.button("Cancel").on_hover_text("Stop reading; the open scene stays").clicked()
    })
    .inner
}
