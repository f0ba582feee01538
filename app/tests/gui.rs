//! Logic tests of the editor window with egui_kittest: they find widgets by label, click and
//! set values as a user would, and check the document and the renderer. No GPU needed.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use glam::Vec3;
use tracelab::app::{AppOptions, Pending, TracelabApp};
use tracelab::state::Selection;
use tracelab_core::{MeshCache, NodeId, NodeKind, TransformOp, View};

mod common;
use common::skip_note;

fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(rel)
}

fn shared_scene(name: &str) -> Option<PathBuf> {
    let p = repo("../shared/mit6837/scenes").join(name);
    if p.is_file() {
        return Some(p);
    }
    assert!(
        std::env::var_os("TRACELAB_REQUIRE_SHARED").is_none(),
        "../shared/mit6837 is required here"
    );
    skip_note(&format!("SKIPPED: {} is not there (../shared absent)", p.display()));
    None
}

fn temp_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("tracelab-gui-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

fn harness(scene: Option<PathBuf>, size: (u32, u32)) -> Harness<'static, TracelabApp> {
    Harness::builder()
        .with_size(egui::vec2(1200.0, 760.0))
        .with_max_steps(10_000)
        .build_eframe(move |cc| {
            TracelabApp::new(
                Some(cc),
                AppOptions {
                    scene,
                    fixed_size: Some(size),
                },
            )
        })
}

/// Steps the UI until the renderer has finished the newest request.
fn settle(h: &mut Harness<'static, TracelabApp>) {
    let start = Instant::now();
    loop {
        h.step();
        if h.state().worker.is_idle() {
            // One more frame uploads the last pixels.
            h.step();
            return;
        }
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "render did not finish"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// The first Transform in the scene whose first op is a Translate.
fn translate_transform(app: &TracelabApp) -> (NodeId, Vec3) {
    app.doc
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
        h.state().doc.messages.iter().all(|m| m.contains("warning")),
        "{:?}",
        h.state().doc.messages
    );
    let original = h.state().doc.scene.clone();
    let (id, t) = translate_transform(h.state());

    let label = tracelab::ui::tree::node_label(&h.state().doc.scene.graph.node(id).kind, 1);
    h.get_all_by_label_contains(&label)
        .next()
        .expect("tree row")
        .click();
    h.step();
    assert_eq!(h.state().doc.selection, Some(Selection::Node(id)));

    let gen_before = h.state().doc.generation;
    let worker_before = h.state().worker.last_generation();
    let new_x = t.x + 0.75;
    h.get_by_label("Translate x")
        .set_value_accesskit(f64::from(new_x));
    h.step();
    h.step();
    let app = h.state();
    let NodeKind::Transform(ops) = &app.doc.scene.graph.node(id).kind else {
        panic!("still a Transform")
    };
    assert_eq!(ops[0], TransformOp::Translate(Vec3::new(new_x, t.y, t.z)));
    assert!(app.doc.generation > gen_before, "the document changed");
    assert!(app.doc.is_dirty());
    assert!(
        app.worker.last_generation() > worker_before,
        "the render restarted"
    );
    settle(&mut h);
    let shown = h
        .state()
        .worker
        .with_published(|p| p.map(|p| p.job.generation));
    assert_eq!(
        shown,
        Some(h.state().doc.generation),
        "the image shows the edited scene"
    );

    let out = temp_dir("save").join(scene.file_name().expect("name"));
    h.state_mut().save_as(&out);
    assert!(!h.state().doc.is_dirty());
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
        h.state().doc.scene,
        original,
        "undo restores the identical document"
    );
    let _ = std::fs::remove_file(&out);
}

#[test]
fn course_scene_edit_save_and_undo() {
    let Some(scene) = shared_scene("scene2_16_t_scale.txt") else {
        return;
    };
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
    let before = h.state().doc.scene.clone();
    let bad = temp_dir("bad").join("broken.txt");
    std::fs::write(
        &bad,
        "OrthographicCamera {\n    center 0 0 10\n    direction 0 0 oops\n}\n",
    )
    .expect("write");
    h.state_mut().open(&bad);
    h.step();
    h.step();
    assert_eq!(h.state().doc.scene, before, "the previous scene stays open");
    let msg = h.state().doc.messages.join("\n");
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

/// Normal-view bytes with the switch on Correct, then on Incorrect (clicked in the UI).
fn normals_both_ways(op: &str, tag: &str) -> (Vec<u8>, Vec<u8>) {
    let path = temp_dir(tag).join("sphere.txt");
    std::fs::write(&path, SPHERE_SCENE.replace("OP", op)).expect("write");
    let mut h = harness(Some(path), (40, 40));
    h.state_mut().view.tab = tracelab::ui::viewport::Tab::Normals;
    settle(&mut h);
    let grab = |h: &Harness<'static, TracelabApp>| {
        h.state().worker.with_published(|p| {
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
        h.state().view.normal_transform,
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
    h.state_mut().apply(tracelab::edit::Edit::SetTransformOp {
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
    assert_eq!(h.state().confirm, Some(Pending::Close));
    h.get_by_label("Cancel").click();
    h.step();
    assert_eq!(h.state().confirm, None);
    assert!(h.state().doc.is_dirty(), "cancel keeps the edits");
}

#[test]
fn clicking_a_pixel_selects_its_node_and_tells_the_ray_story() {
    let mut h = harness(None, (64, 48));
    settle(&mut h);
    // A pixel showing an object that sits under a Transform (the built-in scene has several).
    let pixel = h.state().worker.with_published(|p| {
        let p = p.expect("rendered");
        let f = p.frames[0].lock();
        let g = &h.state().doc.scene.graph;
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
    let (story, _) = app.story.as_ref().expect("a story");
    let hit = story.hit.as_ref().expect("the ray hits something");
    assert_eq!(app.doc.selection, Some(Selection::Node(hit.node)));
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
    a.view.tab = tracelab::ui::viewport::Tab::Depth;
    a.view.depth = (3.0, 12.5);
    let mut m = Mem(Default::default());
    eframe::App::save(&mut a, &mut m);
    let mut b = TracelabApp::new(None, AppOptions::default());
    b.load_persisted(&m);
    assert_eq!(b.recent, vec![repo("scenes/hierarchy.txt")]);
    assert_eq!(b.view.tab, tracelab::ui::viewport::Tab::Depth);
    assert_eq!(b.view.depth, (3.0, 12.5));
}

#[test]
fn export_all_three_writes_every_view() {
    let mut h = harness(None, (32, 24));
    h.state_mut().view.tab = tracelab::ui::viewport::Tab::All;
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
        let reloaded = h.state().doc.scene.graph.iter().any(|(_, n)| {
            matches!(&n.kind, NodeKind::Transform(ops) if ops.first() == Some(&TransformOp::UniformScale(0.5)))
        });
        if reloaded {
            break;
        }
        assert!(start.elapsed() < Duration::from_secs(5), "not reloaded");
        std::thread::sleep(Duration::from_millis(50));
    }
    assert!(!h.state().doc.is_dirty());
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
    h.step();
    assert_eq!(h.state().doc.path.as_deref(), Some(path.as_path()));
    assert_eq!(h.state().recent.first(), Some(&path));
}

#[test]
fn opening_over_unsaved_changes_asks_and_discard_opens() {
    let mut h = harness(None, (16, 16));
    settle(&mut h);
    h.state_mut().apply(tracelab::edit::Edit::AddMaterial(
        tracelab_core::Material::diffuse(Vec3::ONE),
    ));
    let target = repo("scenes/hierarchy.txt");
    h.state_mut().open(&target);
    for _ in 0..3 {
        h.step();
    }
    assert_eq!(h.state().confirm, Some(Pending::Open(target.clone())));
    assert_eq!(h.state().doc.path, None, "nothing opened before the answer");
    h.get_by_label("Discard changes").click();
    h.step();
    assert_eq!(h.state().doc.path.as_deref(), Some(target.as_path()));
    assert!(!h.state().doc.is_dirty());
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
        app.doc.path.as_deref(),
        Some(path.as_path()),
        "the scene opened"
    );
    assert!(
        app.doc.messages.iter().any(|m| m.contains("nowhere.obj")),
        "{:?}",
        app.doc.messages
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
    assert!(h.state().dialog.is_some());
    let target = repo("scenes/flat_transforms.txt");
    h.get_by_role(egui::accesskit::Role::TextInput).focus();
    h.step();
    h.get_by_role(egui::accesskit::Role::TextInput)
        .type_text(&target.display().to_string());
    h.step();
    h.get_by_label("Open").click();
    for _ in 0..2 {
        h.step();
    }
    assert!(h.state().dialog.is_none());
    assert_eq!(h.state().doc.path.as_deref(), Some(target.as_path()));
}

#[test]
fn adding_a_triangle_mesh_and_loading_its_obj() {
    let mut h = harness(Some(repo("scenes/flat_transforms.txt")), (16, 16));
    settle(&mut h);
    let before = h.state().doc.scene.graph.stats().triangles;
    h.get_by_label("Add").click();
    for _ in 0..2 {
        h.step();
    }
    h.get_by_label("TriangleMesh").click();
    for _ in 0..2 {
        h.step();
    }
    let Some(Selection::Node(id)) = h.state().doc.selection else {
        panic!("the new mesh is selected")
    };
    h.get_by_role(egui::accesskit::Role::TextInput).focus();
    h.step();
    h.get_by_role(egui::accesskit::Role::TextInput)
        .type_text("../assets/torus.obj");
    h.step();
    h.get_by_label("Load / reload").click();
    h.step();
    let NodeKind::TriangleMesh { obj_file, mesh } = &h.state().doc.scene.graph.node(id).kind else {
        panic!("a TriangleMesh")
    };
    assert_eq!(obj_file, "../assets/torus.obj");
    assert!(mesh.mesh().is_some(), "loaded: {mesh:?}");
    assert!(h.state().doc.scene.graph.stats().triangles > before);
    // Adding and loading are two undo steps; both undo cleanly.
    assert!(h.state_mut().doc.undo() && h.state_mut().doc.undo());
    assert_eq!(h.state().doc.scene.graph.stats().triangles, before);
}

#[test]
fn csg_nodes_show_in_the_tree_and_their_operation_can_be_changed_and_swapped() {
    let mut h = harness(Some(repo("scenes/lecture/csg_subtraction.txt")), (32, 32));
    settle(&mut h);
    let csg = h
        .state()
        .doc
        .scene
        .graph
        .iter()
        .find(|(_, n)| matches!(n.kind, NodeKind::Csg(_)))
        .map(|(id, _)| id)
        .expect("the scene has a CSG node");
    let before = h.state().doc.scene.graph.node(csg).children.clone();
    h.get_by_label_contains("Subtraction: A minus B").click();
    h.step();
    assert_eq!(h.state().doc.selection, Some(Selection::Node(csg)));
    let generation = h.state().doc.generation;
    h.get_by_label("Union").click();
    h.step();
    assert_eq!(h.state().doc.scene.graph.node(csg).kind, NodeKind::Csg(tracelab_core::CsgOp::Union));
    assert!(h.state().doc.generation > generation, "the edit restarts the render");
    h.get_by_label("Swap A and B").click();
    h.step();
    let after = h.state().doc.scene.graph.node(csg).children.clone();
    assert_eq!(after, [before[1], before[0]]);
    settle(&mut h);
    // Clicking the render on a CSG surface selects the operand it came from.
    let pixel = h.state().worker.with_published(|p| {
        let p = p.expect("rendered");
        let f = p.frames[0].lock();
        let s = f.get(16, 16).expect("in frame");
        s.is_hit().then_some(NodeId(s.node))
    });
    let node = pixel.expect("the centre pixel shows the union");
    assert!(
        matches!(h.state().doc.scene.graph.node(node).kind, NodeKind::Sphere { .. }),
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
        h.state().worker.with_published(|p| {
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
fn shade_back_changes_the_picture_of_an_inside_view() {
    let Some(scene) = shared_scene("scene2_05_inside_sphere.txt") else {
        return;
    };
    let mut h = harness(Some(scene), (40, 40));
    settle(&mut h);
    let before = on_screen(&h);
    h.get_by_label("shade back").click();
    h.step();
    settle(&mut h);
    assert!(h.state().view.shade_back);
    assert_ne!(before, on_screen(&h), "shade back changed nothing on screen");
}

// Issue 16: nothing the editor lets you do may produce a file it cannot open again. Each
// test types into the inspector as a user would, saves with Ctrl+S over a copy of the
// course's squashed-sphere scene, and opens what was saved.

/// scene2_11 (orthographic camera, one light, `Scale 1 0.2 1` around a sphere) copied to a
/// folder of its own and opened.
fn squashed_sphere(tag: &str) -> Option<(Harness<'static, TracelabApp>, PathBuf)> {
    let src = shared_scene("scene2_11_squashed_sphere.txt")?;
    let path = temp_dir(tag).join("squashed.txt");
    std::fs::copy(&src, &path).expect("copy");
    let mut h = harness(Some(path.clone()), (16, 16));
    settle(&mut h);
    Some((h, path))
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
    out.into_result().unwrap_or_else(|d| panic!("the saved file does not open:\n{d}")).0
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
fn adding_a_triangle_mesh_then_saving_refuses_says_why_and_writes_nothing() {
    let Some((mut h, path)) = squashed_sphere("mesh-save") else { return };
    let before = std::fs::read_to_string(&path).expect("read");
    h.get_by_label("Add").click();
    h.step();
    h.step();
    h.get_by_label("TriangleMesh").click();
    h.step();
    h.step();
    let Some(Selection::Node(mesh)) = h.state().doc.selection else { panic!("the new mesh is selected") };
    ctrl_s(&mut h);
    assert_eq!(std::fs::read_to_string(&path).expect("read"), before, "Save wrote a file with no obj_file");
    let msg = h.state().doc.messages.join("\n");
    assert!(msg.contains("not saved") && msg.contains(&format!("node #{}): no OBJ file chosen yet", mesh.0)), "{msg}");
    // The explanation is on screen, and the tree shows the node in red (its row has an error).
    let _ = h.get_by_label_contains("not saved; first fix");
    let rows = tracelab::ui::tree::tree_rows(&h.state().doc.scene);
    assert!(rows.iter().any(|r| r.id == mesh && r.error.is_some()));
    assert!(h.state().doc.is_dirty(), "nothing was saved");
}

#[test]
fn typing_nan_or_1e39_into_a_number_field_is_refused_beside_the_field() {
    let Some((mut h, path)) = squashed_sphere("nan") else { return };
    select_row(&mut h, "Sphere: (0, 0, 0) r 1");
    for text in ["nan", "1e39"] {
        type_into(&mut h, "radius", text);
        assert_eq!(sphere_radius(&h.state().doc.scene), 1.0, "{text} was stored as the radius");
        // Beside the field, the inspector says why.
        let _ = h.get_by_label("radius must be a finite number");
    }
    type_into(&mut h, "radius", "0.5");
    assert_eq!(sphere_radius(&h.state().doc.scene), 0.5, "a valid value still goes in");
    ctrl_s(&mut h);
    assert_eq!(sphere_radius(&reopened(&path)), 0.5);
}

#[test]
fn scale_y_zero_on_the_squashed_sphere_is_refused_and_ctrl_s_leaves_a_file_that_opens() {
    let Some((mut h, path)) = squashed_sphere("scale0") else { return };
    select_row(&mut h, "Transform: Scale(1, 0.2, 1)");
    type_into(&mut h, "Scale y", "0");
    let _ = h.get_by_label("singular transform: Scale(1, 0, 1) flattens space, so rays cannot be moved into object space");
    ctrl_s(&mut h);
    let saved = reopened(&path);
    let scale = saved.graph.iter().find_map(|(_, n)| match &n.kind {
        NodeKind::Transform(ops) => ops.first().cloned(),
        _ => None,
    });
    assert_eq!(scale, Some(TransformOp::Scale(Vec3::new(1.0, 0.2, 1.0))), "the last valid Scale is kept");
}

#[test]
fn an_orthographic_size_of_zero_is_refused_and_the_saved_file_opens() {
    let Some((mut h, path)) = squashed_sphere("size0") else { return };
    select_row(&mut h, "Camera (orthographic)");
    type_into(&mut h, "size", "0");
    let _ = h.get_by_label("OrthographicCamera: size must be positive, found 0");
    ctrl_s(&mut h);
    assert!(matches!(reopened(&path).camera, tracelab_core::Camera::Orthographic { size: 2.5, .. }));
}

#[test]
fn a_camera_direction_parallel_to_up_is_refused_and_the_saved_file_opens() {
    let Some((mut h, path)) = squashed_sphere("parallel") else { return };
    select_row(&mut h, "Camera (orthographic)");
    // (0, 0, -1) → (0, 1, -1), fine → (0, 1, 0), along up.
    type_into(&mut h, "direction y", "1");
    type_into(&mut h, "direction z", "0");
    let _ = h.get_by_label("OrthographicCamera: up must not be zero or parallel to direction");
    assert_eq!(h.state().doc.scene.camera.direction(), Vec3::new(0.0, 1.0, -1.0), "the last valid direction");
    ctrl_s(&mut h);
    assert_eq!(reopened(&path).camera.direction(), Vec3::new(0.0, 1.0, -1.0));
}

#[test]
fn a_zero_light_direction_is_refused_and_the_saved_file_opens() {
    let Some((mut h, path)) = squashed_sphere("light0") else { return };
    select_row(&mut h, "Light 0");
    for axis in ["x", "y", "z"] {
        type_into(&mut h, &format!("direction {axis}"), "0");
    }
    let _ = h.get_by_label("DirectionalLight: direction must not be zero");
    assert_eq!(h.state().doc.scene.lights()[0].direction, Vec3::new(0.0, 0.0, -1.0));
    ctrl_s(&mut h);
    assert_eq!(reopened(&path).lights()[0].direction, Vec3::new(0.0, 0.0, -1.0));
}

#[test]
fn a_tiny_uniform_scale_is_fine_and_the_saved_file_opens() {
    let Some((mut h, path)) = squashed_sphere("tiny") else { return };
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
