//! Property test of the document: random sequences of edits, undos and redos never panic,
//! and undoing everything gives back the document we started from, exactly.

use glam::{Mat4, Vec3};
use tracelab::edit::Edit;
use tracelab::state::Document;
use tracelab_core::{Background, Camera, CsgOp, Light, Material, MeshSlot, NodeId, NodeKind, TransformOp};

/// xorshift64*: small, seeded, repeatable.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
    fn f(&mut self) -> f32 {
        (self.next() % 2001) as f32 / 1000.0 - 1.0
    }
    fn v(&mut self) -> Vec3 {
        Vec3::new(self.f(), self.f(), self.f())
    }
}

fn random_op(r: &mut Rng) -> TransformOp {
    match r.below(8) {
        0 => TransformOp::Translate(r.v()),
        1 => TransformOp::Scale(r.v()),
        2 => TransformOp::UniformScale(r.f()),
        3 => TransformOp::XRotate(r.f() * 180.0),
        4 => TransformOp::YRotate(r.f() * 180.0),
        5 => TransformOp::ZRotate(r.f() * 180.0),
        6 => TransformOp::Rotate {
            axis: r.v(),
            degrees: r.f() * 90.0,
        },
        _ => TransformOp::Matrix(Mat4::from_scale(r.v())),
    }
}

fn random_kind(r: &mut Rng) -> NodeKind {
    match r.below(9) {
        6 => NodeKind::Box {
            min: r.v() - Vec3::ONE,
            max: r.v() + Vec3::ONE,
        },
        7 => NodeKind::Csg(CsgOp::ALL[r.below(3)]),
        0 => NodeKind::Sphere {
            center: r.v(),
            radius: r.f(),
        },
        1 => NodeKind::Plane {
            normal: r.v(),
            offset: r.f(),
        },
        2 => NodeKind::Triangle {
            vertices: [r.v(), r.v(), r.v()],
        },
        3 => NodeKind::TriangleMesh {
            obj_file: "missing.obj".into(),
            mesh: MeshSlot::Failed("missing".into()),
        },
        4 => NodeKind::Group,
        _ => NodeKind::Transform(vec![random_op(r)]),
    }
}

/// Any node id the arena has ever held, plus one that never existed, so stale and invalid
/// ids are exercised too.
fn random_node(r: &mut Rng, d: &Document) -> NodeId {
    NodeId(r.below(d.scene.graph.capacity_len() + 1) as u32)
}

fn random_edit(r: &mut Rng, d: &Document) -> Edit {
    let node = random_node(r, d);
    let small = r.below(4);
    match r.below(21) {
        20 => Edit::SwapOperands { node },
        0 => Edit::SetTransformOp {
            node,
            index: small,
            op: random_op(r),
        },
        1 => Edit::AddOp {
            node,
            op: random_op(r),
        },
        2 => Edit::RemoveOp { node, index: small },
        3 => Edit::MoveOp {
            node,
            from: small,
            to: r.below(4),
        },
        4 => Edit::SetNodeKind {
            node,
            kind: random_kind(r),
        },
        5 => Edit::SetNodeMaterial {
            node,
            material: (r.below(3) > 0).then(|| r.below(7) as u32),
        },
        6 => Edit::AddNode {
            parent: random_node(r, d),
            kind: random_kind(r),
        },
        7 => Edit::DeleteNode { node },
        8 => Edit::DuplicateNode { node },
        9 => Edit::MoveNode {
            node,
            new_parent: random_node(r, d),
            index: r.below(6),
        },
        10 => Edit::WrapInTransform { node },
        11 => Edit::WrapInGroup { node },
        12 => Edit::SetMaterial {
            index: r.below(7),
            material: Material::diffuse(r.v()),
        },
        13 => Edit::AddMaterial(Material::diffuse(r.v())),
        14 => Edit::RemoveMaterial { index: r.below(7) },
        15 => Edit::SetCamera(Camera::Orthographic {
            center: r.v(),
            direction: r.v(),
            up: r.v(),
            size: r.f(),
        }),
        16 => Edit::AddLight(Light::new(r.v(), r.v())),
        17 => Edit::RemoveLight { index: r.below(4) },
        18 => Edit::SetLight {
            index: r.below(4),
            light: Light::new(r.v(), r.v()),
        },
        _ => Edit::SetBackground(Background {
            color: Some(r.v()),
            ambient: None,
        }),
    }
}

#[test]
fn random_edits_and_undos_never_panic_and_full_undo_restores_the_document() {
    for seed in 1..=60u64 {
        let mut r = Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1);
        let mut d = Document::builtin();
        let original = d.scene.clone();
        let mut applied = 0;
        for _ in 0..150 {
            match r.below(10) {
                0 => {
                    d.undo();
                }
                1 => {
                    d.redo();
                }
                2 => d.end_gesture(),
                _ => {
                    let e = random_edit(&mut r, &d);
                    if d.apply(e).is_ok() {
                        applied += 1;
                    }
                }
            }
            // Every state is a scene the renderer and the writer accept, and every CSG node
            // still holds two solids.
            let _ = tracelab_core::write_scene(&d.scene);
            let _ = tracelab_core::compile(&d.scene);
            check_csg_operands(&d, seed);
        }
        assert!(
            applied > 20,
            "seed {seed}: only {applied} edits applied; the generator is too timid"
        );
        while d.undo() {}
        assert_eq!(d.scene, original, "seed {seed}");
        assert!(
            !d.is_dirty(),
            "seed {seed}: back at the opened state, nothing is unsaved"
        );
    }
}

fn check_csg_operands(d: &Document, seed: u64) {
    let g = &d.scene.graph;
    for id in g.preorder() {
        let n = g.node(id);
        if let NodeKind::Csg(op) = n.kind {
            assert_eq!(n.children.len(), 2, "seed {seed}: {} with {} operands", op.name(), n.children.len());
            for &c in &n.children {
                let k = &g.node(c).kind;
                assert!(
                    !matches!(k, NodeKind::Group | NodeKind::Triangle { .. }),
                    "seed {seed}: a {} became a CSG operand",
                    k.name()
                );
            }
        }
    }
}

fn add_subtraction(d: &mut Document) -> NodeId {
    let root = d.scene.graph.root();
    d.apply(Edit::AddNode { parent: root, kind: NodeKind::Csg(CsgOp::Subtraction) }).expect("adds");
    *d.scene.graph.node(root).children.last().expect("the new node")
}

#[test]
fn a_new_csg_node_holds_two_solids_and_renders() {
    let mut d = Document::builtin();
    let csg = add_subtraction(&mut d);
    let kids = d.scene.graph.node(csg).children.clone();
    assert_eq!(kids.len(), 2);
    assert!(matches!(d.scene.graph.node(kids[0]).kind, NodeKind::Box { .. }));
    assert!(matches!(d.scene.graph.node(kids[1]).kind, NodeKind::Sphere { .. }));
    let text = tracelab_core::write_scene(&d.scene);
    assert!(text.contains("Subtraction {"), "{text}");
    // Switching the operation and swapping operands are single edits that undo.
    let before = d.scene.clone();
    d.apply(Edit::SetNodeKind { node: csg, kind: NodeKind::Csg(CsgOp::Union) }).expect("op change");
    d.apply(Edit::SwapOperands { node: csg }).expect("swap");
    assert_eq!(d.scene.graph.node(csg).kind, NodeKind::Csg(CsgOp::Union));
    assert_eq!(d.scene.graph.node(csg).children, [kids[1], kids[0]]);
    while d.scene != before && d.undo() {}
    assert_eq!(d.scene, before);
}

#[test]
fn deleting_one_operand_leaves_the_other_in_the_csg_node_s_place() {
    let mut d = Document::builtin();
    let csg = add_subtraction(&mut d);
    let [a, b] = d.scene.graph.node(csg).children[..] else { panic!("two operands") };
    d.apply(Edit::DeleteNode { node: b }).expect("deletes");
    let root = d.scene.graph.root();
    let kids = &d.scene.graph.node(root).children;
    assert_eq!(kids.last(), Some(&a), "the Box takes the Subtraction's place");
    assert!(!kids.contains(&csg));
}

#[test]
fn a_csg_operand_cannot_become_a_group_or_a_triangle() {
    let mut d = Document::builtin();
    let csg = add_subtraction(&mut d);
    let a = d.scene.graph.node(csg).children[0];
    let before = d.scene.clone();
    assert!(d.apply(Edit::WrapInGroup { node: a }).is_err());
    let tri = NodeKind::Triangle { vertices: [Vec3::ZERO, Vec3::X, Vec3::Y] };
    assert!(d.apply(Edit::SetNodeKind { node: a, kind: tri }).is_err());
    assert_eq!(d.scene, before);
    // Wrapping in a Transform keeps it a solid, so that is allowed.
    d.apply(Edit::WrapInTransform { node: a }).expect("a Transform of a solid is a solid");
}

#[test]
fn a_drag_is_one_undo_step() {
    let mut d = Document::builtin();
    let original = d.scene.clone();
    let t = d
        .scene
        .graph
        .iter()
        .find(|(_, n)| matches!(n.kind, NodeKind::Transform(_)))
        .map(|(id, _)| id)
        .expect("a Transform");
    for i in 0..10 {
        let op = TransformOp::Translate(Vec3::new(i as f32 * 0.1, 0.0, 0.0));
        d.apply(Edit::SetTransformOp {
            node: t,
            index: 0,
            op,
        })
        .expect("edit applies");
    }
    d.end_gesture();
    assert!(d.undo());
    assert_eq!(d.scene, original);
    assert!(!d.can_undo());
}

#[test]
fn removing_a_material_keeps_every_other_node_s_colour() {
    let mut d = Document::builtin();
    let before = tracelab_core::compile(&d.scene);
    d.apply(Edit::RemoveMaterial { index: 2 }).expect("applies");
    let after = tracelab_core::compile(&d.scene);
    for (a, b) in before.objects.iter().zip(&after.objects) {
        let ca = before.materials[a.material as usize];
        let cb = after.materials[b.material as usize];
        if ca != Vec3::new(0.95, 0.7, 0.2) {
            assert_eq!(ca, cb, "node {:?}", a.node);
        }
    }
}

#[test]
fn moving_a_node_into_its_own_subtree_is_refused() {
    let mut d = Document::builtin();
    let g = &d.scene.graph;
    let (outer, inner) = g
        .iter()
        .find_map(|(id, n)| {
            let NodeKind::Transform(_) = n.kind else {
                return None;
            };
            let child = *n.children.first()?;
            matches!(g.node(child).kind, NodeKind::Group).then_some((id, child))
        })
        .expect("a Transform holding a Group");
    let before = d.scene.clone();
    assert!(
        d.apply(Edit::MoveNode {
            node: outer,
            new_parent: inner,
            index: 0
        })
        .is_err()
    );
    assert_eq!(d.scene, before);
}
