//! `CompiledScene::occluded` against `intersect(..).is_some()`, ray by ray, on real scene
//! files: every scene under scenes/, and (tests `#[ignore]`d for needing them) the course's
//! scenes of `TRACELAB_COURSE_DIR` and those of `TRACELAB_SEMESTER_DIR` that tracelab
//! reads. Camera rays of a 64×64 image, then from each hit point rays toward the lights, a
//! few fixed directions and back to the eye, each asked about ranges cut at its closest hit
//! (t_max exclusive, so that hit's t, one ulp either side). Plus the benchmark (`bench`).

mod common;
use common::scene_files;

use std::path::Path;
use std::time::Instant;

use glam::Vec3;
use tracelab_core::geometry::Ray;
use tracelab_core::{CompiledScene, MeshCache, load_scene};

/// The scene compiled, or why tracelab's reader refused it.
fn compiled(path: &Path) -> Result<CompiledScene, String> {
    let (scene, _warnings) = load_scene(path, &mut MeshCache::new())
        .into_result()
        .map_err(|d| d.to_string())?;
    Ok(CompiledScene::new(&scene))
}

/// Directions every hit point sends a ray along, besides the lights and the way back.
const FIXED: [Vec3; 4] = [
    Vec3::Y,
    Vec3::new(1.0, 1.0, 1.0),
    Vec3::new(-0.8, 0.3, 0.5),
    Vec3::new(0.05, -1.0, -0.2),
];

/// Rays compared, queries compared (a ray over one t range), and how many of those were
/// occluded.
#[derive(Clone, Copy, Debug, Default)]
struct Count {
    rays: u64,
    compared: u64,
    occluded: u64,
}

impl Count {
    fn add(&mut self, o: Count) {
        self.rays += o.rays;
        self.compared += o.compared;
        self.occluded += o.occluded;
    }
}

impl std::fmt::Display for Count {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} rays, {} queries compared, {} occluded",
            self.rays, self.compared, self.occluded
        )
    }
}

/// One ray over the ranges a shadow query asks about, from `t_min`: unbounded, a few fixed
/// ends, and where it hits, cut at that hit and one ulp either side.
fn compare_ray(c: &CompiledScene, ray: &Ray, t_min: f32, what: &str, n: &mut Count) {
    n.rays += 1;
    let first = c.intersect(ray, t_min, f32::INFINITY).map(|h| h.t);
    let mut ends = vec![f32::INFINITY, 0.5, 3.0, 40.0];
    if let Some(t) = first {
        ends.extend([t, t.next_down(), t.next_up()]);
    }
    for t_max in ends {
        let want = c.intersect(ray, t_min, t_max).is_some();
        let got = c.occluded(ray, t_min, t_max);
        assert_eq!(
            got, want,
            "{what}: ray {ray:?}, t in ({t_min}, {t_max}), closest hit {first:?}"
        );
        n.compared += 1;
        n.occluded += got as u64;
    }
}

/// Camera rays of a 64×64 image and the secondary rays from their hits.
fn compare_scene(c: &CompiledScene, name: &str) -> Count {
    let (w, h) = (64, 64);
    let rays = c.camera.pixel_rays(w, h);
    let t_min = c.camera.t_min();
    let mut n = Count::default();
    for row in 0..h {
        for x in 0..w {
            let ray = rays.row(row).ray(x);
            let what = format!("{name} pixel ({x}, {row})");
            compare_ray(c, &ray, t_min, &what, &mut n);
            let Some(hit) = c.intersect(&ray, t_min, f32::INFINITY) else {
                continue;
            };
            let p = ray.at(hit.t);
            let toward = c.lights.iter().map(|l| l.0).chain(FIXED);
            for (k, d) in toward.enumerate() {
                compare_ray(c, &Ray::new(p, d), 1e-4, &format!("{what} dir {k}"), &mut n);
            }
            // Back to the eye: the camera ray reversed, whose hit distance is known.
            let back = Ray::new(p, -ray.direction);
            compare_ray(c, &back, 1e-4, &format!("{what} back"), &mut n);
            for t_max in [hit.t, hit.t.next_down(), hit.t.next_up()] {
                let want = c.intersect(&back, 1e-4, t_max).is_some();
                assert_eq!(
                    c.occluded(&back, 1e-4, t_max),
                    want,
                    "{what} back, t_max {t_max}"
                );
                n.compared += 1;
            }
        }
    }
    n
}

/// Every scene under `dir` that loads compared; panics on a mismatch. Returns the rays
/// compared, the scenes compared, and the files skipped with their first error line.
fn compare_all(dir: &Path) -> (Count, usize, Vec<String>) {
    let mut total = Count::default();
    let mut loaded = 0;
    let mut skipped = Vec::new();
    for path in scene_files(dir) {
        let name = path
            .strip_prefix(dir)
            .unwrap_or(&path)
            .display()
            .to_string();
        let c = match compiled(&path) {
            Ok(c) => c,
            Err(e) => {
                skipped.push(format!("{name}: {}", e.lines().next().unwrap_or("")));
                continue;
            }
        };
        let n = compare_scene(&c, &name);
        println!("{name}: {n}");
        total.add(n);
        loaded += 1;
    }
    (total, loaded, skipped)
}

#[test]
fn occluded_is_intersect_is_some_on_our_scenes() {
    let (n, loaded, skipped) = compare_all(&common::repo().join("scenes"));
    assert!(skipped.is_empty(), "our scenes must load: {skipped:#?}");
    println!("scenes/: {loaded} scenes, {n}");
    assert!(loaded >= 20, "{loaded} scenes");
    assert!(
        n.occluded > n.compared / 10 && n.occluded < n.compared,
        "{n}"
    );
}

#[test]
#[ignore = "needs ../shared/mit6837 (TRACELAB_COURSE_DIR)"]
fn occluded_is_intersect_is_some_on_the_course_scenes() {
    let (mut n, loaded, skipped) = compare_all(&common::course_dir().join("scenes"));
    assert!(
        skipped.is_empty(),
        "the course's scenes must load: {skipped:#?}"
    );
    println!("course: {loaded} scenes, {n}");
    let (m, loaded, skipped) = compare_all(&common::semester_dir().join("scenes"));
    println!(
        "semester: {loaded} scenes, {m}; {} skipped (not read by tracelab):\n  {}",
        skipped.len(),
        skipped.join("\n  ")
    );
    assert!(loaded >= 20, "only {loaded} semester scenes load");
    n.add(m);
    println!("course and semester: {n}");
}

/// Shadow-like rays: from each hit point of a 1024×1024 camera image toward each light and
/// the fixed directions, until about a million (t_min 1e-4, t_max unbounded).
fn shadow_rays(c: &CompiledScene, want: usize) -> Vec<Ray> {
    let (w, h) = (1024, 1024);
    let rays = c.camera.pixel_rays(w, h);
    let mut points = Vec::new();
    for row in 0..h {
        for x in 0..w {
            let ray = rays.row(row).ray(x);
            if let Some(hit) = c.intersect(&ray, c.camera.t_min(), f32::INFINITY) {
                points.push(ray.at(hit.t));
            }
        }
    }
    let dirs: Vec<Vec3> = c.lights.iter().map(|l| l.0).chain(FIXED).collect();
    let mut out = Vec::with_capacity(want);
    'fill: for d in dirs.iter().cycle().take(64) {
        for &p in &points {
            if out.len() == want {
                break 'fill;
            }
            out.push(Ray::new(p, *d));
        }
    }
    out
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Times one query over all rays, 5 times: the median in seconds and its count of trues.
fn time(rays: &[Ray], query: impl Fn(&Ray) -> bool) -> (f64, usize) {
    let mut times = Vec::new();
    let mut trues = 0;
    for _ in 0..5 {
        let start = Instant::now();
        trues = rays
            .iter()
            .filter(|r| query(std::hint::black_box(r)))
            .count();
        times.push(start.elapsed().as_secs_f64());
    }
    (median(times), trues)
}

/// Times both queries over `rays` and prints the medians and their ratio.
fn bench_rays(what: &str, c: &CompiledScene, rays: &[Ray]) {
    let (t_any, n_any) = time(rays, |r| c.occluded(r, 1e-4, f32::INFINITY));
    let (t_closest, n_closest) = time(rays, |r| c.intersect(r, 1e-4, f32::INFINITY).is_some());
    assert_eq!(n_any, n_closest);
    let mrays = |t: f64| rays.len() as f64 / t / 1e6;
    println!(
        "  {what}: {} rays, {n_any} occluded; one thread, median of 5:\n    \
         occluded:              {:7.1} ms ({:.2} Mrays/s)\n    \
         intersect().is_some(): {:7.1} ms ({:.2} Mrays/s)\n    \
         intersect / occluded time: {:.2}x",
        rays.len(),
        t_any * 1e3,
        mrays(t_any),
        t_closest * 1e3,
        mrays(t_closest),
        t_closest / t_any
    );
}

/// All the shadow rays, then those occluded alone (where stopping early can pay).
fn bench_scene(path: &Path) {
    let c = compiled(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    println!("{}", path.display());
    let rays = shadow_rays(&c, 1 << 20);
    bench_rays("all", &c, &rays);
    let blocked: Vec<Ray> = rays
        .iter()
        .filter(|r| c.intersect(r, 1e-4, f32::INFINITY).is_some())
        .copied()
        .collect();
    bench_rays("occluded only", &c, &blocked);
}

#[test]
#[ignore = "benchmark: prints figures"]
fn bench_occluded_against_intersect() {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| "unknown".into());
    println!("CPU: {cpu}; SIMD: {}", tracelab_core::simd::level().name());
    // The largest course bunny tracelab reads, alone (the one-mesh path), then the
    // checkout's 1,000 bunny instances (the top-level BVH).
    let semester = common::semester_dir().join("scenes");
    let bunny = [
        "scene6_07_bunny_mesh_40k.txt",
        "scene5_09_bunny_mesh_40k.txt",
    ]
    .map(|f| semester.join(f))
    .into_iter()
    .find(|p| compiled(p).is_ok())
    .unwrap_or_else(|| common::course_dir().join("scenes/scene2_10_bunny_1k.txt"));
    bench_scene(&bunny);
    bench_scene(&common::repo().join("scenes/perf/bunny_instances_1000.txt"));
}
