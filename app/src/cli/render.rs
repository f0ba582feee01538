//! `tracelab render` (and the course's flags, which make the same [`RenderJob`]): a scene to
//! colour, normal and depth images.

use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use clap::ValueEnum;
use tracelab_core::render::{
    Filter, FilterError, RenderPlan, SamplerKind, Secondary, SharedFrame, Uncancellable, render,
};
use tracelab_core::{CompiledScene, NormalTransform, ObjectRays, RenderSettings, View};

use super::progress::Watcher;
use super::supersample::{Supersample, film_for, filtered_frame, write_pictures};
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
    #[command(flatten)]
    pub sampling: SamplingArgs,
}

/// Assignment 7's flags (the course's -uniform_samples, -box_filter, ... spelled long).
#[derive(clap::Args, Debug, Clone, Default)]
pub struct SamplingArgs {
    /// Samples a pixel (1 to 65536; a square for uniform and jittered sampling; at most
    /// 67,108,864 samples in the image). Default: one sample at the pixel's centre.
    #[arg(long, value_name = "N")]
    pub samples: Option<OsString>,
    /// Where the samples lie in the pixel: a k×k grid of cell centres, anywhere (random), or
    /// one anywhere in each cell of a k×k grid (jittered). Needs --samples.
    #[arg(long, value_enum, requires = "samples")]
    pub sampler: Option<SamplerMode>,
    /// Box filter of half-width R pixels (0 < R ≤ 64): the course's -box_filter.
    #[arg(long, value_name = "R", allow_negative_numbers = true)]
    pub box_filter: Option<OsString>,
    /// Tent filter of radius R pixels (0 < R ≤ 64): the course's -tent_filter.
    #[arg(long, value_name = "R", allow_negative_numbers = true)]
    pub tent_filter: Option<OsString>,
    /// Gaussian filter e^(−d²/2σ²) over 2σ pixels (0 < σ ≤ 32): the course's -gaussian_filter.
    #[arg(long, value_name = "SIGMA", allow_negative_numbers = true)]
    pub gaussian_filter: Option<OsString>,
    /// Seed of random and jittered sampling (0 to 2^64−1; default 6837): the same seed gives
    /// the same image. The course's lines take -seed N.
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub seed: Option<OsString>,
    /// The samples as dots of their colour, each pixel ZOOM×ZOOM: the course's -render_samples.
    #[arg(long, num_args = 2, value_names = ["FILE", "ZOOM"], allow_negative_numbers = true)]
    pub render_samples: Option<Vec<OsString>>,
    /// The filter's weights around the centre pixel, each pixel ZOOM×ZOOM: the course's
    /// -render_filter.
    #[arg(long, num_args = 2, value_names = ["FILE", "ZOOM"], allow_negative_numbers = true)]
    pub render_filter: Option<Vec<OsString>>,
}

/// A filter from its one number, checked (`Filter::box_filter`, `tent`, `gaussian`).
type MakeFilter = fn(f32) -> Result<Filter, FilterError>;

#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum SamplerMode {
    /// A k×k grid of cell centres, (a + ½)/k (the course's -uniform_samples).
    Uniform,
    /// Anywhere in the pixel, seeded (-random_samples).
    Random,
    /// One anywhere in each cell of a k×k grid, seeded (-jittered_samples).
    Jittered,
}

impl SamplingArgs {
    /// The flags checked one by one, as the course's are.
    pub fn supersample(&self) -> anyhow::Result<Supersample> {
        let mut s = Supersample::default();
        if let Some(n) = &self.samples {
            let kind = match self.sampler.unwrap_or(SamplerMode::Uniform) {
                SamplerMode::Uniform => SamplerKind::Uniform,
                SamplerMode::Random => SamplerKind::Random,
                SamplerMode::Jittered => SamplerKind::Jittered,
            };
            s.set_sampler(kind, n, "--samples")?;
        }
        let filters: [(&Option<OsString>, &str, MakeFilter); 3] = [
            (&self.box_filter, "--box-filter", Filter::box_filter),
            (&self.tent_filter, "--tent-filter", Filter::tent),
            (&self.gaussian_filter, "--gaussian-filter", Filter::gaussian),
        ];
        for (v, flag, make) in filters {
            if let Some(v) = v {
                s.set_filter(make, v, flag)?;
            }
        }
        if let Some(v) = &self.seed {
            s.set_seed(v, "--seed")?;
        }
        for (v, flag) in [
            (&self.render_samples, "--render-samples"),
            (&self.render_filter, "--render-filter"),
        ] {
            let Some(v) = v else { continue };
            let [file, zoom] = v.as_slice() else {
                return Err(usage(format!("{flag} needs FILE ZOOM")));
            };
            let picture = Supersample::picture(file, zoom, flag)?;
            if flag == "--render-samples" {
                s.render_samples = Some(picture);
            } else {
                s.render_filter = Some(picture);
            }
        }
        Ok(s)
    }
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
    /// Assignment 7: the sampler, the filter, the seed and the pictures of them.
    pub supersample: Supersample,
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
    let supersample = r.sampling.supersample()?;
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
        supersample,
    };
    if job.output.is_none()
        && job.normals.is_none()
        && job.depth.is_none()
        && job.supersample.outputs().next().is_none()
    {
        return Err(usage(
            "nothing to write: give --output, --normals, --depth, --render-samples or --render-filter",
        ));
    }
    let mut others = Vec::new();
    if job.normals.is_some() {
        others.push("--normals");
    }
    if job.depth.is_some() {
        others.push("--depth");
    }
    job.supersample
        .resolve(job.width, job.height, &others, None)?;
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
            .map(PathBuf::as_path)
            .chain(job.depth.as_ref().map(|d| d.2.as_path()))
            .chain(job.supersample.outputs())
    };
    for p in outputs() {
        check_extension(p)?;
    }
    // Before loading, and long before allocating the frame.
    check_size(job.width, job.height)?;
    check_memory(job.width, job.height)?;
    let resolved = job.supersample.resolve(job.width, job.height, &[], None)?;
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
        // The command line traces and filters its film itself (`supersample.rs`).
        supersample: None,
    };
    if job.supersample.is_set() {
        // The film is traced where the colour image or the samples' picture needs it.
        let film = (job.output.is_some() && job.supersample.filters_the_output()
            || job.supersample.render_samples.is_some())
        .then(|| film_for(&compiled, &settings, &resolved))
        .transpose()?;
        if let Some(p) = &job.output {
            let frame = match &film {
                Some(f) if job.supersample.filters_the_output() => {
                    filtered_frame(f, &resolved.filter)?
                }
                _ => render_with_progress(&compiled, &settings)?,
            };
            crate::io::write_image(&frame, View::Color, (0.0, 1.0), p)
                .map_err(anyhow::Error::msg)?;
        }
        return write_pictures(
            &job.supersample,
            &resolved,
            film.as_ref(),
            (job.width, job.height),
        );
    }
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
    if job.supersample.filters_the_output() {
        let resolved = job
            .supersample
            .resolve(settings.width, settings.height, &[], None)?;
        return filtered_frame(&film_for(compiled, settings, &resolved)?, &resolved.filter);
    }
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
    let watched = target.clone();
    let bar = Watcher::on_stderr(RENDER_PROGRESS, 1000, move || {
        (watched.progress() * 1000.0) as u64
    });
    let plan = RenderPlan::FULL;
    let Ok(()) = render(scene, settings, plan, &target, &Uncancellable, |_| {});
    bar.finish();
    Ok(std::mem::replace(
        &mut *target.lock(),
        tracelab_core::Frame::new(0, 0),
    ))
}
