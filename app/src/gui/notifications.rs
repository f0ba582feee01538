//! The document's notices as notifications over the view's corner: an overlay, so a new one
//! never moves a widget the user is about to click. Info fades after a while; warnings and
//! errors stay until dismissed. The question asked when the open file changes on disk under
//! unsaved edits is such an overlay too, at the view's top.

use std::time::Duration;

use crate::document::notice::{Level, Notices};

/// How long an info notice ("exported …", "reloaded") stays.
pub const INFO_FOR: Duration = Duration::from_secs(8);

pub fn colour(ui: &egui::Ui, level: Level) -> egui::Color32 {
    match level {
        Level::Info => ui.visuals().text_color(),
        Level::Warning => ui.visuals().warn_fg_color,
        Level::Error => ui.visuals().error_fg_color,
    }
}

fn word(level: Level) -> &'static str {
    match level {
        Level::Info => "Info",
        Level::Warning => "Warning",
        Level::Error => "Error",
    }
}

/// Draws the notices in the bottom right corner of `over` (the view), newest at the bottom.
pub fn ui(ctx: &egui::Context, notices: &mut Notices, over: egui::Rect) {
    notices.expire(Level::Info, INFO_FOR);
    if notices.is_empty() {
        return;
    }
    if notices.iter().any(|n| n.level == Level::Info) {
        ctx.request_repaint_after(Duration::from_millis(500));
    }
    let width = (over.width() * 0.6).clamp(160.0, 480.0);
    let mut dismiss = None;
    let mut clear = false;
    egui::Area::new(egui::Id::unique("tracelab-notifications"))
        .order(egui::Order::Foreground)
        .pivot(egui::Align2::RIGHT_BOTTOM)
        .fixed_pos(over.right_bottom() - egui::vec2(8.0, 8.0))
        .constrain_to(over)
        .show(ctx, |ui| {
            ui.set_max_width(width);
            ui.set_max_height(over.height() * 0.5);
            egui::Frame::popup(ui.style()).show(ui, |ui| {
                egui::ScrollArea::vertical()
                    .max_height(over.height() * 0.45)
                    .stick_to_bottom(true)
                    .show(ui, |ui| {
                        for (i, n) in notices.iter().enumerate() {
                            ui.horizontal(|ui| {
                                if ui.small_button("×").on_hover_text("Dismiss").clicked() {
                                    dismiss = Some(i);
                                }
                                let mut text = format!("{}: {}", word(n.level), n.text);
                                if n.count > 1 {
                                    text.push_str(&format!(" (×{})", n.count));
                                }
                                ui.add(
                                    egui::Label::new(
                                        egui::RichText::new(text).color(colour(ui, n.level)),
                                    )
                                    .wrap(),
                                );
                            });
                        }
                    });
                if notices.len() > 1 && ui.small_button("Dismiss all").clicked() {
                    clear = true;
                }
            });
        });
    if clear {
        notices.clear();
    } else if let Some(i) = dismiss {
        notices.dismiss(i);
    }
}

/// The answer to the file-changed question.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DiskAnswer {
    /// Read the file again, losing the edits.
    Reload,
    /// Keep the edits; the file on disk counts as seen.
    KeepMine,
}

/// "The file changed on disk, and you have unsaved edits", with its two answers, over the
/// top of `over` (the view): it covers the picture's top edge instead of pushing the whole
/// window down a row.
pub fn disk_changed(ctx: &egui::Context, over: egui::Rect) -> Option<DiskAnswer> {
    let mut answer = None;
    egui::Area::new(egui::Id::unique("tracelab-disk-changed"))
        .order(egui::Order::Foreground)
        .pivot(egui::Align2::CENTER_TOP)
        .fixed_pos(over.center_top() + egui::vec2(0.0, 8.0))
        .constrain_to(over)
        .show(ctx, |ui| {
            egui::Frame::popup(ui.style()).show(ui, |ui| {
                ui.horizontal(|ui| {
                    ui.colored_label(
                        colour(ui, Level::Warning),
                        "The file changed on disk, and you have unsaved edits.",
                    );
                    if ui.button("Reload (lose edits)").clicked() {
                        answer = Some(DiskAnswer::Reload);
                    }
                    if ui.button("Keep mine").clicked() {
                        answer = Some(DiskAnswer::KeepMine);
                    }
                });
            });
        });
    answer
}

/// A warning about what the view shows (a refused grid, supersampling past its caps), over
/// the bottom of `over` (the view) for as long as it holds, never a row that pushes the
/// layout. `what` keeps two warnings apart.
pub fn view_warning(ctx: &egui::Context, over: egui::Rect, what: &str, text: &str) {
    egui::Area::new(egui::Id::unique("tracelab-view-warning").with(what))
        .order(egui::Order::Foreground)
        .pivot(egui::Align2::CENTER_BOTTOM)
        .fixed_pos(over.center_bottom() - egui::vec2(0.0, 8.0))
        .constrain_to(over)
        .show(ctx, |ui| {
            egui::Frame::popup(ui.style()).show(ui, |ui| {
                ui.colored_label(colour(ui, Level::Warning), text);
            });
        });
}
