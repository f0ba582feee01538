//! The render view's mouse tools: orbit (middle-drag, Alt+left-drag), pan (Shift+middle-
//! drag), zoom (wheel) and the gizmo's drags. Each turns pointer motion into an ordinary
//! edit (`SetCamera`, `SetOpOfKind`) queued as a command; a drag coalesces into one undo
//! step, and Esc takes it back.

use std::time::{Duration, Instant};

use glam::{Vec2, Vec3};
use tracelab_core::Camera;

use crate::bounds::{world_bounds, world_centre};
use crate::document::edit::Edit;
use crate::document::{Document, Selection};
use crate::gui::command::AppCommand;
use crate::gui::gizmo::{Axes, Gizmo, GizmoDrag, Handle};
use crate::gui::light_gizmo::{LightDrag, LightGizmo};
use crate::gui::on_screen::OnScreen;
use crate::navigation::{self, ViewBasis};

/// The render counts as "moving" this long after the last pointer motion or wheel notch:
/// meanwhile only coarse passes are rendered.
pub const STILL_AFTER: Duration = Duration::from_millis(150);

enum Tool {
    Orbit {
        camera: Camera,
        pivot: Vec3,
    },
    Pan {
        camera: Camera,
        basis: ViewBasis,
        depth: f32,
    },
    Gizmo(GizmoDrag),
    Light(LightDrag),
}

struct Drag {
    tool: Tool,
    /// Where the button went down (screen points): the drag is measured from there.
    origin: egui::Pos2,
    /// The document's state before the drag, for Esc.
    mark: u64,
    last_pos: egui::Pos2,
    /// The image cell it started in: only that one follows it.
    cell: usize,
}

/// Tool state of the view: plain data, no document.
#[derive(Default)]
pub struct ViewTools {
    drag: Option<Drag>,
    /// Esc ended the drag; ignore the pointer until the button is released.
    cancelled: bool,
    /// The handle under the pointer (or being dragged).
    pub hot: Option<Handle>,
    last_motion: Option<Instant>,
    last_wheel: Option<Instant>,
    /// The point the last wheel notch zoomed toward: the rest of a burst keeps it while the
    /// image under the pointer is still being rendered.
    wheel_toward: Option<Vec3>,
}

/// Where to turn or zoom about when the pointer is over the background: the selection's
/// centre, else the scene's, else a point ahead of the camera.
fn fallback_pivot(doc: &Document) -> Vec3 {
    let sel = match doc.selection {
        Some(Selection::Node(id)) => world_centre(&doc.scene, id),
        _ => None,
    };
    sel.or_else(|| world_bounds(&doc.scene, doc.scene.graph.root()).map(|(a, b)| (a + b) * 0.5))
        .unwrap_or_else(|| {
            doc.scene.camera.center()
                + doc.scene.camera.direction().normalize_or(Vec3::NEG_Z) * 10.0
        })
}

/// Wheel notches this frame (positive: away from the user, which zooms in).
fn wheel_notches(ui: &egui::Ui) -> f32 {
    ui.input(|i| {
        i.events
            .iter()
            .map(|e| match e {
                egui::Event::MouseWheel { unit, delta, .. } => match unit {
                    egui::MouseWheelUnit::Line => delta.y,
                    egui::MouseWheelUnit::Point => delta.y / 50.0,
                    egui::MouseWheelUnit::Page => delta.y * 10.0,
                },
                _ => 0.0,
            })
            .sum()
    })
}

impl ViewTools {
    /// Called once a frame before the cells: a handle is hot only while the pointer is on it.
    pub fn begin_frame(&mut self) {
        if self.drag.is_none() {
            self.hot = None;
        }
    }

    /// Whether a drag is going on.
    pub fn dragging(&self) -> bool {
        self.drag.is_some()
    }

    /// Whether the view is being moved right now (the pointer moved or the wheel turned
    /// within [`STILL_AFTER`]): render coarse passes only.
    pub fn moving(&self) -> bool {
        let recent = |t: Option<Instant>| t.is_some_and(|t| t.elapsed() < STILL_AFTER);
        (self.drag.is_some() && recent(self.last_motion)) || recent(self.last_wheel)
    }

    /// Whether wheel notches may still follow (one undo step for a burst of them).
    pub fn wheel_busy(&self) -> bool {
        self.last_wheel
            .is_some_and(|t| t.elapsed() < Duration::from_millis(600))
    }

    /// The gizmo for the document's selection in this view.
    pub fn gizmo(doc: &Document, view: &OnScreen, axes: Axes) -> Option<Gizmo> {
        match doc.selection {
            Some(Selection::Node(id)) => Gizmo::new(&doc.scene, id, view, axes),
            _ => None,
        }
    }

    /// The arrows of the selected point light in this view.
    pub fn light_gizmo(doc: &Document, view: &OnScreen) -> Option<LightGizmo> {
        match doc.selection {
            Some(Selection::Light(i)) => LightGizmo::new(&doc.scene, i, view),
            _ => None,
        }
    }

    /// Handles one image cell's pointer input. `surface` gives the world point shown at an
    /// image pixel (from the render on screen), if it shows one. Returns true when the
    /// pointer was used, so a click there is not also a pick.
    #[allow(clippy::too_many_arguments)]
    pub fn cell(
        &mut self,
        ui: &egui::Ui,
        resp: &egui::Response,
        cell: usize,
        view: &OnScreen,
        doc: &Document,
        axes: Axes,
        surface: &dyn Fn(Vec2) -> Option<Vec3>,
        out: &mut Vec<AppCommand>,
    ) -> bool {
        let gizmo = Self::gizmo(doc, view, axes);
        let light_gizmo = Self::light_gizmo(doc, view);
        let (pos, press_origin, any_down, modifiers, esc) = ui.input(|i| {
            (
                i.pointer.interact_pos(),
                i.pointer.press_origin(),
                i.pointer.any_down(),
                i.modifiers,
                i.key_pressed(egui::Key::Escape),
            )
        });
        if !any_down {
            self.cancelled = false;
        }
        if self.drag.is_none()
            && !self.cancelled
            && let (Some(g), Some(p)) = (&gizmo, pos)
            && view.rect.contains(p)
        {
            self.hot = g.pick(view, p);
        }
        if self.drag.is_none()
            && !self.cancelled
            && let (Some(g), Some(p)) = (&light_gizmo, pos)
            && view.rect.contains(p)
        {
            self.hot = g.pick(view, p);
        }
        let mut used = false;
        // A new drag.
        if self.drag.is_none() && !self.cancelled && resp.drag_started() {
            let origin = press_origin.or(pos).unwrap_or(view.rect.center());
            let under = surface(view.to_pixels(origin));
            let camera = doc.scene.camera.clone();
            let middle = resp.dragged_by(egui::PointerButton::Middle);
            let primary = resp.dragged_by(egui::PointerButton::Primary);
            let tool = if primary && !modifiers.alt {
                let light = light_gizmo.as_ref().and_then(|g| {
                    let l = doc.scene.lights().get(g.light)?;
                    let h = g.pick(view, origin)?;
                    g.grab(view, h, origin, l)
                });
                gizmo
                    .as_ref()
                    .and_then(|g| g.pick(view, origin).and_then(|h| g.grab(view, h, origin)))
                    .map(Tool::Gizmo)
                    .or(light.map(Tool::Light))
            } else if (middle && modifiers.shift) || (primary && modifiers.alt && modifiers.shift) {
                let depth = view
                    .basis
                    .depth(under.unwrap_or_else(|| fallback_pivot(doc)));
                Some(Tool::Pan {
                    camera,
                    basis: view.basis,
                    depth,
                })
            } else if middle || (primary && modifiers.alt) {
                Some(Tool::Orbit {
                    camera,
                    pivot: under.unwrap_or_else(|| fallback_pivot(doc)),
                })
            } else {
                None
            };
            if let Some(tool) = tool {
                match &tool {
                    Tool::Gizmo(g) => self.hot = Some(g.handle),
                    Tool::Light(g) => self.hot = Some(g.handle),
                    _ => {}
                }
                self.drag = Some(Drag {
                    tool,
                    origin,
                    mark: doc.history_mark(),
                    last_pos: origin,
                    cell,
                });
            }
        }
        if let Some(drag) = self.drag.as_mut().filter(|d| d.cell == cell) {
            used = true;
            if esc {
                out.push(AppCommand::CancelDrag { mark: drag.mark });
                self.drag = None;
                self.cancelled = true;
                self.hot = None;
                return used;
            }
            if !any_down {
                self.drag = None;
                return used;
            }
            let Some(p) = pos else { return used };
            if p != drag.last_pos {
                drag.last_pos = p;
                self.last_motion = Some(Instant::now());
                let d = p - drag.origin;
                let edit = match &mut drag.tool {
                    Tool::Orbit { camera, pivot } => {
                        let k = navigation::ORBIT_DEGREES_PER_POINT;
                        // Grab the scene: dragging right turns its near side right.
                        Some(Edit::SetCamera(navigation::orbit(
                            camera,
                            *pivot,
                            -d.x * k,
                            -d.y * k,
                        )))
                    }
                    Tool::Pan {
                        camera,
                        basis,
                        depth,
                    } => {
                        let ppp = view.pixels_per_point();
                        Some(Edit::SetCamera(navigation::pan(
                            camera,
                            basis,
                            *depth,
                            d.x * ppp,
                            d.y * ppp,
                        )))
                    }
                    Tool::Gizmo(g) => g
                        .value(view, p, modifiers.command)
                        .map(|op| Edit::SetOpOfKind { node: g.node, op }),
                    // One undo step per drag: SetLight edits of one gesture coalesce.
                    Tool::Light(g) => {
                        g.value(view, p, modifiers.command)
                            .map(|light| Edit::SetLight {
                                index: g.light,
                                light,
                            })
                    }
                };
                out.extend(edit.map(AppCommand::Edit));
            }
            return used;
        }
        if self.drag.is_some() {
            return used;
        }
        // The wheel, over the image.
        let notches = if resp.hovered() {
            wheel_notches(ui)
        } else {
            0.0
        };
        if notches != 0.0 {
            let at = pos.unwrap_or(view.rect.center());
            let burst = self.wheel_toward.filter(|_| self.wheel_busy());
            let toward = surface(view.to_pixels(at)).or(burst).unwrap_or_else(|| {
                // Over the background: the point on the pointer's ray at the pivot's depth.
                let (o, d) = view.ray(at);
                let depth = view.basis.depth(fallback_pivot(doc)).max(1e-3);
                o + d * (depth / d.dot(view.basis.rays.direction).max(1e-3))
            });
            self.wheel_toward = Some(toward);
            self.last_wheel = Some(Instant::now());
            out.push(AppCommand::Edit(Edit::SetCamera(navigation::zoom(
                &doc.scene.camera,
                toward,
                notches,
            ))));
            used = true;
        }
        used
    }
}
