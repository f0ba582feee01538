//! Statistical checks of assignment 7's random and jittered sampling, on an inline scene (a
//! sphere and a triangle, as the course's scene7_01, at 8 × 8 pixels so that about a third of
//! the pixels hold an edge). A pixel's value is the plain mean of its samples (the default box
//! filter), each channel a value of its own. The exact pixel value (the colour averaged over the pixel's
//! square) is stood in for by a 64 × 64 uniform grid (4,096 samples), whose error on a pixel
//! crossed by smooth edges is at most about one column of cells: DELTA = 1/64.
//!
//! What they prove, and why they can fail:
//! - `the_mean_over_seeds_converges_to_the_pixel_average`: random and jittered sampling are
//!   unbiased (their expected image is the exact one). The statistic is a mean χ² per pixel,
//!   (mean − exact)² / (variance of that mean + DELTA²), ≈ 1 or less when unbiased, and a
//!   sampler whose positions lean anywhere (toward the centre, a corner, or that ignores the
//!   seed so its "mean" is one noisy image) makes it far larger; the test shows the last case
//!   fail the same bound.
//! - `the_spread_shrinks_as_one_over_root_n`: for random sampling, each pixel's standard
//!   deviation over seeds goes as 1/√N (independent samples): ×4 samples halves it. Pooled over
//!   the edge pixels from 128 seeds, the estimate's own error is a few per cent, so the ratio
//!   must lie in [1.7, 2.3]; samples that were not independent (repeated, or the same in every
//!   pixel) would not halve it.
//! - `jittered_sampling_spreads_less_than_random_at_the_same_count`: stratification lowers the
//!   variance on edges (to about N^-1.5 from N^-1): at 16 samples jittered's pooled variance is
//!   well under random's; the bound, 0.6 of it, leaves room for the estimate's error while a
//!   jittered sampler that were really random (no cells) would sit at 1.

use glam::Vec3;
use tracelab_core::render::{Film, Filter, Sampler, SamplerKind};
use tracelab_core::{CompiledScene, MeshCache, RenderSettings, compile, parse_scene};

const SCENE: &str = "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 5.0 }
Lights { numLights 1 DirectionalLight { direction 0 -1 -1 color 0.5 0.5 0.5 } }
Materials { numMaterials 2 PhongMaterial { diffuseColor 1 0 0 } PhongMaterial { diffuseColor 0 1 0 } }
Background { color 0 0 1 ambientLight 0.5 0.5 0.5 }
Group { numObjects 2
  MaterialIndex 0 Sphere { center 1 1 0 radius 1 }
  MaterialIndex 1 Triangle { vertex0 -2.0 -2.0 0 vertex1 1.8 -1.8 0 vertex2 -1.95 1.95 0 }
}";

const SIZE: u32 = 8;
const SEEDS: u64 = 128;
/// Error bound of the 64 × 64 stand-in for the exact pixel value.
const DELTA: f64 = 1.0 / 64.0;

fn scene() -> CompiledScene {
    let s = parse_scene(SCENE.as_bytes(), "t.txt", None, &mut MeshCache::new())
        .into_result()
        .unwrap_or_else(|d| panic!("{d}"))
        .0;
    compile(&s)
}

/// Each pixel's red, green and blue (the means of its samples), rows from the bottom: three
/// values a pixel, each judged on its own.
fn image(scene: &CompiledScene, sampler: Sampler) -> Vec<f64> {
    let film = Film::render(scene, &RenderSettings::new(SIZE, SIZE), sampler).expect("film");
    let mut out = Vec::new();
    for j in 0..SIZE {
        for i in 0..SIZE {
            let c: Vec3 = film.filtered(&Filter::default(), i, j);
            out.extend([c.x, c.y, c.z].map(f64::from));
        }
    }
    out
}

/// Per pixel, the mean and the variance (unbiased) over the images of `seeds`.
fn over_seeds(
    scene: &CompiledScene,
    kind: SamplerKind,
    n: u32,
    seeds: impl Iterator<Item = u64>,
) -> (Vec<f64>, Vec<f64>) {
    let images: Vec<Vec<f64>> = seeds
        .map(|s| image(scene, Sampler::new(kind, n, s).expect("a valid test value")))
        .collect();
    let k = images.len() as f64;
    let px = images[0].len();
    let mean: Vec<f64> = (0..px)
        .map(|p| images.iter().map(|im| im[p]).sum::<f64>() / k)
        .collect();
    let var = (0..px)
        .map(|p| {
            images
                .iter()
                .map(|im| (im[p] - mean[p]).powi(2))
                .sum::<f64>()
                / (k - 1.0)
        })
        .collect();
    (mean, var)
}

fn exact(scene: &CompiledScene) -> Vec<f64> {
    image(
        scene,
        Sampler::new(SamplerKind::Uniform, 64 * 64, 0).expect("a valid test value"),
    )
}

/// The pixels an edge crosses (as channel values): those whose one random sample varies
/// over seeds.
fn edge_pixels(scene: &CompiledScene) -> Vec<usize> {
    let (_, v) = over_seeds(scene, SamplerKind::Random, 1, 5000..5000 + SEEDS);
    let edge: Vec<usize> = (0..v.len()).filter(|&p| v[p] > 1e-4).collect();
    assert!(edge.len() >= 8, "too few edge pixels: {}", edge.len());
    edge
}

/// Mean over the edge pixels of (mean − exact)² / (var/K + DELTA²).
fn chi2(mean: &[f64], var: &[f64], exact: &[f64], k: f64, edge: &[usize]) -> f64 {
    edge.iter()
        .map(|&p| (mean[p] - exact[p]).powi(2) / (var[p] / k + DELTA * DELTA))
        .sum::<f64>()
        / edge.len() as f64
}

#[test]
fn the_mean_over_seeds_converges_to_the_pixel_average() {
    let scene = scene();
    let exact = exact(&scene);
    let edge = edge_pixels(&scene);
    for kind in [SamplerKind::Random, SamplerKind::Jittered] {
        let (mean, var) = over_seeds(&scene, kind, 4, 0..SEEDS);
        let q = chi2(&mean, &var, &exact, SEEDS as f64, &edge);
        println!("{kind:?}, 4 samples, {SEEDS} seeds: mean χ² {q:.2}");
        assert!(q < 3.0, "{kind:?}: mean χ² {q:.2} (unbiased ≈ 1 or less)");
    }
    // The same statistic catches a sampler that ignores its seed: 128 copies of one image
    // have no spread, and that image's noise is then a bias.
    let (mean, var) = over_seeds(&scene, SamplerKind::Random, 4, std::iter::repeat_n(7, 16));
    let q = chi2(&mean, &var, &exact, 16.0, &edge);
    println!("seed-blind: mean χ² {q:.2}");
    assert!(q > 3.0, "a seed-blind sampler should fail: mean χ² {q:.2}");
    // And the centred sample, which is biased wherever an edge misses the pixel's centre.
    let centred = image(&scene, Sampler::default());
    let q = chi2(&centred, &vec![0.0; centred.len()], &exact, 1.0, &edge);
    println!("one centred sample: mean χ² {q:.2}");
    assert!(q > 3.0, "one centred sample should fail: mean χ² {q:.2}");
}

/// Root of the mean variance over the pixels that vary at the smallest count.
fn pooled_sd(var: &[f64], pixels: &[usize]) -> f64 {
    (pixels.iter().map(|&p| var[p]).sum::<f64>() / pixels.len() as f64).sqrt()
}

#[test]
fn the_spread_shrinks_as_one_over_root_n() {
    let scene = scene();
    let (_, v1) = over_seeds(&scene, SamplerKind::Random, 1, 0..SEEDS);
    let (_, v4) = over_seeds(&scene, SamplerKind::Random, 4, 1000..1000 + SEEDS);
    let (_, v16) = over_seeds(&scene, SamplerKind::Random, 16, 2000..2000 + SEEDS);
    let edge = edge_pixels(&scene);
    let (s1, s4, s16) = (
        pooled_sd(&v1, &edge),
        pooled_sd(&v4, &edge),
        pooled_sd(&v16, &edge),
    );
    for (a, b, what) in [(s1, s4, "1 → 4"), (s4, s16, "4 → 16")] {
        let ratio = a / b;
        println!("{what} samples: spread {a:.4} → {b:.4}, ratio {ratio:.2}");
        assert!(
            (1.7..=2.3).contains(&ratio),
            "{what} samples: spread {a:.4} → {b:.4}, ratio {ratio:.2} (1/√N: 2)"
        );
    }
}

#[test]
fn jittered_sampling_spreads_less_than_random_at_the_same_count() {
    let scene = scene();
    let (_, vr) = over_seeds(&scene, SamplerKind::Random, 16, 0..SEEDS);
    let (_, vj) = over_seeds(&scene, SamplerKind::Jittered, 16, 0..SEEDS);
    let edge = edge_pixels(&scene);
    let (r, j) = (pooled_sd(&vr, &edge).powi(2), pooled_sd(&vj, &edge).powi(2));
    println!(
        "16 samples: jittered variance {j:.5}, random {r:.5}, ratio {:.2}",
        j / r
    );
    assert!(
        j > 0.0,
        "jittered sampling with no spread at all ignores its seed"
    );
    assert!(j < 0.6 * r, "jittered variance {j:.5} vs random {r:.5}");
}
