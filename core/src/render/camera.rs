//! Primary rays, with the course's conventions: pixel centres, j = 0 at the bottom, and for
//! non-square images the larger dimension spans the camera's size or angle (square pixels,
//! the smaller dimension cropped symmetrically).

use glam::Vec3;

use crate::geometry::Ray;
use crate::scene::{Camera, unit};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraRays {
    pub center: Vec3,
    /// Unit view direction.
    pub direction: Vec3,
    /// Unit screen right and up (up made perpendicular to the direction).
    pub horizontal: Vec3,
    pub up: Vec3,
    /// Orthographic: full size of the screen. Perspective: 2·tan(angle/2).
    pub extent: f32,
    pub perspective: bool,
}

impl CameraRays {
    pub fn new(camera: &Camera) -> Self {
        let (center, dir, up, extent, perspective) = match *camera {
            Camera::Orthographic {
                center,
                direction,
                up,
                size,
            } => (center, direction, up, size, false),
            Camera::Perspective {
                center,
                direction,
                up,
                angle,
            } => (
                center,
                direction,
                up,
                2.0 * (angle.to_radians() * 0.5).tan(),
                true,
            ),
        };
        // Overflow-safe: a direction of 0 0 -3e38 is just -z.
        let direction = unit(dir).unwrap_or(Vec3::NEG_Z);
        let horizontal = direction
            .cross(unit(up).unwrap_or(Vec3::Y))
            .normalize_or(Vec3::X);
        let up = horizontal.cross(direction);
        CameraRays {
            center,
            direction,
            horizontal,
            up,
            extent,
            perspective,
        }
    }

    /// Orthographic rays must find hits behind the camera centre (scene1_07 relies on it).
    pub fn t_min(&self) -> f32 {
        if self.perspective {
            0.0
        } else {
            f32::NEG_INFINITY
        }
    }

    /// The ray through screen point (x, y) in [0, 1]², y up.
    pub fn ray_at(&self, x: f32, y: f32) -> Ray {
        let (sx, sy) = ((x - 0.5) * self.extent, (y - 0.5) * self.extent);
        if self.perspective {
            let d = self.direction + sx * self.horizontal + sy * self.up;
            Ray::new(self.center, d.normalize())
        } else {
            Ray::new(
                self.center + sx * self.horizontal + sy * self.up,
                self.direction,
            )
        }
    }

    /// The ray through the centre of pixel (i, row) of a width × height image, rows counted
    /// from the top as images store them.
    pub fn pixel_ray(&self, i: u32, row: u32, width: u32, height: u32) -> Ray {
        let (x, y) = screen_point(i, row, width, height);
        self.ray_at(x, y)
    }

    /// The per-column half of every `pixel_ray` of a width × height image, computed once, so
    /// a frame's rays cost no division but the normalisation's.
    pub fn pixel_rays(&self, width: u32, height: u32) -> PixelRays {
        let columns: Vec<Vec3> = (0..width)
            .map(|i| {
                let (x, _) = screen_point(i, 0, width, height);
                let sx = (x - 0.5) * self.extent;
                // The first addition of `ray_at`, in its order, so the sum stays bit-identical.
                if self.perspective {
                    self.direction + sx * self.horizontal
                } else {
                    self.center + sx * self.horizontal
                }
            })
            .collect();
        let rows = (0..height)
            .map(|row| {
                let (_, y) = screen_point(0, row, width, height);
                ((y - 0.5) * self.extent) * self.up
            })
            .collect();
        let soa = [0, 1, 2].map(|a| columns.iter().map(|c: &Vec3| c[a]).collect());
        PixelRays {
            camera: *self,
            columns,
            soa,
            rows,
        }
    }
}

/// `CameraRays::pixel_ray` for one image size with the columns' share precomputed; its rays
/// are bit for bit those of `pixel_ray` (a test checks it).
#[derive(Clone, Debug)]
pub struct PixelRays {
    camera: CameraRays,
    /// Perspective: direction + sx·horizontal; orthographic: centre + sx·horizontal.
    columns: Vec<Vec3>,
    /// `columns` component by component, for loading eight columns at once.
    soa: [Vec<f32>; 3],
    /// sy·up of each row (counted from the top).
    rows: Vec<Vec3>,
}

/// One row's share of `PixelRays`: sy·up.
#[derive(Clone, Copy, Debug)]
pub struct RowRays<'a> {
    camera: &'a CameraRays,
    columns: &'a [Vec3],
    soa: &'a [Vec<f32>; 3],
    sy_up: Vec3,
}

impl PixelRays {
    /// The rays of row `row` (counted from the top).
    #[inline]
    pub fn row(&self, row: u32) -> RowRays<'_> {
        let sy_up = self
            .rows
            .get(row as usize)
            .or(self.rows.last())
            .copied()
            .unwrap_or(Vec3::ZERO);
        RowRays {
            camera: &self.camera,
            columns: &self.columns,
            soa: &self.soa,
            sy_up,
        }
    }
}

impl RowRays<'_> {
    /// All rays of the row into `out` (cleared first), in one tight loop: with no traversal
    /// between them, each ray's square root and division overlap the next ray's.
    pub fn fill(&self, out: &mut Vec<Ray>) {
        out.clear();
        self.fill_range(0, self.columns.len() as u32, out);
    }

    /// The rays of columns `x0..x1` (within the row) appended to `out`. With AVX a
    /// perspective camera's rays are made eight at a time (`avx::fill`).
    pub fn fill_range(&self, x0: u32, x1: u32, out: &mut Vec<Ray>) {
        let x1 = x1.min(self.columns.len() as u32);
        let x0 = x0.min(x1);
        #[cfg(target_arch = "x86_64")]
        if self.camera.perspective && crate::simd::level() >= crate::simd::Level::Avx {
            #[allow(unsafe_code)]
            // SAFETY: the CPU has AVX, checked just above.
            unsafe {
                avx::fill(self, x0 as usize, x1 as usize, out)
            };
            return;
        }
        out.extend((x0..x1).map(|i| self.ray(i)));
    }

    /// The ray through pixel `i` of this row (`pixel_ray`'s, bit for bit); the origin for i
    /// past the width.
    #[inline]
    pub fn ray(&self, i: u32) -> Ray {
        if self.camera.perspective {
            Ray::new(self.camera.center, self.unnormalised(i).normalize())
        } else {
            let a = self.columns.get(i as usize).copied().unwrap_or(Vec3::ZERO);
            Ray::new(a + self.sy_up, self.camera.direction)
        }
    }

    /// A perspective ray's direction before it is normalised.
    #[inline]
    fn unnormalised(&self, i: u32) -> Vec3 {
        self.columns.get(i as usize).copied().unwrap_or(Vec3::ZERO) + self.sy_up
    }
}

/// Perspective rays eight at a time. Bit for bit the scalar rays: glam's `normalize` is
/// x·x + y·y + z·z, its square root, 1 / that and three products, each IEEE-exact in every
/// lane, so eight lanes give the scalar bits (a test checks it). The inputs are loaded
/// from the long-lived columns, not from a just-written array: 16-byte loads across 4-byte
/// stores failed store forwarding and made a first version slower than the scalar loop.
/// Only runs of a row gain (`tracelab bench`'s rows, the editor's full pass per tile row):
/// gathering a packet's eight pixels into lanes made the editor's frame 2% slower
/// (`docs/perf.md`).
#[cfg(target_arch = "x86_64")]
mod avx {
    use std::arch::x86_64::*;

    use glam::Vec3;

    use super::{Ray, RowRays};

    /// Unit directions of eight lanes (x, y, z) as eight floats per component.
    #[target_feature(enable = "avx")]
    #[inline]
    fn normalized_lanes(x: __m256, y: __m256, z: __m256) -> [[f32; 8]; 3] {
        let (add, mul) = (_mm256_add_ps, _mm256_mul_ps);
        let dot = add(add(mul(x, x), mul(y, y)), mul(z, z));
        let r = _mm256_div_ps(_mm256_set1_ps(1.0), _mm256_sqrt_ps(dot));
        [mul(x, r), mul(y, r), mul(z, r)].map(|m| {
            let mut a = [0.0f32; 8];
            #[allow(unsafe_code)]
            // SAFETY: `a` holds eight floats; the store is unaligned.
            unsafe {
                _mm256_storeu_ps(a.as_mut_ptr(), m)
            };
            a
        })
    }

    /// `RowRays::fill_range` for a perspective camera (`x0 <= x1 <= ` the row's width).
    #[target_feature(enable = "avx")]
    pub(super) fn fill(r: &RowRays, x0: usize, x1: usize, out: &mut Vec<Ray>) {
        let up = [r.sy_up.x, r.sy_up.y, r.sy_up.z].map(|u| _mm256_set1_ps(u));
        let mut x0 = x0;
        while x0 + 8 <= x1 {
            let column = |a: usize| {
                let row = r.soa[a]
                    .get(x0..x0 + 8)
                    .and_then(|s| <&[f32; 8]>::try_from(s).ok());
                #[allow(unsafe_code)]
                // SAFETY: eight contiguous floats, what an unaligned 256-bit load reads.
                row.map_or(up[a], |s| unsafe { _mm256_loadu_ps(s.as_ptr()) })
            };
            let x = _mm256_add_ps(column(0), up[0]);
            let y = _mm256_add_ps(column(1), up[1]);
            let z = _mm256_add_ps(column(2), up[2]);
            let [dx, dy, dz] = normalized_lanes(x, y, z);
            let center = r.camera.center;
            out.extend((0..8).map(|k| Ray::new(center, Vec3::new(dx[k], dy[k], dz[k]))));
            x0 += 8;
        }
        out.extend((x0 as u32..x1 as u32).map(|i| r.ray(i)));
    }
}

/// Screen coordinates of pixel (i, row): ((i+0.5)/W, (j+0.5)/H) with j = H−1−row counted from
/// the bottom, cropped to square pixels for non-square images.
pub fn screen_point(i: u32, row: u32, width: u32, height: u32) -> (f32, f32) {
    let s = width.max(height) as f32;
    let j = height - 1 - row.min(height - 1);
    let x = (i as f32 + 0.5 + (s - width as f32) * 0.5) / s;
    let y = (j as f32 + 0.5 + (s - height as f32) * 0.5) / s;
    (x, y)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn square_pixels_sample_centres_bottom_up() {
        assert_eq!(screen_point(0, 1, 2, 2), (0.25, 0.25));
        assert_eq!(screen_point(1, 0, 2, 2), (0.75, 0.75));
    }

    #[test]
    fn wide_images_crop_vertically() {
        // 4×2: the width spans the screen; rows sit in the middle half.
        let (x, y) = screen_point(0, 1, 4, 2);
        assert_eq!((x, y), (0.125, 0.375));
        let (_, y) = screen_point(0, 0, 4, 2);
        assert_eq!(y, 0.625);
    }

    #[test]
    fn orthographic_basis_follows_course() {
        let c = CameraRays::new(&Camera::Orthographic {
            center: Vec3::new(0.0, 0.0, 10.0),
            direction: Vec3::NEG_Z,
            up: Vec3::Y,
            size: 4.0,
        });
        let r = c.ray_at(1.0, 0.5);
        assert!((r.origin - Vec3::new(2.0, 0.0, 10.0)).length() < 1e-6);
        assert_eq!(c.t_min(), f32::NEG_INFINITY);
    }

    #[test]
    fn row_rays_equal_pixel_rays_bit_for_bit() {
        let cams = [
            Camera::Perspective {
                center: Vec3::new(0.3, 0.8, 5.0),
                direction: Vec3::new(0.1, -0.2, -1.0),
                up: Vec3::Y,
                angle: 30.0,
            },
            Camera::Orthographic {
                center: Vec3::new(0.0, 1.0, 10.0),
                direction: Vec3::new(0.0, 0.3, -1.0),
                up: Vec3::Y,
                size: 4.5,
            },
        ];
        for cam in &cams {
            let c = CameraRays::new(cam);
            for (w, h) in [(1, 1), (7, 3), (3, 7), (800, 800), (640, 480)] {
                let rays = c.pixel_rays(w, h);
                let mut filled = Vec::new();
                for row in 0..h {
                    let r = rays.row(row);
                    r.fill(&mut filled);
                    assert_eq!(filled.len(), w as usize);
                    for i in 0..w {
                        assert_eq!(
                            r.ray(i),
                            c.pixel_ray(i, row, w, h),
                            "{w}x{h} pixel ({i}, {row})"
                        );
                        assert_eq!(
                            filled[i as usize],
                            r.ray(i),
                            "fill, {w}x{h} pixel ({i}, {row})"
                        );
                    }
                    // Ranges that start off the eight-lane grid, and past the width.
                    for (x0, x1) in [(3, 12), (1, w), (w / 2, w + 9), (w, w + 1)] {
                        let mut part = vec![Ray::new(Vec3::ZERO, Vec3::X)];
                        r.fill_range(x0, x1, &mut part);
                        let want = x1.min(w).saturating_sub(x0.min(w)) as usize;
                        assert_eq!(part.len(), 1 + want, "{w}x{h} {x0}..{x1}");
                        for (k, ray) in part[1..].iter().enumerate() {
                            assert_eq!(*ray, r.ray(x0 + k as u32), "{w}x{h} {x0}..{x1} +{k}");
                        }
                    }
                }
            }
        }
    }
}
