//! The gizmo of a selected point light: the three translate arrows at its position, along
//! the world's axes (a light's position is in world space, with no Transform above it), and
//! the drag that turns the pointer into its new position.

use glam::Vec3;
use tracelab_core::scene::LightKind;
use tracelab_core::{Light, Scene};

use crate::gui::gizmo::{
    ARM, Handle, PICK, SNAP_LENGTH, arrow_distance, axis_colour, line_param, paint_arrow,
};
use crate::gui::on_screen::OnScreen;

/// The arrows of point light `light`, as they stand this frame.
#[derive(Clone, Debug)]
pub struct LightGizmo {
    pub light: usize,
    /// The light's world position.
    pub origin: Vec3,
    /// World length of an arm.
    arm: f32,
}

impl LightGizmo {
    /// `None` for a directional light (it has no place) or one behind the camera.
    pub fn new(scene: &Scene, light: usize, view: &OnScreen) -> Option<LightGizmo> {
        let LightKind::Point { position, .. } = scene.lights().get(light)?.kind else {
            return None;
        };
        view.project(position)?;
        Some(LightGizmo {
            light,
            origin: position,
            arm: ARM * view.world_per_point(position),
        })
    }

    /// A point of an arrow where a hand would take it (world): for tests and scripts.
    pub fn handle_point(&self, axis: usize) -> Vec3 {
        self.origin + Vec3::AXES[axis % 3] * self.arm * 0.8
    }

    /// The arrow under `pos` (screen points), if any.
    pub fn pick(&self, view: &OnScreen, pos: egui::Pos2) -> Option<Handle> {
        (0..3)
            .filter_map(|i| {
                arrow_distance(view, self.origin, Vec3::AXES[i], self.arm, pos).map(|d| (d, i))
            })
            .filter(|(d, _)| *d < PICK)
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(_, i)| Handle::Move(i))
    }

    /// Draws the arrows; `hot` is the one hovered or dragged.
    pub fn paint(&self, painter: &egui::Painter, view: &OnScreen, hot: Option<Handle>) {
        for i in 0..3 {
            let col = axis_colour(i, hot == Some(Handle::Move(i)));
            paint_arrow(painter, view, self.origin, Vec3::AXES[i], self.arm, col);
        }
    }

    /// Starts dragging arrow `handle` of `light` (as the document holds it), grabbed at `pos`.
    pub fn grab(
        &self,
        view: &OnScreen,
        handle: Handle,
        pos: egui::Pos2,
        light: &Light,
    ) -> Option<LightDrag> {
        let Handle::Move(i) = handle else { return None };
        let axis = Vec3::AXES[i % 3];
        Some(LightDrag {
            light: self.light,
            handle,
            axis,
            grabbed: line_param(self.origin, axis, view.ray(pos))?,
            start: light.clone(),
        })
    }
}

/// One drag of a light's arrow: measured when grabbed, so the position is a function of the
/// pointer alone.
#[derive(Clone, Debug)]
pub struct LightDrag {
    pub light: usize,
    pub handle: Handle,
    axis: Vec3,
    grabbed: f32,
    /// The light when the drag started.
    pub start: Light,
}

impl LightDrag {
    /// The light moved so the grabbed point stays under the pointer at `pos` along the arrow
    /// (Ctrl: the moved coordinate snapped); `None` where the arrow points at the eye.
    pub fn value(&self, view: &OnScreen, pos: egui::Pos2, snap: bool) -> Option<Light> {
        let mut light = self.start.clone();
        let LightKind::Point { position, .. } = &mut light.kind else {
            return None;
        };
        let origin = *position;
        let s = line_param(origin, self.axis, view.ray(pos))? - self.grabbed;
        *position += self.axis * s;
        if snap && let Handle::Move(i) = self.handle {
            position[i] = (position[i] / SNAP_LENGTH).round() * SNAP_LENGTH;
        }
        Some(light)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tracelab_core::{MeshCache, parse_scene};

    #[test]
    fn an_arrow_drag_moves_the_light_along_its_axis_with_the_pointer() {
        let s = parse_scene(
            "PerspectiveCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 angle 30 }\n\
             Lights { numLights 1 PointLight { position 1 1 2 color 1 1 1 } }\n\
             Group { numObjects 0 }\n"
                .as_bytes(),
            "t",
            None,
            &mut MeshCache::new(),
        )
        .scene
        .expect("parses");
        let view = OnScreen::new(
            &s.camera,
            300,
            300,
            egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(300.0, 300.0)),
        );
        let g = LightGizmo::new(&s, 0, &view).expect("a gizmo");
        for i in 0..3 {
            let at = g.handle_point(i);
            let grab = view.project(at).expect("on screen");
            let Some(Handle::Move(picked)) = g.pick(&view, grab) else {
                panic!("axis {i}: no arrow under its own point")
            };
            if i == 2 {
                // z points almost at the eye: its arrow is short and may lose to x or y.
                continue;
            }
            assert_eq!(picked, i);
            let drag = g
                .grab(&view, Handle::Move(i), grab, &s.lights()[0])
                .expect("grabbed");
            let to = view.project(at + Vec3::AXES[i] * 0.5).expect("on screen");
            let moved = drag.value(&view, to, false).expect("follows");
            let LightKind::Point { position, .. } = moved.kind else {
                panic!("a point light")
            };
            let want = Vec3::new(1.0, 1.0, 2.0) + Vec3::AXES[i] * 0.5;
            assert!((position - want).length() < 1e-3, "{position} vs {want}");
        }
        // Off every arrow: nothing to take.
        let far = view.project(Vec3::new(-2.0, -2.0, 0.0)).expect("on screen");
        assert_eq!(g.pick(&view, far), None);
    }
}
