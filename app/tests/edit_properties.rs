//! Property test of the document: random sequences of edits, undos and redos never panic,
//! every edit either is refused (changing nothing) or leaves a document whose saved text
//! reads back as the same document, and undoing everything gives back the document we
//! started from, exactly. Edits draw typed extreme values (0, -0, ±1e30, 1e39, nan, inf,
//! empty, 400 digits, letters) as well as tame ones.

use std::path::Path;

use glam::{Mat4, Vec3};
use tracelab::document::Document;
use tracelab::document::edit::Edit;
use tracelab_core::{
    Background, Camera, CsgOp, Light, Material, MeshCache, MeshSlot, NodeId, NodeKind,
    RenderSettings, Scene, TransformOp, check_scene, compile, parse_scene, render_frame,
    write_scene,
};

/// xorshift64*: small, seeded, repeatable.
struct Rng(u64);

/// What a user can type into a field.
const TYPED: &[&str] = &[
    "0", "-0", "1e30", "-1e30", "1e39", "nan", "inf", "-inf", "", DIGITS_400, "letters",
];
const DIGITS_400: &str = "7777777777777777777777777777777777777777777777777777777777777777777777777777777777777777777777777777\
7777777777777777777777777777777777777777777777777777777777777777777777777777777777777777777777777777\
7777777777777777777777777777777777777777777777777777777777777777777777777777777777777777777777777777\
7777777777777777777777777777777777777777777777777777777777777777777777777777777777777777777777777777";

/// A number field's value after `text` is typed into it: egui reads an f64 (NaN clamped
/// to +inf by the field's range) and the field stores an f32; text that reads as no number
/// (empty, letters) changes nothing.
fn typed_number(text: &str) -> Option<f32> {
    let v: f64 = text.parse().ok()?;
    Some(if v.is_nan() { f32::INFINITY } else { v as f32 })
}

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
    fn tame(&mut self) -> f32 {
        (self.next() % 2001) as f32 / 1000.0 - 1.0
    }
    /// Mostly tame, one in eight an extreme: typed, or a raw NaN (an edit can carry one).
    fn f(&mut self) -> f32 {
        match self.below(16) {
            0 => typed_number(TYPED[self.below(TYPED.len())]).unwrap_or_else(|| self.tame()),
            1 => [f32::NAN, 1e-45, f32::MAX][self.below(3)],
            _ => self.tame(),
        }
    }
    fn v(&mut self) -> Vec3 {
        Vec3::new(self.f(), self.f(), self.f())
    }
    fn word(&mut self) -> String {
        const WORDS: &[&str] = &["missing.obj", "two words.obj", "a{b", "#x", "tab\there"];
        match self.below(3) {
            0 => TYPED[self.below(TYPED.len())].to_string(),
            _ => WORDS[self.below(WORDS.len())].to_string(),
        }
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
        _ => {
            // Now and then a projective last row.
            let mut m = Mat4::from_scale(r.v());
            if r.below(4) == 0 {
                m.x_axis.w = r.f();
            }
            TransformOp::Matrix(m)
        }
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
            obj_file: r.word(),
            mesh: MeshSlot::Failed("missing".into()),
        },
        4 => NodeKind::Group,
        _ => NodeKind::Transform(vec![random_op(r)]),
    }
}

fn random_material(r: &mut Rng) -> Material {
    let mut m = Material::diffuse(r.v());
    if r.below(4) == 0 {
        let name = if r.below(2) == 0 {
            "specularColor".to_string()
        } else {
            r.word()
        };
        m.extra.push((name, vec![r.f(), r.f(), r.f()]));
    }
    m
}

/// Mostly a node of the scene; else any id the arena has ever held, or one that never
/// existed, so stale and invalid ids are exercised too.
fn random_node(r: &mut Rng, d: &Document) -> NodeId {
    let live = d.scene.graph.preorder();
    if r.below(4) > 0 {
        return live[r.below(live.len())];
    }
    NodeId(r.below(d.scene.graph.capacity_len() + 1) as u32)
}

fn random_camera(r: &mut Rng) -> Camera {
    // Now and then up parallel to the direction.
    let direction = r.v();
    let up = if r.below(6) == 0 {
        direction * 2.0
    } else {
        r.v()
    };
    if r.below(2) == 0 {
        Camera::Orthographic {
            center: r.v(),
            direction,
            up,
            size: r.f() * 5.0,
        }
    } else {
        Camera::Perspective {
            center: r.v(),
            direction,
            up,
            angle: r.f() * 180.0,
        }
    }
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
            material: random_material(r),
        },
        13 => Edit::AddMaterial(random_material(r)),
        14 => Edit::RemoveMaterial { index: r.below(7) },
        15 => Edit::SetCamera(random_camera(r)),
        16 => Edit::AddLight(Light::new(r.v(), r.v())),
        17 => Edit::RemoveLight { index: r.below(4) },
        18 => Edit::SetLight {
            index: r.below(4),
            light: Light::new(r.v(), r.v()),
        },
        _ => Edit::SetBackground(Background {
            color: Some(r.v()),
            ambient: (r.below(2) == 0).then(|| r.v()),
        }),
    }
}

/// Where the property test pretends to save: in the current folder, so relative mesh paths
/// need no rewriting. Nothing is written there.
const SAVE_AS: &str = "edit-property-never-written.txt";

fn render(s: &Scene) -> Vec<[u8; 3]> {
    render_frame(&compile(s), &RenderSettings::new(4, 4))
        .samples
        .iter()
        .map(|p| p.color)
        .collect()
}

/// What Save would do now: write text that reads back as this document (checked here
/// independently of Save's own check: it parses, writes back the same text, renders the
/// same), or write nothing because a node is incomplete, and say which.
fn check_save(d: &mut Document, seed: u64, step: usize) {
    let (s, t) = (seed, step);
    match d.text_for(Path::new(SAVE_AS)) {
        Ok(text) => {
            let back = parse_scene(
                text.as_bytes(),
                SAVE_AS,
                Some(Path::new(".")),
                &mut MeshCache::new(),
            );
            let Some(read) = back.scene else {
                panic!(
                    "seed {s} step {t}: Save would write a file that does not open:\n{}\n{text}",
                    back.diagnostics
                )
            };
            assert_eq!(
                d.scene.reads_back_as(&read),
                Ok(()),
                "seed {s} step {t}:\n{text}"
            );
            assert_eq!(
                write_scene(&read),
                text,
                "seed {s} step {t}: writing is not canonical"
            );
            assert_eq!(
                render(&read),
                render(&d.scene),
                "seed {s} step {t}: renders differently:\n{text}"
            );
        }
        Err(why) => {
            let incomplete: Vec<_> = check_scene(&d.scene)
                .into_iter()
                .filter(|p| p.incomplete)
                .collect();
            assert!(
                !incomplete.is_empty(),
                "seed {s} step {t}: Save refuses a complete document: {why}"
            );
            assert!(
                why.to_string().contains(&incomplete[0].message),
                "seed {s} step {t}: {why}"
            );
        }
    }
}

/// Seeds: 2000 (about half a minute here); `TRACELAB_EDIT_SEEDS` asks for more or fewer.
fn seeds() -> u64 {
    std::env::var("TRACELAB_EDIT_SEEDS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(2000)
}

#[test]
fn random_edits_are_refused_or_saved_faithfully_and_full_undo_restores_the_document() {
    let (mut applied_all, mut refused_all) = (0u64, 0u64);
    for seed in 1..=seeds() {
        let mut r = Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1);
        let mut d = Document::builtin();
        let original = d.scene.clone();
        let mut applied = 0;
        for step in 0..60 {
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
                    let before = d.scene.clone();
                    if d.apply(e.clone()).is_ok() {
                        applied += 1;
                    } else {
                        refused_all += 1;
                        assert_eq!(
                            d.scene, before,
                            "seed {seed} step {step}: a refused {e:?} changed the document"
                        );
                    }
                }
            }
            check_save(&mut d, seed, step);
            check_csg_operands(&d, seed);
        }
        applied_all += applied;
        while d.undo() {}
        assert_eq!(d.scene, original, "seed {seed}");
        assert!(
            !d.is_dirty(),
            "seed {seed}: back at the opened state, nothing is unsaved"
        );
    }
    // Both ways must be exercised, or the property says little.
    assert!(
        applied_all > seeds() * 15,
        "only {applied_all} edits applied; the generator is too timid"
    );
    assert!(
        refused_all * 20 > applied_all,
        "{refused_all} refused of {applied_all} applied"
    );
}

fn check_csg_operands(d: &Document, seed: u64) {
    let g = &d.scene.graph;
    for id in g.preorder() {
        let n = g.node(id);
        if let NodeKind::Csg(op) = n.kind {
            assert_eq!(
                n.children.len(),
                2,
                "seed {seed}: {} with {} operands",
                op.name(),
                n.children.len()
            );
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
    d.apply(Edit::AddNode {
        parent: root,
        kind: NodeKind::Csg(CsgOp::Subtraction),
    })
    .expect("adds");
    *d.scene
        .graph
        .node(root)
        .children
        .last()
        .expect("the new node")
}

#[test]
fn a_new_csg_node_holds_two_solids_and_renders() {
    let mut d = Document::builtin();
    let csg = add_subtraction(&mut d);
    let kids = d.scene.graph.node(csg).children.clone();
    assert_eq!(kids.len(), 2);
    assert!(matches!(
        d.scene.graph.node(kids[0]).kind,
        NodeKind::Box { .. }
    ));
    assert!(matches!(
        d.scene.graph.node(kids[1]).kind,
        NodeKind::Sphere { .. }
    ));
    let text = tracelab_core::write_scene(&d.scene);
    assert!(text.contains("Subtraction {"), "{text}");
    // Switching the operation and swapping operands are single edits that undo.
    let before = d.scene.clone();
    d.apply(Edit::SetNodeKind {
        node: csg,
        kind: NodeKind::Csg(CsgOp::Union),
    })
    .expect("op change");
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
    let [a, b] = d.scene.graph.node(csg).children[..] else {
        panic!("two operands")
    };
    d.apply(Edit::DeleteNode { node: b }).expect("deletes");
    let root = d.scene.graph.root();
    let kids = &d.scene.graph.node(root).children;
    assert_eq!(
        kids.last(),
        Some(&a),
        "the Box takes the Subtraction's place"
    );
    assert!(!kids.contains(&csg));
}

/// Every way of giving the operands of a CSG node under a Transform (and the Transform)
/// materials, then deleting one operand: the survivor takes the CSG node's place inside the
/// Transform, where no MaterialIndex can stand. The deletion applies, every object keeps its
/// colour, and the saved text reads back as the document (it used to wrap the survivor in a
/// Group of its own, which read back as a different tree).
#[test]
fn deleting_a_csg_operand_under_a_transform_keeps_colours_and_saves_faithfully() {
    let index = |m: Option<u32>| m.map_or(String::new(), |m| format!("MaterialIndex {m} "));
    let choices = [None, Some(1), Some(3)];
    let mut cases = 0;
    for nested in [false, true] {
        for (a_mat, b_mat, t_mat) in choices.iter().flat_map(|&a| {
            choices
                .iter()
                .flat_map(move |&b| choices.map(move |t| (a, b, t)))
        }) {
            for delete_a in [false, true] {
                let t = format!(
                    "{}Transform {{ Translate 0 1 0 Subtraction {{ {}Box {{ min -1 -1 -1 max 1 1 1 }} {}Sphere {{ center 0 0 0 radius 1.3 }} }} }}",
                    index(t_mat),
                    index(a_mat),
                    index(b_mat)
                );
                // Nested: the Transform is operand B of a Union.
                let t = if nested {
                    format!("Union {{ Sphere {{ center 3 0 0 radius 1 }} {t} }}")
                } else {
                    t
                };
                let text = format!(
                    "PerspectiveCamera {{ center 0 0 10 direction 0 0 -1 up 0 1 0 angle 40 }}\n\
                     Lights {{ numLights 1 DirectionalLight {{ direction -1 -1 -1 color 1 1 1 }} }}\n\
                     Materials {{ numMaterials 4 Material {{ diffuseColor 1 0 0 }} Material {{ diffuseColor 0 1 0 }} Material {{ diffuseColor 0 0 1 }} Material {{ diffuseColor 1 1 0 }} }}\n\
                     Group {{ numObjects 3 MaterialIndex 2 Sphere {{ center -3 0 0 radius 1 }} {t} Sphere {{ center 0 -3 0 radius 1 }} }}\n"
                );
                let scene = parse_scene(text.as_bytes(), "t.txt", None, &mut MeshCache::new())
                    .into_result()
                    .expect("parses")
                    .0;
                let mut d = Document::new(scene, None);
                let g = &d.scene.graph;
                let sub = g
                    .iter()
                    .find(|(_, n)| n.kind == NodeKind::Csg(CsgOp::Subtraction))
                    .map(|(id, _)| id)
                    .expect("the Subtraction");
                let transform = g.parents()[sub.index()].expect("its Transform");
                let [a, b] = g.node(sub).children[..] else {
                    panic!("two operands")
                };
                let (gone, kept) = if delete_a { (a, b) } else { (b, a) };
                let before = g.effective_materials();
                d.apply(Edit::DeleteNode { node: gone })
                    .unwrap_or_else(|e| panic!("case {cases}: refused: {e}\n{text}"));
                let after = d.scene.graph.effective_materials();
                for (id, _) in d.scene.graph.iter() {
                    // The Transform may now carry the survivor's material for it.
                    if id != transform {
                        assert_eq!(
                            after[id.index()],
                            before[id.index()],
                            "case {cases}: node {id:?} changed colour\n{text}"
                        );
                    }
                }
                assert!(
                    d.scene.graph.path_to(kept).is_some(),
                    "case {cases}: the survivor is in the scene"
                );
                check_save(&mut d, cases, 0);
                cases += 1;
            }
        }
    }
    assert_eq!(cases, 108);
}

#[test]
fn a_csg_operand_cannot_become_a_group_or_a_triangle() {
    let mut d = Document::builtin();
    let csg = add_subtraction(&mut d);
    let a = d.scene.graph.node(csg).children[0];
    let before = d.scene.clone();
    assert!(d.apply(Edit::WrapInGroup { node: a }).is_err());
    let tri = NodeKind::Triangle {
        vertices: [Vec3::ZERO, Vec3::X, Vec3::Y],
    };
    assert!(d.apply(Edit::SetNodeKind { node: a, kind: tri }).is_err());
    assert_eq!(d.scene, before);
    // Wrapping in a Transform keeps it a solid, so that is allowed.
    d.apply(Edit::WrapInTransform { node: a })
        .expect("a Transform of a solid is a solid");
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
