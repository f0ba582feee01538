//! Logic tests of the editor window with egui_kittest: they find widgets by label, click and
//! set values as a user would, and check the document and the renderer. No GPU needed.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use egui_kittest::Harness;
use egui_kittest::kittest::{NodeT, Queryable};
use glam::Vec3;
use tracelab::document::Selection;
use tracelab::gui::{AppOptions, Pending, TracelabApp};
use tracelab_core::{MeshCache, NodeId, NodeKind, TransformOp, View};

mod common;
use common::settle;

fn repo(rel: &str) -> PathBuf {
    common::repo().join(rel)
}

/// A course scene (see `common::course_dir`). Tests that use one are `#[ignore]`d with the
/// reason, so a plain `cargo test` lists them as ignored; run with `--ignored`, missing
/// course files fail them here.
fn course_scene(name: &str) -> PathBuf {
    let p = common::course_dir().join("scenes").join(name);
    assert!(p.is_file(), "{} is missing", p.display());
    p
}

fn temp_dir(tag: &str) -> PathBuf {
    common::temp_dir("gui", tag)
}

fn harness(scene: Option<PathBuf>, size: (u32, u32)) -> Harness<'static, TracelabApp> {
    common::app_harness(scene, size)
}

/// The first Transform in the scene whose first op is a Translate.
fn translate_transform(app: &TracelabApp) -> (NodeId, Vec3) {
    app.doc()
        .scene
        .graph
        .iter()
        .find_map(|(id, n)| match &n.kind {
            NodeKind::Transform(ops) => match ops.first() {
                Some(TransformOp::Translate(t)) => Some((id, *t)),
                _ => None,
            },
            _ => None,
        })
        .expect("a Transform starting with Translate")
}

/// Select a Transform in the tree, change its Translate x in the inspector, check the
/// document and the render, save and read back, undo.
fn edit_save_undo(scene: PathBuf) {
    let mut h = harness(Some(scene.clone()), (48, 48));
    settle(&mut h);
    assert!(
        h.state()
            .doc()
            .messages
            .iter()
            .all(|m| m.text.contains("warning")),
        "{:?}",
        h.state().doc().messages
    );
    let original = h.state().doc().scene.clone();
    let (id, t) = translate_transform(h.state());

    let label = tracelab::node_label::node_label(&h.state().doc().scene.graph.node(id).kind, 1);
    h.get_all_by_label_contains(&label)
        .next()
        .expect("tree row")
        .click();
    h.step();
    assert_eq!(h.state().doc().selection, Some(Selection::Node(id)));

    let gen_before = h.state().doc().generation;
    let worker_before = h.state().worker().last_generation();
    let new_x = t.x + 0.75;
    h.get_by_label("Translate x")
        .set_value_accesskit(f64::from(new_x));
    h.step();
    h.step();
    let app = h.state();
    let NodeKind::Transform(ops) = &app.doc().scene.graph.node(id).kind else {
        panic!("still a Transform")
    };
    assert_eq!(ops[0], TransformOp::Translate(Vec3::new(new_x, t.y, t.z)));
    assert!(app.doc().generation > gen_before, "the document changed");
    assert!(app.doc().is_dirty());
    assert!(
        app.worker().last_generation() > worker_before,
        "the render restarted"
    );
    settle(&mut h);
    let shown = h
        .state()
        .worker()
        .with_published(|p| p.map(|p| p.job.generation));
    assert_eq!(
        shown,
        Some(h.state().doc().generation),
        "the image shows the edited scene"
    );

    let out = temp_dir("save").join(scene.file_name().expect("name"));
    h.state_mut().save_as(&out);
    assert!(!h.state().doc().is_dirty());
    let back = tracelab_core::load_scene(&out, &mut MeshCache::new())
        .into_result()
        .expect("saved file reads back")
        .0;
    let found = back.graph.iter().any(|(_, n)| {
        matches!(&n.kind, NodeKind::Transform(ops) if ops.first() == Some(&TransformOp::Translate(Vec3::new(new_x, t.y, t.z))))
    });
    assert!(found, "saved file holds the new Translate");

    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    h.step();
    // Save As moved the document, so its relative mesh paths (undo history included) now
    // start from the new folder.
    let mut original = original;
    let dir = |p: &Path| p.parent().map(Path::to_path_buf).unwrap_or_default();
    tracelab_core::rebase_mesh_paths(&mut original, &dir(&scene), &dir(&out));
    assert_eq!(
        h.state().doc().scene,
        original,
        "undo restores the identical document"
    );
    let _ = std::fs::remove_file(&out);
}

#[test]
#[ignore = "needs the course files: TRACELAB_COURSE_DIR, default ../shared/mit6837"]
fn course_scene_edit_save_and_undo() {
    let scene = course_scene("scene2_16_t_scale.txt");
    edit_save_undo(scene);
}

#[test]
fn own_scene_edit_save_and_undo() {
    edit_save_undo(repo("scenes/nested_transforms.txt"));
}

#[test]
fn syntax_error_shows_its_location_and_keeps_the_scene() {
    let mut h = harness(None, (32, 32));
    settle(&mut h);
    let before = h.state().doc().scene.clone();
    let bad = temp_dir("bad").join("broken.txt");
    std::fs::write(
        &bad,
        "OrthographicCamera {\n    center 0 0 10\n    direction 0 0 oops\n}\n",
    )
    .expect("write");
    h.state_mut().open(&bad);
    // Read in the background: wait for its answer.
    step_until(&mut h, 10, "the error", |a| !a.is_loading());
    h.step();
    assert_eq!(
        h.state().doc().scene,
        before,
        "the previous scene stays open"
    );
    let msg = h.state().doc().messages.joined();
    assert!(msg.contains("broken.txt:3:"), "{msg}");
    // Shown in the window, with file:line:col.
    let _ = h.get_by_label_contains("broken.txt:3:");
    // And the app keeps working.
    settle(&mut h);
}

const SPHERE_SCENE: &str = "
OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 2.5 }
Lights { numLights 1 DirectionalLight { direction -0.2 -0.2 -1 color 1 1 1 } }
Background { color 0.2 0 0.6 ambientLight 0 0 0 }
Materials { numMaterials 1 Material { diffuseColor 1 1 1 } }
Group { numObjects 1 MaterialIndex 0
  Transform { OP Sphere { center 0 0 0 radius 1 } } }
";

/// `SPHERE_SCENE` seen by a perspective camera of 30 degrees, its Transform's ops `op`.
fn perspective_sphere_scene(op: &str) -> String {
    SPHERE_SCENE
        .replace(
            "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 2.5 }",
            "PerspectiveCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 angle 30 }",
        )
        .replace("OP", op)
}

/// Normal-view bytes with the switch on Correct, then on Incorrect (clicked in the UI).
fn normals_both_ways(op: &str, tag: &str) -> (Vec<u8>, Vec<u8>) {
    let path = temp_dir(tag).join("sphere.txt");
    std::fs::write(&path, SPHERE_SCENE.replace("OP", op)).expect("write");
    let mut h = harness(Some(path), (40, 40));
    h.state_mut().view_mut().tab = tracelab::gui::panels::viewport::Tab::Normals;
    settle(&mut h);
    let grab = |h: &Harness<'static, TracelabApp>| {
        h.state().worker().with_published(|p| {
            p.expect("rendered").frames[0]
                .lock()
                .rgb8(View::Normals, (0.0, 1.0))
        })
    };
    let correct = grab(&h);
    h.get_by_label("Incorrect M").click();
    h.step();
    settle(&mut h);
    assert_eq!(
        h.state().view().normal_transform,
        tracelab_core::NormalTransform::Incorrect
    );
    (correct, grab(&h))
}

#[test]
fn normal_switch_changes_a_squashed_sphere_and_not_a_plain_one() {
    let (c, i) = normals_both_ways("Scale 1 0.2 1", "squashed");
    let differ = c.chunks(3).zip(i.chunks(3)).filter(|(a, b)| a != b).count();
    assert!(differ > 50, "only {differ} pixels changed");
    let (c, i) = normals_both_ways("UniformScale 0.8", "plain");
    assert_eq!(c, i, "a uniformly scaled sphere looks the same either way");
}

#[test]
fn closing_with_unsaved_changes_asks_first() {
    let mut h = harness(None, (32, 32));
    settle(&mut h);
    let (id, t) = translate_transform(h.state());
    h.state_mut()
        .apply(tracelab::document::edit::Edit::SetTransformOp {
            node: id,
            index: 0,
            op: TransformOp::Translate(t + Vec3::X),
        });
    h.step();
    h.input_mut()
        .viewports
        .entry(egui::ViewportId::ROOT)
        .or_default()
        .events
        .push(egui::ViewportEvent::Close);
    h.step();
    h.step();
    assert_eq!(h.state().confirm(), Some(&Pending::Close));
    h.get_by_label("Cancel").click();
    h.step();
    assert_eq!(h.state().confirm(), None);
    assert!(h.state().doc().is_dirty(), "cancel keeps the edits");
}

#[test]
fn clicking_a_pixel_selects_its_node_and_tells_the_ray_story() {
    let mut h = harness(None, (64, 48));
    settle(&mut h);
    // A pixel showing an object that sits under a Transform (the built-in scene has several).
    let pixel = h.state().worker().with_published(|p| {
        let p = p.expect("rendered");
        let f = p.frames[0].lock();
        let g = &h.state().doc().scene.graph;
        (0..f.height)
            .flat_map(|row| (0..f.width).map(move |x| (x, row)))
            .find(|&(x, row)| {
                let s = f.get(x, row).expect("in frame");
                s.is_hit()
                    && g.path_to(NodeId(s.node)).is_some_and(|path| {
                        path.iter()
                            .any(|&id| matches!(g.node(id).kind, NodeKind::Transform(_)))
                    })
            })
    });
    let (x, row) = pixel.expect("some pixel shows a transformed object");
    h.state_mut().inspect(0, x, row);
    // A new window lays itself out in its first frame and shows in the next.
    for _ in 0..3 {
        h.step();
    }
    let app = h.state();
    let (story, _) = app.story().expect("a story");
    let hit = story.hit.as_ref().expect("the ray hits something");
    assert_eq!(app.doc().selection, Some(Selection::Node(hit.node)));
    assert!(hit.path.iter().any(|s| s.kind == "Transform"));
    let _ = h.get_by_label_contains("world normal by (M^-1)^T");
}

#[test]
fn recent_files_and_view_settings_persist() {
    struct Mem(std::collections::HashMap<String, String>);
    impl eframe::Storage for Mem {
        fn get_string(&self, key: &str) -> Option<String> {
            self.0.get(key).cloned()
        }
        fn set_string(&mut self, key: &str, value: String) {
            self.0.insert(key.into(), value);
        }
        fn remove_string(&mut self, key: &str) {
            self.0.remove(key);
        }
        fn flush(&mut self) {}
    }
    let mut a = TracelabApp::new(None, AppOptions::default());
    assert!(a.open_now(&repo("scenes/hierarchy.txt")));
    a.view_mut().tab = tracelab::gui::panels::viewport::Tab::Depth;
    a.view_mut().depth = (3.0, 12.5);
    let mut m = Mem(Default::default());
    eframe::App::save(&mut a, &mut m);
    let mut b = TracelabApp::new(None, AppOptions::default());
    b.load_persisted(&m);
    // Kept canonical, so the entry works from any folder (issue 26 bug 5).
    let canonical = std::fs::canonicalize(repo("scenes/hierarchy.txt")).expect("canonical");
    assert_eq!(b.recent(), vec![canonical]);
    assert_eq!(b.view().tab, tracelab::gui::panels::viewport::Tab::Depth);
    assert_eq!(b.view().depth, (3.0, 12.5));
}

#[test]
fn export_all_three_writes_every_view() {
    let mut h = harness(None, (32, 24));
    h.state_mut().view_mut().tab = tracelab::gui::panels::viewport::Tab::All;
    settle(&mut h);
    let out = temp_dir("export").join("shot.png");
    let files = h.state_mut().export(&out).expect("exports");
    assert_eq!(files.len(), 3);
    for f in &files {
        let img = image::open(f).expect("readable").to_rgb8();
        assert_eq!(img.dimensions(), (32, 24));
    }
    let names: Vec<String> = files
        .iter()
        .map(|f| {
            f.file_name()
                .unwrap_or_default()
                .to_string_lossy()
                .to_string()
        })
        .collect();
    assert_eq!(
        names,
        ["shot_color.png", "shot_normals.png", "shot_depth.png"]
    );
}

#[cfg(unix)]
#[test]
fn export_never_writes_the_open_scene_or_through_a_planted_link() {
    let d = temp_dir("export-policy");
    // A scene whose name is an image's: exporting over it is refused.
    let scene = d.join("scene.png");
    let text = SPHERE_SCENE.replace("OP", "UniformScale 1");
    std::fs::write(&scene, &text).expect("write");
    let mut h = harness(Some(scene.clone()), (16, 12));
    settle(&mut h);
    let e = h.state_mut().export(&scene).expect_err("the open scene");
    assert!(e.to_string().contains("names an input"), "{e}");
    assert_eq!(std::fs::read_to_string(&scene).expect("read"), text);
    // The names made for "All three" never follow a symlink, and nothing is written.
    std::fs::write(d.join("victim.txt"), "keep").expect("write");
    std::os::unix::fs::symlink("victim.txt", d.join("shot_normals.png")).expect("plant");
    h.state_mut().view_mut().tab = tracelab::gui::panels::viewport::Tab::All;
    settle(&mut h);
    let e = h
        .state_mut()
        .export(&d.join("shot.png"))
        .expect_err("a planted link");
    assert!(e.to_string().contains("symbolic link"), "{e}");
    assert_eq!(
        std::fs::read_to_string(d.join("victim.txt")).expect("read"),
        "keep"
    );
    assert!(!d.join("shot_color.png").exists());
}

#[test]
fn a_file_changed_on_disk_is_reloaded() {
    let path = temp_dir("reload").join("sphere.txt");
    std::fs::write(&path, SPHERE_SCENE.replace("OP", "UniformScale 1")).expect("write");
    let mut h = harness(Some(path.clone()), (16, 16));
    settle(&mut h);
    // Someone edits the file in a text editor beside the app.
    std::thread::sleep(Duration::from_millis(20));
    std::fs::write(&path, SPHERE_SCENE.replace("OP", "UniformScale 0.5")).expect("write");
    let start = Instant::now();
    loop {
        h.step();
        let reloaded = h.state().doc().scene.graph.iter().any(|(_, n)| {
            matches!(&n.kind, NodeKind::Transform(ops) if ops.first() == Some(&TransformOp::UniformScale(0.5)))
        });
        if reloaded {
            break;
        }
        assert!(start.elapsed() < Duration::from_secs(5), "not reloaded");
        std::thread::sleep(Duration::from_millis(50));
    }
    assert!(!h.state().doc().is_dirty());
}

#[derive(Debug)]
struct Dropped(PathBuf);

impl egui::DroppedFile for Dropped {
    fn path(&self) -> &Path {
        &self.0
    }
    fn bytes(&self) -> Result<Vec<u8>, String> {
        std::fs::read(&self.0).map_err(|e| e.to_string())
    }
}

#[test]
fn a_scene_dropped_on_the_window_opens() {
    let mut h = harness(None, (16, 16));
    settle(&mut h);
    let path = repo("scenes/hierarchy.txt");
    h.input_mut()
        .dropped_files
        .push(std::sync::Arc::new(Dropped(path.clone())));
    step_until(&mut h, 10, "the dropped scene", |a| {
        a.doc().path.as_deref() == Some(path.as_path())
    });
    let canonical = std::fs::canonicalize(&path).expect("canonical");
    assert_eq!(h.state().recent().first(), Some(&canonical));
}

#[test]
fn opening_over_unsaved_changes_asks_and_discard_opens() {
    let mut h = harness(None, (16, 16));
    settle(&mut h);
    h.state_mut()
        .apply(tracelab::document::edit::Edit::AddMaterial(
            tracelab_core::Material::diffuse(Vec3::ONE),
        ));
    let target = repo("scenes/hierarchy.txt");
    h.state_mut().open(&target);
    // The file is read first; the question comes once there is something to switch to.
    step_until(&mut h, 10, "the question", |a| a.confirm().is_some());
    h.step();
    assert_eq!(h.state().confirm(), Some(&Pending::Open(target.clone())));
    assert_eq!(
        h.state().doc().path,
        None,
        "nothing opened before the answer"
    );
    h.get_by_label("Discard changes").click();
    h.step();
    assert_eq!(h.state().doc().path.as_deref(), Some(target.as_path()));
    assert!(!h.state().doc().is_dirty());
}

#[test]
fn a_missing_obj_is_an_error_on_its_node_not_a_failure_to_open() {
    let dir = temp_dir("missing-obj");
    let path = dir.join("mesh.txt");
    std::fs::write(
        &path,
        SPHERE_SCENE
            .replace(
                "Sphere { center 0 0 0 radius 1 }",
                "TriangleMesh { obj_file nowhere.obj }",
            )
            .replace("OP", "UniformScale 1"),
    )
    .expect("write");
    let mut h = harness(Some(path.clone()), (16, 16));
    settle(&mut h);
    let app = h.state();
    assert_eq!(
        app.doc().path.as_deref(),
        Some(path.as_path()),
        "the scene opened"
    );
    assert!(
        app.doc()
            .messages
            .iter()
            .any(|m| m.text.contains("nowhere.obj")),
        "{:?}",
        app.doc().messages
    );
    let _ = h.get_by_label_contains("TriangleMesh: nowhere.obj (not loaded)");
}

#[test]
fn ctrl_o_opens_the_file_dialog_and_it_opens_a_typed_name() {
    let mut h = harness(None, (16, 16));
    settle(&mut h);
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::O);
    for _ in 0..3 {
        h.step();
    }
    assert!(h.state().dialog().is_some());
    let target = repo("scenes/flat_transforms.txt");
    h.get_by_role(egui::accesskit::Role::TextInput).focus();
    h.step();
    h.get_by_role(egui::accesskit::Role::TextInput)
        .type_text(&target.display().to_string());
    h.step();
    h.get_by_label("Open").click();
    step_until(&mut h, 10, "the file to open", |a| {
        a.doc().path.as_deref() == Some(target.as_path())
    });
    assert!(h.state().dialog().is_none());
}

#[test]
fn adding_a_triangle_mesh_and_loading_its_obj() {
    let mut h = harness(Some(repo("scenes/flat_transforms.txt")), (16, 16));
    settle(&mut h);
    let before = h.state().doc().scene.graph.stats().triangles;
    h.get_by_label("Add").click();
    for _ in 0..2 {
        h.step();
    }
    h.get_by_label("TriangleMesh").click();
    for _ in 0..2 {
        h.step();
    }
    let Some(Selection::Node(id)) = h.state().doc().selection else {
        panic!("the new mesh is selected")
    };
    h.get_by_role(egui::accesskit::Role::TextInput).focus();
    h.step();
    h.get_by_role(egui::accesskit::Role::TextInput)
        .type_text("../assets/torus.obj");
    h.step();
    h.get_by_label("Load / reload").click();
    h.step();
    // Read on a thread (the window keeps painting): wait for it.
    step_until(&mut h, 10, "the mesh to load", |a| !a.is_loading());
    let NodeKind::TriangleMesh { obj_file, mesh } = &h.state().doc().scene.graph.node(id).kind
    else {
        panic!("a TriangleMesh")
    };
    assert_eq!(obj_file, "../assets/torus.obj");
    assert!(mesh.mesh().is_some(), "loaded: {mesh:?}");
    assert!(h.state().doc().scene.graph.stats().triangles > before);
    // Adding and loading are two undo steps; both undo cleanly.
    assert!(h.state_mut().doc_mut().undo() && h.state_mut().doc_mut().undo());
    assert_eq!(h.state().doc().scene.graph.stats().triangles, before);
}

#[test]
fn csg_nodes_show_in_the_tree_and_their_operation_can_be_changed_and_swapped() {
    let mut h = harness(Some(repo("scenes/lecture/csg_subtraction.txt")), (32, 32));
    settle(&mut h);
    let csg = h
        .state()
        .doc()
        .scene
        .graph
        .iter()
        .find(|(_, n)| matches!(n.kind, NodeKind::Csg(_)))
        .map(|(id, _)| id)
        .expect("the scene has a CSG node");
    let before = h.state().doc().scene.graph.node(csg).children.clone();
    h.get_by_label_contains("Subtraction: A minus B").click();
    h.step();
    assert_eq!(h.state().doc().selection, Some(Selection::Node(csg)));
    let generation = h.state().doc().generation;
    h.get_by_label("Union").click();
    h.step();
    assert_eq!(
        h.state().doc().scene.graph.node(csg).kind,
        NodeKind::Csg(tracelab_core::CsgOp::Union)
    );
    assert!(
        h.state().doc().generation > generation,
        "the edit restarts the render"
    );
    h.get_by_label("Swap A and B").click();
    h.step();
    let after = h.state().doc().scene.graph.node(csg).children.clone();
    assert_eq!(after, [before[1], before[0]]);
    settle(&mut h);
    // Clicking the render on a CSG surface selects the operand it came from.
    let pixel = h.state().worker().with_published(|p| {
        let p = p.expect("rendered");
        let f = p.frames[0].lock();
        let s = f.get(16, 16).expect("in frame");
        s.is_hit().then_some(NodeId(s.node))
    });
    let node = pixel.expect("the centre pixel shows the union");
    assert!(
        matches!(
            h.state().doc().scene.graph.node(node).kind,
            NodeKind::Sphere { .. }
        ),
        "an operand, not the CSG node"
    );
}

/// The pixels the view drew (the uploaded texture), as RGB, for the single view.
fn on_screen(h: &Harness<'static, TracelabApp>) -> Vec<u8> {
    let shown = h.state().shown();
    assert_eq!(shown.len(), 1, "one image in the single view");
    shown[0].rgb8()
}

#[test]
fn the_picture_on_screen_follows_the_normal_switch_and_shade_back() {
    // Bug: the texture was keyed by document generation and frame version; a re-render of
    // the same generation for another rule reached the same version and never replaced it.
    let path = temp_dir("screen-switch").join("sphere.txt");
    std::fs::write(&path, SPHERE_SCENE.replace("OP", "Scale 1 0.2 1")).expect("write");
    let mut h = harness(Some(path), (40, 40));
    h.get_by_label("Normals").click();
    h.step();
    settle(&mut h);
    let correct = on_screen(&h);
    let rendered = |h: &Harness<'static, TracelabApp>| {
        h.state().worker().with_published(|p| {
            p.expect("rendered").frames[0]
                .lock()
                .rgb8(View::Normals, (0.0, 1.0))
        })
    };
    assert_eq!(correct, rendered(&h), "the screen shows the render");
    h.get_by_label("Incorrect M").click();
    h.step();
    settle(&mut h);
    let incorrect = on_screen(&h);
    assert_ne!(correct, incorrect, "Incorrect M changed nothing on screen");
    assert_eq!(incorrect, rendered(&h));
    h.get_by_label("Correct (M^-1)^T").click();
    h.step();
    settle(&mut h);
    assert_eq!(on_screen(&h), correct, "Correct restores the picture");
}

#[test]
#[ignore = "needs the course files: TRACELAB_COURSE_DIR, default ../shared/mit6837"]
fn shade_back_changes_the_picture_of_an_inside_view() {
    let scene = course_scene("scene2_05_inside_sphere.txt");
    let mut h = harness(Some(scene), (40, 40));
    settle(&mut h);
    let before = on_screen(&h);
    h.get_by_label("shade back").click();
    h.step();
    settle(&mut h);
    assert!(h.state().view().shade_back);
    assert_ne!(
        before,
        on_screen(&h),
        "shade back changed nothing on screen"
    );
}

// ---- Issue 10 and 16: each test below failed on e638896 (see the commit message). ----

/// Steps until `done` holds, failing after `secs`; for work that finishes in the background.
fn step_until(
    h: &mut Harness<'static, TracelabApp>,
    secs: u64,
    what: &str,
    done: impl Fn(&TracelabApp) -> bool,
) {
    let start = Instant::now();
    loop {
        h.step();
        if done(h.state()) {
            return;
        }
        assert!(
            start.elapsed() < Duration::from_secs(secs),
            "timed out waiting for {what}"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
}

fn inspected_hit(app: &TracelabApp) -> Option<tracelab_core::render::HitStory> {
    app.story().and_then(|(s, _)| s.hit.clone())
}

#[test]
fn the_pixel_inspector_retraces_its_pixel_after_an_edit_and_keeps_the_selection() {
    let path = temp_dir("inspect-edit").join("sphere.txt");
    std::fs::write(&path, SPHERE_SCENE.replace("OP", "Translate 0 0 0")).expect("write");
    let mut h = harness(Some(path), (40, 40));
    settle(&mut h);
    h.state_mut().inspect(0, 20, 20);
    for _ in 0..3 {
        h.step();
    }
    let before = inspected_hit(h.state()).expect("the centre pixel hits the sphere");
    let (id, _) = translate_transform(h.state());
    h.state_mut().doc_mut().selection = Some(Selection::Node(id));
    h.state_mut()
        .apply(tracelab::document::edit::Edit::SetTransformOp {
            node: id,
            index: 0,
            op: TransformOp::Translate(Vec3::new(0.3, 0.2, 0.5)),
        });
    settle(&mut h);
    h.step();
    let after = inspected_hit(h.state()).expect("still a hit");
    assert_ne!(
        before.world_point, after.world_point,
        "the inspector kept the old story"
    );
    // Exactly what the new render's scene gives for that pixel.
    let fresh = h.state().worker().with_published(|p| {
        let p = p.expect("rendered");
        tracelab_core::render::inspect_pixel(&p.job.scene, &p.compiled, &p.job.settings, 20, 20)
    });
    assert_eq!(Some(&fresh), h.state().story().map(|(s, _)| s));
    assert_eq!(
        h.state().doc().selection,
        Some(Selection::Node(id)),
        "re-tracing must not change the selection"
    );
}

#[test]
fn the_pixel_inspector_forgets_a_deleted_box() {
    let path = temp_dir("inspect-delete").join("box.txt");
    std::fs::write(
        &path,
        SPHERE_SCENE.replace(
            "Transform { OP Sphere { center 0 0 0 radius 1 } }",
            "Box { min -1 -1 -1 max 1 1 1 }",
        ),
    )
    .expect("write");
    let mut h = harness(Some(path), (40, 40));
    settle(&mut h);
    h.state_mut().inspect(0, 20, 20);
    for _ in 0..3 {
        h.step();
    }
    let hit = inspected_hit(h.state()).expect("the centre pixel shows the box");
    let _ = h.get_by_label_contains("Hit Box");
    h.state_mut()
        .apply(tracelab::document::edit::Edit::DeleteNode { node: hit.node });
    settle(&mut h);
    for _ in 0..3 {
        h.step();
    }
    assert!(
        inspected_hit(h.state()).is_none(),
        "the ray now misses: {:?}",
        inspected_hit(h.state())
    );
    assert!(
        h.query_by_label_contains("Hit Box").is_none(),
        "the inspector still shows the deleted box"
    );
}

/// Two scenes of the same shape whose only TriangleMesh names `obj`, so its node id is the same.
fn mesh_scene(tag: &str, obj: &str) -> PathBuf {
    let path = temp_dir(tag).join(format!("{tag}.txt"));
    let text = SPHERE_SCENE
        .replace(
            "Sphere { center 0 0 0 radius 1 }",
            &format!("TriangleMesh {{ obj_file {obj} }}"),
        )
        .replace("OP", "UniformScale 1");
    std::fs::write(&path, text).expect("write");
    path
}

fn mesh_node(app: &TracelabApp) -> NodeId {
    app.doc()
        .scene
        .graph
        .iter()
        .find(|(_, n)| matches!(n.kind, NodeKind::TriangleMesh { .. }))
        .map(|(id, _)| id)
        .expect("a TriangleMesh")
}

fn obj_field(h: &Harness<'static, TracelabApp>) -> String {
    h.get_by_role(egui::accesskit::Role::TextInput)
        .value()
        .unwrap_or_default()
}

#[test]
fn the_obj_file_field_shows_the_current_documents_value_after_open_undo_and_redo() {
    let cube = repo("assets/cube.obj").display().to_string();
    let torus = repo("assets/torus.obj").display().to_string();
    let a = mesh_scene("mesh-a", &cube);
    let b = mesh_scene("mesh-b", &torus);
    let mut h = harness(Some(a), (16, 16));
    settle(&mut h);
    let id = mesh_node(h.state());
    h.state_mut().doc_mut().selection = Some(Selection::Node(id));
    h.step();
    h.step();
    assert_eq!(obj_field(&h), cube);
    h.state_mut().open(&b);
    step_until(&mut h, 30, "the second scene", |a| {
        a.doc().path.as_deref() == Some(b.as_path())
    });
    assert_eq!(mesh_node(h.state()), id, "same shape, same node id");
    h.state_mut().doc_mut().selection = Some(Selection::Node(id));
    h.step();
    h.step();
    assert_eq!(
        obj_field(&h),
        torus,
        "the field shows the previous document's file"
    );
    h.get_by_label("Load / reload").click();
    h.step();
    step_until(&mut h, 10, "the mesh to load", |a| !a.is_loading());
    let file = |app: &TracelabApp| match &app.doc().scene.graph.node(id).kind {
        NodeKind::TriangleMesh { obj_file, .. } => obj_file.clone(),
        _ => String::new(),
    };
    assert_eq!(
        file(h.state()),
        torus,
        "Load swapped in the other scene's mesh"
    );
    // An edit from elsewhere, then undo and redo: the field follows each time.
    let mut kind = h.state().doc().scene.graph.node(id).kind.clone();
    if let NodeKind::TriangleMesh { obj_file, .. } = &mut kind {
        *obj_file = cube.clone();
    }
    h.state_mut()
        .apply(tracelab::document::edit::Edit::SetNodeKind { node: id, kind });
    h.step();
    h.step();
    assert_eq!(obj_field(&h), cube);
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    h.step();
    h.step();
    assert_eq!(file(h.state()), torus);
    assert_eq!(obj_field(&h), torus, "after undo");
    h.key_press_modifiers(
        egui::Modifiers::COMMAND | egui::Modifiers::SHIFT,
        egui::Key::Z,
    );
    h.step();
    h.step();
    assert_eq!(obj_field(&h), cube, "after redo");
}

/// A scene using the 871k-triangle scanned dragon, written to a temporary folder.
fn dragon_scene() -> PathBuf {
    let dragon = common::meshes_dir().join("dragon_vrip.obj");
    assert!(dragon.is_file(), "{} is missing", dragon.display());
    let path = temp_dir("dragon").join("dragon.txt");
    let text = SPHERE_SCENE
        .replace(
            "Sphere { center 0 0 0 radius 1 }",
            &format!("TriangleMesh {{ obj_file {} }}", dragon.display()),
        )
        .replace("OP", "UniformScale 8");
    std::fs::write(&path, text).expect("write");
    path
}

#[test]
#[ignore = "needs the scanned meshes: TRACELAB_MESHES_DIR, default ../shared/meshes"]
fn opening_a_large_mesh_keeps_the_window_painting_shows_progress_and_can_be_cancelled() {
    let dragon = dragon_scene();
    let mut h = harness(None, (32, 32));
    settle(&mut h);
    let before = h.state().doc().scene.clone();
    let t = Instant::now();
    h.state_mut().open(&dragon);
    assert!(
        t.elapsed() < Duration::from_millis(300),
        "open() blocked for {:?}",
        t.elapsed()
    );
    assert_eq!(
        h.state().doc().path,
        None,
        "the old scene stays open while the new one loads"
    );
    h.step();
    let _ = h.get_by_label_contains("Opening dragon.txt");
    h.get_by_label("Cancel").click();
    h.step();
    // Long enough for the load to have finished had it gone on; nothing may arrive.
    let start = Instant::now();
    while start.elapsed() < Duration::from_secs(4) {
        h.step();
        std::thread::sleep(Duration::from_millis(20));
    }
    // Not assert_eq: the Debug of an 871k-triangle scene is hundreds of MB.
    assert!(
        h.state().doc().scene == before,
        "a cancelled load replaced the scene"
    );
    assert!(h.query_by_label_contains("Opening dragon.txt").is_none());
    // Opened for real: frames keep coming while it loads.
    h.state_mut().open(&dragon);
    let mut slowest = Duration::ZERO;
    let start = Instant::now();
    while h.state().doc().path.as_deref() != Some(dragon.as_path()) {
        let f = Instant::now();
        h.step();
        slowest = slowest.max(f.elapsed());
        assert!(start.elapsed() < Duration::from_secs(60), "never loaded");
        std::thread::sleep(Duration::from_millis(5));
    }
    assert!(
        slowest < Duration::from_millis(300),
        "a frame took {slowest:?} while loading"
    );
    assert_eq!(h.state().doc().scene.graph.stats().triangles, 871_414);
}

#[test]
#[ignore = "needs the scanned meshes: TRACELAB_MESHES_DIR, default ../shared/meshes"]
fn a_large_scene_given_at_start_does_not_hold_up_the_first_frame() {
    let dragon = dragon_scene();
    // What eframe does with `tracelab dragon.txt`: make the app, then paint frames.
    let t = Instant::now();
    let mut app = TracelabApp::new(
        None,
        AppOptions {
            scene: Some(dragon.clone()),
            fixed_size: Some((32, 32)),
            ..AppOptions::default()
        },
    );
    assert!(
        t.elapsed() < Duration::from_millis(300),
        "making the app took {:?}",
        t.elapsed()
    );
    let ctx = egui::Context::default();
    let mut frames_before = 0;
    let mut slowest = Duration::ZERO;
    while app.doc().path.as_deref() != Some(dragon.as_path()) {
        let f = Instant::now();
        let mut out = ctx.run_ui(egui::RawInput::default(), |ui| app.frame(ui));
        // No GPU here: the textures have nowhere to go.
        out.textures_delta.clear();
        slowest = slowest.max(f.elapsed());
        frames_before += 1;
        assert!(t.elapsed() < Duration::from_secs(60), "never loaded");
        std::thread::sleep(Duration::from_millis(10));
    }
    assert!(
        frames_before > 5,
        "only {frames_before} frames before the scene was there"
    );
    assert!(
        slowest < Duration::from_millis(300),
        "a frame took {slowest:?}"
    );
}

#[test]
fn a_file_that_fails_to_parse_over_unsaved_changes_is_reported_without_asking() {
    let mut h = harness(None, (16, 16));
    settle(&mut h);
    h.state_mut()
        .apply(tracelab::document::edit::Edit::AddMaterial(
            tracelab_core::Material::diffuse(Vec3::ONE),
        ));
    let edited = h.state().doc().scene.clone();
    let bad = temp_dir("bad-dirty").join("broken.txt");
    std::fs::write(
        &bad,
        "OrthographicCamera {\n    center 0 0 10\n    direction 0 0 oops\n}\n",
    )
    .expect("write");
    h.state_mut().open(&bad);
    step_until(&mut h, 10, "an answer", |a| {
        a.confirm().is_some()
            || a.doc()
                .messages
                .iter()
                .any(|m| m.text.contains("broken.txt:3:"))
    });
    assert_eq!(
        h.state().confirm(),
        None,
        "asked about unsaved changes with nothing to switch to"
    );
    assert_eq!(h.state().doc().scene, edited);
    assert!(h.state().doc().is_dirty());
}

fn focus_text_and_type(h: &mut Harness<'static, TracelabApp>, text: &str) {
    h.get_by_role(egui::accesskit::Role::TextInput).focus();
    h.step();
    h.get_by_role(egui::accesskit::Role::TextInput)
        .type_text(text);
    h.step();
}

#[test]
fn enter_in_the_open_dialog_opens_the_typed_name() {
    let mut h = harness(None, (16, 16));
    settle(&mut h);
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::O);
    for _ in 0..3 {
        h.step();
    }
    let target = repo("scenes/flat_transforms.txt");
    focus_text_and_type(&mut h, &target.display().to_string());
    h.key_press(egui::Key::Enter);
    step_until(&mut h, 10, "the file to open", |a| {
        a.doc().path.as_deref() == Some(target.as_path())
    });
    assert!(h.state().dialog().is_none());
}

#[test]
fn enter_in_the_save_as_dialog_saves() {
    let mut h = harness(None, (16, 16));
    settle(&mut h);
    h.key_press_modifiers(
        egui::Modifiers::COMMAND | egui::Modifiers::SHIFT,
        egui::Key::S,
    );
    for _ in 0..3 {
        h.step();
    }
    let out = temp_dir("save-enter").join("saved.txt");
    let _ = std::fs::remove_file(&out);
    focus_text_and_type(&mut h, &out.display().to_string());
    h.key_press(egui::Key::Enter);
    for _ in 0..3 {
        h.step();
    }
    assert!(out.is_file(), "Enter did not save");
    assert!(h.state().dialog().is_none());
}

#[test]
fn the_file_dialog_lists_scene_files_and_folders_only() {
    let d = temp_dir("dialog-filter");
    std::fs::write(d.join("a.txt"), "x").expect("write");
    std::fs::write(d.join("b.obj"), "x").expect("write");
    std::fs::create_dir_all(d.join("sub")).expect("mkdir");
    let mut h = harness(None, (16, 16));
    settle(&mut h);
    h.state_mut()
        .set_dialog(Some(tracelab::gui::file_dialog::FileDialog::new(
            tracelab::gui::file_dialog::Purpose::Open,
            Some(&d.join("a.txt")),
        )));
    for _ in 0..3 {
        h.step();
    }
    let _ = h.get_by_label("a.txt");
    let _ = h.get_by_label("sub/");
    assert!(
        h.query_by_label("b.obj").is_none(),
        "the Open dialog lists a mesh file"
    );
}

#[test]
fn the_file_dialog_never_shows_the_folder_as_a_dot() {
    let mut h = harness(None, (16, 16));
    settle(&mut h);
    h.state_mut()
        .set_dialog(Some(tracelab::gui::file_dialog::FileDialog::new(
            tracelab::gui::file_dialog::Purpose::Open,
            Some(Path::new("scene.txt")),
        )));
    for _ in 0..3 {
        h.step();
    }
    assert!(h.query_by_label(".").is_none(), "the folder shows as \".\"");
    let cwd = std::env::current_dir().expect("cwd");
    let _ = h.get_by_label(&cwd.display().to_string());
}

#[test]
fn file_new_asks_about_unsaved_changes_then_starts_an_untitled_scene() {
    let mut h = harness(Some(repo("scenes/hierarchy.txt")), (16, 16));
    settle(&mut h);
    h.state_mut()
        .apply(tracelab::document::edit::Edit::AddMaterial(
            tracelab_core::Material::diffuse(Vec3::ONE),
        ));
    h.get_by_label("File").click();
    h.step();
    h.step();
    h.get_by_label_contains("New").click();
    for _ in 0..2 {
        h.step();
    }
    assert!(
        h.state().confirm().is_some(),
        "New over unsaved changes must ask"
    );
    h.get_by_label("Discard changes").click();
    for _ in 0..2 {
        h.step();
    }
    assert_eq!(h.state().doc().path, None);
    assert!(!h.state().doc().is_dirty());
    assert_eq!(
        h.state().doc().scene,
        tracelab::document::Document::builtin().scene
    );
}

#[test]
fn ctrl_q_quits_asking_first_about_unsaved_changes() {
    let mut h = harness(None, (16, 16));
    settle(&mut h);
    h.state_mut()
        .apply(tracelab::document::edit::Edit::AddMaterial(
            tracelab_core::Material::diffuse(Vec3::ONE),
        ));
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Q);
    for _ in 0..3 {
        h.step();
    }
    assert_eq!(h.state().confirm(), Some(&Pending::Close));
}

#[test]
fn a_new_sphere_inherits_the_groups_material_and_says_which() {
    let path = temp_dir("inherit").join("one.txt");
    std::fs::write(&path, SPHERE_SCENE.replace("OP", "UniformScale 1")).expect("write");
    let mut h = harness(Some(path), (16, 16));
    settle(&mut h);
    h.get_by_label("Add").click();
    h.step();
    h.step();
    h.get_by_label("Sphere").click();
    for _ in 0..3 {
        h.step();
    }
    let Some(Selection::Node(id)) = h.state().doc().selection else {
        panic!("the new sphere is selected")
    };
    let shown = h.get_by_label("material").value().unwrap_or_default();
    assert!(
        shown.contains("Material 0") && !shown.contains("default"),
        "the inspector says {shown:?}"
    );
    // What it shows is what it renders with, and what the saved file gives back.
    let eff = h.state().doc().scene.graph.effective_materials()[id.index()];
    assert_eq!(eff, Some(0));
    let out = temp_dir("inherit").join("saved.txt");
    h.state_mut().save_as(&out);
    let (back, _) = tracelab_core::load_scene(&out, &mut MeshCache::new())
        .into_result()
        .expect("reads back");
    let spheres: Vec<Option<u32>> = {
        let eff = back.graph.effective_materials();
        back.graph
            .iter()
            .filter(|(_, n)| matches!(n.kind, NodeKind::Sphere { .. }))
            .map(|(i, _)| eff[i.index()])
            .collect()
    };
    assert_eq!(spheres, [Some(0), Some(0)]);
}

#[test]
fn the_pixel_inspector_covers_neither_the_tree_nor_the_image() {
    let mut h = harness(None, (64, 48));
    settle(&mut h);
    h.state_mut().inspect(0, 32, 30);
    for _ in 0..4 {
        h.step();
    }
    let image = h.state().shown()[0].rect;
    let mut inspector = Vec::new();
    for label in [
        "Pixel (32, 30)",
        "World ray:",
        "hit point (world)",
        "colour (sum)",
    ] {
        if let Some(n) = h.query_by_label_contains(label) {
            inspector.push(n.rect());
        }
    }
    assert!(inspector.len() >= 2, "the pixel inspector shows its story");
    let mut tree = Vec::new();
    for label in [
        "Camera (perspective)",
        "Camera (orthographic)",
        "Background",
        "Lights (",
        "Materials (",
    ] {
        tree.extend(h.query_all_by_label_contains(label).map(|n| n.rect()));
    }
    assert!(!tree.is_empty());
    for r in &inspector {
        assert!(
            !r.intersects(image),
            "pixel inspector {r:?} covers the image {image:?}"
        );
        for t in &tree {
            assert!(
                !r.intersects(*t),
                "pixel inspector {r:?} covers the tree row {t:?}"
            );
        }
    }
}

/// A primary-button drag of the widget's centre by `dx` points, in small moves.
fn drag_by(h: &mut Harness<'static, TracelabApp>, label: &str, dx: f32) {
    let at = h.get_by_label(label).rect().center();
    let push = |h: &mut Harness<'static, TracelabApp>, e: egui::Event| h.input_mut().events.push(e);
    push(h, egui::Event::PointerMoved(at));
    h.step();
    push(
        h,
        egui::Event::PointerButton {
            pos: at,
            button: egui::PointerButton::Primary,
            pressed: true,
            modifiers: egui::Modifiers::NONE,
        },
    );
    h.step();
    for i in 1..=6 {
        push(
            h,
            egui::Event::PointerMoved(at + egui::vec2(dx * i as f32 / 6.0, 0.0)),
        );
        h.step();
    }
    let end = at + egui::vec2(dx, 0.0);
    push(
        h,
        egui::Event::PointerButton {
            pos: end,
            button: egui::PointerButton::Primary,
            pressed: false,
            modifiers: egui::Modifiers::NONE,
        },
    );
    h.step();
}

#[test]
fn dragging_a_translate_moves_by_a_step_scaled_to_the_scene_and_the_transform() {
    // The camera sees about 5.4 units across; the Translate is scaled by 5 (listed after it).
    let path = temp_dir("drag-speed").join("scaled.txt");
    let text = perspective_sphere_scene("UniformScale 5 Translate 0 0 0")
        .replace("radius 1", "radius 0.1");
    std::fs::write(&path, text).expect("write");
    let mut h = harness(Some(path), (16, 16));
    settle(&mut h);
    let id = h
        .state()
        .doc()
        .scene
        .graph
        .iter()
        .find(|(_, n)| matches!(n.kind, NodeKind::Transform(_)))
        .map(|(id, _)| id)
        .expect("the Transform");
    h.state_mut().doc_mut().selection = Some(Selection::Node(id));
    h.step();
    h.step();
    drag_by(&mut h, "Translate x", 60.0);
    let NodeKind::Transform(ops) = &h.state().doc().scene.graph.node(id).kind else {
        panic!()
    };
    let Some(TransformOp::Translate(t)) = ops.get(1) else {
        panic!("{ops:?}")
    };
    let world = 5.0 * t.x;
    assert!(world > 0.05, "the drag moved nothing: {world}");
    assert!(
        world < 5.4 * 0.25,
        "60 px moved the object {world} world units in a view 5.4 across"
    );
}

// ---- Issue 16: layout and small things ----

#[test]
fn a_side_panel_dragged_wide_leaves_the_render_view_usable() {
    let mut h = Harness::builder()
        .with_size(egui::vec2(1200.0, 760.0))
        .with_max_steps(10_000)
        .build_eframe(|cc| TracelabApp::new(Some(cc), AppOptions::default()));
    for _ in 0..3 {
        h.step();
    }
    let splitters: Vec<_> = h
        .query_all_by_role(egui::accesskit::Role::Splitter)
        .map(|n| n.rect().center().x)
        .collect();
    assert!(!splitters.is_empty(), "no panel resize handles found");
    // The leftmost handle is the tree panel's; ask for it at 1000 px.
    let left = h
        .query_all_by_role(egui::accesskit::Role::Splitter)
        .min_by(|a, b| a.rect().center().x.total_cmp(&b.rect().center().x))
        .expect("handle");
    left.set_value_accesskit(1000.0 / 1200.0);
    settle(&mut h);
    let width = h
        .state()
        .worker()
        .with_published(|p| p.expect("rendered").job.settings.width);
    assert!(width >= 300, "the render view is {width} px wide");
}

#[test]
fn the_fixed_render_size_refuses_nan_and_sizes_past_the_limit() {
    let mut h = harness(None, (40, 40));
    settle(&mut h);
    let type_into = |h: &mut Harness<'static, TracelabApp>, label: &str, text: &str| {
        // Focus turns a drag value into a text field.
        h.get_by_label(label).focus();
        h.step();
        h.step();
        // Gaining focus selects the old text; typing replaces it.
        h.get_by_label(label).type_text(text);
        h.step();
        h.key_press(egui::Key::Enter);
        h.step();
        h.step();
    };
    type_into(&mut h, "w", "nan");
    assert_eq!(
        h.state().view().fixed_size,
        Some((40, 40)),
        "nan was taken as a size"
    );
    type_into(&mut h, "w", "8192");
    assert_eq!(h.state().view().fixed_size, Some((8192, 40)));
    // 8192 × 16384 is more pixels than core renders (8192 × 8192).
    type_into(&mut h, "h", "16384");
    let (w, hh) = h.state().view().fixed_size.expect("fixed");
    assert!(
        tracelab_core::render::check_image_size(w, hh).is_ok(),
        "{w}×{hh} accepted"
    );
}

#[test]
fn twenty_thousand_nested_groups_make_a_short_breadcrumb() {
    let n = 20_000;
    let mut text = String::from(
        "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 2.5 }\nMaterials { numMaterials 1 Material { diffuseColor 1 1 1 } }\n",
    );
    for _ in 0..n {
        text.push_str("Group { numObjects 1 MaterialIndex 0\n");
    }
    text.push_str("Sphere { center 0 0 0 radius 1 }\n");
    for _ in 0..n {
        text.push_str("}\n");
    }
    let path = temp_dir("deep").join("deep.txt");
    std::fs::write(&path, text).expect("write");
    let mut h = harness(Some(path), (8, 8));
    settle(&mut h);
    let sphere = h
        .state()
        .doc()
        .scene
        .graph
        .iter()
        .find(|(_, n)| matches!(n.kind, NodeKind::Sphere { .. }))
        .map(|(id, _)| id)
        .expect("sphere");
    h.state_mut().doc_mut().selection = Some(Selection::Node(sphere));
    h.step();
    h.step();
    let node = h.get_by_label_contains("Group › Group");
    let crumb = node
        .accesskit_node()
        .label()
        .or_else(|| node.value())
        .unwrap_or_default();
    assert!(
        crumb.chars().count() < 200,
        "breadcrumb of {} characters",
        crumb.chars().count()
    );
    assert!(crumb.contains('…') && crumb.ends_with("Sphere"), "{crumb}");
}

#[test]
fn save_says_which_comments_it_would_drop_before_writing() {
    let d = temp_dir("lost-comments");
    let path = d.join("s.txt");
    let text = SPHERE_SCENE
        .replace("size 2.5", "size # two and a half\n 2.5")
        .replace("OP", "UniformScale 1");
    std::fs::write(&path, &text).expect("write");
    let mut h = harness(Some(path.clone()), (16, 16));
    settle(&mut h);
    h.state_mut()
        .apply(tracelab::document::edit::Edit::AddMaterial(
            tracelab_core::Material::diffuse(Vec3::ONE),
        ));
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::S);
    for _ in 0..3 {
        h.step();
    }
    assert_eq!(
        std::fs::read_to_string(&path).expect("read"),
        text,
        "saved without a word"
    );
    let _ = h.get_by_label("Saving loses something");
    assert!(
        h.query_all_by_label_contains("saving the scene drops it")
            .count()
            >= 1
    );
    h.get_by_label("Save anyway").click();
    for _ in 0..2 {
        h.step();
    }
    assert_ne!(std::fs::read_to_string(&path).expect("read"), text);
    assert!(!h.state().doc().is_dirty());
}

fn layout_harness(width: f32, memory: Option<egui::Memory>) -> Harness<'static, TracelabApp> {
    Harness::builder()
        .with_size(egui::vec2(width, 760.0))
        .with_max_steps(10_000)
        .build_eframe(move |cc| {
            if let Some(m) = memory {
                // What eframe restores from the last run, before the first frame.
                cc.egui_ctx.memory_mut(|mem| *mem = m);
            }
            TracelabApp::new(Some(cc), AppOptions::default())
        })
}

/// The x of the tree panel's resize handle (the leftmost one).
fn tree_edge(h: &Harness<'static, TracelabApp>) -> f32 {
    h.query_all_by_role(egui::accesskit::Role::Splitter)
        .map(|n| n.rect().center().x)
        .min_by(f32::total_cmp)
        .expect("a panel resize handle")
}

fn render_width(h: &Harness<'static, TracelabApp>) -> u32 {
    h.state()
        .worker()
        .with_published(|p| p.expect("rendered").job.settings.width)
}

#[test]
fn a_remembered_1000_px_panel_is_clamped_and_reset_layout_restores_the_defaults() {
    // Remembered on a wide screen, where a 1000 px tree still leaves room for the view...
    let mut wide = layout_harness(2400.0, None);
    for _ in 0..3 {
        wide.step();
    }
    let handle = wide
        .query_all_by_role(egui::accesskit::Role::Splitter)
        .min_by(|a, b| a.rect().center().x.total_cmp(&b.rect().center().x))
        .expect("handle");
    handle.set_value_accesskit(1000.0 / 2400.0);
    for _ in 0..3 {
        wide.step();
    }
    assert!(
        (tree_edge(&wide) - 1000.0).abs() < 10.0,
        "the tree is {} px wide",
        tree_edge(&wide)
    );
    let memory = wide.ctx.memory(|m| m.clone());
    // ...and started on a 1200 px one.
    let mut h = layout_harness(1200.0, Some(memory));
    settle(&mut h);
    assert!(
        render_width(&h) >= 300,
        "the render view is {} px wide",
        render_width(&h)
    );
    assert!(tree_edge(&h) < 1200.0 - 320.0);
    h.get_by_label("View").click();
    h.step();
    h.step();
    h.get_by_label("Reset layout").click();
    settle(&mut h);
    assert!(
        (tree_edge(&h) - 280.0).abs() < 10.0,
        "after Reset layout the tree is {} px wide",
        tree_edge(&h)
    );
    assert!(
        render_width(&h) > 500,
        "the view has its default room: {}",
        render_width(&h)
    );
}

// Issue 16: nothing the editor lets you do may produce a file it cannot open again. Each
// test types into the inspector as a user would, saves with Ctrl+S over a copy of the
// course's squashed-sphere scene, and opens what was saved.

/// scene2_11 (orthographic camera, one light, `Scale 1 0.2 1` around a sphere) copied to a
/// folder of its own and opened.
fn squashed_sphere(tag: &str) -> (Harness<'static, TracelabApp>, PathBuf) {
    let src = course_scene("scene2_11_squashed_sphere.txt");
    let path = temp_dir(tag).join("squashed.txt");
    std::fs::copy(&src, &path).expect("copy");
    let mut h = harness(Some(path.clone()), (16, 16));
    settle(&mut h);
    (h, path)
}

fn select_row(h: &mut Harness<'static, TracelabApp>, label: &str) {
    h.get_by_label_contains(label).click();
    h.step();
    h.step();
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

fn ctrl_s(h: &mut Harness<'static, TracelabApp>) {
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::S);
    h.step();
    h.step();
}

/// The saved file, opened again as tracelab opens files.
fn reopened(path: &Path) -> tracelab_core::Scene {
    let out = tracelab_core::load_scene(path, &mut MeshCache::new());
    out.into_result()
        .unwrap_or_else(|d| panic!("the saved file does not open:\n{d}"))
        .0
}

fn sphere_radius(scene: &tracelab_core::Scene) -> f32 {
    scene
        .graph
        .iter()
        .find_map(|(_, n)| match n.kind {
            NodeKind::Sphere { radius, .. } => Some(radius),
            _ => None,
        })
        .expect("a sphere")
}

#[test]
#[ignore = "needs the course files: TRACELAB_COURSE_DIR, default ../shared/mit6837"]
fn adding_a_triangle_mesh_then_saving_refuses_says_why_and_writes_nothing() {
    let (mut h, path) = squashed_sphere("mesh-save");
    let before = std::fs::read_to_string(&path).expect("read");
    h.get_by_label("Add").click();
    h.step();
    h.step();
    h.get_by_label("TriangleMesh").click();
    h.step();
    h.step();
    let Some(Selection::Node(mesh)) = h.state().doc().selection else {
        panic!("the new mesh is selected")
    };
    ctrl_s(&mut h);
    assert_eq!(
        std::fs::read_to_string(&path).expect("read"),
        before,
        "Save wrote a file with no obj_file"
    );
    let msg = h.state().doc().messages.joined();
    assert!(
        msg.contains("not saved")
            && msg.contains(&format!("node #{}): no OBJ file chosen yet", mesh.0)),
        "{msg}"
    );
    // The explanation is on screen, and the tree shows the node in red (its row has an error).
    let _ = h.get_by_label_contains("not saved; first fix");
    let rows = tracelab::gui::panels::tree::tree_rows(&h.state().doc().scene);
    assert!(rows.iter().any(|r| r.id == mesh && r.error.is_some()));
    assert!(h.state().doc().is_dirty(), "nothing was saved");
}

#[test]
#[ignore = "needs the course files: TRACELAB_COURSE_DIR, default ../shared/mit6837"]
fn typing_nan_or_1e39_into_a_number_field_is_refused_beside_the_field() {
    let (mut h, path) = squashed_sphere("nan");
    select_row(&mut h, "Sphere: (0, 0, 0) r 1");
    for text in ["nan", "1e39"] {
        type_into(&mut h, "radius", text);
        assert_eq!(
            sphere_radius(&h.state().doc().scene),
            1.0,
            "{text} was stored as the radius"
        );
        // Beside the field, the inspector says why.
        let _ = h.get_by_label("radius must be a finite number");
    }
    type_into(&mut h, "radius", "0.5");
    assert_eq!(
        sphere_radius(&h.state().doc().scene),
        0.5,
        "a valid value still goes in"
    );
    ctrl_s(&mut h);
    assert_eq!(sphere_radius(&reopened(&path)), 0.5);
}

#[test]
fn a_camera_angle_of_180_is_refused_beside_the_angle_not_clamped() {
    // The inspector has no limits of its own: the rules judge the angle, and say why beside it.
    let path = temp_dir("angle180").join("perspective.txt");
    let text = perspective_sphere_scene("Translate 0 0 0");
    std::fs::write(&path, text).expect("write");
    let mut h = harness(Some(path), (16, 16));
    settle(&mut h);
    select_row(&mut h, "Camera (perspective)");
    type_into(&mut h, "angle (degrees)", "180");
    let angle = |h: &Harness<'static, TracelabApp>| match h.state().doc().scene.camera {
        tracelab_core::Camera::Perspective { angle, .. } => angle,
        _ => panic!("a perspective camera"),
    };
    assert_eq!(angle(&h), 30.0, "180 was stored");
    let _ = h.get_by_label("PerspectiveCamera: angle must be between 0 and 180 degrees, found 180");
    type_into(&mut h, "angle (degrees)", "179.5");
    assert_eq!(angle(&h), 179.5, "a valid angle past the old clamp goes in");
}

#[test]
#[ignore = "needs the course files: TRACELAB_COURSE_DIR, default ../shared/mit6837"]
fn scale_y_zero_on_the_squashed_sphere_is_refused_and_ctrl_s_leaves_a_file_that_opens() {
    let (mut h, path) = squashed_sphere("scale0");
    select_row(&mut h, "Transform: Scale(1, 0.2, 1)");
    type_into(&mut h, "Scale y", "0");
    let _ = h.get_by_label("singular transform: Scale(1, 0, 1) flattens space, so rays cannot be moved into object space");
    ctrl_s(&mut h);
    let saved = reopened(&path);
    let scale = saved.graph.iter().find_map(|(_, n)| match &n.kind {
        NodeKind::Transform(ops) => ops.first().cloned(),
        _ => None,
    });
    assert_eq!(
        scale,
        Some(TransformOp::Scale(Vec3::new(1.0, 0.2, 1.0))),
        "the last valid Scale is kept"
    );
}

#[test]
#[ignore = "needs the course files: TRACELAB_COURSE_DIR, default ../shared/mit6837"]
fn an_orthographic_size_of_zero_is_refused_and_the_saved_file_opens() {
    let (mut h, path) = squashed_sphere("size0");
    select_row(&mut h, "Camera (orthographic)");
    type_into(&mut h, "size", "0");
    let _ = h.get_by_label("OrthographicCamera: size must be positive, found 0");
    ctrl_s(&mut h);
    assert!(matches!(
        reopened(&path).camera,
        tracelab_core::Camera::Orthographic { size: 2.5, .. }
    ));
}

#[test]
#[ignore = "needs the course files: TRACELAB_COURSE_DIR, default ../shared/mit6837"]
fn a_camera_direction_parallel_to_up_is_refused_and_the_saved_file_opens() {
    let (mut h, path) = squashed_sphere("parallel");
    select_row(&mut h, "Camera (orthographic)");
    // (0, 0, -1) → (0, 1, -1), fine → (0, 1, 0), along up.
    type_into(&mut h, "direction y", "1");
    type_into(&mut h, "direction z", "0");
    let _ = h.get_by_label("OrthographicCamera: up must not be zero or parallel to direction");
    assert_eq!(
        h.state().doc().scene.camera.direction(),
        Vec3::new(0.0, 1.0, -1.0),
        "the last valid direction"
    );
    ctrl_s(&mut h);
    assert_eq!(
        reopened(&path).camera.direction(),
        Vec3::new(0.0, 1.0, -1.0)
    );
}

#[test]
#[ignore = "needs the course files: TRACELAB_COURSE_DIR, default ../shared/mit6837"]
fn a_zero_light_direction_is_refused_and_the_saved_file_opens() {
    let (mut h, path) = squashed_sphere("light0");
    select_row(&mut h, "Light 0");
    for axis in ["x", "y", "z"] {
        type_into(&mut h, &format!("direction {axis}"), "0");
    }
    let _ = h.get_by_label("DirectionalLight: direction must not be zero");
    assert_eq!(
        h.state().doc().scene.lights()[0].direction(),
        Some(Vec3::new(0.0, 0.0, -1.0))
    );
    ctrl_s(&mut h);
    assert_eq!(
        reopened(&path).lights()[0].direction(),
        Some(Vec3::new(0.0, 0.0, -1.0))
    );
}

#[test]
#[ignore = "needs the course files: TRACELAB_COURSE_DIR, default ../shared/mit6837"]
fn a_tiny_uniform_scale_is_fine_and_the_saved_file_opens() {
    let (mut h, path) = squashed_sphere("tiny");
    select_row(&mut h, "Transform: Scale(1, 0.2, 1)");
    h.get_by_label("Add op").click();
    h.step();
    h.step();
    h.get_by_label("UniformScale").click();
    h.step();
    h.step();
    type_into(&mut h, "UniformScale", "0.0001");
    ctrl_s(&mut h);
    let saved = reopened(&path);
    assert!(
        saved.graph.iter().any(|(_, n)| matches!(&n.kind, NodeKind::Transform(ops) if ops.contains(&TransformOp::UniformScale(0.0001)))),
        "the saved file holds the tiny scale"
    );
}
