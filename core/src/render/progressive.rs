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

/// Traces one pixel's ray and shades it.
#[inline]
fn trace_sample(scene: &CompiledScene, s: &RenderSettings, ray: Ray) -> Sample {
    // The default rule stays on the fast path, exactly as before the other rules existed.
    let hit = if s.object_rays == ObjectRays::Unnormalized {
        scene.intersect(&ray, scene.camera.t_min(), f32::INFINITY)
    } else {
        scene.intersect_with(&ray, scene.camera.t_min(), f32::INFINITY, s.object_rays)
    };
    match hit {
        Some(hit) => {
            let (c, n) = shade_fast(scene, &ray, &hit, s);
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
    render_scales(scene, settings, target, cancel, &SCALES, &mut on_pass)
}

/// Renders the full-resolution image in one pass.
pub fn render_frame(scene: &CompiledScene, settings: &RenderSettings) -> Frame {
    let target = SharedFrame::new();
    let never = AtomicBool::new(false);
    let _ = render_full(scene, settings, &target, &never);
    std::mem::replace(&mut *target.lock(), Frame::new(0, 0))
}

/// One full-resolution pass into `target` (which others may watch for progress).
pub fn render_full(
    scene: &CompiledScene,
    settings: &RenderSettings,
    target: &SharedFrame,
    cancel: &AtomicBool,
) -> Result<(), Cancelled> {
    render_scales(scene, settings, target, cancel, &[1], &mut |_| {})
}

fn render_scales(
    scene: &CompiledScene,
    settings: &RenderSettings,
    target: &SharedFrame,
    cancel: &AtomicBool,
    scales: &[u32],
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
            let mut local: Vec<(u32, u32, Sample)> = Vec::new();
            for row in (y0..y1).step_by(scale as usize) {
                let row_rays = rays.row(row);
                for x in (x0..x1).step_by(scale as usize) {
                    // Already traced by a coarser pass.
                    if let Some(c) = coarser
                        && x % c == 0
                        && row % c == 0
                    {
                        continue;
                    }
                    local.push((x, row, trace_sample(scene, settings, row_rays.ray(x))));
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
