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
mod commands;
mod dialogs;
mod files;
mod ui;

use crate::gui::animation_dialog::{self, AnimationForm};
use crate::gui::command::AppCommand;
use crate::gui::file_dialog::{FileDialog, Purpose};
use crate::gui::file_watch::{self, FileWatch};
use crate::gui::grid_view::{self, GridPick, GridSettings};
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
use crate::gui::panels::{inspector, pixel_inspector, ray_panel, status, tree, view_bar};
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
    doc: Document,
    worker: RenderWorker,
    view: ViewSettings,
    viewport: Viewport,
    /// The last pixel inspected and the scene snapshot it was traced in.
    story: Option<(RayStory, Arc<Scene>)>,
    /// Which pixel that is and the render it was traced in: every new render traces it again.
    inspected: Option<Inspected>,
    pixel_inspector_open: bool,
    /// The Ray panel (world and object space diagrams) in the dock, beside the story.
    ray_panel_open: bool,
    /// The Ray panel's diagrams in their own window instead of the dock.
    ray_window: bool,
    /// File › Export animation's form, while open, and the export under way.
    animation: Option<AnimationForm>,
    animation_running: Option<animation_dialog::Running>,
    /// The Lecture menu's figure on show, for its caption.
    lecture: Option<usize>,
    /// A figure whose scene is being read (or waits for the unsaved-changes answer): its view
    /// and caption are applied when that scene is installed, and dropped if it is not.
    pending_lecture: Option<usize>,
    /// View › Uniform grid: the course's grid instead of the BVH, or its picture.
    grid: GridSettings,
    /// The grid and the inspected pixel's walk through it, while the render on screen went
    /// through a grid (drawn in the Ray panel's world diagram).
    grid_pick: Option<GridPick>,
    /// How each Ray diagram (world, object) is turned.
    ray_orbits: [Orbit; 2],
    dialog: Option<FileDialog>,
    native: Option<NativeDialog>,
    native_dialogs: bool,
    confirm: Option<Pending>,
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
    recent: Vec<PathBuf>,
    rows: (u64, Vec<TreeRow>, (usize, usize, usize)),
    file_watch: FileWatch,
    /// The file changed on disk while there were unsaved edits: ask before reloading.
    disk_changed: bool,
    title: String,
    allow_close: bool,
    /// The selection the tree last showed, to scroll to selections made elsewhere.
    tree_seen: Option<Selection>,
    /// Timings in the status bar; snapshot tests turn them off to stay deterministic.
    show_timings: bool,
    /// What the UI asked for this frame, carried out by [`Self::run_commands`].
    commands: Vec<AppCommand>,
    /// A note for the status bar (what a gizmo drag added), and when it was made.
    note: Option<(String, Instant)>,
    /// The size the view renders at, for framing.
    render_size: (u32, u32),
    /// When the last frame's UI code ended (the edit → screen timing log).
    last_frame_end: Option<Instant>,
}

/// What other modules and the tests read and set; the fields are the app's own.
impl TracelabApp {
    pub fn doc(&self) -> &Document {
        &self.doc
    }

    /// The document itself (tests select or edit directly; the panels go through commands).
    pub fn doc_mut(&mut self) -> &mut Document {
        &mut self.doc
    }

    pub fn worker(&self) -> &RenderWorker {
        &self.worker
    }

    /// The render worker (a test swaps in one that failed to start).
    pub fn worker_mut(&mut self) -> &mut RenderWorker {
        &mut self.worker
    }

    pub fn view(&self) -> &ViewSettings {
        &self.view
    }

    pub fn view_mut(&mut self) -> &mut ViewSettings {
        &mut self.view
    }

    /// The last pixel inspected and the scene snapshot it was traced in.
    pub fn story(&self) -> Option<&(RayStory, Arc<Scene>)> {
        self.story.as_ref()
    }

    /// View › Uniform grid's setting.
    pub fn grid(&self) -> &GridSettings {
        &self.grid
    }

    /// The picked pixel's walk through the grid, when the view renders through one.
    pub fn grid_pick(&self) -> Option<&GridPick> {
        self.grid_pick.as_ref()
    }

    /// The pixel the pixel inspector describes.
    pub fn inspected(&self) -> Option<&Inspected> {
        self.inspected.as_ref()
    }

    /// Whether the Ray panel's diagrams are in their own window instead of the dock.
    pub fn ray_window(&self) -> bool {
        self.ray_window
    }

    /// Whether the file changed on disk while there are unsaved edits (the question is up).
    pub fn disk_changed(&self) -> bool {
        self.disk_changed
    }

    pub fn pixel_inspector_open(&self) -> bool {
        self.pixel_inspector_open
    }

    /// File › Export animation's form, while open.
    pub fn animation(&self) -> Option<&AnimationForm> {
        self.animation.as_ref()
    }

    pub fn set_animation(&mut self, form: Option<AnimationForm>) {
        self.animation = form;
    }

    /// Whether an animation export is under way.
    pub fn animation_running(&self) -> bool {
        self.animation_running.is_some()
    }

    /// The Lecture menu's figure on show.
    pub fn lecture(&self) -> Option<usize> {
        self.lecture
    }

    pub fn dialog(&self) -> Option<&FileDialog> {
        self.dialog.as_ref()
    }

    pub fn set_dialog(&mut self, dialog: Option<FileDialog>) {
        self.dialog = dialog;
    }

    /// The question waiting for an answer (unsaved changes, a lossy save).
    pub fn confirm(&self) -> Option<&Pending> {
        self.confirm.as_ref()
    }

    /// Recently opened files, newest first.
    pub fn recent(&self) -> &[PathBuf] {
        &self.recent
    }

    /// The status bar's note (what a gizmo drag added), while it shows.
    pub fn note(&self) -> Option<&str> {
        self.note.as_ref().map(|(text, _)| text.as_str())
    }

    /// Timings in the status bar (snapshot tests turn them off to stay deterministic).
    pub fn set_show_timings(&mut self, on: bool) {
        self.show_timings = on;
    }
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
            ray_window: false,
            ray_orbits: [Orbit::default(); 2],
            grid: GridSettings::default(),
            grid_pick: None,
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
            last_frame_end: None,
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

    pub(super) fn apply_settings(&mut self, s: Settings) {
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
