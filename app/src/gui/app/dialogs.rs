//! The file dialogs and the questions (unsaved changes, saving loses something), and what
//! their answers carry out.

use super::*;

impl TracelabApp {
    /// Opens a file dialog: the desktop's where there is one, else the built-in one.
    pub fn show_file_dialog(&mut self, purpose: Purpose) {
        let start = self.doc.path.clone();
        if self.native_dialogs
            && self.native.is_none()
            && let Some(d) = NativeDialog::start(purpose, start.as_deref(), self.repaint.clone())
        {
            self.native = Some(d);
            return;
        }
        self.dialog = Some(FileDialog::new(purpose, start.as_deref()));
    }

    /// What to do with a path a file dialog gave.
    pub(super) fn chosen(&mut self, purpose: Purpose, path: &Path) {
        self.queue(match purpose {
            Purpose::Open => AppCommand::Open(path.to_path_buf()),
            Purpose::SaveAs => AppCommand::SaveAs(path.to_path_buf()),
            Purpose::Export => AppCommand::Export(path.to_path_buf()),
        });
    }

    /// Carries out an action the user agreed to.
    pub(super) fn carry_out(&mut self, pending: Pending, ctx: &egui::Context) {
        match pending {
            Pending::Close => {
                self.allow_close = true;
                ctx.send_viewport_cmd(egui::ViewportCommand::Close);
            }
            Pending::Open(_) => {
                if let Some(read) = self.ready.take() {
                    self.install(read, false);
                }
            }
            Pending::New => self.new_now(),
            Pending::Save { path, then, .. } => {
                if self.write(&path)
                    && let Some(then) = then
                {
                    self.carry_out(*then, ctx);
                }
            }
        }
    }

    pub(super) fn dialogs(&mut self, ctx: &egui::Context) {
        if let Some(msg) = self
            .animation_running
            .as_ref()
            .and_then(animation_dialog::Running::poll)
        {
            self.animation_running = None;
            match msg {
                Ok(m) => self.doc.messages.info(m),
                Err(e) => self.doc.messages.error(e),
            }
        }
        if let Some(form) = &mut self.animation
            && let Some(c) =
                animation_dialog::ui(ctx, form, &self.doc.scene, self.animation_running.as_ref())
        {
            self.queue(c);
        }
        if self.animation_running.is_some() {
            ctx.request_repaint_after(Duration::from_millis(100));
        }
        if let Some(answer) = self.native.as_ref().and_then(NativeDialog::poll)
            && let Some(d) = self.native.take()
        {
            match answer {
                Answer::Chosen(p) => self.chosen(d.purpose, &p),
                Answer::Cancelled => {}
                Answer::Unavailable => {
                    // This desktop has none after all: the built-in one, from now on.
                    self.native_dialogs = false;
                    self.show_file_dialog(d.purpose);
                }
            }
        }
        if let Some(d) = &mut self.dialog {
            let purpose = d.purpose;
            if let Some(result) = d.ui(ctx) {
                self.dialog = None;
                if let Some(path) = result {
                    self.chosen(purpose, &path);
                }
            }
        }
        match self.confirm.clone() {
            Some(Pending::Save {
                path,
                warnings,
                then,
            }) => {
                let mut choice = None;
                egui::Modal::new(egui::Id::unique("save-loses")).show(ctx, |ui| {
                    ui.heading("Saving loses something");
                    ui.label(format!("Saving {} cannot keep:", path.display()));
                    for w in warnings.iter().take(8) {
                        ui.label(w);
                    }
                    if warnings.len() > 8 {
                        ui.label(format!("… and {} more", warnings.len() - 8));
                    }
                    ui.horizontal(|ui| {
                        if ui.button("Save anyway").clicked() {
                            choice = Some(true);
                        }
                        if ui.button("Cancel").clicked() {
                            choice = Some(false);
                        }
                    });
                });
                if let Some(yes) = choice {
                    self.confirm = None;
                    if yes {
                        self.carry_out(
                            Pending::Save {
                                path,
                                warnings,
                                then,
                            },
                            ctx,
                        );
                    } else if then.is_some() {
                        // Not saved: whatever was to follow waits for another answer.
                        self.ready = None;
                    }
                }
            }
            Some(pending) => {
                let mut choice = None;
                egui::Modal::new(egui::Id::unique("unsaved-changes")).show(ctx, |ui| {
                    ui.heading("Unsaved changes");
                    ui.label(format!(
                        "{} has changes that are not saved.",
                        self.doc.title_name()
                    ));
                    ui.horizontal(|ui| {
                        if ui.button("Save").clicked() {
                            choice = Some(0);
                        }
                        if ui.button("Discard changes").clicked() {
                            choice = Some(1);
                        }
                        if ui.button("Cancel").clicked() {
                            choice = Some(2);
                        }
                    });
                });
                match choice {
                    Some(0) => {
                        self.confirm = None;
                        match self.doc.path.clone() {
                            Some(p) => {
                                if self.save_to(&p, Some(pending.clone())) {
                                    self.carry_out(pending, ctx);
                                }
                            }
                            // Never saved: Save As first; the user repeats the action after.
                            None => {
                                self.ready = None;
                                self.show_file_dialog(Purpose::SaveAs);
                            }
                        }
                    }
                    Some(1) => {
                        self.confirm = None;
                        self.carry_out(pending, ctx);
                    }
                    Some(_) => {
                        self.confirm = None;
                        self.ready = None;
                        self.pending_lecture = None;
                    }
                    None => {}
                }
            }
            None => {}
        }
        if !self.pixel_inspector_open {
            self.viewport.marker = None;
        }
    }

    /// The dialog waiting for an answer, if any: the scene's shortcuts and menus wait for it.
    pub fn dialog_up(&self) -> Option<menu::Dialog> {
        if self.confirm.is_some() {
            Some(menu::Dialog::Confirm)
        } else if self.dialog.is_some() || self.native.is_some() {
            Some(menu::Dialog::File)
        } else {
            None
        }
    }
}
