//! The command line: modern subcommands (clap) and the course's own `raytracer` flags.
//!
//! Exit codes: 0 success, 1 scene or I/O error, 2 usage error.

use std::ffi::{OsStr, OsString};
use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use clap::{Parser, Subcommand, ValueEnum};
use tracelab_core::render::{SharedFrame, check_image_size, render_full};
use tracelab_core::{CompiledScene, MeshCache, NormalTransform, RenderSettings, Scene, View};

#[derive(Parser, Debug)]
#[command(
    name = "tracelab",
    version,
    about = "Scene viewer, editor and ray tracer for MIT 6.837 scene files",
    long_about = "Scene viewer, editor and ray tracer for MIT 6.837 scene files.\n\n\
        With no arguments, opens the editor on a built-in scene; with a SCENE, opens that file.\n\
        The course's own command lines work unchanged, e.g.\n  \
        tracelab -input scene2_05_inside_sphere.txt -size 200 200 -output out.tga \\\n    \
        -depth 9 11 depth.tga -normals normals.tga -shade_back\n\n\
        Images are at most 16384 pixels a side and 67108864 (8192x8192) pixels in all.",
    args_conflicts_with_subcommands = true
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
    /// Scene file to open in the editor.
    pub scene: Option<PathBuf>,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Render a scene to image files (format from the extension: .png .tga .ppm .bmp).
    Render(RenderArgs),
    /// Rewrite a scene file in canonical form.
    Fmt {
        scene: PathBuf,
        /// Where to write (default: standard output).
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
    /// Time closest-hit queries for one primary ray per pixel (see ../shared/perf).
    Bench(BenchArgs),
    /// Time the progressive renderer from a scene change to the first coarse and the full image.
    BenchProgressive(ProgressiveArgs),
}

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
}

#[derive(clap::Args, Debug)]
pub struct BenchArgs {
    pub scene: PathBuf,
    /// Image size in pixels (each side 1 to 16384, at most 8192x8192 pixels in all).
    #[arg(long, num_args = 2, value_names = ["W", "H"], default_values_t = [800u32, 800], allow_negative_numbers = true)]
    pub size: Vec<u32>,
    #[arg(long, default_value_t = 1, allow_negative_numbers = true)]
    pub threads: usize,
    #[arg(long, default_value_t = 5, allow_negative_numbers = true)]
    pub repeat: usize,
    /// Trace 4x2 pixel tiles as 8-ray packets (as Embree's rtcIntersect8 loop does).
    #[arg(long)]
    pub packets: bool,
}

#[derive(clap::Args, Debug)]
pub struct ProgressiveArgs {
    pub scene: PathBuf,
    /// Image size in pixels (each side 1 to 16384, at most 8192x8192 pixels in all).
    #[arg(long, num_args = 2, value_names = ["W", "H"], default_values_t = [800u32, 800], allow_negative_numbers = true)]
    pub size: Vec<u32>,
    /// Threads (default: all cores, as the GUI uses).
    #[arg(long, allow_negative_numbers = true)]
    pub threads: Option<usize>,
    #[arg(long, default_value_t = 10, allow_negative_numbers = true)]
    pub repeat: usize,
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
}

/// An error with the exit code it maps to.
#[derive(Debug)]
pub enum CliError {
    Usage(String),
    Failed(String),
    /// A usage error already printed (by clap).
    UsagePrinted,
    /// The reader of standard output went away (`| head`): it wanted no more, so stop
    /// quietly with success, as a program killed by SIGPIPE would in a shell pipeline.
    OutputClosed,
}

impl CliError {
    fn code(&self) -> ExitCode {
        match self {
            CliError::Usage(_) | CliError::UsagePrinted => ExitCode::from(2),
            CliError::Failed(_) => ExitCode::from(1),
            CliError::OutputClosed => ExitCode::SUCCESS,
        }
    }
}

pub fn main() -> ExitCode {
    // args_os: a file name need not be UTF-8.
    let args: Vec<OsString> = std::env::args_os().collect();
    let result = run(&args);
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            match &e {
                CliError::Usage(m) => print_err(&format!("tracelab: {m}\nTry 'tracelab --help'.\n")),
                CliError::Failed(m) => print_err(&format!("{m}{}", if m.ends_with('\n') { "" } else { "\n" })),
                CliError::UsagePrinted | CliError::OutputClosed => {}
            }
            e.code()
        }
    }
}

/// Writes to standard error; with standard error closed or full there is no one left to tell.
fn print_err(text: &str) {
    let _ = std::io::stderr().lock().write_all(text.as_bytes());
}

pub fn run(args: &[OsString]) -> Result<(), CliError> {
    // The course's raytracer flags start with a single dash: `-input`, `-size`, ...
    if args.iter().skip(1).any(|a| a == "-input") {
        let job = parse_course_args(args.get(1..).unwrap_or_default())?;
        return run_render(&job);
    }
    let cli = match Cli::try_parse_from(args) {
        Ok(c) => c,
        Err(e) => {
            // --help and --version print and succeed; real usage errors exit 2.
            let _ = e.print();
            return match e.kind() {
                clap::error::ErrorKind::DisplayHelp | clap::error::ErrorKind::DisplayVersion => Ok(()),
                _ => Err(CliError::UsagePrinted),
            };
        }
    };
    match cli.command {
        Some(Command::Render(r)) => run_render(&render_job(r)?),
        Some(Command::Fmt { scene, output }) => run_fmt(&scene, output.as_deref()),
        Some(Command::Bench(b)) => with_threads(b.threads, || crate::bench::run(&b)),
        Some(Command::BenchProgressive(b)) => {
            with_threads(b.threads.unwrap_or_else(rayon::current_num_threads), || crate::bench::run_progressive(&b))
        }
        None => run_gui(cli.scene),
    }
}

fn run_gui(scene: Option<PathBuf>) -> Result<(), CliError> {
    crate::app::run(scene).map_err(CliError::Failed)
}

fn render_job(r: RenderArgs) -> Result<RenderJob, CliError> {
    let depth = match r.depth {
        None => None,
        Some(v) => {
            let [min, max, file] = v.as_slice() else {
                return Err(CliError::Usage("--depth needs MIN MAX FILE".into()));
            };
            Some((parse_f32(min, "--depth MIN")?, parse_f32(max, "--depth MAX")?, PathBuf::from(file)))
        }
    };
    let job = RenderJob {
        scene: r.scene,
        width: r.size.first().copied().unwrap_or(0),
        height: r.size.get(1).copied().unwrap_or(0),
        output: r.output,
        normals: r.normals,
        depth,
        shade_back: r.shade_back,
        normal_transform: r.normal_transform.into(),
    };
    if job.output.is_none() && job.normals.is_none() && job.depth.is_none() {
        return Err(CliError::Usage("nothing to write: give --output, --normals or --depth".into()));
    }
    Ok(job)
}

fn parse_f32(s: &OsStr, what: &str) -> Result<f32, CliError> {
    s.to_str()
        .and_then(|t| t.parse::<f32>().ok())
        .filter(|v| v.is_finite())
        .ok_or_else(|| CliError::Usage(format!("{what}: expected a number, found \"{}\"", s.display())))
}

fn parse_u32(s: &OsStr, what: &str) -> Result<u32, CliError> {
    s.to_str()
        .and_then(|t| t.parse::<u32>().ok())
        .filter(|&v| v > 0)
        .ok_or_else(|| CliError::Usage(format!("{what}: expected a positive whole number, found \"{}\"", s.display())))
}

/// The size limit of `tracelab_core::render::check_image_size`, as a usage error.
pub fn check_size(width: u32, height: u32) -> Result<(), CliError> {
    check_image_size(width, height).map_err(|e| CliError::Usage(e.to_string()))
}

/// The course's flags, verbatim: `-input F -size W H -output F -normals F -depth MIN MAX F
/// -shade_back`, plus tracelab's `-normal_transform correct|incorrect`.
pub fn parse_course_args(args: &[OsString]) -> Result<RenderJob, CliError> {
    let mut job = RenderJob {
        scene: None,
        width: 0,
        height: 0,
        output: None,
        normals: None,
        depth: None,
        shade_back: false,
        normal_transform: NormalTransform::Correct,
    };
    let mut it = args.iter();
    let take = |it: &mut std::slice::Iter<OsString>, flag: &str| -> Result<OsString, CliError> {
        it.next().cloned().ok_or_else(|| CliError::Usage(format!("{flag} needs a value")))
    };
    while let Some(arg) = it.next() {
        // Flags are ASCII; a value after one may be any bytes (a file name).
        let a = arg.to_str().unwrap_or_default();
        match a {
            "-input" => job.scene = Some(PathBuf::from(take(&mut it, a)?)),
            "-size" => {
                job.width = parse_u32(&take(&mut it, a)?, "-size width")?;
                job.height = parse_u32(&take(&mut it, a)?, "-size height")?;
            }
            "-output" => job.output = Some(PathBuf::from(take(&mut it, a)?)),
            "-normals" => job.normals = Some(PathBuf::from(take(&mut it, a)?)),
            "-depth" => {
                let min = parse_f32(&take(&mut it, a)?, "-depth min")?;
                let max = parse_f32(&take(&mut it, a)?, "-depth max")?;
                job.depth = Some((min, max, PathBuf::from(take(&mut it, a)?)));
            }
            "-shade_back" => job.shade_back = true,
            "-normal_transform" => {
                let v = take(&mut it, a)?;
                job.normal_transform = match v.to_str() {
                    Some("correct") => NormalTransform::Correct,
                    Some("incorrect") => NormalTransform::Incorrect,
                    _ => return Err(CliError::Usage(format!("-normal_transform: expected correct or incorrect, found \"{}\"", v.display()))),
                }
            }
            _ => return Err(CliError::Usage(format!("unknown option \"{}\" (course flags: -input -size -output -normals -depth -shade_back)", arg.display()))),
        }
    }
    if job.scene.is_none() {
        return Err(CliError::Usage("-input needs a scene file".into()));
    }
    if job.width == 0 {
        return Err(CliError::Usage("-size W H is required".into()));
    }
    Ok(job)
}

/// Reads a scene, printing warnings; errors come back as one message.
pub fn load(path: Option<&Path>) -> Result<Scene, CliError> {
    let mut cache = MeshCache::new();
    let outcome = match path {
        Some(p) => tracelab_core::load_scene(p, &mut cache),
        None => tracelab_core::parse_scene(crate::DEFAULT_SCENE.as_bytes(), crate::DEFAULT_SCENE_NAME, None, &mut cache),
    };
    match outcome.into_result() {
        Ok((scene, warnings)) => {
            for w in warnings.warnings() {
                eprintln!("{w}");
            }
            Ok(scene)
        }
        Err(diags) => Err(CliError::Failed(diags.to_string())),
    }
}

fn check_extension(path: &Path) -> Result<(), CliError> {
    match crate::io::image_format(path) {
        Some(_) => Ok(()),
        None => Err(CliError::Usage(format!(
            "{}: unknown image format (use .png, .tga, .ppm or .bmp)",
            path.display()
        ))),
    }
}

pub fn run_render(job: &RenderJob) -> Result<(), CliError> {
    for p in [&job.output, &job.normals].into_iter().flatten().chain(job.depth.as_ref().map(|d| &d.2)) {
        check_extension(p)?;
    }
    // Before loading, and long before allocating the frame.
    check_size(job.width, job.height)?;
    let scene = load(job.scene.as_deref())?;
    let compiled = CompiledScene::new(&scene);
    let settings = RenderSettings {
        width: job.width,
        height: job.height,
        shade_back: job.shade_back,
        normal_transform: job.normal_transform,
    };
    let frame = render_with_progress(&compiled, &settings);
    let save = |view: View, depth: (f32, f32), path: &Path| {
        crate::io::write_image(&frame, view, depth, path).map_err(CliError::Failed)
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

/// Renders at full resolution; shows a progress bar on a terminal once it takes over a second.
fn render_with_progress(scene: &CompiledScene, settings: &RenderSettings) -> tracelab_core::Frame {
    let target = Arc::new(SharedFrame::new());
    let done = Arc::new(AtomicBool::new(false));
    let watcher = std::io::stderr().is_terminal().then(|| {
        let (target, done) = (target.clone(), done.clone());
        std::thread::spawn(move || {
            let start = Instant::now();
            let mut shown = false;
            while !done.load(Ordering::Relaxed) {
                std::thread::sleep(Duration::from_millis(100));
                if start.elapsed() > Duration::from_secs(1) {
                    let p = target.progress();
                    let bar = (p * 30.0) as usize;
                    eprint!("\rrendering [{}{}] {:3.0}%", "#".repeat(bar), " ".repeat(30 - bar.min(30)), p * 100.0);
                    shown = true;
                }
            }
            if shown {
                eprintln!("\rrendering [{}] 100%", "#".repeat(30));
            }
        })
    });
    let never = AtomicBool::new(false);
    let _ = render_full(scene, settings, &target, &never);
    done.store(true, Ordering::Relaxed);
    if let Some(w) = watcher {
        let _ = w.join();
    }
    std::mem::replace(&mut *target.lock(), tracelab_core::Frame::new(0, 0))
}

/// Warnings (comments that cannot be kept, meshes not next to the scene) go to stderr
/// before anything is written.
fn run_fmt(scene: &Path, output: Option<&Path>) -> Result<(), CliError> {
    let mut s = load(Some(scene))?;
    if let Some(out) = output {
        let dir = |p: &Path| p.parent().map_or_else(|| PathBuf::from("."), Path::to_path_buf);
        for w in tracelab_core::rebase_mesh_paths(&mut s, &dir(scene), &dir(out)) {
            eprintln!("{}: warning: {w}", out.display());
        }
    }
    let text = tracelab_core::write_scene(&s);
    match output {
        None => write_stdout(text.as_bytes()),
        Some(out) => crate::io::write_atomic(out, text.as_bytes())
            .map_err(|e| CliError::Failed(format!("{}: cannot write: {e}", out.display()))),
    }
}

/// Writes to standard output, checking the write and the flush: a reader that closed the
/// pipe (`| head`) wanted no more, which ends the run quietly; anything else (a full disk)
/// is an error.
pub(crate) fn write_stdout(bytes: &[u8]) -> Result<(), CliError> {
    let mut out = std::io::stdout().lock();
    match out.write_all(bytes).and_then(|()| out.flush()) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Err(CliError::OutputClosed),
        Err(e) => Err(CliError::Failed(format!("standard output: cannot write: {e}"))),
    }
}

fn with_threads(threads: usize, f: impl FnOnce() -> Result<(), CliError> + Send) -> Result<(), CliError> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.max(1))
        .build()
        .map_err(|e| CliError::Failed(format!("cannot start threads: {e}")))?;
    pool.install(f)
}
