//! The transform gizmo over the render view: three arrows (Translate), three squares
//! (Scale) and a ring (ZRotate) at the selection's centre, their picking, and the maths that
//! turns a drag into the value of one op of the course's Transform list.
//!
//! Our own rather than the `transform-gizmo` crate: that crate edits a whole
//! scale-quaternion-translation transform, builds on egui 0.34's emath/epaint (a second
//! copy beside our 0.37), and has no notion of a list of ops. Here a drag must set one
//! `Translate`, `Scale` or `ZRotate` in its place in the list, with the ops before it (which
//! act after it) and every enclosing Transform deciding how the value moves the object; that
//! is a few lines of linear algebra per handle, below.

use glam::{Mat4, Vec3};
use tracelab_core::{NodeId, Scene, TransformOp};

use crate::bounds::{world_centre, world_from_parent};
use crate::document::op_target::{OpKind, OpTarget, op_target};
use crate::gui::on_screen::OnScreen;

/// Arm length on screen, in points.
pub(crate) const ARM: f32 = 90.0;
/// Where the scale squares sit along the arms, and where the arrows' shafts start.
const SQUARE_AT: f32 = 0.45;
const SHAFT_FROM: f32 = 0.62;
const RING: f32 = 1.15;
/// How near (points) the pointer must be to take a handle.
pub(crate) const PICK: f32 = 7.0;

/// Ctrl snaps translations to this step (in the op's own units) …
pub const SNAP_LENGTH: f32 = 0.1;
/// … scale factors to this step …
pub const SNAP_FACTOR: f32 = 0.1;
/// … and rotations to this many degrees.
pub const SNAP_DEGREES: f32 = 15.0;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Handle {
    Move(usize),
    Scale(usize),
    Rotate,
}

impl Handle {
    pub fn kind(self) -> OpKind {
        match self {
            Handle::Move(_) => OpKind::Translate,
            Handle::Scale(_) => OpKind::Scale,
            Handle::Rotate => OpKind::ZRotate,
        }
    }
}

/// Whether the arrows follow the world's axes or the Translate's own (its Transform's
/// space). Scale and ZRotate can only act along their op's axes, so those handles always do.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Axes {
    #[default]
    World,
    Local,
}

/// The op space of one kind of handle: world = `world_from_op` · (op · after) · object.
#[derive(Clone, Debug)]
struct OpSpace {
    target: OpTarget,
    world_from_op: Mat4,
    value: TransformOp,
}

impl OpSpace {
    fn find(scene: &Scene, node: NodeId, kind: OpKind) -> Option<OpSpace> {
        let target = op_target(&scene.graph, node, kind).ok()?;
        // The space around the Transform: a new one takes the node's place.
        let around = match target.transform {
            Some(t) => world_from_parent(scene, t)?,
            None => world_from_parent(scene, node)?,
        };
        let world_from_op = around * tracelab_core::scene::compose(target.before());
        let value = if target.exists {
            target.ops.get(target.index)?.clone()
        } else {
            kind.identity()
        };
        Some(OpSpace {
            target,
            world_from_op,
            value,
        })
    }

    /// Unit world direction of the op space's axis `i`.
    fn axis(&self, i: usize) -> Vec3 {
        self.world_from_op
            .transform_vector3(Vec3::AXES[i])
            .normalize_or(Vec3::AXES[i])
    }
}

/// The gizmo for the selected node, as it stands this frame.
#[derive(Clone, Debug)]
pub struct Gizmo {
    pub node: NodeId,
    /// World centre of the node's objects.
    pub origin: Vec3,
    /// World length of an arm.
    arm: f32,
    translate: OpSpace,
    scale: OpSpace,
    rotate: OpSpace,
    axes: Axes,
}

impl Gizmo {
    pub fn new(scene: &Scene, node: NodeId, view: &OnScreen, axes: Axes) -> Option<Gizmo> {
        let origin = world_centre(scene, node)?;
        view.project(origin)?;
        Some(Gizmo {
            node,
            origin,
            arm: ARM * view.world_per_point(origin),
            translate: OpSpace::find(scene, node, OpKind::Translate)?,
            scale: OpSpace::find(scene, node, OpKind::Scale)?,
            rotate: OpSpace::find(scene, node, OpKind::ZRotate)?,
            axes,
        })
    }

    fn move_axis(&self, i: usize) -> Vec3 {
        match self.axes {
            Axes::World => Vec3::AXES[i],
            Axes::Local => self.translate.axis(i),
        }
    }

    /// The ring's points in the world: a circle in the ZRotate's own xy plane through the
    /// origin's depth, about its z axis.
    fn ring(&self) -> Vec<Vec3> {
        let s = &self.rotate.world_from_op;
        let Some(inv) = invert(s) else {
            return Vec::new();
        };
        let o = inv.transform_point3(self.origin);
        let centre = Vec3::new(0.0, 0.0, o.z);
        let (ex, ey) = (
            s.transform_vector3(Vec3::X).length(),
            s.transform_vector3(Vec3::Y).length(),
        );
        let r = RING * self.arm / ex.max(ey).max(1e-9);
        // Around the rotation's centre when the object sits on its axis; else around the
        // object, with the same orientation, so it stays where the eye is.
        let at = if (o - centre).truncate().length() < r * 0.5 {
            centre
        } else {
            o
        };
        (0..=48)
            .map(|k| {
                let a = k as f32 / 48.0 * std::f32::consts::TAU;
                s.transform_point3(at + Vec3::new(a.cos() * r, a.sin() * r, 0.0))
            })
            .collect()
    }

    /// A point of a handle where a hand would take it (world): for tests and scripts.
    pub fn handle_point(&self, h: Handle) -> Vec3 {
        match h {
            Handle::Move(i) => self.origin + self.move_axis(i) * self.arm * 0.8,
            Handle::Scale(i) => self.origin + self.scale.axis(i) * self.arm * SQUARE_AT,
            Handle::Rotate => self.ring().first().copied().unwrap_or(self.origin),
        }
    }

    /// The handle under `pos` (screen points), if any.
    pub fn pick(&self, view: &OnScreen, pos: egui::Pos2) -> Option<Handle> {
        let mut best: Option<(f32, Handle)> = None;
        let mut consider = |d: f32, h: Handle| {
            if d < PICK && best.is_none_or(|(b, _)| d < b) {
                best = Some((d, h));
            }
        };
        let o = self.origin;
        for i in 0..3 {
            let a = self.move_axis(i);
            if let Some(d) = arrow_distance(view, o, a, self.arm, pos) {
                consider(d, Handle::Move(i));
            }
            if let Some(c) = view.project(o + self.scale.axis(i) * self.arm * SQUARE_AT) {
                // The squares win over a shaft they overlap.
                consider((pos - c).length() * 0.8, Handle::Scale(i));
            }
        }
        let ring: Vec<egui::Pos2> = self
            .ring()
            .into_iter()
            .filter_map(|p| view.project(p))
            .collect();
        for w in ring.windows(2) {
            consider(segment_distance(pos, w[0], w[1]), Handle::Rotate);
        }
        best.map(|(_, h)| h)
    }

    /// Draws the handles; `hot` is the one hovered or dragged.
    pub fn paint(&self, painter: &egui::Painter, view: &OnScreen, hot: Option<Handle>) {
        let colour = |i: usize, h: Handle| axis_colour(i, hot == Some(h));
        let o = self.origin;
        let Some(c) = view.project(o) else { return };
        let ring: Vec<egui::Pos2> = self
            .ring()
            .into_iter()
            .filter_map(|p| view.project(p))
            .collect();
        let ring_colour = if hot == Some(Handle::Rotate) {
            egui::Color32::from_rgb(255, 230, 60)
        } else {
            egui::Color32::from_rgb(90, 210, 230)
        };
        painter.add(egui::Shape::line(ring, egui::Stroke::new(2.0, ring_colour)));
        for i in 0..3 {
            let a = self.move_axis(i);
            paint_arrow(painter, view, o, a, self.arm, colour(i, Handle::Move(i)));
            if let Some(q) = view.project(o + self.scale.axis(i) * self.arm * SQUARE_AT) {
                let col = colour(i, Handle::Scale(i));
                painter.rect_filled(
                    egui::Rect::from_center_size(q, egui::vec2(8.0, 8.0)),
                    1.0,
                    col,
                );
                painter.line_segment([c, q], egui::Stroke::new(1.0, col.gamma_multiply(0.6)));
            }
        }
        painter.circle_filled(c, 3.0, egui::Color32::WHITE);
    }

    /// Starts dragging `handle`, grabbed at `pos`.
    pub fn grab(&self, view: &OnScreen, handle: Handle, pos: egui::Pos2) -> Option<GizmoDrag> {
        let ray = view.ray(pos);
        let space = match handle {
            Handle::Move(_) => &self.translate,
            Handle::Scale(_) => &self.scale,
            Handle::Rotate => &self.rotate,
        };
        let inv = invert(&space.world_from_op)?;
        let along = match handle {
            Handle::Move(i) => line_param(self.origin, self.move_axis(i), ray)?,
            Handle::Scale(i) => {
                // Measured in op units along the op's own axis, from its origin.
                let dir = space.world_from_op.transform_vector3(Vec3::AXES[i]);
                let per_unit = dir.length();
                let o_op = inv.transform_point3(self.origin);
                o_op[i] + line_param(self.origin, dir / per_unit, ray)? / per_unit
            }
            Handle::Rotate => op_angle(&inv, inv.transform_point3(self.origin).z, ray)?,
        };
        Some(GizmoDrag {
            node: self.node,
            handle,
            origin: self.origin,
            axis: match handle {
                Handle::Move(i) => self.move_axis(i),
                _ => Vec3::ZERO,
            },
            world_from_op: space.world_from_op,
            start: space.value.clone(),
            grabbed: along,
            arm_in_op: self.arm
                / space
                    .world_from_op
                    .transform_vector3(Vec3::X)
                    .length()
                    .max(1e-9),
            last_angle: along,
            turned: 0.0,
            target: space.target.clone(),
        })
    }
}

/// One drag of a handle: everything measured when it was grabbed, so the value is a function
/// of the pointer alone (no drift), and the start value for Esc.
#[derive(Clone, Debug)]
pub struct GizmoDrag {
    pub node: NodeId,
    pub handle: Handle,
    origin: Vec3,
    axis: Vec3,
    world_from_op: Mat4,
    pub start: TransformOp,
    /// Where along the handle it was grabbed: world units along the arrow, op units along a
    /// scale axis, degrees round the ring.
    grabbed: f32,
    arm_in_op: f32,
    last_angle: f32,
    turned: f32,
    /// Where the op is (or will be added) when the drag started.
    pub target: OpTarget,
}

impl GizmoDrag {
    /// The op's value for the pointer at `pos`; `None` where the handle cannot follow (an
    /// axis pointing at the eye, a ring seen edge on).
    pub fn value(&mut self, view: &OnScreen, pos: egui::Pos2, snap: bool) -> Option<TransformOp> {
        let ray = view.ray(pos);
        let inv = invert(&self.world_from_op)?;
        let op = match (&self.start, self.handle) {
            (TransformOp::Translate(t0), Handle::Move(_)) => {
                // The world move that keeps the grabbed point under the pointer along the
                // axis, taken back into the op's units through the linear part of everything
                // that acts after the Translate: the same move whatever the scales above it.
                let s = line_param(self.origin, self.axis, ray)? - self.grabbed;
                let delta = inv.transform_vector3(self.axis * s);
                let mut t = *t0 + delta;
                if snap {
                    for k in 0..3 {
                        if delta[k].abs() > 1e-7 {
                            t[k] = (t[k] / SNAP_LENGTH).round() * SNAP_LENGTH;
                        }
                    }
                }
                TransformOp::Translate(t)
            }
            (TransformOp::Scale(s0), Handle::Scale(i)) => {
                let dir = self.world_from_op.transform_vector3(Vec3::AXES[i]);
                let per_unit = dir.length();
                let o_op = inv.transform_point3(self.origin);
                let now = o_op[i] + line_param(self.origin, dir / per_unit, ray)? / per_unit;
                // The grabbed point, at op coordinate `grabbed`, goes to `now` under a factor
                // now/grabbed; near the op's origin that is ill-conditioned, so there the arm
                // length sets the rate.
                let f = if self.grabbed.abs() > 0.25 * self.arm_in_op {
                    now / self.grabbed
                } else {
                    1.0 + (now - self.grabbed) / self.arm_in_op
                };
                let mut s = *s0;
                s[i] = s0[i] * f.max(0.01);
                if snap {
                    let snapped = (s[i] / SNAP_FACTOR).round() * SNAP_FACTOR;
                    s[i] = if snapped.abs() < SNAP_FACTOR {
                        SNAP_FACTOR.copysign(s0[i])
                    } else {
                        snapped
                    };
                }
                TransformOp::Scale(s)
            }
            (TransformOp::ZRotate(d0), Handle::Rotate) => {
                let a = op_angle(&inv, inv.transform_point3(self.origin).z, ray)?;
                // Unwrapped, so turning past half a circle keeps going.
                self.turned += wrap_degrees(a - self.last_angle);
                self.last_angle = a;
                let mut d = d0 + self.turned;
                if snap {
                    d = (d / SNAP_DEGREES).round() * SNAP_DEGREES;
                }
                TransformOp::ZRotate(d)
            }
            _ => return None,
        };
        Some(op)
    }
}

/// A handle's colour: x red, y green, z blue; yellow while hot.
pub(crate) fn axis_colour(i: usize, hot: bool) -> egui::Color32 {
    if hot {
        egui::Color32::from_rgb(255, 230, 60)
    } else {
        [
            egui::Color32::from_rgb(230, 60, 60),
            egui::Color32::from_rgb(80, 200, 80),
            egui::Color32::from_rgb(70, 120, 255),
        ][i % 3]
    }
}

/// How far (points) `pos` is from the translate arrow along unit `a` from `o`, `arm` world
/// units long (its head counted in); `None` when the arrow is off screen.
pub(crate) fn arrow_distance(
    view: &OnScreen,
    o: Vec3,
    a: Vec3,
    arm: f32,
    pos: egui::Pos2,
) -> Option<f32> {
    let p0 = view.project(o + a * arm * SHAFT_FROM)?;
    let p1 = view.project(o + a * arm)?;
    Some(segment_distance(pos, p0, p1 + (p1 - p0) * 0.3))
}

/// Draws the translate arrow along unit `a` from `o`, `arm` world units long.
pub(crate) fn paint_arrow(
    painter: &egui::Painter,
    view: &OnScreen,
    o: Vec3,
    a: Vec3,
    arm: f32,
    col: egui::Color32,
) {
    let (Some(p0), Some(p1)) = (
        view.project(o + a * arm * SHAFT_FROM),
        view.project(o + a * arm),
    ) else {
        return;
    };
    painter.line_segment([p0, p1], egui::Stroke::new(2.5, col));
    let d = (p1 - p0).normalized();
    if d.is_finite() && (p1 - p0).length() > 4.0 {
        let n = egui::vec2(-d.y, d.x);
        let tip = p1 + d * 12.0;
        painter.add(egui::Shape::convex_polygon(
            vec![tip, p1 + n * 5.0, p1 - n * 5.0],
            col,
            egui::Stroke::NONE,
        ));
    }
}

fn invert(m: &Mat4) -> Option<Mat4> {
    let d = m.determinant();
    (d.is_finite() && d.abs() > 1e-30).then(|| m.inverse())
}

fn wrap_degrees(d: f32) -> f32 {
    (d + 180.0).rem_euclid(360.0) - 180.0
}

/// The parameter along the line `o + s·a` (a unit) of its point nearest the ray.
pub(crate) fn line_param(o: Vec3, a: Vec3, (ro, rd): (Vec3, Vec3)) -> Option<f32> {
    let rd = rd.normalize_or_zero();
    let b = a.dot(rd);
    let denom = 1.0 - b * b;
    // An axis pointing (almost) along the ray has no screen direction to follow.
    if denom < 1e-4 {
        return None;
    }
    let w = o - ro;
    let s = (b * rd.dot(w) - a.dot(w)) / denom;
    s.is_finite().then_some(s)
}

/// The angle (degrees) round the op's z axis of the point where the ray meets the op's
/// plane z = `z0`, all in op space.
fn op_angle(inv: &Mat4, z0: f32, (ro, rd): (Vec3, Vec3)) -> Option<f32> {
    let (o, d) = (inv.transform_point3(ro), inv.transform_vector3(rd));
    if d.z.abs() < 1e-6 * d.length() {
        return None;
    }
    let t = (z0 - o.z) / d.z;
    let h = o + d * t;
    let a = h.y.atan2(h.x).to_degrees();
    (a.is_finite() && h.truncate().length() > 1e-9).then_some(a)
}

fn segment_distance(p: egui::Pos2, a: egui::Pos2, b: egui::Pos2) -> f32 {
    let ab = b - a;
    let t = ((p - a).dot(ab) / ab.length_sq().max(1e-9)).clamp(0.0, 1.0);
    (p - (a + ab * t)).length()
}

#[cfg(test)]
mod tests {
    use super::*;
    use tracelab_core::{MeshCache, NodeKind, parse_scene};

    fn scene(text: &str) -> Scene {
        parse_scene(text.as_bytes(), "t", None, &mut MeshCache::new())
            .scene
            .expect("parses")
    }

    fn sphere(s: &Scene) -> NodeId {
        s.graph
            .preorder()
            .into_iter()
            .find(|&id| matches!(s.graph.node(id).kind, NodeKind::Sphere { .. }))
            .expect("sphere")
    }

    const SCALED: &str = "PerspectiveCamera { center 1 2 12 direction -0.1 -0.15 -1 up 0 1 0 angle 30 }\n\
        Group { numObjects 1 Transform { UniformScale 5 ZRotate 30 Transform { Scale 1 2 1 Translate 0.1 0 0 Sphere { center 0 0 0 radius 0.1 } } } }\n";

    #[test]
    fn a_translate_drag_keeps_the_grabbed_point_under_the_pointer_whatever_the_scales() {
        let s = scene(SCALED);
        let node = sphere(&s);
        let view = OnScreen::new(
            &s.camera,
            400,
            400,
            egui::Rect::from_min_size(egui::pos2(10.0, 20.0), egui::vec2(400.0, 400.0)),
        );
        for axes in [Axes::World, Axes::Local] {
            let g = Gizmo::new(&s, node, &view, axes).expect("gizmo");
            for i in 0..3 {
                let a = g.move_axis(i);
                let grab_world = g.origin + a * g.arm * 0.8;
                let grab = view.project(grab_world).expect("visible");
                let mut drag = g.grab(&view, Handle::Move(i), grab).expect("grabbed");
                let to_world = grab_world + a * 0.3;
                let to = view.project(to_world).expect("visible");
                let op = drag.value(&view, to, false).expect("follows");
                let mut moved = s.clone();
                crate::document::edit::apply_to(
                    &mut moved,
                    crate::document::edit::Edit::SetOpOfKind { node, op },
                )
                .expect("applies");
                let c = world_centre(&moved, node).expect("centre");
                assert!(
                    (c - (g.origin + a * 0.3)).length() < 1e-3,
                    "{axes:?} axis {i}: {c} vs {}",
                    g.origin + a * 0.3
                );
            }
        }
    }

    #[test]
    fn a_ring_drag_turns_the_grabbed_point_to_the_pointer_and_snaps_to_15_degrees() {
        let s = scene(
            "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 6 }\n\
            Group { numObjects 1 Transform { Translate 1 0 0 Sphere { center 0 0 0 radius 0.5 } } }\n",
        );
        let node = sphere(&s);
        let view = OnScreen::new(
            &s.camera,
            300,
            300,
            egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(300.0, 300.0)),
        );
        let g = Gizmo::new(&s, node, &view, Axes::World).expect("gizmo");
        let ring = g.ring();
        let grab = view.project(ring[0]).expect("on screen");
        assert_eq!(g.pick(&view, grab), Some(Handle::Rotate));
        let mut drag = g.grab(&view, Handle::Rotate, grab).expect("grabbed");
        assert!(
            !drag.target.exists && drag.target.index == 1,
            "{:?}",
            drag.target
        );
        let to = view.project(ring[8]).expect("on screen"); // 60° on
        let Some(TransformOp::ZRotate(d)) = drag.value(&view, to, false) else {
            panic!("a ZRotate")
        };
        assert!((d - 60.0).abs() < 0.5, "{d}");
        let Some(TransformOp::ZRotate(d)) =
            drag.value(&view, view.project(ring[10]).expect("on"), true)
        else {
            panic!("a ZRotate")
        };
        assert_eq!(d, 75.0);
    }
}
