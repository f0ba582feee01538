//! The eframe app: wires the document, the panels and the render worker together. Panels,
//! menus and shortcuts return [`AppCommand`]s; [`TracelabApp::run_commands`] is the one place
//! that carries them out (edits through `Document::apply`, which records undo).

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use tracelab_core::render::RayStory;
use tracelab_core::{NodeKind, Scene};

use crate::document::edit::Edit;
use crate::document::op_target::{OpKind, op_target};
use crate::document::{Document, Selection};
use crate::gui::animation_dialog::{self, AnimationForm};
use crate::gui::command::AppCommand;
use crate::gui::file_dialog::{FileDialog, Purpose};
use crate::gui::file_watch::{self, FileWatch};
use crate::gui::layout::Layout;
use crate::gui::lecture;
use crate::gui::loading::{LoadPurpose, Loading};
use crate::gui::menu;
use crate::gui::mesh_load::MeshLoad;
use crate::gui::native_dialog::{Answer, NativeDialog};
use crate::gui::notifications;
use crate::gui::panels::pixel_inspector::Inspected;
use crate::gui::panels::tree::TreeRow;
use crate::gui::panels::viewport::{Compare, ViewSettings, Viewport};
use crate::gui::panels::{inspector, pixel_inspector, ray_panel, status, tree};
use crate::gui::ray_diagram::Orbit;
use crate::gui::settings::Settings;
use crate::gui::view_tools;
use crate::io::{SceneRead, read_scene_file};
use crate::render_worker::RenderWorker;
use crate::{bounds, navigation};
use glam::Vec3;

#[derive(Clone, Debug, Default)]
pub struct AppOptions {
    /// Scene file to open (`None`: the built-in scene).
    pub scene: Option<PathBuf>,
    /// Render at this size instead of following the view (tests use small fixed sizes).
    pub fixed_size: Option<(u32, u32)>,
    /// Use the desktop's file dialog where this build and desktop have one (the window does;
    /// tests drive the built-in one).
    pub native_dialogs: bool,
}

/// An action waiting for the user to decide.
#[derive(Clone, Debug, PartialEq)]
pub enum Pending {
    /// Close the window, over unsaved changes.
    Close,
    /// Switch to this file, already read, over unsaved changes.
    Open(PathBuf),
    /// Start a new untitled scene, over unsaved changes.
    New,
    /// Write `path` although saving loses what `warnings` name; then carry on with `then`.
    Save {
        path: PathBuf,
        warnings: Vec<String>,
        then: Option<Box<Pending>>,
    },
}

const MAX_RECENT: usize = 10;

pub struct TracelabApp {
    pub doc: Document,
    pub worker: RenderWorker,
    pub view: ViewSettings,
    viewport: Viewport,
    /// The last pixel inspected and the scene snapshot it was traced in.
    pub story: Option<(RayStory, Arc<Scene>)>,
    /// Which pixel that is and the render it was traced in: every new render traces it again.
    pub inspected: Option<Inspected>,
    pub pixel_inspector_open: bool,
    /// The Ray panel (world and object space diagrams) in the dock, beside the story.
    pub ray_panel_open: bool,
    /// File › Export animation's form, while open, and the export under way.
    pub animation: Option<AnimationForm>,
    pub animation_running: Option<animation_dialog::Running>,
    /// The Lecture menu's figure on show, for its caption.
    pub lecture: Option<usize>,
    /// A figure whose scene is being read (or waits for the unsaved-changes answer): its view
    /// and caption are applied when that scene is installed, and dropped if it is not.
    pending_lecture: Option<usize>,
    /// How each Ray diagram (world, object) is turned.
    pub ray_orbits: [Orbit; 2],
    pub dialog: Option<FileDialog>,
    native: Option<NativeDialog>,
    native_dialogs: bool,
    pub confirm: Option<Pending>,
    /// A file read while there were unsaved changes, waiting for the answer to `confirm`.
    ready: Option<SceneRead>,
    /// The file being read in the background, if any.
    loading: Option<Loading>,
    /// TriangleMesh files being read in the background, for the document open now (dropped
    /// when another is installed: their node ids belong to this one).
    mesh_loads: Vec<MeshLoad>,
    repaint: Arc<dyn Fn() + Send + Sync>,
    layout: Layout,
    /// Bumped whenever the document changes other than by the panels' own edits (open,
    /// reload, New, undo, redo): the inspector's widgets get fresh ids, so no edit buffer
    /// from before (a typed obj_file, a half-typed number) shows or is committed there.
    widget_epoch: u64,
    /// The document generation right after the panels' edits were applied.
    panels_generation: u64,
    pub recent: Vec<PathBuf>,
    rows: (u64, Vec<TreeRow>, (usize, usize, usize)),
    file_watch: FileWatch,
    /// The file changed on disk while there were unsaved edits: ask before reloading.
    pub disk_changed: bool,
    title: String,
    allow_close: bool,
    /// The selection the tree last showed, to scroll to selections made elsewhere.
    tree_seen: Option<Selection>,
    /// Timings in the status bar; snapshot tests turn them off to stay deterministic.
    pub show_timings: bool,
    /// What the UI asked for this frame, carried out by [`Self::run_commands`].
    commands: Vec<AppCommand>,
    /// A note for the status bar (what a gizmo drag added), and when it was made.
    pub note: Option<(String, Instant)>,
    /// The size the view renders at, for framing.
    render_size: (u32, u32),
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
            inspected: None,
            pixel_inspector_open: false,
            ray_panel_open: true,
            ray_orbits: [Orbit::default(); 2],
            lecture: None,
            pending_lecture: None,
            animation: None,
            animation_running: None,
            dialog: None,
            native: None,
            native_dialogs: opts.native_dialogs,
            confirm: None,
            ready: None,
            loading: None,
            mesh_loads: Vec::new(),
            repaint: Arc::new(|| {}),
            layout: Layout::default(),
            widget_epoch: 0,
            panels_generation: 0,
            recent: Vec::new(),
            rows: (0, Vec::new(), (0, 0, 0)),
            file_watch: FileWatch::default(),
            disk_changed: false,
            title: String::new(),
            allow_close: false,
            show_timings: true,
            tree_seen: None,
            commands: Vec::new(),
            note: None,
            render_size: (1, 1),
        };
        if let Some(cc) = cc {
            let ctx = cc.egui_ctx.clone();
            app.worker.set_repaint(move || ctx.request_repaint());
            let ctx = cc.egui_ctx.clone();
            app.repaint = Arc::new(move || ctx.request_repaint());
            if let Some(s) = cc.storage {
                app.load_persisted(s);
            }
        }
        if opts.fixed_size.is_some() {
            app.view.fixed_size = opts.fixed_size;
        }
        // Read in the background: the window paints at once, on the built-in scene.
        if let Some(p) = opts.scene {
            app.open(&p);
        }
        app
    }

    pub fn load_persisted(&mut self, s: &dyn eframe::Storage) {
        if let Some(settings) = Settings::load(s) {
            self.apply_settings(settings);
        }
    }

    /// What is kept between runs (see [`Settings`]).
    pub fn settings(&self) -> Settings {
        Settings {
            recent: self.recent.clone(),
            tab: self.view.tab,
            shade_back: self.view.shade_back,
            depth: self.view.depth,
            layout_epoch: self.layout.epoch,
        }
    }

    fn apply_settings(&mut self, s: Settings) {
        let Settings {
            recent,
            tab,
            shade_back,
            depth,
            layout_epoch,
        } = s;
        self.recent = recent;
        self.view.tab = tab;
        self.view.shade_back = shade_back;
        if depth.0.is_finite() && depth.1.is_finite() {
            self.view.depth = depth;
        }
        self.layout.epoch = layout_epoch;
    }

    /// Asks for an action; it runs with the others at the end of the frame.
    pub fn queue(&mut self, command: AppCommand) {
        self.commands.push(command);
    }

    /// Carries out what the UI has asked for so far, in order: the one place where panels,
    /// menus, shortcuts and dialogs change the app. The frame calls it after the menu bar
    /// (menus, shortcuts, dropped files), after the tree (so the inspector shows a selection
    /// in the frame it was clicked) and at the end (the inspector, the view, dialogs).
    pub fn run_commands(&mut self, ctx: &egui::Context) {
        let commands = std::mem::take(&mut self.commands);
        let from_panels = commands.iter().all(AppCommand::from_panels);
        let before = self.doc.generation;
        for c in commands {
            self.run_command(c, ctx);
        }
        if self.doc.generation != before {
            if !from_panels {
                // Undo, New, Open…: no edit buffer from before may show (see `widget_epoch`).
                self.widget_epoch += 1;
            }
            self.panels_generation = self.doc.generation;
        }
    }

    fn run_command(&mut self, command: AppCommand, ctx: &egui::Context) {
        match command {
            AppCommand::Select(s) => self.doc.select(s),
            AppCommand::Edit(Edit::SetOpOfKind { node, op }) => self.gizmo_edit(node, op),
            AppCommand::Edit(e) => self.apply(e),
            AppCommand::LoadMesh { node, obj_file } => {
                let base = self.doc.path.as_deref().and_then(Path::parent);
                self.mesh_loads.push(MeshLoad::start(
                    node,
                    obj_file,
                    base.map(Path::to_path_buf),
                    self.doc.mesh_cache.clone(),
                    self.repaint.clone(),
                ));
            }
            AppCommand::DeleteSelected => {
                if let Some(Selection::Node(node)) = self.doc.selection {
                    self.apply(Edit::DeleteNode { node });
                }
            }
            AppCommand::Inspect { frame, x, row } => self.inspect(frame, x, row),
            AppCommand::New => {
                self.lecture = None;
                self.pending_lecture = None;
                self.new_document();
            }
            AppCommand::OpenDialog => self.show_file_dialog(Purpose::Open),
            AppCommand::Open(p) => {
                self.lecture = None;
                self.pending_lecture = None;
                self.open(&p);
            }
            AppCommand::OpenLecture(i) => {
                if let Some(f) = lecture::FIGURES.get(i) {
                    // Its view and caption come with its scene, once installed: a Cancel
                    // over unsaved changes leaves everything as it was.
                    self.open(&f.path());
                    self.pending_lecture = Some(i);
                }
            }
            AppCommand::CloseCaption => self.lecture = None,
            AppCommand::AnimationDialog => match self.doc.selection {
                Some(Selection::Node(id))
                    if matches!(
                        self.doc.scene.graph.get(id).map(|n| &n.kind),
                        Some(NodeKind::Transform(_))
                    ) =>
                {
                    self.animation = Some(AnimationForm::new(id));
                }
                _ => self
                    .doc
                    .messages
                    .warning("Export animation: select a Transform first"),
            },
            AppCommand::StartAnimation(form) => {
                if self.animation_running.is_none() {
                    let size = self.view.fixed_size.unwrap_or(self.viewport.shown_size);
                    let settings = Viewport::settings(&self.view, size);
                    self.animation_running = Some(animation_dialog::Running::start(
                        Arc::new(self.doc.scene.clone()),
                        &form,
                        settings,
                        self.doc.path.iter().cloned().collect(),
                    ));
                    self.animation = Some(form);
                }
            }
            AppCommand::CancelAnimation => {
                if let Some(r) = &self.animation_running {
                    r.cancel.store(true, std::sync::atomic::Ordering::Relaxed);
                }
            }
            AppCommand::CloseAnimationDialog => self.animation = None,
            AppCommand::Save => self.save(),
            AppCommand::SaveAsDialog => self.show_file_dialog(Purpose::SaveAs),
            AppCommand::SaveAs(p) => self.save_as(&p),
            AppCommand::ExportDialog => self.show_file_dialog(Purpose::Export),
            AppCommand::Export(p) => match self.export(&p) {
                Ok(files) => self.doc.messages.info(format!(
                    "exported {}",
                    files
                        .iter()
                        .map(|f| f.display().to_string())
                        .collect::<Vec<_>>()
                        .join(", ")
                )),
                Err(e) => self.doc.messages.error(e.to_string()),
            },
            AppCommand::Reload => self.reload(),
            AppCommand::Quit => self.quit(ctx),
            AppCommand::Undo => {
                self.doc.undo();
            }
            AppCommand::Redo => {
                self.doc.redo();
            }
            AppCommand::ShowPixelInspector(open) => self.pixel_inspector_open = open,
            AppCommand::ShowRayPanel(open) => self.ray_panel_open = open,
            AppCommand::ResetLayout => self.layout.reset(),
            AppCommand::FrameSelected => match self.doc.selection {
                Some(Selection::Node(id)) => self.frame_node(id),
                _ => self
                    .doc
                    .messages
                    .warning("Frame selected: select an object first"),
            },
            AppCommand::FrameAll => self.frame_node(self.doc.scene.graph.root()),
            AppCommand::AxisView(v) => {
                let root = self.doc.scene.graph.root();
                let (lo, hi) = bounds::world_bounds(&self.doc.scene, root)
                    .unwrap_or((Vec3::splat(-1.0), Vec3::ONE));
                let (w, h) = self.render_size;
                self.apply(Edit::SetCamera(navigation::axis_view(
                    &self.doc.scene.camera,
                    v,
                    lo,
                    hi,
                    w,
                    h,
                )));
            }
            AppCommand::CancelDrag { mark } => {
                self.doc.revert_to(mark);
            }
        }
    }

    /// Moves the camera, along its own direction, to show `node` whole.
    fn frame_node(&mut self, node: tracelab_core::NodeId) {
        match bounds::world_bounds(&self.doc.scene, node) {
            Some((lo, hi)) => {
                let (w, h) = self.render_size;
                self.apply(Edit::SetCamera(navigation::frame(
                    &self.doc.scene.camera,
                    lo,
                    hi,
                    w,
                    h,
                )));
            }
            None => self
                .doc
                .messages
                .warning("nothing with bounds to frame there (a plane has none)"),
        }
    }

    /// A gizmo drag's edit; the status bar says what its first step added.
    fn gizmo_edit(&mut self, node: tracelab_core::NodeId, op: tracelab_core::TransformOp) {
        let added = OpKind::of(&op).and_then(|kind| {
            let target = op_target(&self.doc.scene.graph, node, kind).ok()?;
            let name = self.doc.scene.graph.get(node)?.kind.name();
            target.added(kind, name)
        });
        if self.doc.apply(Edit::SetOpOfKind { node, op }).is_ok() {
            if let Some(a) = added {
                self.note = Some((a, Instant::now()));
            }
        } else if let Some(r) = &self.doc.refusal {
            self.doc.messages.error(format!("edit refused: {r}"));
        }
    }

    /// Applies an edit through the document (the one place that records undo).
    pub fn apply(&mut self, edit: Edit) {
        if let Err(e) = self.doc.apply(edit) {
            self.doc.messages.error(format!("edit refused: {e}"));
        }
    }

    /// Opens a file: reads it in the background, then switches to it, asking first when
    /// there are unsaved changes. A file that does not parse is reported and nothing is
    /// asked: there is nothing to switch to.
    pub fn open(&mut self, path: &Path) {
        self.start_loading(path, LoadPurpose::Open);
    }

    /// Opens a file at once, blocking, without asking (scripts and tests; the window uses
    /// [`Self::open`]). False when it could not be read: the current scene stays.
    pub fn open_now(&mut self, path: &Path) -> bool {
        let read = read_scene_file(path, self.doc.mesh_cache.clone());
        self.install(read, false)
    }

    /// Whether a file (a scene or a mesh) is being read in the background.
    pub fn is_loading(&self) -> bool {
        self.loading.is_some() || !self.mesh_loads.is_empty()
    }

    /// Applies the meshes read since the last frame, each as one edit.
    fn poll_mesh_loads(&mut self) {
        let mut i = 0;
        while i < self.mesh_loads.len() {
            let Some(r) = self.mesh_loads[i].poll() else {
                i += 1;
                continue;
            };
            self.mesh_loads.remove(i);
            if matches!(r.mesh, tracelab_core::MeshSlot::Loaded(_)) {
                self.doc.mesh_cache = r.cache;
            }
            if let Err(e) = self.doc.set_mesh(r.node, r.obj_file, r.mesh) {
                self.doc.messages.error(format!("edit refused: {e}"));
            }
        }
    }

    fn start_loading(&mut self, path: &Path, purpose: LoadPurpose) {
        // One read at a time: the newer request wins.
        if let Some(old) = self.loading.take() {
            old.cancel();
        }
        self.loading = Some(Loading::start(
            path,
            purpose,
            self.doc.mesh_cache.clone(),
            self.repaint.clone(),
        ));
    }

    /// Stops the background read; the open scene stays as it is.
    pub fn cancel_loading(&mut self) {
        if let Some(l) = self.loading.take() {
            l.cancel();
        }
    }

    /// Takes the background read's result when it is there.
    fn poll_loading(&mut self) {
        let Some(read) = self.loading.as_ref().and_then(Loading::poll) else {
            return;
        };
        let Some(loading) = self.loading.take() else {
            return;
        };
        let ask = read.outcome.is_ok() && self.doc.is_dirty();
        match loading.purpose {
            LoadPurpose::Open | LoadPurpose::Refresh if ask => {
                self.confirm = Some(Pending::Open(read.path.clone()));
                self.ready = Some(read);
            }
            LoadPurpose::Open => {
                self.install(read, false);
            }
            LoadPurpose::Reload | LoadPurpose::Refresh => {
                self.install(read, true);
            }
        }
    }

    /// Makes a file read the document (or reports why it cannot be). `reload`: the same file
    /// again, keeping the selection where it still exists.
    fn install(&mut self, read: SceneRead, reload: bool) -> bool {
        let path = read.path.clone();
        let selection = self.doc.selection;
        let figure = self
            .pending_lecture
            .take()
            .filter(|&i| !reload && lecture::FIGURES.get(i).is_some_and(|f| f.path() == path));
        if self.doc.install(read).is_err() {
            if reload {
                // Not again until the file changes again.
                self.doc.disk_stamp = std::fs::metadata(&path).and_then(|m| m.modified()).ok();
            }
            return false;
        }
        self.story = None;
        self.inspected = None;
        self.viewport.marker = None;
        self.disk_changed = false;
        self.mesh_loads.clear();
        if let Some(i) = figure {
            lecture::FIGURES[i].apply(&mut self.view);
            self.lecture = Some(i);
        }
        if reload {
            self.doc.select(selection);
            self.doc
                .messages
                .info(format!("{}: reloaded (changed on disk)", path.display()));
        }
        self.remember(&path);
        true
    }

    /// Puts `path` first in Open recent, as a canonical path: an entry works from any folder
    /// tracelab is started in, and one file is one entry however it was named.
    fn remember(&mut self, path: &Path) {
        let path = std::fs::canonicalize(path)
            .or_else(|_| std::path::absolute(path))
            .unwrap_or_else(|_| path.to_path_buf());
        self.recent.retain(|r| r != &path);
        self.recent.insert(0, path);
        self.recent.truncate(MAX_RECENT);
    }

    /// Re-reads the file from disk (in the background), keeping the selection when it
    /// still exists.
    pub fn reload(&mut self) {
        if let Some(p) = self.doc.path.clone() {
            self.start_loading(&p, LoadPurpose::Reload);
        }
    }

    /// File › New: the built-in scene, untitled, asking first about unsaved changes.
    pub fn new_document(&mut self) {
        if self.doc.is_dirty() {
            self.confirm = Some(Pending::New);
        } else {
            self.new_now();
        }
    }

    fn new_now(&mut self) {
        self.cancel_loading();
        let cache = std::mem::take(&mut self.doc.mesh_cache);
        // Generations stay monotonic across documents: the worker compares them.
        let generation = self.doc.generation + 1;
        self.doc = Document::builtin();
        self.doc.mesh_cache = cache;
        self.doc.generation = generation;
        self.mesh_loads.clear();
        self.story = None;
        self.inspected = None;
        self.viewport.marker = None;
        self.disk_changed = false;
    }

    /// File › Quit (Ctrl+Q): closes the window, asking first about unsaved changes.
    pub fn quit(&mut self, ctx: &egui::Context) {
        if self.doc.is_dirty() {
            self.confirm = Some(Pending::Close);
        } else {
            self.allow_close = true;
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        }
    }

    pub fn save(&mut self) {
        match self.doc.path.clone() {
            Some(p) => {
                self.save_to(&p, None);
            }
            None => self.show_file_dialog(Purpose::SaveAs),
        }
    }

    /// Saves to `path`; asks first when saving would lose something (comments that cannot
    /// be kept, mesh paths that cannot be rewritten).
    pub fn save_as(&mut self, path: &Path) {
        self.save_to(path, None);
    }

    /// True when written now. Otherwise the user is asked (then `then` follows a yes) or
    /// the error is shown.
    fn save_to(&mut self, path: &Path, then: Option<Pending>) -> bool {
        let warnings = self.doc.save_warnings(path);
        if !warnings.is_empty() {
            self.confirm = Some(Pending::Save {
                path: path.to_path_buf(),
                warnings,
                then: then.map(Box::new),
            });
            return false;
        }
        self.write(path)
    }

    fn write(&mut self, path: &Path) -> bool {
        match self.doc.save_as(path) {
            Ok(()) => {
                self.remember(path);
                true
            }
            Err(e) => {
                self.doc.messages.error(e.to_string());
                false
            }
        }
    }

    /// Writes what the view shows: one image, or one per view for "All three" (suffixes
    /// _color, _normals, _depth) and per rule in compare mode (_correct, _incorrect).
    pub fn export(&mut self, path: &Path) -> anyhow::Result<Vec<PathBuf>> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        if !matches!(ext.as_deref(), Some("png" | "tga")) {
            anyhow::bail!("{}: export as .png or .tga", path.display());
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
        // The output policy (crate::io::output): never the open scene file; the names made
        // for several images never a symlink, folder or device; checked before any is written.
        let mut plan = crate::io::OutputPlan::new();
        if let Some(scene) = &self.doc.path {
            plan.reads(scene);
        }
        self.worker.with_published(|p| {
            let p = p.ok_or_else(|| anyhow::anyhow!("nothing rendered yet"))?;
            let mut targets = Vec::new();
            for (f, view, _) in &cells {
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
                if many {
                    plan.implicit_exact(&target)?;
                } else {
                    plan.writes(&target);
                }
                targets.push((*f, *view, target));
            }
            plan.check()?;
            let mut written = Vec::new();
            for (f, view, target) in targets {
                let frame = p
                    .frames
                    .get(f)
                    .ok_or_else(|| anyhow::anyhow!("no such frame"))?
                    .lock()
                    .clone();
                crate::io::write_image(&frame, view, depth, &target)?;
                written.push(target);
            }
            Ok(written)
        })
    }

    /// Inspects a pixel of the image last published (the image on screen) and selects
    /// what it shows.
    pub fn inspect(&mut self, frame: usize, x: u32, row: u32) {
        let found = self
            .worker
            .with_published(|p| pixel_inspector::trace(p?, frame, x, row));
        if let Some((at, story, scene)) = found {
            if let Some(h) = &story.hit {
                // Ids are stable across edits that do not delete the node.
                if self.doc.scene.graph.path_to(h.node).is_some() {
                    self.doc.select(Some(Selection::Node(h.node)));
                }
            }
            self.viewport.marker = Some((at.x, at.row));
            self.inspected = Some(at);
            self.story = Some((story, scene));
            self.pixel_inspector_open = true;
        }
    }

    /// Traces the inspected pixel again when a newer render is published, so the story is
    /// always that of the image on screen. The selection stays as the user left it.
    fn follow_inspected(&mut self) {
        let Some(at) = self.inspected.clone() else {
            return;
        };
        if let Some((at, story, scene)) = self
            .worker
            .with_published(|p| pixel_inspector::follow(p?, &at))
        {
            self.viewport.marker = Some((at.x, at.row));
            self.inspected = Some(at);
            self.story = Some((story, scene));
        }
    }

    /// The images the view drew in the last frame, with the pixels on screen.
    pub fn shown(&self) -> Vec<crate::gui::panels::viewport::Shown> {
        self.viewport.shown()
    }

    /// Starts (or keeps) the render for the current document and view.
    pub fn request_render(&mut self, size: (u32, u32)) {
        let settings = Viewport::settings(&self.view, size);
        // While the view is being dragged, coarse passes only; the full image once it stops.
        self.worker.coarse_only = self.viewport.tools.moving();
        let scene = &self.doc.scene;
        self.worker.request(
            self.doc.generation,
            || Arc::new(scene.clone()),
            settings,
            self.view.modes(),
        );
    }

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
    fn chosen(&mut self, purpose: Purpose, path: &Path) {
        self.queue(match purpose {
            Purpose::Open => AppCommand::Open(path.to_path_buf()),
            Purpose::SaveAs => AppCommand::SaveAs(path.to_path_buf()),
            Purpose::Export => AppCommand::Export(path.to_path_buf()),
        });
    }

    fn menu(&mut self, ui: &mut egui::Ui) {
        let mut out = Vec::new();
        // Behind a dialog the menus wait too (a Modal blocks them already; the file dialog
        // is a window, so say it here).
        let free = self.dialog_up().is_none();
        egui::MenuBar::new().ui(ui, |ui| {
            ui.add_enabled_ui(free, |ui| self.menu_entries(ui, &mut out));
        });
        self.commands.extend(out);
    }

    fn menu_entries(&self, ui: &mut egui::Ui, out: &mut Vec<AppCommand>) {
        ui.menu_button("File", |ui| {
                menu::button(ui, true, AppCommand::New, out);
                menu::button(ui, true, AppCommand::OpenDialog, out);
                ui.menu_button("Open recent", |ui| {
                    if self.recent.is_empty() {
                        ui.label("(none yet)");
                    }
                    for r in &self.recent {
                        if ui.button(r.display().to_string()).clicked() {
                            out.push(AppCommand::Open(r.clone()));
                        }
                    }
                });
                menu::button(ui, true, AppCommand::Save, out);
                menu::button(ui, true, AppCommand::SaveAsDialog, out);
                menu::button(ui, self.doc.path.is_some(), AppCommand::Reload, out);
                menu::button(ui, true, AppCommand::ExportDialog, out);
                let transform = matches!(self.doc.selection, Some(Selection::Node(id)) if matches!(self.doc.scene.graph.get(id).map(|n| &n.kind), Some(NodeKind::Transform(_))));
                menu::button(ui, transform, AppCommand::AnimationDialog, out)
                    .on_disabled_hover_text("Select a Transform: one of its ops' numbers is swept");
                ui.separator();
                menu::button(ui, true, AppCommand::Quit, out);
            });
        ui.menu_button("Edit", |ui| {
            menu::button(ui, self.doc.can_undo(), AppCommand::Undo, out);
            menu::button(ui, self.doc.can_redo(), AppCommand::Redo, out);
        });
        ui.menu_button("Lecture", |ui| {
            for (i, f) in lecture::FIGURES.iter().enumerate() {
                if ui.button(f.caption).on_hover_text(f.look[0]).clicked() {
                    out.push(AppCommand::OpenLecture(i));
                    ui.close();
                }
            }
        });
        ui.menu_button("View", |ui| {
            let mut open = self.pixel_inspector_open;
            if ui.checkbox(&mut open, "Pixel inspector").changed() {
                out.push(AppCommand::ShowPixelInspector(open));
            }
            ui.separator();
            let node = matches!(self.doc.selection, Some(Selection::Node(_)));
            menu::button(ui, node, AppCommand::FrameSelected, out);
            menu::button(ui, true, AppCommand::FrameAll, out);
            for v in [
                navigation::AxisView::Front,
                navigation::AxisView::Right,
                navigation::AxisView::Top,
            ] {
                menu::button(ui, true, AppCommand::AxisView(v), out);
            }
            ui.separator();
            let mut ray = self.ray_panel_open;
            if ui
                .checkbox(&mut ray, "Ray panel (in the pixel inspector)")
                .changed()
            {
                out.push(AppCommand::ShowRayPanel(ray));
            }
            if menu::button(ui, true, AppCommand::ResetLayout, out)
                .on_hover_text("Panels back to their first sizes")
                .clicked()
            {
                ui.close();
            }
        });
    }

    fn messages(&mut self, ui: &mut egui::Ui) {
        if let Some(l) = &self.loading
            && crate::gui::panels::loading::ui(ui, l)
        {
            self.cancel_loading();
        }
        if self.disk_changed {
            ui.horizontal(|ui| {
                ui.colored_label(
                    ui.visuals().warn_fg_color,
                    "The file changed on disk, and you have unsaved edits.",
                );
                if ui.button("Reload (lose edits)").clicked() {
                    self.queue(AppCommand::Reload);
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
        // The document's notices are drawn over the view (`notifications::ui`).
    }

    /// Carries out an action the user agreed to.
    fn carry_out(&mut self, pending: Pending, ctx: &egui::Context) {
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

    fn dialogs(&mut self, ctx: &egui::Context) {
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

    /// Watches the file: reload quietly when nothing is unsaved, else ask.
    fn watch_disk(&mut self) {
        self.file_watch
            .follow(self.doc.path.as_deref(), self.repaint.clone());
        // A read under way will set the stamp; asking again would restart it. (A change
        // seen meanwhile stays pending until it is done.)
        if self.loading.is_some() || !self.file_watch.take_changed() {
            return;
        }
        if !self.disk_changed && self.doc.changed_on_disk() {
            if self.doc.is_dirty() {
                self.disk_changed = true;
            } else if let Some(p) = self.doc.path.clone() {
                self.start_loading(&p, LoadPurpose::Refresh);
            }
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

    /// One frame of UI, shared by eframe and tests.
    pub fn frame(&mut self, ui: &mut egui::Ui) {
        let t0 = Instant::now();
        self.frame_inner(ui);
        log::info!(target: crate::logging::FRAMES, "ui code {:.1} ms", t0.elapsed().as_secs_f64() * 1e3);
    }

    fn frame_inner(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
        let keys = menu::shortcuts(&ctx, self.dialog_up());
        self.commands.extend(keys);
        self.poll_loading();
        self.poll_mesh_loads();
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
            self.queue(AppCommand::Open(p.clone()));
        }
        if ctx.input(|i| i.viewport().close_requested()) && self.doc.is_dirty() && !self.allow_close
        {
            ctx.send_viewport_cmd(egui::ViewportCommand::CancelClose);
            self.confirm = Some(Pending::Close);
        }
        if ctx.input(|i| i.viewport().close_requested()) && self.loading.is_some() {
            self.cancel_loading();
        }
        // A drag, or a burst of wheel notches, is one undo step.
        if !ctx.input(|i| i.pointer.any_down()) && !self.viewport.tools.wheel_busy() {
            self.doc.end_gesture();
        }
        if self.doc.generation != self.panels_generation {
            // Changed by something other than the panels' own edits: fresh widget ids.
            self.widget_epoch += 1;
            self.panels_generation = self.doc.generation;
        }
        self.follow_inspected();
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
        self.run_commands(&ctx);
        egui::Panel::bottom("status").show(ui, |ui| {
            let note = self
                .note
                .as_ref()
                .filter(|(_, t)| t.elapsed() < Duration::from_secs(10))
                .map(|(n, _)| n.as_str());
            status::ui(
                ui,
                &self.doc,
                &self.worker,
                self.rows.2,
                self.show_timings,
                note,
            )
        });
        let mut asked: Vec<AppCommand> = Vec::new();
        let total = ui.available_rect_before_wrap().width();
        let tree = self.layout.tree_panel(total).show(ui, |ui| {
            ui.heading("Scene");
            let rows = std::mem::take(&mut self.rows.1);
            let reveal = match self.doc.selection {
                Some(Selection::Node(id)) if self.doc.selection != self.tree_seen => Some(id),
                _ => None,
            };
            asked.extend(tree::ui(ui, &self.doc, &rows, reveal));
            self.rows.1 = rows;
        });
        self.commands.append(&mut asked);
        self.run_commands(&ctx);
        // A row clicked in the tree is in view already: only selections made elsewhere scroll.
        self.tree_seen = self.doc.selection;
        self.layout.shown_tree(tree.response.rect.width());
        let left = ui.available_rect_before_wrap().width();
        let epoch = self.widget_epoch;
        let inspector = self.layout.inspector_panel(left).show(ui, |ui| {
            ui.heading("Inspector");
            ui.push_id(("document", epoch), |ui| {
                asked.extend(inspector::ui(ui, &self.doc))
            });
        });
        self.layout.shown_inspector(inspector.response.rect.width());
        // The height the dock takes from the view: the picture keeps the size and place it
        // had without the dock (its bottom hidden behind it), so opening the dock by a click
        // never moves or rescales what is under the pointer.
        let bottom = ui.available_rect_before_wrap().bottom();
        if self.pixel_inspector_open {
            // Docked under the view, between the side panels: it covers neither the tree nor
            // the image, and the next click in the view is free.
            let height = ui.available_rect_before_wrap().height();
            self.layout.dock_panel(height).show(ui, |ui| {
                ui.horizontal(|ui| {
                    ui.strong("Pixel inspector");
                    let mut ray = self.ray_panel_open;
                    if ui.checkbox(&mut ray, "Ray diagrams").changed() {
                        asked.push(AppCommand::ShowRayPanel(ray));
                    }
                    if ui.small_button("Close").clicked() {
                        asked.push(AppCommand::ShowPixelInspector(false));
                    }
                });
                if self.ray_panel_open {
                    // The lecture's figure, docked beside the story: never over the image.
                    let width = ui.available_width();
                    egui::Panel::right(self.layout.panel_id("ray"))
                        .resizable(true)
                        .default_size((width * 0.5).max(200.0))
                        .max_size((width - 200.0).max(200.0))
                        .show(ui, |ui| {
                            let story = self.story.as_ref().map(|(s, sc)| (s, sc.as_ref()));
                            ray_panel::ui(ui, story, &mut self.ray_orbits);
                        });
                }
                egui::ScrollArea::both()
                    .auto_shrink([false, false])
                    .show(ui, |ui| match &self.story {
                        Some((story, scene)) => pixel_inspector::ui(ui, story, scene),
                        None => {
                            ui.label("Click a pixel in the render view.");
                        }
                    });
            });
        }
        let reserve = (bottom - ui.available_rect_before_wrap().bottom()).max(0.0);
        let mut pick = None;
        let mut size = (1, 1);
        let view = egui::CentralPanel::default().show(ui, |ui| {
            let gap = self.worker.with_published(|p| p.and_then(|p| p.normal_gap));
            Viewport::toolbar(ui, &mut self.view, gap);
            if let Some(f) = self.lecture.and_then(|i| lecture::FIGURES.get(i)) {
                ui.separator();
                ui.horizontal(|ui| {
                    ui.vertical(|ui| {
                        ui.strong(f.caption);
                        ui.label(f.look[0]);
                        ui.label(f.look[1]);
                    });
                    if ui
                        .small_button("×")
                        .on_hover_text("Hide the caption")
                        .clicked()
                    {
                        asked.push(AppCommand::CloseCaption);
                    }
                });
            }
            ui.separator();
            let area = ui.available_size() + egui::vec2(0.0, reserve);
            size = Viewport::render_size(&self.view, area, ui.pixels_per_point());
            self.render_size = size;
            self.request_render(size);
            pick = self.viewport.images(
                ui,
                &mut self.view,
                &self.worker,
                &self.doc,
                &mut asked,
                reserve,
            );
        });
        notifications::ui(&ctx, &mut self.doc.messages, view.response.rect);
        self.commands.extend(asked);
        if let Some(p) = pick {
            self.queue(AppCommand::Inspect {
                frame: p.frame,
                x: p.x,
                row: p.row,
            });
        }
        self.dialogs(&ctx);
        self.run_commands(&ctx);
        // Edits and dialogs above changed the document after the view asked for its render:
        // start the new one now, not on the next input event.
        self.request_render(size);
        if self.viewport.tools.dragging() || self.viewport.tools.wheel_busy() {
            // Notice when the pointer stops, to refine.
            ctx.request_repaint_after(view_tools::STILL_AFTER / 2);
        } else if !self.worker.is_idle() || self.is_loading() {
            ctx.request_repaint_after(Duration::from_millis(30));
        } else if !self.file_watch.has_events() {
            // No file events here: look at the file on disk now and then while idle.
            ctx.request_repaint_after(file_watch::POLL_EVERY);
        }
    }
}

impl eframe::App for TracelabApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        self.frame(ui);
    }

    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        self.settings().save(storage);
    }
}

/// Opens the window (the `tracelab` command with no subcommand).
pub fn run(scene: Option<PathBuf>) -> anyhow::Result<()> {
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_inner_size([1280.0, 800.0])
            .with_min_inner_size(crate::gui::layout::MIN_WINDOW)
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
                    native_dialogs: true,
                },
            )))
        }),
    )
    .map_err(|e| anyhow::anyhow!("cannot open the window: {e}"))
}
