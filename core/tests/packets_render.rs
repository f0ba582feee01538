//! The renderer's primary rays as packets (`Tracing::Packets`, what every render uses) give
//! the image single rays give, bit for bit: colour, normal, t and object id of every pixel,
//! in one full pass and through the progressive passes (whose coarse samples are sparse
//! packets), on tracelab's scenes, on the course's and perf scenes (`TRACELAB_COURSE_DIR`, `TRACELAB_PERF_DIR`) and on
//! scenes/perf's 1,000 bunny instances, under both normal rules and with and without
//! shade_back.

mod common;

use std::path::{Path, PathBuf};

use tracelab_core::render::{RenderPlan, Tracing, Uncancellable, render};
use tracelab_core::{
    CompiledScene, Frame, MeshCache, NormalTransform, RenderSettings, SharedFrame, load_scene,
};

fn same(a: &Frame, b: &Frame) -> Result<(), String> {
    if (a.width, a.height) != (b.width, b.height) {
        return Err("sizes differ".into());
    }
    for (i, (x, y)) in a.samples.iter().zip(&b.samples).enumerate() {
        if x.color != y.color
            || x.normal != y.normal
            || x.t.to_bits() != y.t.to_bits()
            || x.node != y.node
        {
            return Err(format!(
                "pixel {} of row {} differs: {x:?} vs {y:?}",
                i as u32 % a.width,
                i as u32 / a.width
            ));
        }
    }
    Ok(())
}

fn check(path: &Path, (w, h): (u32, u32)) {
    let scene = load_scene(path, &mut MeshCache::new())
        .into_result()
        .unwrap_or_else(|d| panic!("{}: {d}", path.display()))
        .0;
    let c = CompiledScene::new(&scene);
    for normal_transform in [NormalTransform::Correct, NormalTransform::Incorrect] {
        for shade_back in [false, true] {
            let s = RenderSettings {
                shade_back,
                normal_transform,
                ..RenderSettings::new(w, h)
            };
            let full = |tracing| {
                let target = SharedFrame::new();
                let plan = RenderPlan::FULL.traced(tracing);
                let Ok(()) = render(&c, &s, plan, &target, &Uncancellable, |_| {});
                target.take()
            };
            let single = full(Tracing::SingleRays);
            let packets = full(Tracing::Packets);
            same(&single, &packets)
                .unwrap_or_else(|e| panic!("{} {s:?}: one pass: {e}", path.display()));
            let target = SharedFrame::new();
            let plan = RenderPlan::PROGRESSIVE;
            let Ok(()) = render(&c, &s, plan, &target, &Uncancellable, |_| {});
            same(&single, &target.lock())
                .unwrap_or_else(|e| panic!("{} {s:?}: progressive: {e}", path.display()));
        }
    }
}

fn txt_files(dir: &Path, prefix: &str) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "txt"))
        .filter(|p| {
            p.file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with(prefix))
        })
        .collect();
    v.sort();
    v
}

/// `.ci/run` runs these tests again with `TRACELAB_SIMD=sse`: make sure that took.
#[test]
fn the_kernels_are_the_ones_tracelab_simd_asks_for() {
    use tracelab_core::simd::{Level, detected, level};
    let want = match std::env::var("TRACELAB_SIMD").as_deref() {
        Ok("sse") => Level::Sse,
        Ok("avx") => Level::Avx.min(detected()),
        Ok("avx512") => Level::Avx512.min(detected()),
        _ => detected(),
    };
    eprintln!(
        "kernels in use: {} (the CPU has {})",
        level().name(),
        detected().name()
    );
    assert_eq!(level(), want);
}

#[test]
fn packets_match_single_rays_on_tracelab_s_scenes() {
    let scenes = txt_files(&common::repo().join("scenes"), "");
    assert!(scenes.len() >= 5, "{scenes:?}");
    // Odd sizes: partial 4×2 neighbourhoods at the right and bottom edges and in coarse passes.
    for s in &scenes {
        check(s, (83, 61));
    }
}

#[test]
#[ignore = "needs the course files and the perf scenes with their meshes: TRACELAB_COURSE_DIR, TRACELAB_PERF_DIR, defaults ../shared/mit6837, ../shared/perf"]
fn packets_match_single_rays_on_the_course_and_perf_scenes() {
    let course = txt_files(&common::course_dir().join("scenes"), "scene");
    assert!(course.len() >= 20, "{course:?}");
    for s in &course {
        check(s, (101, 75));
    }
    // The perf scenes' meshes (bunny 69k, dragon 871k) at a size that keeps this quick.
    let perf = txt_files(&common::perf_dir(), "bench_");
    assert_eq!(perf.len(), 4, "{perf:?}");
    for s in &perf {
        check(s, (64, 48));
    }
    // 1,000 instances of the course's bunny_1k: the top-level BVH walked by packets.
    check(
        &common::repo().join("scenes/perf/bunny_instances_1000.txt"),
        (64, 48),
    );
}
