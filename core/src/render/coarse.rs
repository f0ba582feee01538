//! A coarse pass at its own resolution: one sample per scale×scale block of the frame. The
//! progressive renderer keeps its coarse passes so, and spreads them over the full frame only
//! when the frame is read or a finer pass needs it: at 800² the spread writes 10 MB, a third
//! of the dragon's first coarse image (docs/perf.md).

use rayon::prelude::*;

use super::frame::{Frame, Sample, View};

/// Samples one per `scale`×`scale` block of a `width` × `height` frame: sample (i, j) is
/// pixel (i·scale, j·scale)'s, and every pixel of its block shows it (blocks at the right
/// and bottom edges may be partial).
#[derive(Clone, Debug, PartialEq)]
pub struct CoarseFrame {
    pub width: u32,
    pub height: u32,
    pub scale: u32,
    /// `grid_width()` × `grid_height()` samples, row-major.
    pub samples: Vec<Sample>,
}

impl CoarseFrame {
    pub fn grid_width(&self) -> u32 {
        self.width.div_ceil(self.scale)
    }

    pub fn grid_height(&self) -> u32 {
        self.height.div_ceil(self.scale)
    }

    /// The sample shown at pixel (x, row), as in the spread frame.
    pub fn get(&self, x: u32, row: u32) -> Option<&Sample> {
        if x >= self.width || row >= self.height {
            return None;
        }
        let (i, j) = (x / self.scale, row / self.scale);
        self.samples
            .get(j as usize * self.grid_width() as usize + i as usize)
    }

    /// Grid row `j` spread over one pixel row.
    fn line(&self, j: u32, line: &mut Vec<Sample>) {
        let (gw, s) = (self.grid_width() as usize, self.scale as usize);
        let row = &self.samples[j as usize * gw..(j as usize + 1) * gw];
        line.clear();
        for &sample in row {
            line.extend(std::iter::repeat_n(sample, s));
        }
        line.truncate(self.width as usize);
    }

    /// The full-resolution frame it stands for.
    pub fn spread(&self) -> Frame {
        let mut f = Frame::new(0, 0);
        self.spread_into(&mut f, false);
        f
    }

    /// Every pixel of `frame` its block's sample (`frame` takes this size). `parallel`: the
    /// bands of block rows on rayon's threads, for the renderer; a reader on another thread
    /// (the GUI's) spreads on its own, not waiting for a pool that may be busy tracing.
    pub fn spread_into(&self, frame: &mut Frame, parallel: bool) {
        let (w, h) = (self.width as usize, self.height as usize);
        if frame.width != self.width || frame.height != self.height || frame.samples.len() != w * h
        {
            // Written once below, not filled first.
            frame.width = self.width;
            frame.height = self.height;
            frame.samples = Vec::with_capacity(w * h);
            let mut line = Vec::with_capacity(w + self.scale as usize);
            for j in 0..self.grid_height() {
                self.line(j, &mut line);
                let rows = (h - (j * self.scale) as usize).min(self.scale as usize);
                for _ in 0..rows {
                    frame.samples.extend_from_slice(&line);
                }
            }
            return;
        }
        let band = |(j, band): (usize, &mut [Sample])| {
            let mut line = Vec::with_capacity(w + self.scale as usize);
            self.line(j as u32, &mut line);
            for row in band.chunks_mut(w) {
                row.copy_from_slice(&line);
            }
        };
        let band_len = w * self.scale as usize;
        if parallel {
            frame
                .samples
                .par_chunks_mut(band_len)
                .enumerate()
                .for_each(band);
        } else {
            frame
                .samples
                .chunks_mut(band_len)
                .enumerate()
                .for_each(band);
        }
    }

    /// [`Frame::rgba8`] of the spread frame, made from the grid: each sample's bytes once.
    pub fn rgba8(&self, view: View, depth: (f32, f32)) -> Vec<u8> {
        let (w, s) = (self.width as usize, self.scale as usize);
        let mut out = Vec::with_capacity(w * self.height as usize * 4);
        let mut line = Vec::with_capacity((w + s) * 4);
        let gw = self.grid_width() as usize;
        for (j, row) in self.samples.chunks(gw).enumerate() {
            line.clear();
            for sample in row {
                let [r, g, b] = sample.rgb8(view, depth);
                for _ in 0..s {
                    line.extend_from_slice(&[r, g, b, 255]);
                }
            }
            line.truncate(w * 4);
            let rows = (self.height as usize - j * s).min(s);
            for _ in 0..rows {
                out.extend_from_slice(&line);
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A grid with partial blocks at both edges, every sample distinct in every view.
    fn grid(w: u32, h: u32, scale: u32) -> CoarseFrame {
        let n = w.div_ceil(scale) * h.div_ceil(scale);
        let samples = (0..n)
            .map(|k| Sample {
                color: [k as u8, (k >> 8) as u8, 7],
                normal: [3, k as u8, 200],
                t: if k % 5 == 0 { f32::INFINITY } else { k as f32 },
                node: if k % 5 == 0 { u32::MAX } else { k },
            })
            .collect();
        CoarseFrame {
            width: w,
            height: h,
            scale,
            samples,
        }
    }

    /// Every pixel of the spread frame is its block's sample, whether the frame is made,
    /// resized or overwritten in place, one band at a time or in parallel; `get` and
    /// `rgba8` agree with it.
    #[test]
    fn spread_gives_every_pixel_its_blocks_sample() {
        for (w, h, s) in [
            (150, 97, 16),
            (64, 64, 8),
            (7, 130, 4),
            (1, 1, 16),
            (33, 2, 2),
        ] {
            let c = grid(w, h, s);
            let gw = w.div_ceil(s);
            let f = c.spread();
            assert_eq!(
                (f.width, f.height, f.samples.len()),
                (w, h, (w * h) as usize)
            );
            for row in 0..h {
                for x in 0..w {
                    let want = c.samples[((row / s) * gw + x / s) as usize];
                    assert_eq!(f.get(x, row), Some(&want), "{w}x{h}/{s} ({x}, {row})");
                    assert_eq!(c.get(x, row), Some(&want));
                }
            }
            assert_eq!(c.get(w, 0), None);
            assert_eq!(c.get(0, h), None);
            for parallel in [false, true] {
                let mut same = Frame::new(w, h);
                c.spread_into(&mut same, parallel);
                assert_eq!(same, f, "in place, parallel {parallel}");
                let mut other = Frame::new(w + 3, h);
                c.spread_into(&mut other, parallel);
                assert_eq!(other, f, "resized, parallel {parallel}");
            }
            for view in [View::Color, View::Normals, View::Depth] {
                assert_eq!(c.rgba8(view, (0.0, 50.0)), f.rgba8(view, (0.0, 50.0)));
            }
        }
    }
}
