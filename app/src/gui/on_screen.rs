//! An image drawn in a screen rectangle: the camera maths of `crate::navigation` in egui's
//! screen points.

use glam::{Vec2, Vec3};
use tracelab_core::Camera;

use crate::navigation::ViewBasis;

/// An image drawn in a screen rectangle: its basis, and the mapping between screen points
/// and image pixels (the image may be scaled to fit).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OnScreen {
    pub basis: ViewBasis,
    pub rect: egui::Rect,
}

impl OnScreen {
    pub fn new(camera: &Camera, width: u32, height: u32, rect: egui::Rect) -> Self {
        OnScreen {
            basis: ViewBasis::new(camera, width, height),
            rect,
        }
    }

    /// Image pixels per screen point.
    pub fn pixels_per_point(&self) -> f32 {
        self.basis.width / self.rect.width().max(1e-3)
    }

    pub fn to_pixels(&self, p: egui::Pos2) -> Vec2 {
        let k = Vec2::new(
            self.basis.width / self.rect.width().max(1e-3),
            self.basis.height / self.rect.height().max(1e-3),
        );
        Vec2::new(p.x - self.rect.min.x, p.y - self.rect.min.y) * k
    }

    pub fn to_screen(&self, px: Vec2) -> egui::Pos2 {
        let k = Vec2::new(
            self.rect.width() / self.basis.width,
            self.rect.height() / self.basis.height,
        );
        egui::pos2(self.rect.min.x + px.x * k.x, self.rect.min.y + px.y * k.y)
    }

    pub fn project(&self, world: Vec3) -> Option<egui::Pos2> {
        self.basis.project(world).map(|px| self.to_screen(px))
    }

    pub fn ray(&self, p: egui::Pos2) -> (Vec3, Vec3) {
        self.basis.ray(self.to_pixels(p))
    }

    /// World units per screen point at the depth of `world`.
    pub fn world_per_point(&self, world: Vec3) -> f32 {
        self.basis.world_per_pixel(self.basis.depth(world)) * self.pixels_per_point()
    }
}
