//! One frame of the window: menus, panels, the view, the pixel inspector's story.

use super::*;
use crate::gui::notifications::DiskAnswer;
use crate::gui::view_menus;

impl TracelabApp {
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
            self.grid_pick = self.worker.with_published(|p| grid_view::pick(p?, &at));
            self.inspected = Some(at);
            self.story = Some((story, scene));
            self.pixel_inspector_open = true;
        }
    }

    /// Traces the inspected pixel again when a newer render is published, so the story is
    /// always that of the image on screen. The selection stays as the user left it.
    pub(super) fn follow_inspected(&mut self) {
        let Some(at) = self.inspected.clone() else {
            return;
        };
        if let Some((at, story, scene)) = self
            .worker
            .with_published(|p| pixel_inspector::follow(p?, &at))
        {
            self.viewport.marker = Some((at.x, at.row));
            self.grid_pick = self.worker.with_published(|p| grid_view::pick(p?, &at));
            self.inspected = Some(at);
            self.story = Some((story, scene));
        }
    }

    /// The images the view drew in the last frame, with the pixels on screen.
    pub fn shown(&self) -> Vec<crate::gui::panels::viewport::Shown> {
        self.viewport.shown()
    }

    /// Where the view drew the axes triad and the light badges in the last frame.
    pub fn overlay_badges(&self) -> Vec<egui::Rect> {
        self.viewport.badges().to_vec()
    }

    /// Starts (or keeps) the render for the current document and view; true when a new
    /// render was started.
    pub fn request_render(&mut self, size: (u32, u32)) -> bool {
        let settings = Viewport::settings(&self.view, size);
        // While the view is being dragged, coarse passes only; the full image once it stops.
        self.worker.coarse_only = self.viewport.tools.moving();
        self.worker.grid = self.grid.request();
        let scene = &self.doc.scene;
        self.worker.request(
            self.doc.generation,
            || Arc::new(scene.clone()),
            settings,
            self.view.modes(),
        )
    }

    pub(super) fn menu(&mut self, ui: &mut egui::Ui) {
        let mut out = Vec::new();
        // Behind a dialog the menus wait too (a Modal blocks them already; the file dialog
        // is a window, so say it here).
        let free = self.dialog_up().is_none();
        egui::MenuBar::new().ui(ui, |ui| {
            ui.add_enabled_ui(free, |ui| self.menu_entries(ui, &mut out));
        });
        self.commands.extend(out);
    }

    pub(super) fn menu_entries(&self, ui: &mut egui::Ui, out: &mut Vec<AppCommand>) {
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
            ui.separator();
            // Settings, not actions: a click on one keeps the submenu open for the next.
            let keep_open = egui::containers::menu::MenuConfig::new()
                .close_behavior(egui::PopupCloseBehavior::CloseOnClickOutside);
            egui::containers::menu::SubMenuButton::new("Rays (assignments 3–4)")
                .config(keep_open.clone())
                .ui(ui, |ui| {
                    let mut rays = self.view.secondary;
                    view_menus::rays(ui, &mut rays);
                    if rays != self.view.secondary {
                        out.push(AppCommand::SetRays(rays));
                    }
                });
            egui::containers::menu::SubMenuButton::new("Uniform grid (assignments 5–6)")
                .config(keep_open.clone())
                .ui(ui, |ui| {
                    let mut grid = self.grid;
                    grid_view::menu(ui, &mut grid);
                    if grid != self.grid {
                        out.push(AppCommand::SetGrid(grid));
                    }
                });
            egui::containers::menu::SubMenuButton::new("Supersampling (assignment 7)")
                .config(keep_open)
                .ui(ui, |ui| {
                    let ss = view_menus::supersampling(ui, self.view.supersample);
                    if ss != self.view.supersample {
                        out.push(AppCommand::SetSupersampling(ss));
                    }
                });
        });
    }

    pub(super) fn messages(&mut self, ui: &mut egui::Ui) {
        if let Some(l) = &self.loading
            && crate::gui::panels::loading::ui(ui, l)
        {
            self.cancel_loading();
        }
        // The document's notices and the file-changed question are drawn over the view
        // (`notifications`), so they never push the layout down.
    }

    /// One frame of UI, shared by eframe and tests.
    pub fn frame(&mut self, ui: &mut egui::Ui) {
        let t0 = Instant::now();
        // The edit → screen timings (`TRACELAB_LOG_TIMES`): the frame after the one that
        // uploaded a finished image starts once that one is painted and presented.
        if let Some(u) = self.viewport.take_uploaded_full() {
            let ms = |d: Duration| d.as_secs_f64() * 1e3;
            log::info!(
                target: crate::logging::TIMES,
                "generation {}: on screen {:.1} ms after the edit's render was submitted: render {:.1} ms, wait for a frame {:.1} ms, upload {:.1} ms, rest of that frame's UI code {:.1} ms, paint and present {:.1} ms",
                u.generation,
                ms(t0 - u.submitted),
                ms(u.full),
                ms(u.upload_started.saturating_duration_since(u.submitted + u.full)),
                ms(u.uploaded - u.upload_started),
                ms(self.last_frame_end.map_or(Duration::ZERO, |e| e.saturating_duration_since(u.uploaded))),
                ms(self.last_frame_end.map_or(Duration::ZERO, |e| t0.saturating_duration_since(e))),
            );
        }
        let generation = self.doc.generation;
        self.frame_inner(ui);
        let end = Instant::now();
        if self.doc.generation != generation {
            log::info!(
                target: crate::logging::TIMES,
                "generation {}: edit applied and its render submitted by a frame whose UI code took {:.1} ms",
                self.doc.generation,
                ms_since(t0, end)
            );
        }
        self.last_frame_end = Some(end);
        log::info!(target: crate::logging::FRAMES, "ui code {:.1} ms", ms_since(t0, end));
    }

    pub(super) fn frame_inner(&mut self, ui: &mut egui::Ui) {
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
        // The view bar spans the window, so its groups fit two rows at 1280 wide (beside
        // the side panels they took four).
        egui::Panel::top("view-bar").show(ui, |ui| {
            let gap = self.worker.with_published(|p| p.and_then(|p| p.normal_gap));
            view_bar::ui(ui, &mut self.view, gap);
        });
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
                    if self.ray_panel_open {
                        let (text, tip) = if self.ray_window {
                            ("Dock the diagrams", "Back beside the story")
                        } else {
                            (
                                "Diagrams in a window",
                                "A window of their own: drag its corner to make them bigger",
                            )
                        };
                        if ui.small_button(text).on_hover_text(tip).clicked() {
                            asked.push(AppCommand::RayDiagramsInWindow(!self.ray_window));
                        }
                    }
                    if ui.small_button("Close").clicked() {
                        asked.push(AppCommand::ShowPixelInspector(false));
                    }
                });
                if self.ray_panel_open && !self.ray_window {
                    // The lecture's figure, docked beside the story: never over the image.
                    let width = ui.available_width();
                    egui::Panel::right(self.layout.panel_id("ray"))
                        .resizable(true)
                        .default_size((width * 0.5).max(200.0))
                        .max_size((width - 200.0).max(200.0))
                        .show(ui, |ui| {
                            let story = self.story.as_ref().map(|(s, sc)| (s, sc.as_ref()));
                            ray_panel::ui(ui, story, &mut self.ray_orbits, self.grid_pick.as_ref());
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
        if self.pixel_inspector_open && self.ray_panel_open && self.ray_window {
            let mut open = true;
            egui::Window::new("Ray diagrams")
                .id(egui::Id::unique(self.layout.panel_id("ray-window")))
                .open(&mut open)
                .resizable(true)
                .default_size([760.0, 440.0])
                .show(&ctx, |ui| {
                    let story = self.story.as_ref().map(|(s, sc)| (s, sc.as_ref()));
                    ray_panel::ui(ui, story, &mut self.ray_orbits, self.grid_pick.as_ref());
                });
            if !open {
                asked.push(AppCommand::ShowRayPanel(false));
            }
        }
        let reserve = (bottom - ui.available_rect_before_wrap().bottom()).max(0.0);
        let mut pick = None;
        let mut size = (1, 1);
        let mut started = false;
        let view = egui::CentralPanel::default().show(ui, |ui| {
            if let Some(f) = self.lecture.and_then(|i| lecture::FIGURES.get(i)) {
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
                ui.separator();
            }
            let area = ui.available_size() + egui::vec2(0.0, reserve);
            size = Viewport::render_size(&self.view, area, ui.pixels_per_point());
            self.render_size = size;
            started |= self.request_render(size);
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
        if let Some(e) = self
            .worker
            .with_published(|p| p.and_then(|p| p.grid_error.clone()))
        {
            notifications::view_warning(
                &ctx,
                view.response.rect,
                "grid",
                &format!("View › Uniform grid: {e}. The view renders through the BVH instead."),
            );
        }
        // The renderer skips a supersampled pass past the caps (samples, filter weights) and
        // keeps the one-ray image: say so over the view rather than only in the log.
        if let Some(ss) = self.view.supersample {
            let (w, h) = self.render_size;
            if let Err(e) = tracelab_core::render::check_film(w, h, &ss.sampler, &ss.filter) {
                notifications::view_warning(
                    &ctx,
                    view.response.rect,
                    "supersampling",
                    &format!(
                        "View › Supersampling at {w}×{h}: {e}. The view shows one ray a pixel."
                    ),
                );
            }
        }
        if self.disk_changed {
            match notifications::disk_changed(&ctx, view.response.rect) {
                Some(DiskAnswer::Reload) => self.queue(AppCommand::Reload),
                Some(DiskAnswer::KeepMine) => self.keep_mine(),
                None => {}
            }
        }
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
        started |= self.request_render(size);
        // A typed value, a click or a key changed what the view shows. A small scene renders
        // in a few milliseconds, and painting a frame costs more (tens of milliseconds on a
        // software rasteriser): rather than paint this frame with the old picture and the
        // next with the new one, wait a little for the render and lay this frame out again
        // with it (egui discards this pass and runs another before painting). Not while a
        // pointer drags or the wheel turns: those frames keep the coarse passes flowing.
        let gesture = ctx.input(|i| i.pointer.any_down())
            || self.viewport.tools.dragging()
            || self.viewport.tools.wheel_busy();
        if started && !gesture && !ctx.will_discard() {
            self.worker.wait_for_full(SAME_FRAME_BUDGET);
            ctx.request_discard("the edit's picture is ready: show it in this frame");
        }
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

/// How long a frame that changed the picture waits for the render to finish, so that it is
/// painted with the new picture instead of the old one (see `frame_inner`).
const SAME_FRAME_BUDGET: Duration = Duration::from_millis(25);

fn ms_since(a: Instant, b: Instant) -> f64 {
    b.saturating_duration_since(a).as_secs_f64() * 1e3
}
