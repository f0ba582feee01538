//! The command line: modern subcommands (clap) and the course's own `raytracer` flags.
//! This module dispatches; each command lives in its own file (`render`, `fmt`, the course's
//! flags in `course`), the benchmarks in `crate::bench`, the editor in `crate::gui`.
//!
//! Exit codes: 0 success, 1 scene or I/O error, 2 usage error (see `crate::exit`).

mod animate;
mod course;
mod diff;
mod fmt;
mod inspect;
mod progress;
mod render;
mod values;

use std::ffi::OsString;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

pub use course::parse_course_args;
pub use render::{NormalMode, RenderArgs, RenderJob, run_render};

use crate::bench::{BenchArgs, ProgressiveArgs};
use crate::exit::Exit;

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
    /// Sweep one number of a Transform op over N frames: a PNG sequence and an animated PNG.
    Animate(animate::AnimateArgs),
    /// Compare your image with the reference for a course command line (after --): heat map, worst pixels.
    #[command(long_about = diff::LONG_ABOUT)]
    Diff(diff::DiffArgs),
    /// One pixel's story: ray, path with M / M⁻¹ / (M⁻¹)ᵀ, t, normals, shading (rows from the top).
    #[command(long_about = inspect::LONG_ABOUT)]
    Inspect(inspect::InspectArgs),
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

pub fn main() -> ExitCode {
    crate::logging::init();
    // args_os: a file name need not be UTF-8.
    let args: Vec<OsString> = std::env::args_os().collect();
    match run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => report(&e),
    }
}

/// Prints an error once, as its kind asks, and gives its exit code.
fn report(e: &anyhow::Error) -> ExitCode {
    match e.downcast_ref::<Exit>() {
        Some(Exit::Usage(m)) => {
            print_err(&format!("tracelab: {m}\nTry 'tracelab --help'.\n"));
            ExitCode::from(2)
        }
        Some(Exit::UsagePrinted) => ExitCode::from(2),
        Some(Exit::OutputClosed) => ExitCode::SUCCESS,
        Some(Exit::Differs) => ExitCode::from(3),
        None => {
            let m = e.to_string();
            print_err(&format!("{m}{}", if m.ends_with('\n') { "" } else { "\n" }));
            ExitCode::from(1)
        }
    }
}

/// Writes to standard error; with standard error closed or full there is no one left to tell.
fn print_err(text: &str) {
    let _ = std::io::stderr().lock().write_all(text.as_bytes());
}

pub fn run(args: &[OsString]) -> anyhow::Result<()> {
    // The course's raytracer flags start with a single dash: `-input`, `-size`, ... A course
    // line after `--` belongs to a subcommand (`tracelab diff mine.png -- -input ...`).
    if args
        .iter()
        .skip(1)
        .take_while(|a| *a != "--")
        .any(|a| a == "-input")
    {
        let job = parse_course_args(args.get(1..).unwrap_or_default())?;
        return run_render(&job);
    }
    let cli = match Cli::try_parse_from(args) {
        Ok(c) => c,
        Err(e) => {
            // --help and --version print and succeed; real usage errors exit 2.
            let _ = e.print();
            return match e.kind() {
                clap::error::ErrorKind::DisplayHelp | clap::error::ErrorKind::DisplayVersion => {
                    Ok(())
                }
                _ => Err(Exit::UsagePrinted.into()),
            };
        }
    };
    match cli.command {
        Some(Command::Render(r)) => run_render(&render::render_job(r)?),
        Some(Command::Inspect(a)) => inspect::run_inspect(&a),
        Some(Command::Diff(a)) => diff::run_diff(&a),
        Some(Command::Animate(a)) => animate::run_animate(&a),
        Some(Command::Fmt { scene, output }) => fmt::run_fmt(&scene, output.as_deref()),
        Some(Command::Bench(b)) => with_threads(b.threads, || crate::bench::run(&b)),
        Some(Command::BenchProgressive(b)) => {
            with_threads(b.threads.unwrap_or_else(rayon::current_num_threads), || {
                crate::bench::run_progressive(&b)
            })
        }
        None => open_editor(cli.scene),
    }
}

#[cfg(feature = "gui")]
fn open_editor(scene: Option<PathBuf>) -> anyhow::Result<()> {
    crate::gui::run(scene)
}

/// A command-line build (`--no-default-features`) has no editor: say so, and how to get one.
#[cfg(not(feature = "gui"))]
fn open_editor(_scene: Option<PathBuf>) -> anyhow::Result<()> {
    Err(crate::exit::usage(
        "the editor is not built in: this tracelab was built without the cargo feature `gui`.\n\
         To get it, build with the default features: cargo install --path app",
    ))
}

fn with_threads(
    threads: usize,
    f: impl FnOnce() -> anyhow::Result<()> + Send,
) -> anyhow::Result<()> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.max(1))
        .build()
        .map_err(|e| anyhow::anyhow!("cannot start threads: {e}"))?;
    pool.install(f)
}
