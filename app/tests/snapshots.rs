//! Snapshot tests of the main window, rendered with wgpu (lavapipe in CI). The reference
//! images under tests/snapshots/ were reviewed by eye (see the README there); refresh with
//! `UPDATE_SNAPSHOTS=1 cargo test -p tracelab --test snapshots` and review again.
//! Deterministic: a small fixed render size, and the snapshot waits for the render to finish.

use std::time::{Duration, Instant};

use egui_kittest::Harness;
use tracelab::gui::{AppOptions, TracelabApp};

/// Snapshots are only comparable on the pinned backend (lavapipe via Vulkan): other
/// backends differ in a few pixels. `.ci/run` pins it; these tests are `#[ignore]`d so a
/// plain `cargo test` lists them, and fail here when run without it.
fn require_pinned_backend() {
    assert!(
        std::env::var("WGPU_BACKEND").is_ok_and(|b| b == "vulkan"),
        "set WGPU_BACKEND=vulkan and VK_DRIVER_FILES to lavapipe (see .ci/run) to compare snapshots"
    );
}

fn settled_harness() -> Harness<'static, TracelabApp> {
    let mut h = Harness::builder()
        .with_size(egui::vec2(1280.0, 800.0))
        .with_max_steps(10_000)
        .wgpu()
        .build_eframe(|cc| {
            let mut app = TracelabApp::new(
                Some(cc),
                AppOptions {
                    scene: None,
                    fixed_size: Some((320, 240)),
                    ..AppOptions::default()
                },
            );
            app.set_show_timings(false);
            app
        });
    let start = Instant::now();
    while !h.state().worker().is_idle() {
        h.step();
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "render did not finish"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
    for _ in 0..3 {
        h.step();
    }
    h
}

#[test]
#[ignore = "needs lavapipe: WGPU_BACKEND=vulkan and VK_DRIVER_FILES as .ci/run sets them"]
fn main_window_on_the_default_scene() {
    require_pinned_backend();
    let mut h = settled_harness();
    h.snapshot("main_window");
}

#[test]
#[ignore = "needs lavapipe: WGPU_BACKEND=vulkan and VK_DRIVER_FILES as .ci/run sets them"]
fn pixel_inspector_open() {
    require_pinned_backend();
    let mut h = settled_harness();
    // A pixel on the squashed yellow sphere at the bottom of the stack.
    h.state_mut().inspect(0, 170, 150);
    for _ in 0..3 {
        h.step();
    }
    h.snapshot("pixel_inspector");
}
