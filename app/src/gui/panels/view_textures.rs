//! The render view's texture cache: the worker's pixels uploaded to the GPU when they
//! change (and only then), the pixels each texture holds (what the user sees), and the
//! selection's outline.

use tracelab_core::View;

use crate::document::{Document, Selection};
use crate::gui::overlays;
use crate::gui::panels::view_settings::{Compare, ViewSettings};
use crate::render_worker::Published;

/// (render request, frame version, view, depth range bits): what a texture holds. The
/// request, not the document generation, names the render: a change of normal rule, shade
/// back or size re-renders the same generation into new frames whose version counters
/// start again, so a key by generation once kept the old picture on screen.
type UploadKey = (u64, u64, View, (u32, u32));

/// Texture state: what is on the GPU, so unchanged pixels are not uploaded again.
#[derive(Default)]
pub struct ViewTextures {
    textures: Vec<Option<egui::TextureHandle>>,
    /// Per texture: (request, frame version, view, depth range) last uploaded.
    uploaded: Vec<Option<UploadKey>>,
    /// Per texture: the pixels last uploaded, so tests can read what the view shows.
    images: Vec<Option<std::sync::Arc<egui::ColorImage>>>,
    /// Size of the image shown, in pixels.
    pub shown_size: (u32, u32),
    /// Generation of the image on screen, for the edit→screen timing log.
    shown_generation: u64,
    /// The selection's outline, and what it was made from (request, passes, selection,
    /// generation).
    outline: Option<egui::TextureHandle>,
    outline_key: Option<(u64, u64, Option<Selection>, u64)>,
    /// Timing log: the render request whose finished image was logged as uploaded.
    full_logged: u64,
    /// Timing log: a finished image uploaded this frame, to be reported as painted by the
    /// next frame.
    pub uploaded_full: Option<UploadedFull>,
}

/// When a finished image went to the GPU (the edit → screen timing log).
#[derive(Clone, Copy, Debug)]
pub struct UploadedFull {
    pub generation: u64,
    /// When the UI asked for the render (right after applying the edit).
    pub submitted: std::time::Instant,
    /// From the submit to the render's last pass.
    pub full: std::time::Duration,
    pub upload_started: std::time::Instant,
    pub uploaded: std::time::Instant,
}

/// The texture slot of a frame's view.
pub fn index(frame: usize, view: View) -> usize {
    frame * 3
        + match view {
            View::Color => 0,
            View::Normals => 1,
            View::Depth => 2,
        }
}

impl ViewTextures {
    pub fn get(&self, i: usize) -> Option<&egui::TextureHandle> {
        self.textures.get(i).and_then(Option::as_ref)
    }

    /// The pixels texture `i` holds.
    pub fn image(&self, i: usize) -> Option<std::sync::Arc<egui::ColorImage>> {
        self.images.get(i)?.clone()
    }

    pub fn outline(&self) -> Option<&egui::TextureHandle> {
        self.outline.as_ref()
    }

    pub fn drop_outline(&mut self) {
        self.outline = None;
    }

    /// The outline of the selection, made again when the pixels or the selection change.
    pub fn upload_outline(&mut self, ctx: &egui::Context, p: &Published, doc: &Document) {
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
        // Nothing selected: no outline, and no read that would spread a coarse pass over the
        // full frame on this thread.
        let image = if ids.contains(&true) {
            overlays::outline(&frame.lock(), &ids)
        } else {
            None
        };
        self.outline = image.map(|img| match self.outline.take() {
            Some(mut t) => {
                t.set(img, egui::TextureOptions::NEAREST);
                t
            }
            None => ctx.load_texture("selection-outline", img, egui::TextureOptions::NEAREST),
        });
    }

    /// Uploads the views the cells need whenever their pixels changed. The previous image
    /// stays until a new render has completed its first (coarse) pass.
    pub fn upload(&mut self, ctx: &egui::Context, p: &Published, s: &ViewSettings) {
        if p.passes_done == 0 {
            return;
        }
        let started = std::time::Instant::now();
        let mut any = false;
        let mut need: Vec<(usize, View)> = s.cells().iter().map(|&(f, v, _)| (f, v)).collect();
        if s.compare == Compare::Split {
            need.extend(s.cells().iter().map(|&(_, v, _)| (1, v)));
        }
        for (frame_i, view) in need {
            let Some(frame) = p.frames.get(frame_i) else {
                continue;
            };
            let i = index(frame_i, view);
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
            // A coarse pass not yet spread over the frame is shown from its own grid: the
            // same bytes, without the renderer or this thread writing the full frame first.
            let (w, h, rgba) = match frame.coarse() {
                Some(c) => (c.width, c.height, c.rgba8(view, s.depth)),
                None => {
                    let f = frame.lock();
                    (f.width, f.height, f.rgba8(view, s.depth))
                }
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
            any = true;
        }
        let timing = log::log_enabled!(target: crate::logging::TIMES, log::Level::Info);
        if timing && any && p.full.is_some() && self.full_logged != p.job.request {
            // The finished image went to the GPU in this frame; the next frame reports when
            // it was painted, so ask for it at once.
            self.full_logged = p.job.request;
            self.uploaded_full = Some(UploadedFull {
                generation: p.job.generation,
                submitted: p.job.submitted,
                full: p.full.unwrap_or_default(),
                upload_started: started,
                uploaded: std::time::Instant::now(),
            });
            ctx.request_repaint();
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
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;
    use std::sync::atomic::{AtomicBool, Ordering};

    use tracelab_core::render::{RenderPlan, render, render_frame};
    use tracelab_core::{CompiledScene, NormalTransform, RenderSettings, SharedFrame};

    use super::*;
    use crate::gui::panels::view_settings::Tab;
    use crate::render_worker::Job;

    /// After the first (16×) pass, kept at its own resolution, the view shows in every view
    /// exactly the bytes it showed when that pass was written into the full frame: each pixel
    /// its block's corner pixel of the full render. And showing it spreads nothing.
    #[test]
    fn a_coarse_pass_is_shown_as_its_blocks_of_the_full_render() {
        let out = tracelab_core::parse_scene(
            crate::DEFAULT_SCENE.as_bytes(),
            "default",
            None,
            &mut tracelab_core::MeshCache::new(),
        );
        let scene = Arc::new(out.scene.expect("built-in scene parses"));
        let compiled = Arc::new(CompiledScene::new(&scene));
        // Partial blocks at the right and bottom edges.
        let settings = RenderSettings::new(150, 97);
        let frame = Arc::new(SharedFrame::new());
        let stop = AtomicBool::new(false);
        let mut scales = Vec::new();
        let _ = render(
            &compiled,
            &settings,
            RenderPlan::PROGRESSIVE,
            &frame,
            &stop,
            |p| {
                scales.push(p.scale);
                stop.store(true, Ordering::Relaxed);
            },
        );
        assert_eq!(scales, [16]);
        assert!(frame.coarse().is_some(), "the 16× pass is kept coarse");
        let p = Published {
            job: Job {
                generation: 1,
                request: 1,
                scene: scene.clone(),
                settings,
                modes: vec![NormalTransform::Correct],
                submitted: std::time::Instant::now(),
                coarse: false,
                grid: None,
            },
            compiled: compiled.clone(),
            frames: vec![frame.clone()],
            passes_done: 1,
            passes: 5,
            first_image: None,
            full: None,
            normal_gap: None,
            grid_error: None,
        };
        let s = ViewSettings {
            tab: Tab::All,
            ..ViewSettings::default()
        };
        let mut textures = ViewTextures::default();
        textures.upload(&egui::Context::default(), &p, &s);
        assert!(frame.coarse().is_some(), "shown without spreading it");
        assert_eq!(textures.shown_size, (150, 97));
        let full = render_frame(&compiled, &settings);
        let written = frame.lock().clone();
        for view in [View::Color, View::Normals, View::Depth] {
            let shown = textures.image(index(0, view)).expect("uploaded");
            let before =
                egui::ColorImage::from_rgba_unmultiplied([150, 97], &written.rgba8(view, s.depth));
            assert_eq!(*shown, before, "{view:?}");
            for y in 0..97 {
                for x in 0..150 {
                    let corner = full.get(x - x % 16, y - y % 16).expect("in the frame");
                    let [r, g, b] = corner.rgb8(view, s.depth);
                    let px = shown.pixels[(y * 150 + x) as usize];
                    assert_eq!([px.r(), px.g(), px.b()], [r, g, b], "{view:?} ({x}, {y})");
                }
            }
        }
    }
}
