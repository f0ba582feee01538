//! Assignment 7's film: every sample's position and colour, the filtered image made from
//! them, and the course's two pictures of them (`-render_samples`: each sample as a dot in a
//! zoomed image; `-render_filter`: the filter's weights around the centre pixel).
//!
//! Pixels are numbered as the course numbers them, (i, j) with j counted from the bottom;
//! the images these functions return are rows top to bottom, as files store them.

use glam::{Vec2, Vec3};
use rayon::prelude::*;
use thiserror::Error;

use super::ObjectRays;
use super::RenderSettings;
use super::compile::CompiledScene;
use super::filter::Filter;
use super::frame::{Frame, Sample, quantize};
use super::limits::{ImageSizeError, check_image_size};
use super::plan::{Cancel, Uncancellable};
use super::sampling::{Sampler, SamplerError};
use super::shade::shade_fast;
use super::whitted::{needs_whitted, shade_primary};
use crate::geometry::Ray;
use crate::memory::{OutOfMemory, try_vec};

/// Most weights one filtered image may evaluate (pixels × samples a pixel × pixels in the
/// filter's square). At the cap a Gaussian or tent filter takes minutes (Zen 5, 2 threads:
/// ~45 ns a weight and thread, exp and f64 sums), so the command line shows a bar.
pub const MAX_FILTER_TERMS: u64 = 1 << 32;

#[derive(Debug, Error)]
pub enum FilmError {
    #[error(transparent)]
    Sampler(#[from] SamplerError),
    #[error(
        "{terms} filter weights ({pixels} pixels × {count} samples × {square} pixels in the \
         filter's square): at most {MAX_FILTER_TERMS} are allowed; use a smaller filter or \
         fewer samples"
    )]
    FilterTooWide {
        terms: u64,
        pixels: u64,
        count: u32,
        square: u64,
    },
    #[error("{what}: {source}")]
    ImageSize {
        what: &'static str,
        source: ImageSizeError,
    },
    #[error(transparent)]
    OutOfMemory(#[from] OutOfMemory),
}

/// A render's sampler and filter: what the progressive renderer refines toward after its
/// full-resolution pass (`RenderSettings::supersample`; the editor's View › Supersampling).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Supersampling {
    pub sampler: Sampler,
    pub filter: Filter,
}

/// Every sample of a render: for pixel (i, j) and sample n, its colour at
/// `(j * width + i) * count + n`; positions are the sampler's, recomputed when needed.
#[derive(Clone, Debug)]
pub struct Film {
    pub width: u32,
    pub height: u32,
    pub sampler: Sampler,
    colors: Vec<Vec3>,
}

/// An RGB8 picture, rows top to bottom.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Picture {
    pub width: u32,
    pub height: u32,
    pub rgb: Vec<u8>,
}

impl Picture {
    fn filled(width: u32, height: u32, c: [u8; 3]) -> Result<Self, OutOfMemory> {
        let n = width as usize * height as usize;
        let mut rgb = try_vec(n * 3, 0u8, "the picture's bytes")?;
        for p in rgb.chunks_exact_mut(3) {
            p.copy_from_slice(&c);
        }
        Ok(Picture { width, height, rgb })
    }
    /// Sets pixel (x, y), y counted from the bottom (the course's `Image::SetPixel`).
    fn set(&mut self, x: u32, y: u32, c: [u8; 3]) {
        if x < self.width && y < self.height {
            let row = (self.height - 1 - y) as usize;
            let k = (row * self.width as usize + x as usize) * 3;
            self.rgb[k..k + 3].copy_from_slice(&c);
        }
    }
}

fn bytes(c: Vec3) -> [u8; 3] {
    [quantize(c.x), quantize(c.y), quantize(c.z)]
}

/// The colour one ray brings back, before quantisation (the background for a miss): what a
/// supersampled render averages.
fn trace_color(scene: &CompiledScene, s: &RenderSettings, ray: &Ray) -> glam::Vec3 {
    let hit = if s.object_rays == ObjectRays::Unnormalized {
        scene.intersect(ray, scene.camera.t_min(), f32::INFINITY)
    } else {
        scene.intersect_with(ray, scene.camera.t_min(), f32::INFINITY, s.object_rays)
    };
    match hit {
        None => scene.background,
        Some(h) if needs_whitted(scene, s) => shade_primary(scene, ray, &h, s).0,
        Some(h) => shade_fast(scene, ray, &h, s).0,
    }
}

/// The pixel number the sampler is given for pixel (i, j): the same in every render of one
/// size, so a seed fixes the image.
fn pixel_number(width: u32, i: u32, j: u32) -> u64 {
    u64::from(j) * u64::from(width) + u64::from(i)
}

/// Checks that a `width` × `height` image filtered by `filter` from `sampler`'s samples is
/// within the caps: samples in all, and filter weights in all.
pub fn check_film(
    width: u32,
    height: u32,
    sampler: &Sampler,
    filter: &Filter,
) -> Result<(), FilmError> {
    sampler.check_image(width, height)?;
    let pixels = u64::from(width) * u64::from(height);
    let side = 2 * u64::from(filter.support_radius()) + 1;
    let square = side * side;
    let terms = pixels
        .saturating_mul(u64::from(sampler.count()))
        .saturating_mul(square);
    if terms > MAX_FILTER_TERMS {
        return Err(FilmError::FilterTooWide {
            terms,
            pixels,
            count: sampler.count(),
            square,
        });
    }
    Ok(())
}

impl Film {
    /// Traces every sample of a `settings.width` × `settings.height` render (rows in
    /// parallel). The store is allocated fallibly.
    pub fn render(
        scene: &CompiledScene,
        settings: &RenderSettings,
        sampler: Sampler,
    ) -> Result<Film, FilmError> {
        match Self::render_until(scene, settings, sampler, &Uncancellable) {
            Ok(film) => film,
            Err(never) => match never {},
        }
    }

    /// [`Film::render`], stopped between rows when `cancel` says so.
    pub fn render_until<C: Cancel>(
        scene: &CompiledScene,
        settings: &RenderSettings,
        sampler: Sampler,
        cancel: &C,
    ) -> Result<Result<Film, FilmError>, C::Stop> {
        let (w, h) = (settings.width, settings.height);
        if let Err(source) = check_image_size(w, h) {
            return Ok(Err(FilmError::ImageSize {
                what: "the image",
                source,
            }));
        }
        if let Err(e) = sampler.check_image(w, h) {
            return Ok(Err(e.into()));
        }
        let n = sampler.count() as usize;
        let mut colors = match try_vec(w as usize * h as usize * n, Vec3::ZERO, "the samples") {
            Ok(c) => c,
            Err(e) => return Ok(Err(e.into())),
        };
        let s = w.max(h) as f32;
        let (dx, dy) = ((s - w as f32) * 0.5, (s - h as f32) * 0.5);
        colors
            .par_chunks_mut(w as usize * n)
            .enumerate()
            .try_for_each(|(j, row)| {
                if let Some(stop) = cancel.stop() {
                    return Err(stop);
                }
                let j = j as u32;
                for (i, px) in row.chunks_mut(n).enumerate() {
                    let i = i as u32;
                    let number = pixel_number(w, i, j);
                    for (k, c) in px.iter_mut().enumerate() {
                        let p = sampler.position(number, k as u32);
                        // The pixel's square in the screen's unit square, cropped to square
                        // pixels as `camera::screen_point` crops the centres.
                        let x = (i as f32 + p.x + dx) / s;
                        let y = (j as f32 + p.y + dy) / s;
                        *c = trace_color(scene, settings, &scene.camera.ray_at(x, y));
                    }
                }
                Ok(())
            })?;
        Ok(Ok(Film {
            width: w,
            height: h,
            sampler,
            colors,
        }))
    }

    /// A film from given colours (tests): `colors` as [`Film`] orders them.
    pub fn from_colors(
        width: u32,
        height: u32,
        sampler: Sampler,
        colors: Vec<Vec3>,
    ) -> Option<Film> {
        (colors.len() == width as usize * height as usize * sampler.count() as usize).then_some(
            Film {
                width,
                height,
                sampler,
                colors,
            },
        )
    }

    /// Position (in its pixel's unit square) and colour of sample `n` of pixel (i, j).
    pub fn sample(&self, i: u32, j: u32, n: u32) -> (Vec2, Vec3) {
        let count = self.sampler.count();
        let k = (pixel_number(self.width, i, j) * u64::from(count) + u64::from(n)) as usize;
        (
            self.sampler.position(pixel_number(self.width, i, j), n),
            self.colors[k],
        )
    }

    /// The colour of pixel (i, j) reconstructed by `filter`: Σ w·c / Σ w over the samples of
    /// the pixels within its support (those inside the image), black where every weight is 0
    /// (the course's `Filter::getColor`).
    pub fn filtered(&self, filter: &Filter, i: u32, j: u32) -> Vec3 {
        let r = filter.support_radius() as i64;
        let (mut sum, mut weight) = (glam::DVec3::ZERO, 0.0f64);
        for y in (j as i64 - r).max(0)..=(j as i64 + r).min(self.height as i64 - 1) {
            for x in (i as i64 - r).max(0)..=(i as i64 + r).min(self.width as i64 - 1) {
                for n in 0..self.sampler.count() {
                    let (p, c) = self.sample(x as u32, y as u32, n);
                    // Offset of the sample from the centre of pixel (i, j), in pixels.
                    let ox = (x - i as i64) as f32 + p.x - 0.5;
                    let oy = (y - j as i64) as f32 + p.y - 0.5;
                    let w = f64::from(filter.weight(ox, oy));
                    sum += c.as_dvec3() * w;
                    weight += w;
                }
            }
        }
        if weight == 0.0 {
            Vec3::ZERO
        } else {
            (sum / weight).as_vec3()
        }
    }

    /// The filtered image as a frame (colour only: its normals are black and nothing is hit,
    /// so its depth and picking say nothing).
    pub fn frame(&self, filter: &Filter) -> Result<Frame, FilmError> {
        match self.frame_until(filter, &Uncancellable) {
            Ok(frame) => frame,
            Err(never) => match never {},
        }
    }

    /// [`Film::frame`], asking `cancel` before each row (to stop, or to count rows done).
    pub fn frame_until<C: Cancel>(
        &self,
        filter: &Filter,
        cancel: &C,
    ) -> Result<Result<Frame, FilmError>, C::Stop> {
        if let Err(e) = check_film(self.width, self.height, &self.sampler, filter) {
            return Ok(Err(e));
        }
        let mut frame = match Frame::try_new(self.width, self.height) {
            Ok(f) => f,
            Err(e) => return Ok(Err(e.into())),
        };
        let w = self.width as usize;
        frame
            .samples
            .par_chunks_mut(w)
            .enumerate()
            .try_for_each(|(row, out)| {
                if let Some(stop) = cancel.stop() {
                    return Err(stop);
                }
                let j = self.height - 1 - row as u32;
                for (i, s) in out.iter_mut().enumerate() {
                    *s = Sample {
                        color: bytes(self.filtered(filter, i as u32, j)),
                        ..Sample::UNSET
                    };
                }
                Ok(())
            })?;
        Ok(Ok(frame))
    }

    /// `-render_samples`: each pixel a `zoom` × `zoom` square, grey (0.2) and black as a
    /// checkerboard, with every sample a dot of its colour at ⌊(i + x)·zoom⌋, ⌊(j + y)·zoom⌋.
    pub fn samples_picture(&self, zoom: u32) -> Result<Picture, FilmError> {
        let (w, h) = samples_picture_size(self.width, self.height, zoom)?;
        let mut pic = Picture::filled(w, h, [0, 0, 0])?;
        let grey = bytes(Vec3::splat(0.2));
        for j in 0..self.height {
            for i in 0..self.width {
                if (i + j) % 2 == 0 {
                    for y in j * zoom..(j + 1) * zoom {
                        for x in i * zoom..(i + 1) * zoom {
                            pic.set(x, y, grey);
                        }
                    }
                }
                for n in 0..self.sampler.count() {
                    let (p, c) = self.sample(i, j, n);
                    let x = ((i as f32 + p.x) * zoom as f32).floor() as u32;
                    let y = ((j as f32 + p.y) * zoom as f32).floor() as u32;
                    pic.set(x.min(w - 1), y.min(h - 1), bytes(c));
                }
            }
        }
        Ok(pic)
    }
}

/// The film of the progressive renderer's pass after its full-resolution one, where the
/// settings ask for supersampling, traced cancellably; `None` (and a warning saying why)
/// where the samples or the filter's work would pass their caps or do not fit in memory:
/// the one-ray image then stays.
pub(super) fn supersample_film<C: Cancel>(
    scene: &CompiledScene,
    settings: &RenderSettings,
    ss: Supersampling,
    cancel: &C,
) -> Result<Option<Film>, C::Stop> {
    let (w, h) = (settings.width, settings.height);
    let film = match check_film(w, h, &ss.sampler, &ss.filter) {
        Ok(()) => Film::render_until(scene, settings, ss.sampler, cancel)?,
        Err(e) => Err(e),
    };
    Ok(film
        .map_err(|e| log::warn!("supersampling skipped at {w}x{h}: {e}"))
        .ok())
}

/// The size of `-render_samples`' picture, checked against the image caps.
pub fn samples_picture_size(width: u32, height: u32, zoom: u32) -> Result<(u32, u32), FilmError> {
    zoomed(width, height, zoom, 0, "-render_samples' picture")
}

/// The size of `-render_filter`' picture (one more than zoomed, for the closing grid line),
/// checked against the image caps.
pub fn filter_picture_size(width: u32, height: u32, zoom: u32) -> Result<(u32, u32), FilmError> {
    zoomed(width, height, zoom, 1, "-render_filter's picture")
}

fn zoomed(
    width: u32,
    height: u32,
    zoom: u32,
    extra: u64,
    what: &'static str,
) -> Result<(u32, u32), FilmError> {
    let side = |s: u32| u32::try_from(u64::from(s) * u64::from(zoom) + extra).unwrap_or(u32::MAX);
    let (w, h) = (side(width), side(height));
    check_image_size(w, h).map_err(|source| FilmError::ImageSize { what, source })?;
    Ok((w, h))
}

/// `-render_filter`: the weights `filter` gives the points of the pixels around the centre
/// pixel (i = j = ⌊width/2⌋, as the course's `Film` takes it), each pixel a `zoom` × `zoom`
/// square of grey levels on dark blue (0, 0, 0.5), under a blue grid (0, 0, 1) one line a
/// pixel. The weights are not normalised: a box is white.
pub fn filter_picture(
    width: u32,
    height: u32,
    zoom: u32,
    filter: &Filter,
) -> Result<Picture, FilmError> {
    let (pw, ph) = filter_picture_size(width, height, zoom)?;
    let mut pic = Picture::filled(pw, ph, bytes(Vec3::new(0.0, 0.0, 0.5)))?;
    let r = i64::from(filter.support_radius());
    let center = i64::from(width / 2);
    let z = zoom as f32;
    for j in (center - r).max(0)..=(center + r).min(i64::from(height) - 1) {
        for i in (center - r).max(0)..=(center + r).min(i64::from(width) - 1) {
            for j2 in 0..zoom {
                for i2 in 0..zoom {
                    let x = i as f32 + i2 as f32 / z - (center as f32 + 0.5);
                    let y = j as f32 + j2 as f32 / z - (center as f32 + 0.5);
                    let g = quantize(filter.weight(x, y));
                    pic.set(i as u32 * zoom + i2, j as u32 * zoom + j2, [g, g, g]);
                }
            }
        }
    }
    let blue = bytes(Vec3::new(0.0, 0.0, 1.0));
    for y in 0..ph {
        for x in 0..pw {
            if x % zoom == 0 || y % zoom == 0 {
                pic.set(x, y, blue);
            }
        }
    }
    Ok(pic)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::sampling::SamplerKind;

    /// A 3 × 1 film of one centred sample a pixel: red, green, blue.
    fn rgb_strip() -> Film {
        let colors = vec![Vec3::X, Vec3::Y, Vec3::Z];
        Film::from_colors(3, 1, Sampler::default(), colors).expect("a valid test value")
    }

    /// `frame_until` asks its `Cancel` once a row (the command line's bar counts them), gives
    /// `frame`'s image, and stops when told.
    #[test]
    fn filtering_asks_once_a_row_and_stops_when_told() {
        use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
        struct Count(AtomicU32);
        impl Cancel for Count {
            type Stop = std::convert::Infallible;
            fn stop(&self) -> Option<Self::Stop> {
                self.0.fetch_add(1, Ordering::Relaxed);
                None
            }
        }
        let colors = (0..12).map(|k| Vec3::splat(k as f32 / 12.0)).collect();
        let f = Film::from_colors(3, 4, Sampler::default(), colors).expect("a valid test value");
        let tent = Filter::tent(1.5).expect("a valid test value");
        let count = Count(AtomicU32::new(0));
        let Ok(got) = f.frame_until(&tent, &count);
        assert_eq!(count.0.load(Ordering::Relaxed), 4);
        let want = f.frame(&tent).expect("frame");
        let got = got.expect("frame");
        assert!(
            got.samples
                .iter()
                .zip(&want.samples)
                .all(|(a, b)| a.color == b.color)
        );
        assert!(f.frame_until(&tent, &AtomicBool::new(true)).is_err());
    }

    #[test]
    fn the_default_box_keeps_each_pixel_its_own_colour() {
        let f = rgb_strip();
        for (i, want) in [Vec3::X, Vec3::Y, Vec3::Z].into_iter().enumerate() {
            assert_eq!(f.filtered(&Filter::default(), i as u32, 0), want);
        }
    }

    #[test]
    fn a_wide_box_averages_the_neighbours_inside_the_image() {
        let f = rgb_strip();
        let b = Filter::box_filter(1.5).expect("a valid test value");
        let third = Vec3::splat(1.0 / 3.0);
        assert!((f.filtered(&b, 1, 0) - third).abs().max_element() < 1e-6);
        // At the edge only the pixels inside the image count.
        assert!(
            (f.filtered(&b, 0, 0) - Vec3::new(0.5, 0.5, 0.0))
                .abs()
                .max_element()
                < 1e-6
        );
    }

    #[test]
    fn a_tent_weighs_neighbours_by_distance() {
        let f = rgb_strip();
        let t = Filter::tent(2.0).expect("a valid test value");
        // Weights 1 (own), 0.5 (each neighbour at distance 1): (0.5, 1, 0.5)/2.
        let c = f.filtered(&t, 1, 0);
        assert!(
            (c - Vec3::new(0.25, 0.5, 0.25)).abs().max_element() < 1e-6,
            "{c}"
        );
    }

    #[test]
    fn where_every_weight_is_zero_the_pixel_is_black() {
        let s = Sampler::new(SamplerKind::Uniform, 4, 0).expect("a valid test value");
        let f = Film::from_colors(1, 1, s, vec![Vec3::ONE; 4]).expect("a valid test value");
        // Samples at ±¼ from the centre; a box of radius 0.1 holds none.
        assert_eq!(
            f.filtered(&Filter::box_filter(0.1).expect("a valid test value"), 0, 0),
            Vec3::ZERO
        );
    }

    #[test]
    fn the_samples_picture_puts_dots_at_the_zoomed_positions() {
        let s = Sampler::new(SamplerKind::Uniform, 4, 0).expect("a valid test value");
        let f = Film::from_colors(2, 1, s, vec![Vec3::X; 8]).expect("a valid test value");
        let p = f.samples_picture(4).expect("a valid test value");
        assert_eq!((p.width, p.height), (8, 4));
        let at = |x: usize, row: usize| &p.rgb[(row * 8 + x) * 3..(row * 8 + x) * 3 + 3];
        // Dots at x = 1, 3 (pixel 0) and 5, 7 (pixel 1); y = 1, 3 from the bottom.
        for x in [1, 3, 5, 7] {
            for row in [0, 2] {
                assert_eq!(at(x, row), [255, 0, 0]);
            }
        }
        assert_eq!(at(0, 0), [51, 51, 51]);
        assert_eq!(at(4, 0), [0, 0, 0]);
    }

    #[test]
    fn zoomed_pictures_over_the_image_caps_are_refused() {
        assert!(samples_picture_size(9, 9, 20).is_ok());
        assert!(samples_picture_size(9, 9, u32::MAX).is_err());
        assert!(filter_picture_size(8192, 8192, 1).is_err());
        assert!(samples_picture_size(8192, 8192, 1).is_ok());
    }

    #[test]
    fn filters_too_wide_for_their_samples_are_refused() {
        let s = Sampler::new(SamplerKind::Random, 1024, 0).expect("a valid test value");
        let g = Filter::gaussian(30.0).expect("a valid test value");
        assert!(matches!(
            check_film(256, 256, &s, &g),
            Err(FilmError::FilterTooWide { .. })
        ));
        assert!(check_film(256, 256, &s, &Filter::default()).is_ok());
    }
}
