//! File › Export animation: the form (which op of the selected Transform, which number,
//! from, to, frames; or the bounce count from A to B with the view's rays; compare, folder)
//! and the export running on its own thread with a progress bar and Cancel. The form only
//! asks: starting and cancelling are `AppCommand`s.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::mpsc::{Receiver, channel};

use tracelab_core::render::MAX_BOUNCES;
use tracelab_core::{NodeKind, RenderSettings, Scene};

pub use crate::animation::AnimationForm;
use crate::animation::{AnimateError, Destination, components, export};
use crate::gui::command::AppCommand;

/// An export under way.
pub struct Running {
    pub done: Arc<AtomicU32>,
    pub total: u32,
    pub cancel: Arc<AtomicBool>,
    result: Receiver<Result<String, String>>,
}

impl Running {
    /// Renders and writes on a thread of its own; `inputs` (the open file) are never written.
    pub fn start(
        scene: Arc<Scene>,
        form: &AnimationForm,
        settings: RenderSettings,
        inputs: Vec<PathBuf>,
    ) -> Running {
        let (tx, rx) = channel();
        let done = Arc::new(AtomicU32::new(0));
        let cancel = Arc::new(AtomicBool::new(false));
        let (d, c, compare) = (done.clone(), cancel.clone(), form.compare);
        let sweep = form.animated();
        let total = sweep.frames();
        let to = Destination {
            dir: PathBuf::from(&form.folder),
            stem: "frame".into(),
            delay_ms: 100,
            inputs,
        };
        std::thread::spawn(move || {
            let progress = |k| d.store(k, Ordering::Relaxed);
            let out = match export(&scene, &sweep, &settings, compare, &to, &c, progress) {
                Ok(files) => Ok(format!(
                    "exported {} frames to {} ({})",
                    files.len().saturating_sub(1),
                    to.dir.display(),
                    files
                        .last()
                        .map_or(String::new(), |f| f.display().to_string())
                )),
                Err(AnimateError::Cancelled { written }) => Err(format!(
                    "animation export cancelled: {written} frame files written to {}, no \
                     animated PNG",
                    to.dir.display()
                )),
                Err(
                    AnimateError::Refused(m)
                    | AnimateError::Output(m)
                    | AnimateError::OutOfMemory(m),
                ) => Err(format!("animation not exported: {m}")),
            };
            let _ = tx.send(out);
        });
        Running {
            done,
            total,
            cancel,
            result: rx,
        }
    }

    /// The message once finished.
    pub fn poll(&self) -> Option<Result<String, String>> {
        self.result.try_recv().ok()
    }
}

/// The form as a window; returns the command its buttons ask for.
pub fn ui(
    ctx: &egui::Context,
    form: &mut AnimationForm,
    scene: &Scene,
    running: Option<&Running>,
) -> Option<AppCommand> {
    let mut asked = None;
    let ops = match form
        .node
        .and_then(|id| scene.graph.get(id))
        .map(|n| &n.kind)
    {
        Some(NodeKind::Transform(ops)) => ops.clone(),
        _ => Vec::new(),
    };
    egui::Window::new("Export animation").collapsible(false).resizable(false).show(ctx, |ui| {
        if ops.is_empty() {
            // Nothing to sweep but the bounce count.
            form.bounce_sweep = true;
        } else {
            ui.horizontal(|ui| {
                ui.radio_value(&mut form.bounce_sweep, false, "an op of the Transform");
                ui.radio_value(&mut form.bounce_sweep, true, "the bounce count");
            });
        }
        if form.bounce_sweep {
            let b = &mut form.bounces;
            ui.horizontal(|ui| {
                ui.add(egui::DragValue::new(&mut b.from).range(0..=MAX_BOUNCES).prefix("bounces from "));
                ui.add(egui::DragValue::new(&mut b.to).range(0..=MAX_BOUNCES).prefix("to "));
            });
            b.to = b.to.max(b.from);
            ui.small("A frame per bounce count, with View › Rays' shadows and weight.");
        } else {
            op_fields(ui, form, &ops);
        }
        ui.checkbox(&mut form.compare, "compare view: (M^-1)^T left, M right");
        ui.horizontal(|ui| {
            ui.label("folder");
            ui.text_edit_singleline(&mut form.folder);
        });
        ui.small("Writes frame_0000.png … and frame.apng.png (an animated PNG) at the view's render size.");
        match running {
            Some(r) => {
                let done = r.done.load(Ordering::Relaxed);
                ui.add(egui::ProgressBar::new(done as f32 / r.total.max(1) as f32).text(format!("{done} of {} frames", r.total)));
                if ui.button("Cancel").clicked() {
                    asked = Some(AppCommand::CancelAnimation);
                }
            }
            None => {
                ui.horizontal(|ui| {
                    if ui.button("Export").clicked() {
                        asked = Some(AppCommand::StartAnimation(form.clone()));
                    }
                    if ui.button("Close").clicked() {
                        asked = Some(AppCommand::CloseAnimationDialog);
                    }
                });
            }
        }
    });
    asked
}

/// The op sweep's fields: which op and number, from, to, frames.
fn op_fields(ui: &mut egui::Ui, form: &mut AnimationForm, ops: &[tracelab_core::TransformOp]) {
    form.op = form.op.min(ops.len().saturating_sub(1));
    let Some(op) = ops.get(form.op) else {
        return;
    };
    egui::ComboBox::from_label("op")
        .selected_text(format!("{}: {}", form.op, op.summary()))
        .show_ui(ui, |ui| {
            for (i, op) in ops.iter().enumerate() {
                ui.selectable_value(&mut form.op, i, format!("{i}: {}", op.summary()));
            }
        });
    let names = components(op);
    form.component = form.component.min(names.len().saturating_sub(1));
    egui::ComboBox::from_label("number")
        .selected_text(names.get(form.component).cloned().unwrap_or_default())
        .show_ui(ui, |ui| {
            for (i, n) in names.iter().enumerate() {
                ui.selectable_value(&mut form.component, i, n);
            }
        });
    ui.horizontal(|ui| {
        ui.add(
            egui::DragValue::new(&mut form.from)
                .speed(0.05)
                .prefix("from "),
        );
        ui.add(egui::DragValue::new(&mut form.to).speed(0.05).prefix("to "));
        ui.add(
            egui::DragValue::new(&mut form.frames)
                .range(1..=1000)
                .prefix("frames "),
        );
    });
}
