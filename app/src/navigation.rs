//! Camera maths for moving through the scene with the mouse: the view's projection (the
//! same conventions as core's `CameraRays`), turntable orbit, pan, zoom, framing and the
//! axis views. Pure functions of a `Camera`, no UI types: the editor's viewport turns mouse
//! motion into them (through `gui::on_screen`) and queues the result as an ordinary
//! `Edit::SetCamera`; `bench-progressive` orbits with them.

use glam::{Quat, Vec2, Vec3};
use tracelab_core::Camera;
use tracelab_core::render::CameraRays;
use tracelab_core::scene::unit;

/// Blender's turntable sensitivity: 0.4° of orbit per point of drag.
pub const ORBIT_DEGREES_PER_POINT: f32 = 0.4;
/// One wheel notch dollies (or shrinks the orthographic size) by this factor, as Blender's.
pub const ZOOM_PER_NOTCH: f32 = 1.2;
/// The orbit stops this far from looking straight along the up axis: there the view would
/// spin about itself and flip.
const MAX_ELEVATION_DEGREES: f32 = 89.0;

/// The camera's frame as the renderer builds it (core's `CameraRays`, so what is drawn
/// over the image lines up with its rays), with the image it renders into: maps between
/// world points, image pixels (continuous, (0, 0) the top-left corner) and rays.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewBasis {
    pub rays: CameraRays,
    /// Image size in pixels.
    pub width: f32,
    pub height: f32,
}

impl ViewBasis {
    pub fn new(camera: &Camera, width: u32, height: u32) -> Self {
        ViewBasis {
            rays: CameraRays::new(camera),
            width: width.max(1) as f32,
            height: height.max(1) as f32,
        }
    }

    /// The larger image side: it spans the camera's size or angle (see core's camera.rs).
    fn span(&self) -> f32 {
        self.width.max(self.height)
    }

    /// Screen coordinates in [0, 1]² (y up) of an image position in pixels.
    fn screen(&self, px: Vec2) -> Vec2 {
        let s = self.span();
        Vec2::new(
            (px.x + (s - self.width) * 0.5) / s,
            ((self.height - px.y) + (s - self.height) * 0.5) / s,
        )
    }

    /// The ray (origin, unit direction) through an image position in pixels: core's
    /// `CameraRays::ray_at` at its screen point.
    pub fn ray(&self, px: Vec2) -> (Vec3, Vec3) {
        let p = self.screen(px);
        let r = self.rays.ray_at(p.x, p.y);
        (r.origin, r.direction)
    }

    /// Depth of a world point along the view direction.
    pub fn depth(&self, world: Vec3) -> f32 {
        (world - self.rays.center).dot(self.rays.direction)
    }

    /// The image position (pixels) of a world point; `None` behind a perspective camera.
    pub fn project(&self, world: Vec3) -> Option<Vec2> {
        let c = &self.rays;
        let q = world - c.center;
        let z = q.dot(c.direction);
        let (sx, sy) = if self.rays.perspective {
            if z <= 1e-6 {
                return None;
            }
            (q.dot(c.horizontal) / z, q.dot(c.up) / z)
        } else {
            (q.dot(c.horizontal), q.dot(c.up))
        };
        let s = self.span();
        let x = (sx / self.rays.extent + 0.5) * s - (s - self.width) * 0.5;
        let y = (sy / self.rays.extent + 0.5) * s - (s - self.height) * 0.5;
        let p = Vec2::new(x, self.height - y);
        p.is_finite().then_some(p)
    }

    /// World units per image pixel at depth `depth` (in the image plane).
    pub fn world_per_pixel(&self, depth: f32) -> f32 {
        let at = if self.rays.perspective {
            depth.max(1e-4)
        } else {
            1.0
        };
        at * self.rays.extent / self.span()
    }
}

fn with_pose(camera: &Camera, center: Vec3, direction: Vec3, up: Vec3) -> Camera {
    match *camera {
        Camera::Orthographic { size, .. } => Camera::Orthographic {
            center,
            direction,
            up,
            size,
        },
        Camera::Perspective { angle, .. } => Camera::Perspective {
            center,
            direction,
            up,
            angle,
        },
    }
}

/// Turntable orbit of `start` about `pivot`: `yaw` degrees about the camera's own `up`
/// (the scene's up axis, whatever vector the file gives, as long as it is not along the
/// direction), then `pitch` degrees up or down, stopping short of looking along that axis.
/// The camera moves rigidly about the pivot, so the pivot stays where it is on screen, and
/// `up` is kept as written: the view never rolls.
pub fn orbit(start: &Camera, pivot: Vec3, yaw: f32, pitch: f32) -> Camera {
    let (c, d, up) = (start.center(), start.direction(), start.up());
    let (Some(axis), Some(dir)) = (unit(up), unit(d)) else {
        return start.clone();
    };
    // Elevation of the view above the plane perpendicular to up; clamp the pitch so it
    // stays inside (−89°, 89°).
    let elevation = dir.dot(axis).clamp(-1.0, 1.0).asin().to_degrees();
    // Rotating about the screen's right by +p raises the view by p. A file's camera already
    // past the limit may only move back towards it.
    let limit = MAX_ELEVATION_DEGREES;
    let target = (elevation + pitch).clamp((-limit).min(elevation), limit.max(elevation));
    let pitch = target - elevation;
    let right = dir.cross(axis).normalize_or(Vec3::X);
    let rot = Quat::from_axis_angle(axis, yaw.to_radians())
        * Quat::from_axis_angle(right, pitch.to_radians());
    let center = pivot + rot * (c - pivot);
    let direction = rot * d;
    with_pose(start, center, direction, up)
}

/// The camera moved in its own image plane by the pixels `(dx, dy)` (y down), measured at
/// `depth`: the point at that depth under the cursor stays under it (the scene is grabbed).
pub fn pan(start: &Camera, basis: &ViewBasis, depth: f32, dx: f32, dy: f32) -> Camera {
    let k = basis.world_per_pixel(depth);
    let shift = -(dx * k) * basis.rays.horizontal + (dy * k) * basis.rays.up;
    with_pose(start, start.center() + shift, start.direction(), start.up())
}

/// `notches` of the wheel (positive: towards the scene) about the world point `toward`,
/// which stays where it is on screen: a dolly for the perspective camera, a smaller `size`
/// for the orthographic one.
pub fn zoom(start: &Camera, toward: Vec3, notches: f32) -> Camera {
    let f = ZOOM_PER_NOTCH.powf(-notches);
    match *start {
        Camera::Perspective {
            center,
            direction,
            up,
            angle,
        } => {
            // A homothety about `toward` keeps its image fixed and its distance × f.
            Camera::Perspective {
                center: toward + (center - toward) * f,
                direction,
                up,
                angle,
            }
        }
        Camera::Orthographic {
            center,
            direction,
            up,
            size,
        } => {
            let d = unit(direction).unwrap_or(Vec3::NEG_Z);
            let off = center - toward;
            // Shrink only the part across the view: the depth of an orthographic camera
            // changes nothing on screen.
            let across = off - d * off.dot(d);
            Camera::Orthographic {
                center: center - across * (1.0 - f),
                direction,
                up,
                size: size * f,
            }
        }
    }
}

/// The camera, looking along its own direction, moved (and for the orthographic one sized)
/// so that the box `min..max` fills a `width` × `height` image with a small margin.
pub fn frame(start: &Camera, min: Vec3, max: Vec3, width: u32, height: u32) -> Camera {
    let c = (min + max) * 0.5;
    let r = ((max - min).length() * 0.5).max(1e-3);
    let (w, h) = (width.max(1) as f32, height.max(1) as f32);
    // The camera spans the larger side; the smaller one sees less.
    let small = w.min(h) / w.max(h);
    let margin = 1.1;
    let dir = unit(start.direction()).unwrap_or(Vec3::NEG_Z);
    match *start {
        Camera::Perspective {
            direction,
            up,
            angle,
            ..
        } => {
            let half = ((angle.to_radians() * 0.5).tan() * small).atan();
            let distance = r * margin / half.sin();
            Camera::Perspective {
                center: c - dir * distance,
                direction,
                up,
                angle,
            }
        }
        Camera::Orthographic { direction, up, .. } => {
            let size = 2.0 * r * margin / small;
            Camera::Orthographic {
                center: c - dir * (2.0 * r + 1.0),
                direction,
                up,
                size,
            }
        }
    }
}

/// The views along the axes (Blender's numpad 1, 3 and 7).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AxisView {
    /// Looking along −z, y up.
    Front,
    /// Looking along −x (from the right), y up.
    Right,
    /// Looking down −y, −z up (the front at the bottom of the picture).
    Top,
}

impl AxisView {
    pub fn direction_up(self) -> (Vec3, Vec3) {
        match self {
            AxisView::Front => (Vec3::NEG_Z, Vec3::Y),
            AxisView::Right => (Vec3::NEG_X, Vec3::Y),
            AxisView::Top => (Vec3::NEG_Y, Vec3::NEG_Z),
        }
    }
}

/// The camera turned to an axis view (same kind, angle or size), then framed on the box.
pub fn axis_view(
    start: &Camera,
    view: AxisView,
    min: Vec3,
    max: Vec3,
    width: u32,
    height: u32,
) -> Camera {
    let (d, up) = view.direction_up();
    frame(
        &with_pose(start, start.center(), d, up),
        min,
        max,
        width,
        height,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use tracelab_core::render::CameraRays;

    fn persp() -> Camera {
        Camera::Perspective {
            center: Vec3::new(0.0, 0.8, 5.0),
            direction: Vec3::new(0.0, 0.0, -2.0),
            up: Vec3::Y,
            angle: 30.0,
        }
    }

    #[test]
    fn rays_match_the_renderers_for_both_kinds_and_odd_sizes() {
        let ortho = Camera::Orthographic {
            center: Vec3::new(1.0, 2.0, 9.0),
            direction: Vec3::new(0.2, -0.1, -1.0),
            up: Vec3::new(0.1, 1.0, 0.3),
            size: 4.5,
        };
        for cam in [persp(), ortho] {
            let core = CameraRays::new(&cam);
            for (w, h) in [(7u32, 3u32), (3, 7), (680, 656)] {
                let b = ViewBasis::new(&cam, w, h);
                for (i, row) in [(0, 0), (w - 1, h - 1), (w / 2, h / 3)] {
                    let r = core.pixel_ray(i, row, w, h);
                    let (o, d) = b.ray(Vec2::new(i as f32 + 0.5, row as f32 + 0.5));
                    assert!(
                        (o - r.origin).length() < 1e-4 && (d - r.direction).length() < 1e-5,
                        "{w}x{h} ({i},{row})"
                    );
                    // And a point on that ray projects back to the pixel's centre.
                    let p = b.project(o + d * 3.0).expect("in front");
                    assert!(
                        (p - Vec2::new(i as f32 + 0.5, row as f32 + 0.5)).length() < 1e-2,
                        "{p}"
                    );
                }
            }
        }
    }

    #[test]
    fn orbit_keeps_the_pivot_on_screen_and_up_as_written() {
        let cam = Camera::Perspective {
            center: Vec3::new(1.0, 2.0, 6.0),
            direction: Vec3::new(-0.1, -0.3, -1.0),
            up: Vec3::new(0.0, 2.0, 0.5),
            angle: 40.0,
        };
        let b = ViewBasis::new(&cam, 400, 300);
        let pivot = cam.center() + Vec3::new(0.3, -0.1, -1.0) * 4.0;
        let before = b.project(pivot).expect("visible");
        let after_cam = orbit(&cam, pivot, 35.0, -20.0);
        let after = ViewBasis::new(&after_cam, 400, 300)
            .project(pivot)
            .expect("visible");
        assert!((before - after).length() < 1e-2, "{before} {after}");
        assert_eq!(after_cam.up(), cam.up());
        // No roll: the screen's right stays perpendicular to the up axis.
        assert!(
            ViewBasis::new(&after_cam, 400, 300)
                .rays
                .horizontal
                .dot(cam.up().normalize())
                .abs()
                < 1e-5
        );
    }

    #[test]
    fn orbit_stops_short_of_the_pole() {
        let cam = persp();
        let down = orbit(&cam, Vec3::ZERO, 0.0, -500.0);
        let e = unit(down.direction())
            .expect("dir")
            .dot(Vec3::Y)
            .asin()
            .to_degrees();
        assert!((e - (-MAX_ELEVATION_DEGREES)).abs() < 1e-3, "{e}");
        let up = orbit(&cam, Vec3::ZERO, 0.0, 500.0);
        let e = unit(up.direction())
            .expect("dir")
            .dot(Vec3::Y)
            .asin()
            .to_degrees();
        assert!((e - MAX_ELEVATION_DEGREES).abs() < 1e-3, "{e}");
    }

    #[test]
    fn zoom_keeps_the_point_toward_on_screen() {
        let ortho = Camera::Orthographic {
            center: Vec3::new(0.0, 0.0, 10.0),
            direction: Vec3::NEG_Z,
            up: Vec3::Y,
            size: 5.0,
        };
        for cam in [persp(), ortho] {
            let p = Vec3::new(0.7, 0.2, 0.0);
            let before = ViewBasis::new(&cam, 300, 300).project(p).expect("visible");
            let z = zoom(&cam, p, 2.0);
            let after = ViewBasis::new(&z, 300, 300).project(p).expect("visible");
            assert!((before - after).length() < 1e-2, "{before} {after}");
        }
    }

    #[test]
    fn framing_puts_the_box_inside_the_image() {
        let cam = orbit(&persp(), Vec3::ZERO, 30.0, 20.0);
        let (min, max) = (Vec3::new(-3.0, 1.0, -2.0), Vec3::new(-1.0, 4.0, 0.5));
        for (w, h) in [(680, 656), (300, 600)] {
            let f = frame(&cam, min, max, w, h);
            let b = ViewBasis::new(&f, w, h);
            for i in 0..8 {
                let corner = Vec3::new(
                    if i & 1 == 0 { min.x } else { max.x },
                    if i & 2 == 0 { min.y } else { max.y },
                    if i & 4 == 0 { min.z } else { max.z },
                );
                let p = b.project(corner).expect("in front");
                assert!(
                    p.x > 0.0 && p.y > 0.0 && p.x < w as f32 && p.y < h as f32,
                    "{p} in {w}x{h}"
                );
            }
        }
    }
}
