//! Shared by app's integration tests.
// Each test binary that includes this module uses only part of it.
#![allow(dead_code, unused_imports)]

use std::path::{Path, PathBuf};

// The one reader of the data settings (TRACELAB_COURSE_DIR, …), shared with core's tests.
#[path = "../../../core/tests/common/data.rs"]
mod data;
pub use data::{course_dir, meshes_dir, perf_dir, semester_dir};

// The unit tests' helpers, for the one both kinds of test need.
#[path = "../../src/test_support.rs"]
mod test_support;
#[cfg(unix)]
pub use test_support::mknod;

/// Runs the built `tracelab` with `args` in `dir`, its output captured.
pub fn tracelab(args: &[&str], dir: &Path) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_tracelab"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run tracelab")
}

/// Copies the files of `from` (not its subfolders) into `to`, made first.
pub fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).expect("create temp dir");
    for e in std::fs::read_dir(from).expect("read scenes") {
        let e = e.expect("entry");
        std::fs::copy(e.path(), to.join(e.file_name())).expect("copy");
    }
}

/// The repository's root (scenes/, assets/).
pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// An empty folder of the system's temporary folder, private to this test process:
/// `tracelab-{area}-{pid}-{name}`, emptied first.
pub fn temp_dir(area: &str, name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("tracelab-{area}-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

/// Steps the UI until the scene is read and the renderer has finished the newest request,
/// then once more so the last pixels are uploaded and drawn.
#[cfg(feature = "gui")]
pub fn settle(h: &mut egui_kittest::Harness<'static, tracelab::gui::TracelabApp>) {
    let start = std::time::Instant::now();
    loop {
        h.step();
        if h.state().worker().is_idle() && !h.state().is_loading() {
            h.step();
            return;
        }
        assert!(
            start.elapsed() < std::time::Duration::from_secs(60),
            "render did not finish"
        );
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
}

/// The editor in a 1200×760 window as the kittests drive it: `scene` opened (or the built-in
/// one), the render at the fixed `size`; not yet stepped.
#[cfg(feature = "gui")]
pub fn app_harness(
    scene: Option<PathBuf>,
    size: (u32, u32),
) -> egui_kittest::Harness<'static, tracelab::gui::TracelabApp> {
    egui_kittest::Harness::builder()
        .with_size(egui::vec2(1200.0, 760.0))
        .with_max_steps(10_000)
        .build_eframe(move |cc| {
            tracelab::gui::TracelabApp::new(
                Some(cc),
                tracelab::gui::AppOptions {
                    scene,
                    fixed_size: Some(size),
                    ..tracelab::gui::AppOptions::default()
                },
            )
        })
}

/// `app_harness`, stepped until the scene is read and rendered (`settle`).
#[cfg(feature = "gui")]
pub fn settled_harness(
    scene: Option<PathBuf>,
    size: (u32, u32),
) -> egui_kittest::Harness<'static, tracelab::gui::TracelabApp> {
    let mut h = app_harness(scene, size);
    settle(&mut h);
    h
}
