//! One description of a primitive in its own space, shared by the compiled scene's objects
//! (`compile::Shape`) and CSG's leaves (`csg::LeafShape`): read from a node once, bounded
//! once. `C` is what a CSG subtree is: the compiled tree for an object; nothing for a leaf,
//! whose nested CSG nodes are steps of its tree's program (`Infallible`: no such leaf).

use std::sync::Arc;

use glam::Vec3;

use crate::geometry::{Aabb, sphere_bounds, triangle_normal};
use crate::scene::{Mesh, MeshSlot, NodeKind, unit};

#[derive(Clone, Debug)]
pub enum Shape<C> {
    Sphere {
        center: Vec3,
        radius: f32,
    },
    /// `normal` is unit length: the plane is {p : normal·p = offset}. As a CSG operand, the
    /// half-space behind it, {p : normal·p ≤ offset}.
    Plane {
        normal: Vec3,
        offset: f32,
    },
    Triangle {
        vertices: [Vec3; 3],
        normal: Vec3,
    },
    Mesh(Arc<Mesh>),
    /// An axis-aligned box in object space; a hit's `prim` is the face (axis·2, +1 for max).
    Box {
        min: Vec3,
        max: Vec3,
    },
    /// A CSG subtree whose leaves carry their own world transforms and materials; a hit's
    /// `prim` is the boundary code of `csg::CsgTree` (leaf, exit and flip bits).
    Csg(C),
}

impl<C> Shape<C> {
    /// The primitive a node holds; None for a container (Group, Transform, CSG) and for a
    /// mesh not loaded.
    pub fn of_node(kind: &NodeKind) -> Option<Self> {
        Some(match kind {
            NodeKind::Sphere { center, radius } => Shape::Sphere {
                center: *center,
                radius: *radius,
            },
            // The offset is measured along the normalised normal, as the course's Plane does.
            NodeKind::Plane { normal, offset } => Shape::Plane {
                normal: unit(*normal).unwrap_or(Vec3::Y),
                offset: *offset,
            },
            NodeKind::Triangle {
                vertices: [a, b, c],
            } => Shape::Triangle {
                vertices: [*a, *b, *c],
                normal: triangle_normal(*a, *b, *c),
            },
            NodeKind::TriangleMesh {
                mesh: MeshSlot::Loaded(mesh),
                ..
            } => Shape::Mesh(mesh.clone()),
            NodeKind::Box { min, max } => Shape::Box {
                min: *min,
                max: *max,
            },
            NodeKind::TriangleMesh { .. }
            | NodeKind::Group
            | NodeKind::Transform(_)
            | NodeKind::Csg(_) => return None,
        })
    }

    /// Whether it bounds a solid, so it can be a CSG operand: not a lone Triangle.
    pub fn is_solid(&self) -> bool {
        !matches!(self, Shape::Triangle { .. })
    }

    /// Its box in its own space (a Plane's is all of space); None for a CSG subtree, whose
    /// bounds are its tree's.
    pub fn local_bounds(&self) -> Option<Aabb> {
        Some(match self {
            Shape::Sphere { center, radius } => sphere_bounds(*center, *radius),
            Shape::Plane { .. } => Aabb::new(Vec3::NEG_INFINITY, Vec3::INFINITY),
            Shape::Triangle { vertices, .. } => Aabb::from_points(vertices),
            Shape::Mesh(m) => m.bounds(),
            Shape::Box { min, max } => Aabb::new(*min, *max),
            Shape::Csg(_) => return None,
        })
    }
}
