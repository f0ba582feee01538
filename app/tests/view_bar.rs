//! Every control of the view bar, checked on the pixels the view actually drew (the
//! viewport's `shown()`: the textures as uploaded) against the command line's render of the
//! same settings. Deterministic: each check waits for the render worker to be idle.

mod common;
use common::settle;
use std::path::{Path, PathBuf};

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use tracelab::gui::panels::viewport::Shown;
use tracelab::gui::{AppOptions, TracelabApp};

/// Scaled in y only and turned, so the two normal rules differ visibly.
const SQUASHED: &str = "
OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 2.5 }
Lights { numLights 1 DirectionalLight { direction -0.3 -0.5 -1 color 1 1 1 } }
Background { color 0.2 0 0.6 ambientLight 0.1 0.1 0.1 }
Materials { numMaterials 1 Material { diffuseColor 1 0.8 0.3 } }
Group { numObjects 1 MaterialIndex 0
  Transform { ZRotate 30 Scale 1 0.35 1 Sphere { center 0 0 0 radius 1 } } }
";

/// A perspective camera inside a sphere: everything it sees is a back face. (An orthographic
/// camera's rays start at t = -infinity, as in the course, and would see the front.)
const INSIDE: &str = "
PerspectiveCamera { center 0 0 0 direction 0 0 -1 up 0 1 0 angle 60 }
Lights { numLights 1 DirectionalLight { direction 0.2 0.1 -1 color 1 1 1 } }
Background { color 0.2 0 0.6 ambientLight 0.1 0.1 0.1 }
Materials { numMaterials 1 Material { diffuseColor 1 0.5 0.2 } }
Group { numObjects 1 MaterialIndex 0 Sphere { center 0 0 0 radius 3 } }
";

fn scene_file(tag: &str, text: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("tracelab-viewbar-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&d).expect("temp dir");
    let p = d.join("scene.txt");
    std::fs::write(&p, text).expect("write scene");
    p
}

fn harness(scene: &Path, size: (u32, u32)) -> Harness<'static, TracelabApp> {
    common::app_harness(Some(scene.to_path_buf()), size)
}

fn click(h: &mut Harness<'static, TracelabApp>, label: &str) {
    h.get_by_label(label).click();
    h.step();
    settle(h);
}

/// What the command line writes for `view` (color, normals or depth) with `flags`, as RGB rows.
fn cli(scene: &Path, size: [usize; 2], view: &str, depth: (f32, f32), flags: &[&str]) -> Vec<u8> {
    let out = scene.with_file_name(format!("cli-{view}-{}.png", flags.join("_")));
    let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_tracelab"));
    cmd.arg("render")
        .arg(scene)
        .arg("--size")
        .arg(size[0].to_string())
        .arg(size[1].to_string());
    match view {
        "color" => cmd.arg("-o").arg(&out),
        "normals" => cmd.arg("--normals").arg(&out),
        _ => cmd
            .arg("--depth")
            .arg(depth.0.to_string())
            .arg(depth.1.to_string())
            .arg(&out),
    };
    let status = cmd.args(flags).status().expect("run tracelab render");
    assert!(status.success(), "tracelab render failed");
    let img = image::open(&out).expect("the render").to_rgb8();
    assert_eq!([img.width() as usize, img.height() as usize], size);
    img.into_raw()
}

fn shown(h: &Harness<'static, TracelabApp>) -> Vec<Shown> {
    h.state().shown()
}

fn single(h: &Harness<'static, TracelabApp>) -> Shown {
    let s = shown(h);
    assert_eq!(s.len(), 1, "one image in the single view");
    s.into_iter().next().expect("one")
}

#[test]
fn each_view_tab_shows_what_the_command_line_renders() {
    let scene = scene_file("tabs", SQUASHED);
    let mut h = harness(&scene, (40, 32));
    settle(&mut h);
    let depth = h.state().view().depth;
    let mut seen = Vec::new();
    for (tab, view) in [
        ("Normals", "normals"),
        ("Depth", "depth"),
        ("Colour", "color"),
    ] {
        click(&mut h, tab);
        let s = single(&h);
        assert_eq!(
            s.rgb8(),
            cli(&scene, s.size(), view, depth, &[]),
            "the {tab} tab"
        );
        seen.push(s.rgb8());
    }
    assert!(
        seen[0] != seen[1] && seen[1] != seen[2] && seen[0] != seen[2],
        "the tabs show the same picture"
    );
}

#[test]
fn all_three_shows_colour_normals_and_depth_as_the_command_line_renders_them() {
    let scene = scene_file("all", SQUASHED);
    let mut h = harness(&scene, (36, 36));
    settle(&mut h);
    click(&mut h, "All three");
    let depth = h.state().view().depth;
    let s = shown(&h);
    assert_eq!(s.len(), 3);
    for (s, view) in s.iter().zip(["color", "normals", "depth"]) {
        assert_eq!(
            s.rgb8(),
            cli(&scene, s.size(), view, depth, &[]),
            "the {view} cell"
        );
    }
    // Side by side, left to right, none over another.
    assert!(s[0].rect.max.x <= s[1].rect.min.x && s[1].rect.max.x <= s[2].rect.min.x);
}

#[test]
fn the_normal_switch_shows_each_rule_as_the_command_line_renders_it() {
    let scene = scene_file("switch", SQUASHED);
    let mut h = harness(&scene, (40, 40));
    settle(&mut h);
    let depth = h.state().view().depth;
    for (tab, view) in [("Normals", "normals"), ("Colour", "color")] {
        click(&mut h, tab);
        let correct = single(&h).rgb8();
        assert_eq!(
            correct,
            cli(
                &scene,
                [40, 40],
                view,
                depth,
                &["--normal-transform", "correct"]
            )
        );
        click(&mut h, "Incorrect M");
        let incorrect = single(&h).rgb8();
        assert_ne!(
            incorrect, correct,
            "Incorrect M changed nothing in the {tab} view"
        );
        assert_eq!(
            incorrect,
            cli(
                &scene,
                [40, 40],
                view,
                depth,
                &["--normal-transform", "incorrect"]
            )
        );
        click(&mut h, "Correct (M^-1)^T");
        assert_eq!(
            single(&h).rgb8(),
            correct,
            "Correct restores the {tab} picture"
        );
    }
}

#[test]
fn shade_back_shows_what_the_command_line_renders_with_shade_back() {
    let scene = scene_file("shade-back", INSIDE);
    let mut h = harness(&scene, (40, 40));
    settle(&mut h);
    let depth = h.state().view().depth;
    let off = single(&h).rgb8();
    assert_eq!(off, cli(&scene, [40, 40], "color", depth, &[]));
    click(&mut h, "shade back");
    assert!(h.state().view().shade_back);
    let on = single(&h).rgb8();
    assert_ne!(on, off, "shade back changed nothing on screen");
    assert_eq!(on, cli(&scene, [40, 40], "color", depth, &["--shade-back"]));
    click(&mut h, "shade back");
    assert_eq!(single(&h).rgb8(), off);
}

#[test]
fn the_depth_range_maps_depth_as_the_command_line_does() {
    let scene = scene_file("depth", SQUASHED);
    let mut h = harness(&scene, (40, 40));
    settle(&mut h);
    click(&mut h, "Depth");
    let before = single(&h).rgb8();
    h.get_by_label("depth min").set_value_accesskit(9.0);
    h.step();
    h.get_by_label("max").set_value_accesskit(10.5);
    h.step();
    settle(&mut h);
    assert_eq!(h.state().view().depth, (9.0, 10.5));
    let after = single(&h).rgb8();
    assert_ne!(
        after, before,
        "the new depth range changed nothing on screen"
    );
    assert_eq!(after, cli(&scene, [40, 40], "depth", (9.0, 10.5), &[]));
}

#[test]
fn fixed_size_renders_the_size_asked_for_and_off_follows_the_view() {
    let scene = scene_file("fixed", SQUASHED);
    let mut h = harness(&scene, (40, 40));
    settle(&mut h);
    let depth = h.state().view().depth;
    h.get_by_label("w").set_value_accesskit(30.0);
    h.step();
    settle(&mut h);
    let s = single(&h);
    assert_eq!(s.size(), [30, 40]);
    assert_eq!(s.rgb8(), cli(&scene, [30, 40], "color", depth, &[]));
    click(&mut h, "fixed size");
    assert_eq!(h.state().view().fixed_size, None);
    let s = single(&h);
    let [w, hh] = s.size();
    assert!(w > 200 && hh > 200, "the render follows the view: {w}×{hh}");
    // Drawn 1:1 (or smaller) in the view, never cropped.
    assert!(s.rect.width() <= w as f32 + 0.5 && s.rect.height() <= hh as f32 + 0.5);
    assert_eq!(s.rgb8(), cli(&scene, [w, hh], "color", depth, &[]));
    click(&mut h, "fixed size");
    assert_eq!(
        single(&h).size(),
        [200, 200],
        "the handout's size by default"
    );
}

fn choose_compare(h: &mut Harness<'static, TracelabApp>, mode: &str) {
    h.get_by_label("compare").click();
    h.step();
    h.step();
    h.get_by_label(mode).click();
    h.step();
    settle(h);
}

#[test]
fn side_by_side_shows_both_rules_as_the_command_line_renders_them() {
    let scene = scene_file("side", SQUASHED);
    let mut h = harness(&scene, (40, 40));
    settle(&mut h);
    click(&mut h, "Normals");
    choose_compare(&mut h, "side by side");
    let depth = h.state().view().depth;
    let s = shown(&h);
    assert_eq!(s.len(), 2);
    assert_eq!(
        s[0].rgb8(),
        cli(
            &scene,
            s[0].size(),
            "normals",
            depth,
            &["--normal-transform", "correct"]
        )
    );
    assert_eq!(
        s[1].rgb8(),
        cli(
            &scene,
            s[1].size(),
            "normals",
            depth,
            &["--normal-transform", "incorrect"]
        )
    );
    assert!(s[0].rect.max.x <= s[1].rect.min.x, "the cells overlap");
    choose_compare(&mut h, "off");
    assert_eq!(shown(&h).len(), 1);
}

#[test]
fn split_shows_the_correct_rule_left_of_the_line_and_the_incorrect_right() {
    let scene = scene_file("split", SQUASHED);
    let mut h = harness(&scene, (40, 40));
    settle(&mut h);
    click(&mut h, "Normals");
    choose_compare(&mut h, "split");
    let depth = h.state().view().depth;
    let s = shown(&h);
    assert_eq!(s.len(), 2, "two halves");
    assert_eq!(
        s[0].rgb8(),
        cli(
            &scene,
            s[0].size(),
            "normals",
            depth,
            &["--normal-transform", "correct"]
        )
    );
    assert_eq!(
        s[1].rgb8(),
        cli(
            &scene,
            s[1].size(),
            "normals",
            depth,
            &["--normal-transform", "incorrect"]
        )
    );
    assert_eq!(
        (s[0].uv.min.x, s[0].uv.max.x, s[1].uv.min.x, s[1].uv.max.x),
        (0.0, 0.5, 0.5, 1.0)
    );
    assert!(
        (s[0].rect.max.x - s[1].rect.min.x).abs() < 0.01,
        "the halves meet at the line"
    );
}

/// The view bar's controls, as found by label, and their rectangles on screen.
fn bar_controls(h: &Harness<'static, TracelabApp>) -> Vec<(&'static str, egui::Rect)> {
    [
        "Colour",
        "Normals",
        "Depth",
        "All three",
        "depth min",
        "max",
        "Correct (M^-1)^T",
        "Incorrect M",
        "compare",
        "depth t",
        "shade back",
        "gizmo & overlays",
        "world axes",
        "local axes",
        "fixed size",
    ]
    .into_iter()
    .map(|l| (l, h.get_by_label(l).rect()))
    .collect()
}

/// How many rows the controls sit on: centres within a few points of each other share one.
fn rows(controls: &[(&str, egui::Rect)]) -> usize {
    let mut ys: Vec<f32> = controls.iter().map(|(_, r)| r.center().y).collect();
    ys.sort_by(f32::total_cmp);
    1 + ys.windows(2).filter(|w| w[1] - w[0] > 6.0).count()
}

fn window(scene: &Path, width: f32) -> Harness<'static, TracelabApp> {
    let scene = scene.to_path_buf();
    let mut h = Harness::builder()
        .with_size(egui::vec2(width, 800.0))
        .with_max_steps(10_000)
        .build_eframe(move |cc| {
            TracelabApp::new(
                Some(cc),
                AppOptions {
                    scene: Some(scene),
                    fixed_size: Some((24, 24)),
                    ..AppOptions::default()
                },
            )
        });
    settle(&mut h);
    h
}

#[test]
fn the_view_bar_is_two_rows_at_1280_wide_with_labels_before_their_controls() {
    let scene = scene_file("bar-rows", SQUASHED);
    let h = window(&scene, 1280.0);
    let controls = bar_controls(&h);
    assert_eq!(rows(&controls), 2, "{controls:?}");
    let row_of = |l: &str| h.get_by_label(l).rect().center().y;
    // Each label before its control, on its row.
    for (label, control) in [
        ("Compare:", "compare"),
        ("Depth t:", "depth t"),
        ("Normal transform:", "Correct (M^-1)^T"),
        ("View:", "Colour"),
        ("depth range", "depth min"),
    ] {
        let (l, c) = (h.get_by_label(label).rect(), h.get_by_label(control).rect());
        assert!(
            l.right() <= c.left() && (l.center().y - c.center().y).abs() < 6.0,
            "{label} {l:?} is not before {control} {c:?}"
        );
    }
    // The largest angle beside the normal rule, the depth range beside the tabs.
    let gap = h.get_by_label_contains("° apart").rect().center().y;
    assert!((gap - row_of("Normal transform:")).abs() < 6.0);
    assert!((row_of("depth min") - row_of("Depth")).abs() < 6.0);
    // Two rows down to the smallest window (960 wide).
    assert_eq!(rows(&bar_controls(&window(&scene, 960.0))), 2);
    // Control: narrower than any window may be, the same count sees the bar wrap.
    let narrow = window(&scene, 560.0);
    assert!(
        rows(&bar_controls(&narrow)) > 2,
        "the row count counts rows"
    );
}

/// A sphere so big that it fills the bottom third of the image, edge to edge.
const FLOOR: &str = "
OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 4 }
Lights { numLights 1 DirectionalLight { direction -0.3 -0.5 -1 color 1 1 1 } }
Background { color 0.2 0 0.6 ambientLight 0.1 0.1 0.1 }
Materials { numMaterials 1 Material { diffuseColor 1 0.8 0.3 } }
Group { numObjects 1 MaterialIndex 0 Sphere { center 0 -10 0 radius 9.4 } }
";

/// The badges (axes triad, light directions) drawn over a pixel that shows the object.
fn badges_over_the_object(h: &Harness<'static, TracelabApp>) -> Vec<egui::Rect> {
    let app = h.state();
    let shown = app.shown();
    app.overlay_badges()
        .into_iter()
        .filter(|b| {
            let s = shown
                .iter()
                .find(|s| s.rect.contains(b.center()))
                .expect("a badge over an image");
            let [w, hh] = s.size();
            let px =
                |p: egui::Pos2| (p - s.rect.min) / s.rect.size() * egui::vec2(w as f32, hh as f32);
            let (a, z) = (px(b.min), px(b.max));
            app.worker().with_published(|p| {
                let f = p.expect("published").frames[0].lock();
                (a.y.max(0.0) as u32..(z.y.ceil() as u32).min(hh as u32)).any(|row| {
                    (a.x.max(0.0) as u32..(z.x.ceil() as u32).min(w as u32))
                        .any(|x| f.get(x, row).is_some_and(|s| s.t.is_finite()))
                })
            })
        })
        .collect()
}

#[test]
fn the_triad_and_light_badges_keep_off_the_object_and_leave_small_views() {
    let scene = scene_file("badges", FLOOR);
    let mut h = harness(&scene, (48, 48));
    settle(&mut h);
    for tab in ["Colour", "All three"] {
        click(&mut h, tab);
        let badges = h.state().overlay_badges();
        // Control: drawn (a triad and a light per image), so "none over the object" says something.
        let images = h.state().shown().len();
        assert_eq!(badges.len(), 2 * images, "{tab}: {badges:?}");
        assert_eq!(badges_over_the_object(&h), [], "{tab}");
    }
    // "All three" in the smallest window: images under 120 points, no badges at all.
    h.set_size(egui::vec2(960.0, 600.0));
    for _ in 0..3 {
        h.step();
    }
    settle(&mut h);
    let small = h.state().shown();
    assert!(
        small
            .iter()
            .all(|s| s.rect.width().min(s.rect.height()) < 120.0),
        "{small:?}"
    );
    assert_eq!(h.state().overlay_badges(), []);
}
