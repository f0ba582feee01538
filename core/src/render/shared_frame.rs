//! The frame a render fills while others (the GUI) read it. The renderer's coarse passes stay
//! at their own resolution ([`CoarseFrame`]) until someone locks the frame, which spreads the
//! last of them over it first: every reader of [`SharedFrame::lock`] sees the full-resolution
//! frame, as if each pass had written it.

use std::ops::{Deref, DerefMut};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, MutexGuard, PoisonError};

use super::coarse::CoarseFrame;
use super::frame::{Frame, Sample};

/// The frame and the coarse pass not yet spread over it (it then shows that pass).
#[derive(Debug)]
pub(super) struct Pixels {
    pub frame: Frame,
    pub coarse: Option<CoarseFrame>,
}

/// A frame being filled by a render and read by others (the GUI) while it fills.
#[derive(Debug)]
pub struct SharedFrame {
    pixels: Mutex<Pixels>,
    /// Bumped whenever pixels change, so readers copy only when there is something new.
    version: AtomicU64,
    /// Tiles finished and tiles planned in the current render, over all passes.
    pub(super) tiles_done: AtomicU64,
    pub(super) tiles_total: AtomicU64,
}

/// The locked frame, at full resolution.
pub struct FrameGuard<'a>(MutexGuard<'a, Pixels>);

impl Deref for FrameGuard<'_> {
    type Target = Frame;
    fn deref(&self) -> &Frame {
        &self.0.frame
    }
}

impl DerefMut for FrameGuard<'_> {
    fn deref_mut(&mut self) -> &mut Frame {
        &mut self.0.frame
    }
}

/// The locked pixels as shown, read without spreading a coarse pass.
pub struct ShownPixels<'a>(pub(super) MutexGuard<'a, Pixels>);

impl ShownPixels<'_> {
    /// The frame's size.
    pub fn size(&self) -> (u32, u32) {
        let p = &self.0;
        p.coarse
            .as_ref()
            .map_or((p.frame.width, p.frame.height), |c| (c.width, c.height))
    }
    /// The sample shown at pixel (x, row).
    pub fn get(&self, x: u32, row: u32) -> Option<&Sample> {
        match &self.0.coarse {
            Some(c) => c.get(x, row),
            None => self.0.frame.get(x, row),
        }
    }
}

impl Default for SharedFrame {
    fn default() -> Self {
        SharedFrame {
            pixels: Mutex::new(Pixels {
                frame: Frame::new(0, 0),
                coarse: None,
            }),
            version: AtomicU64::new(0),
            tiles_done: AtomicU64::new(0),
            tiles_total: AtomicU64::new(0),
        }
    }
}

impl SharedFrame {
    pub fn new() -> Self {
        Self::default()
    }
    /// A `width` × `height` frame allocated now, fallibly: a render of that size into it
    /// allocates no frame of its own.
    pub fn try_sized(width: u32, height: u32) -> Result<Self, crate::memory::OutOfMemory> {
        let shared = Self::new();
        shared.pixels().frame = Frame::try_new(width, height)?;
        Ok(shared)
    }
    /// The frame as it is now, at full resolution (a coarse pass not yet spread over it is
    /// spread first). Hold the guard briefly: the renderer waits for it.
    pub fn lock(&self) -> FrameGuard<'_> {
        let mut p = self.pixels();
        if let Some(c) = p.coarse.take() {
            c.spread_into(&mut p.frame, false);
        }
        FrameGuard(p)
    }
    /// The last pass at its own resolution, while it is a coarse pass not yet spread over the
    /// frame (a small copy: the GUI shows it without the full frame being written).
    pub fn coarse(&self) -> Option<CoarseFrame> {
        self.pixels().coarse.clone()
    }
    /// The pixels as shown, read in place: a coarse pass not yet spread is read from its grid
    /// (for readers of a few pixels, which should not pay for writing the full frame).
    pub fn shown(&self) -> ShownPixels<'_> {
        ShownPixels(self.pixels())
    }
    /// The frame, leaving an empty one: a finished render's image as a value.
    pub fn take(&self) -> Frame {
        std::mem::replace(&mut *self.lock(), Frame::new(0, 0))
    }
    /// Puts a whole finished image in place (one not rendered by passes, such as
    /// `-visualize_grid`'s), so readers see it as new.
    pub fn set(&self, frame: Frame) {
        let mut p = self.pixels();
        p.coarse = None;
        p.frame = frame;
        drop(p);
        self.bump();
    }
    pub fn version(&self) -> u64 {
        self.version.load(Ordering::Acquire)
    }
    /// Fraction of the current render's work done, in [0, 1].
    pub fn progress(&self) -> f32 {
        let total = self.tiles_total.load(Ordering::Relaxed);
        if total == 0 {
            0.0
        } else {
            self.tiles_done.load(Ordering::Relaxed) as f32 / total as f32
        }
    }
    pub(super) fn bump(&self) {
        self.version.fetch_add(1, Ordering::AcqRel);
    }
    /// Frame and pending coarse pass as they are, for the renderer.
    pub(super) fn pixels(&self) -> MutexGuard<'_, Pixels> {
        self.pixels.lock().unwrap_or_else(PoisonError::into_inner)
    }
}
