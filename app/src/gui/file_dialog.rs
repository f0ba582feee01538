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

impl Purpose {
    /// The extensions the listing shows (folders are always shown).
    pub fn extensions(self) -> &'static [&'static str] {
        match self {
            Purpose::Open | Purpose::SaveAs => &["txt"],
            Purpose::Export => &["png", "tga"],
        }
    }

    /// What the filter is called, e.g. "Scene files (*.txt)".
    pub fn filter_name(self) -> &'static str {
        match self {
            Purpose::Open | Purpose::SaveAs => "Scene files (*.txt)",
            Purpose::Export => "Images (*.png, *.tga)",
        }
    }
}

pub struct FileDialog {
    pub purpose: Purpose,
    dir: PathBuf,
    name: String,
    entries: Vec<(String, bool)>,
    error: Option<String>,
    /// List every file, not only those the filter names.
    all_files: bool,
    /// A folder was entered by the first click of what may be a double-click: its second
    /// click lands on the new folder's list and must not open the file now under it.
    entered: bool,
}

impl FileDialog {
    pub fn new(purpose: Purpose, start: Option<&Path>) -> Self {
        // Absolute, so a file opened as "scene.txt" shows its folder, not ".".
        let start = start.map(|p| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf()));
        let start = start.as_deref();
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
        let dir = std::path::absolute(&dir).unwrap_or(dir);
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
            all_files: false,
            entered: false,
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

    /// Whether the listing shows `name` (a file; folders always show).
    fn listed(&self, name: &str) -> bool {
        self.all_files
            || Path::new(name)
                .extension()
                .and_then(|e| e.to_str())
                .is_some_and(|e| {
                    self.purpose
                        .extensions()
                        .iter()
                        .any(|x| e.eq_ignore_ascii_case(x))
                })
    }

    /// The folder shown.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// What the dialog gives for the name typed: a folder is entered, not returned.
    fn choose(&mut self) -> Option<PathBuf> {
        if self.name.is_empty() {
            return None;
        }
        // A typed absolute path wins over the folder shown.
        let p = self.dir.join(&self.name);
        if p.is_dir() {
            self.dir = std::path::absolute(&p).unwrap_or(p);
            self.name.clear();
            self.refresh();
            return None;
        }
        Some(p)
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
                            if !is_dir && !self.listed(name) {
                                continue;
                            }
                            let label = if *is_dir {
                                format!("{name}/")
                            } else {
                                name.clone()
                            };
                            let r = ui.selectable_label(*name == self.name, label);
                            if r.double_clicked() && self.entered {
                                // The second click of the double-click that entered here.
                                self.entered = false;
                                continue;
                            }
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
                            if r.clicked() {
                                self.entered = *is_dir;
                            }
                        }
                        if let Some(d) = go {
                            self.dir = d;
                            self.refresh();
                        }
                    });
                let mut enter = false;
                ui.horizontal(|ui| {
                    ui.label("File name");
                    let r = ui.text_edit_singleline(&mut self.name);
                    // A single-line field gives up focus on Enter: that is the confirm key.
                    enter = r.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
                });
                ui.checkbox(&mut self.all_files, "All files")
                    .on_hover_text(format!(
                        "Off: {} and folders only",
                        self.purpose.filter_name()
                    ));
                ui.horizontal(|ui| {
                    let ok = match self.purpose {
                        Purpose::Open => "Open",
                        _ => "Save",
                    };
                    let clicked = ui
                        .add_enabled(!self.name.is_empty(), egui::Button::new(ok))
                        .clicked();
                    if (clicked || enter)
                        && let Some(p) = self.choose()
                    {
                        result = Some(Some(p));
                    }
                    if ui.button("Cancel").clicked() {
                        result = Some(None);
                    }
                });
            });
        result
    }
}
