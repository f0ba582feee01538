use super::super::{Graph, MeshSlot, Node};
use super::*;
use glam::Mat4;

fn ts(ops: Vec<TransformOp>) -> Result<(), Invalid> {
    check_kind(&NodeKind::Transform(ops))
}

#[test]
fn unit_survives_components_whose_square_overflows() {
    assert_eq!(unit(Vec3::new(0.0, 0.0, 1e20)), Some(Vec3::Z));
    assert_eq!(unit(Vec3::new(0.0, 0.0, -3e38)), Some(Vec3::NEG_Z));
    let l = Vec3::new(-0.5, -1.0, -0.5);
    assert!((unit(l * 1e20).expect("unit") - l.normalize()).length() < 1e-6);
    assert_eq!(unit(Vec3::ZERO), None);
    assert_eq!(unit(Vec3::new(f32::NAN, 0.0, 1.0)), None);
}

#[test]
fn singularity_is_relative_to_the_matrix_s_own_scale() {
    assert!(ts(vec![TransformOp::UniformScale(0.0001)]).is_ok());
    assert!(ts(vec![TransformOp::UniformScale(1e13)]).is_ok());
    assert!(ts(vec![TransformOp::Scale(Vec3::new(1.0, 0.0, 1.0))]).is_err());
    assert!(ts(vec![TransformOp::Scale(Vec3::new(1.0, 1e-8, 1.0))]).is_err());
    assert!(ts(vec![TransformOp::UniformScale(0.0)]).is_err());
    let e = ts(vec![
        TransformOp::Translate(Vec3::X),
        TransformOp::Scale(Vec3::new(1.0, 0.0, 1.0)),
    ])
    .expect_err("flat");
    assert_eq!((e.field, e.op), (Field::Op("Scale"), Some(1)));
}

#[test]
fn a_projective_matrix_and_a_zero_rotate_axis_are_errors() {
    let mut m = Mat4::IDENTITY.to_cols_array_2d();
    m[0][3] = 0.5; // row 3, column 0
    let e = check_op(&TransformOp::Matrix(Mat4::from_cols_array_2d(&m))).expect_err("projective");
    assert!(e.message.contains("last row must be 0 0 0 1"), "{e}");
    let e = check_op(&TransformOp::Rotate {
        axis: Vec3::ZERO,
        degrees: 45.0,
    })
    .expect_err("zero axis");
    assert!(e.message.contains("axis must not be zero"), "{e}");
}

#[test]
fn camera_rules_use_unit_vectors_and_name_their_field() {
    let cam = |direction: Vec3, up: Vec3, size: f32| Camera::Orthographic {
        center: Vec3::ZERO,
        direction,
        up,
        size,
    };
    assert!(check_camera(&cam(Vec3::new(0.0, 0.0, -3e38), Vec3::Y, 1.0)).is_ok());
    assert_eq!(
        check_camera(&cam(Vec3::Y * 2.0, Vec3::Y, 1.0))
            .expect_err("parallel")
            .field,
        Field::Up
    );
    assert_eq!(
        check_camera(&cam(Vec3::NEG_Z, Vec3::Y, 0.0))
            .expect_err("size 0")
            .field,
        Field::Size
    );
    assert_eq!(
        check_camera(&cam(Vec3::NEG_Z, Vec3::Y, f32::NAN))
            .expect_err("nan")
            .field,
        Field::Size
    );
}

#[test]
fn negative_radius_and_empty_mesh_file_differ_in_kind() {
    let e = check_kind(&NodeKind::Sphere {
        center: Vec3::ZERO,
        radius: -1.0,
    })
    .expect_err("negative");
    assert!(
        !e.incomplete,
        "a negative radius is invalid, not incomplete"
    );
    let mesh = |f: &str| NodeKind::TriangleMesh {
        obj_file: f.into(),
        mesh: MeshSlot::Failed(String::new()),
    };
    assert!(check_kind(&mesh("")).expect_err("no file").incomplete);
    assert!(!check_kind(&mesh("a b.obj")).expect_err("space").incomplete);
    assert!(
        check_kind(&mesh("1.obj")).is_ok(),
        "the reader takes any word after obj_file"
    );
}

#[test]
fn material_field_names_must_read_back_as_fields() {
    let with = |name: &str| Material {
        extra: vec![(name.into(), vec![1.0])],
        ..Material::diffuse(Vec3::ONE)
    };
    assert!(check_material(&with("exponent")).is_ok());
    for bad in [
        "",
        "2x",
        "-e",
        "nan",
        "obj_file",
        "diffuseColor",
        "a b",
        "x}",
    ] {
        assert!(check_material(&with(bad)).is_err(), "{bad:?}");
    }
}

#[test]
fn graph_verdicts_name_the_child_at_fault_by_field() {
    let sphere = || {
        Node::new(NodeKind::Sphere {
            center: Vec3::ZERO,
            radius: 1.0,
        })
    };
    // A Transform of two objects: the second is named, where the parser places it.
    let mut g = Graph::new();
    let t = g.add(Node::new(NodeKind::Transform(Vec::new())));
    let (a, b) = (g.add(sphere()), g.add(sphere()));
    g.push_child(g.root(), t);
    g.push_child(t, a);
    g.push_child(t, b);
    let p = check_graph(&g, 0);
    assert_eq!(p.len(), 1, "{p:?}");
    assert_eq!(
        (p[0].place, &p[0].field),
        (Place::Node(t), &Field::Child(b))
    );
    // A CSG operand through a Transform: the Triangle it leads to is named.
    let mut g = Graph::new();
    let u = g.add(Node::new(NodeKind::Csg(super::super::CsgOp::Union)));
    let t = g.add(Node::new(NodeKind::Transform(Vec::new())));
    let tri = g.add(Node::new(NodeKind::Triangle {
        vertices: [Vec3::ZERO, Vec3::X, Vec3::Y],
    }));
    let s = g.add(sphere());
    g.push_child(g.root(), u);
    g.push_child(u, t);
    g.push_child(t, tri);
    g.push_child(u, s);
    let p = check_graph(&g, 0);
    assert_eq!(p.len(), 1, "{p:?}");
    assert_eq!(
        (p[0].place, &p[0].field),
        (Place::Node(u), &Field::Child(tri))
    );
    assert!(
        p[0].reason.starts_with("a lone Triangle is not a solid"),
        "{p:?}"
    );
    assert!(!is_solid(&g, t) && is_solid(&g, s));
}

#[test]
fn nested_tiny_scales_are_fine_and_a_flattening_one_is_found_in_the_chain() {
    let mut g = Graph::new();
    let mut parent = g.root();
    for _ in 0..10 {
        let t = g.add(Node::new(NodeKind::Transform(vec![
            TransformOp::UniformScale(0.1),
        ])));
        g.push_child(parent, t);
        parent = t;
    }
    let s = g.add(Node::new(NodeKind::Sphere {
        center: Vec3::ZERO,
        radius: 1e10,
    }));
    g.push_child(parent, s);
    assert_eq!(check_graph(&g, 0), []);
    // Two ops, each fine alone, that squash y by 1e-8 together.
    let mut g = Graph::new();
    let ops = vec![TransformOp::Scale(Vec3::new(1.0, 1e-4, 1.0))];
    let a = g.add(Node::new(NodeKind::Transform(ops.clone())));
    let b = g.add(Node::new(NodeKind::Transform(ops)));
    let s = g.add(Node::new(NodeKind::Sphere {
        center: Vec3::ZERO,
        radius: 1.0,
    }));
    g.push_child(g.root(), a);
    g.push_child(a, b);
    g.push_child(b, s);
    let p = check_graph(&g, 0);
    assert_eq!(p.len(), 1, "{p:?}");
    assert_eq!(p[0].place, Place::Node(b));
}
