//! `tracelab bench`: closest-hit throughput for one primary ray per pixel, as
//! `../shared/perf/embree_bench.cpp` measures Embree (same rays, same checksums).

use std::sync::Arc;
use std::time::{Duration, Instant};

use rayon::prelude::*;
use tracelab_core::accel::TriangleBvh;
use tracelab_core::geometry::Ray;
use tracelab_core::{CompiledScene, Mesh, MeshSlot, NodeKind, Scene};

use super::{BenchArgs, median};
use crate::exit::check_size;
use crate::io::load_scene;

pub fn run(b: &BenchArgs) -> anyhow::Result<()> {
    let (w, h) = (b.size[0], b.size[1]);
    check_size(w, h)?;
    let t_load = Instant::now();
    let scene = load_scene(Some(&b.scene))?;
    let load_ms = t_load.elapsed().as_secs_f64() * 1e3;
    out!(
        "load: {load_ms:.1} ms for the scene, its OBJ files and their BVHs, {} threads",
        rayon::current_num_threads()
    );

    let meshes = distinct_meshes(&scene);
    let t_build = Instant::now();
    for m in &meshes {
        std::hint::black_box(TriangleBvh::build(&m.positions, &m.triangles));
    }
    for m in &meshes {
        out!("bvh: {}", m.accel.shape());
    }
    let compiled = CompiledScene::new(&scene);
    let build_ms = t_build.elapsed().as_secs_f64() * 1e3;

    let tris: usize = meshes.iter().map(|m| m.triangle_count()).sum();
    let bytes: usize = meshes.iter().map(|m| m.memory_bytes()).sum();
    if tris > 0 {
        out!(
            "mesh: {tris} triangles, {bytes} bytes for geometry + BVH ({:.1} bytes/triangle)",
            bytes as f64 / tris as f64
        );
    }

    let t_min = compiled.camera.t_min();
    let mut buf = tracelab_core::memory::try_vec(
        w as usize * h as usize,
        f32::INFINITY,
        "the benchmark's hit distances",
    )?;
    let frame = |buf: &mut Vec<f32>| {
        // The columns' share of every ray, once per frame (bit-identical to `pixel_ray`).
        let rays = compiled.camera.pixel_rays(w, h);
        // Jobs of at most `ROWS_PER_JOB` rows, each with one row buffer (made per job, not
        // per row: docs/perf.md, "Figures behind the code's comments"). Embree's and
        // tinybvh's benches hand out single rows.
        buf.par_chunks_mut(w as usize)
            .enumerate()
            .with_max_len(ROWS_PER_JOB)
            .for_each_init(
                || Vec::with_capacity(w as usize),
                |row_buf, (row, out)| {
                    // The row's rays first, in one tight loop, then the traversals: made
                    // between two traversals, each ray's set-up headed its own dependency
                    // chain (docs/perf.md).
                    rays.row(row as u32).fill(row_buf);
                    for (ray, t) in row_buf.iter().zip(out.iter_mut()) {
                        *t = compiled
                            .intersect(ray, t_min, f32::INFINITY)
                            .map_or(f32::INFINITY, |hit| hit.t);
                    }
                },
            );
    };
    // --packets: 4x2 pixel tiles traced as 8-ray packets, as embree_bench's rtcIntersect8
    // loop does; the same rays (two rows made as above), the same t per pixel.
    let packet_frame = |buf: &mut Vec<f32>| {
        let rays = compiled.camera.pixel_rays(w, h);
        // The packet lives with the row buffers and is filled in place: made by
        // `array::from_fn` per tile, its 192 bytes went through a `memcpy` call on every
        // packet (5% of bunny_1k's packet frame in the profile).
        let new_bufs = || {
            (
                Vec::with_capacity(w as usize),
                Vec::with_capacity(w as usize),
                [Ray::new(glam::Vec3::ZERO, glam::Vec3::Z); 8],
            )
        };
        buf.par_chunks_mut(2 * w as usize)
            .enumerate()
            .with_min_len(8)
            .for_each_init(new_bufs, |(top, bottom, packet), (pair, out)| {
                let row = 2 * pair as u32;
                rays.row(row).fill(top);
                let two = out.len() > w as usize;
                if two {
                    rays.row(row + 1).fill(bottom);
                } else {
                    bottom.clear();
                    bottom.extend_from_slice(top);
                }
                let (out_top, out_bottom) = out.split_at_mut(w as usize);
                for x in (0..w as usize).step_by(4) {
                    let n = (w as usize - x).min(4);
                    let ray = |k: usize| {
                        let row = if k < 4 { &*top } else { &*bottom };
                        row[x + (k & 3).min(n - 1)]
                    };
                    for (k, r) in packet.iter_mut().enumerate() {
                        *r = ray(k);
                    }
                    let cols = (1u8 << n) - 1;
                    let active = if two { cols | (cols << 4) } else { cols };
                    let hits = compiled.intersect8(packet, active, t_min, f32::INFINITY);
                    for k in 0..n {
                        out_top[x + k] = hits[k].map_or(f32::INFINITY, |hit| hit.t);
                        if two {
                            out_bottom[x + k] = hits[4 + k].map_or(f32::INFINITY, |hit| hit.t);
                        }
                    }
                }
            });
    };
    let run_frame = |buf: &mut Vec<f32>| {
        if b.packets {
            packet_frame(buf)
        } else {
            frame(buf)
        }
    };
    if b.packets {
        out!("mode: PACKETS, 4x2 pixel tiles traced as 8-ray packets");
    }
    run_frame(&mut buf); // warm-up
    let mut times = Vec::with_capacity(b.repeat);
    let started = Instant::now();
    // `--repeat` frames, and more until `MIN_TIMED` has passed: on a shared 2-core guest the
    // second core sometimes stalls for some 25 ms, longer than seven of the cube's 3.3 ms
    // frames, whose median then showed one core (docs/perf.md).
    while times.len() < b.repeat.max(1)
        || (started.elapsed() < MIN_TIMED && times.len() < MAX_FRAMES)
    {
        let t = Instant::now();
        run_frame(&mut buf);
        times.push(t.elapsed().as_secs_f64());
    }
    let frames = times.len();
    // The best frame too: on a shared machine it shows the code's speed, the median the load.
    let best = times.iter().copied().fold(f64::INFINITY, f64::min);
    let secs = median(times);
    let hits = buf.iter().filter(|t| t.is_finite()).count();
    let sum_t: f64 = buf
        .iter()
        .filter(|t| t.is_finite())
        .map(|&t| t as f64)
        .sum();
    let mrays = (w as f64 * h as f64) / secs / 1e6;
    out!(
        "frame: {w}x{h}, {} threads, {} kernels, median {:.3} ms of {}, best {:.3} ms ({:.3} Mrays/s)",
        rayon::current_num_threads(),
        tracelab_core::simd::level().name(),
        secs * 1e3,
        frames,
        best * 1e3,
        (w as f64 * h as f64) / best / 1e6
    );
    let mode = if b.packets { " mode=packets" } else { "" };
    out!("BENCH mrays_per_s={mrays:.3} hits={hits} sum_t={sum_t:.6} build_ms={build_ms:.3}{mode}");
    Ok(())
}

/// The most rows in one job of the single-ray frame. With jobs of at least 16 rows (rayon then
/// splits a frame into a few long jobs and balances them only by stealing), 2-thread frames
/// of the Stanford bunny were 7% slower, the other meshes' 1-3%; 1-thread frames even
/// (docs/perf.md).
const ROWS_PER_JOB: usize = 8;

/// The least time the timed frames take, more frames than `--repeat` asks if need be.
const MIN_TIMED: Duration = Duration::from_millis(250);
/// At most this many frames beyond `--repeat` for `MIN_TIMED` (a 1x1 image's frames are
/// microseconds).
const MAX_FRAMES: usize = 10_000;

/// Distinct meshes (shared by path, so each appears once).
fn distinct_meshes(scene: &Scene) -> Vec<Arc<Mesh>> {
    let mut meshes: Vec<Arc<Mesh>> = Vec::new();
    for (_, n) in scene.graph.iter() {
        if let NodeKind::TriangleMesh {
            mesh: MeshSlot::Loaded(m),
            ..
        } = &n.kind
            && !meshes.iter().any(|x| Arc::ptr_eq(x, m))
        {
            meshes.push(m.clone());
        }
    }
    meshes
}
