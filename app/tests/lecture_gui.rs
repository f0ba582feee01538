//! The editor's teaching views (issue 14) driven as a user would, with egui_kittest: the
//! Lecture menu, the depth-t switch, the Ray panel and the animation export. No GPU needed.

mod common;
use common::settle;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use tracelab::document::Selection;
use tracelab::gui::TracelabApp;
use tracelab::gui::command::AppCommand;
use tracelab_core::{NodeKind, ObjectRays};

fn harness(size: (u32, u32)) -> Harness<'static, TracelabApp> {
    common::app_harness(None, size)
}

fn depth_t_index() -> usize {
    tracelab::gui::lecture::FIGURES
        .iter()
        .position(|f| f.file == "depth_t.txt")
        .expect("in the menu")
}

#[test]
fn the_lecture_menu_opens_the_depth_t_figure_with_the_bug_on_and_its_caption() {
    let mut h = harness((48, 48));
    settle(&mut h);
    h.get_by_label("Lecture").click();
    for _ in 0..3 {
        h.step();
    }
    h.get_by_label("What to do about the depth t").click();
    settle(&mut h);
    let app = h.state();
    assert!(
        app.doc()
            .path
            .as_ref()
            .is_some_and(|p| p.ends_with("depth_t.txt")),
        "{:?}",
        app.doc().path
    );
    assert_eq!(app.view().object_rays, ObjectRays::NormalizedNoRescale);
    assert_eq!(app.lecture(), Some(depth_t_index()));
    let _ = h.get_by_label_contains("the big blue sphere jumps in front");
    // The render on screen uses the rule: the centre pixel, the small red sphere in truth,
    // shows the big blue one.
    let centre = h.state().worker().with_published(|p| {
        let p = p.expect("published");
        assert_eq!(p.job.settings.object_rays, ObjectRays::NormalizedNoRescale);
        let f = p.frames[0].lock();
        f.get(28, 23).expect("pixel").color
    });
    assert!(
        centre[2] > centre[0],
        "blue in front under the bug: {centre:?}"
    );
    // The toolbar's switch back to the lecture's rule: red in front again.
    h.state_mut().view_mut().object_rays = ObjectRays::Unnormalized;
    settle(&mut h);
    let centre = h.state().worker().with_published(|p| {
        p.expect("published").frames[0]
            .lock()
            .get(28, 23)
            .expect("pixel")
            .color
    });
    assert!(centre[0] > centre[2], "red in front: {centre:?}");
    // Opening another file drops the caption.
    h.state_mut().queue(AppCommand::New);
    h.step();
    assert_eq!(h.state().lecture(), None);
}

#[test]
fn the_ray_panel_draws_both_spaces_for_the_picked_pixel_and_can_be_hidden() {
    let mut h = harness((48, 48));
    settle(&mut h);
    h.state_mut()
        .queue(AppCommand::OpenLecture(depth_t_index()));
    settle(&mut h);
    h.state_mut().view_mut().object_rays = ObjectRays::Unnormalized;
    settle(&mut h);
    h.state_mut().inspect(0, 28, 23);
    for _ in 0..3 {
        h.step();
    }
    let _ = h.get_by_label("World space");
    let _ = h.get_by_label("Object space (of the primitive hit)");
    let _ = h.get_by_label_contains("t: world");
    h.state_mut().queue(AppCommand::ShowRayPanel(false));
    for _ in 0..2 {
        h.step();
    }
    assert!(h.query_by_label("World space").is_none());
}

#[test]
fn an_animation_exported_from_the_editor_writes_every_frame() {
    let mut h = harness((24, 24));
    settle(&mut h);
    h.state_mut()
        .queue(AppCommand::OpenLecture(depth_t_index()));
    settle(&mut h);
    let (id, _) = h
        .state()
        .doc()
        .scene
        .graph
        .iter()
        .find(|(_, n)| matches!(n.kind, NodeKind::Transform(_)))
        .expect("a Transform");
    h.state_mut().doc_mut().select(Some(Selection::Node(id)));
    h.state_mut().queue(AppCommand::AnimationDialog);
    h.step();
    assert!(
        h.state().animation().is_some(),
        "{:?}",
        h.state().doc().messages
    );
    let dir = std::env::temp_dir().join(format!("tracelab-lecture-gui-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let mut form = h.state().animation().cloned().expect("form");
    form.frames = 3;
    form.from = 0.0;
    form.to = 1.0;
    form.folder = dir.to_string_lossy().into_owned();
    h.state_mut().queue(AppCommand::StartAnimation(form));
    let start = Instant::now();
    loop {
        h.step();
        if !h.state().animation_running()
            && h.state()
                .doc()
                .messages
                .iter()
                .any(|m| m.text.contains("animation") || m.text.contains("exported"))
        {
            break;
        }
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "export did not finish"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    let msg = h
        .state()
        .doc()
        .messages
        .iter()
        .last()
        .map(|n| n.text.clone())
        .unwrap_or_default();
    assert!(msg.starts_with("exported 3 frames"), "{msg}");
    for f in [
        "frame_0000.png",
        "frame_0001.png",
        "frame_0002.png",
        "frame.apng.png",
    ] {
        assert!(PathBuf::from(&dir).join(f).is_file(), "{f}");
    }
    // Without a Transform selected the dialog offers the bounce sweep only.
    h.state_mut().doc_mut().select(None);
    h.state_mut().set_animation(None);
    h.state_mut().queue(AppCommand::AnimationDialog);
    h.step();
    let form = h.state().animation().cloned().expect("the dialog");
    assert_eq!(form.node, None);
    assert!(form.bounce_sweep);
}

/// File › Export animation's bounce sweep: opened on a bounce figure, it writes a frame per
/// bounce count with the view's rays, each the render the view shows at that count.
#[test]
fn a_bounce_sweep_exported_from_the_editor_writes_a_frame_per_count() {
    use tracelab::gui::lecture::FIGURES;
    use tracelab_core::RenderSettings;
    let mut h = harness((24, 24));
    settle(&mut h);
    let i = FIGURES
        .iter()
        .position(|f| f.file == "bounces_mirrors.txt")
        .expect("in the menu");
    h.state_mut().queue(AppCommand::OpenLecture(i));
    settle(&mut h);
    h.state_mut().doc_mut().select(None);
    h.state_mut().queue(AppCommand::AnimationDialog);
    h.step();
    let mut form = h.state().animation().cloned().expect("the dialog");
    assert!(form.bounce_sweep);
    assert_eq!(
        (form.bounces.from, form.bounces.to),
        (0, 3),
        "the view's count"
    );
    let _ = h.get_by_label_contains("bounces from");
    let dir = std::env::temp_dir().join(format!("tracelab-lecture-bounces-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    form.bounces.to = 2;
    form.folder = dir.to_string_lossy().into_owned();
    h.state_mut().queue(AppCommand::StartAnimation(form));
    let start = Instant::now();
    loop {
        h.step();
        if !h.state().animation_running()
            && h.state()
                .doc()
                .messages
                .iter()
                .any(|m| m.text.contains("exported"))
        {
            break;
        }
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "export did not finish"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    let scene = h.state().doc().scene.clone();
    let view = h.state().view().secondary;
    for k in 0..3u32 {
        let frame = image::open(dir.join(format!("frame_{k:04}.png")))
            .expect("frame")
            .to_rgb8();
        let mut settings = RenderSettings {
            shade_back: true,
            secondary: view,
            ..RenderSettings::new(24, 24)
        };
        settings.secondary.bounces = k;
        let single = tracelab_core::render_frame(&tracelab_core::compile(&scene), &settings)
            .rgb8(tracelab_core::View::Color, (0.0, 1.0));
        assert_eq!(frame.as_raw(), &single, "frame {k}");
    }
    assert!(dir.join("frame.apng.png").is_file());
    assert!(!dir.join("frame_0003.png").exists());
}

/// The bounce figures (issue 30): each opens with its scene's rays (shadows, its last bounce
/// count, weight 0.01) and shade-back, the render on screen uses them, and a plain figure
/// opened after it puts the course's defaults back.
#[test]
fn a_bounce_figure_opens_with_its_rays_and_a_plain_figure_puts_them_back() {
    use tracelab::gui::lecture::FIGURES;
    use tracelab_core::render::Secondary;
    let mut h = harness((24, 24));
    settle(&mut h);
    for file in [
        "bounces_mirrors.txt",
        "bounces_glass_bars.txt",
        "bounces_gem.txt",
    ] {
        let i = FIGURES
            .iter()
            .position(|f| f.file == file)
            .expect("in the menu");
        h.state_mut().queue(AppCommand::OpenLecture(i));
        settle(&mut h);
        let view = &h.state().view();
        assert_eq!(h.state().lecture(), Some(i), "{file}");
        assert!(view.shade_back, "{file}");
        assert!(view.secondary.shadows, "{file}");
        assert_eq!(view.secondary.weight, 0.01, "{file}");
        let last = if file == "bounces_mirrors.txt" { 3 } else { 5 };
        assert_eq!(view.secondary.bounces, last, "{file}");
        let _ = h.get_by_label_contains(&format!("View › Rays: step the bounces from 0 to {last}"));
        let job = h
            .state()
            .worker()
            .with_published(|p| p.map(|p| (p.job.settings.secondary, p.job.settings.shade_back)));
        assert_eq!(job, Some((h.state().view().secondary, true)), "{file}");
    }
    h.state_mut()
        .queue(AppCommand::OpenLecture(depth_t_index()));
    settle(&mut h);
    assert_eq!(h.state().view().secondary, Secondary::NONE);
    assert!(!h.state().view().shade_back);
}

/// Pixels of `s`'s shown part that are the sheared sphere's red and the box's green.
fn red_and_green(s: &tracelab::gui::panels::viewport::Shown) -> (usize, usize) {
    let [w, h] = s.size();
    let (x0, x1) = (
        (s.uv.min.x * w as f32) as usize,
        (s.uv.max.x * w as f32) as usize,
    );
    let (y0, y1) = (
        (s.uv.min.y * h as f32) as usize,
        (s.uv.max.y * h as f32) as usize,
    );
    let rgb = s.rgb8();
    let (mut red, mut green) = (0, 0);
    for y in y0..y1 {
        for x in x0..x1 {
            let i = (y * w + x) * 3;
            let (r, g) = (rgb[i] as i32, rgb[i + 1] as i32);
            red += usize::from(r > g + 20 && r > 40);
            green += usize::from(g > r + 20 && g > 40);
        }
    }
    (red, green)
}

/// "Incorrect vs correct normal transformation" opens split so that each of its two objects
/// (placed side by side) is seen under both rules: each half of the split shows some of both.
#[test]
fn the_normal_transform_figure_shows_each_object_under_both_rules() {
    let i = tracelab::gui::lecture::FIGURES
        .iter()
        .position(|f| f.file == "normal_transform.txt")
        .expect("in the menu");
    let mut h = harness((64, 48));
    settle(&mut h);
    h.state_mut().queue(AppCommand::OpenLecture(i));
    settle(&mut h);
    let shown = h.state().shown();
    assert_eq!(shown.len(), 2, "the two rules' parts");
    let (correct, incorrect) = (red_and_green(&shown[0]), red_and_green(&shown[1]));
    // The colours are told apart at all (control: the whole picture has both objects).
    assert!(correct.0 + incorrect.0 > 50 && correct.1 + incorrect.1 > 50);
    for (rule, (red, green)) in [("correct", correct), ("incorrect", incorrect)] {
        assert!(
            red > 20 && green > 20,
            "the {rule} part shows {red} red (sphere) and {green} green (box) pixels"
        );
    }
    // A click below the line inspects the incorrect rule's image; above it, the correct one.
    for (part, frame) in [(&shown[1], 1), (&shown[0], 0)] {
        let c = part.rect.center();
        h.hover_at(c);
        h.step();
        h.event(egui::Event::PointerButton {
            pos: c,
            button: egui::PointerButton::Primary,
            pressed: true,
            modifiers: egui::Modifiers::NONE,
        });
        h.event(egui::Event::PointerButton {
            pos: c,
            button: egui::PointerButton::Primary,
            pressed: false,
            modifiers: egui::Modifiers::NONE,
        });
        for _ in 0..3 {
            h.step();
        }
        let at = h.state().inspected().cloned().expect("a pixel inspected");
        assert_eq!(at.frame, frame, "clicked at {c:?}");
    }
}

/// Every label the Ray panel's diagrams draw, found on screen, with where it is.
fn diagram_labels(h: &Harness<'static, TracelabApp>) -> Vec<(String, egui::Rect)> {
    let mut out = Vec::new();
    for text in ["hit", "(M^-1)^T n", "M n", "n", "M^-1 o"] {
        for n in h.query_all_by_label(text) {
            out.push((text.to_string(), n.rect()));
        }
    }
    for text in ["t = ", "M^-1 d, length", "ray origin", "L0"] {
        for n in h.query_all_by_label_contains(text) {
            out.push((text.to_string(), n.rect()));
        }
    }
    out
}

fn assert_apart(labels: &[(String, egui::Rect)]) {
    for (i, (a, ra)) in labels.iter().enumerate() {
        for (b, rb) in &labels[i + 1..] {
            assert!(
                !ra.shrink(0.5).intersects(rb.shrink(0.5)),
                "{a:?} {ra:?} overlaps {b:?} {rb:?}"
            );
        }
    }
}

/// The Ray panel's labels never overlap (the ray's "t =", the "hit" and, in object space,
/// M^-1 d all end at the hit point), and its diagrams can be made big: in a window of
/// their own, resizable, instead of ~160 points wide in the dock.
#[test]
fn the_ray_diagrams_can_be_big_and_their_labels_never_overlap() {
    let mut h = harness((48, 48));
    settle(&mut h);
    h.state_mut()
        .queue(AppCommand::OpenLecture(depth_t_index()));
    settle(&mut h);
    h.state_mut().view_mut().object_rays = ObjectRays::Unnormalized;
    settle(&mut h);
    h.state_mut().inspect(0, 28, 23);
    for _ in 0..3 {
        h.step();
    }
    let docked = h.get_by_label("World space diagram").rect();
    let labels = diagram_labels(&h);
    // Control: the labels are there to be compared (both diagrams' hits, t, normals).
    assert!(labels.len() >= 8, "{labels:?}");
    assert_apart(&labels);
    h.get_by_label("Diagrams in a window").click();
    for _ in 0..4 {
        h.step();
    }
    let big = h.get_by_label("World space diagram").rect();
    assert!(
        big.width() >= 300.0 && big.height() >= 300.0,
        "{big:?} (docked {docked:?})"
    );
    let labels = diagram_labels(&h);
    assert!(labels.len() >= 8, "{labels:?}");
    assert_apart(&labels);
    // And back into the dock.
    h.get_by_label("Dock the diagrams").click();
    for _ in 0..3 {
        h.step();
    }
    assert!(!h.state().ray_window());
    let again = h.get_by_label("World space diagram").rect();
    assert!(again.width() < 250.0, "docked again: {again:?}");
}
