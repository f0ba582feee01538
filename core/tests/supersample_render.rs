//! The progressive renderer refining toward a sampler and a filter (the editor's View ›
//! Supersampling): after the full-resolution pass, one more pass whose colours are the film's
//! filtered image, the other views left as the centre rays made them; none in a coarse-only
//! render; a cancel stops it.

use std::sync::atomic::AtomicBool;

use tracelab_core::render::{
    Film, Filter, PassInfo, RenderPlan, Sampler, SamplerKind, Supersampling, Uncancellable, render,
};
use tracelab_core::{MeshCache, RenderSettings, SharedFrame, compile, parse_scene, render_frame};

const SCENE: &str = "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 5.0 }
Lights { numLights 1 DirectionalLight { direction 0 -1 -1 color 0.5 0.5 0.5 } }
Materials { numMaterials 2 PhongMaterial { diffuseColor 1 0 0 } PhongMaterial { diffuseColor 0 1 0 } }
Background { color 0 0 1 ambientLight 0.5 0.5 0.5 }
Group { numObjects 2
  MaterialIndex 0 Sphere { center 1 1 0 radius 1 }
  MaterialIndex 1 Triangle { vertex0 -2.0 -2.0 0 vertex1 1.8 -1.8 0 vertex2 -1.95 1.95 0 }
}";

fn settings(w: u32, h: u32) -> (tracelab_core::CompiledScene, RenderSettings, Supersampling) {
    let s = parse_scene(SCENE.as_bytes(), "t.txt", None, &mut MeshCache::new())
        .into_result()
        .unwrap_or_else(|d| panic!("{d}"))
        .0;
    let ss = Supersampling {
        sampler: Sampler::new(SamplerKind::Jittered, 9, 5).expect("a valid sampler"),
        filter: Filter::tent(1.5).expect("a valid filter"),
    };
    let settings = RenderSettings {
        supersample: Some(ss),
        ..RenderSettings::new(w, h)
    };
    (compile(&s), settings, ss)
}

#[test]
fn the_last_pass_is_the_filtered_film_over_the_centre_rays_other_views() {
    let (scene, settings, ss) = settings(40, 30);
    let target = SharedFrame::new();
    let mut passes: Vec<PassInfo> = Vec::new();
    let Ok(()) = render(
        &scene,
        &settings,
        RenderPlan::PROGRESSIVE,
        &target,
        &Uncancellable,
        |p| passes.push(p),
    );
    let got = target.take();
    let plain = render_frame(
        &scene,
        &RenderSettings {
            supersample: None,
            ..settings
        },
    );
    let film = Film::render(&scene, &settings, ss.sampler)
        .expect("film")
        .frame(&ss.filter)
        .expect("filtered");
    let last = passes.last().expect("passes");
    assert_eq!(last.pass + 1, last.passes, "{passes:?}");
    // Fewer once a quick coarse pass skips the passes before the full one (how quick
    // depends on the machine), never more: the supersampled pass is counted from the start.
    assert!(
        passes.windows(2).all(|w| w[0].passes >= w[1].passes),
        "{passes:?}"
    );
    let mut changed = 0;
    for ((g, p), f) in got.samples.iter().zip(&plain.samples).zip(&film.samples) {
        assert_eq!(g.color, f.color);
        assert_eq!((g.normal, g.t, g.node), (p.normal, p.t, p.node));
        changed += usize::from(g.color != p.color);
    }
    assert!(changed > 20, "supersampling changed only {changed} pixels");
}

#[test]
fn a_coarse_render_does_not_supersample_and_a_cancel_stops_it() {
    let (scene, settings, _) = settings(32, 32);
    let target = SharedFrame::new();
    let mut passes = Vec::new();
    let Ok(()) = render(
        &scene,
        &settings,
        RenderPlan::COARSE,
        &target,
        &Uncancellable,
        |p: PassInfo| passes.push(p),
    );
    assert_eq!(passes.len(), 3, "16×, 8× and 4×: {passes:?}");
    assert!(passes.iter().all(|p| p.scale > 1));
    let cancel = AtomicBool::new(true);
    assert!(
        render(
            &scene,
            &settings,
            RenderPlan::FULL,
            &target,
            &cancel,
            |_| {}
        )
        .is_err()
    );
}
