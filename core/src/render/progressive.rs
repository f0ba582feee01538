//! The progressive, cancellable renderer. A render runs in passes from coarse (one ray per
//! 8×8 block) to full resolution; each pass traces only the pixels no earlier pass traced,
//! so the last pass leaves exactly the image a single full pass would. Tiles are rendered in
//! parallel with rayon and copied into a shared frame that another thread may read at any
//! time; a cancel flag stops the work within one tile.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Mutex, MutexGuard, PoisonError};
use std::time::{Duration, Instant};

use rayon::prelude::*;

use super::compile::CompiledScene;
use super::frame::{Frame, Sample, sample_from};
use super::shade::shade_fast;
use super::{ObjectRays, RenderSettings};
use crate::geometry::Ray;

const TILE: u32 = 64;
const SCALES: [u32; 4] = [8, 4, 2, 1];

/// A frame being filled by a render and read by others (the GUI) while it fills.
#[derive(Debug)]
pub struct SharedFrame {
    frame: Mutex<Frame>,
    /// Bumped whenever pixels change, so readers copy only when there is something new.
    version: AtomicU64,
    /// Tiles finished and tiles planned in the current render, over all passes.
    tiles_done: AtomicU64,
    tiles_total: AtomicU64,
}

impl Default for SharedFrame {
    fn default() -> Self {
        SharedFrame {
            frame: Mutex::new(Frame::new(0, 0)),
            version: AtomicU64::new(0),
            tiles_done: AtomicU64::new(0),
            tiles_total: AtomicU64::new(0),
        }
    }
}

impl SharedFrame {
    pub fn new() -> Self {
        Self::default()
    }
    /// The frame as it is now. Hold the guard briefly: the renderer waits for it.
    pub fn lock(&self) -> MutexGuard<'_, Frame> {
        self.frame.lock().unwrap_or_else(PoisonError::into_inner)
    }
    pub fn version(&self) -> u64 {
        self.version.load(Ordering::Acquire)
    }
    /// Fraction of the current render's work done, in [0, 1].
    pub fn progress(&self) -> f32 {
        let total = self.tiles_total.load(Ordering::Relaxed);
        if total == 0 { 0.0 } else { self.tiles_done.load(Ordering::Relaxed) as f32 / total as f32 }
    }
    fn bump(&self) {
        self.version.fetch_add(1, Ordering::AcqRel);
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PassInfo {
    /// 0-based index of the pass just completed.
    pub pass: usize,
    pub passes: usize,
    /// Pixels per traced sample along each axis in this pass (8, 4, 2, then 1).
    pub scale: u32,
    /// Time since the render started.
    pub elapsed: Duration,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Cancelled;

/// How primary rays reach the scene. The two give the same image bit for bit (tested on every
/// course and perf scene); `Packets` is what every render uses, `SingleRays` is there to
/// prove that and to measure the difference.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Tracing {
    /// Eight neighbouring pixels at a time (`CompiledScene::intersect8`: one packet for a
    /// one-mesh scene, else one by one), shaded one by one.
    #[default]
    Packets,
    SingleRays,
}

/// Traces one pixel's ray and shades it.
#[inline]
fn trace_sample(scene: &CompiledScene, s: &RenderSettings, ray: Ray) -> Sample {
    // The default rule stays on the fast path, exactly as before the other rules existed.
    let hit = if s.object_rays == ObjectRays::Unnormalized {
        scene.intersect(&ray, scene.camera.t_min(), f32::INFINITY)
    } else {
        scene.intersect_with(&ray, scene.camera.t_min(), f32::INFINITY, s.object_rays)
    };
    shade_sample(scene, s, &ray, hit)
}

/// Appends the samples of `px` (one tile's pixels to trace, in the order `pixels_to_trace`
/// gives them: 4×2 neighbourhoods), eight rays at a time.
fn trace_packets(
    scene: &CompiledScene,
    s: &RenderSettings,
    rays: &super::camera::PixelRays,
    px: &[(u32, u32)],
    out: &mut Vec<(u32, u32, Sample)>,
) {
    let t_min = scene.camera.t_min();
    for chunk in px.chunks(8) {
        let mut r = [Ray::new(glam::Vec3::ZERO, glam::Vec3::Z); 8];
        // A packet spans two rows: each row's share of the rays once.
        let mut row_rays = (u32::MAX, rays.row(chunk[0].1));
        for (k, &(x, row)) in chunk.iter().enumerate() {
            if row != row_rays.0 {
                row_rays = (row, rays.row(row));
            }
            r[k] = row_rays.1.ray(x);
        }
        let active = ((1u16 << chunk.len()) - 1) as u8;
        let hits = scene.intersect8(&r, active, t_min, f32::INFINITY);
        for (k, &(x, row)) in chunk.iter().enumerate() {
            out.push((x, row, shade_sample(scene, s, &r[k], hits[k])));
        }
    }
}

#[inline]
fn shade_sample(scene: &CompiledScene, s: &RenderSettings, ray: &Ray, hit: Option<super::compile::Hit>) -> Sample {
    match hit {
        Some(hit) => {
            let (c, n) = shade_fast(scene, ray, &hit, s);
            // The operand, for a CSG surface: what the pixel inspector and picking show.
            let node = scene.hit_node(&hit).map_or(u32::MAX, |n| n.0);
            sample_from(c, n, hit.t, node)
        }
        None => {
            let mut m = sample_from(scene.background, glam::Vec3::ZERO, f32::INFINITY, u32::MAX);
            m.normal = [0; 3];
            m
        }
    }
}

/// Renders progressively into `target`, calling `on_pass` after each pass. Returns
/// `Err(Cancelled)` promptly once `cancel` is set.
pub fn render_progressive(
    scene: &CompiledScene,
    settings: &RenderSettings,
    target: &SharedFrame,
    cancel: &AtomicBool,
    mut on_pass: impl FnMut(PassInfo),
) -> Result<(), Cancelled> {
    render_scales(scene, settings, target, cancel, &SCALES, Tracing::default(), &mut on_pass)
}

/// Only the coarse passes (one ray per 8×8 block, then per 4×4): what the editor renders
/// while the mouse drags the view, refining once it stops.
pub fn render_coarse(
    scene: &CompiledScene,
    settings: &RenderSettings,
    target: &SharedFrame,
    cancel: &AtomicBool,
    mut on_pass: impl FnMut(PassInfo),
) -> Result<(), Cancelled> {
    render_scales(scene, settings, target, cancel, &SCALES[..2], Tracing::default(), &mut on_pass)
}

/// Renders the full-resolution image in one pass.
pub fn render_frame(scene: &CompiledScene, settings: &RenderSettings) -> Frame {
    render_frame_traced(scene, settings, Tracing::default())
}

/// [`render_frame`] with the primary rays traced as `tracing` says.
pub fn render_frame_traced(scene: &CompiledScene, settings: &RenderSettings, tracing: Tracing) -> Frame {
    let target = SharedFrame::new();
    let never = AtomicBool::new(false);
    let _ = render_scales(scene, settings, &target, &never, &[1], tracing, &mut |_| {});
    std::mem::replace(&mut *target.lock(), Frame::new(0, 0))
}

/// [`render_progressive`] with the primary rays traced as `tracing` says (for comparing the
/// two in `bench-progressive`).
pub fn render_progressive_traced(
    scene: &CompiledScene,
    settings: &RenderSettings,
    target: &SharedFrame,
    cancel: &AtomicBool,
    tracing: Tracing,
    mut on_pass: impl FnMut(PassInfo),
) -> Result<(), Cancelled> {
    render_scales(scene, settings, target, cancel, &SCALES, tracing, &mut on_pass)
}

/// One full-resolution pass into `target` (which others may watch for progress).
pub fn render_full(
    scene: &CompiledScene,
    settings: &RenderSettings,
    target: &SharedFrame,
    cancel: &AtomicBool,
) -> Result<(), Cancelled> {
    render_scales(scene, settings, target, cancel, &[1], Tracing::default(), &mut |_| {})
}

/// The pixels of a tile that a pass of `scale` traces, in 4×2 neighbourhoods of its grid (two
/// rows, four columns at a time), so that eight consecutive ones make a coherent packet.
fn pixels_to_trace(
    (x0, y0, x1, y1): (u32, u32, u32, u32),
    scale: u32,
    traced_before: impl Fn(u32, u32) -> bool,
) -> Vec<(u32, u32)> {
    let step = scale as usize;
    // At most the tile's grid points: no growing while filling.
    let cap = ((x1 - x0) as usize).div_ceil(step) * ((y1 - y0) as usize).div_ceil(step);
    let mut px = Vec::with_capacity(cap);
    for row in (y0..y1).step_by(2 * step) {
        for x in (x0..x1).step_by(4 * step) {
            for r in [row, row + scale] {
                for k in 0..4 {
                    let xx = x + k * scale;
                    if r < y1 && xx < x1 && !traced_before(xx, r) {
                        px.push((xx, r));
                    }
                }
            }
        }
    }
    px
}

fn render_scales(
    scene: &CompiledScene,
    settings: &RenderSettings,
    target: &SharedFrame,
    cancel: &AtomicBool,
    scales: &[u32],
    tracing: Tracing,
    on_pass: &mut dyn FnMut(PassInfo),
) -> Result<(), Cancelled> {
    let start = Instant::now();
    let (w, h) = (settings.width, settings.height);
    {
        let mut f = target.lock();
        if f.width != w || f.height != h {
            *f = Frame::new(w, h);
        }
    }
    target.bump();
    if w == 0 || h == 0 {
        return Ok(());
    }
    // The columns' share of every camera ray, once per render rather than per pixel.
    let rays = scene.camera.pixel_rays(w, h);
    let tiles_x = w.div_ceil(TILE);
    let tiles_y = h.div_ceil(TILE);
    let tiles: Vec<(u32, u32)> = (0..tiles_y).flat_map(|ty| (0..tiles_x).map(move |tx| (tx, ty))).collect();
    target.tiles_done.store(0, Ordering::Relaxed);
    target.tiles_total.store((tiles.len() * scales.len()) as u64, Ordering::Relaxed);
    for (pass, &scale) in scales.iter().enumerate() {
        let coarser = (pass > 0).then(|| scales[pass - 1]);
        tiles.par_iter().try_for_each(|&(tx, ty)| {
            if cancel.load(Ordering::Relaxed) {
                return Err(Cancelled);
            }
            let x0 = tx * TILE;
            let y0 = ty * TILE;
            let x1 = (x0 + TILE).min(w);
            let y1 = (y0 + TILE).min(h);
            let grid = ((x1 - x0) as usize).div_ceil(scale as usize) * ((y1 - y0) as usize).div_ceil(scale as usize);
            let mut local: Vec<(u32, u32, Sample)> = Vec::with_capacity(grid);
            let traced_before = |x: u32, row: u32| coarser.is_some_and(|c| x % c == 0 && row % c == 0);
            match tracing {
                // The lecture's other depth-t rules trace ray by ray (`intersect_with`).
                Tracing::Packets if settings.object_rays == ObjectRays::Unnormalized => {
                    let px = pixels_to_trace((x0, y0, x1, y1), scale, traced_before);
                    trace_packets(scene, settings, &rays, &px, &mut local);
                }
                _ => {
                    for row in (y0..y1).step_by(scale as usize) {
                        let row_rays = rays.row(row);
                        for x in (x0..x1).step_by(scale as usize) {
                            if !traced_before(x, row) {
                                local.push((x, row, trace_sample(scene, settings, row_rays.ray(x))));
                            }
                        }
                    }
                }
            }
            let mut f = target.lock();
            for (x, row, s) in local {
                for yy in row..(row + scale).min(h) {
                    let base = yy as usize * w as usize;
                    for xx in x..(x + scale).min(w) {
                        f.samples[base + xx as usize] = s;
                    }
                }
            }
            drop(f);
            target.tiles_done.fetch_add(1, Ordering::Relaxed);
            target.bump();
            Ok(())
        })?;
        on_pass(PassInfo { pass, passes: scales.len(), scale, elapsed: start.elapsed() });
    }
    Ok(())
}
