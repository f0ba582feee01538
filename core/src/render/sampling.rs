//! Assignment 7's samplers: where inside a pixel its samples lie. Positions are in the unit
//! square of the pixel, x to the right and y up (the course's `Sample::getPosition`).
//!
//! Uniform and jittered sampling need a square count (k × k cells, as the handout's `k²`
//! grids); random sampling takes any count. Random numbers come from a counter-based hash of
//! (seed, pixel, sample, axis), so a position does not depend on the order or the thread the
//! pixels are rendered in, and the same seed gives the same image.

use glam::Vec2;
use thiserror::Error;

/// The seed used when none is given, so a course line gives the same image every time.
pub const DEFAULT_SEED: u64 = 6837;
/// Most samples one pixel may take (256 × 256): the course's largest is 36.
pub const MAX_SAMPLES_PER_PIXEL: u32 = 65_536;
/// Most samples one image may take (width × height × samples per pixel): each keeps its colour
/// (12 bytes) until the filter has used it, so this bounds that store at 768 MiB.
pub const MAX_FILM_SAMPLES: u64 = 1 << 26;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SamplerKind {
    /// A k × k grid of cell centres, (a + ½)/k.
    Uniform,
    /// Independent uniform positions in the pixel.
    Random,
    /// One uniform position in each cell of a k × k grid.
    Jittered,
}

impl SamplerKind {
    /// The course's flag for this sampler, for messages.
    pub fn course_flag(self) -> &'static str {
        match self {
            SamplerKind::Uniform => "-uniform_samples",
            SamplerKind::Random => "-random_samples",
            SamplerKind::Jittered => "-jittered_samples",
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            SamplerKind::Uniform => "uniform",
            SamplerKind::Random => "random",
            SamplerKind::Jittered => "jittered",
        }
    }
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "uniform" => Some(SamplerKind::Uniform),
            "random" => Some(SamplerKind::Random),
            "jittered" => Some(SamplerKind::Jittered),
            _ => None,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Error)]
pub enum SamplerError {
    #[error("expected a whole number of samples from 1 to {MAX_SAMPLES_PER_PIXEL}, found {0}")]
    Count(u64),
    #[error(
        "{count} samples is not a square number: {kind} sampling puts k × k samples in a pixel \
         (1, 4, 9, 16, ...; the nearest are {below} and {above})",
        kind = .kind.name()
    )]
    NotSquare {
        kind: SamplerKind,
        count: u32,
        below: u32,
        above: u32,
    },
    #[error(
        "{width}x{height} pixels with {count} samples each is {total} samples: at most \
         {MAX_FILM_SAMPLES} are allowed in one image"
    )]
    TooManyInAll {
        width: u32,
        height: u32,
        count: u32,
        total: u64,
    },
}

/// How many samples each pixel takes and where they lie.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Sampler {
    kind: SamplerKind,
    count: u32,
    /// Cells per side for uniform and jittered sampling.
    side: u32,
    seed: u64,
}

impl Default for Sampler {
    /// The handout's default: one sample at the centre of the pixel.
    fn default() -> Self {
        Sampler {
            kind: SamplerKind::Uniform,
            count: 1,
            side: 1,
            seed: DEFAULT_SEED,
        }
    }
}

impl Sampler {
    /// A sampler of `count` samples a pixel, checked: 1 to [`MAX_SAMPLES_PER_PIXEL`], and a
    /// square for uniform and jittered sampling.
    pub fn new(kind: SamplerKind, count: u32, seed: u64) -> Result<Self, SamplerError> {
        if count == 0 || count > MAX_SAMPLES_PER_PIXEL {
            return Err(SamplerError::Count(u64::from(count)));
        }
        let side = count.isqrt();
        if kind != SamplerKind::Random && side * side != count {
            return Err(SamplerError::NotSquare {
                kind,
                count,
                below: side * side,
                above: (side + 1) * (side + 1),
            });
        }
        Ok(Sampler {
            kind,
            count,
            side,
            seed,
        })
    }

    pub fn kind(&self) -> SamplerKind {
        self.kind
    }
    pub fn count(&self) -> u32 {
        self.count
    }
    pub fn seed(&self) -> u64 {
        self.seed
    }
    /// The same sampler with another seed.
    pub fn with_seed(self, seed: u64) -> Self {
        Sampler { seed, ..self }
    }

    /// Refuses a `width` × `height` image whose samples would pass [`MAX_FILM_SAMPLES`].
    pub fn check_image(&self, width: u32, height: u32) -> Result<(), SamplerError> {
        let total = u64::from(width) * u64::from(height) * u64::from(self.count);
        if total > MAX_FILM_SAMPLES {
            return Err(SamplerError::TooManyInAll {
                width,
                height,
                count: self.count,
                total,
            });
        }
        Ok(())
    }

    /// Position of sample `n` (0-based, below `count`) of the pixel numbered `pixel`, in the
    /// pixel's unit square, each coordinate in [0, 1).
    pub fn position(&self, pixel: u64, n: u32) -> Vec2 {
        let cell = |n: u32| Vec2::new((n % self.side.max(1)) as f32, (n / self.side.max(1)) as f32);
        let k = self.side.max(1) as f32;
        match self.kind {
            SamplerKind::Uniform => (cell(n) + Vec2::splat(0.5)) / k,
            SamplerKind::Random => Vec2::new(self.uniform(pixel, n, 0), self.uniform(pixel, n, 1)),
            SamplerKind::Jittered => {
                let u = Vec2::new(self.uniform(pixel, n, 0), self.uniform(pixel, n, 1));
                // (a + u)/k rounds up to exactly 1 only where u is within an ulp of 1.
                ((cell(n) + u) / k).min(Vec2::splat(ONE_BELOW_1))
            }
        }
    }

    /// A number in [0, 1) fixed by (seed, pixel, sample, axis).
    fn uniform(&self, pixel: u64, n: u32, axis: u32) -> f32 {
        let h = mix(mix(mix(self.seed) ^ pixel) ^ (u64::from(n) << 1 | u64::from(axis)));
        // The top 24 bits: every value is an exact f32 below 1.
        (h >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
    }
}

/// The largest f32 below 1.
const ONE_BELOW_1: f32 = 1.0 - f32::EPSILON / 2.0;

/// SplitMix64's finaliser: a bijection of u64 whose output bits each depend on every input bit.
fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn positions(s: &Sampler, pixel: u64) -> Vec<Vec2> {
        (0..s.count()).map(|n| s.position(pixel, n)).collect()
    }

    #[test]
    fn the_default_is_one_centred_sample() {
        let s = Sampler::default();
        assert_eq!(s.count(), 1);
        assert_eq!(s.position(7, 0), Vec2::splat(0.5));
    }

    #[test]
    fn uniform_samples_are_the_cell_centres_of_a_k_by_k_grid() {
        let s = Sampler::new(SamplerKind::Uniform, 4, 1).expect("a valid test value");
        let p = positions(&s, 0);
        for want in [(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)] {
            assert!(
                p.contains(&Vec2::new(want.0, want.1)),
                "{want:?} not in {p:?}"
            );
        }
        let s = Sampler::new(SamplerKind::Uniform, 9, 1).expect("a valid test value");
        let xs: Vec<f32> = positions(&s, 3).iter().map(|p| p.x).take(3).collect();
        assert_eq!(xs, [1.0 / 6.0, 0.5, 5.0 / 6.0]);
    }

    #[test]
    fn uniform_and_jittered_counts_must_be_squares_random_need_not() {
        for kind in [SamplerKind::Uniform, SamplerKind::Jittered] {
            assert_eq!(
                Sampler::new(kind, 8, 0),
                Err(SamplerError::NotSquare {
                    kind,
                    count: 8,
                    below: 4,
                    above: 9
                })
            );
            assert!(Sampler::new(kind, 36, 0).is_ok());
        }
        assert!(Sampler::new(SamplerKind::Random, 8, 0).is_ok());
        for kind in [SamplerKind::Uniform, SamplerKind::Random] {
            assert_eq!(Sampler::new(kind, 0, 0), Err(SamplerError::Count(0)));
            assert!(Sampler::new(kind, MAX_SAMPLES_PER_PIXEL, 0).is_ok());
            assert!(Sampler::new(kind, MAX_SAMPLES_PER_PIXEL + 1, 0).is_err());
        }
    }

    #[test]
    fn jittered_samples_keep_one_to_each_cell() {
        let s = Sampler::new(SamplerKind::Jittered, 16, 42).expect("a valid test value");
        for pixel in 0..50 {
            let mut seen = [false; 16];
            for p in positions(&s, pixel) {
                assert!(
                    (0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y),
                    "{p}"
                );
                let c = (p.y * 4.0) as usize * 4 + (p.x * 4.0) as usize;
                assert!(!seen[c], "two samples in cell {c} of pixel {pixel}");
                seen[c] = true;
            }
        }
    }

    #[test]
    fn random_positions_depend_on_seed_pixel_and_sample_and_repeat() {
        let a = Sampler::new(SamplerKind::Random, 9, 1).expect("a valid test value");
        let b = a.with_seed(2);
        assert_eq!(positions(&a, 5), positions(&a, 5));
        assert_ne!(positions(&a, 5), positions(&b, 5));
        assert_ne!(positions(&a, 5), positions(&a, 6));
        let p = positions(&a, 5);
        assert!(p.windows(2).all(|w| w[0] != w[1]));
    }

    #[test]
    fn random_positions_fill_the_pixel_evenly() {
        // 40,000 positions in a 10 × 10 histogram: each bin expects 400 with a standard
        // deviation of about 20; 6 deviations either way would fail a skewed generator.
        let s = Sampler::new(SamplerKind::Random, 400, DEFAULT_SEED).expect("a valid test value");
        let mut bins = [0u32; 100];
        let mut sum = Vec2::ZERO;
        for pixel in 0..100 {
            for p in positions(&s, pixel) {
                bins[(p.y * 10.0) as usize * 10 + (p.x * 10.0) as usize] += 1;
                sum += p;
            }
        }
        assert!(bins.iter().all(|&b| (280..=520).contains(&b)), "{bins:?}");
        let mean = sum / 40_000.0;
        assert!(
            (mean - Vec2::splat(0.5)).abs().max_element() < 0.005,
            "{mean}"
        );
    }

    #[test]
    fn too_many_samples_in_all_are_refused_without_overflow() {
        let s = Sampler::new(SamplerKind::Random, MAX_SAMPLES_PER_PIXEL, 0)
            .expect("a valid test value");
        assert!(s.check_image(1024, 1).is_ok());
        assert!(matches!(
            s.check_image(16384, 16384),
            Err(SamplerError::TooManyInAll { .. })
        ));
    }
}
