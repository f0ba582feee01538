//! The strip that shows a scene being read in the background: what it is doing, a progress
//! bar, and Cancel.

use crate::gui::loading::Loading;

/// Draws the strip; true when Cancel was clicked.
pub fn ui(ui: &mut egui::Ui, loading: &Loading) -> bool {
    // Cancel and the bar first, the changing text last: a button after the text would
    // move as the text changes, and a click aimed at it could land beside it.
    ui.horizontal(|ui| {
        ui.add(egui::Spinner::new());
        let cancel = ui
            .button("Cancel")
            .on_hover_text("Stop reading; the open scene stays")
            .clicked();
        ui.add(
            egui::ProgressBar::new(loading.fraction())
                .desired_width(160.0)
                .animate(true),
        );
        ui.label(loading.describe());
        cancel
    })
    .inner
}
