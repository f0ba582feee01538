//! Solid textures at a hit point (assignment 6): Ken Perlin's improved noise, the
//! turbulence N(x) the handout sums from it, and each texture's weight between its two
//! materials. The choices the handout leaves open are in README.md, "Solid textures".

use glam::{DMat4, DVec3};

use crate::scene::{SolidTexture, TextureKind};

/// Ken Perlin's permutation of 0..=255 from his reference implementation of improved noise
/// (2002), so the noise is the one the course provides.
const PERMUTATION: [u8; 256] = [
    151, 160, 137, 91, 90, 15, 131, 13, 201, 95, 96, 53, 194, 233, 7, 225, 140, 36, 103, 30, 69,
    142, 8, 99, 37, 240, 21, 10, 23, 190, 6, 148, 247, 120, 234, 75, 0, 26, 197, 62, 94, 252, 219,
    203, 117, 35, 11, 32, 57, 177, 33, 88, 237, 149, 56, 87, 174, 20, 125, 136, 171, 168, 68, 175,
    74, 165, 71, 134, 139, 48, 27, 166, 77, 146, 158, 231, 83, 111, 229, 122, 60, 211, 133, 230,
    220, 105, 92, 41, 55, 46, 245, 40, 244, 102, 143, 54, 65, 25, 63, 161, 1, 216, 80, 73, 209, 76,
    132, 187, 208, 89, 18, 169, 200, 196, 135, 130, 116, 188, 159, 86, 164, 100, 109, 198, 173,
    186, 3, 64, 52, 217, 226, 250, 124, 123, 5, 202, 38, 147, 118, 126, 255, 82, 85, 212, 207, 206,
    59, 227, 47, 16, 58, 17, 182, 189, 28, 42, 223, 183, 170, 213, 119, 248, 152, 2, 44, 154, 163,
    70, 221, 153, 101, 155, 167, 43, 172, 9, 129, 22, 39, 253, 19, 98, 108, 110, 79, 113, 224, 232,
    178, 185, 112, 104, 218, 246, 97, 228, 251, 34, 242, 193, 238, 210, 144, 12, 191, 179, 162,
    241, 81, 51, 145, 235, 249, 14, 239, 107, 49, 192, 214, 31, 181, 199, 106, 157, 184, 84, 204,
    176, 115, 121, 50, 45, 127, 4, 150, 254, 138, 236, 205, 93, 222, 114, 67, 29, 24, 72, 243, 141,
    128, 195, 78, 66, 215, 61, 156, 180,
];

/// The table read twice over, as Perlin's `p[512]` (indices up to 511 without wrapping).
fn p(i: usize) -> usize {
    usize::from(PERMUTATION[i & 255])
}

fn fade(t: f64) -> f64 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

fn lerp(t: f64, a: f64, b: f64) -> f64 {
    a + t * (b - a)
}

/// The dot product of (x, y, z) with one of the 12 cube-edge gradients `hash` picks.
fn grad(hash: usize, x: f64, y: f64, z: f64) -> f64 {
    let h = hash & 15;
    let u = if h < 8 { x } else { y };
    let v = if h < 4 {
        y
    } else if h == 12 || h == 14 {
        x
    } else {
        z
    };
    (if h & 1 == 0 { u } else { -u }) + (if h & 2 == 0 { v } else { -v })
}

/// Perlin's improved noise at `q`: 0 on the integer lattice, within about ±1, period 256.
pub fn perlin_noise(q: DVec3) -> f64 {
    let f = q.floor();
    // The lattice cell modulo 256; `rem_euclid` keeps negative and huge cells in range.
    let cell = |v: f64| v.rem_euclid(256.0) as usize & 255;
    let (xi, yi, zi) = (cell(f.x), cell(f.y), cell(f.z));
    let DVec3 { x, y, z } = q - f;
    let (u, v, w) = (fade(x), fade(y), fade(z));
    let a = p(xi) + yi;
    let (aa, ab) = (p(a) + zi, p(a + 1) + zi);
    let b = p(xi + 1) + yi;
    let (ba, bb) = (p(b) + zi, p(b + 1) + zi);
    lerp(
        w,
        lerp(
            v,
            lerp(u, grad(p(aa), x, y, z), grad(p(ba), x - 1.0, y, z)),
            lerp(
                u,
                grad(p(ab), x, y - 1.0, z),
                grad(p(bb), x - 1.0, y - 1.0, z),
            ),
        ),
        lerp(
            v,
            lerp(
                u,
                grad(p(aa + 1), x, y, z - 1.0),
                grad(p(ba + 1), x - 1.0, y, z - 1.0),
            ),
            lerp(
                u,
                grad(p(ab + 1), x, y - 1.0, z - 1.0),
                grad(p(bb + 1), x - 1.0, y - 1.0, z - 1.0),
            ),
        ),
    )
}

/// The handout's N(x) = Σ_{i<octaves} noise(2^i x) / 2^i.
pub fn turbulence(q: DVec3, octaves: u32) -> f64 {
    (0..octaves)
        .map(|i| {
            let s = f64::from(i).exp2();
            perlin_noise(q * s) / s
        })
        .sum()
}

/// The handout's checkerboard: unit cells of texture space, material A where
/// floor(x) + floor(y) + floor(z) is even, B where it is odd.
pub fn checker_is_b(q: DVec3) -> bool {
    let f = q.floor();
    // Each floor is an integer-valued f64, so their sum's parity is exact below 2^53; past
    // that every f64 is even, and cells no longer mean anything.
    (f.x.rem_euclid(2.0) + f.y.rem_euclid(2.0) + f.z.rem_euclid(2.0)) % 2.0 == 1.0
}

/// A texture ready for hits: its matrix composed once.
#[derive(Clone, Debug)]
pub struct CompiledTexture {
    pub kind: TextureKind,
    pub texture_from_world: DMat4,
    /// Materials A and B (indices into the compiled materials).
    pub materials: [u32; 2],
    pub octaves: u32,
    pub frequency: f64,
    pub amplitude: f64,
}

impl CompiledTexture {
    pub fn new(t: &SolidTexture) -> Self {
        CompiledTexture {
            kind: t.kind,
            texture_from_world: t.texture_from_world(),
            materials: t.materials,
            octaves: t.octaves,
            frequency: f64::from(t.frequency),
            amplitude: f64::from(t.amplitude),
        }
    }

    /// How much of material B the world point `p` gets, in [0, 1] (0: all A, 1: all B); a
    /// Checkerboard gives exactly 0 or 1.
    pub fn weight(&self, p: glam::Vec3) -> f32 {
        let q = self.texture_from_world.transform_point3(p.as_dvec3());
        let w = match self.kind {
            TextureKind::Checkerboard => return if checker_is_b(q) { 1.0 } else { 0.0 },
            // N is within about ±1 (±2 summed over octaves) and mostly within ±0.5: centred
            // on an even blend, clamped. Noise and Marble give material A the weight
            // 0.5 + N and (1 + sin)/2, so B the rest, as the students' programs that agree
            // on output7_03a do (README, "Solid textures").
            TextureKind::Noise => 0.5 - turbulence(q, self.octaves),
            TextureKind::Marble => {
                let s = self.frequency * q.x + self.amplitude * turbulence(q, self.octaves);
                0.5 - 0.5 * s.sin()
            }
            // Rings about the texture's y axis, bent by N.
            TextureKind::Wood => {
                let r = (q.x * q.x + q.z * q.z).sqrt();
                let s = self.frequency * r + self.amplitude * turbulence(q, self.octaves);
                0.5 + 0.5 * s.sin()
            }
        };
        // A NaN (a point at infinity) blends evenly rather than poisoning the colour.
        if w.is_nan() {
            0.5
        } else {
            w.clamp(0.0, 1.0) as f32
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_is_a_permutation() {
        let mut seen = [false; 256];
        for &v in &PERMUTATION {
            assert!(!seen[usize::from(v)], "{v} twice");
            seen[usize::from(v)] = true;
        }
    }

    #[test]
    // 3.14 is Perlin's own example point, not an approximation of π.
    #[allow(clippy::approx_constant)]
    fn noise_matches_perlins_reference_values() {
        // The value Perlin's Java reference prints for its own example point, and values
        // computed from the published algorithm (in Python, f64).
        let cases = [
            (DVec3::new(3.14, 42.0, 7.0), 0.13691995878400012),
            (DVec3::new(0.5, 0.5, 0.5), -0.25),
            (DVec3::new(1.25, 2.5, 3.75), -0.03836345672607422),
            (DVec3::new(-0.3, 0.7, -1.9), 0.43756943182041597),
            (DVec3::new(10.1, -20.2, 30.3), 0.3410360150525964),
        ];
        for (q, want) in cases {
            let got = perlin_noise(q);
            assert!((got - want).abs() < 1e-12, "noise{q} = {got}, want {want}");
        }
    }

    #[test]
    fn noise_is_zero_on_the_lattice_bounded_and_periodic() {
        for q in [
            DVec3::ZERO,
            DVec3::new(3.0, -7.0, 12.0),
            DVec3::splat(-300.0),
        ] {
            assert_eq!(perlin_noise(q), 0.0);
        }
        let mut state = 0x2545_f491_u64;
        let mut r = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64 * 200.0 - 100.0
        };
        for _ in 0..20_000 {
            let q = DVec3::new(r(), r(), r());
            let n = perlin_noise(q);
            assert!(n.abs() <= 1.05, "noise{q} = {n}");
            assert!((perlin_noise(q + DVec3::new(256.0, -512.0, 0.0)) - n).abs() < 1e-9);
            let t = turbulence(q, 8);
            assert!(t.abs() <= 2.1, "N{q} = {t}");
        }
        assert_eq!(turbulence(DVec3::new(0.3, 0.4, 0.5), 0), 0.0);
        let q = DVec3::new(0.3, 0.4, 0.5);
        let two = perlin_noise(q) + perlin_noise(q * 2.0) / 2.0;
        assert!((turbulence(q, 2) - two).abs() < 1e-15);
    }

    #[test]
    fn checker_cells_alternate_by_floor_parity() {
        assert!(!checker_is_b(DVec3::new(0.5, 0.5, 0.5)));
        assert!(checker_is_b(DVec3::new(1.5, 0.5, 0.5)));
        assert!(checker_is_b(DVec3::new(0.5, -0.5, 0.5)));
        assert!(!checker_is_b(DVec3::new(1.5, 1.5, 0.5)));
        assert!(checker_is_b(DVec3::new(-0.5, -0.5, -0.5)));
        assert!(!checker_is_b(DVec3::new(-1.5, 0.5, 0.5)));
        // Each step of one cell along any axis flips the material.
        for i in -4..4 {
            let q = DVec3::new(f64::from(i) + 0.5, 0.25, 0.75);
            assert_ne!(checker_is_b(q), checker_is_b(q + DVec3::X));
            assert_ne!(checker_is_b(q), checker_is_b(q + DVec3::Y));
            assert_ne!(checker_is_b(q), checker_is_b(q + DVec3::Z));
        }
        assert!(!checker_is_b(DVec3::splat(1e300)));
    }

    #[test]
    fn the_transform_scales_the_cells() {
        use crate::scene::TransformOp;
        let mut t = SolidTexture::new(TextureKind::Checkerboard, 0, 1);
        t.transform = Some(vec![TransformOp::UniformScale(2.0)]);
        let c = CompiledTexture::new(&t);
        // Texture point = 2·world: cells half a world unit wide.
        assert_eq!(c.weight(glam::Vec3::new(0.25, 0.1, 0.1)), 0.0);
        assert_eq!(c.weight(glam::Vec3::new(0.75, 0.1, 0.1)), 1.0);
        assert_eq!(c.weight(glam::Vec3::new(1.25, 0.1, 0.1)), 0.0);
        let plain = CompiledTexture::new(&SolidTexture::new(TextureKind::Checkerboard, 0, 1));
        assert_eq!(plain.weight(glam::Vec3::new(0.75, 0.1, 0.1)), 0.0);
        // A translation moves the pattern: texture = world + (1, 0, 0).
        t.transform = Some(vec![TransformOp::Translate(glam::Vec3::X)]);
        let moved = CompiledTexture::new(&t);
        assert_eq!(moved.weight(glam::Vec3::new(0.5, 0.1, 0.1)), 1.0);
    }

    #[test]
    fn weights_stay_in_the_unit_interval() {
        for kind in TextureKind::ALL {
            let mut t = SolidTexture::new(kind, 0, 1);
            t.octaves = t.octaves.min(5);
            let c = CompiledTexture::new(&t);
            for i in 0..500 {
                let x = i as f32 * 0.037 - 9.0;
                let w = c.weight(glam::Vec3::new(x, x * 0.7 + 1.0, -x * 1.3));
                assert!((0.0..=1.0).contains(&w), "{kind:?} {w}");
            }
            assert!((0.0..=1.0).contains(&c.weight(glam::Vec3::INFINITY)));
        }
        // Marble with no noise is the pure sine of x: 0.5 at x = 0; where sin is 1 it is
        // all A (weight of B 0), where sin is -1 all B.
        let mut m = SolidTexture::new(TextureKind::Marble, 0, 1);
        m.octaves = 0;
        m.frequency = 1.0;
        let c = CompiledTexture::new(&m);
        assert!((c.weight(glam::Vec3::new(0.0, 5.0, 5.0)) - 0.5).abs() < 1e-6);
        let top = c.weight(glam::Vec3::new(std::f32::consts::FRAC_PI_2, 0.0, 0.0));
        assert!(top.abs() < 1e-6, "{top}");
        let bottom = c.weight(glam::Vec3::new(-std::f32::consts::FRAC_PI_2, 0.0, 0.0));
        assert!((bottom - 1.0).abs() < 1e-6, "{bottom}");
        // Noise: 0.5 + N is A's weight, so B's is 0.5 - N (0.5 on the lattice, where N = 0).
        let mut n = SolidTexture::new(TextureKind::Noise, 0, 1);
        n.octaves = 3;
        let c = CompiledTexture::new(&n);
        assert!((c.weight(glam::Vec3::new(1.0, 2.0, 3.0)) - 0.5).abs() < 1e-6);
        let q = glam::Vec3::new(0.3, 0.7, 0.2);
        let expect = (0.5 - turbulence(q.as_dvec3(), 3)).clamp(0.0, 1.0) as f32;
        assert!((c.weight(q) - expect).abs() < 1e-6);
    }
}
