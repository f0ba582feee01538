//! `tracelab render` (and the course's flags, which make the same [`RenderJob`]): a scene to
//! colour, normal and depth images.

use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use clap::ValueEnum;
use tracelab_core::render::{RenderPlan, Secondary, SharedFrame, Uncancellable, render};
use tracelab_core::{CompiledScene, NormalTransform, ObjectRays, RenderSettings, View};

use super::progress::Progress;
use super::values::parse_f32;
use crate::exit::{check_size, usage};
use crate::io::{OutputError, OutputPlan, load_scene_and_meshes};

#[derive(clap::Args, Debug)]
pub struct RenderArgs {
    /// Scene file (default: the built-in scene).
    pub scene: Option<PathBuf>,
    /// Image size in pixels (each side 1 to 16384, at most 8192x8192 pixels in all).
    #[arg(long, num_args = 2, value_names = ["W", "H"], default_values_t = [400u32, 400], allow_negative_numbers = true)]
    pub size: Vec<u32>,
    /// Colour image.
    #[arg(long, short)]
    pub output: Option<PathBuf>,
    /// Normal image: |n| of the world normal as RGB.
    #[arg(long)]
    pub normals: Option<PathBuf>,
    /// Depth image: t in [MIN, MAX] mapped to white..black (MIN may be negative).
    #[arg(long, num_args = 3, value_names = ["MIN", "MAX", "FILE"], allow_negative_numbers = true)]
    pub depth: Option<Vec<OsString>>,
    /// Shade back-facing surfaces with the flipped normal instead of black.
    #[arg(long)]
    pub shade_back: bool,
    /// How normals go through Transforms.
    #[arg(long, value_enum, default_value_t = NormalMode::Correct)]
    pub normal_transform: NormalMode,
    /// How rays go into object space, and which t is kept as the depth.
    #[arg(long, value_enum, default_value_t = ObjectRaysMode::Unnormalized)]
    pub object_rays: ObjectRaysMode,
    #[command(flatten)]
    pub secondary: SecondaryArgs,
}

/// Assignments 3–4's flags, shared by `render` and `inspect`.
#[derive(clap::Args, Debug, Clone)]
pub struct SecondaryArgs {
    /// Shadow rays toward every light (the course's -shadows).
    #[arg(long)]
    pub shadows: bool,
    /// Levels of reflected and refracted rays (the course's -bounces; 0 to 100).
    #[arg(long, default_value_t = 0)]
    pub bounces: u32,
    /// Rays whose weight is below this are not traced (the course's -weight).
    #[arg(long, default_value_t = 0.0)]
    pub weight: f32,
    /// Assignment 3's optional fix: highlights fade with max(N·L, 0) instead of stopping.
    #[arg(long)]
    pub specular_fix: bool,
}

impl SecondaryArgs {
    /// The secondary-ray settings, checked as the course form checks them.
    pub fn secondary(&self) -> anyhow::Result<Secondary> {
        let s = Secondary {
            shadows: self.shadows,
            bounces: self.bounces,
            weight: self.weight,
            specular_fix: self.specular_fix,
            ..Secondary::default()
        };
        s.check_flags("--bounces", "--weight").map_err(usage)?;
        Ok(s)
    }
}

#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum ObjectRaysMode {
    /// M⁻¹d kept as it is: t is the same in object and world space.
    Unnormalized,
    /// M⁻¹d normalised, and t rescaled to world space after intersection (same image).
    Normalized,
    /// M⁻¹d normalised and t not rescaled: the lecture's bug (wrong depth and occlusion).
    NormalizedNoRescale,
}

impl From<ObjectRaysMode> for ObjectRays {
    fn from(m: ObjectRaysMode) -> Self {
        match m {
            ObjectRaysMode::Unnormalized => ObjectRays::Unnormalized,
            ObjectRaysMode::Normalized => ObjectRays::Normalized,
            ObjectRaysMode::NormalizedNoRescale => ObjectRays::NormalizedNoRescale,
        }
    }
}

#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum NormalMode {
    /// (M⁻¹)ᵀ n: perpendicular to the surface under any transform.
    Correct,
    /// M n: the lecture's incorrect transformation, for comparison.
    Incorrect,
}

impl From<NormalMode> for NormalTransform {
    fn from(m: NormalMode) -> Self {
        match m {
            NormalMode::Correct => NormalTransform::Correct,
            NormalMode::Incorrect => NormalTransform::Incorrect,
        }
    }
}

/// A request to render, however it was spelled on the command line.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderJob {
    pub scene: Option<PathBuf>,
    pub width: u32,
    pub height: u32,
    pub output: Option<PathBuf>,
    pub normals: Option<PathBuf>,
    pub depth: Option<(f32, f32, PathBuf)>,
    pub shade_back: bool,
    pub normal_transform: NormalTransform,
    pub object_rays: ObjectRays,
    /// Shadows, bounces, weight and the specular fix (assignments 3–4).
    pub secondary: Secondary,
    /// Assignments 5–6: `-grid NX NY NZ` (the uniform grid instead of the BVH),
    /// `-visualize_grid` (the grid's occupied cells instead of the scene), `-stats`.
    pub grid: Option<[u32; 3]>,
    pub visualize_grid: bool,
    pub stats: bool,
}

pub(super) fn render_job(r: RenderArgs) -> anyhow::Result<RenderJob> {
    let depth = match r.depth {
        None => None,
        Some(v) => {
            let [min, max, file] = v.as_slice() else {
                return Err(usage("--depth needs MIN MAX FILE"));
            };
            Some((
                parse_f32(min, "--depth MIN")?,
                parse_f32(max, "--depth MAX")?,
                PathBuf::from(file),
            ))
        }
    };
    let secondary = r.secondary.secondary()?;
    let job = RenderJob {
        scene: r.scene,
        width: r.size.first().copied().unwrap_or(0),
        height: r.size.get(1).copied().unwrap_or(0),
        output: r.output,
        normals: r.normals,
        depth,
        shade_back: r.shade_back,
        normal_transform: r.normal_transform.into(),
        object_rays: r.object_rays.into(),
        secondary,
        grid: None,
        visualize_grid: false,
        stats: false,
    };
    if job.output.is_none() && job.normals.is_none() && job.depth.is_none() {
        return Err(usage(
            "nothing to write: give --output, --normals or --depth",
        ));
    }
    Ok(job)
}

fn check_extension(path: &Path) -> anyhow::Result<()> {
    if crate::io::output::names_a_folder(path) {
        return Err(OutputError::NamesAFolder(path.to_path_buf()).into_cli());
    }
    match crate::io::image_format(path) {
        Some(_) => Ok(()),
        None => Err(usage(format!(
            "{}: unknown image format (use .png, .tga, .ppm or .bmp)",
            path.display()
        ))),
    }
}

pub fn run_render(job: &RenderJob) -> anyhow::Result<()> {
    let outputs = || {
        [&job.output, &job.normals]
            .into_iter()
            .flatten()
            .chain(job.depth.as_ref().map(|d| &d.2))
    };
    for p in outputs() {
        check_extension(p)?;
    }
    // Before loading, and long before allocating the frame.
    check_size(job.width, job.height)?;
    check_memory(job.width, job.height)?;
    // Outputs against the scene, each other and their folders before anything is read, then
    // against the meshes the scene turned out to read, before the render.
    let mut plan = OutputPlan::new();
    if let Some(s) = &job.scene {
        plan.reads(s);
    }
    for p in outputs() {
        plan.writes(p);
    }
    plan.check().map_err(OutputError::into_cli)?;
    let (scene, meshes) = load_scene_and_meshes(job.scene.as_deref())?;
    if !meshes.is_empty() {
        for m in &meshes {
            plan.reads(m);
        }
        plan.check().map_err(OutputError::into_cli)?;
    }
    let start = std::time::Instant::now();
    let compiled = compile_for(job, &scene)?;
    let settings = RenderSettings {
        width: job.width,
        height: job.height,
        shade_back: job.shade_back,
        normal_transform: job.normal_transform,
        object_rays: job.object_rays,
        variant: None,
        secondary: job.secondary,
    };
    let frame = frame_for(job, &compiled, &settings)?;
    if job.stats {
        crate::io::write_stdout_text(&super::stats::stats_text(
            &compiled,
            &settings,
            start.elapsed(),
        ))?;
    }
    let save = |view: View, depth: (f32, f32), path: &Path| {
        crate::io::write_image(&frame, view, depth, path).map_err(anyhow::Error::msg)
    };
    if let Some(p) = &job.output {
        save(View::Color, (0.0, 1.0), p)?;
    }
    if let Some(p) = &job.normals {
        save(View::Normals, (0.0, 1.0), p)?;
    }
    if let Some((min, max, p)) = &job.depth {
        save(View::Depth, (*min, *max), p)?;
    }
    Ok(())
}

/// The scene compiled for a job: with the course's uniform grid where `-grid` asks for one.
pub(super) fn compile_for(
    job: &RenderJob,
    scene: &tracelab_core::Scene,
) -> anyhow::Result<CompiledScene> {
    let mut compiled = CompiledScene::try_new(scene).map_err(|e| {
        anyhow::anyhow!("not enough memory to prepare the scene for rendering: {e}")
    })?;
    if let Some([x, y, z]) = job.grid {
        compiled
            .use_grid(glam::UVec3::new(x, y, z))
            .map_err(|e| usage(e.to_string()))?;
    }
    Ok(compiled)
}

/// The job's image: the grid's occupied cells under `-visualize_grid`, else the render.
pub(super) fn frame_for(
    job: &RenderJob,
    compiled: &CompiledScene,
    settings: &RenderSettings,
) -> anyhow::Result<tracelab_core::Frame> {
    if job.visualize_grid {
        return Ok(tracelab_core::render::visualize_grid(
            compiled,
            settings.width,
            settings.height,
        ));
    }
    render_with_progress(compiled, settings)
}

/// Bytes a `width` × `height` render takes at its peak: the frame, one view's RGB bytes
/// and their encoded file (at most about as big).
pub fn render_bytes(width: u32, height: u32) -> u64 {
    let rgb = u64::from(width) * u64::from(height) * 3;
    tracelab_core::Frame::bytes(width, height) + 2 * rgb
}

fn out_of_memory(width: u32, height: u32) -> anyhow::Error {
    anyhow::anyhow!(
        "not enough memory to render {width}x{height} (needs about {} MB)",
        tracelab_core::memory::megabytes(render_bytes(width, height))
    )
}

/// Whether a render of this size fits in the memory to be had now, checked before the scene
/// is read: a message then, not an abort half-way.
pub(super) fn check_memory(width: u32, height: u32) -> anyhow::Result<()> {
    tracelab_core::memory::check_available(render_bytes(width, height), "a render")
        .map_err(|_| out_of_memory(width, height))
}

/// The render's bar: share of the tiles done.
const RENDER_PROGRESS: &str = "rendering [{bar:30}] {percent:>3}% ({elapsed}, about {eta} left)";

/// Renders at full resolution; shows a progress bar on a terminal once it takes over a second.
/// The frame is allocated fallibly.
pub(super) fn render_with_progress(
    scene: &CompiledScene,
    settings: &RenderSettings,
) -> anyhow::Result<tracelab_core::Frame> {
    // Rays that double at every bounce would never finish: refused before any work.
    settings.secondary.check_bounded(scene).map_err(usage)?;
    let target = Arc::new(
        SharedFrame::try_sized(settings.width, settings.height)
            .map_err(|_| out_of_memory(settings.width, settings.height))?,
    );
    let done = Arc::new(AtomicBool::new(false));
    let mut bar = Progress::on_stderr(RENDER_PROGRESS, 1000);
    let watcher = bar.on_terminal().then(|| {
        let (target, done) = (target.clone(), done.clone());
        std::thread::spawn(move || {
            while !done.load(Ordering::Relaxed) {
                std::thread::sleep(Duration::from_millis(100));
                bar.set((target.progress() * 1000.0) as u64);
            }
            bar.finish();
        })
    });
    let plan = RenderPlan::FULL;
    let Ok(()) = render(scene, settings, plan, &target, &Uncancellable, |_| {});
    done.store(true, Ordering::Relaxed);
    if let Some(w) = watcher {
        let _ = w.join();
    }
    Ok(std::mem::replace(
        &mut *target.lock(),
        tracelab_core::Frame::new(0, 0),
    ))
}
