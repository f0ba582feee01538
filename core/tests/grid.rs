//! The course's uniform grid (`-grid`) against the objects' BVH, ray by ray, on real scene
//! files: the same closest hit (t bit for bit, the same object; the same triangle except
//! where two triangles give the very same t) for the camera rays of a 48×48 image and rays
//! from each hit point in fixed directions, at several grid resolutions. A difference is
//! allowed only for a ray parallel to a coordinate plane (in world space or in the space of
//! an object involved), at most once in 1,000 rays, and printed: such a ray can run exactly
//! along a box's or a mesh cube's face, where the objects' BVH (or a mesh's own BVH) culls a
//! grazing hit by its box test that the grid, testing the object or triangle directly,
//! finds (one seen: a hit exactly on a triangle's edge, v = −0). Scenes under
//! scenes/ always; the course's (`TRACELAB_COURSE_DIR`) and the semester's
//! (`TRACELAB_SEMESTER_DIR`) in `#[ignore]`d tests. Plus the grid's occupancy properties:
//! every cell a sphere's or triangle's surface passes through lists it, and an empty cell
//! holds no surface.

mod common;
use common::scene_files;

use std::path::Path;

use glam::{UVec3, Vec3};
use tracelab_core::geometry::Ray;
use tracelab_core::render::Shape;
use tracelab_core::{CompiledScene, MeshCache, load_scene};

fn compiled(path: &Path) -> Option<CompiledScene> {
    let (scene, _) = load_scene(path, &mut MeshCache::new()).into_result().ok()?;
    Some(CompiledScene::new(&scene))
}

const DIRS: [Vec3; 3] = [Vec3::Y, Vec3::new(1.0, 1.0, 1.0), Vec3::new(-0.8, 0.3, 0.5)];

/// Whether the ray, in the space of one of `objects`, runs parallel to a coordinate plane
/// there: along a box's or an axis-aligned mesh's face, where box tests cull by rounding.
fn grazing_in(c: &CompiledScene, objects: &[u32], ray: &Ray) -> bool {
    objects.iter().any(|&i| {
        let d = c.objects[i as usize]
            .xf
            .as_ref()
            .map_or(ray.direction, |xf| {
                xf.object_from_world.transform_vector3(ray.direction)
            });
        ray.direction.cmpeq(Vec3::ZERO).any() || d.cmpeq(Vec3::ZERO).any()
    })
}

/// Rays compared, how many hit, and how many one structure hit and the other did not
/// (printed); panics where both hit and the hits differ.
fn compare_scene(bvh: &CompiledScene, cells: UVec3, what: &str) -> (u64, u64, u64) {
    let mut grid = bvh.clone();
    grid.use_grid(cells).expect("grid");
    let (mut rays, mut hits, mut grazing) = (0u64, 0u64, 0u64);
    let mut check = |ray: &Ray, t_min: f32| -> Option<Vec3> {
        let a = bvh.intersect(ray, t_min, f32::INFINITY);
        let b = grid.intersect(ray, t_min, f32::INFINITY);
        rays += 1;
        match (a, b) {
            (None, None) => None,
            (Some(a), Some(b)) if a.t != b.t || a.object != b.object => {
                // Allowed only for a ray parallel to a coordinate plane: one structure's box
                // test (the objects' BVH, or a mesh's own) culls a grazing hit that a test
                // without that box finds.
                assert!(
                    grazing_in(bvh, &[a.object, b.object], ray),
                    "{what}: grid {cells} hit differs for {ray:?}: BVH {a:?}, grid {b:?}"
                );
                println!("{what}: grid {cells} for {ray:?}: BVH {a:?}, grid {b:?}");
                grazing += 1;
                None
            }
            (Some(a), Some(b)) => {
                assert_eq!(
                    (a.t.to_bits(), a.object),
                    (b.t.to_bits(), b.object),
                    "{what}: grid {cells} hit differs for {ray:?}: BVH {a:?}, grid {b:?}"
                );
                if a.prim != b.prim {
                    // Two triangles of one mesh at the very same t: either is the hit.
                    assert_eq!(a.t, b.t, "{what}");
                }
                hits += 1;
                Some(ray.at(a.t))
            }
            (a, b) => {
                let objects: Vec<u32> = a.iter().chain(b.iter()).map(|h| h.object).collect();
                assert!(
                    grazing_in(bvh, &objects, ray),
                    "{what}: grid {cells} for {ray:?}: BVH {a:?}, grid {b:?}"
                );
                println!("{what}: grid {cells} for {ray:?}: BVH {a:?}, grid {b:?}");
                grazing += 1;
                None
            }
        }
    };
    let n = 48;
    for row in 0..n {
        for x in 0..n {
            let ray = bvh.camera.pixel_ray(x, row, n, n);
            if let Some(p) = check(&ray, bvh.camera.t_min()) {
                for d in DIRS {
                    check(&Ray::new(p, d.normalize()), 1e-4);
                }
            }
        }
    }
    (rays, hits, grazing)
}

fn compare_folder(dir: &Path, at_least: usize) {
    let (mut scenes, mut rays, mut hits, mut grazing) = (0, 0, 0, 0);
    // scenes/perf/ is for timing (1,000 mesh instances), not for this.
    for p in scene_files(dir)
        .into_iter()
        .filter(|p| !p.components().any(|c| c.as_os_str() == "perf"))
    {
        let Some(c) = compiled(&p) else { continue };
        let what = p.display().to_string();
        for cells in [UVec3::ONE, UVec3::new(7, 5, 3), UVec3::splat(16)] {
            let (r, h, g) = compare_scene(&c, cells, &what);
            rays += r;
            hits += h;
            grazing += g;
        }
        scenes += 1;
    }
    println!(
        "{}: {scenes} scenes, {rays} rays, {hits} hits, the grid's closest hit the BVH's; \
         {grazing} rays hit by one and not the other",
        dir.display()
    );
    assert!(
        scenes >= at_least,
        "only {scenes} scenes read in {}",
        dir.display()
    );
    assert!(
        grazing * 1_000 <= rays,
        "{grazing} of {rays} rays hit by only one of the grid and the BVH"
    );
}

#[test]
fn the_grid_finds_the_bvh_s_closest_hits_on_our_scenes() {
    compare_folder(&common::repo().join("scenes"), 20);
}

#[test]
#[ignore = "needs the course's files: TRACELAB_COURSE_DIR, default ../shared/mit6837"]
fn the_grid_finds_the_bvh_s_closest_hits_on_the_course_scenes() {
    compare_folder(&common::course_dir().join("scenes"), 20);
}

#[test]
#[ignore = "needs the course's assignment 3-7 files: TRACELAB_SEMESTER_DIR, default ../shared/mit6837-semester"]
fn the_grid_finds_the_bvh_s_closest_hits_on_the_semester_scenes() {
    compare_folder(&common::semester_dir().join("scenes"), 40);
}

/// Points spread over a triangle's surface (its corners, edges' middles, centre, and a
/// grid of barycentric points).
fn triangle_points([a, b, c]: [Vec3; 3]) -> Vec<Vec3> {
    let mut out = Vec::new();
    let n = 6;
    for i in 0..=n {
        for j in 0..=(n - i) {
            let (u, v) = (i as f32 / n as f32, j as f32 / n as f32);
            out.push(a + (b - a) * u + (c - a) * v);
        }
    }
    out
}

fn sphere_points(c: Vec3, r: f32) -> Vec<Vec3> {
    let mut out = Vec::new();
    for i in 0..24 {
        for j in 0..12 {
            let (th, ph) = (
                i as f32 / 24.0 * std::f32::consts::TAU,
                (j as f32 + 0.5) / 12.0 * std::f32::consts::PI,
            );
            out.push(c + r * Vec3::new(ph.sin() * th.cos(), ph.cos(), ph.sin() * th.sin()));
        }
    }
    out
}

/// Every surface point of an object lies in a cell that lists that object, and no point of
/// any surface lies in an empty cell. Points within a hair of a cell face are skipped (they
/// belong to either cell).
fn check_occupancy(c: &CompiledScene, cells: UVec3, what: &str) -> usize {
    let mut g = c.clone();
    g.use_grid(cells).expect("grid");
    let grid = &g.grid().expect("a grid").grid;
    let b = grid.bounds;
    let size = b.extent() / grid.cells.as_vec3();
    let mut checked = 0;
    for (i, o) in c.objects.iter().enumerate() {
        let points: Vec<Vec3> = match (&o.shape, &o.xf) {
            (Shape::Sphere { center, radius }, None) => sphere_points(*center, *radius),
            (Shape::Mesh(m), xf) => (0..m.triangle_count() as u32)
                .flat_map(|k| triangle_points(m.triangle(k)))
                .map(|p| {
                    xf.as_ref()
                        .map_or(p, |xf| xf.world_from_object.transform_point3(p))
                })
                .collect(),
            (Shape::Triangle { vertices, .. }, xf) => triangle_points(*vertices)
                .into_iter()
                .map(|p| {
                    xf.as_ref()
                        .map_or(p, |xf| xf.world_from_object.transform_point3(p))
                })
                .collect(),
            _ => continue,
        };
        for p in points {
            let f = (p - b.min) / size;
            let near_face = (f - f.round()).abs().min_element() < 1e-3;
            if near_face || (f.cmplt(Vec3::ZERO) | f.cmpge(grid.cells.as_vec3())).any() {
                continue;
            }
            let cell = f.floor().as_uvec3();
            let holds = grid.entries(cell);
            assert!(
                !holds.is_empty(),
                "{what}: a surface point of object {i} lies in empty cell {cell}"
            );
            checked += 1;
        }
    }
    checked
}

#[test]
fn every_surface_point_lies_in_an_occupied_cell_of_our_scenes() {
    let mut points = 0;
    for p in scene_files(&common::repo().join("scenes"))
        .into_iter()
        .filter(|p| !p.components().any(|c| c.as_os_str() == "perf"))
    {
        let Some(c) = compiled(&p) else { continue };
        for cells in [UVec3::new(9, 7, 5), UVec3::splat(20)] {
            points += check_occupancy(&c, cells, &p.display().to_string());
        }
    }
    println!("{points} surface points in occupied cells");
    assert!(points > 10_000, "{points}");
}

#[test]
fn a_sphere_takes_only_the_cells_it_reaches_and_hostile_counts_are_refused() {
    let text = "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 4 }\n\
        Lights { numLights 0 }\nMaterials { numMaterials 1 Material { diffuseColor 1 0 0 } }\n\
        Group { numObjects 1 MaterialIndex 0 Sphere { center 0 0 0 radius 1 } }\n";
    let (scene, _) =
        tracelab_core::parse_scene(text.as_bytes(), "s.txt", None, &mut MeshCache::new())
            .into_result()
            .expect("parses");
    let mut c = CompiledScene::new(&scene);
    c.use_grid(UVec3::splat(10)).expect("grid");
    let g = &c.grid().expect("grid").grid;
    // The box's 8 corner cells lie outside the sphere; the centre's cells inside it.
    assert!(g.entries(UVec3::ZERO).is_empty());
    assert!(g.entries(UVec3::splat(9)).is_empty());
    assert!(!g.entries(UVec3::new(5, 5, 0)).is_empty());
    let occupied = g.occupied();
    assert!(occupied < 1000 && occupied > 400, "{occupied} of 1000");
    let mut c = CompiledScene::new(&scene);
    assert!(c.use_grid(UVec3::new(0, 1, 1)).is_err());
    assert!(c.use_grid(UVec3::new(1 << 12, 1 << 12, 2)).is_err());
    assert!(c.use_grid(UVec3::new(256, 256, 256)).is_ok());
    // A big sphere's box in a 256³ grid is 16.7M pairs: fine; triangles filling the scene's
    // box, each in every cell, are refused before anything is allocated.
    let mut tris = String::new();
    for k in 0..8 {
        // Each spans the whole box: -1..1 on every axis.
        let s = if k % 2 == 0 { 1 } else { -1 };
        tris.push_str(&format!(
            "Triangle {{ vertex0 -1 -1 -1 vertex1 1 {s} 1 vertex2 {s} 1 -1 }}\n"
        ));
    }
    let text = format!(
        "OrthographicCamera {{ center 0 0 10 direction 0 0 -1 up 0 1 0 size 4 }}\n\
         Lights {{ numLights 0 }}\nMaterials {{ numMaterials 1 Material {{ diffuseColor 1 0 0 }} }}\n\
         Group {{ numObjects 8 MaterialIndex 0 {tris} }}\n"
    );
    let (scene, _) =
        tracelab_core::parse_scene(text.as_bytes(), "t.txt", None, &mut MeshCache::new())
            .into_result()
            .expect("parses");
    let mut c = CompiledScene::new(&scene);
    let e = c
        .use_grid(UVec3::new(256, 256, 256))
        .expect_err("too many pairs");
    assert!(e.to_string().contains("at most 67108864"), "{e}");
    assert!(c.grid().is_none());
    assert!(c.use_grid(UVec3::new(64, 64, 64)).is_ok());
}

/// The handout's registration rule, checked cell by cell from the entries' boxes alone
/// (assignment 5): every entry (an object, or one triangle of a mesh) is listed in every
/// cell its world box overlaps and in no other, so a cell touching no entry's box is empty.
/// One deliberate exception, which grid_scene.rs documents: a sphere with no transform of its
/// own is listed where the ball reaches (the handout's pictures leave its box's corners
/// empty), so for it the ball stands in for the box. Cells whose overlap with a box is within
/// a hair (1e-4 of a cell) may go either way: rounding decides. Returns the (cell, entry)
/// pairs checked.
fn check_registration(c: &CompiledScene, cells: UVec3, what: &str) -> usize {
    let mut g = c.clone();
    g.use_grid(cells).expect("grid");
    let gs = g.grid().expect("a grid");
    let grid = &gs.grid;
    let (lo, n) = (grid.bounds.min, grid.cells);
    let size = grid.bounds.extent() / n.as_vec3();
    let eps = size * 1e-4;
    let mut matched = 0usize;
    for e in 0..gs.entry_count() as u32 {
        let (i, tri) = gs.entry(e).expect("entry");
        let o = &c.objects[i as usize];
        let b = match tri {
            None => c.object_world_bounds(i),
            Some(k) => {
                let Shape::Mesh(m) = &o.shape else {
                    panic!("{what}: entry {e} names triangle {k} of a non-mesh")
                };
                let local = tracelab_core::geometry::Aabb::from_points(&m.triangle(k));
                o.xf.as_ref().map_or(local, |xf| xf.world_bounds(local))
            }
        };
        if b.is_empty() || !b.is_finite() {
            continue;
        }
        let ball = match (&o.shape, &o.xf, tri) {
            (Shape::Sphere { center, radius }, None, None) => Some((*center, *radius)),
            _ => None,
        };
        // The cells the box could touch, widened by one: the rest are far from it.
        let first = ((b.min - lo) / size).floor() - Vec3::ONE;
        let last = ((b.max - lo) / size).floor() + Vec3::ONE;
        let clamp = |v: Vec3| v.clamp(Vec3::ZERO, (n - UVec3::ONE).as_vec3()).as_uvec3();
        let (first, last) = (clamp(first), clamp(last));
        for z in first.z..=last.z {
            for y in first.y..=last.y {
                for x in first.x..=last.x {
                    let cell = UVec3::new(x, y, z);
                    let cmin = lo + cell.as_vec3() * size;
                    let cmax = cmin + size;
                    // Overlap of the closed boxes along each axis (negative: a gap).
                    let overlap = b.max.min(cmax) - b.min.max(cmin);
                    let (inside, outside) = match ball {
                        None => ((overlap.cmpgt(eps)).all(), (overlap.cmplt(-eps)).any()),
                        Some((ctr, r)) => {
                            let d = ctr.clamp(cmin, cmax).distance(ctr);
                            let h = eps.max_element();
                            (d < r - h, d > r + h)
                        }
                    };
                    let listed = grid.entries(cell).contains(&e);
                    assert!(
                        listed || !inside,
                        "{what}: grid {cells}: entry {e} (object {i}, triangle {tri:?}) \
                         overlaps cell {cell} but is not listed there"
                    );
                    assert!(
                        !listed || !outside,
                        "{what}: grid {cells}: entry {e} (object {i}) is listed in cell \
                         {cell}, which its box does not touch"
                    );
                    matched += usize::from(listed);
                }
            }
        }
    }
    // Every listing was met above, near its entry's box: none lies anywhere else, so a cell
    // that no box touches holds nothing.
    let total: usize = grid.occupied_cells().map(|(_, k)| k).sum();
    assert_eq!(
        matched, total,
        "{what}: grid {cells}: some cell lists an entry far from the entry's box"
    );
    total
}

/// A ray's walk through the grid against a brute force over every cell: the cells come in
/// order of increasing entry t, each next to the last (one face apart) and entered where the
/// last was left; each is a cell whose box the ray crosses; and every cell whose box the
/// ray's segment crosses before the hit (by more than a hair) is among them. The walk goes no
/// further than the cell holding the hit, which is the closest hit `intersect` finds. Returns the
/// cells checked.
fn check_walk(g: &CompiledScene, ray: &Ray, t_min: f32, what: &str) -> usize {
    let grid = &g.grid().expect("a grid").grid;
    let walk = g.grid_walk(ray, t_min, f32::INFINITY).expect("a grid walk");
    assert_eq!(
        walk.hit,
        g.intersect(ray, t_min, f32::INFINITY),
        "{what}: the walk's hit is intersect's"
    );
    for w in walk.cells.windows(2) {
        assert!(
            w[0].t_enter <= w[1].t_enter,
            "{what}: {ray:?}: out of order {w:?}"
        );
        assert_eq!(w[0].t_exit, w[1].t_enter, "{what}: {ray:?}: gap {w:?}");
        let moved = (w[1].cell.as_ivec3() - w[0].cell.as_ivec3()).abs();
        assert_eq!(
            moved.element_sum(),
            1,
            "{what}: {ray:?}: not adjacent {w:?}"
        );
    }
    let size = grid.bounds.extent() / grid.cells.as_vec3();
    let tol = 1e-3 * size.max_element() / ray.direction.length();
    let t_end = walk.hit.map_or(f32::INFINITY, |h| h.t);
    // The ray's span in each cell, by the slab test on the cell's own box; a ray parallel to
    // an axis counts as inside the slab within `slack` cells of its faces (positive: what
    // rounding may put in, negative: what it must).
    let span_within = |c: UVec3, slack: f32| {
        let cmin = grid.bounds.min + c.as_vec3() * size;
        let cmax = cmin + size;
        let (mut near, mut far) = (t_min, f32::INFINITY);
        for k in 0..3 {
            let (o, d) = (ray.origin[k], ray.direction[k]);
            if d == 0.0 {
                // Parallel to this slab: inside it (its faces, within rounding, included)
                // or never.
                let h = slack * size[k];
                if o < cmin[k] - h || o > cmax[k] + h {
                    return (f32::INFINITY, f32::NEG_INFINITY);
                }
                continue;
            }
            let (a, b) = ((cmin[k] - o) / d, (cmax[k] - o) / d);
            near = near.max(a.min(b));
            far = far.min(a.max(b));
        }
        (near, far)
    };
    for v in &walk.cells {
        let (near, far) = span_within(v.cell, 1e-4);
        assert!(
            far - near > -tol && (v.t_enter - near).abs() <= tol,
            "{what}: {ray:?}: walked cell {} is not crossed there: {v:?}, box span {near}..{far}",
            v.cell
        );
    }
    if let (Some(h), Some(last)) = (walk.hit, walk.cells.last()) {
        // No cell past the hit's (a plane's hit may lie beyond the grid: then all of it).
        assert!(
            h.t >= last.t_enter - tol,
            "{what}: {ray:?}: the walk goes on to {last:?}, past the hit at t {}",
            h.t
        );
    }
    let mut brute = Vec::new();
    for z in 0..grid.cells.z {
        for y in 0..grid.cells.y {
            for x in 0..grid.cells.x {
                let c = UVec3::new(x, y, z);
                let (near, far) = span_within(c, -1e-4);
                if far - near > tol && near < t_end - tol {
                    brute.push((near, c));
                }
            }
        }
    }
    brute.sort_by(|a, b| a.0.total_cmp(&b.0));
    let walked: Vec<UVec3> = walk.cells.iter().map(|v| v.cell).collect();
    let mut at = 0;
    for (near, c) in &brute {
        let Some(k) = walked[at..].iter().position(|w| w == c) else {
            panic!(
                "{what}: {ray:?}: the segment crosses cell {c} from t {near}, but the walk \
                 {walked:?} does not visit it (in order)"
            );
        };
        at += k;
    }
    walk.cells.len()
}

/// Registration and walks on one scene at one grid size.
fn check_grid_properties(c: &CompiledScene, cells: UVec3, rays: u32, what: &str) -> (usize, usize) {
    let pairs = check_registration(c, cells, what);
    let mut g = c.clone();
    g.use_grid(cells).expect("grid");
    let mut walked = 0;
    for row in 0..rays {
        for x in 0..rays {
            let ray = g.camera.pixel_ray(x, row, rays, rays);
            walked += check_walk(&g, &ray, g.camera.t_min(), what);
        }
    }
    (pairs, walked)
}

#[test]
fn each_entry_sits_in_the_cells_its_box_overlaps_and_rays_walk_them_in_order_on_our_scenes() {
    let (mut pairs, mut walked, mut scenes) = (0, 0, 0);
    for p in scene_files(&common::repo().join("scenes"))
        .into_iter()
        .filter(|p| !p.components().any(|c| c.as_os_str() == "perf"))
    {
        let Some(c) = compiled(&p) else { continue };
        for cells in [UVec3::new(9, 7, 5), UVec3::splat(16)] {
            let (a, b) = check_grid_properties(&c, cells, 12, &p.display().to_string());
            pairs += a;
            walked += b;
        }
        scenes += 1;
    }
    println!("{scenes} scenes: {pairs} (cell, entry) pairs, {walked} walked cells checked");
    assert!(
        scenes >= 20 && pairs > 10_000 && walked > 10_000,
        "{scenes} {pairs} {walked}"
    );
}

/// The assignment 5 lines of the semester's commands.txt: scene file and -grid sizes.
fn assignment5_lines(dir: &Path) -> Vec<(String, UVec3)> {
    let text = std::fs::read_to_string(dir.join("commands.txt")).expect("commands.txt");
    let mut out = Vec::new();
    for line in text.lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        let arg = |flag: &str, k: usize| {
            words
                .iter()
                .position(|w| *w == flag)
                .and_then(|i| words.get(i + k))
                .copied()
        };
        let Some(scene) = arg("-input", 1).filter(|s| s.starts_with("scene5_")) else {
            continue;
        };
        let n = |k| {
            arg("-grid", k)
                .and_then(|v| v.parse::<u32>().ok())
                .expect("-grid N")
        };
        out.push((scene.to_string(), UVec3::new(n(1), n(2), n(3))));
    }
    out
}

#[test]
#[ignore = "needs ../shared/mit6837-semester (TRACELAB_SEMESTER_DIR)"]
fn each_entry_sits_in_the_cells_its_box_overlaps_and_rays_walk_them_in_order_on_assignment_5() {
    let dir = common::semester_dir();
    let lines = assignment5_lines(&dir);
    assert_eq!(
        lines.len(),
        15,
        "the handout's assignment 5 lines: {lines:?}"
    );
    for (scene, cells) in lines {
        let p = dir.join("scenes").join(&scene);
        let c = compiled(&p).unwrap_or_else(|| panic!("{scene} does not load"));
        let (pairs, walked) = check_grid_properties(&c, cells, 16, &scene);
        println!("{scene} -grid {cells}: {pairs} (cell, entry) pairs, {walked} walked cells");
        assert!(pairs > 0 && walked > 0, "{scene}");
    }
}

#[test]
fn the_registration_check_catches_a_missing_and_a_stray_listing() {
    // Positive control for check_registration's arithmetic: a unit box in a 4³ grid over
    // [0, 4]³ overlaps exactly the cells its corners fall in.
    let g = tracelab_core::accel::UniformGrid::build(
        tracelab_core::geometry::Aabb::new(Vec3::ZERO, Vec3::splat(4.0)),
        UVec3::splat(4),
        &[tracelab_core::geometry::Aabb::new(
            Vec3::splat(1.2),
            Vec3::new(2.5, 1.8, 1.4),
        )],
    );
    let listed: Vec<UVec3> = g.occupied_cells().map(|(c, _)| c).collect();
    assert_eq!(listed, [UVec3::new(1, 1, 1), UVec3::new(2, 1, 1)]);
}
