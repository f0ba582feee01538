//! The app's file logic: opening (read on a thread), reloading, watching, saving, exporting.

use super::*;

impl TracelabApp {
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
    pub(super) fn poll_mesh_loads(&mut self) {
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

    pub(super) fn start_loading(&mut self, path: &Path, purpose: LoadPurpose) {
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
    pub(super) fn poll_loading(&mut self) {
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
    pub(super) fn install(&mut self, read: SceneRead, reload: bool) -> bool {
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
        } else if !reload {
            self.tell_about_rays();
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

    /// A scene with mirrors or glass, opened while View › Rays traces no bounces, would show
    /// them dull without saying why: say which setting brings them out.
    fn tell_about_rays(&mut self) {
        let bounces_matter = self.doc.scene.materials.iter().any(|m| {
            m.phong().reflective != glam::Vec3::ZERO || m.phong().transparent != glam::Vec3::ZERO
        });
        if bounces_matter && self.view.secondary.bounces == 0 {
            self.doc.messages.info(
                "This scene has mirrors or glass: View › Rays (assignments 3–4) sets the \
                 bounces that show them (0 now, as the course's raytracer starts)",
            );
        }
    }

    /// Puts `path` first in Open recent, as a canonical path: an entry works from any folder
    /// tracelab is started in, and one file is one entry however it was named.
    pub(super) fn remember(&mut self, path: &Path) {
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

    pub(super) fn new_now(&mut self) {
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
    pub(super) fn save_to(&mut self, path: &Path, then: Option<Pending>) -> bool {
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

    pub(super) fn write(&mut self, path: &Path) -> bool {
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

    /// Watches the file: reload quietly when nothing is unsaved, else ask.
    /// "Keep mine" to the file-changed question: the edits stay, and the file as it is now
    /// on disk counts as seen.
    pub(super) fn keep_mine(&mut self) {
        self.disk_changed = false;
        self.doc.disk_stamp = self
            .doc
            .path
            .as_deref()
            .and_then(|p| std::fs::metadata(p).and_then(|m| m.modified()).ok());
    }

    pub(super) fn watch_disk(&mut self) {
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
}
