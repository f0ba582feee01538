//! A BVH over a mesh's triangles, with the triangles stored in leaf order as (v0, e1, e2)
//! so a leaf test touches contiguous memory and skips two subtractions per triangle.

use glam::Vec3;
use rayon::prelude::*;

use super::Bvh;
use crate::geometry::{Aabb, Ray};

#[derive(Clone, Copy, Debug, PartialEq)]
struct Tri {
    v0: Vec3,
    e1: Vec3,
    e2: Vec3,
}

impl Tri {
    /// Two-sided Möller–Trumbore: the ray parameter of a hit, if any.
    #[inline]
    fn hit(&self, o: Vec3, d: Vec3) -> Option<f32> {
        let p = d.cross(self.e2);
        let det = self.e1.dot(p);
        if det == 0.0 {
            return None;
        }
        let inv_det = 1.0 / det;
        let s = o - self.v0;
        let u = s.dot(p) * inv_det;
        if !(0.0..=1.0).contains(&u) {
            return None;
        }
        let q = s.cross(self.e1);
        let v = d.dot(q) * inv_det;
        if v < 0.0 || u + v > 1.0 {
            return None;
        }
        Some(self.e2.dot(q) * inv_det)
    }
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleBvh {
    bvh: Bvh,
    /// Triangles in leaf order; `bvh.indices[i]` is the original index of `tris[i]`.
    tris: Vec<Tri>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    pub t: f32,
    /// Index of the triangle in the mesh's own order.
    pub triangle: u32,
}

impl TriangleBvh {
    pub fn build(positions: &[Vec3], triangles: &[[u32; 3]]) -> TriangleBvh {
        let vert = |i: u32| positions.get(i as usize).copied().unwrap_or(Vec3::ZERO);
        let bounds: Vec<Aabb> = triangles
            .par_iter()
            .map(|t| Aabb::EMPTY.grow(vert(t[0])).grow(vert(t[1])).grow(vert(t[2])))
            .collect();
        let bvh = Bvh::build(&bounds);
        let tris: Vec<Tri> = bvh
            .indices
            .par_iter()
            .map(|&i| {
                let t = triangles[i as usize];
                let (a, b, c) = (vert(t[0]), vert(t[1]), vert(t[2]));
                Tri { v0: a, e1: b - a, e2: c - a }
            })
            .collect();
        TriangleBvh { bvh, tris }
    }

    /// Checks the BVH invariants against the mesh it was built from (for tests): every
    /// triangle in exactly one leaf, children inside their parents' bounds.
    pub fn check_invariants(&self, positions: &[Vec3], triangles: &[[u32; 3]]) -> Result<(), String> {
        let vert = |i: u32| positions.get(i as usize).copied().unwrap_or(Vec3::ZERO);
        let bounds: Vec<Aabb> =
            triangles.iter().map(|t| Aabb::EMPTY.grow(vert(t[0])).grow(vert(t[1])).grow(vert(t[2]))).collect();
        self.bvh.check_invariants(&bounds)
    }

    /// Every hit with t in (t_min, t_max), in no particular order, appended to `out`. CSG
    /// needs all crossings of a closed mesh along a ray, not just the nearest.
    pub fn intersect_all(&self, ray: &Ray, t_min: f32, t_max: f32, out: &mut Vec<TriangleHit>) {
        let nodes = &self.bvh.nodes;
        if nodes.is_empty() {
            return;
        }
        let (o, d) = (ray.origin, ray.direction);
        let inv = d.recip();
        let mut stack = vec![0usize];
        while let Some(idx) = stack.pop() {
            let node = &nodes[idx];
            if node.bounds().hit(o, inv, t_min, t_max).is_none() {
                continue;
            }
            if node.count > 0 {
                let first = node.right_or_first as usize;
                for k in first..first + node.count as usize {
                    if let Some(t) = self.tris[k].hit(o, d) {
                        if t > t_min && t < t_max {
                            out.push(TriangleHit { t, triangle: self.bvh.indices[k] });
                        }
                    }
                }
            } else {
                stack.push(idx + 1);
                stack.push(node.right_or_first as usize);
            }
        }
    }

    pub fn bounds(&self) -> Aabb {
        self.bvh.bounds()
    }

    /// Bytes held by the BVH and its triangle copies.
    pub fn memory_bytes(&self) -> usize {
        self.bvh.nodes.len() * std::mem::size_of::<super::BvhNode>()
            + self.bvh.indices.len() * 4
            + self.tris.len() * std::mem::size_of::<Tri>()
    }

    /// Closest hit in (t_min, t_max). Two-sided Möller–Trumbore.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_min: f32, t_max: f32) -> Option<TriangleHit> {
        let mut best: Option<u32> = None;
        let nodes = &self.bvh.nodes;
        if nodes.is_empty() {
            return None;
        }
        let o = ray.origin;
        let d = ray.direction;
        let inv = d.recip();
        let mut t_best = t_max;
        let mut stack = [0u32; 64];
        let mut sp = 0usize;
        let mut idx = 0usize;
        if nodes[0].bounds().hit(o, inv, t_min, t_best).is_none() {
            return None;
        }
        loop {
            let node = &nodes[idx];
            if node.count > 0 {
                let first = node.right_or_first as usize;
                for k in first..first + node.count as usize {
                    let tri = &self.tris[k];
                    let p = d.cross(tri.e2);
                    let det = tri.e1.dot(p);
                    if det == 0.0 {
                        continue;
                    }
                    let inv_det = 1.0 / det;
                    let s = o - tri.v0;
                    let u = s.dot(p) * inv_det;
                    if !(0.0..=1.0).contains(&u) {
                        continue;
                    }
                    let q = s.cross(tri.e1);
                    let v = d.dot(q) * inv_det;
                    if v < 0.0 || u + v > 1.0 {
                        continue;
                    }
                    let t = tri.e2.dot(q) * inv_det;
                    if t > t_min && t < t_best {
                        t_best = t;
                        best = Some(k as u32);
                    }
                }
            } else {
                let l = idx + 1;
                let r = node.right_or_first as usize;
                let tl = nodes[l].bounds().hit(o, inv, t_min, t_best);
                let tr = nodes[r].bounds().hit(o, inv, t_min, t_best);
                match (tl, tr) {
                    (Some(a), Some(b)) => {
                        let (near, far) = if a <= b { (l, r) } else { (r, l) };
                        if sp < stack.len() {
                            stack[sp] = far as u32;
                            sp += 1;
                        }
                        idx = near;
                        continue;
                    }
                    (Some(_), None) => {
                        idx = l;
                        continue;
                    }
                    (None, Some(_)) => {
                        idx = r;
                        continue;
                    }
                    (None, None) => {}
                }
            }
            loop {
                if sp == 0 {
                    return best.map(|k| TriangleHit { t: t_best, triangle: self.bvh.indices[k as usize] });
                }
                sp -= 1;
                let n = stack[sp] as usize;
                if nodes[n].bounds().hit(o, inv, t_min, t_best).is_some() {
                    idx = n;
                    break;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::intersect_triangle;

    fn random_mesh(n: usize, seed: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let mut s = seed.max(1);
        let mut rnd = || {
            s ^= s << 13;
            s ^= s >> 17;
            s ^= s << 5;
            s as f32 / u32::MAX as f32
        };
        let mut pos = Vec::new();
        let mut tris = Vec::new();
        for i in 0..n {
            let c = Vec3::new(rnd(), rnd(), rnd()) * 4.0 - 2.0;
            for _ in 0..3 {
                pos.push(c + (Vec3::new(rnd(), rnd(), rnd()) - 0.5) * 0.6);
            }
            let b = (3 * i) as u32;
            tris.push([b, b + 1, b + 2]);
        }
        // A degenerate triangle too.
        pos.push(Vec3::ZERO);
        let z = (pos.len() - 1) as u32;
        tris.push([z, z, z]);
        (pos, tris)
    }

    fn brute(pos: &[Vec3], tris: &[[u32; 3]], ray: &Ray) -> Option<TriangleHit> {
        let mut best: Option<TriangleHit> = None;
        for (i, t) in tris.iter().enumerate() {
            let lim = best.map_or(f32::INFINITY, |b| b.t);
            if let Some((th, _, _)) =
                intersect_triangle(ray, pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize], 0.0, lim)
            {
                best = Some(TriangleHit { t: th, triangle: i as u32 });
            }
        }
        best
    }

    #[test]
    fn random_rays_agree_with_brute_force() {
        for (n, seed) in [(1, 7), (50, 11), (2000, 13)] {
            let (pos, tris) = random_mesh(n, seed);
            let bvh = TriangleBvh::build(&pos, &tris);
            bvh.check_invariants(&pos, &tris).expect("invariants");
            let mut s = 99u32;
            let mut rnd = || {
                s ^= s << 13;
                s ^= s >> 17;
                s ^= s << 5;
                s as f32 / u32::MAX as f32
            };
            for _ in 0..2000 {
                let o = Vec3::new(rnd(), rnd(), rnd()) * 8.0 - 4.0;
                let target = Vec3::new(rnd(), rnd(), rnd()) * 3.0 - 1.5;
                let ray = Ray::new(o, target - o);
                let a = bvh.intersect(&ray, 0.0, f32::INFINITY);
                let b = brute(&pos, &tris, &ray);
                match (a, b) {
                    (None, None) => {}
                    (Some(a), Some(b)) => {
                        assert!((a.t - b.t).abs() <= 1e-5 * b.t.abs().max(1.0), "t {a:?} vs {b:?}");
                        if a.triangle != b.triangle {
                            // Ties between coincident triangles are fine if t matches.
                            assert!((a.t - b.t).abs() < 1e-6);
                        }
                    }
                    _ => panic!("bvh {a:?} vs brute {b:?}"),
                }
            }
        }
    }

    #[test]
    fn intersect_all_finds_every_crossing() {
        let (pos, tris) = random_mesh(500, 5);
        let bvh = TriangleBvh::build(&pos, &tris);
        let mut out = Vec::new();
        for k in 0..200 {
            let o = Vec3::new(-5.0, (k as f32 * 0.37).sin() * 1.5, (k as f32 * 0.11).cos() * 1.5);
            let ray = Ray::new(o, Vec3::new(1.0, 0.01 * k as f32 - 1.0, 0.3));
            out.clear();
            bvh.intersect_all(&ray, 0.0, f32::INFINITY, &mut out);
            let mut got: Vec<u32> = out.iter().map(|h| h.triangle).collect();
            got.sort_unstable();
            let want: Vec<u32> = (0..tris.len() as u32)
                .filter(|&i| {
                    let t = tris[i as usize];
                    let (a, b, c) = (pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize]);
                    intersect_triangle(&ray, a, b, c, 0.0, f32::INFINITY).is_some()
                })
                .collect();
            assert_eq!(got, want, "ray {k}");
        }
    }

    #[test]
    fn empty_mesh_never_hits() {
        let bvh = TriangleBvh::build(&[], &[]);
        assert!(bvh.intersect(&Ray::new(Vec3::ZERO, Vec3::X), 0.0, f32::INFINITY).is_none());
    }
}
