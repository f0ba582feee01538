//! The result of a render: per pixel, the quantised colour and normal views, the hit t (the
//! depth view is made from it for any range) and the node hit (for picking).

use glam::Vec3;

use crate::memory::{OutOfMemory, try_vec, try_with_capacity};

/// One pixel's results.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    pub color: [u8; 3],
    pub normal: [u8; 3],
    /// World ray parameter of the hit; `f32::INFINITY` for a miss.
    pub t: f32,
    /// Raw `NodeId` of the object hit; `u32::MAX` for a miss.
    pub node: u32,
}

impl Sample {
    pub const UNSET: Sample = Sample {
        color: [0; 3],
        normal: [0; 3],
        t: f32::INFINITY,
        node: u32::MAX,
    };
    pub fn is_hit(&self) -> bool {
        self.node != u32::MAX
    }
    /// The pixel's bytes in one view; `depth` is (min, max) for the depth view.
    #[inline]
    pub fn rgb8(&self, view: View, depth: (f32, f32)) -> [u8; 3] {
        match view {
            View::Color => self.color,
            View::Normals => self.normal,
            View::Depth => {
                let g = if self.is_hit() {
                    quantize(depth_shade(self.t, depth.0, depth.1))
                } else {
                    0
                };
                [g, g, g]
            }
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum View {
    Color,
    Normals,
    Depth,
}

/// Pixels stored in image order: row 0 is the top of the picture.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    pub width: u32,
    pub height: u32,
    pub samples: Vec<Sample>,
}

/// The course's quantiser: byte = clamp(⌊c·255⌋, 0, 255).
#[inline]
pub fn quantize(c: f32) -> u8 {
    (c * 255.0).clamp(0.0, 255.0) as u8
}

/// Depth view shade: (max − t)/(max − min) clamped to [0, 1]; t < min is white, t > max black.
/// In f32 where both differences are f32 numbers (so ordinary ranges shade as they always
/// have), else in f64, where they cannot overflow: `--depth -3e38 3e38` is a gradient too.
#[inline]
pub fn depth_shade(t: f32, min: f32, max: f32) -> f32 {
    if max == min {
        return if t <= min { 1.0 } else { 0.0 };
    }
    let (num, den) = (max - t, max - min);
    if num.is_finite() && den.is_finite() {
        return (num / den).clamp(0.0, 1.0);
    }
    let (t, min, max) = (f64::from(t), f64::from(min), f64::from(max));
    (((max - t) / (max - min)).clamp(0.0, 1.0)) as f32
}

impl Frame {
    pub fn new(width: u32, height: u32) -> Self {
        Frame {
            width,
            height,
            samples: vec![Sample::UNSET; width as usize * height as usize],
        }
    }

    /// [`Frame::new`], or an error where the samples do not fit in memory.
    pub fn try_new(width: u32, height: u32) -> Result<Self, OutOfMemory> {
        Ok(Frame {
            width,
            height,
            samples: try_vec(
                width as usize * height as usize,
                Sample::UNSET,
                "the frame's samples",
            )?,
        })
    }

    /// Bytes a `width` × `height` frame takes.
    pub fn bytes(width: u32, height: u32) -> u64 {
        u64::from(width) * u64::from(height) * std::mem::size_of::<Sample>() as u64
    }

    pub fn get(&self, x: u32, row: u32) -> Option<&Sample> {
        if x >= self.width || row >= self.height {
            return None;
        }
        self.samples
            .get(row as usize * self.width as usize + x as usize)
    }

    /// RGB8 bytes of one view, rows top to bottom. `depth` is (min, max) for the depth view.
    pub fn rgb8(&self, view: View, depth: (f32, f32)) -> Vec<u8> {
        let mut out = Vec::with_capacity(self.samples.len() * 3);
        self.rgb8_into(view, depth, &mut out);
        out
    }

    /// [`Frame::rgb8`], or an error where the bytes do not fit in memory.
    pub fn try_rgb8(&self, view: View, depth: (f32, f32)) -> Result<Vec<u8>, OutOfMemory> {
        let mut out = try_with_capacity(self.samples.len() * 3, "the image's bytes")?;
        self.rgb8_into(view, depth, &mut out);
        Ok(out)
    }

    fn rgb8_into(&self, view: View, depth: (f32, f32), out: &mut Vec<u8>) {
        for s in &self.samples {
            out.extend_from_slice(&s.rgb8(view, depth));
        }
    }

    /// RGBA8 bytes (opaque) of one view, for textures.
    pub fn rgba8(&self, view: View, depth: (f32, f32)) -> Vec<u8> {
        let rgb = self.rgb8(view, depth);
        let mut out = Vec::with_capacity(rgb.len() / 3 * 4);
        for p in rgb.chunks_exact(3) {
            out.extend_from_slice(&[p[0], p[1], p[2], 255]);
        }
        out
    }
}

/// Stores a pixel's results into `dst` field by field. Built whole and then copied, the
/// sample went through the stack: its narrow stores (the byte arrays) read back as one 16-byte
/// load, a failed store forward costing about a quarter of a frame's time (docs/perf.md).
#[inline(always)]
pub(super) fn write_sample(dst: &mut Sample, color: Vec3, normal: Vec3, t: f32, node: u32) {
    dst.color = quantize3(color);
    dst.normal = quantize3(normal.abs());
    dst.t = t;
    dst.node = node;
}

/// `quantize` of each component, the three at once (SSE2, which every x86_64 CPU has):
/// ×255, max with 0 (which also turns NaN into 0, as `NaN as u8` does), min with 255, then
/// truncation: `quantize`'s steps in its order, so its result (tested on every edge case).
#[inline(always)]
fn quantize3(v: Vec3) -> [u8; 3] {
    #[cfg(target_arch = "x86_64")]
    #[allow(unsafe_code)]
    // SAFETY: SSE2 is part of every x86_64 CPU (the target's baseline), and these
    // intrinsics work on registers only, touching no memory.
    unsafe {
        use std::arch::x86_64::*;
        let x = _mm_mul_ps(_mm_setr_ps(v.x, v.y, v.z, 0.0), _mm_set1_ps(255.0));
        // maxps gives its second operand when the first is NaN.
        let x = _mm_min_ps(_mm_max_ps(x, _mm_setzero_ps()), _mm_set1_ps(255.0));
        let words = _mm_packs_epi32(_mm_cvttps_epi32(x), _mm_setzero_si128());
        let [r, g, b, _] = (_mm_cvtsi128_si32(_mm_packus_epi16(words, words)) as u32).to_le_bytes();
        [r, g, b]
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        [quantize(v.x), quantize(v.y), quantize(v.z)]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The three-at-once quantiser gives the course's byte for the edge cases (NaN, the
    /// infinities, signed zeros, values either side of every clamp and rounding edge) and a
    /// sweep through [-0.5, 1.5].
    #[test]
    fn quantize3_is_quantize_for_every_input() {
        let mut xs = vec![
            f32::NAN,
            -f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            0.0,
            -0.0,
            f32::MIN_POSITIVE,
            -f32::MIN_POSITIVE,
            1e-45,
            1.0,
            1.0 - f32::EPSILON,
            1.0 + f32::EPSILON,
            0.5,
            254.5 / 255.0,
            1.0 / 255.0,
            0.999_999_9 / 255.0,
            f32::MAX,
            f32::MIN,
            1e10,
            -1e10,
            8_388_608.0,
        ];
        xs.extend((0..=200_000).map(|i| -0.5 + i as f32 * 1e-5));
        for w in xs.chunks(3) {
            let v = Vec3::new(w[0], *w.get(1).unwrap_or(&0.25), *w.get(2).unwrap_or(&-3.0));
            assert_eq!(
                quantize3(v),
                [quantize(v.x), quantize(v.y), quantize(v.z)],
                "{v:?}"
            );
        }
    }

    /// A range whose width overflows f32 (`--depth 3e38 -3e38`, or -3e38 3e38) still maps
    /// depth to a gradient (it was black everywhere: (max − min) was ±inf), and ranges whose
    /// differences are f32 numbers keep their f32 quotient bit for bit.
    #[test]
    fn depth_ranges_wider_than_f32_still_shade() {
        assert_eq!(depth_shade(0.0, 3e38, -3e38), 0.5);
        assert_eq!(depth_shade(0.0, -3e38, 3e38), 0.5);
        assert_eq!(depth_shade(-3e38, -3e38, 3e38), 1.0);
        assert_eq!(depth_shade(3e38, -3e38, 3e38), 0.0);
        let near = depth_shade(1.5e38, -3e38, 3e38);
        assert!((near - 0.25).abs() < 1e-6, "{near}");
        // t itself so far off that max − t overflows.
        assert_eq!(depth_shade(-3e38, 0.0, 3e38), 1.0);
        for (t, min, max) in [
            (9.5f32, 8.0f32, 12.0f32),
            (3.3, 1.0, 7.7),
            (1e20, -1e20, 3e20),
        ] {
            let f32_quotient = ((max - t) / (max - min)).clamp(0.0, 1.0);
            assert_eq!(depth_shade(t, min, max).to_bits(), f32_quotient.to_bits());
        }
    }
}
