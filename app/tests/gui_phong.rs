//! The editor's side of assignments 3–4 (issue 30, item 4), with egui_kittest: a material's
//! Phong fields in the inspector (edits, undo, refusals), point lights in the tree and moved
//! with the gizmo's arrows, and the ray tree in the Ray panel's world diagram (its data).
//! Each check has a positive control, so a test that cannot see its effect fails.

mod common;
use common::settle;
use std::path::PathBuf;

use egui::{Event, Modifiers, PointerButton, Pos2, vec2};
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use glam::Vec3;
use tracelab::document::Selection;
use tracelab::gui::TracelabApp;
use tracelab::gui::gizmo::Handle;
use tracelab::gui::on_screen::OnScreen;
use tracelab::gui::ray_diagram::{Role, diagrams};
use tracelab::gui::view_tools::ViewTools;
use tracelab_core::render::{RayStory, Secondary, inspect_pixel};
use tracelab_core::scene::LightKind;
use tracelab_core::{CompiledScene, MeshCache, RenderSettings, Scene};

/// A private copy of `scenes/mirror_glass.txt`.
fn mirror_glass(tag: &str) -> PathBuf {
    let dir = common::temp_dir("phong", tag);
    let p = dir.join("mirror_glass.txt");
    std::fs::copy(common::repo().join("scenes/mirror_glass.txt"), &p).expect("copy");
    p
}

fn harness(scene: PathBuf) -> Harness<'static, TracelabApp> {
    common::settled_harness(Some(scene), (160, 160))
}

fn select(h: &mut Harness<'static, TracelabApp>, s: Selection) {
    h.state_mut().doc_mut().select(Some(s));
    for _ in 0..3 {
        h.step();
    }
}

/// Focus turns a drag value into a text field; typing replaces the selected old text.
fn type_into(h: &mut Harness<'static, TracelabApp>, label: &str, text: &str) {
    let role = egui::accesskit::Role::SpinButton;
    h.get_by_role_and_label(role, label).focus();
    h.step();
    h.step();
    h.get_by_role_and_label(role, label).type_text(text);
    h.step();
    h.key_press(egui::Key::Enter);
    h.step();
    h.step();
}

/// The number a drag value shows.
fn number_shown(node: &egui_kittest::Node<'_>) -> Option<f64> {
    node.value()?.parse().ok()
}

fn undo(h: &mut Harness<'static, TracelabApp>) {
    h.key_press_modifiers(Modifiers::COMMAND, egui::Key::Z);
    h.step();
    h.step();
}

fn material(h: &Harness<'static, TracelabApp>, i: usize) -> tracelab_core::Material {
    h.state().doc().scene.materials[i].clone()
}

#[test]
fn typing_a_materials_exponent_and_specular_colour_edits_it_one_undo_step_each() {
    let mut h = harness(mirror_glass("edit"));
    select(&mut h, Selection::Material(1));
    // What the file gives is shown: the red plastic's exponent 60.
    let shown = h.get_by_role_and_label(egui::accesskit::Role::SpinButton, "exponent");
    assert_eq!(number_shown(&shown), Some(60.0));
    let before = material(&h, 1);
    type_into(&mut h, "exponent", "20");
    assert_eq!(material(&h, 1).phong().exponent, 20.0);
    assert_eq!(material(&h, 1).field("exponent"), Some(&[20.0][..]));
    type_into(&mut h, "specularColor r", "0.25");
    let m = material(&h, 1);
    assert_eq!(m.phong().specular, Vec3::new(0.25, 0.8, 0.8));
    assert_eq!(
        m.diffuse, before.diffuse,
        "only the field typed into changes"
    );
    // The writer keeps the file's order: the edited fields stay where they were.
    let names: Vec<&str> = m.extra.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["specularColor", "exponent"]);
    undo(&mut h);
    assert_eq!(material(&h, 1).phong().specular, Vec3::splat(0.8));
    assert_eq!(
        material(&h, 1).phong().exponent,
        20.0,
        "one step: the colour only"
    );
    undo(&mut h);
    assert_eq!(material(&h, 1), before);
}

#[test]
fn an_absent_field_shows_the_course_default_and_typing_writes_it_unticking_removes_it() {
    let mut h = harness(mirror_glass("default"));
    // Material 3, matte green, gives no Phong field at all.
    select(&mut h, Selection::Material(3));
    assert!(material(&h, 3).extra.is_empty());
    let shown = h.get_by_role_and_label(egui::accesskit::Role::SpinButton, "indexOfRefraction");
    assert_eq!(number_shown(&shown), Some(1.0), "the course default");
    let _ = h.get_by_label("transparentColor");
    type_into(&mut h, "exponent", "8");
    assert_eq!(material(&h, 3).field("exponent"), Some(&[8.0][..]));
    // Unticking the field's box takes it out of the file again: the default.
    h.get_by_role_and_label(egui::accesskit::Role::CheckBox, "exponent")
        .click();
    h.step();
    h.step();
    assert_eq!(material(&h, 3).field("exponent"), None);
    undo(&mut h);
    assert_eq!(material(&h, 3).field("exponent"), Some(&[8.0][..]));
}

#[test]
fn a_negative_exponent_and_a_zero_index_are_refused_with_the_reason_beside_the_field() {
    let mut h = harness(mirror_glass("refused"));
    select(&mut h, Selection::Material(2));
    let before = material(&h, 2);
    // The positive control: a valid value is taken.
    type_into(&mut h, "exponent", "50");
    assert_eq!(material(&h, 2).phong().exponent, 50.0);
    type_into(&mut h, "exponent", "-1");
    assert_eq!(
        material(&h, 2).phong().exponent,
        50.0,
        "the last valid value"
    );
    let _ = h.get_by_label("exponent must not be negative, found -1");
    type_into(&mut h, "indexOfRefraction", "0");
    assert_eq!(material(&h, 2).phong().index_of_refraction, 1.5);
    let _ = h.get_by_label("indexOfRefraction must be positive, found 0");
    assert!(
        h.query_by_label("exponent must not be negative, found -1")
            .is_none(),
        "only the last refusal is shown"
    );
    undo(&mut h);
    assert_eq!(material(&h, 2), before, "refusals left no undo step");
}

/// The image on screen, as the view draws it, with the document's camera.
fn view(h: &Harness<'static, TracelabApp>) -> OnScreen {
    let shown = h.state().shown();
    let s = shown.first().expect("an image on screen");
    let camera = h.state().doc().scene.camera.clone();
    OnScreen::new(&camera, s.size()[0] as u32, s.size()[1] as u32, s.rect)
}

fn press(h: &mut Harness<'static, TracelabApp>, at: Pos2, pressed: bool) {
    h.event(Event::PointerButton {
        pos: at,
        button: PointerButton::Primary,
        pressed,
        modifiers: Modifiers::NONE,
    });
    h.step();
}

fn drag(h: &mut Harness<'static, TracelabApp>, from: Pos2, to: Pos2) {
    h.event(Event::PointerMoved(from));
    h.step();
    press(h, from, true);
    for k in 1..=6 {
        h.event(Event::PointerMoved(from + (to - from) * (k as f32 / 6.0)));
        h.step();
    }
    press(h, to, false);
    settle(h);
}

fn position(h: &Harness<'static, TracelabApp>, i: usize) -> Vec3 {
    match h.state().doc().scene.lights()[i].kind {
        LightKind::Point { position, .. } => position,
        LightKind::Directional { .. } => panic!("light {i} is directional"),
    }
}

/// mirror_glass.txt with a third light, a point light added in the inspector and moved in
/// front of the camera by typing; selected through its row in the tree.
fn added_point_light(tag: &str) -> Harness<'static, TracelabApp> {
    let mut h = harness(mirror_glass(tag));
    select(&mut h, Selection::Lights);
    h.get_by_label("Add point light").click();
    h.step();
    h.step();
    assert_eq!(h.state().doc().scene.lights().len(), 3);
    // Named apart from the directional "Light 0" in the tree.
    let _ = h.get_by_label("Light 0");
    let _ = h.get_by_label("Point light 1");
    h.get_by_label("Point light 2").click();
    h.step();
    h.step();
    assert_eq!(h.state().doc().selection, Some(Selection::Light(2)));
    for (axis, v) in [("x", "-1"), ("y", "1"), ("z", "2")] {
        type_into(&mut h, &format!("position {axis}"), v);
    }
    assert_eq!(position(&h, 2), Vec3::new(-1.0, 1.0, 2.0));
    settle(&mut h);
    h
}

#[test]
fn dragging_a_point_lights_x_arrow_moves_it_along_x_as_one_undo_step() {
    let mut h = added_point_light("drag");
    let v = view(&h);
    let g = ViewTools::light_gizmo(h.state().doc(), &v).expect("arrows at the selected light");
    let p0 = position(&h, 2);
    assert_eq!(g.origin, p0);
    let grab = v.project(g.handle_point(0)).expect("visible");
    assert_eq!(
        g.pick(&v, grab),
        Some(Handle::Move(0)),
        "the x arrow is there"
    );
    let along =
        (v.project(p0 + Vec3::X).expect("visible") - v.project(p0).expect("visible")).normalized();
    drag(&mut h, grab, grab + along * 50.0);
    let p1 = position(&h, 2);
    // The positive control: the drag landed on the arrow, so x moved, and only x.
    assert!(p1.x > p0.x + 0.1, "{p0} -> {p1}");
    assert_eq!((p1.y, p1.z), (p0.y, p0.z));
    // The grabbed point followed the pointer: the light's new place is 50 points along.
    let moved = v.project(p1).expect("visible") - v.project(p0).expect("visible");
    assert!((moved - along * 50.0).length() < 1.0, "{moved:?}");
    undo(&mut h);
    assert_eq!(position(&h, 2), p0, "the whole drag is one undo step");
    assert_eq!(h.state().doc().scene.lights().len(), 3);
}

#[test]
fn a_drag_beside_the_arrows_does_not_move_the_light() {
    let mut h = added_point_light("miss");
    let v = view(&h);
    let g = ViewTools::light_gizmo(h.state().doc(), &v).expect("arrows at the selected light");
    let p0 = position(&h, 2);
    let on = v.project(g.handle_point(0)).expect("visible");
    // 30 points below the x arrow: on the picture, off every handle.
    let off = on + vec2(0.0, 30.0);
    assert_eq!(g.pick(&v, off), None);
    drag(&mut h, off, off + vec2(50.0, 0.0));
    assert_eq!(position(&h, 2), p0);
    // The positive control: the same drag from the arrow does move it.
    drag(&mut h, on, on + vec2(50.0, 0.0));
    assert_ne!(position(&h, 2), p0);
}

fn mirror_glass_scene() -> Scene {
    let path = common::repo().join("scenes/mirror_glass.txt");
    tracelab_core::load_scene(&path, &mut MeshCache::new())
        .into_result()
        .expect("opens")
        .0
}

/// Every pixel's story on a 40×40 image with `bounces` levels and shadows.
fn stories(scene: &Scene, bounces: u32) -> Vec<RayStory> {
    let compiled = CompiledScene::new(scene);
    let mut s = RenderSettings::new(40, 40);
    s.shade_back = true;
    s.secondary = Secondary {
        shadows: true,
        bounces,
        weight: 0.01,
        ..Secondary::default()
    };
    (0..40)
        .flat_map(|y| (0..40).map(move |x| (x, y)))
        .map(|(x, y)| inspect_pixel(scene, &compiled, &s, x, y))
        .collect()
}

#[test]
fn the_world_diagram_draws_the_ray_trees_reflected_refracted_and_shadow_rays() {
    let scene = mirror_glass_scene();
    let count = |stories: &[RayStory], role: Role| {
        stories
            .iter()
            .filter_map(|st| diagrams(&scene, st))
            .map(|(world, _)| world.find(role).count())
            .sum::<usize>()
    };
    let deep = stories(&scene, 4);
    // The glass sphere: a pixel whose diagram has both kinds, the refracted ray starting
    // where the eye ray hit.
    let glass = deep
        .iter()
        .find(|st| {
            diagrams(&scene, st).is_some_and(|(w, _)| {
                w.find(Role::Reflected).next().is_some() && w.find(Role::Refracted).next().is_some()
            })
        })
        .expect("a pixel on the glass sphere");
    let (world, _) = diagrams(&scene, glass).expect("diagrams");
    let hit = glass.hit.as_ref().expect("a hit").world_point;
    let starts: Vec<Vec3> = world
        .find(Role::Refracted)
        .filter_map(|i| match &i.shape {
            tracelab::gui::ray_diagram::Shape::Line(ps) => ps.first().copied(),
            _ => None,
        })
        .collect();
    assert!(
        starts.iter().any(|s| (*s - hit).length() < 1e-3),
        "a refracted ray leaves the eye ray's hit {hit}: {starts:?}"
    );
    // Shadow rays, some blocked (the floor under the spheres).
    assert!(count(&deep, Role::Shadow) > 0);
    assert!(count(&deep, Role::ShadowBlocked) > 0);
    // The control: with no bounces and no shadows the same pixels draw none of them.
    let flat: Vec<RayStory> = {
        let compiled = CompiledScene::new(&scene);
        let mut s = RenderSettings::new(40, 40);
        s.shade_back = true;
        (0..40)
            .flat_map(|y| (0..40).map(move |x| (x, y)))
            .map(|(x, y)| inspect_pixel(&scene, &compiled, &s, x, y))
            .collect()
    };
    for role in [
        Role::Reflected,
        Role::Refracted,
        Role::Shadow,
        Role::ShadowBlocked,
    ] {
        assert!(count(&deep, role) > 0, "{role:?}");
        assert_eq!(count(&flat, role), 0, "{role:?} without the ray tree");
    }
    // Bounces 0 with shadows: shadow rays, but no secondary ray.
    let shadows_only = stories(&scene, 0);
    assert_eq!(count(&shadows_only, Role::Reflected), 0);
    assert!(count(&shadows_only, Role::Shadow) > 0);
}

/// A scene with mirrors or glass opened with no bounces says where the bounces are set; a
/// scene without them says nothing (the control), and neither does one opened with bounces.
#[test]
fn opening_a_scene_with_mirrors_or_glass_says_where_bounces_are_set() {
    let says = |h: &Harness<'static, TracelabApp>| {
        h.state().doc().messages.iter().any(|n| {
            n.text
                .contains("View › Rays (assignments 3–4) sets the bounces")
        })
    };
    let h = harness(mirror_glass("rays-notice"));
    assert!(says(&h), "no notice on opening mirror_glass.txt");
    let _ = h.get_by_label_contains("This scene has mirrors or glass");
    let plain = common::temp_dir("phong", "rays-plain").join("default.txt");
    std::fs::copy(common::repo().join("scenes/default.txt"), &plain).expect("copy");
    let h = harness(plain);
    assert!(!says(&h), "a notice for a scene without mirrors or glass");
}

/// View › Rays re-renders: the picture on screen is the render with the rays asked for. (Once
/// the worker's request key left the rays out, so shadows and bounces changed nothing on
/// screen until another setting did.) The control: the picture before equals a library render
/// without them, after equals one with them, and the two differ.
#[test]
fn setting_the_rays_renders_the_picture_with_them() {
    let path = mirror_glass("rays-rerender");
    let mut h = harness(path.clone());
    let size = (160, 160);
    let library = |secondary: Secondary| {
        let mut cache = MeshCache::new();
        let (scene, _) = tracelab_core::load_scene(&path, &mut cache)
            .into_result()
            .expect("loads");
        let c = CompiledScene::new(&scene);
        let s = RenderSettings {
            secondary,
            ..RenderSettings::new(size.0, size.1)
        };
        tracelab_core::render_frame(&c, &s).rgb8(tracelab_core::View::Color, (0.0, 1.0))
    };
    let shown = |h: &Harness<'static, TracelabApp>| h.state().shown()[0].rgb8();
    let before = shown(&h);
    assert_eq!(before, library(Secondary::default()));
    let rays = Secondary {
        shadows: true,
        bounces: 3,
        weight: 0.01,
        ..Secondary::default()
    };
    h.state_mut()
        .queue(tracelab::gui::command::AppCommand::SetRays(rays));
    settle(&mut h);
    let after = shown(&h);
    assert_ne!(after, before, "View › Rays changed nothing on screen");
    assert_eq!(after, library(rays));
}
