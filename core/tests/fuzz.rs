//! The fuzzing harness that stays: deterministic mutations of scenes through parser,
//! writer, compiler and a 4×4 render, and of OBJ meshes through both OBJ readers.
//! Properties: no panic; every diagnostic has a location; an accepted scene writes back to
//! text that reads as the same scene and renders the same pixels; the fast OBJ reader and
//! tobj agree whenever the fast one accepts.
//!
//! The plain tests mutate only the checkout's own seeds (scenes/ and assets/). The course's
//! scenes and meshes (`TRACELAB_COURSE_DIR`) are seeds of two tests of their own, `#[ignore]`d
//! for needing them, which fail when they are missing.
//!
//! `TRACELAB_FUZZ_CASES=N` sets the number of cases per test (default 100,000 scenes,
//! 50,000 OBJ files); `TRACELAB_FUZZ_CASE=K` replays case K alone (with the same test's
//! seeds). A failure prints the case number and its input as a byte string.

mod common;

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Instant;

use common::{Rng, fuzz_cases, mutate_text, quoted, repo};
use tracelab_core::format::obj::{load_with_tobj, parse_obj, parse_obj_fast};
use tracelab_core::{
    Frame, MeshCache, RenderSettings, Scene, check_scene, compile, parse_scene, render_frame,
    write_scene,
};

/// One case taking longer than this is a hang (cases take well under a millisecond).
const CASE_LIMIT_MS: u64 = 20_000;

const SCENE_SEED: u64 = 0x5eed_0f5c_e9e5;
const OBJ_SEED: u64 = 0x0b1_5eed_f00d;

fn skip_note(msg: &str) {
    use std::io::Write as _;
    let _ = writeln!(std::io::stderr(), "{msg}");
}

/// `dir`'s files ending in `ext`, recursively, sorted.
fn files_in(dir: &Path, ext: &str, out: &mut Vec<PathBuf>) {
    let Ok(rd) = std::fs::read_dir(dir) else {
        return;
    };
    let mut paths: Vec<PathBuf> = rd.filter_map(|e| e.ok().map(|e| e.path())).collect();
    paths.sort();
    for p in paths {
        if p.is_dir() {
            files_in(&p, ext, out);
        } else if p.extension().is_some_and(|e| e == ext) {
            out.push(p);
        }
    }
}

/// The files ending in `ext` under `dirs`, under 128 KiB (scenes/perf's generated
/// 1,000-instance scene, 230 KiB, is too slow to mutate by the thousand for a grammar the
/// small files cover; assets/torus.obj, 64.4 KiB, is needed: the checkout has 3 meshes),
/// with their bytes.
fn seeds(dirs: &[PathBuf], ext: &str) -> Vec<(PathBuf, Vec<u8>)> {
    let mut paths = Vec::new();
    for d in dirs {
        files_in(d, ext, &mut paths);
    }
    paths
        .into_iter()
        .filter_map(|p| std::fs::read(&p).ok().map(|b| (p, b)))
        .filter(|(_, b)| b.len() < 128 << 10)
        .collect()
}

/// Runs cases `0..n` (or only `TRACELAB_FUZZ_CASE`) on every core, each under catch_unwind;
/// returns the number run. `case` returns Err(why) when a property fails.
fn run_cases(
    name: &str,
    n: u64,
    case: impl Fn(u64, &mut MeshCache) -> Result<(), String> + Sync,
) -> u64 {
    let only: Option<u64> = std::env::var("TRACELAB_FUZZ_CASE")
        .ok()
        .and_then(|v| v.parse().ok());
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get()) as u64;
    let start = Instant::now();
    // Per thread: the case running and when it started (ms since `start`), for the watchdog.
    let running: Vec<(AtomicU64, AtomicU64)> = (0..threads)
        .map(|_| (AtomicU64::new(0), AtomicU64::new(0)))
        .collect();
    let done = AtomicBool::new(false);
    let failures: Vec<String> = std::thread::scope(|s| {
        // A hang cannot be caught: name the case, then end the run.
        s.spawn(|| {
            while !done.load(Ordering::Relaxed) {
                std::thread::sleep(std::time::Duration::from_millis(200));
                let now = start.elapsed().as_millis() as u64;
                for (k, since) in &running {
                    let (k, since) = (k.load(Ordering::Relaxed), since.load(Ordering::Relaxed));
                    if now.saturating_sub(since) > CASE_LIMIT_MS && !done.load(Ordering::Relaxed) {
                        skip_note(&format!(
                            "{name}: case {k} has run for over {} s: a hang; replay it with TRACELAB_FUZZ_CASE={k}",
                            CASE_LIMIT_MS / 1000
                        ));
                        std::process::exit(1);
                    }
                }
            }
        });
        let handles: Vec<_> = (0..threads)
            .map(|t| {
                let case = &case;
                let running = &running;
                s.spawn(move || {
                    let mut cache = MeshCache::new();
                    let mut failures = Vec::new();
                    let mut k = t;
                    while k < n && failures.len() < 3 {
                        if only.is_none_or(|o| o == k) {
                            running[t as usize].0.store(k, Ordering::Relaxed);
                            running[t as usize]
                                .1
                                .store(start.elapsed().as_millis() as u64, Ordering::Relaxed);
                            match catch_unwind(AssertUnwindSafe(|| case(k, &mut cache))) {
                                Ok(Ok(())) => {}
                                Ok(Err(why)) => failures.push(format!("case {k}: {why}")),
                                Err(_) => failures
                                    .push(format!("case {k}: panicked (see the message above)")),
                            }
                        }
                        if k > 0 && k % 1_000_000 == 0 {
                            skip_note(&format!(
                                "{name}: {k} cases, {:.0} s",
                                start.elapsed().as_secs_f64()
                            ));
                        }
                        k += threads;
                    }
                    failures
                })
            })
            .collect();
        let failures = handles
            .into_iter()
            .flat_map(|h| {
                h.join()
                    .unwrap_or_else(|_| vec!["a worker died".to_string()])
            })
            .collect();
        done.store(true, Ordering::Relaxed);
        failures
    });
    skip_note(&format!(
        "{name}: {n} cases in {:.1} s on {threads} threads",
        start.elapsed().as_secs_f64()
    ));
    assert!(
        failures.is_empty(),
        "{name}: {} failure(s); replay one with TRACELAB_FUZZ_CASE=K\n{}",
        failures.len(),
        failures.join("\n\n")
    );
    n
}

fn differing_pixels(a: &Frame, b: &Frame) -> usize {
    a.samples
        .iter()
        .zip(&b.samples)
        .filter(|(x, y)| {
            x.color != y.color || x.normal != y.normal || x.t.to_bits() != y.t.to_bits()
        })
        .count()
}

fn render(scene: &Scene) -> Frame {
    render_frame(&compile(scene), &RenderSettings::new(4, 4))
}

/// Words a mutation may insert into a scene.
const SCENE_WORDS: &[&str] = &[
    "{",
    "}",
    "Group",
    "Transform",
    "Sphere",
    "Plane",
    "Triangle",
    "TriangleMesh",
    "Box",
    "Union",
    "Intersection",
    "Subtraction",
    "numObjects",
    "MaterialIndex",
    "Material",
    "PhongMaterial",
    "diffuseColor",
    "obj_file",
    "center",
    "radius",
    "normal",
    "offset",
    "Scale",
    "UniformScale",
    "Rotate",
    "Matrix",
    "XRotate",
    "Lights",
    "Materials",
    "numMaterials",
    "numLights",
    "DirectionalLight",
    "Background",
    "color",
    "ambientLight",
    "PerspectiveCamera",
    "angle",
    "size",
    "é",
    "\u{feff}",
    "cube.obj",
    "../assets/cube.obj",
    "no_such.obj",
    ".",
    "/dev/null",
    // Whole fields, so that an insertion can make a block that is still accepted.
    "obj_file cube.obj",
    "obj_file ../assets/cube.obj",
    "diffuseColor 1 0 0",
    "specularColor 1 1 1",
    "exponent 7",
    "MaterialIndex 0",
    "radius 2",
    "Scale 1 2 3",
    "UniformScale -1",
    "ZRotate -0",
    "Rotate { 0 1 0 30 }",
    // Solid textures (assignment 6).
    "Checkerboard",
    "Noise",
    "Marble",
    "Wood",
    "materialIndex 0",
    "materialIndex 1",
    "octaves 3",
    "frequency 2",
    "amplitude 1",
];

/// One scene case: the properties the harness holds the parser, writer and renderer to.
fn scene_case(input: &[u8], dir: &Path, cache: &mut MeshCache) -> Result<(), String> {
    let out = parse_scene(input, "fuzz.txt", Some(dir), cache);
    for d in &out.diagnostics.0 {
        if d.line == 0 {
            return Err(format!("diagnostic without a location: {d}"));
        }
    }
    let shown = out.diagnostics.to_string();
    if shown.chars().any(|c| c.is_control() && c != '\n') {
        return Err(format!("a message prints a control character: {shown:?}"));
    }
    if out.diagnostics.errors().count() > 21 {
        return Err("more than 20 errors shown".to_string());
    }
    let Some(scene) = out.scene else {
        return if out.diagnostics.has_errors() {
            Ok(())
        } else {
            Err("no scene and no error".to_string())
        };
    };
    let image = render(&scene);
    if out.diagnostics.has_errors() {
        // Node errors (a mesh that did not load): usable, but not a clean scene to round-trip.
        return Ok(());
    }
    // One rule set: whatever the parser accepts passes every rule the editor and the
    // checked writer apply.
    let problems = check_scene(&scene);
    if !problems.is_empty() {
        return Err(format!(
            "an accepted scene breaks a validity rule: {}",
            problems[0]
        ));
    }
    let text = write_scene(&scene);
    let back = parse_scene(text.as_bytes(), "written.txt", Some(dir), cache);
    let Some(again) = back.scene.filter(|_| !back.diagnostics.has_errors()) else {
        return Err(format!(
            "the written scene does not read back:\n{}\n--- written:\n{text}",
            back.diagnostics
        ));
    };
    if again != scene {
        return Err(format!(
            "the written scene reads as a different scene\n--- written:\n{text}"
        ));
    }
    let rewritten = write_scene(&again);
    if rewritten != text {
        return Err(format!(
            "writing is not canonical\n--- first:\n{text}\n--- second:\n{rewritten}"
        ));
    }
    let d = differing_pixels(&image, &render(&again));
    if d != 0 {
        return Err(format!(
            "the written scene renders {d} of 16 pixels differently\n--- written:\n{text}"
        ));
    }
    Ok(())
}

/// Seeds: the checkout's scenes/ only; the course's are the next test's.
#[test]
fn mutated_scenes_never_panic_and_accepted_ones_round_trip() {
    let seeds = seeds(&[repo().join("scenes")], "txt");
    assert!(seeds.len() >= 20, "only {} seed scenes", seeds.len());
    fuzz_scenes(&seeds);
}

/// Seeds: the course's scenes.
#[test]
#[ignore = "needs the course files: TRACELAB_COURSE_DIR, default ../shared/mit6837"]
fn mutated_course_scenes_never_panic_and_accepted_ones_round_trip() {
    let seeds = seeds(&[common::course_dir().join("scenes")], "txt");
    assert!(seeds.len() >= 20, "only {} seed scenes", seeds.len());
    fuzz_scenes(&seeds);
}

/// Mutations of `seeds` through parser, writer, compiler and a 4×4 render.
fn fuzz_scenes(seeds: &[(PathBuf, Vec<u8>)]) {
    let n = fuzz_cases(100_000);
    let accepted = std::sync::atomic::AtomicU64::new(0);
    run_cases("scene fuzz", n, |k, cache| {
        let mut rng = Rng::for_case(SCENE_SEED, k);
        let (path, seed) = &seeds[rng.below(seeds.len())];
        let input = mutate_text(seed, SCENE_WORDS, &mut rng);
        if std::env::var("TRACELAB_FUZZ_CASE").is_ok() {
            skip_note(&format!(
                "case {k}: seed {}\ninput {}",
                path.display(),
                quoted(&input)
            ));
        }
        let dir = path.parent().unwrap_or(Path::new("."));
        let r = scene_case(&input, dir, cache);
        if r.is_ok()
            && parse_scene(&input, "fuzz.txt", Some(dir), cache)
                .into_result()
                .is_ok()
        {
            accepted.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        }
        r.map_err(|why| format!("{why}\nseed {}\ninput {}", path.display(), quoted(&input)))
    });
    // A harness whose mutations are always rejected tests only the error paths.
    let accepted = accepted.into_inner();
    assert!(
        accepted * 20 >= n,
        "only {accepted} of {n} mutated scenes were accepted"
    );
}

/// Words a mutation may insert into an OBJ file.
const OBJ_WORDS: &[&str] = &[
    "\nv",
    "\nf",
    "\nvn",
    "\nvt",
    "\nusemtl",
    "\nusemtl x",
    "\nmtllib m.mtl",
    "\no",
    "\ng g1",
    "\ns 1",
    "\nl",
    "\n#",
    "1/1/1",
    "1//1",
    "2/1",
    "-1",
    "0",
    "1/2/3/4",
    "1/",
    "/1",
    "\n",
    "\r\n",
    "v",
    "f",
    // A byte-order mark (skipped at the start) and comments after a value (refused, located).
    "\u{feff}",
    " # c",
    "\nv 1 2 3 # c",
    "\nv 1 2 3 1 0",
    "1e39",
];

/// Both readers on one OBJ text: never a panic; when the fast one accepts, tobj reads the
/// same triangles.
fn obj_case(input: &[u8]) -> Result<(), String> {
    // Every refusal of the text names its line: `fuzz.obj:LINE: what is wrong`.
    if let Err(e) = parse_obj(input, "fuzz.obj") {
        let e = e.to_string();
        let line = e
            .strip_prefix("fuzz.obj:")
            .and_then(|r| r.split_once(": "))
            .map(|(n, _)| n);
        if !line.is_some_and(|n| n.parse::<u32>().is_ok_and(|n| n > 0)) {
            return Err(format!("a refusal without a line: {e}"));
        }
    }
    let Some((fp, ft)) = parse_obj_fast(input) else {
        return Ok(());
    };
    let (tp, tt) = load_with_tobj(input, "fuzz.obj")
        .map_err(|e| format!("the fast reader accepts, tobj rejects: {e}"))?;
    let as_points = |p: &[glam::Vec3], t: &[[u32; 3]]| -> Vec<[u32; 9]> {
        t.iter()
            .map(|tri| {
                let v = tri.map(|i| p.get(i as usize).copied().unwrap_or(glam::Vec3::NAN));
                [
                    v[0].x, v[0].y, v[0].z, v[1].x, v[1].y, v[1].z, v[2].x, v[2].y, v[2].z,
                ]
                .map(f32::to_bits)
            })
            .collect()
    };
    if as_points(&fp, &ft) != as_points(&tp, &tt) {
        return Err(format!(
            "the readers disagree: fast {} triangles, tobj {}",
            ft.len(),
            tt.len()
        ));
    }
    Ok(())
}

/// Seeds: the checkout's assets/ only; the course's meshes are the next test's.
#[test]
fn mutated_obj_files_never_panic_and_both_readers_agree() {
    let seeds = seeds(&[repo().join("assets")], "obj");
    assert!(seeds.len() >= 3, "only {} seed meshes", seeds.len());
    fuzz_objs(&seeds);
}

/// Seeds: the meshes among the course's scenes.
#[test]
#[ignore = "needs the course files: TRACELAB_COURSE_DIR, default ../shared/mit6837"]
fn mutated_course_obj_files_never_panic_and_both_readers_agree() {
    let seeds = seeds(&[common::course_dir().join("scenes")], "obj");
    assert!(seeds.len() >= 3, "only {} seed meshes", seeds.len());
    fuzz_objs(&seeds);
}

/// Mutations of `seeds` through both OBJ readers.
fn fuzz_objs(seeds: &[(PathBuf, Vec<u8>)]) {
    let n = fuzz_cases(100_000) / 2;
    run_cases("OBJ fuzz", n, |k, _| {
        let mut rng = Rng::for_case(OBJ_SEED, k);
        let (path, seed) = &seeds[rng.below(seeds.len())];
        let input = mutate_text(seed, OBJ_WORDS, &mut rng);
        obj_case(&input)
            .map_err(|why| format!("{why}\nseed {}\ninput {}", path.display(), quoted(&input)))
    });
}
