//! A packet's mesh hits shaded eight at a time. Each lane does exactly what `shade_fast`
//! does for one pixel (the same IEEE operations in the same order: no fused multiply-adds,
//! no reassociation), written as loops over eight lanes so the compiler turns each step
//! into one vector instruction: the three square roots and divisions of a pixel (its ray's,
//! its face normal's, its world normal's) cost one of each for eight. Lanes that hit
//! anything but a mesh, and every lane under the depth rules that move the hit point, go
//! through `shade_fast` itself.
//!
//! Two builds of the same loops: AVX (eight lanes a register) where the CPU has it, SSE
//! (four) elsewhere; `TRACELAB_SIMD=sse` forces the narrower one, so tests run both.

use glam::Vec3;

use super::compile::{CompiledScene, Hit, Shape};
use super::shade::shade_fast;
use super::{NormalTransform, ObjectRays, RenderSettings};
use crate::geometry::{Ray, triangle_normal};

const N: usize = 8;
type Lanes = [f32; N];

/// Three lanes' worth of vectors, one array per component.
#[derive(Clone, Copy, Default)]
struct V3 {
    x: Lanes,
    y: Lanes,
    z: Lanes,
}

/// What the lane loops are given and give back; `run` picks the build.
type Kernel = fn(&Input, Vec3, &[(Vec3, Vec3)], bool) -> Shaded;

/// Colour and world normal of each lane that hit (zeros elsewhere), as `shade_fast` gives.
pub(super) fn shade_packet(
    scene: &CompiledScene,
    rays: &[Ray; N],
    hits: &[Option<Hit>; N],
    settings: &RenderSettings,
) -> [(Vec3, Vec3); N] {
    shade_packet_with(scene, rays, hits, settings, run)
}

#[inline(always)]
fn shade_packet_with(
    scene: &CompiledScene,
    rays: &[Ray; N],
    hits: &[Option<Hit>; N],
    settings: &RenderSettings,
    kernel: Kernel,
) -> [(Vec3, Vec3); N] {
    let mut out = [(Vec3::ZERO, Vec3::ZERO); N];
    // A packet that misses everything (the background around a model) needs no lane inputs.
    if hits.iter().all(Option::is_none) {
        return out;
    }
    let mut input = Input::default();
    for k in 0..N {
        let Some(hit) = &hits[k] else { continue };
        let o = scene.objects.get(hit.object as usize);
        match o.map(|o| &o.shape) {
            Some(Shape::Mesh(m)) if settings.object_rays == ObjectRays::Unnormalized => {
                input.set(
                    k,
                    rays[k].direction,
                    m.triangle(hit.prim),
                    scene.hit_color(hit),
                );
                let xf = o.and_then(|o| o.xf.as_ref());
                match (xf, settings.normal_transform) {
                    (None, _) => {}
                    (Some(xf), NormalTransform::Correct) => {
                        input.set_matrix(k, xf.normal_from_object.to_cols_array())
                    }
                    (Some(xf), NormalTransform::Incorrect) => {
                        let (x, y, z) = (
                            xf.world_from_object.x_axis,
                            xf.world_from_object.y_axis,
                            xf.world_from_object.z_axis,
                        );
                        input.set_matrix(k, [x.x, x.y, x.z, y.x, y.y, y.z, z.x, z.y, z.z]);
                    }
                }
            }
            _ => out[k] = shade_fast(scene, &rays[k], hit, settings),
        }
    }
    if input.lanes == 0 {
        return out;
    }
    let shaded = kernel(&input, scene.ambient, &scene.lights, settings.shade_back);
    for (k, o) in out.iter_mut().enumerate() {
        if input.lanes & (1 << k) != 0 {
            *o = (
                Vec3::new(shaded.color.x[k], shaded.color.y[k], shaded.color.z[k]),
                Vec3::new(shaded.normal.x[k], shaded.normal.y[k], shaded.normal.z[k]),
            );
        }
    }
    out
}

/// What the lanes need, gathered from the scene.
#[derive(Clone, Copy, Default)]
struct Input {
    /// Lanes to shade here.
    lanes: u8,
    /// 1 in the lanes with a normal matrix, else 0: a float per lane, so that choosing
    /// between the two normals compiles to one blend, not a branch per lane.
    transformed: Lanes,
    dir: V3,
    a: V3,
    b: V3,
    c: V3,
    kd: V3,
    /// The normal matrix's columns, x_axis.xyz, y_axis.xyz, z_axis.xyz.
    m: [Lanes; 9],
}

impl Input {
    fn set(&mut self, k: usize, dir: Vec3, [a, b, c]: [Vec3; 3], kd: Vec3) {
        self.lanes |= 1 << k;
        for (v, p) in [
            (&mut self.dir, dir),
            (&mut self.a, a),
            (&mut self.b, b),
            (&mut self.c, c),
            (&mut self.kd, kd),
        ] {
            (v.x[k], v.y[k], v.z[k]) = (p.x, p.y, p.z);
        }
    }
    fn set_matrix(&mut self, k: usize, cols: [f32; 9]) {
        self.transformed[k] = 1.0;
        for (row, v) in self.m.iter_mut().zip(cols) {
            row[k] = v;
        }
    }
}

struct Shaded {
    color: V3,
    normal: V3,
}

fn run(input: &Input, ambient: Vec3, lights: &[(Vec3, Vec3)], shade_back: bool) -> Shaded {
    #[cfg(target_arch = "x86_64")]
    if crate::simd::level() >= crate::simd::Level::Avx {
        #[allow(unsafe_code)]
        // SAFETY: the CPU has AVX, checked just above.
        return unsafe { run_avx(input, ambient, lights, shade_back) };
    }
    lanes(input, ambient, lights, shade_back)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
fn run_avx(input: &Input, ambient: Vec3, lights: &[(Vec3, Vec3)], shade_back: bool) -> Shaded {
    lanes(input, ambient, lights, shade_back)
}

#[inline(always)]
fn map(f: impl Fn(usize) -> f32) -> Lanes {
    std::array::from_fn(f)
}

/// `Vec3::dot`: (x·x') + (y·y') + (z·z'), left to right.
#[inline(always)]
fn dot(a: &V3, b: &V3) -> Lanes {
    map(|k| (a.x[k] * b.x[k]) + (a.y[k] * b.y[k]) + (a.z[k] * b.z[k]))
}

/// `Vec3::normalize_or`: v · (1 / √(v·v)) where that reciprocal is finite and positive, else
/// the fallback.
#[inline(always)]
fn normalize_or(v: &V3, fallback: &V3) -> V3 {
    let d = dot(v, v);
    let rcp = map(|k| 1.0 / d[k].sqrt());
    // Finite and positive, as 0 < r < ∞ (false for NaN): two compares and an and, where
    // `is_finite() && > 0.0` compiled to a branch per lane.
    let ok = map(|k| {
        if (rcp[k] > 0.0) & (rcp[k] < f32::INFINITY) {
            1.0
        } else {
            0.0
        }
    });
    let pick = |v: &Lanes, f: &Lanes| map(|k| if ok[k] != 0.0 { v[k] * rcp[k] } else { f[k] });
    V3 {
        x: pick(&v.x, &fallback.x),
        y: pick(&v.y, &fallback.y),
        z: pick(&v.z, &fallback.z),
    }
}

#[inline(always)]
fn lanes(input: &Input, ambient: Vec3, lights: &[(Vec3, Vec3)], shade_back: bool) -> Shaded {
    let sub = |p: &V3, q: &V3| V3 {
        x: map(|k| p.x[k] - q.x[k]),
        y: map(|k| p.y[k] - q.y[k]),
        z: map(|k| p.z[k] - q.z[k]),
    };
    // `triangle_normal`: (b − a) × (c − a), `normalize_or_zero`.
    let (e1, e2) = (sub(&input.b, &input.a), sub(&input.c, &input.a));
    let cross = V3 {
        x: map(|k| e1.y[k] * e2.z[k] - e2.y[k] * e1.z[k]),
        y: map(|k| e1.z[k] * e2.x[k] - e2.z[k] * e1.x[k]),
        z: map(|k| e1.x[k] * e2.y[k] - e2.x[k] * e1.y[k]),
    };
    let mut n_obj = normalize_or(&cross, &V3::default());
    // Where f32 gave up (zero: overflow, underflow or a degenerate triangle),
    // `triangle_normal` takes its f64 path: the same call gives the same bits.
    for k in 0..N {
        let zero = n_obj.x[k] == 0.0 && n_obj.y[k] == 0.0 && n_obj.z[k] == 0.0;
        if zero && input.lanes & (1 << k) != 0 {
            let at = |v: &V3| Vec3::new(v.x[k], v.y[k], v.z[k]);
            let n = triangle_normal(at(&input.a), at(&input.b), at(&input.c));
            (n_obj.x[k], n_obj.y[k], n_obj.z[k]) = (n.x, n.y, n.z);
        }
    }
    // The normal matrix times n: (x_axis·n.x + y_axis·n.y) + z_axis·n.z, both rules' order
    // (`Mat3::mul_vec3`, and `Mat4::transform_vector3` up to the commuted first sum).
    let m = &input.m;
    let row = |i: usize| {
        map(|k| (m[i][k] * n_obj.x[k]) + (m[3 + i][k] * n_obj.y[k]) + (m[6 + i][k] * n_obj.z[k]))
    };
    let moved = normalize_or(
        &V3 {
            x: row(0),
            y: row(1),
            z: row(2),
        },
        &n_obj,
    );
    let t = &input.transformed;
    let keep = |a: &Lanes, b: &Lanes| map(|k| if t[k] != 0.0 { a[k] } else { b[k] });
    let normal = V3 {
        x: keep(&moved.x, &n_obj.x),
        y: keep(&moved.y, &n_obj.y),
        z: keep(&moved.z, &n_obj.z),
    };

    // `shade::lit`: black for a back face unless shade_back turns the normal to the eye.
    let facing = dot(&input.dir, &normal);
    let back = map(|k| if facing[k] > 0.0 { 1.0 } else { 0.0 });
    let flip = |v: &Lanes| map(|k| if back[k] != 0.0 { -v[k] } else { v[k] });
    let n = V3 {
        x: flip(&normal.x),
        y: flip(&normal.y),
        z: flip(&normal.z),
    };
    let kd = &input.kd;
    let mut c = V3 {
        x: map(|k| ambient.x * kd.x[k]),
        y: map(|k| ambient.y * kd.y[k]),
        z: map(|k| ambient.z * kd.z[k]),
    };
    for &(l, color) in lights {
        let d = map(|k| (l.x * n.x[k]) + (l.y * n.y[k]) + (l.z * n.z[k]));
        let d = map(|k| d[k].max(0.0));
        c.x = map(|k| c.x[k] + (d[k] * color.x) * kd.x[k]);
        c.y = map(|k| c.y[k] + (d[k] * color.y) * kd.y[k]);
        c.z = map(|k| c.z[k] + (d[k] * color.z) * kd.z[k]);
    }
    if shade_back {
        return Shaded { color: c, normal };
    }
    let black = |v: &Lanes| map(|k| if back[k] != 0.0 { 0.0 } else { v[k] });
    Shaded {
        color: V3 {
            x: black(&c.x),
            y: black(&c.y),
            z: black(&c.z),
        },
        normal,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::compile::CompiledScene;
    use crate::{MeshCache, load_scene};

    fn run_sse(input: &Input, ambient: Vec3, lights: &[(Vec3, Vec3)], shade_back: bool) -> Shaded {
        lanes(input, ambient, lights, shade_back)
    }

    #[cfg(target_arch = "x86_64")]
    fn run_avx_here(
        input: &Input,
        ambient: Vec3,
        lights: &[(Vec3, Vec3)],
        shade_back: bool,
    ) -> Shaded {
        assert!(std::arch::is_x86_feature_detected!("avx"));
        #[allow(unsafe_code)]
        // SAFETY: the CPU has AVX, asserted just above.
        unsafe {
            run_avx(input, ambient, lights, shade_back)
        }
    }

    fn bits(v: Vec3) -> [u32; 3] {
        v.to_array().map(f32::to_bits)
    }

    /// Both builds of the lane loops give `shade_fast`'s colour and normal bit for bit (the
    /// floats, before quantising) on a scene of two transformed meshes, planes, two lights
    /// and uneven colours, under both normal rules, with and without shade_back.
    #[test]
    fn both_builds_equal_shade_fast_bit_for_bit() {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/perspective_mesh.txt");
        let scene = load_scene(&path, &mut MeshCache::new())
            .into_result()
            .expect("scene loads")
            .0;
        let c = CompiledScene::new(&scene);
        let (w, h) = (96u32, 72u32);
        let rays = c.camera.pixel_rays(w, h);
        let mut kernels: Vec<(&str, Kernel)> = vec![("sse", run_sse)];
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx") {
            kernels.push(("avx", run_avx_here));
        }
        let mut mesh_lanes = 0;
        for normal_transform in [NormalTransform::Correct, NormalTransform::Incorrect] {
            for shade_back in [false, true] {
                let s = RenderSettings {
                    shade_back,
                    normal_transform,
                    ..RenderSettings::new(w, h)
                };
                for row in (0..h).step_by(2) {
                    for x in (0..w).step_by(4) {
                        let r: [Ray; N] = std::array::from_fn(|k| {
                            rays.row(row + k as u32 / 4).ray(x + k as u32 % 4)
                        });
                        let hits = c.intersect8(&r, 0xff, c.camera.t_min(), f32::INFINITY);
                        for (name, kernel) in &kernels {
                            let got = shade_packet_with(&c, &r, &hits, &s, *kernel);
                            for k in 0..N {
                                let Some(hit) = &hits[k] else { continue };
                                mesh_lanes +=
                                    matches!(c.objects[hit.object as usize].shape, Shape::Mesh(_))
                                        as usize;
                                let (cw, nw) = shade_fast(&c, &r[k], hit, &s);
                                assert_eq!(
                                    (bits(got[k].0), bits(got[k].1)),
                                    (bits(cw), bits(nw)),
                                    "{name} {s:?} lane {k} at ({x}, {row})"
                                );
                            }
                        }
                    }
                }
            }
        }
        assert!(
            mesh_lanes > 1000,
            "the meshes cover too little of the image: {mesh_lanes}"
        );
    }
}
