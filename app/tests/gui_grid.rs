//! View › Uniform grid in the editor (issue 31, assignment 5), with egui_kittest: turning the
//! grid on through the menu renders the same picture (the grid finds the BVH's hits), its
//! "Show the occupied cells" shows the library's `-visualize_grid` image, and a picked
//! pixel's Ray panel lists and draws the cells its eye ray walks, which are checked against
//! a brute force over every cell of an independently built grid. Each check has a positive
//! control: the picture before the change, the pick without a grid.

mod common;
use common::settle;
use std::path::PathBuf;

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use glam::{UVec3, Vec3};
use tracelab::gui::TracelabApp;
use tracelab::gui::command::AppCommand;
use tracelab::gui::grid_view::{GridSettings, box_path};
use tracelab::gui::ray_diagram::{Role, Shape};
use tracelab_core::{CompiledScene, MeshCache, RenderSettings, View};

const SIZE: (u32, u32) = (160, 160);

fn scene_path() -> PathBuf {
    common::repo().join("scenes/perspective_mesh.txt")
}

fn harness() -> Harness<'static, TracelabApp> {
    harness_on(scene_path())
}

fn harness_on(scene: PathBuf) -> Harness<'static, TracelabApp> {
    common::settled_harness(Some(scene), SIZE)
}

/// The scene compiled by the library, with a grid of `cells` when given.
fn library(cells: Option<UVec3>) -> CompiledScene {
    library_of(&scene_path(), cells)
}

fn library_of(path: &std::path::Path, cells: Option<UVec3>) -> CompiledScene {
    let (scene, _) = tracelab_core::load_scene(path, &mut MeshCache::new())
        .into_result()
        .expect("loads");
    let mut c = CompiledScene::new(&scene);
    if let Some(n) = cells {
        c.use_grid(n).expect("grid");
    }
    c
}

fn shown(h: &Harness<'static, TracelabApp>) -> Vec<u8> {
    h.state().shown()[0].rgb8()
}

/// View › Uniform grid (assignments 5–6) › the checkbox `label`, clicked as a user would
/// (the submenu stays open after a click on a setting, so it is opened only when closed).
fn click_in_grid_menu(h: &mut Harness<'static, TracelabApp>, label: &str) {
    const SUBMENU: &str = "Uniform grid (assignments 5–6)";
    if h.query_by_label(label).is_none() {
        if h.query_by_label(SUBMENU).is_none() {
            h.get_by_label("View").click();
            h.step();
            h.step();
        }
        h.get_by_label(SUBMENU).click();
        h.step();
        h.step();
    }
    h.get_by_label(label).click();
    h.step();
    h.step();
    settle(h);
}

#[test]
fn the_grid_menu_renders_through_the_grid_and_shows_the_visualize_grid_picture() {
    let mut h = harness();
    let (w, hgt) = SIZE;
    let bvh = tracelab_core::render_frame(&library(None), &RenderSettings::new(w, hgt))
        .rgb8(View::Color, (0.0, 1.0));
    let before = shown(&h);
    assert_eq!(before, bvh, "the editor's picture is the library's render");

    click_in_grid_menu(&mut h, "Render through a uniform grid (-grid)");
    assert_eq!(
        h.state().grid().request().map(|g| g.cells),
        Some([10, 10, 10])
    );
    let p = h.state().worker().with_published(|p| {
        p.map(|p| {
            (
                p.compiled.grid().map(|g| g.grid.cells),
                p.grid_error.clone(),
            )
        })
    });
    assert_eq!(
        p,
        Some((Some(UVec3::splat(10)), None)),
        "the render on screen went through the grid"
    );
    assert_eq!(
        shown(&h),
        bvh,
        "the grid finds the BVH's hits: the same picture"
    );

    click_in_grid_menu(&mut h, "Show the occupied cells (-visualize_grid)");
    let visualized =
        tracelab_core::render::visualize_grid(&library(Some(UVec3::splat(10))), w, hgt)
            .rgb8(View::Color, (0.0, 1.0));
    let after = shown(&h);
    assert_ne!(
        after, before,
        "View › Uniform grid › Show the occupied cells changed nothing"
    );
    assert_eq!(after, visualized, "the view shows -visualize_grid's image");

    // Off again: the render comes back.
    click_in_grid_menu(&mut h, "Render through a uniform grid (-grid)");
    assert_eq!(h.state().grid().request(), None);
    assert_eq!(shown(&h), bvh);
}

/// Eight triangles each spanning the whole scene box: in 256³ cells they would be listed
/// 134 million times, past the core's cap (`MAX_ENTRIES`), so the grid is refused.
fn big_triangles(tag: &str) -> PathBuf {
    let mut tris = String::new();
    for k in 0..8 {
        let s = if k % 2 == 0 { 1 } else { -1 };
        tris.push_str(&format!(
            "Triangle {{ vertex0 -1 -1 -1 vertex1 1 {s} 1 vertex2 {s} 1 -1 }}\n"
        ));
    }
    let text = format!(
        "OrthographicCamera {{ center 0 0 10 direction 0 0 -1 up 0 1 0 size 4 }}\n\
         Lights {{ numLights 1 DirectionalLight {{ direction 0 0 -1 color 1 1 1 }} }}\n\
         Materials {{ numMaterials 1 Material {{ diffuseColor 1 0 0 }} }}\n\
         Group {{ numObjects 8 MaterialIndex 0 {tris} }}\n"
    );
    // A folder per test: temp_dir empties it, and tests run side by side.
    let p = common::temp_dir("grid", tag).join("big_triangles.txt");
    std::fs::write(&p, text).expect("write scene");
    p
}

#[test]
fn a_grid_the_core_refuses_is_said_and_the_view_renders_through_the_bvh() {
    let path = big_triangles("refused");
    let mut h = harness_on(path.clone());
    let before = shown(&h);
    let set = |h: &mut Harness<'static, TracelabApp>, n: u32| {
        h.state_mut()
            .queue(tracelab::gui::command::AppCommand::SetGrid(GridSettings {
                on: true,
                cells: [n; 3],
                visualize: true,
            }));
        settle(h);
    };
    let error = |h: &Harness<'static, TracelabApp>| {
        h.state()
            .worker()
            .with_published(|p| p.and_then(|p| p.grid_error.clone()))
    };
    // Positive control: 16³ is built and its cells are on show.
    assert!(library_of(&path, None).use_grid(UVec3::splat(16)).is_ok());
    set(&mut h, 16);
    assert_eq!(error(&h), None);
    assert_ne!(shown(&h), before, "a 16³ grid's cells are on show");
    assert!(h.query_by_label_contains("View › Uniform grid:").is_none());

    assert!(library_of(&path, None).use_grid(UVec3::splat(256)).is_err());
    set(&mut h, 256);
    let e = error(&h).expect("the refusal is kept with the render");
    assert!(e.contains("at most 67108864"), "{e}");
    assert_eq!(
        shown(&h),
        before,
        "a refused grid: the BVH's picture, said beside it"
    );
    let said = h.get_by_label_contains("View › Uniform grid:");
    assert!(
        format!("{said:?}").contains("renders through the BVH"),
        "{said:?}"
    );
}

/// The cells whose boxes the ray `o + t d`, t in (t_min, t_end), crosses by more than `tol`
/// (in t), in order of entry, by the slab test on every cell of `grid`'s box: the brute force
/// the walk must agree with. Also each cell's span, for the walk's cells.
fn brute_force(
    bounds: (Vec3, Vec3),
    n: UVec3,
    o: Vec3,
    d: Vec3,
    t_min: f32,
    t_end: f32,
) -> (Vec<UVec3>, impl Fn(UVec3) -> (f32, f32)) {
    let size = (bounds.1 - bounds.0) / n.as_vec3();
    let span = move |c: UVec3| {
        let lo = bounds.0 + c.as_vec3() * size;
        let hi = lo + size;
        let (mut near, mut far) = (t_min, f32::INFINITY);
        for k in 0..3 {
            if d[k] == 0.0 {
                if o[k] <= lo[k] || o[k] >= hi[k] {
                    return (f32::INFINITY, f32::NEG_INFINITY);
                }
                continue;
            }
            let (a, b) = ((lo[k] - o[k]) / d[k], (hi[k] - o[k]) / d[k]);
            near = near.max(a.min(b));
            far = far.min(a.max(b));
        }
        (near, far)
    };
    let tol = 1e-4;
    let mut crossed = Vec::new();
    for z in 0..n.z {
        for y in 0..n.y {
            for x in 0..n.x {
                let c = UVec3::new(x, y, z);
                let (near, far) = span(c);
                if far - near > tol && near < t_end - tol {
                    crossed.push((near, c));
                }
            }
        }
    }
    crossed.sort_by(|a, b| a.0.total_cmp(&b.0));
    (crossed.into_iter().map(|(_, c)| c).collect(), span)
}

#[test]
fn the_ray_panel_lists_and_draws_the_cells_the_picked_ray_walks() {
    let mut h = harness();
    let (x, row) = (80, 100);
    // Positive control: without a grid, a pick has no walk.
    h.state_mut().inspect(0, x, row);
    settle(&mut h);
    assert!(h.state().story().is_some());
    assert_eq!(h.state().grid_pick(), None);

    let cells = [7u32, 5, 6];
    h.state_mut()
        .queue(tracelab::gui::command::AppCommand::SetGrid(GridSettings {
            on: true,
            cells,
            visualize: false,
        }));
    settle(&mut h);
    h.state_mut().inspect(0, x, row);
    h.state_mut().queue(AppCommand::ShowRayPanel(true));
    settle(&mut h);
    let pick = h
        .state()
        .grid_pick()
        .cloned()
        .expect("a walk through the grid");

    // Independently: the grid's box from the library's grid, the ray from the camera, the
    // hit from the BVH (no grid), and every cell tried.
    let bvh = library(None);
    let grid = library(Some(UVec3::from_array(cells)));
    let g = &grid.grid().expect("grid").grid;
    let ray = bvh.camera.pixel_ray(x, row, SIZE.0, SIZE.1);
    let hit = bvh
        .intersect(&ray, bvh.camera.t_min(), f32::INFINITY)
        .expect("the pixel shows an object");
    let (crossed, span) = brute_force(
        (g.bounds.min, g.bounds.max),
        g.cells,
        ray.origin,
        ray.direction,
        bvh.camera.t_min(),
        hit.t,
    );
    let walked: Vec<UVec3> = pick.walk.iter().map(|v| v.cell).collect();
    assert!(crossed.len() >= 3, "a walk worth checking: {crossed:?}");
    assert_eq!(
        walked, crossed,
        "the walk is the brute force's cells, in order"
    );
    for v in &pick.walk {
        let (near, far) = span(v.cell);
        assert!((v.t_enter - near).abs() < 1e-3, "{v:?}: enters at {near}");
        assert!(far >= near);
    }
    assert!(
        pick.hit
            && pick
                .walk
                .last()
                .is_some_and(|v| v.t_enter <= hit.t && hit.t <= v.t_exit)
    );

    // Drawn: one orange box per walked cell, in order, numbered; and the occupied cells.
    let drawn: Vec<&Vec<Vec3>> = pick
        .items
        .iter()
        .filter(|i| i.role == Role::GridWalk)
        .map(|i| match &i.shape {
            Shape::Line(ps) => ps,
            s => panic!("a walked cell drawn as {s:?}"),
        })
        .collect();
    let expected: Vec<Vec<Vec3>> = walked.iter().map(|c| box_path(&g.cell_box(*c))).collect();
    assert_eq!(drawn.len(), expected.len());
    for (a, b) in drawn.iter().zip(&expected) {
        assert_eq!(*a, b);
    }
    let occupied = pick
        .items
        .iter()
        .filter(|i| i.role == Role::GridCell)
        .count();
    assert_eq!(occupied, g.occupied());
    // The panel says it, cell by cell.
    let list: Vec<String> = walked
        .iter()
        .map(|c| format!("({},{},{})", c.x, c.y, c.z))
        .collect();
    let text = format!("The ray walks {} cells", walked.len());
    let label = h.get_by_label_contains(&text);
    let shown = format!("{label:?}");
    assert!(shown.contains(&list.join(" ")), "{shown}");
}

#[test]
fn a_ray_that_walks_the_grid_and_hits_nothing_still_has_its_walk_drawn() {
    let path = big_triangles("miss");
    let mut h = harness_on(path.clone());
    h.state_mut()
        .queue(tracelab::gui::command::AppCommand::SetGrid(GridSettings {
            on: true,
            cells: [6, 6, 6],
            visualize: false,
        }));
    settle(&mut h);
    // A pixel whose ray crosses the grid's box between the triangles, by the library.
    let lib = library_of(&path, Some(UVec3::splat(6)));
    let t_min = lib.camera.t_min();
    let (x, row, cells) = (0..SIZE.1)
        .flat_map(|r| (0..SIZE.0).map(move |x| (x, r)))
        .find_map(|(x, r)| {
            let ray = lib.camera.pixel_ray(x, r, SIZE.0, SIZE.1);
            let w = lib.grid_walk(&ray, t_min, f32::INFINITY)?;
            (w.hit.is_none() && w.cells.len() >= 2).then_some((x, r, w.cells))
        })
        .expect("a ray through the grid that misses every triangle");
    h.state_mut().inspect(0, x, row);
    h.state_mut().queue(AppCommand::ShowRayPanel(true));
    settle(&mut h);
    let story = h.state().story().map(|(s, _)| s.hit.is_some());
    assert_eq!(
        story,
        Some(false),
        "pixel ({x}, {row}): {:?}",
        h.state().grid_pick()
    );
    let pick = h.state().grid_pick().cloned().expect("a walk");
    assert!(!pick.hit);
    assert_eq!(pick.walk, cells);
    let said = h.get_by_label_contains("hits nothing in the grid");
    assert!(format!("{said:?}").contains(&format!("walks {} cells", cells.len())));
    assert!(
        h.query_by_label("The ray misses every object: nothing to draw.")
            .is_none(),
        "the walk is drawn instead"
    );
    assert!(h.query_by_label("World space").is_some());
}
