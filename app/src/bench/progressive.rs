//! `tracelab bench-progressive`: how long the GUI waits after a change for its first coarse
//! image and for the full colour+normal+depth frame.

use std::time::{Duration, Instant};

use glam::Vec3;
use tracelab_core::render::SharedFrame;
use tracelab_core::render::{RenderPlan, Tracing, Uncancellable, render};
use tracelab_core::{CompiledScene, RenderSettings, Scene};

use crate::bounds::world_bounds;
use crate::navigation::orbit;

use super::{ProgressiveArgs, median};

use crate::exit::check_size;
use crate::io::load_scene;

/// One timed run: time to the first coarse image, to the full image (ms), and each pass by
/// its scale with its own time.
type Run = (f64, f64, Vec<(u32, f64)>);

/// From "the scene changed" (compile the loaded scene) to the first complete coarse pass and
/// to the last, full-resolution pass of the progressive renderer, as the GUI drives it.
pub fn run_progressive(b: &ProgressiveArgs) -> anyhow::Result<()> {
    let (w, h) = (b.size[0], b.size[1]);
    check_size(w, h)?;
    let settings = b.settings(w, h)?;
    let scene = load_scene(Some(&b.scene))?;
    let target = SharedFrame::try_sized(w, h)?;
    let tracing = if b.single_rays {
        Tracing::SingleRays
    } else {
        Tracing::Packets
    };
    // (first coarse image, full frame, each pass's scale and own time), in ms.
    // A line whose rays would never finish is refused, as `render` refuses it.
    settings
        .secondary
        .check_bounded(&CompiledScene::new(&scene))
        .map_err(crate::exit::usage)?;
    let once = || {
        let start = Instant::now();
        let compiled = CompiledScene::new(&scene);
        let mut ends = Vec::new();
        if b.one_pass {
            let plan = RenderPlan::FULL.traced(tracing);
            let Ok(()) = render(&compiled, &settings, plan, &target, &Uncancellable, |_| {});
            std::hint::black_box(target.take());
            let t = start.elapsed().as_secs_f64() * 1e3;
            return (t, t, vec![(1, t)]);
        }
        let plan = RenderPlan::PROGRESSIVE.traced(tracing);
        let Ok(()) = render(&compiled, &settings, plan, &target, &Uncancellable, |p| {
            ends.push((p.scale, start.elapsed().as_secs_f64() * 1e3));
        });
        let full = ends
            .last()
            .map_or_else(|| start.elapsed().as_secs_f64() * 1e3, |e| e.1);
        // The first pass's time counts from the compile, as the coarse image's does.
        let passes = ends
            .iter()
            .scan(0.0, |before, &(s, end)| {
                Some((s, end - std::mem::replace(before, end)))
            })
            .collect();
        (ends.first().map_or(full, |e| e.1), full, passes)
    };
    once(); // warm-up
    let runs: Vec<Run> = (0..b.repeat.max(1)).map(|_| once()).collect();
    let coarse = median(runs.iter().map(|r| r.0).collect());
    let full = median(runs.iter().map(|r| r.1).collect());
    // Each pass by its scale: a quick coarse pass leaves out the finer ones before the full
    // pass, maybe in some runs only.
    let mut scales: Vec<u32> = runs.iter().flat_map(|r| r.2.iter().map(|p| p.0)).collect();
    scales.sort_unstable_by(|a, b| b.cmp(a));
    scales.dedup();
    let passes: Vec<String> = scales
        .iter()
        .map(|&s| {
            let times: Vec<f64> = runs
                .iter()
                .flat_map(|r| r.2.iter().filter(|p| p.0 == s).map(|p| p.1))
                .collect();
            let some = if times.len() < runs.len() {
                format!(" (in {} of {} runs)", times.len(), runs.len())
            } else {
                String::new()
            };
            format!("{s}× {:.2}{some}", median(times))
        })
        .collect();
    out!(
        "frame: {w}x{h}, {} threads, {} kernels, medians of {}, {}, primary rays {}{}",
        rayon::current_num_threads(),
        tracelab_core::simd::level().name(),
        runs.len(),
        if b.one_pass {
            "one full-resolution pass"
        } else {
            "coarse passes, then the full one"
        },
        if b.single_rays {
            "one at a time"
        } else {
            "in packets of 8"
        },
        secondary_text(&settings)
    );
    out!(
        "passes: {} ms each (scale, median; the first from the compile on)",
        passes.join(" + ")
    );
    // Three decimals: a small scene's first coarse pass (a few rays, no frame written) takes
    // microseconds.
    out!("PROGRESSIVE coarse_ms={coarse:.3} full_ms={full:.2}");
    if let Some(steps) = b.orbit {
        run_orbit(&scene, &settings, steps.max(1))?;
    }
    Ok(())
}

/// The assignment 3–4 settings, when any is on.
fn secondary_text(s: &RenderSettings) -> String {
    let x = &s.secondary;
    if !x.shadows && x.bounces == 0 && !s.shade_back {
        return String::new();
    }
    format!(
        "; shadows {}, bounces {}, weight {}, shade back {}, shadow rays by {}",
        if x.shadows { "on" } else { "off" },
        x.bounces,
        x.weight,
        if s.shade_back { "on" } else { "off" },
        match x.shadow_query {
            tracelab_core::render::ShadowQuery::AnyHit => "the any-hit query",
            tracelab_core::render::ShadowQuery::ClosestHit => "the closest hit",
        }
    )
}

/// A turn of the camera about the scene's centre in `steps` steps, each as the editor
/// renders a mouse move: the scene copied with the new camera, compiled, then the coarse
/// passes (what is shown while the mouse moves) and, separately, the full progressive render
/// (what the view refines to when it stops). Medians over the steps.
fn run_orbit(scene: &Scene, settings: &RenderSettings, steps: usize) -> anyhow::Result<()> {
    let root = scene.graph.root();
    let pivot = world_bounds(scene, root).map_or(Vec3::ZERO, |(a, b)| (a + b) * 0.5);
    let target = SharedFrame::try_sized(settings.width, settings.height)?;
    let step_scene = |k: usize| {
        let mut s = scene.clone();
        s.camera = orbit(&scene.camera, pivot, 360.0 * k as f32 / steps as f32, 0.0);
        s
    };
    let mut first = Vec::new();
    let mut coarse_done = Vec::new();
    let mut full = Vec::new();
    for k in 1..=steps {
        let start = Instant::now();
        let compiled = CompiledScene::new(&step_scene(k));
        let mut t_first = None;
        let mut t_last = Duration::ZERO;
        let Ok(()) = render(
            &compiled,
            settings,
            RenderPlan::COARSE,
            &target,
            &Uncancellable,
            |_| {
                t_first.get_or_insert(start.elapsed());
                t_last = start.elapsed();
            },
        );
        first.push(t_first.unwrap_or(t_last).as_secs_f64() * 1e3);
        coarse_done.push(t_last.as_secs_f64() * 1e3);
        let start = Instant::now();
        let compiled = CompiledScene::new(&step_scene(k));
        let mut t_full = Duration::ZERO;
        let plan = RenderPlan::PROGRESSIVE;
        let Ok(()) = render(&compiled, settings, plan, &target, &Uncancellable, |_| {
            t_full = start.elapsed()
        });
        full.push(t_full.as_secs_f64() * 1e3);
    }
    out!(
        "ORBIT steps={steps} first_ms={:.3} coarse_ms={:.3} full_ms={:.2} max_first_ms={:.3}",
        median(first.clone()),
        median(coarse_done),
        median(full),
        first.iter().copied().fold(0.0, f64::max)
    );
    Ok(())
}
