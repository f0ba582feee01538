//! Moving through the scene in the render view, as a user does it with the mouse and keys:
//! orbit, zoom, framing, the axis views and the gizmo's handles, with egui_kittest. Every
//! check is on the document (the course's camera and Transform ops) or on the pixels shown.

mod common;
use common::settle;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use egui::{Event, Modifiers, PointerButton, Pos2, vec2};
use egui_kittest::Harness;
use glam::Vec3;
use tracelab::document::Selection;
use tracelab::gui::TracelabApp;
use tracelab::gui::command::AppCommand;
use tracelab::gui::gizmo::{Axes, Handle};
use tracelab::gui::on_screen::OnScreen;
use tracelab::gui::view_tools::ViewTools;
use tracelab::navigation::ViewBasis;
use tracelab_core::{Camera, MeshCache, NodeId, NodeKind, TransformOp};

const SIZE: (u32, u32) = (160, 160);

fn scene_file(tag: &str, objects: &str, camera: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("tracelab-nav-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&d).expect("temp dir");
    let p = d.join("scene.txt");
    let text = format!(
        "{camera}\nLights {{ numLights 1 DirectionalLight {{ direction -0.5 -0.5 -1 color 0.9 0.9 0.9 }} }}\n\
         Background {{ color 0 0 0 ambientLight 0.2 0.2 0.2 }}\n\
         Materials {{ numMaterials 1 Material {{ diffuseColor 1 0 0 }} }}\n\
         Group {{ numObjects 1 MaterialIndex 0 {objects} }}\n"
    );
    std::fs::write(&p, text).expect("scene written");
    p
}

const PERSPECTIVE: &str = "PerspectiveCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 angle 30 }";
const SPHERE: &str = "Sphere { center 0 0 0 radius 1 }";
/// A sphere of world radius 0.5 at world (0.5, 0, 0), under a `UniformScale 5` parent.
const SCALED: &str = "Transform { UniformScale 5 Transform { Translate 0.1 0 0 Sphere { center 0 0 0 radius 0.1 } } }";

fn harness(scene: PathBuf) -> Harness<'static, TracelabApp> {
    common::settled_harness(Some(scene), SIZE)
}

fn camera(h: &Harness<'static, TracelabApp>) -> Camera {
    h.state().doc().scene.camera.clone()
}

/// The image on screen, as the view draws it, with the document's camera.
fn view(h: &Harness<'static, TracelabApp>) -> OnScreen {
    let shown = h.state().shown();
    let s = shown.first().expect("an image on screen");
    OnScreen::new(&camera(h), s.size()[0] as u32, s.size()[1] as u32, s.rect)
}

fn press(h: &mut Harness<'static, TracelabApp>, button: PointerButton, at: Pos2, pressed: bool) {
    h.event(Event::PointerButton {
        pos: at,
        button,
        pressed,
        modifiers: Modifiers::NONE,
    });
    h.step();
}

/// Presses `button` at `from`, moves to `to` in `steps` steps; releases when `release`.
fn drag(
    h: &mut Harness<'static, TracelabApp>,
    button: PointerButton,
    from: Pos2,
    to: Pos2,
    steps: usize,
    release: bool,
) {
    h.event(Event::PointerMoved(from));
    h.step();
    press(h, button, from, true);
    for k in 1..=steps {
        h.event(Event::PointerMoved(
            from + (to - from) * (k as f32 / steps as f32),
        ));
        h.step();
    }
    if release {
        press(h, button, to, false);
    }
}

fn node_where(h: &Harness<'static, TracelabApp>, f: impl Fn(&NodeKind) -> bool) -> NodeId {
    let g = &h.state().doc().scene.graph;
    g.preorder()
        .into_iter()
        .find(|&id| f(&g.node(id).kind))
        .expect("such a node")
}

fn sphere(h: &Harness<'static, TracelabApp>) -> NodeId {
    node_where(h, |k| matches!(k, NodeKind::Sphere { .. }))
}

fn select(h: &mut Harness<'static, TracelabApp>, id: NodeId) {
    h.state_mut()
        .queue(AppCommand::Select(Some(Selection::Node(id))));
    settle(h);
}

fn angle_between(a: Vec3, b: Vec3) -> f32 {
    a.normalize()
        .dot(b.normalize())
        .clamp(-1.0, 1.0)
        .acos()
        .to_degrees()
}

#[test]
fn a_middle_drag_orbits_by_04_degrees_per_point_about_the_point_under_the_pointer() {
    let mut h = harness(scene_file("orbit", SPHERE, PERSPECTIVE));
    let before = camera(&h);
    let v = view(&h);
    let from = v.rect.center();
    // The sphere's front, under the pointer: the pivot.
    let pivot = Vec3::new(0.0, 0.0, 1.0);
    let pivot_on_screen = v.project(pivot).expect("visible");
    drag(
        &mut h,
        PointerButton::Middle,
        from,
        from + vec2(100.0, 0.0),
        10,
        true,
    );
    let after = camera(&h);
    let turned = angle_between(before.direction(), after.direction());
    assert!(
        (turned - 40.0).abs() < 0.05,
        "turned {turned}°, expected 100 points × 0.4°"
    );
    // The scene turns with the pointer: its near side goes right, so the camera goes left
    // and looks a little towards +x.
    assert!(
        after.direction().x > 0.0 && after.center().x < 0.0,
        "{after:?}"
    );
    assert_eq!(after.up(), before.up(), "turntable: up stays as written");
    let still = view(&h).project(pivot).expect("visible");
    assert!(
        (still - pivot_on_screen).length() < 1.5,
        "the pivot stays under the pointer: {pivot_on_screen:?} → {still:?}"
    );
    // A vertical drag tilts about the screen's right axis, without rolling.
    drag(
        &mut h,
        PointerButton::Middle,
        from,
        from + vec2(0.0, 50.0),
        5,
        true,
    );
    let tilted = camera(&h);
    assert!((angle_between(after.direction(), tilted.direction()) - 20.0).abs() < 0.05);
    assert!(
        ViewBasis::new(&tilted, 10, 10).rays.horizontal.y.abs() < 1e-5,
        "no roll"
    );
}

#[test]
fn an_orbit_drag_is_one_undo_step_that_restores_the_exact_camera_and_save_writes_it() {
    let path = scene_file("undo", SPHERE, PERSPECTIVE);
    let mut h = harness(path.clone());
    let before = camera(&h);
    let from = view(&h).rect.center();
    drag(
        &mut h,
        PointerButton::Middle,
        from,
        from + vec2(-70.0, 30.0),
        12,
        true,
    );
    settle(&mut h);
    let moved = camera(&h);
    assert_ne!(moved, before);
    // Save writes the new camera in the course's form.
    h.state_mut().save();
    let saved = tracelab_core::load_scene(&path, &mut MeshCache::new())
        .into_result()
        .expect("reads back")
        .0;
    assert_eq!(saved.camera, moved);
    h.key_press_modifiers(Modifiers::COMMAND, egui::Key::Z);
    settle(&mut h);
    assert_eq!(camera(&h), before, "one undo returns the exact camera");
    assert!(!h.state().doc().can_undo(), "the whole drag was one step");
}

#[test]
fn alt_left_drag_orbits_too_and_shift_middle_drag_pans_with_the_pointer() {
    let mut h = harness(scene_file("alt", SPHERE, PERSPECTIVE));
    let before = camera(&h);
    let from = view(&h).rect.center();
    h.event(Event::ModifiersChanged(Modifiers::ALT));
    drag(
        &mut h,
        PointerButton::Primary,
        from,
        from + vec2(50.0, 0.0),
        5,
        true,
    );
    h.event(Event::ModifiersChanged(Modifiers::NONE));
    settle(&mut h);
    assert!((angle_between(before.direction(), camera(&h).direction()) - 20.0).abs() < 0.05);
    h.state_mut().doc_mut().undo();
    settle(&mut h);
    // Pan: the sphere's front follows the pointer.
    let v = view(&h);
    let front = Vec3::new(0.0, 0.0, 1.0);
    let at = v.project(front).expect("visible");
    h.event(Event::ModifiersChanged(Modifiers::SHIFT));
    drag(
        &mut h,
        PointerButton::Middle,
        at,
        at + vec2(40.0, -25.0),
        5,
        true,
    );
    h.event(Event::ModifiersChanged(Modifiers::NONE));
    settle(&mut h);
    assert_eq!(
        camera(&h).direction(),
        before.direction(),
        "a pan does not turn"
    );
    let now = view(&h).project(front).expect("visible");
    assert!(
        (now - (at + vec2(40.0, -25.0))).length() < 1.5,
        "{at:?} → {now:?}"
    );
}

fn wheel(h: &mut Harness<'static, TracelabApp>, at: Pos2, lines: f32) {
    h.event(Event::PointerMoved(at));
    h.step();
    h.event(Event::MouseWheel {
        unit: egui::MouseWheelUnit::Line,
        delta: vec2(0.0, lines),
        phase: egui::TouchPhase::Move,
        source: egui::MouseWheelSource::Wheel,
        modifiers: Modifiers::NONE,
    });
    h.step();
}

#[test]
fn the_wheel_dollies_the_perspective_camera_and_sizes_the_orthographic_one() {
    let mut h = harness(scene_file("wheel", SPHERE, PERSPECTIVE));
    let at = view(&h).rect.center();
    wheel(&mut h, at, 1.0);
    // Towards the sphere's front (z = 1): the distance 9 becomes 9 / 1.2.
    let c = camera(&h).center();
    assert!(
        (c.z - (1.0 + 9.0 / 1.2)).abs() < 0.05 && c.x.abs() < 0.05,
        "{c}"
    );
    wheel(&mut h, at, -2.0);
    let c = camera(&h).center();
    assert!((c.z - (1.0 + 9.0 * 1.2)).abs() < 0.1, "{c}");

    let ortho = "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 5 }";
    let mut h = harness(scene_file("wheel-ortho", SPHERE, ortho));
    let at = view(&h).rect.center();
    wheel(&mut h, at, 1.0);
    let Camera::Orthographic {
        size, direction, ..
    } = camera(&h)
    else {
        panic!("still orthographic")
    };
    assert!((size - 5.0 / 1.2).abs() < 1e-4, "{size}");
    assert_eq!(direction, Vec3::NEG_Z);
}

fn corners((lo, hi): (Vec3, Vec3)) -> impl Iterator<Item = Vec3> {
    (0..8).map(move |i| {
        Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        )
    })
}

fn inside_the_image(h: &Harness<'static, TracelabApp>, b: (Vec3, Vec3)) -> bool {
    let basis = ViewBasis::new(&camera(h), SIZE.0, SIZE.1);
    corners(b).all(|c| {
        basis
            .project(c)
            .is_some_and(|p| p.x > 0.0 && p.y > 0.0 && p.x < SIZE.0 as f32 && p.y < SIZE.1 as f32)
    })
}

#[test]
fn f_frames_the_selection_home_frames_all_and_7_looks_down() {
    let objects = "Transform { Translate 6 3 -4 Sphere { center 0 0 0 radius 0.5 } }";
    let mut h = harness(scene_file("frame", objects, PERSPECTIVE));
    let s = sphere(&h);
    let bounds = tracelab::bounds::world_bounds(&h.state().doc().scene, s).expect("bounded");
    assert!(
        !inside_the_image(&h, bounds),
        "the test needs the sphere out of view at first"
    );
    select(&mut h, s);
    h.key_press(egui::Key::F);
    settle(&mut h);
    assert!(
        inside_the_image(&h, bounds),
        "F frames the selection: {:?}",
        camera(&h)
    );
    assert_eq!(
        camera(&h).direction(),
        Vec3::NEG_Z,
        "framing keeps the direction"
    );
    // The picture shows it: red pixels in the middle of the image.
    let shown = h.state().shown();
    let img = &shown[0];
    let mid = (SIZE.1 as usize / 2) * SIZE.0 as usize + SIZE.0 as usize / 2;
    assert!(
        img.image.pixels[mid].r() > 100 && img.image.pixels[mid].g() < 30,
        "{:?}",
        img.image.pixels[mid]
    );

    h.key_press(egui::Key::Num7);
    settle(&mut h);
    let c = camera(&h);
    assert!(
        matches!(c, Camera::Perspective { angle, .. } if angle == 30.0),
        "keeps the camera type"
    );
    assert_eq!((c.direction(), c.up()), (Vec3::NEG_Y, Vec3::NEG_Z));
    let root = h.state().doc().scene.graph.root();
    let all = tracelab::bounds::world_bounds(&h.state().doc().scene, root).expect("bounded");
    assert!(inside_the_image(&h, all));
}

/// The centroid (image pixels) of the red pixels on screen: where the object is drawn.
fn red_centroid(h: &Harness<'static, TracelabApp>) -> glam::Vec2 {
    let shown = h.state().shown();
    let img = &shown[0].image;
    let (mut sum, mut n) = (glam::Vec2::ZERO, 0.0);
    for (i, c) in img.pixels.iter().enumerate() {
        if c.r() > 40 && c.g() < 20 {
            sum += glam::Vec2::new(
                (i % img.size[0]) as f32 + 0.5,
                (i / img.size[0]) as f32 + 0.5,
            );
            n += 1.0;
        }
    }
    assert!(n > 20.0, "the object is on screen");
    sum / n
}

fn gizmo_point(h: &Harness<'static, TracelabApp>, handle: Handle) -> Pos2 {
    let v = view(h);
    let g = ViewTools::gizmo(h.state().doc(), &v, Axes::World).expect("a gizmo for the selection");
    v.project(g.handle_point(handle)).expect("visible")
}

#[test]
fn a_translate_arrow_drag_moves_the_object_with_the_pointer_under_a_uniform_scale_5() {
    let mut h = harness(scene_file("arrow", SCALED, PERSPECTIVE));
    let s = sphere(&h);
    select(&mut h, s);
    let v = view(&h);
    let centre = tracelab::bounds::world_centre(&h.state().doc().scene, s).expect("centre");
    let c0 = v.project(centre).expect("visible");
    let drawn0 = red_centroid(&h);
    let grab = gizmo_point(&h, Handle::Move(0));
    let axis_on_screen = (v.project(centre + Vec3::X).expect("visible") - c0).normalized();
    let n = 60.0;
    drag(
        &mut h,
        PointerButton::Primary,
        grab,
        grab + axis_on_screen * n,
        6,
        true,
    );
    settle(&mut h);
    let NodeKind::Transform(ops) = &h
        .state()
        .doc()
        .scene
        .graph
        .node(h.state().doc().scene.graph.parents()[s.index()].expect("parent"))
        .kind
    else {
        panic!("the sphere's parent is still its Transform")
    };
    let TransformOp::Translate(t) = ops[0] else {
        panic!("{ops:?}")
    };
    assert_eq!((t.y, t.z), (0.0, 0.0), "only x moves");
    let centre1 = tracelab::bounds::world_centre(&h.state().doc().scene, s).expect("centre");
    let c1 = view(&h).project(centre1).expect("visible");
    let moved = c1 - c0;
    assert!(
        (moved - axis_on_screen * n).length() < 1.0,
        "the centre moved {moved:?} for {n} points along {axis_on_screen:?}"
    );
    // In the op's units that is a fifth of the world distance.
    let world = (centre1 - centre).length();
    assert!(
        ((t.x - 0.1) * 5.0 - world).abs() < 1e-4,
        "{t} for {world} world units"
    );
    // And the picture shows it there: the red pixels moved by as many image pixels.
    let drawn = red_centroid(&h) - drawn0;
    let expected = n / (v.rect.width() / SIZE.0 as f32);
    assert!(
        (drawn.x - expected).abs() < 1.0 && drawn.y.abs() < 1.0,
        "drawn moved {drawn} px, expected {expected}"
    );
    // One undo step, exact.
    h.key_press_modifiers(Modifiers::COMMAND, egui::Key::Z);
    settle(&mut h);
    assert_eq!(
        tracelab::bounds::world_centre(&h.state().doc().scene, s),
        Some(centre)
    );
}

#[test]
fn a_missing_op_is_added_in_its_place_a_lone_node_is_wrapped_and_the_status_bar_says_so() {
    let objects = "Transform { Scale 2 2 2 Sphere { center 0 0 0 radius 0.5 } }";
    let mut h = harness(scene_file("add-op", objects, PERSPECTIVE));
    let s = sphere(&h);
    select(&mut h, s);
    let grab = gizmo_point(&h, Handle::Move(1));
    drag(
        &mut h,
        PointerButton::Primary,
        grab,
        grab + vec2(0.0, -30.0),
        4,
        true,
    );
    settle(&mut h);
    let t = h.state().doc().scene.graph.parents()[s.index()].expect("parent");
    let NodeKind::Transform(ops) = &h.state().doc().scene.graph.node(t).kind else {
        panic!("a Transform")
    };
    assert!(
        matches!(ops.as_slice(), [TransformOp::Translate(v), TransformOp::Scale(_)] if v.y > 0.0 && v.x == 0.0),
        "{ops:?}"
    );
    let note = h.state().note().map(str::to_string).unwrap_or_default();
    assert!(note.contains("added Translate as op 1"), "{note}");
    // The ring adds its ZRotate after the Translate, before the Scale.
    let grab = gizmo_point(&h, Handle::Rotate);
    drag(
        &mut h,
        PointerButton::Primary,
        grab,
        grab + vec2(0.0, 25.0),
        4,
        true,
    );
    settle(&mut h);
    let NodeKind::Transform(ops) = &h.state().doc().scene.graph.node(t).kind else {
        panic!("a Transform")
    };
    assert!(
        matches!(ops.as_slice(), [TransformOp::Translate(_), TransformOp::ZRotate(d), TransformOp::Scale(_)] if *d != 0.0),
        "{ops:?}"
    );

    let mut h = harness(scene_file("wrap", SPHERE, PERSPECTIVE));
    let s = sphere(&h);
    select(&mut h, s);
    let before = h.state().doc().scene.clone();
    let grab = gizmo_point(&h, Handle::Scale(0));
    drag(
        &mut h,
        PointerButton::Primary,
        grab,
        grab + vec2(20.0, 0.0),
        4,
        true,
    );
    settle(&mut h);
    let t = h.state().doc().scene.graph.parents()[s.index()].expect("parent");
    let NodeKind::Transform(ops) = &h.state().doc().scene.graph.node(t).kind else {
        panic!("wrapped in a Transform")
    };
    assert!(
        matches!(ops.as_slice(), [TransformOp::Scale(v)] if v.x > 1.0 && v.y == 1.0 && v.z == 1.0),
        "{ops:?}"
    );
    let note = h.state().note().map(str::to_string).unwrap_or_default();
    assert!(
        note.contains("wrapped the Sphere in a new Transform with Scale"),
        "{note}"
    );
    h.key_press_modifiers(Modifiers::COMMAND, egui::Key::Z);
    settle(&mut h);
    assert_eq!(
        h.state().doc().scene,
        before,
        "one undo takes the Transform away again"
    );
}

#[test]
fn esc_during_a_gizmo_drag_restores_the_value_and_ctrl_snaps() {
    let mut h = harness(scene_file("esc", SCALED, PERSPECTIVE));
    let s = sphere(&h);
    select(&mut h, s);
    let before = h.state().doc().scene.clone();
    let grab = gizmo_point(&h, Handle::Move(0));
    drag(
        &mut h,
        PointerButton::Primary,
        grab,
        grab + vec2(45.0, 0.0),
        5,
        false,
    );
    assert_ne!(h.state().doc().scene, before, "the drag moved it");
    h.key_press(egui::Key::Escape);
    h.step();
    assert_eq!(h.state().doc().scene, before, "Esc puts it back");
    // The rest of that press moves nothing.
    h.event(Event::PointerMoved(grab + vec2(80.0, 0.0)));
    h.step();
    press(
        &mut h,
        PointerButton::Primary,
        grab + vec2(80.0, 0.0),
        false,
    );
    settle(&mut h);
    assert_eq!(h.state().doc().scene, before);
    assert!(
        !h.state().doc().can_undo(),
        "nothing to undo after a cancelled drag"
    );
    // With Ctrl, the Translate lands on a multiple of 0.1 (in the op's own units).
    h.event(Event::ModifiersChanged(Modifiers::COMMAND));
    drag(
        &mut h,
        PointerButton::Primary,
        grab,
        grab + vec2(63.0, 0.0),
        5,
        true,
    );
    h.event(Event::ModifiersChanged(Modifiers::NONE));
    settle(&mut h);
    let t = h.state().doc().scene.graph.parents()[s.index()].expect("parent");
    let NodeKind::Transform(ops) = &h.state().doc().scene.graph.node(t).kind else {
        panic!("a Transform")
    };
    let TransformOp::Translate(v) = ops[0] else {
        panic!("{ops:?}")
    };
    assert!(
        ((v.x * 10.0).round() - v.x * 10.0).abs() < 1e-4 && v.x > 0.15,
        "{v}"
    );
}

#[test]
fn a_drag_renders_coarse_passes_while_the_pointer_moves_and_refines_when_it_stops() {
    let mut h = harness(scene_file("coarse", SPHERE, PERSPECTIVE));
    let from = view(&h).rect.center();
    drag(
        &mut h,
        PointerButton::Middle,
        from,
        from + vec2(30.0, 0.0),
        3,
        false,
    );
    assert!(h.state().worker().coarse_only, "moving: coarse passes only");
    let start = Instant::now();
    while !h
        .state()
        .worker()
        .with_published(|p| p.is_some_and(|p| p.job.coarse && p.full.is_some()))
    {
        h.step();
        assert!(start.elapsed() < Duration::from_secs(20));
    }
    // Held still: the same camera is rendered in full, before the button is even released.
    std::thread::sleep(tracelab::gui::view_tools::STILL_AFTER);
    settle(&mut h);
    h.state().worker().with_published(|p| {
        let p = p.expect("published");
        // Five passes, or fewer where a quick coarse pass went straight to the full one.
        assert!(
            !p.job.coarse
                && p.full.is_some()
                && (2..=5).contains(&p.passes)
                && p.passes_done == p.passes,
            "refined"
        );
        assert_eq!(p.job.generation, h.state().doc().generation);
    });
    press(&mut h, PointerButton::Middle, from + vec2(30.0, 0.0), false);
}
