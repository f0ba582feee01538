//! The command line: modern subcommands (clap) and the course's own `raytracer` flags.
//! This module dispatches; each command lives in its own file (`render`, `fmt`, the course's
//! flags in `course`), the benchmarks in `crate::bench`, the editor in `crate::gui`.
//!
//! Exit codes: 0 success, 1 scene or I/O error, 2 usage error; `diff` adds 3, 4 and 5 (see
//! `crate::exit`).

mod animate;
mod batch;
mod course;
mod diagnose;
mod diff;
mod fmt;
mod inspect;
mod judge;
mod mistyped;
mod progress;
mod regions;
mod render;
mod report_html;
mod stats;
mod supersample;
mod values;

use std::borrow::Cow;
use std::ffi::OsString;
use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{CommandFactory, Parser, Subcommand};

pub use course::parse_course_args;
pub use render::{NormalMode, RenderArgs, RenderJob, run_render};

use crate::bench::{BenchArgs, ProgressiveArgs};
use crate::exit::{Exit, usage};
use crate::io::{write_stderr_text, write_stdout};

#[derive(Parser, Debug)]
#[command(
    name = "tracelab",
    version,
    about = "Scene viewer, editor and ray tracer for MIT 6.837 scene files",
    long_about = "Scene viewer, editor and ray tracer for MIT 6.837 scene files.\n\n\
        With no arguments, opens the editor on a built-in scene; with a SCENE, opens that file.\n\
        The course's own command lines work unchanged, e.g.\n  \
        tracelab -input scene2_05_inside_sphere.txt -size 200 200 -output out.tga \\\n    \
        -depth 9 11 depth.tga -normals normals.tga -shade_back\n  \
        tracelab -input scene4_14_faceted_gem.txt -size 200 200 -output out.png \\\n    \
        -shadows -shade_back -bounces 5 -weight 0.01\n  \
        tracelab -input scene7_02_checkerboard.txt -size 180 180 -output out.png \\\n    \
        -jittered_samples 16 -gaussian_filter 0.6 -seed 1\n\n\
        Assignment 7: -uniform_samples N and -jittered_samples N take a square N (k x k), \
        -random_samples N any N (1 to 65536); -box_filter R, -tent_filter R (0 < R <= 64), \
        -gaussian_filter SIGMA (<= 32); -render_samples FILE ZOOM, -render_filter FILE ZOOM. \
        Random and jittered sampling are repeatable: tracelab's -seed N (0 to 2^64-1, \
        default 6837) picks the positions.\n\n\
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
    /// Sweep one number of a Transform op over N frames, or the bounce count from A to B: a PNG sequence and an animated PNG.
    Animate(animate::AnimateArgs),
    /// Compare your image with the reference for a course command line (after --): verdict, the mistake it matches, regions, heat map.
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

/// Prints an error once, as its kind asks, and gives its exit code. Paths and names in the
/// message are the user's text: escaped.
fn report(e: &anyhow::Error) -> ExitCode {
    match e.downcast_ref::<Exit>() {
        Some(Exit::Usage(m)) => {
            write_stderr_text(&format!("tracelab: {m}\nTry 'tracelab --help'.\n"));
            ExitCode::from(2)
        }
        Some(Exit::UsagePrinted) => ExitCode::from(2),
        Some(Exit::OutputClosed) => ExitCode::SUCCESS,
        Some(Exit::Differs) => ExitCode::from(3),
        Some(Exit::HeatMapNotWritten { matched, message }) => {
            write_stderr_text(&format!("{message}\n"));
            ExitCode::from(if *matched { 4 } else { 5 })
        }
        None => {
            let m = e.to_string();
            write_stderr_text(&format!("{m}{}", if m.ends_with('\n') { "" } else { "\n" }));
            ExitCode::from(1)
        }
    }
}

/// What clap has to say: help and version through [`write_stdout`] (so a closed or full
/// standard output is an error) unless it is a terminal, where clap's colours are kept;
/// usage errors, which quote the arguments, in clap's colours unless an argument holds a
/// control character, then without colours and escaped.
fn clap_says(e: &clap::Error, args: &[OsString]) -> anyhow::Result<()> {
    use clap::error::ErrorKind;
    if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) {
        if std::io::stdout().is_terminal() {
            let _ = e.print();
            return Ok(());
        }
        return write_stdout(e.render().to_string().as_bytes());
    }
    let plain = |a: &OsString| {
        let a = a.to_string_lossy();
        matches!(tracelab_core::format::escape_controls(&a), Cow::Borrowed(_))
    };
    if args.iter().all(plain) {
        let _ = e.print();
    } else {
        // The same error without clap's styles: only the user's bytes are left to escape
        // (clap's own plain text would drop them, and only when not on a terminal).
        let text = match Cli::command()
            .styles(clap::builder::Styles::plain())
            .try_get_matches_from(args)
        {
            Err(unstyled) => unstyled.render().ansi().to_string(),
            Ok(_) => e.render().to_string(),
        };
        write_stderr_text(&text);
    }
    Err(Exit::UsagePrinted.into())
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
        if args.get(1).is_some_and(|a| a == "diff") {
            return Err(Exit::Usage(
                "diff: the course's command line goes after `--`: \
                 tracelab diff IMAGE -- -input SCENE -size W H ..."
                    .into(),
            )
            .into());
        }
        let job = parse_course_args(args.get(1..).unwrap_or_default())?;
        return run_render(&job);
    }
    let cli = match Cli::try_parse_from(args) {
        Ok(c) => c,
        // --help and --version print and succeed; real usage errors exit 2.
        Err(e) => return clap_says(&e, args),
    };
    match cli.command {
        Some(Command::Render(r)) => run_render(&render::render_job(r)?),
        Some(Command::Inspect(a)) => inspect::run_inspect(&a),
        // `--batch` is dispatched here, not from diff.rs, so batch.rs (which uses diff.rs's
        // judging) and diff.rs do not import each other.
        Some(Command::Diff(a)) => match &a.batch {
            Some(commands) => batch::run_batch(&a, commands, &diff::criterion(&a)?),
            None => diff::run_diff(&a),
        },
        Some(Command::Animate(a)) => animate::run_animate(&a),
        Some(Command::Fmt { scene, output }) => {
            fmt::refuse_run_on_output(args.get(2..).unwrap_or_default())?;
            fmt::run_fmt(&scene, output.as_deref())
        }
        Some(Command::Bench(b)) => with_threads(b.threads, || crate::bench::run(&b)),
        Some(Command::BenchProgressive(b)) => {
            with_threads(b.threads.unwrap_or_else(rayon::current_num_threads), || {
                crate::bench::run_progressive(&b)
            })
        }
        None => {
            let commands = Cli::command();
            if let Some(m) = cli.scene.as_deref().and_then(|p| {
                mistyped::mistyped_command(p, commands.get_subcommands().map(|c| c.get_name()))
            }) {
                return Err(usage(m));
            }
            open_editor(cli.scene)
        }
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
