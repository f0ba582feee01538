//! The render view (centre): the images themselves, drawn from the texture cache
//! (`view_textures.rs`) with the gizmo and overlays, and picking. The view bar is
//! `view_bar.rs`; the settings both share are `view_settings.rs`.

use tracelab_core::RenderSettings;

use crate::document::Document;
use crate::gui::command::AppCommand;
use crate::gui::on_screen::OnScreen;
use crate::gui::overlays;
use crate::gui::panels::view_textures::{self, ViewTextures};
use crate::gui::view_tools::ViewTools;
use crate::render_worker::RenderWorker;

pub use crate::gui::panels::view_settings::{
    Compare, SplitLine, Tab, ViewSettings, object_rays_label,
};

/// What a click in the view asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Pick {
    pub frame: usize,
    pub x: u32,
    pub row: u32,
}

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

/// The view's state: the texture cache, what the last frame drew, the marker and the tools.
#[derive(Default)]
pub struct Viewport {
    textures: ViewTextures,
    /// What the last frame drew: each texture, where, and which part of it.
    drawn: Vec<Drawn>,
    /// Where the last frame drew the triad and light badges.
    badges: Vec<egui::Rect>,
    /// The pixel being inspected, marked in every image.
    pub marker: Option<(u32, u32)>,
    /// Orbit, pan, zoom and the gizmo's drags.
    pub tools: ViewTools,
}

impl Viewport {
    /// Timing log: a finished image uploaded last frame, taken once.
    pub fn take_uploaded_full(&mut self) -> Option<view_textures::UploadedFull> {
        self.textures.uploaded_full.take()
    }

    /// Size of the image shown, in pixels.
    pub fn shown_size(&self) -> (u32, u32) {
        self.textures.shown_size
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
        self.badges.clear();
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
            self.textures.upload(&ctx, p, s);
            if s.overlays {
                self.textures.upload_outline(&ctx, p, doc);
            } else {
                self.textures.drop_outline();
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
                let tex_i = view_textures::index(frame, view);
                let Some(tex) = self.textures.get(tex_i) else {
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
                    let other_i = view_textures::index(1, view);
                    let other = self.textures.get(other_i);
                    // The correct rule's part (left or above the line) and the incorrect one's.
                    let (first, second) = split_halves(rect, s.split_line, s.split);
                    let (first_uv, second_uv) = split_halves(uv, s.split_line, s.split);
                    painter.image(tex.id(), first, first_uv, egui::Color32::WHITE);
                    self.drawn
                        .push(Drawn::clipped(tex_i, first, first_uv, cell));
                    if let Some(o) = other {
                        painter.image(o.id(), second, second_uv, egui::Color32::WHITE);
                        self.drawn
                            .push(Drawn::clipped(other_i, second, second_uv, cell));
                    }
                    let line = egui::Stroke::new(2.0, egui::Color32::YELLOW);
                    match s.split_line {
                        SplitLine::Vertical => {
                            painter.vline(first.right(), rect.y_range(), line);
                        }
                        SplitLine::Horizontal => {
                            painter.hline(rect.x_range(), first.bottom(), line);
                        }
                    }
                    if resp.dragged()
                        && let Some(pos) = resp.interact_pointer_pos()
                    {
                        let t = (pos - rect.min) / rect.size();
                        s.split = match s.split_line {
                            SplitLine::Vertical => t.x,
                            SplitLine::Horizontal => t.y,
                        }
                        .clamp(0.0, 1.0);
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
                    if let Some(o) = self.textures.outline() {
                        painter.image(o.id(), rect, uv, egui::Color32::WHITE);
                    }
                    let shows_object = |r: egui::Rect| shows_object(worker, frame, rect, r);
                    let badges = overlays::place_badges(
                        rect.intersect(cell),
                        overlays::directional_lights(&doc.scene),
                        &shows_object,
                    );
                    if let Some(o) = badges.triad {
                        overlays::triad(&painter, &view.basis, o, badges.radius);
                    }
                    overlays::lights(
                        &painter,
                        &view.basis,
                        &badges.lights,
                        badges.radius,
                        &doc.scene,
                    );
                    self.badges.extend(badges.rects());
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
                    let across = match s.split_line {
                        SplitLine::Vertical => u,
                        SplitLine::Horizontal => v,
                    };
                    let frame = if s.compare == Compare::Split && across > s.split {
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

    /// The images the last frame drew, in drawing order, with the pixels their textures
    /// held: what the user sees, not what the renderer has.
    pub fn shown(&self) -> Vec<Shown> {
        self.drawn
            .iter()
            .filter_map(|d| {
                let image = self.textures.image(d.texture)?;
                Some(Shown {
                    rect: d.rect,
                    uv: d.uv,
                    image,
                })
            })
            .collect()
    }

    /// Where the last frame drew the axes triad and the light badges.
    pub fn badges(&self) -> &[egui::Rect] {
        &self.badges
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

/// Whether the part `r` (screen points) of an image drawn in `image` shows an object in the
/// render of frame `frame` on screen (any pixel there a hit).
fn shows_object(worker: &RenderWorker, frame: usize, image: egui::Rect, r: egui::Rect) -> bool {
    worker.with_published(|p| {
        let Some(f) = p.and_then(|p| p.frames.get(frame)) else {
            return false;
        };
        // As shown: a lock would spread a coarse pass over the full frame.
        let f = f.shown();
        let (w, h) = f.size();
        let (w, h) = (w as f32, h as f32);
        let to_px = |q: egui::Pos2| ((q - image.min) / image.size()) * egui::vec2(w, h);
        let (a, b) = (to_px(r.min), to_px(r.max));
        let xs = (a.x.floor().max(0.0) as u32)..(b.x.ceil().min(w) as u32);
        let rows = (a.y.floor().max(0.0) as u32)..(b.y.ceil().min(h) as u32);
        rows.into_iter().any(|row| {
            xs.clone()
                .any(|x| f.get(x, row).is_some_and(|s| s.t.is_finite()))
        })
    })
}

/// `rect` cut by the split line at `at` (0..1 from the left or the top): the part before the
/// line (the correct rule's) and the part after it.
fn split_halves(rect: egui::Rect, line: SplitLine, at: f32) -> (egui::Rect, egui::Rect) {
    match line {
        SplitLine::Vertical => {
            let x = rect.left() + rect.width() * at;
            (
                egui::Rect::from_min_max(rect.min, egui::pos2(x, rect.max.y)),
                egui::Rect::from_min_max(egui::pos2(x, rect.min.y), rect.max),
            )
        }
        SplitLine::Horizontal => {
            let y = rect.top() + rect.height() * at;
            (
                egui::Rect::from_min_max(rect.min, egui::pos2(rect.max.x, y)),
                egui::Rect::from_min_max(egui::pos2(rect.min.x, y), rect.max),
            )
        }
    }
}

/// The world point the image on screen shows at pixel `px` of frame `frame`, from the render
/// itself (its camera and the hit's t); `None` over the background.
fn surface_point(worker: &RenderWorker, frame: usize, px: glam::Vec2) -> Option<glam::Vec3> {
    worker.with_published(|p| {
        let p = p?;
        let f = p.frames.get(frame)?.shown();
        if px.x < 0.0 || px.y < 0.0 {
            return None;
        }
        let (x, row) = (px.x as u32, px.y as u32);
        let t = f.get(x, row)?.t;
        if !t.is_finite() {
            return None;
        }
        let (w, h) = f.size();
        let ray = p.compiled.camera.pixel_ray(x, row, w, h);
        Some(ray.origin + ray.direction * t)
    })
}
