//! Unit tests: the tree's invariants, every query against brute force, AVX against the
//! portable path and packets against single rays, bit for bit.

use glam::{Vec3, Vec3A};

#[cfg(target_arch = "x86_64")]
use super::packet::PacketBounds;
use super::{SLAB_WIDEN, TriangleBvh, TriangleHit, has_avx};
use crate::accel::sah;
use crate::accel::wide::{self, WIDTH};
use crate::geometry::{Aabb, Ray, intersect_triangle};

/// xorshift32: repeatable runs.
struct Rng(u32);
impl Rng {
    fn f(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 17;
        self.0 ^= self.0 << 5;
        self.0 as f32 / u32::MAX as f32
    }
    fn v(&mut self) -> Vec3 {
        Vec3::new(self.f(), self.f(), self.f())
    }
}

fn random_mesh(n: usize, seed: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut r = Rng(seed.max(1));
    let mut pos = Vec::new();
    let mut tris = Vec::new();
    for i in 0..n {
        let c = r.v() * 4.0 - 2.0;
        for _ in 0..3 {
            pos.push(c + (r.v() - 0.5) * 0.6);
        }
        let b = (3 * i) as u32;
        tris.push([b, b + 1, b + 2]);
    }
    // Degenerate triangles too: a point and a sliver along a line.
    pos.extend([Vec3::ZERO, Vec3::X, Vec3::X * 2.0]);
    let z = (pos.len() - 3) as u32;
    tris.push([z, z, z]);
    tris.push([z, z + 1, z + 2]);
    (pos, tris)
}

fn build_checked(pos: &[Vec3], tris: &[[u32; 3]]) -> TriangleBvh {
    let bvh = TriangleBvh::build(pos, tris);
    bvh.check_invariants(pos, tris)
        .unwrap_or_else(|e| panic!("{} triangles: {e}", tris.len()));
    bvh
}

fn brute(pos: &[Vec3], tris: &[[u32; 3]], ray: &Ray, t_min: f32) -> Option<TriangleHit> {
    let mut best: Option<TriangleHit> = None;
    for (i, t) in tris.iter().enumerate() {
        let lim = best.map_or(f32::INFINITY, |b| b.t);
        let [a, b, c] = t.map(|v| pos[v as usize]);
        if let Some((th, _, _)) = intersect_triangle(ray, a, b, c, t_min, lim) {
            best = Some(TriangleHit {
                t: th,
                triangle: i as u32,
            });
        }
    }
    best
}

/// Closest hits agree with the brute-force loop: same t, and the same triangle unless
/// two triangles are hit at that very t.
fn assert_agrees(pos: &[Vec3], tris: &[[u32; 3]], bvh: &TriangleBvh, rays: &[Ray]) {
    for (k, ray) in rays.iter().enumerate() {
        let a = bvh.intersect(ray, 0.0, f32::INFINITY);
        // Whichever instruction set `intersect` picked, the portable path must agree.
        assert_eq!(
            a,
            bvh.walk_portable::<false>(ray.origin.into(), ray.direction.into(), 0.0, f32::INFINITY),
            "ray {k}"
        );
        // And so must the AVX kernels, which an AVX-512 CPU does not pick by itself.
        #[cfg(target_arch = "x86_64")]
        if crate::simd::detected() >= crate::simd::Level::Avx {
            #[allow(unsafe_code)]
            // SAFETY: the CPU has AVX.
            let avx = unsafe {
                bvh.walk_avx::<false, _, _>(
                    ray,
                    |r| (r.origin.into(), r.direction.into()),
                    0.0,
                    f32::INFINITY,
                )
            };
            assert_eq!(a, avx, "ray {k}, avx");
        }
        let b = brute(pos, tris, ray, 0.0);
        match (a, b) {
            (None, None) => {}
            (Some(a), Some(b)) => {
                assert!(
                    (a.t - b.t).abs() <= 1e-6 * b.t.abs().max(1.0),
                    "ray {k}: t {a:?} vs {b:?}"
                );
                if a.triangle != b.triangle {
                    let [p, q, r] = tris[a.triangle as usize].map(|v| pos[v as usize]);
                    let again = intersect_triangle(ray, p, q, r, 0.0, f32::INFINITY).map(|h| h.0);
                    assert_eq!(
                        again,
                        Some(a.t),
                        "ray {k}: triangle {} is not hit at {}",
                        a.triangle,
                        a.t
                    );
                }
            }
            _ => panic!("ray {k}: bvh {a:?} vs brute {b:?}"),
        }
    }
}

fn rays_toward(center: Vec3, radius: f32, n: usize, seed: u32) -> Vec<Ray> {
    let mut r = Rng(seed);
    (0..n)
        .map(|_| {
            let o = center + (r.v() * 2.0 - 1.0) * radius * 2.5;
            let target = center + (r.v() * 2.0 - 1.0) * radius * 0.8;
            Ray::new(o, target - o)
        })
        .collect()
}

#[test]
fn random_rays_agree_with_brute_force_on_random_meshes() {
    for (n, seed) in [(1, 7), (3, 3), (9, 1), (50, 11), (2000, 13), (20_000, 17)] {
        let (pos, tris) = random_mesh(n, seed);
        let bvh = build_checked(&pos, &tris);
        assert_agrees(
            &pos,
            &tris,
            &bvh,
            &rays_toward(Vec3::ZERO, 2.0, 2000, 99 + seed),
        );
    }
}

/// Every triangle twice, so a hit is a tie at the very same t inside a leaf: every path
/// (AVX-512, AVX, portable) picks the same one, the first in leaf order, as the scalar loop
/// does. (Fails if a leaf test picks the last lane of the tie instead.)
#[test]
fn ties_inside_a_leaf_go_the_same_way_on_every_path() {
    let (pos, tris) = random_mesh(150, 57);
    let twice: Vec<[u32; 3]> = tris.iter().flat_map(|&t| [t, t]).collect();
    let bvh = build_checked(&pos, &twice);
    let rays = rays_toward(Vec3::ZERO, 2.0, 2000, 59);
    assert_agrees(&pos, &twice, &bvh, &rays);
    let hits = rays
        .iter()
        .filter(|r| bvh.intersect(r, 0.0, f32::INFINITY).is_some())
        .count();
    assert!(hits > 300, "{hits} of {} rays hit", rays.len());
}

/// Both leaf sizings (the AVX one and the one for CPUs without it) build valid trees that
/// find the brute-force hits; the AVX sizing makes leaves of several triangles.
#[test]
fn both_leaf_sizings_build_valid_trees() {
    let (pos, tris) = random_mesh(5000, 23);
    let mut per_leaf = Vec::new();
    for block in [1, WIDTH as u32] {
        let bvh = TriangleBvh::build_with(&pos, &tris, sah::LeafBlock(block));
        bvh.check_invariants(&pos, &tris)
            .unwrap_or_else(|e| panic!("block {block}: {e}"));
        assert_agrees(&pos, &tris, &bvh, &rays_toward(Vec3::ZERO, 2.0, 2000, 5));
        let leaves: usize = bvh
            .nodes
            .iter()
            .flat_map(|n| {
                n.child
                    .iter()
                    .enumerate()
                    .filter(|&(s, c)| !n.slot_is_empty(s) && wide::is_leaf(*c))
            })
            .count();
        per_leaf.push(tris.len() as f64 / leaves as f64);
    }
    assert!(
        per_leaf[1] > 1.5 * per_leaf[0],
        "triangles per leaf {per_leaf:?}"
    );
}

#[test]
fn a_ray_from_inside_the_mesh_and_axis_parallel_rays_agree() {
    let (pos, tris) = random_mesh(3000, 23);
    let bvh = build_checked(&pos, &tris);
    let mut rays = Vec::new();
    let mut r = Rng(5);
    for _ in 0..500 {
        let o = r.v() * 3.0 - 1.5;
        for d in [
            Vec3::X,
            Vec3::NEG_X,
            Vec3::Y,
            Vec3::NEG_Y,
            Vec3::Z,
            Vec3::NEG_Z,
            r.v() - 0.5,
        ] {
            rays.push(Ray::new(o, d));
        }
    }
    assert_agrees(&pos, &tris, &bvh, &rays);
}

#[test]
fn t_range_is_respected() {
    let (pos, tris) = random_mesh(500, 29);
    let bvh = build_checked(&pos, &tris);
    for ray in rays_toward(Vec3::ZERO, 2.0, 500, 3) {
        let Some(first) = bvh.intersect(&ray, 0.0, f32::INFINITY) else {
            continue;
        };
        // Nothing strictly before the first hit; past it, the brute force's next hit.
        assert!(bvh.intersect(&ray, 0.0, first.t).is_none());
        let next = bvh.intersect(&ray, first.t, f32::INFINITY).map(|h| h.t);
        let want = brute(&pos, &tris, &ray, first.t).map(|h| h.t);
        assert_eq!(next, want);
    }
}

#[test]
fn identical_and_degenerate_triangles_build_and_never_hit_edge_on() {
    // Many copies of one triangle: no split can separate them; leaves must still be small.
    let pos = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
    let tris = vec![[0, 1, 2]; 1000];
    let bvh = build_checked(&pos, &tris);
    let hit = bvh.intersect(
        &Ray::new(Vec3::new(0.2, 0.2, 1.0), Vec3::NEG_Z),
        0.0,
        f32::INFINITY,
    );
    assert_eq!(hit.map(|h| h.t), Some(1.0));
    // Zero-area triangles only.
    let pos = vec![Vec3::ZERO, Vec3::X, Vec3::X * 2.0];
    let tris = vec![[0, 0, 0], [0, 1, 2], [1, 1, 2]];
    let bvh = build_checked(&pos, &tris);
    for ray in rays_toward(Vec3::X, 1.0, 200, 8) {
        assert!(bvh.intersect(&ray, 0.0, f32::INFINITY).is_none());
    }
}

#[test]
fn adversarial_sizes_stay_within_the_depth_cap() {
    // Triangles at exponentially growing distances make SAH peel one at a time.
    let mut pos = Vec::new();
    let mut tris = Vec::new();
    for i in 0..3000u32 {
        let x = 1.02f32.powi(i as i32);
        pos.extend([
            Vec3::new(x, 0.0, 0.0),
            Vec3::new(x, 1.0, 0.0),
            Vec3::new(x, 0.0, 1.0),
        ]);
        tris.push([3 * i, 3 * i + 1, 3 * i + 2]);
    }
    let bvh = build_checked(&pos, &tris);
    let ray = Ray::new(Vec3::new(-1.0, 0.2, 0.2), Vec3::X);
    assert_eq!(
        bvh.intersect(&ray, 0.0, f32::INFINITY).map(|h| h.triangle),
        Some(0)
    );
    let mut all = Vec::new();
    bvh.intersect_all(&ray, 0.0, f32::INFINITY, &mut all);
    assert_eq!(all.len(), 3000);
}

#[test]
fn one_triangle_mesh() {
    let pos = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
    let bvh = build_checked(&pos, &[[0, 1, 2]]);
    let ray = Ray::new(Vec3::new(0.25, 0.25, -2.0), Vec3::Z);
    assert_eq!(
        bvh.intersect(&ray, 0.0, f32::INFINITY),
        Some(TriangleHit {
            t: 2.0,
            triangle: 0
        })
    );
    assert!(
        bvh.intersect(
            &Ray::new(Vec3::new(0.8, 0.8, -2.0), Vec3::Z),
            0.0,
            f32::INFINITY
        )
        .is_none()
    );
    assert_eq!(
        bvh.bounds(),
        Aabb::new(Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0))
    );
}

#[test]
fn empty_mesh_never_hits() {
    let bvh = build_checked(&[], &[]);
    assert!(
        bvh.intersect(&Ray::new(Vec3::ZERO, Vec3::X), 0.0, f32::INFINITY)
            .is_none()
    );
    let mut out = Vec::new();
    bvh.intersect_all(&Ray::new(Vec3::ZERO, Vec3::X), 0.0, f32::INFINITY, &mut out);
    assert!(out.is_empty());
    assert!(bvh.bounds().is_empty());
}

#[test]
fn broken_trees_fail_the_invariant_check() {
    let (pos, tris) = random_mesh(300, 31);
    let good = build_checked(&pos, &tris);
    let mut shrunk = good.clone();
    shrunk.nodes[0].hi[0][0][0] -= 0.5;
    assert!(shrunk.check_invariants(&pos, &tris).is_err());
    let mut dup = good.clone();
    dup.ids[1] = dup.ids[0];
    assert!(dup.check_invariants(&pos, &tris).is_err());
    assert!(good.check_invariants(&pos, &tris[1..]).is_err());
    // An inner child 32 bytes past its node's start: aligned, inside the array, no node's.
    let mut shifted = good.clone();
    let s = (0..WIDTH)
        .find(|&s| !shifted.nodes[0].slot_is_empty(s) && !wide::is_leaf(shifted.nodes[0].child[s]))
        .expect("a 300-triangle tree's root has an inner child");
    shifted.nodes[0].child[s] += 4;
    let e = shifted
        .check_invariants(&pos, &tris)
        .expect_err("a child inside a node is caught");
    assert!(e.to_string().contains("names no node's start"), "{e}");
}

#[test]
fn a_child_past_the_last_node_panics_instead_of_reading_past_the_nodes() {
    let (pos, tris) = random_mesh(300, 31);
    let bvh = build_checked(&pos, &tris);
    let last = wide::inner(bvh.nodes.len() - 1);
    assert_eq!(Some(bvh.node(last)), bvh.nodes.last());
    for bad in [last + 1, last + wide::NODE_UNITS] {
        let r = std::panic::catch_unwind(|| bvh.node(bad).child[0]);
        assert!(r.is_err(), "child {bad} of {} nodes", bvh.nodes.len());
    }
}

#[test]
fn intersect_all_finds_every_crossing() {
    let (pos, tris) = random_mesh(500, 5);
    let bvh = build_checked(&pos, &tris);
    let mut out = Vec::new();
    for k in 0..200 {
        let o = Vec3::new(
            -5.0,
            (k as f32 * 0.37).sin() * 1.5,
            (k as f32 * 0.11).cos() * 1.5,
        );
        let ray = Ray::new(o, Vec3::new(1.0, 0.01 * k as f32 - 1.0, 0.3));
        out.clear();
        bvh.intersect_all(&ray, 0.0, f32::INFINITY, &mut out);
        let mut got: Vec<u32> = out.iter().map(|h| h.triangle).collect();
        got.sort_unstable();
        let want: Vec<u32> = (0..tris.len() as u32)
            .filter(|&i| {
                let [a, b, c] = tris[i as usize].map(|v| pos[v as usize]);
                intersect_triangle(&ray, a, b, c, 0.0, f32::INFINITY).is_some()
            })
            .collect();
        assert_eq!(got, want, "ray {k}");
    }
}

/// Rays with NaN or infinite parts (an overflowing transform) used to loop forever: the
/// NaN slab entered the empty slots, whose child is the root. Run on a thread so a
/// regression fails instead of hanging the test run.
#[test]
fn non_finite_rays_miss_and_return() {
    let (pos, tris) = random_mesh(300, 9);
    let bvh = build_checked(&pos, &tris);
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let (n, i) = (f32::NAN, f32::INFINITY);
        let rays = [
            (Vec3::new(n, 0.0, -5.0), Vec3::Z),
            (Vec3::new(0.0, 0.0, -5.0), Vec3::new(n, n, n)),
            (Vec3::new(0.0, 0.0, -5.0), Vec3::new(i, i, i)),
            (Vec3::new(i, -i, i), Vec3::new(0.0, 0.0, 1.0)),
        ];
        let mut all = Vec::new();
        let mut hits = 0;
        for (o, d) in rays {
            hits += bvh.intersect(&Ray::new(o, d), 0.0, f32::INFINITY).is_some() as usize;
            bvh.intersect_all(&Ray::new(o, d), 0.0, f32::INFINITY, &mut all);
            // Every walk checks the ray itself (the check is in the walk, after the move
            // into object space that `closest_hit_of` inlines), on every instruction set.
            let (o, d) = (Vec3A::from(o), Vec3A::from(d));
            let inf = f32::INFINITY;
            hits += bvh.any_hit(o, d, 0.0, inf) as usize;
            hits += bvh.walk_portable::<false>(o, d, 0.0, inf).is_some() as usize;
            hits += bvh.walk_portable::<true>(o, d, 0.0, inf).is_some() as usize;
            #[cfg(target_arch = "x86_64")]
            if crate::simd::detected() >= crate::simd::Level::Avx {
                #[allow(unsafe_code)]
                // SAFETY: the CPU has AVX.
                let avx = unsafe { bvh.walk_avx::<false, _, _>(&(o, d), |&r| r, 0.0, inf) };
                hits += avx.is_some() as usize;
            }
        }
        let _ = tx.send((hits, all.len()));
    });
    let got = rx.recv_timeout(std::time::Duration::from_secs(10));
    assert_eq!(got, Ok((0, 0)), "non-finite rays must miss, and return");
}

/// Packets of the eight rays `rays[k..k + 8]` under every `active` mask in `masks`: each
/// traced ray gets the single-ray t bit for bit (and a triangle hit at that t), its
/// t_max lowered to it; rays left out get nothing and keep their t_max. Returns how
/// many rays were compared.
fn assert_packets_agree(bvh: &TriangleBvh, rays: &[Ray], t_min: f32, masks: &[u8]) -> usize {
    let mut compared = 0;
    for (p, chunk) in rays.chunks_exact(WIDTH).enumerate() {
        let o: [Vec3A; WIDTH] = std::array::from_fn(|i| chunk[i].origin.into());
        let d: [Vec3A; WIDTH] = std::array::from_fn(|i| chunk[i].direction.into());
        for &active in masks {
            let mut limits = [f32::INFINITY; WIDTH];
            limits[3] = 7.5; // one ray with a finite limit
            let mut t_packet = limits;
            let got = bvh.closest_hit8(&o, &d, active, t_min, &mut t_packet);
            for i in 0..WIDTH {
                let want = if active & (1 << i) != 0 {
                    bvh.closest_hit(o[i], d[i], t_min, limits[i])
                } else {
                    None
                };
                match (got[i], want) {
                    (None, None) => {}
                    (Some(g), Some(w)) => {
                        assert_eq!(
                            g.t.to_bits(),
                            w.t.to_bits(),
                            "packet {p} ray {i} mask {active:#x}"
                        );
                        if g.triangle != w.triangle {
                            // A tie: the other triangle must be hit at that very t.
                            let k = bvh
                                .ids
                                .iter()
                                .position(|&id| id == g.triangle)
                                .expect("a stored id");
                            assert_eq!(
                                bvh.tri(k).hit(chunk[i].origin, chunk[i].direction),
                                Some(g.t),
                                "packet {p} ray {i}: triangle {} not hit at {}",
                                g.triangle,
                                g.t
                            );
                        }
                    }
                    _ => panic!(
                        "packet {p} ray {i} mask {active:#x}: {:?} vs single {want:?}",
                        got[i]
                    ),
                }
                let want_t = want.map_or(limits[i], |h| h.t);
                assert_eq!(
                    t_packet[i].to_bits(),
                    want_t.to_bits(),
                    "packet {p} ray {i}: t_max"
                );
            }
            // The sparse variant (incoherent packets one ray at a time) agrees too.
            let mut t_sparse = limits;
            let sparse = bvh.closest_hit8_with(&o, &d, active, t_min, &mut t_sparse, true);
            assert_eq!(
                t_sparse.map(f32::to_bits),
                t_packet.map(f32::to_bits),
                "sparse, packet {p}"
            );
            assert_eq!(
                sparse.map(|h| h.map(|h| h.t)),
                got.map(|h| h.map(|h| h.t)),
                "sparse, packet {p}"
            );
            // The portable fallback (single rays) agrees too.
            let mut t_singles = limits;
            let singles = bvh.singles8(&o, &d, active, t_min, &mut t_singles);
            assert_eq!(
                t_singles.map(f32::to_bits),
                t_packet.map(f32::to_bits),
                "packet {p}"
            );
            assert_eq!(
                singles.map(|h| h.map(|h| h.t)),
                got.map(|h| h.map(|h| h.t)),
                "packet {p}"
            );
            compared += active.count_ones() as usize;
        }
    }
    compared
}

/// Primary rays of a pinhole camera at `eye` looking at `at`, in 4x2 pixel tiles (the
/// bench's packets): `n` x `n` pixels, n a multiple of 4, spanning `fov` radians.
fn pinhole_tiles(eye: Vec3, at: Vec3, n: usize, fov: f32) -> Vec<Ray> {
    camera_tiles(eye, at, n, fov, 0.0)
}

/// `pinhole_tiles` with origins spread over the screen too (`spread` = 1: a screen as
/// wide as the view at distance 1), so a packet's origins differ.
fn camera_tiles(eye: Vec3, at: Vec3, n: usize, fov: f32, spread: f32) -> Vec<Ray> {
    let f = (at - eye).normalize();
    let r = f.cross(Vec3::Y).normalize();
    let u = r.cross(f);
    let h = (fov * 0.5).tan();
    let mut rays = Vec::new();
    for ty in (0..n).step_by(2) {
        for tx in (0..n).step_by(4) {
            for k in 0..WIDTH {
                let (i, j) = (tx + (k & 3), ty + (k >> 2));
                let x = (2.0 * (i as f32 + 0.5) / n as f32 - 1.0) * h;
                let y = (1.0 - 2.0 * (j as f32 + 0.5) / n as f32) * h;
                let o = eye + (x * r + y * u) * spread;
                rays.push(Ray::new(o, (f + x * r + y * u).normalize()));
            }
        }
    }
    rays
}

const MASKS: [u8; 5] = [0xff, 0x01, 0x80, 0x5a, 0x00];

#[test]
fn packets_agree_with_single_rays_on_random_meshes() {
    for (n, seed) in [(1, 7), (9, 1), (2000, 13), (20_000, 17)] {
        let (pos, tris) = random_mesh(n, seed);
        let bvh = build_checked(&pos, &tris);
        let mut compared = 0;
        // Coherent tiles from pinholes on every side (all eight sign octants).
        for eye in [
            Vec3::new(0.3, 0.4, 6.0),
            Vec3::new(-5.0, -4.0, -3.0),
            Vec3::new(4.0, -5.0, 2.0),
            Vec3::new(-0.2, 6.0, -4.0),
        ] {
            let rays = pinhole_tiles(eye, Vec3::new(0.1, -0.2, 0.05), 32, 0.9);
            compared += assert_packets_agree(&bvh, &rays, 0.0, &MASKS);
            // Origins differing within a packet (the origin bounds matter), and nearly
            // parallel rays (the reciprocal bounds collapse).
            for (fov, spread) in [(0.9, 2.0), (0.01, 400.0)] {
                let rays = camera_tiles(eye, Vec3::new(-0.1, 0.2, 0.0), 32, fov, spread);
                compared += assert_packets_agree(&bvh, &rays, 0.0, &MASKS);
            }
            // A camera inside the mesh's box, with t_min > 0.
            let inside = pinhole_tiles(eye * 0.05, Vec3::ZERO, 16, 1.2);
            compared += assert_packets_agree(&bvh, &inside, 0.3, &MASKS);
        }
        // Incoherent packets: random origins and directions, mixed signs.
        let rays = rays_toward(Vec3::ZERO, 2.0, 1024, 77 + seed);
        compared += assert_packets_agree(&bvh, &rays, 0.0, &MASKS);
        // Axis-parallel rays (zero direction components) amid coherent ones.
        let mut mixed = pinhole_tiles(Vec3::new(0.0, 0.0, 6.0), Vec3::ZERO, 8, 0.6);
        for (k, r) in mixed.iter_mut().enumerate().step_by(5) {
            *r = Ray::new(r.origin + Vec3::new(0.01 * k as f32, 0.0, 0.0), Vec3::NEG_Z);
        }
        compared += assert_packets_agree(&bvh, &mixed, 0.0, &MASKS);
        assert!(compared > 1000, "{compared} rays compared");
    }
}

/// For tests that call the AVX kernels directly: every CPU the project runs on has AVX, and
/// one without fails here rather than passing without checking anything. The CPU's AVX, not
/// `TRACELAB_SIMD`'s, so they also run when that narrows the kernels.
#[cfg(target_arch = "x86_64")]
fn assert_cpu_has_avx(what: &str) {
    assert!(
        crate::simd::detected() >= crate::simd::Level::Avx,
        "this test checks {what}: run it on a CPU with AVX"
    );
}

/// Pins the guard the result tests cannot see (without it, loose bounds only slow the
/// traversal down): a packet whose rays meeting the mesh differ in direction sign on an
/// axis, or have a zero direction component, is not traced as a packet.
#[cfg(target_arch = "x86_64")]
#[test]
fn packets_with_mixed_signs_or_zero_components_go_one_by_one() {
    assert_cpu_has_avx("the AVX packet path");
    let (pos, tris) = random_mesh(200, 3);
    let bvh = build_checked(&pos, &tris);
    let eye = Vec3::new(0.0, 0.0, 6.0);
    // Eight rays toward points near (0.5, 0.5, 0): every one meets the mesh's box.
    let toward = |k: usize| Vec3::new(0.5 + 0.01 * k as f32, 0.5 - 0.01 * k as f32, 0.0);
    let packet = |dirs: [Vec3; WIDTH]| {
        let o = [Vec3A::from(eye); WIDTH];
        let d: [Vec3A; WIDTH] = dirs.map(Vec3A::from);
        #[allow(unsafe_code)]
        // SAFETY: the CPU has AVX, checked above.
        unsafe { PacketBounds::new(&o, &d, 0xff, &bvh, 0.0, &[f32::INFINITY; WIDTH]) }
            .map(|(_, live)| live)
    };
    let coherent: [Vec3; WIDTH] = std::array::from_fn(|k| toward(k) - eye);
    assert_eq!(packet(coherent), Some(0xff), "a coherent tile is a packet");
    let mut mixed = coherent;
    mixed[3].x = -mixed[3].x;
    assert_eq!(packet(mixed), None, "one ray runs toward -x");
    let mut zero = coherent;
    zero[5].y = 0.0;
    assert_eq!(packet(zero), None, "one ray is parallel to the xz plane");
}

/// The AVX 8-box test returns its unwidened mask early and checks it against the widened
/// one (`avx::slab8`): where they differ, a box grazed within rounding, it must give the
/// widened mask, the SSE test's. Rays aimed at a box's edge put near and far a few ulps
/// apart either way; the test counts the boxes only the widening keeps, so a run that
/// never took that branch fails instead of passing unchecked.
#[cfg(target_arch = "x86_64")]
#[test]
fn the_avx_box_test_keeps_boxes_grazed_within_rounding() {
    use glam::Vec4;

    use super::avx;
    use super::traverse::SlabRay;
    assert_cpu_has_avx("the AVX box test");
    let mut rng = Rng(12345);
    let (mut grazed, mut entered, mut missed) = (0, 0, 0);
    for _ in 0..20_000 {
        let lo = rng.v() * 4.0 - 2.0;
        let hi = lo + rng.v() * 2.0 + Vec3::splat(0.01);
        // A point on the box's edge x = hi.x, y = hi.y, and an origin off the box.
        let edge = Vec3::new(hi.x, hi.y, lo.z + (hi.z - lo.z) * rng.f());
        let o = Vec3A::from(rng.v() * 8.0 - 4.0 + Vec3::new(0.0, 0.0, 6.0));
        let d = Vec3A::from(edge) - o;
        let mut node = wide::Node8 {
            lo: [[Vec4::INFINITY; 2]; 3],
            hi: [[Vec4::NEG_INFINITY; 2]; 3],
            child: [0; WIDTH],
        };
        for a in 0..3 {
            node.lo[a][0][0] = lo[a];
            node.hi[a][0][0] = hi[a];
        }
        let r = SlabRay::new(o, d);
        let (mut near_sse, mut near_avx) = ([0.0; WIDTH], [0.0; WIDTH]);
        let sse = r.slab8(&node, 0.0, f32::INFINITY, &mut near_sse);
        #[allow(unsafe_code)]
        // SAFETY: the CPU has AVX, checked above.
        let avx = unsafe {
            avx::slab8(
                &node,
                r.o,
                r.inv,
                r.toward_neg,
                0.0,
                f32::INFINITY,
                &mut near_avx,
            )
        };
        assert_eq!(avx, sse, "ray {o} + t {d}");
        assert_eq!(near_avx, near_sse);
        // Slot 0's far, as the tests compute it before widening.
        let exit = |a: usize| {
            let plane = if r.toward_neg[a] { lo[a] } else { hi[a] };
            (plane - r.o[a]) * r.inv[a]
        };
        let far = exit(0).min(exit(1)).min(exit(2).min(f32::INFINITY));
        match (sse & 1 != 0, near_sse[0] <= far) {
            (true, false) => grazed += 1,
            (true, true) => entered += 1,
            (false, _) => missed += 1,
        }
    }
    assert!(
        grazed > 0 && entered > 0,
        "grazed {grazed}, entered {entered}, missed {missed}"
    );
}

/// The sparse variant gives up on packets whose rays lie far apart on a fine mesh (and only
/// on those: a dense tile of the same camera stays a packet), with the single rays' hits.
#[cfg(target_arch = "x86_64")]
#[test]
fn sparse_packets_of_rays_far_apart_go_one_by_one() {
    // `closest_hit8` takes the packet path only where the kernels may use AVX.
    assert!(
        has_avx(),
        "this test checks the AVX packet path: run it on a CPU with AVX, without \
         TRACELAB_SIMD=sse"
    );
    let (pos, tris) = random_mesh(20_000, 23);
    let bvh = build_checked(&pos, &tris);
    let eye = Vec3::new(0.3, 0.4, 6.0);
    let gave_up = |rays: &[Ray]| {
        super::packet::GAVE_UP.with(|g| g.set(0));
        assert!(assert_packets_agree(&bvh, rays, 0.0, &[0xff]) > 0);
        super::packet::GAVE_UP.with(|g| g.get())
    };
    // 16×16 pixels over 0.9 rad: a packet spans about a quarter of the view.
    let sparse = gave_up(&pinhole_tiles(eye, Vec3::ZERO, 16, 0.9));
    assert!(sparse > 0, "no sparse packet went one by one");
    // 512×512 over 0.02 rad: eight neighbouring rays, nearly one.
    let dense = gave_up(&pinhole_tiles(eye, Vec3::ZERO, 512, 0.02));
    assert_eq!(dense, 0, "a dense tile went one by one");
}

#[test]
fn packets_on_empty_and_one_triangle_meshes() {
    let rays = pinhole_tiles(Vec3::new(0.2, 0.3, 3.0), Vec3::new(0.3, 0.3, 0.0), 8, 0.8);
    let empty = build_checked(&[], &[]);
    let o: [Vec3A; WIDTH] = std::array::from_fn(|i| rays[i].origin.into());
    let d: [Vec3A; WIDTH] = std::array::from_fn(|i| rays[i].direction.into());
    let mut t_max = [f32::INFINITY; WIDTH];
    assert_eq!(
        empty.closest_hit8(&o, &d, 0xff, 0.0, &mut t_max),
        [None; WIDTH]
    );
    assert_eq!(t_max, [f32::INFINITY; WIDTH]);
    let pos = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
    let one = build_checked(&pos, &[[0, 1, 2]]);
    assert_packets_agree(&one, &rays, 0.0, &MASKS);
    // The middle rays of the tiles do hit the triangle.
    let hits: usize = rays
        .chunks_exact(WIDTH)
        .map(|c| {
            let o: [Vec3A; WIDTH] = std::array::from_fn(|i| c[i].origin.into());
            let d: [Vec3A; WIDTH] = std::array::from_fn(|i| c[i].direction.into());
            let mut t = [f32::INFINITY; WIDTH];
            one.closest_hit8(&o, &d, 0xff, 0.0, &mut t)
                .iter()
                .flatten()
                .count()
        })
        .sum();
    assert!(hits > 0 && hits < rays.len(), "{hits} hits");
}

#[test]
#[ignore = "needs the scanned meshes: TRACELAB_MESHES_DIR, default ../shared/meshes"]
fn shared_meshes_agree_with_brute_force() {
    let dir = crate::test_data::meshes_dir();
    // The dragon is left to the benchmark's checksums: brute force over 871k triangles
    // per ray is too slow for a unit test.
    for (name, rays) in [
        ("cube.obj", 2000),
        ("bunny_1k.obj", 2000),
        ("stanford-bunny.obj", 150),
    ] {
        let mesh =
            crate::format::obj::load_obj(&dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        let bvh = build_checked(&mesh.positions, &mesh.triangles);
        let b = bvh.bounds();
        let radius = b.extent().max_element() * 0.5;
        assert_agrees(
            &mesh.positions,
            &mesh.triangles,
            &bvh,
            &rays_toward(b.center(), radius, rays, 41),
        );
        // Packets: pinhole tiles from two sides, and the incoherent rays.
        for eye in [Vec3::new(0.3, 0.5, 3.0), Vec3::new(-2.0, -1.5, -2.5)] {
            let tiles = pinhole_tiles(b.center() + eye * radius, b.center(), 64, 0.8);
            assert_packets_agree(&bvh, &tiles, 0.0, &MASKS);
        }
        let mixed = rays_toward(b.center(), radius, 512, 43);
        assert_packets_agree(&bvh, &mixed, 0.0, &MASKS);
    }
}

/// The widening factor is 1 + 2γ₃ rounded to f32: three ulps of 1.
#[test]
fn slab_widening_is_one_plus_two_gamma_3() {
    assert_eq!(SLAB_WIDEN, 1.0 + 3.0 * f32::EPSILON);
    let u = 2f64.powi(-24);
    let two_gamma_3 = 2.0 * (3.0 * u / (1.0 - 3.0 * u));
    assert_eq!(SLAB_WIDEN, (1.0 + two_gamma_3) as f32);
}

/// Triangles whose edges overflow (so does the determinant): the AVX leaf test and the
/// scalar one still agree bit for bit, for any t_min; with t_min = 0 they agree with the
/// triangle primitive, whose infinite-determinant test then changes nothing.
#[test]
fn overflowing_triangles_give_the_same_hits_on_every_path() {
    let mut r = Rng(3);
    let mut pos = Vec::new();
    let mut tris = Vec::new();
    for i in 0..400u32 {
        for _ in 0..3 {
            // Half the vertices near the origin, half near ±f32::MAX.
            let scale = if r.f() < 0.5 { 4.0 } else { 3.0e38 };
            pos.push((r.v() * 2.0 - 1.0) * scale);
        }
        tris.push([3 * i, 3 * i + 1, 3 * i + 2]);
    }
    let bvh = build_checked(&pos, &tris);
    let rays = rays_toward(Vec3::ZERO, 4.0, 3000, 19);
    let mut hits = 0;
    for (k, ray) in rays.iter().enumerate() {
        let (o, d) = (ray.origin.into(), ray.direction.into());
        for t_min in [0.0, f32::NEG_INFINITY] {
            let got = bvh.closest_hit(o, d, t_min, f32::INFINITY);
            let portable = bvh.walk_portable::<false>(o, d, t_min, f32::INFINITY);
            assert_eq!(got, portable, "ray {k}, t_min {t_min}");
            hits += got.is_some() as usize;
        }
        let want = brute(&pos, &tris, ray, 0.0).map(|h| h.t.to_bits());
        let got = bvh
            .intersect(ray, 0.0, f32::INFINITY)
            .map(|h| h.t.to_bits());
        assert_eq!(got, want, "ray {k}");
    }
    assert!(hits > 100, "{hits} hits");
}

/// The t ranges a shadow ray is asked about, for a ray whose closest hit from `t_min` on
/// is `first`: unbounded, and when there is a hit, cut exactly at it (t_max is exclusive),
/// one ulp either side, halfway, and from that hit on (the next crossing).
fn shadow_ranges(first: Option<f32>, t_min: f32) -> Vec<(f32, f32)> {
    let mut v = vec![(t_min, f32::INFINITY)];
    if let Some(t) = first {
        for t_max in [t, t.next_down(), t.next_up(), t * 0.5, t * 2.0] {
            v.push((t_min, t_max));
        }
        v.extend([(t, f32::INFINITY), (t.next_down(), t.next_up())]);
    }
    v
}

/// `any_hit` answers `closest_hit(..).is_some()` for every range of `shadow_ranges`, on the
/// path the CPU picks and on the SSE path. Returns (comparisons, of which true).
fn assert_any_hit_agrees(bvh: &TriangleBvh, rays: &[Ray], t_min: f32) -> (usize, usize) {
    let (mut compared, mut hit) = (0, 0);
    for (k, ray) in rays.iter().enumerate() {
        let (o, d) = (ray.origin.into(), ray.direction.into());
        let first = bvh.closest_hit(o, d, t_min, f32::INFINITY).map(|h| h.t);
        for (lo, hi) in shadow_ranges(first, t_min) {
            let want = bvh.closest_hit(o, d, lo, hi).is_some();
            assert_eq!(bvh.any_hit(o, d, lo, hi), want, "ray {k} ({lo}, {hi})");
            let portable = bvh.walk_portable::<false>(o, d, lo, hi).is_some();
            assert_eq!(
                bvh.walk_portable::<true>(o, d, lo, hi).is_some(),
                portable,
                "ray {k} ({lo}, {hi}), SSE path"
            );
            compared += 2;
            hit += want as usize + portable as usize;
        }
    }
    (compared, hit)
}

#[test]
fn any_hit_is_closest_hit_is_some_on_random_meshes() {
    let mut total = (0, 0);
    let mut add = |(c, h): (usize, usize)| {
        total.0 += c;
        total.1 += h;
    };
    for (n, seed) in [(1, 7), (9, 1), (50, 11), (2000, 13), (20_000, 17)] {
        let (pos, tris) = random_mesh(n, seed);
        // Both leaf sizings: one triangle per leaf, and the AVX leaves of up to eight.
        for block in [1, WIDTH as u32] {
            let bvh = TriangleBvh::build_with(&pos, &tris, sah::LeafBlock(block));
            add(assert_any_hit_agrees(
                &bvh,
                &rays_toward(Vec3::ZERO, 2.0, 1500, 99 + seed),
                0.0,
            ));
        }
        // Rays from inside the mesh, axis-parallel ones among them, from a small t_min.
        let bvh = build_checked(&pos, &tris);
        let mut r = Rng(seed + 5);
        let mut rays = Vec::new();
        for _ in 0..150 {
            let o = r.v() * 3.0 - 1.5;
            for d in [Vec3::X, Vec3::NEG_Y, Vec3::Z, r.v() - 0.5] {
                rays.push(Ray::new(o, d));
            }
        }
        add(assert_any_hit_agrees(&bvh, &rays, 1e-4));
    }
    println!("{} any-hit comparisons, {} of them hits", total.0, total.1);
    assert!(total.1 > total.0 / 4 && total.1 < total.0, "{total:?}");
}

/// Overflowing triangles (whose AVX lanes go to the scalar test) and degenerate and
/// non-finite rays: the same answers as the closest hit.
#[test]
fn any_hit_agrees_on_overflowing_triangles_and_odd_rays() {
    let mut r = Rng(3);
    let mut pos = Vec::new();
    let mut tris = Vec::new();
    for i in 0..400u32 {
        for _ in 0..3 {
            let scale = if r.f() < 0.5 { 4.0 } else { 3.0e38 };
            pos.push((r.v() * 2.0 - 1.0) * scale);
        }
        tris.push([3 * i, 3 * i + 1, 3 * i + 2]);
    }
    let bvh = build_checked(&pos, &tris);
    let (compared, hits) =
        assert_any_hit_agrees(&bvh, &rays_toward(Vec3::ZERO, 4.0, 2000, 19), 0.0);
    assert!(hits > 100, "{hits} of {compared}");
    let odd = [
        Ray::new(Vec3::ZERO, Vec3::ZERO),
        Ray::new(Vec3::splat(f32::NAN), Vec3::X),
        Ray::new(Vec3::ZERO, Vec3::new(f32::INFINITY, 0.0, 0.0)),
    ];
    for ray in odd {
        let (o, d) = (ray.origin.into(), ray.direction.into());
        assert!(!bvh.any_hit(o, d, 0.0, f32::INFINITY), "{ray:?}");
        assert!(
            bvh.closest_hit(o, d, 0.0, f32::INFINITY).is_none(),
            "{ray:?}"
        );
    }
    let empty = build_checked(&[], &[]);
    assert!(!empty.any_hit(Vec3A::ZERO, Vec3A::X, 0.0, f32::INFINITY));
}

/// On the scanned meshes, camera-like and random rays.
#[test]
#[ignore = "needs the scanned meshes: TRACELAB_MESHES_DIR, default ../shared/meshes"]
fn any_hit_agrees_on_shared_meshes() {
    let dir = crate::test_data::meshes_dir();
    for name in ["cube.obj", "bunny_1k.obj", "stanford-bunny.obj"] {
        let mesh =
            crate::format::obj::load_obj(&dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        let bvh = build_checked(&mesh.positions, &mesh.triangles);
        let b = bvh.bounds();
        let radius = b.extent().max_element() * 0.5;
        let mut rays = rays_toward(b.center(), radius, 3000, 41);
        rays.extend(pinhole_tiles(
            b.center() + Vec3::new(0.3, 0.5, 3.0) * radius,
            b.center(),
            64,
            0.8,
        ));
        let (compared, hits) = assert_any_hit_agrees(&bvh, &rays, 0.0);
        println!("{name}: {compared} any-hit comparisons, {hits} hits");
        assert!(hits > 0 && hits < compared, "{name}");
    }
}

/// Rays exactly on edges (output7_01d_low_res's 3×3 uniform samples at 12×12 on scene7_01's
/// triangle, whose edge x + y = 0 they meet to the bit, beside a mirrored neighbour sharing
/// that edge): every path (AVX-512, AVX, portable, brute force) decides each tie the same,
/// from above and from below (det of either sign), and a ray turned round hits the same.
#[test]
fn rays_exactly_on_edges_agree_on_every_path_and_both_sides() {
    let pos = vec![
        Vec3::new(-2.0, -2.0, 0.0),
        Vec3::new(1.8, -1.8, 0.0),
        Vec3::new(-1.95, 1.95, 0.0),
        Vec3::new(2.0, 2.0, 0.0),
    ];
    let tris = vec![[0, 1, 2], [3, 2, 1]];
    let bvh = build_checked(&pos, &tris);
    let (n, k) = (12, 3);
    let mut above = Vec::new();
    let mut below = Vec::new();
    for j in 0..n {
        for i in 0..n {
            for s in 0..k * k {
                let sx = ((s % k) as f32 + 0.5) / k as f32;
                let sy = ((s / k) as f32 + 0.5) / k as f32;
                let x = ((i as f32 + sx) / n as f32 - 0.5) * 5.0;
                let y = ((j as f32 + sy) / n as f32 - 0.5) * 5.0;
                above.push(Ray::new(Vec3::new(x, y, 10.0), Vec3::NEG_Z));
                below.push(Ray::new(Vec3::new(x, y, -10.0), Vec3::Z));
            }
        }
    }
    assert_agrees(&pos, &tris, &bvh, &above);
    assert_agrees(&pos, &tris, &bvh, &below);
    let on_edge = above
        .iter()
        .filter(|r| r.origin.x == -r.origin.y && r.origin.x.abs() < 1.8)
        .count();
    assert!(on_edge >= 8, "{on_edge} rays exactly on the edge");
    for (a, b) in above.iter().zip(&below) {
        let hit = |r: &Ray| bvh.intersect(r, 0.0, f32::INFINITY).map(|h| h.triangle);
        assert_eq!(hit(a), hit(b), "{:?}", a.origin);
    }
}

/// A mesh of at most `FLAT_MAX` (16) triangles has no nodes, one more has a tree, and every walk
/// agrees with brute force on both (closest hits on every instruction set, any hit, every
/// hit, packets), for both leaf sizings: the walks start from a flat mesh's leaves.
#[test]
fn small_meshes_are_flat_and_every_walk_agrees() {
    let mut hits = 0;
    for n in [1, 5, 6, 7, 10, 13, 14, 15, 22] {
        // `random_mesh` adds two degenerate triangles: 3 to 24 in all, 16 and 17 among them.
        let (pos, tris) = random_mesh(n, 40 + n as u32);
        let mut r = Rng(7 + n as u32);
        // Rays from all around at points of the triangles, and some at nothing.
        let rays: Vec<Ray> = (0..400)
            .map(|i| {
                let [a, b, c] = tris[i % tris.len()].map(|v| pos[v as usize]);
                let (u, v) = (r.f() * 0.5, r.f() * 0.5);
                let target = a + (b - a) * u + (c - a) * v + (r.v() - 0.5) * 0.2;
                let o = (r.v() * 2.0 - 1.0) * 8.0;
                Ray::new(o, target - o)
            })
            .collect();
        for block in [1, WIDTH as u32] {
            let bvh = TriangleBvh::build_with(&pos, &tris, sah::LeafBlock(block));
            bvh.check_invariants(&pos, &tris)
                .unwrap_or_else(|e| panic!("{} triangles, block {block}: {e}", tris.len()));
            // Up to 16: two leaf tests, the 12-triangle cube among them.
            assert_eq!(
                bvh.nodes.is_empty(),
                tris.len() <= 16,
                "{} triangles: {}",
                tris.len(),
                bvh.shape()
            );
            assert_agrees(&pos, &tris, &bvh, &rays);
            hits += assert_any_hit_agrees(&bvh, &rays, 0.0).1;
            let mut out = Vec::new();
            for (k, ray) in rays.iter().enumerate() {
                out.clear();
                bvh.intersect_all(ray, 0.0, f32::INFINITY, &mut out);
                let mut got: Vec<u32> = out.iter().map(|h| h.triangle).collect();
                got.sort_unstable();
                let want: Vec<u32> = (0..tris.len() as u32)
                    .filter(|&i| {
                        let [a, b, c] = tris[i as usize].map(|v| pos[v as usize]);
                        intersect_triangle(ray, a, b, c, 0.0, f32::INFINITY).is_some()
                    })
                    .collect();
                assert_eq!(got, want, "{} triangles, ray {k}", tris.len());
            }
            let tiles = pinhole_tiles(Vec3::new(0.3, -0.2, 7.0), Vec3::ZERO, 16, 0.9);
            assert_packets_agree(&bvh, &tiles, 0.0, &MASKS);
        }
    }
    assert!(hits > 1000, "{hits} rays hit");
}
