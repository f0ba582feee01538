//! The progressive, cancellable renderer. A render runs in passes from coarse (one ray per
//! 16×16 block) to full resolution; each pass traces only the pixels no earlier pass traced,
//! so the last pass leaves exactly the image a single full pass would. The passes between a
//! coarse pass and the full one are left out when that coarse pass shows the full image will
//! come quickly. Tiles are rendered in parallel with rayon into a shared frame that another
//! thread may read at any time: tile by tile in the fine passes; in the coarse ones (cheap to
//! trace, dear to write) a whole pass at once, kept at its own resolution until the frame is
//! read or a fine pass needs it. A cancel flag stops the work within one tile.

use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

use rayon::prelude::*;

use super::camera::PixelRays;
use super::coarse::CoarseFrame;
use super::compile::CompiledScene;
use super::cull::TileCull;
use super::frame::{Frame, Sample, write_sample};
use super::plan::{Cancel, RenderPlan, Schedule, Tracing, Uncancellable};
use super::shade::shade_fast;
use super::shade_lanes::shade_packet;
use super::shared_frame::SharedFrame;
use super::whitted::{needs_whitted, shade_primary};
use super::{ObjectRays, RenderSettings};
use crate::geometry::Ray;

const TILE: u32 = 64;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PassInfo {
    /// 0-based index of the pass just completed.
    pub pass: usize,
    /// Passes this render makes: fewer from a quick coarse pass on, which skips the passes
    /// between it and the full one.
    pub passes: usize,
    /// Pixels per traced sample along each axis in this pass (16, 8, 4, 2, then 1).
    pub scale: u32,
    /// Time since the render started.
    pub elapsed: Duration,
}

/// Traces one pixel's ray and shades it into `dst`.
#[inline]
fn trace_sample(scene: &CompiledScene, s: &RenderSettings, ray: Ray, dst: &mut Sample) {
    // The default rule stays on the fast path, exactly as before the other rules existed.
    let hit = if s.object_rays == ObjectRays::Unnormalized {
        scene.intersect(&ray, scene.camera.t_min(), f32::INFINITY)
    } else {
        scene.intersect_with(&ray, scene.camera.t_min(), f32::INFINITY, s.object_rays)
    };
    let whitted = needs_whitted(scene, s);
    let shaded = hit
        .as_ref()
        .map_or((glam::Vec3::ZERO, glam::Vec3::ZERO), |h| {
            if whitted {
                shade_primary(scene, &ray, h, s)
            } else {
                shade_fast(scene, &ray, h, s)
            }
        });
    store_sample(scene, dst, hit.as_ref(), shaded);
}

/// Traces the grid points `pts` (grid coordinates of one tile's pass, in the order
/// `points_to_trace` gives them: 4×2 neighbourhoods) eight rays at a time, storing each sample
/// at its place in `grid` (row-major, `gw` points a row).
fn trace_packets(
    scene: &CompiledScene,
    s: &RenderSettings,
    pass: &TilePass,
    rays: &PixelRays,
    pts: &[(u32, u32)],
    grid: &mut [Sample],
) {
    let t_min = scene.camera.t_min();
    let whitted = needs_whitted(scene, s);
    // Every miss stores the same sample: quantise the background once, not per pixel.
    let mut miss = Sample::UNSET;
    store_sample(scene, &mut miss, None, (glam::Vec3::ZERO, glam::Vec3::ZERO));
    // The full pass's rays row by row first, where a perspective row's are made eight at a
    // time (`RowRays::fill_range`); the coarse passes' points are too sparse for it.
    let mut tile_rays = Vec::new();
    if pass.scale == 1 {
        tile_rays.reserve(pass.points());
        for j in 0..pass.gh {
            let (x0, row) = pass.pixel(0, j);
            rays.row(row).fill_range(x0, x0 + pass.gw, &mut tile_rays);
        }
        // `pass.index` assumes every row gave its gw rays; a tile reaching past the image
        // (never made) would shift them: then one ray at a time, as the coarse passes.
        if tile_rays.len() != pass.points() {
            tile_rays.clear();
        }
    }
    for chunk in pts.chunks(8) {
        let mut r = [Ray::new(glam::Vec3::ZERO, glam::Vec3::Z); 8];
        for (k, &(i, j)) in chunk.iter().enumerate() {
            r[k] = match tile_rays.get(pass.index(i, j)) {
                Some(ray) => *ray,
                None => {
                    let (x, row) = pass.pixel(i, j);
                    rays.row(row).ray(x)
                }
            };
        }
        let active = ((1u16 << chunk.len()) - 1) as u8;
        let hits = scene.intersect8_with(
            &r,
            active,
            t_min,
            f32::INFINITY,
            pass.scale >= SPARSE_FROM_SCALE,
        );
        let shaded = if whitted {
            // Secondary rays go one by one from each lane's hit.
            std::array::from_fn(|k| {
                hits[k]
                    .as_ref()
                    .map_or((glam::Vec3::ZERO, glam::Vec3::ZERO), |h| {
                        shade_primary(scene, &r[k], h, s)
                    })
            })
        } else {
            shade_packet(scene, &r, &hits, s)
        };
        for (k, &(i, j)) in chunk.iter().enumerate() {
            let dst = &mut grid[pass.index(i, j)];
            match &hits[k] {
                Some(hit) => store_sample(scene, dst, Some(hit), shaded[k]),
                None => *dst = miss,
            }
        }
    }
}

/// One pass over one tile: the grid of every `scale`-th pixel from the tile's corner, of
/// which the points of the coarser pass before (every `ratio`-th point of this grid, or none)
/// are already in the frame.
#[derive(Clone, Copy, Debug)]
struct TilePass {
    x0: u32,
    y0: u32,
    x1: u32,
    y1: u32,
    scale: u32,
    /// Grid points per row and rows.
    gw: u32,
    gh: u32,
    /// The coarser pass's step in this grid's points, a power of two (0: no coarser pass).
    ratio: u32,
}

impl TilePass {
    fn new((x0, y0, x1, y1): (u32, u32, u32, u32), scale: u32, coarser: Option<u32>) -> Self {
        let ratio = coarser.map_or(0, |c| c / scale);
        // Tile corners are multiples of every scale, so the coarser grid is every ratio-th
        // point of this one; `traced_before` tests that with a mask, no division per pixel.
        debug_assert!(coarser.is_none_or(|c| c % scale == 0 && ratio.is_power_of_two()));
        debug_assert!(x0 % TILE == 0 && y0 % TILE == 0 && TILE.is_multiple_of(scale));
        TilePass {
            x0,
            y0,
            x1,
            y1,
            scale,
            gw: (x1 - x0).div_ceil(scale),
            gh: (y1 - y0).div_ceil(scale),
            ratio,
        }
    }
    #[inline]
    fn traced_before(&self, i: u32, j: u32) -> bool {
        self.ratio != 0 && (i | j) & (self.ratio - 1) == 0
    }
    #[inline]
    fn pixel(&self, i: u32, j: u32) -> (u32, u32) {
        (self.x0 + i * self.scale, self.y0 + j * self.scale)
    }
    #[inline]
    fn index(&self, i: u32, j: u32) -> usize {
        (j * self.gw + i) as usize
    }
    fn points(&self) -> usize {
        (self.gw * self.gh) as usize
    }
}

/// Stores a pixel's sample, hit or miss, into `dst`.
#[inline(always)]
fn store_sample(
    scene: &CompiledScene,
    dst: &mut Sample,
    hit: Option<&super::compile::Hit>,
    (c, n): (glam::Vec3, glam::Vec3),
) {
    match hit {
        Some(hit) => {
            // The operand, for a CSG surface: what the pixel inspector and picking show.
            let node = scene.hit_node(hit).map_or(u32::MAX, |n| n.0);
            write_sample(dst, c, n, hit.t, node);
        }
        None => write_sample(
            dst,
            scene.background,
            glam::Vec3::ZERO,
            f32::INFINITY,
            u32::MAX,
        ),
    }
}

/// The renderer's one entry point: renders into `target` as `plan` says, calling `on_pass`
/// after each pass, until done or `cancel` stops it.
pub fn render<C: Cancel>(
    scene: &CompiledScene,
    settings: &RenderSettings,
    plan: RenderPlan,
    target: &SharedFrame,
    cancel: &C,
    mut on_pass: impl FnMut(PassInfo),
) -> Result<(), C::Stop> {
    render_scales(
        scene,
        settings,
        plan.schedule(),
        target,
        cancel,
        &mut on_pass,
    )
}

/// The full-resolution image as a value: [`render`] with [`RenderPlan::FULL`] into a frame of
/// its own.
pub fn render_frame(scene: &CompiledScene, settings: &RenderSettings) -> Frame {
    full_into(scene, settings, SharedFrame::new())
}

/// [`render_frame`], with an error instead of an abort where the frame does not fit in
/// memory.
pub fn try_render_frame(
    scene: &CompiledScene,
    settings: &RenderSettings,
) -> Result<Frame, crate::memory::OutOfMemory> {
    let target = SharedFrame::try_sized(settings.width, settings.height)?;
    Ok(full_into(scene, settings, target))
}

fn full_into(scene: &CompiledScene, settings: &RenderSettings, target: SharedFrame) -> Frame {
    let plan = RenderPlan::FULL;
    let Ok(()) = render(scene, settings, plan, &target, &Uncancellable, |_| {});
    target.take()
}

/// The grid points of a tile's pass not traced before, in 4×2 neighbourhoods (two rows, four
/// columns at a time), so that eight consecutive ones make a coherent packet.
fn points_to_trace(pass: &TilePass) -> Vec<(u32, u32)> {
    let mut pts = Vec::with_capacity(pass.points());
    for j in (0..pass.gh).step_by(2) {
        for i in (0..pass.gw).step_by(4) {
            for jj in [j, j + 1] {
                for ii in i..(i + 4).min(pass.gw) {
                    if jj < pass.gh && !pass.traced_before(ii, jj) {
                        pts.push((ii, jj));
                    }
                }
            }
        }
    }
    pts
}

/// Writes a tile's pass into `band`, the frame's rows from `band_y0` on (`w` pixels a row):
/// every grid point's sample over its scale×scale block. The points traced before are read
/// back from the band (their blocks hold them), so each grid row expands to one pixel row that
/// is then copied to the block's rows.
fn write_tile(
    band: &mut [Sample],
    w: usize,
    band_y0: u32,
    pass: &TilePass,
    grid: &mut [Sample],
    line: &mut Vec<Sample>,
) {
    let (x0, x1) = (pass.x0 as usize, pass.x1 as usize);
    let s = pass.scale as usize;
    line.resize(x1 - x0, Sample::UNSET);
    for j in 0..pass.gh {
        let y = (pass.pixel(0, j).1 - band_y0) as usize;
        let row = &mut grid[pass.index(0, j)..pass.index(0, j) + pass.gw as usize];
        if pass.traced_before(0, j) {
            for i in (0..pass.gw).step_by(pass.ratio as usize) {
                let (x, _) = pass.pixel(i, j);
                row[i as usize] = band[y * w + x as usize];
            }
        }
        if s == 1 {
            // Full resolution: the grid row is the pixel row.
            band[y * w + x0..y * w + x1].copy_from_slice(row);
            continue;
        }
        for (block, &sample) in line.chunks_mut(s).zip(row.iter()) {
            block.fill(sample);
        }
        for yy in y..(y + s).min((pass.y1 - band_y0) as usize) {
            band[yy * w + x0..yy * w + x1].copy_from_slice(line);
        }
    }
}

/// Traces one tile's pass into a grid of its samples (the points traced before left unset,
/// or, in a tile no ray can hit anything in, background like the rest).
fn trace_tile(
    scene: &CompiledScene,
    settings: &RenderSettings,
    rays: &PixelRays,
    tracing: Tracing,
    cull: &TileCull,
    tp: &TilePass,
) -> Vec<Sample> {
    // Packets only: the single rays trace every pixel, so that the two agreeing shows that
    // no culled pixel would have hit.
    if tracing == Tracing::Packets && !cull.may_hit((tp.x0, tp.y0, tp.x1, tp.y1)) {
        let mut miss = Sample::UNSET;
        store_sample(scene, &mut miss, None, (glam::Vec3::ZERO, glam::Vec3::ZERO));
        return vec![miss; tp.points()];
    }
    let mut grid = vec![Sample::UNSET; tp.points()];
    match tracing {
        // The lecture's other depth-t rules trace ray by ray (`intersect_with`).
        Tracing::Packets if settings.object_rays == ObjectRays::Unnormalized => {
            trace_packets(scene, settings, tp, rays, &points_to_trace(tp), &mut grid);
        }
        _ => {
            for j in 0..tp.gh {
                let row_rays = rays.row(tp.pixel(0, j).1);
                for i in 0..tp.gw {
                    if !tp.traced_before(i, j) {
                        trace_sample(
                            scene,
                            settings,
                            row_rays.ray(tp.pixel(i, j).0),
                            &mut grid[tp.index(i, j)],
                        );
                    }
                }
            }
        }
    }
    grid
}

/// Passes this coarse or coarser are traced whole and kept at their own resolution
/// ([`CoarseFrame`], spread over the frame when it is read): their rays are few, and written
/// tile by tile under the frame's lock the blocks' copies (the whole frame, for a sixteenth of
/// the rays or less) kept all but one thread waiting (docs/perf.md).
const WRITE_WHOLE_FROM_SCALE: u32 = 4;

/// A whole pass's tile grids as one grid over the frame (the points traced before unset).
fn gather(traced: &[(TilePass, Vec<Sample>)], w: u32, h: u32, scale: u32) -> CoarseFrame {
    let gw = w.div_ceil(scale) as usize;
    let mut samples = vec![Sample::UNSET; gw * h.div_ceil(scale) as usize];
    for (tp, grid) in traced {
        // Tile corners are multiples of every scale.
        let (i0, j0) = ((tp.x0 / scale) as usize, (tp.y0 / scale) as usize);
        for (j, row) in grid.chunks(tp.gw as usize).enumerate() {
            let at = (j0 + j) * gw + i0;
            samples[at..at + row.len()].copy_from_slice(row);
        }
    }
    CoarseFrame {
        width: w,
        height: h,
        scale,
        samples,
    }
}

/// The points of `grid` the pass at scale `coarser` traced (every ratio-th of this grid),
/// from that pass: kept coarse, or spread over the frame since.
fn fill_traced_before(grid: &mut CoarseFrame, coarser: u32, p: &super::shared_frame::Pixels) {
    let ratio = (coarser / grid.scale) as usize;
    let (gw, gh) = (grid.grid_width() as usize, grid.grid_height() as usize);
    for j in (0..gh).step_by(ratio) {
        for i in (0..gw).step_by(ratio) {
            let (x, y) = ((i as u32) * grid.scale, (j as u32) * grid.scale);
            let before = match &p.coarse {
                Some(c) => c.get(x, y),
                None => p.frame.get(x, y),
            };
            // Always there: the coarser pass covered this frame (a reader spreads it whole).
            if let Some(&s) = before {
                grid.samples[j * gw + i] = s;
            }
        }
    }
}

/// Passes this coarse or coarser let an incoherent packet go one ray at a time
/// (`intersect8_with`); in the finer passes the test misjudged packets that were paying.
const SPARSE_FROM_SCALE: u32 = 4;

/// Passes this fine or finer may skip to the full pass. A 16× pass does not: its few rays
/// leave the tree cold for the full pass, which then took longer than the 8× pass it skipped
/// (the dragon's full image 19.4 → 21.5 ms, docs/perf.md).
const SKIP_FROM_SCALE: u32 = 8;

/// How many passes to skip after pass `pass` of `plan`, which took `took`: those between it
/// and the full-resolution pass that ends the plan, when the full pass's rays would take
/// less than `below` at this pass's time per ray.
fn passes_to_skip(
    plan: &[u32],
    pass: usize,
    took: Duration,
    (w, h): (u32, u32),
    below: Option<Duration>,
) -> usize {
    let Some(below) = below.filter(|_| plan[pass] <= SKIP_FROM_SCALE) else {
        return 0;
    };
    let between = plan.len().saturating_sub(pass + 2);
    if between == 0 || plan.last() != Some(&1) {
        return 0;
    }
    // Grid points of a pass over the whole frame (tiles' partial blocks aside).
    let points = |s: u32| f64::from(w.div_ceil(s)) * f64::from(h.div_ceil(s));
    let traced = points(plan[pass]) - pass.checked_sub(1).map_or(0.0, |p| points(plan[p]));
    let left = f64::from(w) * f64::from(h) - points(plan[pass]);
    if traced > 0.0 && took.as_secs_f64() / traced * left < below.as_secs_f64() {
        between
    } else {
        0
    }
}

fn render_scales<C: Cancel>(
    scene: &CompiledScene,
    settings: &RenderSettings,
    schedule: Schedule<'_>,
    target: &SharedFrame,
    cancel: &C,
    on_pass: &mut dyn FnMut(PassInfo),
) -> Result<(), C::Stop> {
    let Schedule {
        scales,
        straight_to_full_below,
        tracing,
    } = schedule;
    let start = Instant::now();
    let (w, h) = (settings.width, settings.height);
    if settings.variant.is_some() {
        // A mistake's picture (diff's diagnosis): one plain pass, nothing of the fast path.
        target.set(super::mistakes::render_variant(scene, settings));
        on_pass(PassInfo {
            pass: 0,
            passes: 1,
            scale: 1,
            elapsed: start.elapsed(),
        });
        return Ok(());
    }
    {
        let mut p = target.pixels();
        p.coarse = None;
        // A first pass kept coarse leaves the frame to be sized when it is spread (the editor
        // renders into fresh frames: 10 MB less to allocate and fill before the first image).
        let kept_coarse = scales.first().is_some_and(|&s| s >= WRITE_WHOLE_FROM_SCALE);
        if (p.frame.width != w || p.frame.height != h) && !(kept_coarse && w > 0 && h > 0) {
            p.frame = Frame::new(w, h);
        }
    }
    target.bump();
    if w == 0 || h == 0 {
        return Ok(());
    }
    // The columns' share of every camera ray, once per render rather than per pixel.
    let rays = scene.camera.pixel_rays(w, h);
    let cull = TileCull::new(scene, w, h);
    let tiles_x = w.div_ceil(TILE);
    let tiles_y = h.div_ceil(TILE);
    let tiles: Vec<(u32, u32)> = (0..tiles_y)
        .flat_map(|ty| (0..tiles_x).map(move |tx| (tx, ty)))
        .collect();
    target.tiles_done.store(0, Ordering::Relaxed);
    target
        .tiles_total
        .store((tiles.len() * scales.len()) as u64, Ordering::Relaxed);
    let mut plan = scales.to_vec();
    // Supersampling refines the full-resolution pass: not made by a coarse-only plan.
    let supersampled = settings.supersample.is_some() && plan.last() == Some(&1);
    if supersampled {
        target
            .tiles_total
            .fetch_add(tiles.len() as u64, Ordering::Relaxed);
    }
    let mut pass = 0;
    while let Some(&scale) = plan.get(pass) {
        let pass_start = Instant::now();
        let coarser = (pass > 0).then(|| plan[pass - 1]);
        let tile_pass = |&(tx, ty): &(u32, u32)| {
            let (x0, y0) = (tx * TILE, ty * TILE);
            TilePass::new(
                (x0, y0, (x0 + TILE).min(w), (y0 + TILE).min(h)),
                scale,
                coarser,
            )
        };
        if scale >= WRITE_WHOLE_FROM_SCALE {
            let traced: Vec<(TilePass, Vec<Sample>)> = tiles
                .par_iter()
                .map(|t| {
                    if let Some(stop) = cancel.stop() {
                        return Err(stop);
                    }
                    let tp = tile_pass(t);
                    let grid = trace_tile(scene, settings, &rays, tracing, &cull, &tp);
                    target.tiles_done.fetch_add(1, Ordering::Relaxed);
                    Ok((tp, grid))
                })
                .collect::<Result<_, _>>()?;
            let mut grid = gather(&traced, w, h, scale);
            let mut p = target.pixels();
            if let Some(coarser) = coarser {
                fill_traced_before(&mut grid, coarser, &p);
            }
            p.coarse = Some(grid);
            drop(p);
            target.bump();
        } else {
            if let Some(stop) = cancel.stop() {
                return Err(stop);
            }
            {
                // The tiles read the coarser pass's points back from the frame. Spread under
                // the lock, in parallel: no job under it locks this frame, nor can a stolen one
                // (this render's tiles start after it; two renders never share a frame).
                let mut p = target.pixels();
                if let Some(c) = p.coarse.take() {
                    c.spread_into(&mut p.frame, true);
                }
            }
            tiles.par_iter().try_for_each(|t| {
                if let Some(stop) = cancel.stop() {
                    return Err(stop);
                }
                let tp = tile_pass(t);
                let mut grid = trace_tile(scene, settings, &rays, tracing, &cull, &tp);
                let mut line = Vec::with_capacity(TILE as usize);
                write_tile(
                    &mut target.lock().samples,
                    w as usize,
                    0,
                    &tp,
                    &mut grid,
                    &mut line,
                );
                target.tiles_done.fetch_add(1, Ordering::Relaxed);
                target.bump();
                Ok(())
            })?;
        }
        let skip = passes_to_skip(
            &plan,
            pass,
            pass_start.elapsed(),
            (w, h),
            straight_to_full_below,
        );
        if skip > 0 {
            plan.drain(pass + 1..pass + 1 + skip);
            target.tiles_total.store(
                (tiles.len() * (plan.len() + usize::from(supersampled))) as u64,
                Ordering::Relaxed,
            );
        }
        on_pass(PassInfo {
            pass,
            passes: plan.len() + usize::from(supersampled),
            scale,
            elapsed: start.elapsed(),
        });
        pass += 1;
    }
    if let Some(ss) = settings.supersample.filter(|_| supersampled) {
        // Traced and filtered with the frame unlocked, and cancellably: a wide filter over
        // many samples takes seconds, which neither the editor's paint (it locks the frame)
        // nor an edit (it cancels) should wait for. Only the colours are copied in under the
        // lock; the centre rays' normals, depths and hits stay for picking and other views.
        if let Some(film) = super::film::supersample_film(scene, settings, ss, cancel)? {
            match film.frame_until(&ss.filter, cancel)? {
                Ok(filtered) => {
                    let mut frame = target.lock();
                    if (frame.width, frame.height) == (filtered.width, filtered.height) {
                        for (s, f) in frame.samples.iter_mut().zip(&filtered.samples) {
                            s.color = f.color;
                        }
                    }
                    drop(frame);
                    target.bump();
                }
                Err(e) => log::warn!("supersampling skipped: {e}"),
            }
        }
        target
            .tiles_done
            .fetch_add(tiles.len() as u64, Ordering::Relaxed);
        on_pass(PassInfo {
            pass,
            passes: pass + 1,
            scale: 1,
            elapsed: start.elapsed(),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::plan::{Cancelled, SCALES, STRAIGHT_TO_FULL_BELOW};
    use crate::{MeshCache, load_scene};
    use std::sync::atomic::AtomicBool;

    /// scenes/nested_transforms.txt, compiled.
    fn nested_transforms() -> CompiledScene {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../scenes/nested_transforms.txt");
        let scene = load_scene(&path, &mut MeshCache::new())
            .into_result()
            .expect("scene loads")
            .0;
        CompiledScene::new(&scene)
    }

    /// What the viewport shows after each pass: every pixel holds the sample of its block's
    /// corner pixel in that pass's grid (multiples of the scale), which the full-resolution
    /// render traced too. Sizes with partial tiles and partial blocks, both the coarse passes
    /// written whole and those written tile by tile, packets and single rays, every pass made
    /// and a quick 8× pass going straight to the full one (which then fills in around the 8×
    /// grid), or a full pass after the 4× one.
    #[test]
    fn each_pass_shows_its_blocks_of_the_full_render() {
        let c = nested_transforms();
        for (w, h) in [(150u32, 97u32), (64, 64), (7, 130)] {
            let s = RenderSettings::new(w, h);
            let full = render_frame(&c, &s);
            assert!(
                full.samples.iter().any(Sample::is_hit) && full.samples.iter().any(|p| !p.is_hit()),
                "{w}x{h}"
            );
            for tracing in [Tracing::Packets, Tracing::SingleRays] {
                // (plan, bound, the passes shown, PassInfo::passes after each)
                let plans: [(&[u32], _, &[u32], &[usize]); 3] = [
                    (&SCALES, None, &SCALES, &[5, 5, 5, 5, 5]),
                    (&SCALES, Some(Duration::MAX), &[16, 8, 1], &[5, 3, 3]),
                    (&[8, 4, 1], None, &[8, 4, 1], &[3, 3, 3]),
                ];
                for (plan, skip, scales, passes) in plans {
                    let target = SharedFrame::new();
                    let mut shown = Vec::new();
                    let schedule = Schedule {
                        scales: plan,
                        straight_to_full_below: skip,
                        tracing,
                    };
                    let Ok(()) =
                        render_scales(&c, &s, schedule, &target, &Uncancellable, &mut |p| {
                            shown.push((p.scale, p.passes, target.lock().clone()));
                        });
                    assert_eq!(shown.iter().map(|(s, _, _)| *s).collect::<Vec<_>>(), scales);
                    assert_eq!(shown.iter().map(|(_, n, _)| *n).collect::<Vec<_>>(), passes);
                    for (scale, _, f) in &shown {
                        for y in 0..h {
                            for x in 0..w {
                                let corner = full.get(x - x % scale, y - y % scale);
                                assert_eq!(
                                    f.get(x, y),
                                    corner,
                                    "{w}x{h} {tracing:?} {skip:?} after the {scale}× pass, pixel ({x}, {y})"
                                );
                            }
                        }
                    }
                    assert_eq!(target.progress(), 1.0);
                }
            }
        }
    }

    /// Coarse passes nobody reads stay at their own resolution, each taking the points of the
    /// one before from that one's grid: what `coarse()` shows after each, unread, is the
    /// blocks of the full render, the frame is untouched (a fresh frame stays unsized until
    /// read), and the full pass then starts from them and ends with the full render.
    #[test]
    fn unread_coarse_passes_chain_at_their_own_resolution() {
        let c = nested_transforms();
        for (w, h) in [(150u32, 97u32), (7, 130)] {
            let s = RenderSettings::new(w, h);
            let full = render_frame(&c, &s);
            let target = SharedFrame::new();
            let mut shown = Vec::new();
            let schedule = Schedule {
                scales: &SCALES,
                straight_to_full_below: None,
                tracing: Tracing::Packets,
            };
            let Ok(()) = render_scales(&c, &s, schedule, &target, &Uncancellable, &mut |p| {
                let coarse = target.coarse();
                // What readers that do not lock see: the pass shown, at the frame's size.
                let now = target.shown();
                assert_eq!(now.size(), (w, h));
                for (x, y) in [(0, 0), (w - 1, h - 1), (w / 2, h / 3), (w, 0), (0, h)] {
                    let want = match &coarse {
                        Some(c) => c.get(x, y),
                        None => now.0.frame.get(x, y),
                    };
                    assert_eq!(now.get(x, y), want);
                }
                drop(now);
                shown.push((p.scale, coarse, target.pixels().frame.width));
            });
            for (scale, coarse, frame_width) in &shown {
                if *scale < WRITE_WHOLE_FROM_SCALE {
                    assert!(coarse.is_none(), "{scale}× is written into the frame");
                    continue;
                }
                let coarse = coarse.as_ref().expect("kept coarse");
                assert_eq!((coarse.scale, *frame_width), (*scale, 0), "{w}x{h}");
                let f = coarse.spread();
                for y in 0..h {
                    for x in 0..w {
                        let corner = full.get(x - x % scale, y - y % scale);
                        assert_eq!(f.get(x, y), corner, "{w}x{h} {scale}× ({x}, {y})");
                    }
                }
            }
            assert_eq!(*target.lock(), full, "{w}x{h}");
        }
    }

    /// A coarse pass skips the passes between it and the full one when the full pass's rays
    /// would take less than the bound at its time per ray, the 16× pass never. At 800², the
    /// 8× pass traces 7,500 rays after the 16× one and leaves 630,000 (250 ms allows 2.98 ms);
    /// the 4× pass traces 30,000 and leaves 600,000 (12.5 ms).
    #[test]
    fn a_quick_coarse_pass_goes_straight_to_the_full_one() {
        let ms = Duration::from_millis;
        let us = Duration::from_micros;
        let below = Some(STRAIGHT_TO_FULL_BELOW);
        assert_eq!(STRAIGHT_TO_FULL_BELOW, ms(250));
        assert_eq!(SCALES, [16, 8, 4, 2, 1]);
        let skip = |plan: &[u32], pass, took, size| passes_to_skip(plan, pass, took, size, below);
        assert_eq!(skip(&SCALES, 0, Duration::ZERO, (800, 800)), 0, "16× never");
        assert_eq!(skip(&[16, 1], 0, Duration::ZERO, (800, 800)), 0);
        assert_eq!(skip(&SCALES, 1, us(2_950), (800, 800)), 2);
        assert_eq!(skip(&SCALES, 1, us(3_000), (800, 800)), 0);
        assert_eq!(skip(&SCALES, 2, ms(12), (800, 800)), 1);
        assert_eq!(skip(&SCALES, 2, ms(13), (800, 800)), 0);
        // Any size leaves about the same multiple of a pass's rays: the time per ray decides.
        assert_eq!(skip(&SCALES, 2, ms(12), (3840, 2160)), 1);
        assert_eq!(skip(&SCALES, 2, ms(13), (3840, 2160)), 0);
        assert_eq!(passes_to_skip(&SCALES, 0, ms(1), (800, 800), None), 0);
        assert_eq!(
            skip(&SCALES, 3, ms(1), (800, 800)),
            0,
            "nothing between 2× and 1×"
        );
        assert_eq!(
            skip(&SCALES[..3], 1, us(1), (800, 800)),
            0,
            "the coarse passes alone"
        );
        assert_eq!(skip(&[8, 4, 1], 0, ms(1), (800, 800)), 1);
        assert_eq!(skip(&[1], 0, ms(1), (800, 800)), 0, "one full pass");
    }

    /// A cancel before a pass is written leaves the frame as the last pass left it.
    #[test]
    fn a_cancelled_render_stops_without_writing_the_pass() {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/perspective_mesh.txt");
        let scene = load_scene(&path, &mut MeshCache::new())
            .into_result()
            .expect("scene loads")
            .0;
        let c = CompiledScene::new(&scene);
        let s = RenderSettings::new(130, 70);
        let target = SharedFrame::new();
        let cancel = AtomicBool::new(false);
        let mut after_first = None;
        let r = render(&c, &s, RenderPlan::PROGRESSIVE, &target, &cancel, |_| {
            after_first.get_or_insert_with(|| target.lock().clone());
            cancel.store(true, Ordering::Relaxed);
        });
        assert_eq!(r, Err(Cancelled));
        assert_eq!(after_first.as_ref(), Some(&*target.lock()));
    }
}
