//! `tracelab bench-progressive`: how long the GUI waits after a change for its first coarse
//! image and for the full colour+normal+depth frame.

use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

use tracelab_core::render::SharedFrame;
use tracelab_core::{CompiledScene, RenderSettings, render_progressive};

use super::{ProgressiveArgs, median};
use crate::exit::check_size;
use crate::io::load_scene;

/// From "the scene changed" (compile the loaded scene) to the first complete coarse pass and
/// to the last, full-resolution pass of the progressive renderer, as the GUI drives it.
pub fn run_progressive(b: &ProgressiveArgs) -> anyhow::Result<()> {
    let (w, h) = (b.size[0], b.size[1]);
    check_size(w, h)?;
    let scene = load_scene(Some(&b.scene))?;
    let settings = RenderSettings::new(w, h);
    let target = SharedFrame::new();
    let never = AtomicBool::new(false);
    let once = || {
        let start = Instant::now();
        let compiled = CompiledScene::new(&scene);
        let mut coarse = None;
        let mut full = Duration::ZERO;
        let _ = render_progressive(&compiled, &settings, &target, &never, |_| {
            coarse.get_or_insert(start.elapsed());
            full = start.elapsed();
        });
        (
            coarse.unwrap_or(full).as_secs_f64() * 1e3,
            full.as_secs_f64() * 1e3,
        )
    };
    once(); // warm-up
    let runs: Vec<(f64, f64)> = (0..b.repeat.max(1)).map(|_| once()).collect();
    let coarse = median(runs.iter().map(|r| r.0).collect());
    let full = median(runs.iter().map(|r| r.1).collect());
    out!(
        "frame: {w}x{h}, {} threads, medians of {}",
        rayon::current_num_threads(),
        runs.len()
    );
    out!("PROGRESSIVE coarse_ms={coarse:.2} full_ms={full:.2}");
    Ok(())
}
