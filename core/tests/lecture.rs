//! The lecture's figures as scenes (scenes/lecture/): each parses without a warning, renders,
//! and matches its reviewed golden image in core/tests/golden/lecture/ (see the README
//! there for what was checked in each). Regenerate after a deliberate change with
//! `TRACELAB_UPDATE_GOLDEN=1 cargo test -p tracelab-core --test lecture`, then look at
//! every image again before committing it.

mod common;
use common::repo;
use std::path::{Path, PathBuf};

use tracelab_core::render::Secondary;
use tracelab_core::{
    Frame, MeshCache, NormalTransform, ObjectRays, RenderSettings, Scene, View, compile,
    load_scene, render_frame,
};

const SIZE: u32 = 128;

/// One golden image: which scene, which view and which render options.
struct Figure {
    golden: &'static str,
    scene: &'static str,
    view: View,
    normal_transform: NormalTransform,
    object_rays: ObjectRays,
    /// The rays of assignment 4 (shadows, bounces, weight) and shade-back, for the bounce
    /// figures; `None` is the lecture's plain render.
    rays: Option<Secondary>,
}

const fn fig(
    golden: &'static str,
    scene: &'static str,
    view: View,
    normal_transform: NormalTransform,
) -> Figure {
    Figure {
        golden,
        scene,
        view,
        normal_transform,
        object_rays: ObjectRays::Unnormalized,
        rays: None,
    }
}

/// A figure of the depth-t question, rendered with a chosen object-ray rule.
const fn fig_rays(golden: &'static str, scene: &'static str, object_rays: ObjectRays) -> Figure {
    Figure {
        golden,
        scene,
        view: Color,
        normal_transform: Correct,
        object_rays,
        rays: None,
    }
}

/// A bounce figure at its last bounce count: `-shadows -shade_back -bounces N -weight 0.01`,
/// as its comment header says.
const fn fig_bounces(scene: &'static str, bounces: u32) -> Figure {
    Figure {
        golden: scene,
        scene,
        view: Color,
        normal_transform: Correct,
        object_rays: ObjectRays::Unnormalized,
        rays: Some(rays(bounces)),
    }
}

/// The bounce figures and the bounce count each steps up to (`BOUNCE_FIGURES` in
/// app/src/gui/lecture.rs says the same).
const BOUNCE_FIGURES: &[(&str, u32)] = &[
    ("bounces_mirrors", 3),
    ("bounces_glass_bars", 5),
    ("bounces_gem", 5),
];

const fn rays(bounces: u32) -> Secondary {
    Secondary {
        shadows: true,
        bounces,
        weight: 0.01,
        ..Secondary::NONE
    }
}

use NormalTransform::{Correct, Incorrect};
use View::{Color, Normals};

const FIGURES: &[Figure] = &[
    fig("simple_scene", "simple_scene", Color, Correct),
    fig("class_hierarchy", "class_hierarchy", Color, Correct),
    fig(
        "class_hierarchy_transforms",
        "class_hierarchy_transforms",
        Color,
        Correct,
    ),
    fig("nested_transforms", "nested_transforms", Color, Correct),
    fig("flat_transforms", "flat_transforms", Color, Correct),
    fig("normals", "normals", Normals, Correct),
    fig(
        "normal_transform_correct",
        "normal_transform",
        Color,
        Correct,
    ),
    fig(
        "normal_transform_incorrect",
        "normal_transform",
        Color,
        Incorrect,
    ),
    fig("shading_light_only", "shading_light_only", Color, Correct),
    fig(
        "shading_half_ambient",
        "shading_half_ambient",
        Color,
        Correct,
    ),
    fig("perspective", "perspective", Color, Correct),
    fig("cube_mesh", "cube_mesh", Color, Correct),
    fig("csg_union", "csg_union", Color, Correct),
    fig("csg_intersection", "csg_intersection", Color, Correct),
    fig("csg_subtraction", "csg_subtraction", Color, Correct),
    fig("csg_die", "csg_die", Color, Correct),
    fig_rays("depth_t_unnormalized", "depth_t", ObjectRays::Unnormalized),
    fig_rays(
        "depth_t_no_rescale",
        "depth_t",
        ObjectRays::NormalizedNoRescale,
    ),
    fig_bounces("bounces_mirrors", 3),
    fig_bounces("bounces_glass_bars", 5),
    fig_bounces("bounces_gem", 5),
];

fn scene_path(name: &str) -> PathBuf {
    repo().join("scenes/lecture").join(format!("{name}.txt"))
}

fn load(name: &str) -> Scene {
    let path = scene_path(name);
    let (scene, warnings) = load_scene(&path, &mut MeshCache::new())
        .into_result()
        .unwrap_or_else(|d| panic!("{} does not parse:\n{d}", path.display()));
    assert!(
        warnings.is_empty(),
        "{} has warnings:\n{warnings}",
        path.display()
    );
    scene
}

fn render(scene: &Scene, normal_transform: NormalTransform) -> Frame {
    render_with(scene, normal_transform, ObjectRays::Unnormalized)
}

fn render_with(scene: &Scene, normal_transform: NormalTransform, object_rays: ObjectRays) -> Frame {
    let settings = RenderSettings {
        normal_transform,
        object_rays,
        ..RenderSettings::new(SIZE, SIZE)
    };
    render_frame(&compile(scene), &settings)
}

/// A render with the rays of assignment 4 and shade-back, as the bounce figures' lines ask.
fn render_rays(scene: &Scene, size: u32, secondary: Secondary) -> Frame {
    let settings = RenderSettings {
        shade_back: true,
        secondary,
        ..RenderSettings::new(size, size)
    };
    render_frame(&compile(scene), &settings)
}

#[test]
fn every_lecture_scene_has_a_figure() {
    let mut files: Vec<String> = std::fs::read_dir(repo().join("scenes/lecture"))
        .expect("scenes/lecture")
        .filter_map(|e| e.ok()?.path().file_stem()?.to_str().map(str::to_string))
        .filter(|n| scene_path(n).is_file())
        .collect();
    files.sort();
    for f in &files {
        assert!(
            FIGURES.iter().any(|g| g.scene == f),
            "scenes/lecture/{f}.txt has no golden image"
        );
    }
    assert!(files.len() >= 15, "{files:?}");
}

#[test]
fn lecture_scenes_match_their_reviewed_golden_images() {
    let update = std::env::var("TRACELAB_UPDATE_GOLDEN").is_ok_and(|v| v == "1");
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden/lecture");
    let mut failures = Vec::new();
    for f in FIGURES {
        let frame = match f.rays {
            Some(rays) => render_rays(&load(f.scene), SIZE, rays),
            None => render_with(&load(f.scene), f.normal_transform, f.object_rays),
        };
        assert!(
            frame.samples.iter().any(|s| s.is_hit()),
            "{}: nothing visible",
            f.golden
        );
        let rgb = frame.rgb8(f.view, (0.0, 1.0));
        let path = dir.join(format!("{}.png", f.golden));
        if update {
            std::fs::create_dir_all(&dir).expect("golden dir");
            image::RgbImage::from_raw(SIZE, SIZE, rgb)
                .expect("size")
                .save(&path)
                .expect("write golden");
            eprintln!("UPDATED {} (review it before committing)", path.display());
            continue;
        }
        let golden = match image::open(&path) {
            Ok(img) => img.to_rgb8(),
            Err(e) => {
                failures.push(format!(
                    "{}: cannot read golden {}: {e}",
                    f.golden,
                    path.display()
                ));
                continue;
            }
        };
        assert_eq!(golden.dimensions(), (SIZE, SIZE), "{}", path.display());
        // Tolerance: float results may differ in the last bit across platforms, which can
        // move a quantised channel by one step or flip a pixel on a silhouette.
        let mut off = 0usize;
        let mut worst = 0u8;
        for (a, b) in rgb.chunks_exact(3).zip(golden.as_raw().chunks_exact(3)) {
            let d = a
                .iter()
                .zip(b)
                .map(|(x, y)| x.abs_diff(*y))
                .max()
                .unwrap_or(0);
            worst = worst.max(d);
            if d > 2 {
                off += 1;
            }
        }
        let allowed = (SIZE * SIZE) as usize / 200;
        if off > allowed {
            failures.push(format!(
                "{}: {off} pixels differ by more than 2/255 (allowed {allowed}; largest {worst})",
                f.golden
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn nested_and_flat_lecture_transforms_give_identical_images() {
    let (a, b) = (
        render(&load("nested_transforms"), Correct),
        render(&load("flat_transforms"), Correct),
    );
    assert!(a.samples.iter().filter(|s| s.is_hit()).count() > 1000);
    assert!(
        a.samples
            .iter()
            .zip(&b.samples)
            .all(|(x, y)| x.color == y.color && x.normal == y.normal)
    );
}

#[test]
fn incorrect_normal_transform_changes_the_sheared_figure() {
    let s = load("normal_transform");
    let (a, b) = (render(&s, Correct), render(&s, Incorrect));
    let differing = a
        .samples
        .iter()
        .zip(&b.samples)
        .filter(|(x, y)| x.color != y.color)
        .count();
    assert!(differing > 1000, "only {differing} pixels differ");
}

#[test]
fn shading_figures_follow_the_lecture_formula() {
    // c_ambient = 0: a sphere's side away from the light is black.
    let dark = render(&load("shading_light_only"), Correct);
    // c_light = c_ambient = 0.5: nothing exceeds k_d, and the unlit side is k_d / 2.
    let half = render(&load("shading_half_ambient"), Correct);
    let s = load("shading_half_ambient");
    let kd_max = s
        .materials
        .iter()
        .map(|m| m.diffuse.max_element())
        .fold(0.0f32, f32::max);
    assert!(half.samples.iter().filter(|p| p.is_hit()).all(|p| {
        p.color
            .iter()
            .all(|&c| f32::from(c) <= kd_max * 255.0 + 1.0)
    }));
    // The lower left of the right-hand (blue) sphere faces away from the light.
    let (x, row) = (91, 74);
    let d = dark.get(x, row).expect("pixel");
    let h = half.get(x, row).expect("pixel");
    assert!(d.is_hit() && h.is_hit());
    assert_eq!(d.color, [0, 0, 0]);
    let kd = s.materials[2].diffuse * 0.5;
    assert_eq!(
        h.color,
        [kd.x, kd.y, kd.z].map(tracelab_core::render::quantize)
    );
}

#[test]
fn every_bounce_of_a_bounce_figure_changes_the_image() {
    for &(name, last) in BOUNCE_FIGURES {
        let scene = load(name);
        let images: Vec<Vec<u8>> = (0..=last)
            .map(|n| render_rays(&scene, 48, rays(n)).rgb8(Color, (0.0, 1.0)))
            .collect();
        for n in 1..=last as usize {
            let changed = images[n]
                .chunks_exact(3)
                .zip(images[n - 1].chunks_exact(3))
                .filter(|(a, b)| a != b)
                .count();
            assert!(
                changed > 0,
                "{name}: -bounces {n} gives the image of -bounces {}",
                n - 1
            );
        }
    }
}

#[test]
fn the_bounce_figures_say_their_command_line() {
    for &(name, last) in BOUNCE_FIGURES {
        let text = std::fs::read_to_string(scene_path(name)).expect("scene");
        let line = format!(
            "tracelab -input scenes/lecture/{name}.txt -size 300 300 -output a.png -shadows \
             -shade_back -bounces {last} -weight 0.01"
        );
        assert!(text.contains(&line), "{name}: the header lacks {line:?}");
    }
}
