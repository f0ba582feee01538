//! The status bar: render progress, last full-frame time, scene statistics (objects,
//! triangles, nodes), messages.

use crate::document::Document;
use crate::render_worker::RenderWorker;

pub fn ui(
    ui: &mut egui::Ui,
    doc: &Document,
    worker: &RenderWorker,
    stats: (usize, usize, usize),
    timings: bool,
    note: Option<&str>,
) {
    ui.horizontal(|ui| {
        worker.with_published(|p| match p {
            None => {
                ui.label("starting renderer…");
            }
            Some(p) => {
                let (w, h) = (p.job.settings.width, p.job.settings.height);
                let progress = p.frames.iter().map(|f| f.progress()).fold(1.0f32, f32::min);
                match p.full {
                    Some(_) if !timings => ui.label(format!("{w}×{h} · done")),
                    Some(t) => ui.label(format!(
                        "{w}×{h} · done · full frame {:.0} ms",
                        t.as_secs_f64() * 1e3
                    )),
                    None => ui.label(format!(
                        "{w}×{h} · pass {}/{} · {:.0}%",
                        (p.passes_done + 1).min(p.passes.max(1)),
                        p.passes.max(1),
                        progress * 100.0
                    )),
                };
                if let Some(t) = p.first_image.filter(|_| timings) {
                    ui.label(format!("· first image {:.0} ms", t.as_secs_f64() * 1e3));
                }
            }
        });
        ui.separator();
        ui.label(format!(
            "{} objects · {} triangles · {} nodes",
            stats.0, stats.1, stats.2
        ));
        if let Some(worst) = doc.messages.worst() {
            ui.separator();
            let colour = crate::gui::notifications::colour(ui, worst);
            ui.colored_label(colour, format!("{} message(s)", doc.messages.len()));
        }
        ui.separator();
        ui.label(format!("generation {}", doc.generation));
        if let Some(n) = note {
            ui.separator();
            ui.label(n);
        }
    });
}
