//! The lecture's "World Space / Object Space" figure as plain data: for the picked pixel,
//! what to draw in each space (points, polylines, arrows, in 3D) and an orbit projection to
//! the screen. The Ray panel draws it; tests check its points against the ray story.

use glam::{DMat4, Vec2, Vec3};
use tracelab_core::render::{RayKind, RayNode, RayStory};
use tracelab_core::{Camera, MeshSlot, NodeKind, Scene};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    Eye,
    Ray,
    Outline,
    Hit,
    /// (M⁻¹)ᵀ·n, or the object normal in object space.
    NormalCorrect,
    /// M·n.
    NormalIncorrect,
    Tangent,
    Light,
    /// The object-space direction M⁻¹d, drawn from M⁻¹o with its own length.
    Direction,
    /// A reflected ray of the pixel's ray tree (assignment 4), to its hit or, past a miss,
    /// a stretch of its direction.
    Reflected,
    /// A refracted (transmitted) ray of the ray tree.
    Refracted,
    /// A shadow ray that reached its light (to a point light, or a stretch toward a
    /// directional one).
    Shadow,
    /// A shadow ray stopped by an object: it ends at the blocker.
    ShadowBlocked,
    /// An occupied cell of the uniform grid (View › Uniform grid).
    GridCell,
    /// A cell the eye ray walks through in the grid, numbered in DDA order.
    GridWalk,
}

impl Role {
    /// The roles the ray tree adds, in the legend's order, with their names there.
    pub const TREE: [(Role, &'static str); 4] = [
        (Role::Reflected, "reflected"),
        (Role::Refracted, "refracted"),
        (Role::Shadow, "shadow ray, reaches the light"),
        (Role::ShadowBlocked, "shadow ray, blocked"),
    ];
}

#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    Point(Vec3),
    /// A connected line through the points.
    Line(Vec<Vec3>),
    /// From, to (the head at `to`).
    Arrow(Vec3, Vec3),
}

#[derive(Clone, Debug, PartialEq)]
pub struct Item {
    pub role: Role,
    pub shape: Shape,
    pub label: Option<String>,
}

impl Item {
    fn new(role: Role, shape: Shape, label: Option<String>) -> Item {
        Item { role, shape, label }
    }

    /// The points that `Diagram::bounds` fits: all but the ray's origin.
    fn fit_points(&self) -> Vec<Vec3> {
        match (self.role, &self.shape) {
            (Role::Eye, _) => Vec::new(),
            // A light may be far off: the view fits where the rays start.
            (Role::Shadow, Shape::Line(ps)) => ps.first().copied().into_iter().collect(),
            (Role::Ray, Shape::Line(ps)) => ps.last().copied().into_iter().collect(),
            _ => self.points(),
        }
    }

    fn points(&self) -> Vec<Vec3> {
        match &self.shape {
            Shape::Point(p) => vec![*p],
            Shape::Line(ps) => ps.clone(),
            Shape::Arrow(a, b) => vec![*a, *b],
        }
    }
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct Diagram {
    pub items: Vec<Item>,
}

impl Diagram {
    pub fn find(&self, role: Role) -> impl Iterator<Item = &Item> {
        self.items.iter().filter(move |i| i.role == role)
    }

    /// Centre and radius of what is drawn around the hit (for fitting it into a rectangle):
    /// the ray's origin is left out, being often ten times further than the object is big;
    /// the view zooms out to it.
    pub fn bounds(&self) -> (Vec3, f32) {
        let pts: Vec<Vec3> = self
            .items
            .iter()
            .flat_map(Item::fit_points)
            .filter(|p| p.is_finite())
            .collect();
        if pts.is_empty() {
            return (Vec3::ZERO, 1.0);
        }
        let (lo, hi) = pts.iter().fold(
            (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        );
        let c = (lo + hi) * 0.5;
        let r = pts.iter().map(|p| (*p - c).length()).fold(0.0f32, f32::max);
        (c, r.max(1e-6))
    }
}

/// The outline of a primitive in its own space: circles for a sphere, edges for a box, a
/// square patch for a plane (around `near`), edges for a triangle, a mesh's bounding box.
fn outline(kind: &NodeKind, near: Vec3) -> Vec<Vec<Vec3>> {
    let circle = |c: Vec3, r: f32, axis: usize| -> Vec<Vec3> {
        (0..=48)
            .map(|k| {
                let a = k as f32 / 48.0 * std::f32::consts::TAU;
                let (s, co) = a.sin_cos();
                let v = match axis {
                    0 => Vec3::new(0.0, co, s),
                    1 => Vec3::new(co, 0.0, s),
                    _ => Vec3::new(co, s, 0.0),
                };
                c + v * r
            })
            .collect()
    };
    let boxed = |lo: Vec3, hi: Vec3| -> Vec<Vec<Vec3>> {
        let p = |i: u32| {
            Vec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            )
        };
        let mut edges = Vec::new();
        for i in 0..8u32 {
            for bit in [1, 2, 4] {
                if i & bit == 0 {
                    edges.push(vec![p(i), p(i | bit)]);
                }
            }
        }
        edges
    };
    match kind {
        NodeKind::Sphere { center, radius } => {
            (0..3).map(|a| circle(*center, *radius, a)).collect()
        }
        NodeKind::Box { min, max } => boxed(*min, *max),
        NodeKind::Triangle {
            vertices: [a, b, c],
        } => vec![vec![*a, *b, *c, *a]],
        NodeKind::TriangleMesh {
            mesh: MeshSlot::Loaded(m),
            ..
        } => {
            let b = m.bounds();
            boxed(b.min, b.max)
        }
        NodeKind::Plane { normal, offset } => {
            let n = normal.normalize_or(Vec3::Y);
            // A square of the plane around the point nearest `near`.
            let c = near - n * (n.dot(near) - offset);
            let u = n.any_orthonormal_vector();
            let v = n.cross(u);
            let s = 1.5;
            vec![vec![
                c + (u + v) * s,
                c + (u - v) * s,
                c - (u + v) * s,
                c + (v - u) * s,
                c + (u + v) * s,
            ]]
        }
        _ => Vec::new(),
    }
}

/// Both diagrams for a story traced in `scene`; `None` for a miss.
pub fn diagrams(scene: &Scene, story: &RayStory) -> Option<(Diagram, Diagram)> {
    let h = story.hit.as_ref()?;
    let g = &scene.graph;
    let kind = &g.get(h.node)?.kind;
    // World from the hit primitive's own space, composed in f64 as the renderer does.
    let mut m = DMat4::IDENTITY;
    for s in &h.path {
        if let Some(t) = s.transform {
            m *= t;
        }
    }
    let m = m.as_mat4();
    let lines = outline(kind, h.object_point);
    let size_obj = lines
        .iter()
        .flatten()
        .map(|p| (*p - h.object_point).length())
        .fold(0.0f32, f32::max)
        .max(0.5);
    let world_lines: Vec<Vec<Vec3>> = lines
        .iter()
        .map(|l| l.iter().map(|p| m.transform_point3(*p)).collect())
        .collect();
    let size_world = world_lines
        .iter()
        .flatten()
        .map(|p| (*p - h.world_point).length())
        .fold(0.0f32, f32::max)
        .max(0.5);
    let arrow = size_world * 0.6;

    let mut world = Diagram::default();
    let eye = match scene.camera {
        Camera::Orthographic { .. } => "ray origin (on the image plane)",
        Camera::Perspective { .. } => "eye",
    };
    world.items.push(Item::new(
        Role::Eye,
        Shape::Point(story.world_ray.origin),
        Some(eye.into()),
    ));
    world.items.push(Item::new(
        Role::Ray,
        Shape::Line(vec![story.world_ray.origin, h.world_point]),
        Some(format!("t = {:.3}", h.t)),
    ));
    for l in world_lines {
        world
            .items
            .push(Item::new(Role::Outline, Shape::Line(l), None));
    }
    world.items.push(Item::new(
        Role::Hit,
        Shape::Point(h.world_point),
        Some("hit".into()),
    ));
    let p = h.world_point;
    world.items.push(Item::new(
        Role::NormalCorrect,
        Shape::Arrow(p, p + h.normal_correct * arrow),
        Some("(M^-1)^T n".into()),
    ));
    world.items.push(Item::new(
        Role::NormalIncorrect,
        Shape::Arrow(p, p + h.normal_incorrect * arrow),
        Some("M n".into()),
    ));
    let u = h.normal_correct.any_orthonormal_vector() * arrow * 0.5;
    let v = h.normal_correct.cross(u);
    world.items.push(Item::new(
        Role::Tangent,
        Shape::Line(vec![p + u + v, p + u - v, p - u - v, p - u + v, p + u + v]),
        None,
    ));
    for (i, l) in h.shade.lights.iter().enumerate() {
        world.items.push(Item::new(
            Role::Light,
            Shape::Arrow(p, p + l.l * arrow),
            Some(format!("L{i}")),
        ));
    }

    if let Some(tree) = &story.ray_tree {
        world.items.extend(tree_items(tree, size_world * 1.5));
    }

    let mut object = Diagram::default();
    let (o, d) = (h.object_ray.origin, h.object_ray.direction);
    object
        .items
        .push(Item::new(Role::Eye, Shape::Point(o), Some("M^-1 o".into())));
    object.items.push(Item::new(
        Role::Ray,
        Shape::Line(vec![o, h.object_point]),
        Some(format!("t = {:.3}", h.t)),
    ));
    // The direction with its own length, |M⁻¹d| (not renormalised), as the ray's last unit
    // of t before the hit, where it is in view.
    let q = h.object_point;
    object.items.push(Item::new(
        Role::Direction,
        Shape::Arrow(q - d, q),
        Some(format!("M^-1 d, length {:.3}", d.length())),
    ));
    for l in lines {
        object
            .items
            .push(Item::new(Role::Outline, Shape::Line(l), None));
    }
    object.items.push(Item::new(
        Role::Hit,
        Shape::Point(h.object_point),
        Some("hit".into()),
    ));
    object.items.push(Item::new(
        Role::NormalCorrect,
        Shape::Arrow(q, q + h.object_normal * size_obj * 0.6),
        Some("n".into()),
    ));
    Some((world, object))
}

/// The ray tree's secondary rays and every shadow ray, in world space. The eye ray is the
/// diagram's own `Role::Ray`; a ray that meets nothing, and a shadow ray toward a
/// directional light, are drawn `stretch` long.
pub fn tree_items(root: &RayNode, stretch: f32) -> Vec<Item> {
    let mut items = Vec::new();
    let mut stack = vec![root];
    while let Some(node) = stack.pop() {
        let role = match node.kind {
            RayKind::Eye => None,
            RayKind::Reflected => Some(Role::Reflected),
            RayKind::Refracted => Some(Role::Refracted),
        };
        if let Some(role) = role {
            let from = node.ray.origin;
            let to = match node.hit {
                Some((_, _, point, _)) => point,
                None => from + node.ray.direction.normalize_or_zero() * stretch,
            };
            let label = (node.hit.is_none()).then(|| "misses".to_string());
            items.push(Item::new(role, Shape::Line(vec![from, to]), label));
        }
        for sh in &node.shadows {
            let dir = sh.ray.direction;
            let along = |t: f32| sh.ray.origin + dir * t;
            let (role, end) = match sh.blocker {
                Some((t, _)) => (Role::ShadowBlocked, along(t)),
                None if sh.distance.is_finite() => (Role::Shadow, along(sh.distance)),
                None => (Role::Shadow, along(stretch / dir.length().max(1e-12))),
            };
            items.push(Item::new(
                role,
                Shape::Line(vec![sh.ray.origin, end]),
                // Named at the first hit only: a deep tree's would hide the picture.
                (node.kind == RayKind::Eye).then(|| format!("L{}", sh.light)),
            ));
        }
        stack.extend(node.children.iter().rev());
    }
    items
}

/// An orbit view: yaw about +y, then pitch about the turned x axis, looking at a centre.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orbit {
    pub yaw: f32,
    pub pitch: f32,
    /// Above 1 magnifies; below 1 shows more (the ray's origin, far off).
    pub zoom: f32,
}

impl Default for Orbit {
    /// Slightly from above and the side, so depth along the ray shows.
    fn default() -> Self {
        Orbit {
            yaw: 0.6,
            pitch: 0.35,
            zoom: 1.0,
        }
    }
}

impl Orbit {
    /// The view's right and up axes in the diagram's space.
    pub fn axes(&self) -> (Vec3, Vec3) {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        let right = Vec3::new(cy, 0.0, -sy);
        let up = Vec3::new(-sy * sp, cp, -cy * sp);
        (right, up)
    }

    /// A mouse drag of `delta` points turns the view.
    pub fn drag(&mut self, delta: Vec2) {
        self.yaw -= delta.x * 0.01;
        self.pitch = (self.pitch + delta.y * 0.01).clamp(-1.5, 1.5);
    }

    /// The mouse wheel: `scroll` points up zoom in.
    pub fn scroll(&mut self, scroll: f32) {
        self.zoom = (self.zoom * (scroll * 0.004).exp()).clamp(0.02, 50.0);
    }

    /// Where `p` lands in a rectangle centred on `screen_center` holding a ball of `radius`
    /// around `center` in `half_extent` points (screen y grows downward).
    pub fn project(
        &self,
        p: Vec3,
        center: Vec3,
        radius: f32,
        screen_center: Vec2,
        half_extent: f32,
    ) -> Vec2 {
        let (right, up) = self.axes();
        let q = p - center;
        let s = half_extent / radius * self.zoom;
        screen_center + Vec2::new(q.dot(right) * s, -q.dot(up) * s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tracelab_core::render::inspect_pixel;
    use tracelab_core::scene::walk;
    use tracelab_core::{CompiledScene, MeshCache, RenderSettings, parse_scene};

    /// The composed world-from-object matrix of the node a story hit, from its path (f64).
    fn world_from_object(scene: &Scene, story: &RayStory) -> Option<DMat4> {
        let h = story.hit.as_ref()?;
        walk::visit(&scene.graph, h.node).map(|v| v.world_from_object)
    }

    fn sheared() -> Scene {
        let text = include_str!("../../../scenes/sheared_sphere.txt");
        parse_scene(text.as_bytes(), "s.txt", None, &mut MeshCache::new())
            .into_result()
            .expect("parses")
            .0
    }

    fn arrow(d: &Diagram, role: Role) -> (Vec3, Vec3) {
        match d.find(role).next().map(|i| &i.shape) {
            Some(Shape::Arrow(a, b)) => (*a, *b),
            other => panic!("{role:?}: {other:?}"),
        }
    }

    fn point(d: &Diagram, role: Role) -> Vec3 {
        match d.find(role).next().map(|i| &i.shape) {
            Some(Shape::Point(p)) => *p,
            other => panic!("{role:?}: {other:?}"),
        }
    }

    #[test]
    fn the_diagrams_points_are_the_storys_numbers() {
        let s = sheared();
        let c = CompiledScene::new(&s);
        let story = inspect_pixel(&s, &c, &RenderSettings::new(40, 40), 28, 18);
        let h = story.hit.as_ref().expect("hit");
        let (world, object) = diagrams(&s, &story).expect("diagrams");
        assert_eq!(point(&world, Role::Hit), h.world_point);
        assert_eq!(point(&world, Role::Eye), story.world_ray.origin);
        assert_eq!(point(&object, Role::Hit), h.object_point);
        assert_eq!(point(&object, Role::Eye), h.object_ray.origin);
        // M⁻¹d with its own length, 1.25 under Scale z 0.8 (not renormalised), ending at the hit.
        let (from, to) = arrow(&object, Role::Direction);
        assert_eq!(to, h.object_point);
        assert!((to - from - h.object_ray.direction).length() < 1e-6);
        assert!(((to - from).length() - 1.25).abs() < 1e-5);
        // The normals point along the story's, from the hit point.
        let (a, b) = arrow(&world, Role::NormalCorrect);
        assert_eq!(a, h.world_point);
        assert!((b - a).normalize().dot(h.normal_correct) > 1.0 - 1e-5);
        let (a, b) = arrow(&world, Role::NormalIncorrect);
        assert!((b - a).normalize().dot(h.normal_incorrect) > 1.0 - 1e-5);
        // The world outline is the unit sphere moved by M: M⁻¹ takes it back onto |p| = 1.
        let m = world_from_object(&s, &story).expect("matrix").as_mat4();
        let inv = m.inverse();
        let mut n = 0;
        for item in world.find(Role::Outline) {
            let Shape::Line(ps) = &item.shape else {
                panic!("outline is lines")
            };
            for p in ps {
                assert!((inv.transform_point3(*p).length() - 1.0).abs() < 1e-4);
                n += 1;
            }
        }
        assert!(n > 100);
        // The tangent square is perpendicular to the correct normal.
        let Some(Shape::Line(sq)) = world.find(Role::Tangent).next().map(|i| &i.shape) else {
            panic!("tangent")
        };
        for p in sq {
            assert!((*p - h.world_point).dot(h.normal_correct).abs() < 1e-5);
        }
    }

    #[test]
    fn the_projection_keeps_the_hit_on_the_drawn_ray() {
        let s = sheared();
        let c = CompiledScene::new(&s);
        let story = inspect_pixel(&s, &c, &RenderSettings::new(40, 40), 28, 18);
        let (world, object) = diagrams(&s, &story).expect("diagrams");
        for (d, orbit) in [
            (&world, Orbit::default()),
            (
                &object,
                Orbit {
                    yaw: -1.1,
                    pitch: 0.9,
                    zoom: 1.0,
                },
            ),
        ] {
            let (center, r) = d.bounds();
            let sc = Vec2::new(100.0, 80.0);
            let proj = |p: Vec3| orbit.project(p, center, r, sc, 70.0);
            let Some(Shape::Line(ray)) = d.find(Role::Ray).next().map(|i| &i.shape) else {
                panic!("ray")
            };
            let (a, b) = (proj(ray[0]), proj(ray[1]));
            let hit = proj(point(d, Role::Hit));
            // Projection is linear: the hit, at the end of the drawn ray, lands on its end.
            assert!((hit - b).length() < 1e-3, "{hit} vs {b}");
            assert!((a - b).length() > 1.0);
            // Everything but the ray's origin fits the rectangle of half-extent 70.
            for item in &d.items {
                for p in item.fit_points() {
                    assert!((proj(p) - sc).length() <= 70.0 + 1e-3);
                }
            }
        }
        // Seen from the front (no yaw, no pitch), x goes right and y goes up on screen.
        let front = Orbit {
            yaw: 0.0,
            pitch: 0.0,
            zoom: 1.0,
        };
        let o = front.project(Vec3::ZERO, Vec3::ZERO, 1.0, Vec2::ZERO, 10.0);
        assert_eq!(
            front.project(Vec3::X, Vec3::ZERO, 1.0, Vec2::ZERO, 10.0) - o,
            Vec2::new(10.0, 0.0)
        );
        assert_eq!(
            front.project(Vec3::Y, Vec3::ZERO, 1.0, Vec2::ZERO, 10.0) - o,
            Vec2::new(0.0, -10.0)
        );
        assert_eq!(
            front.project(Vec3::Z, Vec3::ZERO, 1.0, Vec2::ZERO, 10.0) - o,
            Vec2::ZERO
        );
        let closer = Orbit { zoom: 2.0, ..front };
        assert_eq!(
            closer.project(Vec3::X, Vec3::ZERO, 1.0, Vec2::ZERO, 10.0),
            Vec2::new(20.0, 0.0)
        );
    }
}
