//! Command handling: [`AppCommand`]s carried out, the one place the UI changes the app
//! (edits through `Document::apply`, which records undo).

use super::*;

impl TracelabApp {
    pub(super) fn run_command(&mut self, command: AppCommand, ctx: &egui::Context) {
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
            AppCommand::AnimationDialog => {
                // An op sweep needs a Transform; without one the form offers the bounce sweep.
                let transform = match self.doc.selection {
                    Some(Selection::Node(id))
                        if matches!(
                            self.doc.scene.graph.get(id).map(|n| &n.kind),
                            Some(NodeKind::Transform(_))
                        ) =>
                    {
                        Some(id)
                    }
                    _ => None,
                };
                self.animation = Some(AnimationForm::new(transform, self.view.secondary.bounces));
            }
            AppCommand::StartAnimation(form) => {
                if self.animation_running.is_none() {
                    let size = self.view.fixed_size.unwrap_or(self.viewport.shown_size());
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
            AppCommand::RayDiagramsInWindow(w) => self.ray_window = w,
            AppCommand::SetRays(rays) => self.view.secondary = rays,
            AppCommand::SetGrid(grid) => self.grid = grid,
            AppCommand::SetSupersampling(ss) => self.view.supersample = ss,
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
    pub(super) fn frame_node(&mut self, node: tracelab_core::NodeId) {
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
    pub(super) fn gizmo_edit(
        &mut self,
        node: tracelab_core::NodeId,
        op: tracelab_core::TransformOp,
    ) {
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
}
