//! The benchmarks, with their own options: `tracelab bench` (closest-hit throughput,
//! [`closest_hit`]) and `tracelab bench-progressive` (the GUI's wait after a change,
//! [`progressive`]). Their `BENCH`/`PROGRESSIVE` lines are what `../shared/perf` compares.

use std::path::PathBuf;

use tracelab_core::RenderSettings;
use tracelab_core::render::{Secondary, ShadowQuery};

/// `println!` that checks the write (a full disk is an error, a closed pipe ends the run).
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::io::write_stdout(format!("{}\n", format_args!($($arg)*)).as_bytes())?
    };
}

mod closest_hit;
mod progressive;

pub use closest_hit::run;
pub use progressive::run_progressive;

/// Most threads a benchmark starts: more than any machine tracelab runs on has cores, and
/// few enough that starting them is quick and cannot use up the process ids.
pub const MAX_THREADS: usize = 1024;
/// Most timed runs: a million keeps the times' list a few megabytes.
pub const MAX_REPEAT: usize = 1_000_000;
/// Most orbit steps.
pub const MAX_ORBIT: usize = 100_000;

/// A count from 0 to `max` for an option, or clap's usage error (exit 2) naming the cap.
fn count_up_to(s: &str, max: usize) -> Result<usize, String> {
    let n: usize = s
        .parse()
        .map_err(|_| format!("expected a whole number from 0 to {max}"))?;
    if n > max {
        return Err(format!("at most {max}"));
    }
    Ok(n)
}

fn threads(s: &str) -> Result<usize, String> {
    count_up_to(s, MAX_THREADS)
}

fn repeat(s: &str) -> Result<usize, String> {
    count_up_to(s, MAX_REPEAT)
}

fn orbit(s: &str) -> Result<usize, String> {
    count_up_to(s, MAX_ORBIT)
}

#[derive(clap::Args, Debug)]
pub struct BenchArgs {
    pub scene: PathBuf,
    /// Image size in pixels (each side 1 to 16384, at most 8192x8192 pixels in all).
    #[arg(long, num_args = 2, value_names = ["W", "H"], default_values_t = [800u32, 800], allow_negative_numbers = true)]
    pub size: Vec<u32>,
    /// Threads, at most 1024.
    #[arg(long, default_value_t = 1, allow_negative_numbers = true, value_parser = threads)]
    pub threads: usize,
    /// Timed frames after a warm-up, at most 1000000; more (up to 10000) until they have taken
    /// 0.25 s, so that a short frame's median outlasts a stall of the shared machine.
    #[arg(long, default_value_t = 5, allow_negative_numbers = true, value_parser = repeat)]
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
    /// Threads, at most 1024 (default: all cores, as the GUI uses).
    #[arg(long, allow_negative_numbers = true, value_parser = threads)]
    pub threads: Option<usize>,
    /// Timed runs after a warm-up, at most 1000000.
    #[arg(long, default_value_t = 10, allow_negative_numbers = true, value_parser = repeat)]
    pub repeat: usize,
    /// Also time a camera orbit of this many steps (a full turn about the scene's centre),
    /// as a middle-drag in the editor makes them: per step, the time to the first (coarse)
    /// image and to the full one. At most 100000.
    #[arg(long, allow_negative_numbers = true, value_parser = orbit)]
    pub orbit: Option<usize>,
    /// Trace the primary rays one at a time instead of eight at a time (the same image, bit
    /// for bit; to measure what the packets gain).
    #[arg(long)]
    pub single_rays: bool,
    /// Time one full-resolution pass (what `tracelab render` does) instead of the coarse
    /// passes and the full one: what the progressive passes cost on top.
    #[arg(long)]
    pub one_pass: bool,
    /// Shadow rays toward every light (the course's -shadows).
    #[arg(long)]
    pub shadows: bool,
    /// Levels of reflected and refracted rays (the course's -bounces; 0 to 100).
    #[arg(long, default_value_t = 0)]
    pub bounces: u32,
    /// Rays whose weight is below this are not traced (the course's -weight).
    #[arg(long, default_value_t = 0.0)]
    pub weight: f32,
    /// Flip back faces toward the eye (the course's -shade_back).
    #[arg(long)]
    pub shade_back: bool,
    /// Ask shadow rays by the closest hit instead of the any-hit query (the same image; to
    /// measure what stopping at the first blocker saves).
    #[arg(long)]
    pub closest_hit_shadows: bool,
}

impl ProgressiveArgs {
    /// The render settings these flags ask for, checked as `render`'s are.
    pub fn settings(&self, w: u32, h: u32) -> anyhow::Result<RenderSettings> {
        let secondary = Secondary {
            shadows: self.shadows,
            bounces: self.bounces,
            weight: self.weight,
            shadow_query: if self.closest_hit_shadows {
                ShadowQuery::ClosestHit
            } else {
                ShadowQuery::AnyHit
            },
            ..Secondary::default()
        };
        secondary
            .check_flags("--bounces", "--weight")
            .map_err(crate::exit::usage)?;
        Ok(RenderSettings {
            shade_back: self.shade_back,
            secondary,
            ..RenderSettings::new(w, h)
        })
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}
