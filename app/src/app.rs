//! The eframe app: wires the document, the panels and the render worker together. Panels
//! return edits; `apply` here is the only place they reach the document.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use tracelab_core::render::{RayStory, inspect_pixel};
use tracelab_core::{RenderSettings, Scene};

use crate::edit::Edit;
use crate::render_worker::RenderWorker;
use crate::state::{Document, Selection};
use crate::ui::file_dialog::{FileDialog, Purpose};
use crate::ui::tree::TreeRow;
use crate::ui::viewport::{Compare, Tab, ViewSettings, Viewport};
use crate::ui::{inspector, pixel_inspector, status, tree};

#[derive(Clone, Debug, Default)]
pub struct AppOptions {
    /// Scene file to open (`None`: the built-in scene).
    pub scene: Option<PathBuf>,
    /// Render at this size instead of following the view (tests use small fixed sizes).
    pub fixed_size: Option<(u32, u32)>,
}

/// An action waiting for the user to decide about unsaved changes.
#[derive(Clone, Debug, PartialEq)]
pub enum Pending {
    Close,
    Open(PathBuf),
}

const MAX_RECENT: usize = 10;

pub struct TracelabApp {
    pub doc: Document,
    pub worker: RenderWorker,
    pub view: ViewSettings,
    viewport: Viewport,
    /// The last pixel inspected and the scene snapshot it was traced in.
    pub story: Option<(RayStory, Arc<Scene>)>,
    pub pixel_inspector_open: bool,
    pub dialog: Option<FileDialog>,
    pub confirm: Option<Pending>,
    pub recent: Vec<PathBuf>,
    rows: (u64, Vec<TreeRow>, (usize, usize, usize)),
    last_disk_check: Instant,
    /// The file changed on disk while there were unsaved edits: ask before reloading.
    pub disk_changed: bool,
    title: String,
    allow_close: bool,
    /// The selection the tree last showed, to scroll to selections made elsewhere.
    tree_seen: Option<Selection>,
    /// Timings in the status bar; snapshot tests turn them off to stay deterministic.
    pub show_timings: bool,
}

impl TracelabApp {
    /// The app outside eframe (tests); `cc` gives persistence and a repaint hook when present.
    pub fn new(cc: Option<&eframe::CreationContext<'_>>, opts: AppOptions) -> Self {
        let mut app = TracelabApp {
            doc: Document::builtin(),
            worker: RenderWorker::new(),
            view: ViewSettings::default(),
            viewport: Viewport::default(),
            story: None,
            pixel_inspector_open: false,
            dialog: None,
            confirm: None,
            recent: Vec::new(),
            rows: (0, Vec::new(), (0, 0, 0)),
            last_disk_check: Instant::now(),
            disk_changed: false,
            title: String::new(),
            allow_close: false,
            show_timings: true,
            tree_seen: None,
        };
        if let Some(cc) = cc {
            let ctx = cc.egui_ctx.clone();
            app.worker.set_repaint(move || ctx.request_repaint());
            if let Some(s) = cc.storage {
                app.load_persisted(s);
            }
        }
        if opts.fixed_size.is_some() {
            app.view.fixed_size = opts.fixed_size;
        }
        if let Some(p) = opts.scene {
            app.open_now(&p);
        }
        app
    }

    pub fn load_persisted(&mut self, s: &dyn eframe::Storage) {
        if let Some(r) = s.get_string("recent") {
            self.recent = r
                .lines()
                .filter(|l| !l.is_empty())
                .map(PathBuf::from)
                .collect();
        }
        if let Some(v) = s.get_string("view") {
            let mut it = v.split(' ');
            let mut next = || it.next().unwrap_or("");
            self.view.tab = match next() {
                "normals" => Tab::Normals,
                "depth" => Tab::Depth,
                "all" => Tab::All,
                _ => Tab::Color,
            };
            self.view.shade_back = next() == "1";
            if let (Ok(a), Ok(b)) = (next().parse(), next().parse()) {
                self.view.depth = (a, b);
            }
        }
    }

    /// Applies an edit through the document (the one place that records undo).
    pub fn apply(&mut self, edit: Edit) {
        if let Err(e) = self.doc.apply(edit) {
            self.doc.messages.push(format!("edit refused: {e}"));
        }
    }

    /// Opens a file, asking first when there are unsaved changes.
    pub fn open(&mut self, path: &Path) {
        if self.doc.is_dirty() {
            self.confirm = Some(Pending::Open(path.to_path_buf()));
        } else {
            self.open_now(path);
        }
    }

    /// Opens a file now; on failure the current scene stays and the errors are shown.
    pub fn open_now(&mut self, path: &Path) -> bool {
        let ok = self.doc.open(path).is_ok();
        if ok {
            self.story = None;
            self.viewport.marker = None;
            self.disk_changed = false;
            self.recent.retain(|r| r != path);
            self.recent.insert(0, path.to_path_buf());
            self.recent.truncate(MAX_RECENT);
        }
        ok
    }

    /// Re-reads the file from disk, keeping the selection when it still exists.
    pub fn reload(&mut self) {
        let Some(p) = self.doc.path.clone() else {
            return;
        };
        let sel = self.doc.selection;
        if self.open_now(&p) {
            self.doc.selection = sel;
            self.doc
                .messages
                .insert(0, format!("{}: reloaded (changed on disk)", p.display()));
        }
    }

    pub fn save(&mut self) {
        if self.doc.path.is_none() {
            self.dialog = Some(FileDialog::new(Purpose::SaveAs, None));
            return;
        }
        if let Err(e) = self.doc.save() {
            self.doc.messages.push(e);
        }
    }

    pub fn save_as(&mut self, path: &Path) {
        match self.doc.save_as(path) {
            Ok(()) => {
                self.recent.retain(|r| r != path);
                self.recent.insert(0, path.to_path_buf());
            }
            Err(e) => self.doc.messages.push(e),
        }
    }

    /// Writes what the view shows: one image, or one per view for "All three" (suffixes
    /// _color, _normals, _depth) and per rule in compare mode (_correct, _incorrect).
    pub fn export(&mut self, path: &Path) -> Result<Vec<PathBuf>, String> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        if !matches!(ext.as_deref(), Some("png" | "tga")) {
            return Err(format!("{}: export as .png or .tga", path.display()));
        }
        let cells = self.view.cells();
        let mut cells: Vec<(usize, tracelab_core::View, &str)> =
            cells.into_iter().map(|(f, v, _)| (f, v, "")).collect();
        if self.view.compare == Compare::Split {
            let v = cells[0].1;
            cells.push((1, v, ""));
        }
        let many = cells.len() > 1;
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_default();
        let ext = ext.unwrap_or_default();
        let depth = self.view.depth;
        self.worker.with_published(|p| {
            let p = p.ok_or("nothing rendered yet")?;
            let mut written = Vec::new();
            for (f, view, _) in &cells {
                let frame = p.frames.get(*f).ok_or("no such frame")?.lock().clone();
                let target = if many {
                    let v = match view {
                        tracelab_core::View::Color => "color",
                        tracelab_core::View::Normals => "normals",
                        tracelab_core::View::Depth => "depth",
                    };
                    let rule = if p.frames.len() > 1 {
                        if *f == 0 { "_correct" } else { "_incorrect" }
                    } else {
                        ""
                    };
                    path.with_file_name(format!("{stem}_{v}{rule}.{ext}"))
                } else {
                    path.to_path_buf()
                };
                crate::io::write_image(&frame, *view, depth, &target)?;
                written.push(target);
            }
            Ok(written)
        })
    }

    /// Inspects a pixel of the image last published (the image on screen).
    pub fn inspect(&mut self, frame: usize, x: u32, row: u32) {
        let found = self.worker.with_published(|p| {
            let p = p?;
            let mode = *p.job.modes.get(frame)?;
            let settings = RenderSettings {
                normal_transform: mode,
                ..p.job.settings
            };
            Some((
                inspect_pixel(&p.job.scene, &p.compiled, &settings, x, row),
                p.job.scene.clone(),
            ))
        });
        if let Some((story, scene)) = found {
            if let Some(h) = &story.hit {
                // Ids are stable across edits that do not delete the node.
                if self.doc.scene.graph.path_to(h.node).is_some() {
                    self.doc.selection = Some(Selection::Node(h.node));
                }
            }
            self.viewport.marker = Some((x, row));
            self.story = Some((story, scene));
            self.pixel_inspector_open = true;
        }
    }

    /// The images the view drew in the last frame, with the pixels on screen.
    pub fn shown(&self) -> Vec<crate::ui::viewport::Shown> {
        self.viewport.shown()
    }

    /// Starts (or keeps) the render for the current document and view.
    pub fn request_render(&mut self, size: (u32, u32)) {
        let settings = Viewport::settings(&self.view, size);
        let scene = &self.doc.scene;
        self.worker.request(
            self.doc.generation,
            || Arc::new(scene.clone()),
            settings,
            self.view.modes(),
        );
    }

    fn shortcuts(&mut self, ctx: &egui::Context) {
        use egui::{Key, KeyboardShortcut, Modifiers};
        let cmd = Modifiers::COMMAND;
        let cmd_shift = Modifiers::COMMAND | Modifiers::SHIFT;
        let pressed = |m: Modifiers, k: Key| {
            ctx.input_mut(|i| i.consume_shortcut(&KeyboardShortcut::new(m, k)))
        };
        // Longer shortcuts first: Ctrl+Shift+Z must not also count as Ctrl+Z.
        if pressed(cmd_shift, Key::Z) || pressed(cmd, Key::Y) {
            self.doc.redo();
        }
        if pressed(cmd, Key::Z) {
            self.doc.undo();
        }
        if pressed(cmd_shift, Key::S) {
            self.dialog = Some(FileDialog::new(Purpose::SaveAs, self.doc.path.as_deref()));
        }
        if pressed(cmd, Key::S) {
            self.save();
        }
        if pressed(cmd, Key::O) {
            self.dialog = Some(FileDialog::new(Purpose::Open, self.doc.path.as_deref()));
        }
        if !ctx.egui_wants_keyboard_input()
            && ctx.input(|i| i.key_pressed(Key::Delete))
            && let Some(Selection::Node(node)) = self.doc.selection
        {
            self.apply(Edit::DeleteNode { node });
        }
    }

    fn menu(&mut self, ui: &mut egui::Ui) {
        egui::MenuBar::new().ui(ui, |ui| {
            ui.menu_button("File", |ui| {
                if ui.button("Open… (Ctrl+O)").clicked() {
                    self.dialog = Some(FileDialog::new(Purpose::Open, self.doc.path.as_deref()));
                }
                ui.menu_button("Open recent", |ui| {
                    if self.recent.is_empty() {
                        ui.label("(none yet)");
                    }
                    for r in self.recent.clone() {
                        if ui.button(r.display().to_string()).clicked() {
                            self.open(&r);
                        }
                    }
                });
                if ui.button("Save (Ctrl+S)").clicked() {
                    self.save();
                }
                if ui.button("Save As… (Ctrl+Shift+S)").clicked() {
                    self.dialog = Some(FileDialog::new(Purpose::SaveAs, self.doc.path.as_deref()));
                }
                if ui
                    .add_enabled(
                        self.doc.path.is_some(),
                        egui::Button::new("Reload from disk"),
                    )
                    .clicked()
                {
                    self.reload();
                }
                if ui.button("Export view…").clicked() {
                    self.dialog = Some(FileDialog::new(Purpose::Export, self.doc.path.as_deref()));
                }
            });
            ui.menu_button("Edit", |ui| {
                if ui
                    .add_enabled(self.doc.can_undo(), egui::Button::new("Undo (Ctrl+Z)"))
                    .clicked()
                {
                    self.doc.undo();
                }
                if ui
                    .add_enabled(
                        self.doc.can_redo(),
                        egui::Button::new("Redo (Ctrl+Shift+Z)"),
                    )
                    .clicked()
                {
                    self.doc.redo();
                }
            });
            ui.menu_button("View", |ui| {
                ui.checkbox(&mut self.pixel_inspector_open, "Pixel inspector");
            });
        });
    }

    fn messages(&mut self, ui: &mut egui::Ui) {
        if self.disk_changed {
            ui.horizontal(|ui| {
                ui.colored_label(
                    ui.visuals().warn_fg_color,
                    "The file changed on disk, and you have unsaved edits.",
                );
                if ui.button("Reload (lose edits)").clicked() {
                    self.reload();
                }
                if ui.button("Keep mine").clicked() {
                    self.disk_changed = false;
                    self.doc.disk_stamp = self
                        .doc
                        .path
                        .as_deref()
                        .and_then(|p| std::fs::metadata(p).and_then(|m| m.modified()).ok());
                }
            });
        }
        if self.doc.messages.is_empty() {
            return;
        }
        ui.horizontal(|ui| {
            ui.vertical(|ui| {
                for m in self.doc.messages.iter().take(8) {
                    let c = if m.contains("warning:") || m.contains("reloaded") {
                        ui.visuals().warn_fg_color
                    } else {
                        ui.visuals().error_fg_color
                    };
                    ui.colored_label(c, m);
                }
                if self.doc.messages.len() > 8 {
                    ui.label(format!("… and {} more", self.doc.messages.len() - 8));
                }
            });
            if ui.button("Dismiss").clicked() {
                self.doc.messages.clear();
            }
        });
    }

    fn dialogs(&mut self, ctx: &egui::Context) {
        if let Some(d) = &mut self.dialog {
            let purpose = d.purpose;
            if let Some(result) = d.ui(ctx) {
                self.dialog = None;
                if let Some(path) = result {
                    match purpose {
                        Purpose::Open => self.open(&path),
                        Purpose::SaveAs => self.save_as(&path),
                        Purpose::Export => match self.export(&path) {
                            Ok(files) => self.doc.messages.push(format!(
                                "exported {}",
                                files
                                    .iter()
                                    .map(|f| f.display().to_string())
                                    .collect::<Vec<_>>()
                                    .join(", ")
                            )),
                            Err(e) => self.doc.messages.push(e),
                        },
                    }
                }
            }
        }
        if let Some(pending) = self.confirm.clone() {
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
            if let Some(c) = choice {
                self.confirm = None;
                if c == 0 {
                    self.save();
                    if self.doc.is_dirty() {
                        return; // Save As dialog or a failed save: stay.
                    }
                }
                if c <= 1 {
                    match pending {
                        Pending::Close => {
                            self.allow_close = true;
                            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
                        }
                        Pending::Open(p) => {
                            self.open_now(&p);
                        }
                    }
                }
            }
        }
        if self.pixel_inspector_open {
            let mut open = true;
            // Over the lower tree, leaving the render view free for the next click.
            let at = ctx.content_rect().left_bottom() + egui::vec2(8.0, -30.0);
            egui::Window::new("Pixel inspector")
                .open(&mut open)
                .default_width(520.0)
                .pivot(egui::Align2::LEFT_BOTTOM)
                .default_pos(at)
                .show(ctx, |ui| match &self.story {
                    Some((story, scene)) => pixel_inspector::ui(ui, story, scene),
                    None => {
                        ui.label("Click a pixel in the render view.");
                    }
                });
            self.pixel_inspector_open = open;
        }
        if !self.pixel_inspector_open {
            self.viewport.marker = None;
        }
    }

    /// Watches the file: reload quietly when nothing is unsaved, else ask.
    fn watch_disk(&mut self) {
        if self.last_disk_check.elapsed() < Duration::from_millis(700) {
            return;
        }
        self.last_disk_check = Instant::now();
        if !self.disk_changed && self.doc.changed_on_disk() {
            if self.doc.is_dirty() {
                self.disk_changed = true;
            } else {
                self.reload();
            }
        }
    }

    /// One frame of UI, shared by eframe and tests.
    pub fn frame(&mut self, ui: &mut egui::Ui) {
        let t0 = Instant::now();
        self.frame_inner(ui);
        if std::env::var_os("TRACELAB_LOG_FRAMES").is_some() {
            eprintln!(
                "tracelab: ui code {:.1} ms",
                t0.elapsed().as_secs_f64() * 1e3
            );
        }
    }

    fn frame_inner(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
        self.shortcuts(&ctx);
        self.watch_disk();
        // Files dropped onto the window.
        let dropped: Vec<PathBuf> = ctx.input(|i| {
            i.raw
                .dropped_files
                .iter()
                .map(|f| f.path().to_path_buf())
                .filter(|p| !p.as_os_str().is_empty())
                .collect()
        });
        if let Some(p) = dropped.first() {
            self.open(p);
        }
        if ctx.input(|i| i.viewport().close_requested()) && self.doc.is_dirty() && !self.allow_close
        {
            ctx.send_viewport_cmd(egui::ViewportCommand::CancelClose);
            self.confirm = Some(Pending::Close);
        }
        if !ctx.input(|i| i.pointer.any_down()) {
            self.doc.end_gesture();
        }
        let title = format!(
            "tracelab — {}{}",
            self.doc.title_name(),
            if self.doc.is_dirty() { " *" } else { "" }
        );
        if title != self.title {
            ctx.send_viewport_cmd(egui::ViewportCommand::Title(title.clone()));
            self.title = title;
        }
        if self.rows.0 != self.doc.generation {
            let s = self.doc.scene.graph.stats();
            self.rows = (
                self.doc.generation,
                tree::tree_rows(&self.doc.scene),
                (s.primitives, s.triangles, s.nodes),
            );
        }

        egui::Panel::top("menu").show(ui, |ui| {
            self.menu(ui);
            self.messages(ui);
        });
        egui::Panel::bottom("status").show(ui, |ui| {
            status::ui(ui, &self.doc, &self.worker, self.rows.2, self.show_timings)
        });
        let mut edits = Vec::new();
        egui::Panel::left("tree")
            .resizable(true)
            .default_size(280.0)
            .show(ui, |ui| {
                ui.heading("Scene");
                let rows = std::mem::take(&mut self.rows.1);
                let reveal = match self.doc.selection {
                    Some(Selection::Node(id)) if self.doc.selection != self.tree_seen => Some(id),
                    _ => None,
                };
                edits.extend(tree::ui(ui, &mut self.doc, &rows, reveal));
                self.tree_seen = self.doc.selection;
                self.rows.1 = rows;
            });
        egui::Panel::right("inspector")
            .resizable(true)
            .default_size(300.0)
            .show(ui, |ui| {
                ui.heading("Inspector");
                edits.extend(inspector::ui(ui, &mut self.doc));
            });
        let mut pick = None;
        let mut size = (1, 1);
        egui::CentralPanel::default().show(ui, |ui| {
            Viewport::toolbar(ui, &mut self.view);
            ui.separator();
            size = Viewport::render_size(&self.view, ui.available_size(), ui.pixels_per_point());
            self.request_render(size);
            pick = self.viewport.images(ui, &mut self.view, &self.worker);
        });
        for e in edits {
            self.apply(e);
        }
        if let Some(p) = pick {
            self.inspect(p.frame, p.x, p.row);
        }
        self.dialogs(&ctx);
        // Edits and dialogs above changed the document after the view asked for its render:
        // start the new one now, not on the next input event.
        self.request_render(size);
        if !self.worker.is_idle() {
            ctx.request_repaint_after(Duration::from_millis(30));
        } else {
            // Keep watching the file on disk while idle.
            ctx.request_repaint_after(Duration::from_secs(1));
        }
    }
}

impl eframe::App for TracelabApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        self.frame(ui);
    }

    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        let recent: Vec<String> = self
            .recent
            .iter()
            .map(|p| p.display().to_string())
            .collect();
        storage.set_string("recent", recent.join("\n"));
        let tab = match self.view.tab {
            Tab::Color => "color",
            Tab::Normals => "normals",
            Tab::Depth => "depth",
            Tab::All => "all",
        };
        storage.set_string(
            "view",
            format!(
                "{tab} {} {} {}",
                u8::from(self.view.shade_back),
                self.view.depth.0,
                self.view.depth.1
            ),
        );
    }
}

/// Opens the window (the `tracelab` command with no subcommand).
pub fn run(scene: Option<PathBuf>) -> Result<(), String> {
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_inner_size([1280.0, 800.0])
            .with_title("tracelab")
            .with_drag_and_drop(true),
        ..Default::default()
    };
    eframe::run_native(
        "tracelab",
        options,
        Box::new(move |cc| {
            Ok(Box::new(TracelabApp::new(
                Some(cc),
                AppOptions {
                    scene,
                    fixed_size: None,
                },
            )))
        }),
    )
    .map_err(|e| format!("cannot open the window: {e}"))
}
