//! The render view (centre): view tabs, the normal-transform switch, compare modes, depth
//! range and size controls, the images themselves (uploaded as textures when the worker has
//! new pixels), and picking.

use tracelab_core::render::{MAX_IMAGE_SIDE, NormalGap, Secondary, check_image_size};
use tracelab_core::{NormalTransform, ObjectRays, RenderSettings, View};

use crate::document::{Document, Selection};
use crate::gui::command::AppCommand;
use crate::gui::gizmo::Axes;
use crate::gui::on_screen::OnScreen;
use crate::gui::overlays;
use crate::gui::view_tools::ViewTools;
use crate::gui::widgets::number;
use crate::render_worker::{Published, RenderWorker};

#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Tab {
    Color,
    Normals,
    Depth,
    All,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Compare {
    Off,
    SideBySide,
    Split,
}

/// The render view's settings. Three are kept between runs (`gui/settings.rs`): the tab,
/// shade back and the depth range; the others start at their defaults every run.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewSettings {
    pub tab: Tab,
    pub compare: Compare,
    pub normal_transform: NormalTransform,
    /// How rays enter object space and which t is kept (the lecture's depth question).
    pub object_rays: ObjectRays,
    pub shade_back: bool,
    pub depth: (f32, f32),
    /// `None`: follow the view's size in pixels.
    pub fixed_size: Option<(u32, u32)>,
    /// Split position in compare-split mode, 0..1 from the left.
    pub split: f32,
    /// The gizmo's arrows along the world's axes or the Translate's own.
    pub gizmo_axes: Axes,
    /// Draw the gizmo and the overlays (outline, axes, lights).
    pub overlays: bool,
    /// Shadows, bounces, weight and the specular fix (View › Rays); the course's defaults.
    pub secondary: Secondary,
    /// Assignment 7's sampler and filter (View › Supersampling); `None`: one ray a pixel.
    pub supersample: Option<tracelab_core::render::Supersampling>,
}

impl Default for ViewSettings {
    fn default() -> Self {
        ViewSettings {
            tab: Tab::Color,
            compare: Compare::Off,
            normal_transform: NormalTransform::Correct,
            object_rays: ObjectRays::Unnormalized,
            shade_back: false,
            depth: (8.0, 18.0),
            fixed_size: None,
            split: 0.5,
            gizmo_axes: Axes::World,
            overlays: true,
            secondary: Secondary::default(),
            supersample: None,
        }
    }
}

/// The depth-t rules as the toolbar names them.
pub fn object_rays_label(r: ObjectRays) -> &'static str {
    match r {
        ObjectRays::Unnormalized => "unnormalised: t_OS = t_WS",
        ObjectRays::Normalized => "normalised, t rescaled",
        ObjectRays::NormalizedNoRescale => "normalised, t not rescaled (bug)",
    }
}

impl ViewSettings {
    /// The renders needed: one, or both rules when comparing.
    pub fn modes(&self) -> Vec<NormalTransform> {
        match self.compare {
            Compare::Off => vec![self.normal_transform],
            _ => vec![NormalTransform::Correct, NormalTransform::Incorrect],
        }
    }

    /// (frame index, view, caption) for each image cell.
    pub fn cells(&self) -> Vec<(usize, View, &'static str)> {
        let single = match self.tab {
            Tab::Color => View::Color,
            Tab::Normals | Tab::All => View::Normals,
            Tab::Depth => View::Depth,
        };
        match (self.compare, self.tab) {
            (Compare::Off, Tab::All) => {
                vec![
                    (0, View::Color, "Colour"),
                    (0, View::Normals, "Normals"),
                    (0, View::Depth, "Depth"),
                ]
            }
            (Compare::Off, _) => vec![(0, single, "")],
            (Compare::SideBySide, _) => vec![
                (0, single, "Correct: (M^-1)^T n"),
                (1, single, "Incorrect: M n"),
            ],
            // Split draws both frames into one cell.
            (Compare::Split, _) => vec![(0, single, "Correct (left) | Incorrect (right)")],
        }
    }
}

/// What a click in the view asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Pick {
    pub frame: usize,
    pub x: u32,
    pub row: u32,
}

/// (render request, frame version, view, depth range bits): what a texture holds. The
/// request, not the document generation, names the render: a change of normal rule, shade
/// back or size re-renders the same generation into new frames whose version counters
/// start again, so a key by generation once kept the old picture on screen.
type UploadKey = (u64, u64, View, (u32, u32));

/// One image drawn in the view: a texture, the screen rectangle it filled and the part of
/// the texture shown there (split mode shows a part of each rule's image).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Drawn {
    texture: usize,
    pub rect: egui::Rect,
    pub uv: egui::Rect,
}

impl Drawn {
    /// The part of `rect` (showing `uv` of the texture) inside `clip`, with its own uv.
    fn clipped(texture: usize, rect: egui::Rect, uv: egui::Rect, clip: egui::Rect) -> Self {
        let shown = rect.intersect(clip);
        let at = |p: egui::Pos2| {
            let t = (p - rect.min) / rect.size();
            uv.min + t * uv.size()
        };
        Drawn {
            texture,
            rect: shown,
            uv: egui::Rect::from_min_max(at(shown.min), at(shown.max)),
        }
    }
}

/// Pixels the view put on screen: what the texture held when it was drawn.
#[derive(Clone, Debug)]
pub struct Shown {
    pub rect: egui::Rect,
    pub uv: egui::Rect,
    pub image: std::sync::Arc<egui::ColorImage>,
}

impl Shown {
    /// The image as RGB bytes, rows from the top (the layout of `Frame::rgb8`).
    pub fn rgb8(&self) -> Vec<u8> {
        self.image
            .pixels
            .iter()
            .flat_map(|c| [c.r(), c.g(), c.b()])
            .collect()
    }

    pub fn size(&self) -> [usize; 2] {
        self.image.size
    }
}

/// Texture state: what is on the GPU, so unchanged pixels are not uploaded again.
#[derive(Default)]
pub struct Viewport {
    textures: Vec<Option<egui::TextureHandle>>,
    /// Per texture: (request, frame version, view, depth range) last uploaded.
    uploaded: Vec<Option<UploadKey>>,
    /// Per texture: the pixels last uploaded, so tests can read what the view shows.
    images: Vec<Option<std::sync::Arc<egui::ColorImage>>>,
    /// What the last frame drew: each texture, where, and which part of it.
    drawn: Vec<Drawn>,
    /// Size of the image shown, in pixels.
    pub shown_size: (u32, u32),
    /// The pixel being inspected, marked in every image.
    pub marker: Option<(u32, u32)>,
    /// Generation of the image on screen, for the edit→screen timing log.
    shown_generation: u64,
    /// Orbit, pan, zoom and the gizmo's drags.
    pub tools: ViewTools,
    /// The selection's outline, and what it was made from (request, passes, selection,
    /// generation).
    outline: Option<egui::TextureHandle>,
    outline_key: Option<(u64, u64, Option<Selection>, u64)>,
}

impl Viewport {
    /// The toolbar. `gap` is the largest angle between the two normal rules over the
    /// pixels of the image on screen, once computed.
    pub fn toolbar(ui: &mut egui::Ui, s: &mut ViewSettings, gap: Option<NormalGap>) {
        ui.horizontal_wrapped(|ui| {
            for (tab, name) in [
                (Tab::Color, "Colour"),
                (Tab::Normals, "Normals"),
                (Tab::Depth, "Depth"),
                (Tab::All, "All three"),
            ] {
                ui.selectable_value(&mut s.tab, tab, name);
            }
            ui.separator();
            ui.label("Normal transform:");
            // Compare mode shows both rules, so the switch has nothing to choose there.
            ui.add_enabled_ui(s.compare == Compare::Off, |ui| {
                ui.selectable_value(
                    &mut s.normal_transform,
                    NormalTransform::Correct,
                    "Correct (M^-1)^T",
                );
                ui.selectable_value(
                    &mut s.normal_transform,
                    NormalTransform::Incorrect,
                    "Incorrect M",
                );
            });
            // Never broken over two rows of the bar.
            let gap_text = match gap {
                Some(g) if g.degrees == 0.0 => "0° apart: all similitudes".to_string(),
                Some(g) => format!("up to {:.2}° apart", g.degrees),
                None => "…".to_string(),
            };
            ui.add(egui::Label::new(gap_text).extend())
            .on_hover_text("The largest angle between (M^-1)^T·n and M·n over the visible pixels (0 exactly when every transform on screen is a similitude)");
            ui.separator();
            egui::ComboBox::from_label("compare")
                .selected_text(match s.compare {
                    Compare::Off => "off",
                    Compare::SideBySide => "side by side",
                    Compare::Split => "split",
                })
                .show_ui(ui, |ui| {
                    ui.selectable_value(&mut s.compare, Compare::Off, "off");
                    ui.selectable_value(&mut s.compare, Compare::SideBySide, "side by side");
                    ui.selectable_value(&mut s.compare, Compare::Split, "split");
                });
        });
        ui.horizontal_wrapped(|ui| {
            // The lecture's "what to do about the depth t", for both images when comparing.
            egui::ComboBox::from_label("depth t")
                .selected_text(object_rays_label(s.object_rays))
                .show_ui(ui, |ui| {
                    for r in ObjectRays::ALL {
                        ui.selectable_value(&mut s.object_rays, r, object_rays_label(r));
                    }
                });
            ui.checkbox(&mut s.overlays, "gizmo & overlays");
            ui.add_enabled_ui(s.overlays, |ui| {
                ui.selectable_value(&mut s.gizmo_axes, Axes::World, "world axes")
                    .on_hover_text("The gizmo's arrows move along the world's x, y and z");
                ui.selectable_value(&mut s.gizmo_axes, Axes::Local, "local axes")
                    .on_hover_text("The gizmo's arrows move along the Translate's own axes (its Transform's space)");
            });
            ui.separator();
            ui.checkbox(&mut s.shade_back, "shade back");
            ui.separator();
            // "depth" inside the first value, so no lone label ends a row of the bar.
            number(ui, &mut s.depth.0, |d| d.speed(0.05).prefix("depth min "));
            number(ui, &mut s.depth.1, |d| d.speed(0.05).prefix("max "));
            ui.separator();
            let mut fixed = s.fixed_size.is_some();
            if ui.checkbox(&mut fixed, "fixed size").changed() {
                s.fixed_size = fixed.then_some((200, 200));
            }
            let error_id = ui.make_persistent_id("fixed-size-refused");
            if let Some(size) = &mut s.fixed_size {
                let before = *size;
                // Whole numbers only: "nan" once parsed, was clamped and became 4096.
                let parse = |t: &str| t.trim().parse::<f64>().ok().filter(|v| v.is_finite());
                let side = 1..=MAX_IMAGE_SIDE;
                number(ui, &mut size.0, |d| d.range(side.clone()).custom_parser(parse).suffix(" w"));
                number(ui, &mut size.1, |d| d.range(side).custom_parser(parse).suffix(" h"));
                if *size != before {
                    // The same limits as the command line: refuse, keep the last good size, say why.
                    let refused = check_image_size(size.0, size.1).err().map(|e| e.to_string());
                    if refused.is_some() {
                        *size = before;
                    }
                    ui.data_mut(|d| d.insert_temp(error_id, refused));
                }
                if let Some(e) = ui.data(|d| d.get_temp::<Option<String>>(error_id)).flatten() {
                    ui.colored_label(ui.visuals().error_fg_color, e);
                }
            }
        });
    }

    /// The render size for the space available (in points), per the settings.
    pub fn render_size(s: &ViewSettings, avail: egui::Vec2, pixels_per_point: f32) -> (u32, u32) {
        if let Some(size) = s.fixed_size {
            return size;
        }
        let n = match (s.compare, s.tab) {
            (Compare::Off, Tab::All) => 3.0,
            (Compare::SideBySide, _) => 2.0,
            _ => 1.0,
        };
        let caption = if n > 1.0 { 18.0 } else { 0.0 };
        let w = (avail.x / n - 4.0).max(8.0) * pixels_per_point;
        let h = (avail.y - caption).max(8.0) * pixels_per_point;
        if n > 1.0 {
            // Several cells side by side are tall and narrow; the camera spans the larger
            // side and crops the other, so a non-square cell would cut the scene off at the
            // sides. Square cells show all of it, as the course's square images do.
            let side = w.min(h) as u32;
            return (side, side);
        }
        (w as u32, h as u32)
    }

    /// Draws the images with the gizmo and overlays, queues what the mouse tools ask for,
    /// and returns a pick when the user clicked a pixel. `hidden_below`: the height a panel
    /// under the view (the dock) takes from it; the images are laid out as if it were not
    /// there and clipped, so that panel never moves or rescales them.
    pub fn images(
        &mut self,
        ui: &mut egui::Ui,
        s: &mut ViewSettings,
        worker: &RenderWorker,
        doc: &Document,
        out: &mut Vec<AppCommand>,
        hidden_below: f32,
    ) -> Option<Pick> {
        let cells = s.cells();
        let ctx = ui.ctx().clone();
        let mut pick = None;
        self.drawn.clear();
        self.tools.begin_frame();
        worker.with_published(|p| {
            let Some(p) = p else {
                match worker.spawn_error() {
                    Some(e) => ui.colored_label(
                        ui.visuals().error_fg_color,
                        format!("cannot start the renderer: {e}"),
                    ),
                    None => ui.label("Rendering…"),
                };
                return;
            };
            self.upload(&ctx, p, s);
            if s.overlays {
                self.upload_outline(&ctx, p, doc);
            } else {
                self.outline = None;
            }
        });
        let avail = ui.available_size();
        let n = cells.len() as f32;
        // Cells sit item_spacing apart; leave room for the gaps so the last one fits.
        let gap = ui.spacing().item_spacing.x;
        let cell_w = ((avail.x - gap * (n - 1.0)) / n).floor();
        let ppp = ui.pixels_per_point();
        ui.horizontal_top(|ui| {
            for (ci, &(frame, view, caption)) in cells.iter().enumerate() {
                let (cell, resp) = ui.allocate_exact_size(
                    egui::vec2(cell_w, avail.y),
                    egui::Sense::click_and_drag(),
                );
                let mut img_area = cell;
                img_area.max.y += hidden_below;
                let painter = ui.painter().with_clip_rect(cell.intersect(ui.clip_rect()));
                if !caption.is_empty() {
                    ui.painter().text(
                        cell.left_top() + egui::vec2(4.0, 2.0),
                        egui::Align2::LEFT_TOP,
                        caption,
                        egui::FontId::proportional(13.0),
                        ui.visuals().text_color(),
                    );
                    img_area.min.y += 18.0;
                }
                let tex_i = self.tex_index(frame, view);
                let Some(Some(tex)) = self.textures.get(tex_i) else {
                    continue;
                };
                let [w, h] = tex.size();
                // View-sized renders show 1:1 (or scaled down to fit); a fixed size (say the
                // handout's 200×200) is scaled up to fill the view, pixels kept sharp.
                let size = egui::vec2(w as f32, h as f32) / ppp;
                let fit = (img_area.width() / size.x).min(img_area.height() / size.y);
                let scale = if s.fixed_size.is_some() {
                    fit
                } else {
                    fit.min(1.0)
                };
                let rect = egui::Rect::from_center_size(img_area.center(), size * scale);
                let uv = egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
                if s.compare == Compare::Split {
                    let other = self
                        .textures
                        .get(self.tex_index(1, view))
                        .and_then(Option::as_ref);
                    let xs = rect.left() + rect.width() * s.split;
                    let left = egui::Rect::from_min_max(rect.min, egui::pos2(xs, rect.max.y));
                    let right = egui::Rect::from_min_max(egui::pos2(xs, rect.min.y), rect.max);
                    let luv =
                        egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(s.split, 1.0));
                    let ruv =
                        egui::Rect::from_min_max(egui::pos2(s.split, 0.0), egui::pos2(1.0, 1.0));
                    painter.image(tex.id(), left, luv, egui::Color32::WHITE);
                    self.drawn.push(Drawn::clipped(tex_i, left, luv, cell));
                    if let Some(o) = other {
                        painter.image(o.id(), right, ruv, egui::Color32::WHITE);
                        let texture = self.tex_index(1, view);
                        self.drawn.push(Drawn::clipped(texture, right, ruv, cell));
                    }
                    painter.vline(
                        xs,
                        rect.y_range(),
                        egui::Stroke::new(2.0, egui::Color32::YELLOW),
                    );
                    if resp.dragged()
                        && let Some(pos) = resp.interact_pointer_pos()
                    {
                        s.split = ((pos.x - rect.left()) / rect.width()).clamp(0.0, 1.0);
                    }
                } else {
                    painter.image(tex.id(), rect, uv, egui::Color32::WHITE);
                    self.drawn.push(Drawn::clipped(tex_i, rect, uv, cell));
                }
                let view = OnScreen::new(&doc.scene.camera, w as u32, h as u32, rect);
                let surface = |px: glam::Vec2| surface_point(worker, frame, px);
                let used = self
                    .tools
                    .cell(ui, &resp, ci, &view, doc, s.gizmo_axes, &surface, out);
                if s.overlays {
                    let painter = painter.with_clip_rect(rect.intersect(painter.clip_rect()));
                    if let Some(o) = &self.outline {
                        painter.image(o.id(), rect, uv, egui::Color32::WHITE);
                    }
                    overlays::triad(&painter, &view.basis, rect);
                    overlays::lights(&painter, &view.basis, rect, &doc.scene);
                    if let Some(g) = ViewTools::gizmo(doc, &view, s.gizmo_axes) {
                        g.paint(&painter, &view, self.tools.hot);
                    }
                    overlays::point_lights(&painter, &view, &doc.scene, doc.selection);
                    if let Some(g) = ViewTools::light_gizmo(doc, &view) {
                        g.paint(&painter, &view, self.tools.hot);
                    }
                }
                if let Some((mx, my)) = self.marker {
                    let c = rect.min
                        + egui::vec2(
                            (mx as f32 + 0.5) / w as f32 * rect.width(),
                            (my as f32 + 0.5) / h as f32 * rect.height(),
                        );
                    let stroke = egui::Stroke::new(1.5, egui::Color32::from_rgb(255, 0, 255));
                    painter.circle_stroke(c, 6.0, stroke);
                    painter.hline((c.x - 10.0)..=(c.x - 3.0), c.y, stroke);
                    painter.hline((c.x + 3.0)..=(c.x + 10.0), c.y, stroke);
                    painter.vline(c.x, (c.y - 10.0)..=(c.y - 3.0), stroke);
                    painter.vline(c.x, (c.y + 3.0)..=(c.y + 10.0), stroke);
                }
                if resp.clicked()
                    && !used
                    && let Some(pos) = resp
                        .interact_pointer_pos()
                        .filter(|p| rect.contains(*p) && cell.contains(*p))
                {
                    let u = (pos.x - rect.left()) / rect.width();
                    let v = (pos.y - rect.top()) / rect.height();
                    let frame = if s.compare == Compare::Split && u > s.split {
                        1
                    } else {
                        frame
                    };
                    let x = ((u * w as f32) as u32).min(w as u32 - 1);
                    let row = ((v * h as f32) as u32).min(h as u32 - 1);
                    pick = Some(Pick { frame, x, row });
                }
            }
        });
        pick
    }

    /// The outline of the selection, made again when the pixels or the selection change.
    fn upload_outline(&mut self, ctx: &egui::Context, p: &Published, doc: &Document) {
        // The image on screen stays the previous one until a pass is done; so does its outline.
        let Some(frame) = p.frames.first().filter(|_| p.passes_done > 0) else {
            return;
        };
        // Once a pass, not once a tile: it runs over every pixel.
        let key = Some((
            p.job.request,
            p.passes_done as u64,
            doc.selection,
            doc.generation,
        ));
        if self.outline_key == key {
            return;
        }
        self.outline_key = key;
        let ids = match doc.selection {
            Some(Selection::Node(id)) => overlays::subtree_ids(&doc.scene, id),
            _ => Default::default(),
        };
        let image = overlays::outline(&frame.lock(), &ids);
        self.outline = image.map(|img| match self.outline.take() {
            Some(mut t) => {
                t.set(img, egui::TextureOptions::NEAREST);
                t
            }
            None => ctx.load_texture("selection-outline", img, egui::TextureOptions::NEAREST),
        });
    }

    /// The images the last frame drew, in drawing order, with the pixels their textures
    /// held: what the user sees, not what the renderer has.
    pub fn shown(&self) -> Vec<Shown> {
        self.drawn
            .iter()
            .filter_map(|d| {
                let image = self.images.get(d.texture)?.clone()?;
                Some(Shown {
                    rect: d.rect,
                    uv: d.uv,
                    image,
                })
            })
            .collect()
    }

    fn tex_index(&self, frame: usize, view: View) -> usize {
        frame * 3
            + match view {
                View::Color => 0,
                View::Normals => 1,
                View::Depth => 2,
            }
    }

    /// Uploads the views the cells need whenever their pixels changed. The previous image
    /// stays until a new render has completed its first (coarse) pass.
    fn upload(&mut self, ctx: &egui::Context, p: &Published, s: &ViewSettings) {
        if p.passes_done == 0 {
            return;
        }
        let mut need: Vec<(usize, View)> = s.cells().iter().map(|&(f, v, _)| (f, v)).collect();
        if s.compare == Compare::Split {
            need.extend(s.cells().iter().map(|&(_, v, _)| (1, v)));
        }
        for (frame_i, view) in need {
            let Some(frame) = p.frames.get(frame_i) else {
                continue;
            };
            let i = self.tex_index(frame_i, view);
            if self.textures.len() <= i {
                self.textures.resize_with(i + 1, || None);
                self.uploaded.resize(i + 1, None);
                self.images.resize(i + 1, None);
            }
            let depth_key = (s.depth.0.to_bits(), s.depth.1.to_bits());
            let key = Some((p.job.request, frame.version(), view, depth_key));
            if self.uploaded[i] == key {
                continue;
            }
            let (w, h, rgba) = {
                let f = frame.lock();
                (f.width, f.height, f.rgba8(view, s.depth))
            };
            if w == 0 || h == 0 {
                continue;
            }
            let image = std::sync::Arc::new(egui::ColorImage::from_rgba_unmultiplied(
                [w as usize, h as usize],
                &rgba,
            ));
            self.images[i] = Some(image.clone());
            match &mut self.textures[i] {
                Some(t) => t.set(image, egui::TextureOptions::NEAREST),
                slot => {
                    *slot = Some(ctx.load_texture(
                        format!("view-{i}"),
                        image,
                        egui::TextureOptions::NEAREST,
                    ))
                }
            }
            self.uploaded[i] = key;
            self.shown_size = (w, h);
        }
        if p.job.generation != self.shown_generation {
            self.shown_generation = p.job.generation;
            if log::log_enabled!(target: crate::logging::TIMES, log::Level::Info) {
                log::info!(
                    target: crate::logging::TIMES,
                    "generation {} on screen {:.1} ms after the edit (last frame took {:.1} ms)",
                    p.job.generation,
                    p.job.submitted.elapsed().as_secs_f64() * 1e3,
                    ctx.input(|i| i.unstable_dt) * 1e3
                );
            }
        }
    }

    /// The settings the worker should render with.
    pub fn settings(s: &ViewSettings, size: (u32, u32)) -> RenderSettings {
        RenderSettings {
            width: size.0.max(1),
            height: size.1.max(1),
            shade_back: s.shade_back,
            normal_transform: s.normal_transform,
            object_rays: s.object_rays,
            variant: None,
            secondary: s.secondary,
            supersample: s.supersample,
        }
    }
}

/// The world point the image on screen shows at pixel `px` of frame `frame`, from the render
/// itself (its camera and the hit's t); `None` over the background.
fn surface_point(worker: &RenderWorker, frame: usize, px: glam::Vec2) -> Option<glam::Vec3> {
    worker.with_published(|p| {
        let p = p?;
        let f = p.frames.get(frame)?.lock();
        if px.x < 0.0 || px.y < 0.0 {
            return None;
        }
        let (x, row) = (px.x as u32, px.y as u32);
        let t = f.get(x, row)?.t;
        if !t.is_finite() {
            return None;
        }
        let ray = p.compiled.camera.pixel_ray(x, row, f.width, f.height);
        Some(ray.origin + ray.direction * t)
    })
}
