//! Which tiles of a frame no primary ray can hit anything in: the screen rectangle that the
//! bounded objects' world box projects to, widened by a pixel, against each tile's pixel
//! centres. The packet renderer fills a culled tile with the background instead of tracing
//! it (around a model, most of the frame); the single-ray renderer traces every pixel, so
//! the two agreeing bit for bit (`packets_render`) also checks that no pixel that hits was
//! culled.

use glam::DVec3;

use super::camera::screen_point;
use super::compile::CompiledScene;

/// The projected rectangle of a render, or nothing to cull by.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct TileCull {
    /// Screen coordinates (sx, sy as `CameraRays::ray_at` scales them) that rays may hit
    /// through: [sx_min, sx_max] × [sy_min, sy_max]; None when every tile must be traced.
    rect: Option<[f64; 4]>,
    /// One pixel in screen units, the margin each tile's centres are widened by.
    pitch: f64,
    extent: f64,
    size: (u32, u32),
}

impl TileCull {
    pub(super) fn new(scene: &CompiledScene, width: u32, height: u32) -> TileCull {
        let cam = &scene.camera;
        let extent = f64::from(cam.extent);
        let pitch = extent / f64::from(width.max(height).max(1));
        let size = (width, height);
        // Planes are everywhere; a box not finite cannot be projected.
        let b = scene.bvh.bounds();
        if !scene.unbounded.is_empty() || (!b.is_empty() && !b.is_finite()) {
            return TileCull {
                rect: None,
                pitch,
                extent,
                size,
            };
        }
        if b.is_empty() {
            // Nothing bounded and nothing unbounded: every ray misses.
            return TileCull {
                rect: Some([1.0, -1.0, 1.0, -1.0]),
                pitch,
                extent,
                size,
            };
        }
        let (c, d, h, u) = (
            cam.center.as_dvec3(),
            cam.direction.as_dvec3(),
            cam.horizontal.as_dvec3(),
            cam.up.as_dvec3(),
        );
        let mut rect = [
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        for k in 0..8 {
            let pick = |bit: usize, lo: f32, hi: f32| f64::from(if k & bit == 0 { lo } else { hi });
            let corner = DVec3::new(
                pick(1, b.min.x, b.max.x),
                pick(2, b.min.y, b.max.y),
                pick(4, b.min.z, b.max.z),
            );
            let v = corner - c;
            let (depth, x, y) = (v.dot(d), v.dot(h), v.dot(u));
            let (sx, sy) = if cam.perspective {
                // A corner at or behind the eye: the box's projection is unbounded.
                if depth <= 1e-6 * v.length() {
                    return TileCull {
                        rect: None,
                        pitch,
                        extent,
                        size,
                    };
                }
                (x / depth, y / depth)
            } else {
                (x, y)
            };
            rect = [
                rect[0].min(sx),
                rect[1].max(sx),
                rect[2].min(sy),
                rect[3].max(sy),
            ];
        }
        if !rect.iter().all(|v| v.is_finite()) {
            return TileCull {
                rect: None,
                pitch,
                extent,
                size,
            };
        }
        TileCull {
            rect: Some(rect),
            pitch,
            extent,
            size,
        }
    }

    /// Whether a ray through some pixel of the tile [x0, x1) × rows [y0, y1) may hit.
    pub(super) fn may_hit(&self, (x0, y0, x1, y1): (u32, u32, u32, u32)) -> bool {
        let Some([sx0, sx1, sy0, sy1]) = self.rect else {
            return true;
        };
        if x1 <= x0 || y1 <= y0 {
            return false;
        }
        let (w, h) = self.size;
        // The tile's outermost pixel centres (rows count from the top, sy from the bottom).
        let (left, bottom) = screen_point(x0, y1 - 1, w, h);
        let (right, top) = screen_point(x1 - 1, y0, w, h);
        let s = |v: f32| (f64::from(v) - 0.5) * self.extent;
        // A pixel's slack each way: far more than the rays' rounding.
        let m = self.pitch;
        s(right) + m >= sx0 && s(left) - m <= sx1 && s(top) + m >= sy0 && s(bottom) - m <= sy1
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{MeshCache, load_scene, parse_scene};

    fn compiled(text: &str) -> CompiledScene {
        let out = parse_scene(text.as_bytes(), "test", None, &mut MeshCache::new());
        CompiledScene::new(&out.scene.expect("scene parses"))
    }

    const CAMERA: &str = "PerspectiveCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 angle 30 }
        Lights { numLights 0 } Background { color 0 0 0 ambientLight 0 0 0 }
        Materials { numMaterials 1 Material { diffuseColor 1 1 1 } }";

    /// A small sphere at the centre: the middle tile may be hit, the corners not; a sphere
    /// off to the right leaves the left half culled; a plane, or a box around the eye,
    /// culls nothing; an empty scene culls everything.
    #[test]
    fn tiles_away_from_the_objects_are_culled_and_no_others() {
        let sphere = |x: f32| {
            compiled(&format!(
                "{CAMERA} Group {{ numObjects 1 MaterialIndex 0 Sphere {{ center {x} 0 0 radius 0.5 }} }}"
            ))
        };
        let c = TileCull::new(&sphere(0.0), 640, 640);
        assert!(c.may_hit((256, 256, 320, 320)) && c.may_hit((320, 320, 384, 384)));
        assert!(!c.may_hit((0, 0, 64, 64)) && !c.may_hit((576, 576, 640, 640)));
        let c = TileCull::new(&sphere(1.8), 640, 640);
        assert!(!c.may_hit((0, 256, 64, 320)) && c.may_hit((576, 256, 640, 320)));
        let plane = compiled(&format!(
            "{CAMERA} Group {{ numObjects 1 MaterialIndex 0 Plane {{ normal 0 1 0 offset -1 }} }}"
        ));
        assert!(TileCull::new(&plane, 640, 640).may_hit((0, 0, 64, 64)));
        let around = compiled(&format!(
            "{CAMERA} Group {{ numObjects 1 MaterialIndex 0 Sphere {{ center 0 0 9 radius 3 }} }}"
        ));
        assert!(TileCull::new(&around, 640, 640).may_hit((0, 0, 64, 64)));
        let empty = compiled(&format!("{CAMERA} Group {{ numObjects 0 }}"));
        assert!(!TileCull::new(&empty, 640, 640).may_hit((256, 256, 320, 320)));
    }

    /// Every pixel whose own ray hits lies in a tile `may_hit` keeps, for one-pixel tiles
    /// too, on the shipped scenes with both cameras; and some pixels are culled.
    #[test]
    fn no_pixel_that_hits_is_culled() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes");
        let (mut checked, mut culled) = (0, 0);
        let names = [
            "perspective_mesh.txt",
            "nested_transforms.txt",
            "hierarchy.txt",
            "sheared_sphere.txt",
            "flat_transforms.txt",
            "inside_sphere.txt",
            "default.txt",
        ];
        for name in names {
            let path = root.join(name);
            let scene = load_scene(&path, &mut MeshCache::new())
                .into_result()
                .expect("scene loads")
                .0;
            let mut c = CompiledScene::new(&scene);
            for ortho in [false, true] {
                if ortho {
                    let cam = c.camera;
                    c.camera = super::super::CameraRays {
                        perspective: false,
                        extent: 6.0,
                        ..cam
                    };
                }
                let (w, h) = (90u32, 70u32);
                let cull = TileCull::new(&c, w, h);
                for row in 0..h {
                    for x in 0..w {
                        let ray = c.camera.pixel_ray(x, row, w, h);
                        let keep = cull.may_hit((x, row, x + 1, row + 1));
                        if c.intersect(&ray, c.camera.t_min(), f32::INFINITY).is_some() {
                            assert!(keep, "{name} ortho={ortho} pixel ({x}, {row})");
                            checked += 1;
                        }
                        culled += usize::from(!keep);
                    }
                }
            }
        }
        assert!(
            checked > 1000 && culled > 1000,
            "hits checked {checked}, pixels culled {culled}"
        );
    }
}
