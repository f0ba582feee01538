//! A small in-app file dialog: a folder listing and a path field. Native dialogs need a
//! desktop portal or GTK, which a bare X server (and CI) lacks; this one works everywhere
//! and can be driven by tests.

use std::path::{Path, PathBuf};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Purpose {
    Open,
    SaveAs,
    Export,
}

pub struct FileDialog {
    pub purpose: Purpose,
    dir: PathBuf,
    name: String,
    entries: Vec<(String, bool)>,
    error: Option<String>,
}

impl FileDialog {
    pub fn new(purpose: Purpose, start: Option<&Path>) -> Self {
        let (dir, name) = match start {
            Some(p) if p.is_dir() => (p.to_path_buf(), String::new()),
            Some(p) => (
                p.parent()
                    .filter(|d| !d.as_os_str().is_empty())
                    .map_or_else(|| PathBuf::from("."), Path::to_path_buf),
                p.file_name()
                    .map(|n| n.to_string_lossy().to_string())
                    .unwrap_or_default(),
            ),
            None => (
                std::env::current_dir().unwrap_or_else(|_| PathBuf::from(".")),
                String::new(),
            ),
        };
        let name = match purpose {
            Purpose::Export => Path::new(&name)
                .with_extension("png")
                .to_string_lossy()
                .to_string(),
            _ => name,
        };
        let mut d = FileDialog {
            purpose,
            dir,
            name,
            entries: Vec::new(),
            error: None,
        };
        d.refresh();
        d
    }

    fn refresh(&mut self) {
        self.entries.clear();
        match std::fs::read_dir(&self.dir) {
            Ok(rd) => {
                for e in rd.flatten() {
                    let name = e.file_name().to_string_lossy().to_string();
                    if name.starts_with('.') {
                        continue;
                    }
                    self.entries
                        .push((name, e.file_type().is_ok_and(|t| t.is_dir())));
                }
                self.entries
                    .sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
                self.error = None;
            }
            Err(e) => self.error = Some(format!("{}: {e}", self.dir.display())),
        }
    }

    /// Shows the dialog; returns `Some(Some(path))` when chosen, `Some(None)` when cancelled.
    pub fn ui(&mut self, ctx: &egui::Context) -> Option<Option<PathBuf>> {
        let title = match self.purpose {
            Purpose::Open => "Open scene",
            Purpose::SaveAs => "Save scene as",
            Purpose::Export => "Export view (.png or .tga)",
        };
        let mut result = None;
        egui::Window::new(title)
            .collapsible(false)
            .default_size([480.0, 400.0])
            .show(ctx, |ui| {
                ui.horizontal(|ui| {
                    if ui.button("Up a folder").clicked()
                        && let Some(p) = self.dir.parent()
                    {
                        self.dir = p.to_path_buf();
                        self.refresh();
                    }
                    ui.label(self.dir.display().to_string());
                });
                if let Some(e) = &self.error {
                    ui.colored_label(ui.visuals().error_fg_color, e);
                }
                egui::ScrollArea::vertical()
                    .max_height(260.0)
                    .show(ui, |ui| {
                        let mut go = None;
                        for (name, is_dir) in &self.entries {
                            let label = if *is_dir {
                                format!("{name}/")
                            } else {
                                name.clone()
                            };
                            let r = ui.selectable_label(*name == self.name, label);
                            if r.clicked() {
                                if *is_dir {
                                    go = Some(self.dir.join(name));
                                } else {
                                    self.name = name.clone();
                                }
                            }
                            if r.double_clicked() && !is_dir {
                                result = Some(Some(self.dir.join(name)));
                            }
                        }
                        if let Some(d) = go {
                            self.dir = d;
                            self.refresh();
                        }
                    });
                ui.horizontal(|ui| {
                    ui.label("File name");
                    ui.text_edit_singleline(&mut self.name);
                });
                ui.horizontal(|ui| {
                    let ok = match self.purpose {
                        Purpose::Open => "Open",
                        _ => "Save",
                    };
                    if ui
                        .add_enabled(!self.name.is_empty(), egui::Button::new(ok))
                        .clicked()
                    {
                        // A typed absolute path wins over the folder shown.
                        result = Some(Some(self.dir.join(&self.name)));
                    }
                    if ui.button("Cancel").clicked() {
                        result = Some(None);
                    }
                });
            });
        result
    }
}
