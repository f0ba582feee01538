//! Constructive solid geometry by intervals along the ray, as the lecture describes it: each
//! solid reports where the ray is inside it (sorted entry/exit boundaries over the whole
//! line, so a ray that starts inside a solid is handled like any other), and each node
//! combines its operands' intervals. The visible hit is the result's first boundary in range.
//!
//! A CSG subtree compiles to a post-order program over its leaves, evaluated with a stack,
//! so deep nesting cannot overflow the call stack.

use std::cell::RefCell;
use std::convert::Infallible;

use glam::{DMat4, Vec3};

use super::NormalTransform;
use super::shape::Shape;
use crate::accel::TriangleHit;
use crate::geometry::{
    Aabb, Ray, Transform, box_face_normal, box_span, sphere_normal, sphere_roots,
};
use crate::scene::{CsgOp, Graph, NodeId, NodeKind, Walk};

/// A boundary's code (also what `Hit::prim` holds for a CSG hit): the leaf index in the low
/// bits, whether the ray leaves that leaf there, and whether the normal is flipped (a
/// surface of B exposed by a subtraction).
pub const LEAF_MASK: u32 = (1 << 30) - 1;
pub const EXIT_BIT: u32 = 1 << 30;
pub const FLIP_BIT: u32 = 1 << 31;
/// The code of an interval end at ±∞ (no surface there).
const NO_SURFACE: u32 = LEAF_MASK;

/// One end of an interval where the ray is inside a solid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bound {
    pub t: f32,
    pub code: u32,
}

impl Bound {
    pub fn leaf(&self) -> Option<u32> {
        let l = self.code & LEAF_MASK;
        (l != NO_SURFACE).then_some(l)
    }
    pub fn is_exit_of_leaf(&self) -> bool {
        self.code & EXIT_BIT != 0
    }
    pub fn is_flipped(&self) -> bool {
        self.code & FLIP_BIT != 0
    }
}

/// A leaf's geometry in its object space: the compiled objects' description (a Plane is the
/// half-space behind it), never a CSG subtree (nested operations are steps of the program).
pub type LeafShape = Shape<Infallible>;

#[derive(Clone, Debug)]
pub struct CsgLeaf {
    /// None: something that bounds no solid (a lone Triangle, a Group, an unloaded mesh, a
    /// missing operand in an edited scene); it contributes nothing.
    pub solid: Option<LeafShape>,
    /// The leaf's whole world transform (Transforms above the CSG node included).
    pub xf: Option<Transform>,
    /// Index into `CompiledScene::materials`: a surface keeps its operand's material.
    pub material: u32,
    pub node: NodeId,
}

#[derive(Clone, Copy, Debug)]
enum Step {
    Leaf(u32),
    Op(CsgOp),
}

/// A compiled CSG subtree.
#[derive(Clone, Debug)]
pub struct CsgTree {
    pub leaves: Vec<CsgLeaf>,
    /// Post-order: a leaf pushes its intervals, an op pops B then A and pushes the result.
    program: Vec<Step>,
    bounds: Aabb,
}

/// Reused buffers, so tracing a CSG pixel allocates nothing after the first.
#[derive(Default)]
struct Scratch {
    heap: Vec<Bound>,
    /// Start of each operand's bounds in `heap`.
    starts: Vec<usize>,
    combined: Vec<Bound>,
    hits: Vec<TriangleHit>,
}

thread_local! {
    static SCRATCH: RefCell<Scratch> = RefCell::new(Scratch::default());
}

impl CsgTree {
    /// Compiles the subtree under `root` (a Union, Intersection or Subtraction node).
    /// `world_from_root` is the transform above it; `material` the material in effect there;
    /// `resolve` maps a material in effect to an index into the compiled materials.
    pub fn build(
        graph: &Graph,
        root: NodeId,
        world_from_root: DMat4,
        material: Option<u32>,
        resolve: &dyn Fn(Option<u32>) -> u32,
    ) -> CsgTree {
        /// A container whose operand slots are being filled: a CSG node has two, a
        /// Transform one; extra children are not read, missing ones are empty.
        struct Open {
            depth: usize,
            op: Option<CsgOp>,
            slots: usize,
            filled: usize,
        }
        let mut leaves = Vec::new();
        let mut program = Vec::new();
        let mut open: Vec<Open> = Vec::new();
        let empty = |leaves: &mut Vec<CsgLeaf>, program: &mut Vec<Step>, node: NodeId| {
            program.push(Step::Leaf(leaves.len() as u32));
            leaves.push(CsgLeaf {
                solid: None,
                xf: None,
                material: resolve(material),
                node,
            });
        };
        let close = |o: Open, leaves: &mut Vec<CsgLeaf>, program: &mut Vec<Step>| {
            // An edited scene may hold fewer operands: read as empty.
            for _ in o.filled..o.slots {
                empty(leaves, program, root);
            }
            if let Some(op) = o.op {
                program.push(Step::Op(op));
            }
        };
        let mut walk = Walk::from_node(graph, root, world_from_root, material);
        while let Some(v) = walk.next() {
            while open.last().is_some_and(|o| o.depth >= v.depth) {
                let o = open.pop().expect("checked");
                close(o, &mut leaves, &mut program);
            }
            if let Some(parent) = open.last_mut() {
                if parent.filled == parent.slots {
                    walk.skip_children();
                    continue;
                }
                parent.filled += 1;
            }
            let m = v.world_from_object;
            let solid = match &v.node.kind {
                NodeKind::Csg(op) => {
                    open.push(Open {
                        depth: v.depth,
                        op: Some(*op),
                        slots: 2,
                        filled: 0,
                    });
                    continue;
                }
                NodeKind::Transform(_) => {
                    open.push(Open {
                        depth: v.depth,
                        op: None,
                        slots: 1,
                        filled: 0,
                    });
                    continue;
                }
                // Groups, lone triangles and unloaded meshes bound no solid.
                kind => {
                    let solid = LeafShape::of_node(kind).filter(LeafShape::is_solid);
                    if solid.is_none() {
                        walk.skip_children();
                    }
                    solid
                }
            };
            program.push(Step::Leaf(leaves.len() as u32));
            leaves.push(CsgLeaf {
                solid,
                xf: (m != DMat4::IDENTITY).then(|| Transform::from_f64(m)),
                material: resolve(v.material),
                node: v.id,
            });
        }
        while let Some(o) = open.pop() {
            close(o, &mut leaves, &mut program);
        }
        let bounds = program_bounds(&program, &leaves);
        CsgTree {
            leaves,
            program,
            bounds,
        }
    }

    /// World-space bounds of the result (infinite when a half-space leaves it unbounded,
    /// empty when nothing can be inside).
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// The result's boundaries along the whole ray (t from −∞ to ∞), sorted: entries and
    /// exits alternate, starting with an entry. t is the world ray parameter.
    pub fn intervals(&self, ray: &Ray) -> Vec<Bound> {
        SCRATCH.with(|s| {
            let mut s = s.borrow_mut();
            self.evaluate(ray, &mut s);
            s.heap.clone()
        })
    }

    /// The first boundary with t in (t_min, t_max): (t, code).
    pub fn intersect(&self, ray: &Ray, t_min: f32, t_max: f32) -> Option<(f32, u32)> {
        SCRATCH.with(|s| {
            let mut s = s.borrow_mut();
            self.evaluate(ray, &mut s);
            s.heap
                .iter()
                .find(|b| b.t > t_min && b.t < t_max && b.leaf().is_some())
                .map(|b| (b.t, b.code))
        })
    }

    fn evaluate(&self, ray: &Ray, s: &mut Scratch) {
        let Scratch {
            heap,
            starts,
            combined,
            hits,
        } = s;
        heap.clear();
        starts.clear();
        for step in &self.program {
            match *step {
                Step::Leaf(i) => {
                    starts.push(heap.len());
                    if let Some(leaf) = self.leaves.get(i as usize) {
                        let r = match &leaf.xf {
                            // Not renormalised: t is the world ray parameter in every leaf.
                            Some(xf) => ray.transformed(&xf.object_from_world),
                            None => *ray,
                        };
                        leaf_bounds(&leaf.solid, &r, i, heap, hits);
                    }
                }
                Step::Op(op) => {
                    let (Some(sb), Some(sa)) = (starts.pop(), starts.pop()) else {
                        continue;
                    };
                    combined.clear();
                    combine(op, &heap[sa..sb], &heap[sb..], combined);
                    heap.truncate(sa);
                    heap.extend_from_slice(combined);
                    starts.push(sa);
                }
            }
        }
    }

    /// The normal of a hit with this code in its leaf's object space, unit length, flipped
    /// for B's surfaces exposed by a subtraction.
    pub fn object_normal(&self, ray: &Ray, t: f32, code: u32) -> Vec3 {
        let Some(leaf) = self.leaves.get((code & LEAF_MASK) as usize) else {
            return Vec3::Z;
        };
        let r = match &leaf.xf {
            Some(xf) => ray.transformed(&xf.object_from_world),
            None => *ray,
        };
        let n = leaf_normal(&leaf.solid, &r, t, code & EXIT_BIT != 0);
        if code & FLIP_BIT != 0 { -n } else { n }
    }

    /// The world normal of a hit with this code, normalised, by the chosen rule (flipped as
    /// `object_normal` is: the flip commutes with either linear map).
    pub fn world_normal(&self, ray: &Ray, t: f32, code: u32, mode: NormalTransform) -> Vec3 {
        let Some(leaf) = self.leaves.get((code & LEAF_MASK) as usize) else {
            return Vec3::Z;
        };
        mode.apply(leaf.xf.as_ref(), self.object_normal(ray, t, code))
    }

    pub fn leaf(&self, code: u32) -> Option<&CsgLeaf> {
        self.leaves.get((code & LEAF_MASK) as usize)
    }
}

fn program_bounds(program: &[Step], leaves: &[CsgLeaf]) -> Aabb {
    let mut stack: Vec<Aabb> = Vec::new();
    for step in program {
        match *step {
            Step::Leaf(i) => stack.push(
                leaves
                    .get(i as usize)
                    .map_or(Aabb::EMPTY, leaf_world_bounds),
            ),
            Step::Op(op) => {
                let (Some(b), Some(a)) = (stack.pop(), stack.pop()) else {
                    continue;
                };
                stack.push(match op {
                    CsgOp::Union => a.union(b),
                    CsgOp::Intersection => {
                        let i = Aabb::new(a.min.max(b.min), a.max.min(b.max));
                        if i.is_empty() { Aabb::EMPTY } else { i }
                    }
                    CsgOp::Subtraction => a,
                });
            }
        }
    }
    stack.pop().unwrap_or(Aabb::EMPTY)
}

fn leaf_world_bounds(leaf: &CsgLeaf) -> Aabb {
    let local = match &leaf.solid {
        // A half-space stays unbounded whatever moves it.
        Some(Shape::Plane { .. }) => return Aabb::new(Vec3::NEG_INFINITY, Vec3::INFINITY),
        Some(shape) => shape.local_bounds().unwrap_or(Aabb::EMPTY),
        None => return Aabb::EMPTY,
    };
    leaf.xf.as_ref().map_or(local, |xf| xf.world_bounds(local))
}

/// Appends a leaf's sorted boundaries along the whole (object-space) ray.
fn leaf_bounds(
    solid: &Option<LeafShape>,
    r: &Ray,
    leaf: u32,
    out: &mut Vec<Bound>,
    hits: &mut Vec<TriangleHit>,
) {
    let mut span = |t0: f32, c0: u32, t1: f32, c1: u32| {
        // `!(t0 < t1)` also rejects NaN, which must never reach `combine`.
        if t0 < t1 {
            out.push(Bound { t: t0, code: c0 });
            out.push(Bound { t: t1, code: c1 });
        }
    };
    let (enter, exit) = (leaf, leaf | EXIT_BIT);
    match solid {
        Some(Shape::Sphere { center, radius }) => {
            if let Some((t0, t1)) = sphere_roots(r, *center, *radius) {
                span(t0, enter, t1, exit);
            }
        }
        Some(Shape::Box { min, max }) => {
            if let Some((t0, _, t1, _)) = box_span(r, *min, *max) {
                span(t0, enter, t1, exit);
            }
        }
        Some(Shape::Plane { normal, offset }) => {
            let nd = normal.dot(r.direction);
            let behind_origin = normal.dot(r.origin) <= *offset;
            if nd == 0.0 {
                if behind_origin {
                    span(f32::NEG_INFINITY, NO_SURFACE, f32::INFINITY, NO_SURFACE);
                }
            } else {
                let t = (offset - normal.dot(r.origin)) / nd;
                if nd > 0.0 {
                    span(f32::NEG_INFINITY, NO_SURFACE, t, exit);
                } else {
                    span(t, enter, f32::INFINITY, NO_SURFACE);
                }
            }
        }
        Some(Shape::Mesh(mesh)) => {
            hits.clear();
            mesh.accel
                .intersect_all(r, f32::NEG_INFINITY, f32::INFINITY, hits);
            hits.sort_by(|a, b| a.t.total_cmp(&b.t));
            // A ray through an edge or vertex meets several triangles at one t; keep one
            // crossing per facing there, so crossings still alternate in and out.
            let facing = |h: &TriangleHit| mesh.face_normal(h.triangle).dot(r.direction) > 0.0;
            let mut kept: Vec<f32> = Vec::with_capacity(hits.len());
            let mut last: Option<(f32, bool)> = None;
            for h in hits.iter() {
                let f = facing(h);
                if let Some((t, lf)) = last
                    && lf == f
                    && (h.t - t).abs() <= 1e-6 * t.abs().max(1.0)
                {
                    continue;
                }
                last = Some((h.t, f));
                kept.push(h.t);
            }
            // An odd count (a ray grazing a silhouette) loses its unmatched last crossing.
            for pair in kept.chunks_exact(2) {
                span(pair[0], enter, pair[1], exit);
            }
        }
        Some(Shape::Csg(never)) => match *never {},
        Some(Shape::Triangle { .. }) | None => {}
    }
}

/// The object-space outward normal of a leaf at the boundary the ray crosses at t.
fn leaf_normal(solid: &Option<LeafShape>, r: &Ray, t: f32, exit: bool) -> Vec3 {
    match solid {
        Some(Shape::Sphere { center, .. }) => sphere_normal(*center, r.at(t)),
        Some(Shape::Box { min, max }) => match box_span(r, *min, *max) {
            Some((_, f_in, _, f_out)) => box_face_normal(if exit { f_out } else { f_in }),
            None => Vec3::Z,
        },
        Some(Shape::Plane { normal, .. }) => *normal,
        Some(Shape::Mesh(mesh)) => {
            let mut hits = Vec::new();
            mesh.accel
                .intersect_all(r, t.next_down(), t.next_up(), &mut hits);
            let n = hits
                .first()
                .map_or(Vec3::Z, |h| mesh.face_normal(h.triangle));
            // Orient by the crossing, not the file's winding: out of the solid along the ray
            // at an exit, against it at an entry.
            if (n.dot(r.direction) > 0.0) != exit {
                -n
            } else {
                n
            }
        }
        Some(Shape::Csg(never)) => match *never {},
        Some(Shape::Triangle { .. }) | None => Vec3::Z,
    }
}

/// Combines two sorted boundary lists by `op` with one sweep. Boundaries at the same t are
/// taken together, so coincident surfaces (A ∪ A, A − A) leave no seam and no sliver.
pub fn combine(op: CsgOp, a: &[Bound], b: &[Bound], out: &mut Vec<Bound>) {
    let (mut i, mut j) = (0, 0);
    let (mut in_a, mut in_b, mut inside) = (false, false, false);
    while i < a.len() || j < b.len() {
        let ta = a.get(i).map_or(f32::INFINITY, |x| x.t);
        let tb = b.get(j).map_or(f32::INFINITY, |x| x.t);
        let t = ta.min(tb);
        let was_a = in_a;
        let (mut code_a, mut code_b) = (NO_SURFACE, NO_SURFACE);
        let (i0, j0) = (i, j);
        while let Some(x) = a.get(i).filter(|x| x.t <= t) {
            in_a = !in_a;
            code_a = x.code;
            i += 1;
        }
        while let Some(x) = b.get(j).filter(|x| x.t <= t) {
            in_b = !in_b;
            code_b = x.code;
            j += 1;
        }
        if i == i0 && j == j0 {
            // Only a NaN could stop progress; leaves never produce one, but never loop.
            break;
        }
        let now = op.combine(in_a, in_b);
        if now != inside {
            let code = if in_a != was_a {
                code_a
            } else if op == CsgOp::Subtraction {
                // B's surface bounds A − B from the other side: its normal turns around.
                code_b ^ FLIP_BIT
            } else {
                code_b
            };
            out.push(Bound { t, code });
            inside = now;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn b(t: f32, code: u32) -> Bound {
        Bound { t, code }
    }

    #[test]
    fn combining_disjoint_and_overlapping_spans() {
        let a = [b(0.0, 0), b(2.0, EXIT_BIT)];
        let bb = [b(1.0, 1), b(3.0, 1 | EXIT_BIT)];
        let mut out = Vec::new();
        combine(CsgOp::Union, &a, &bb, &mut out);
        assert_eq!(out, [b(0.0, 0), b(3.0, 1 | EXIT_BIT)]);
        out.clear();
        combine(CsgOp::Intersection, &a, &bb, &mut out);
        assert_eq!(out, [b(1.0, 1), b(2.0, EXIT_BIT)]);
        out.clear();
        combine(CsgOp::Subtraction, &a, &bb, &mut out);
        assert_eq!(out, [b(0.0, 0), b(1.0, 1 | FLIP_BIT)]);
    }

    #[test]
    fn coincident_boundaries_leave_no_seam() {
        let a = [b(0.0, 0), b(1.0, EXIT_BIT)];
        let bb = [b(1.0, 1), b(2.0, 1 | EXIT_BIT)];
        let mut out = Vec::new();
        combine(CsgOp::Union, &a, &bb, &mut out);
        assert_eq!(out, [b(0.0, 0), b(2.0, 1 | EXIT_BIT)]);
        out.clear();
        combine(CsgOp::Subtraction, &a, &a, &mut out);
        assert!(out.is_empty());
    }
}
