//! View › Supersampling (assignment 7) in the editor: the picture on screen refines to the
//! sampler and filter asked for, the same image a library render with them gives.

mod common;
use common::settle;

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use tracelab::gui::TracelabApp;
use tracelab::gui::command::AppCommand;
use tracelab_core::render::{Filter, Sampler, SamplerKind, Supersampling};
use tracelab_core::{CompiledScene, MeshCache, RenderSettings};

const SIZE: (u32, u32) = (160, 160);

fn harness(scene: std::path::PathBuf) -> Harness<'static, TracelabApp> {
    common::settled_harness(Some(scene), SIZE)
}

#[test]
fn supersampling_renders_the_filtered_film_on_screen() {
    let dir = common::temp_dir("gui-supersample", "menu");
    let path = dir.join("scene.txt");
    std::fs::copy(common::repo().join("scenes/default.txt"), &path).expect("copy");
    let mut h = harness(path.clone());
    let shown = |h: &Harness<'static, TracelabApp>| h.state().shown()[0].rgb8();
    let before = shown(&h);
    let (w, hgt) = SIZE;
    let library = |ss: Option<Supersampling>| {
        let mut cache = MeshCache::new();
        let (scene, _) = tracelab_core::load_scene(&path, &mut cache)
            .into_result()
            .expect("loads");
        let c = CompiledScene::new(&scene);
        let s = RenderSettings {
            supersample: ss,
            ..RenderSettings::new(w, hgt)
        };
        let target = tracelab_core::SharedFrame::new();
        let Ok(()) = tracelab_core::render::render(
            &c,
            &s,
            tracelab_core::render::RenderPlan::PROGRESSIVE,
            &target,
            &tracelab_core::render::Uncancellable,
            |_| {},
        );
        target.take().rgb8(tracelab_core::View::Color, (0.0, 1.0))
    };
    assert_eq!(before, library(None));
    let ss = Supersampling {
        sampler: Sampler::new(SamplerKind::Jittered, 4, 6837).expect("a valid sampler"),
        filter: Filter::tent(1.5).expect("a valid filter"),
    };
    h.state_mut().queue(AppCommand::SetSupersampling(Some(ss)));
    settle(&mut h);
    let after = shown(&h);
    assert_ne!(
        after, before,
        "View › Supersampling changed nothing on screen"
    );
    assert_eq!(after, library(Some(ss)));
}

/// 36 samples a pixel on a 1400×1400 view pass the cap of samples in an image: the renderer
/// keeps the one-ray image, and the view says so (it was only in the log). Control: the same
/// choice on a small view is no warning.
#[test]
fn supersampling_past_its_caps_is_said_over_the_view() {
    let ss = Supersampling {
        sampler: Sampler::new(SamplerKind::Jittered, 36, 6837).expect("a valid sampler"),
        filter: Filter::default(),
    };
    let warned = |h: &Harness<'static, TracelabApp>| {
        h.query_by_label_contains("View › Supersampling at")
            .is_some()
    };
    let mut small = common::settled_harness(None, SIZE);
    small
        .state_mut()
        .queue(AppCommand::SetSupersampling(Some(ss)));
    settle(&mut small);
    assert!(!warned(&small), "a view within the caps is warned about");

    let mut big = common::settled_harness(None, (1400, 1400));
    assert!(!warned(&big), "warned before supersampling was asked for");
    big.state_mut()
        .queue(AppCommand::SetSupersampling(Some(ss)));
    settle(&mut big);
    assert!(
        warned(&big),
        "36 samples × 1400×1400 pixels pass the cap and nothing on screen says so"
    );
}
