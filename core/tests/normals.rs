//! Normal transformation properties: under random affine maps (shear and non-uniform scale
//! included), (M⁻¹)ᵀ·n stays perpendicular to the transformed surface; M·n does not under
//! shear, and agrees for similitudes (rotation, uniform scale, translation).

use glam::{Mat4, Vec3};
use tracelab_core::geometry::Ray;
use tracelab_core::{
    Graph, Material, Node, NodeKind, NormalTransform, Scene, TransformOp, compile,
};

struct Rng(u64);
impl Rng {
    fn f(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
    }
    fn v(&mut self) -> Vec3 {
        Vec3::new(self.f(), self.f(), self.f())
    }
}

/// A scene holding one unit sphere under matrix `m`.
fn sphere_under(m: Mat4) -> Scene {
    let mut scene = Scene::default();
    scene.materials.push(Material::diffuse(Vec3::ONE));
    let mut g = Graph::new();
    let t = g.add(Node {
        material: Some(0),
        ..Node::new(NodeKind::Transform(vec![TransformOp::Matrix(m)]))
    });
    let s = g.add(Node::new(NodeKind::Sphere {
        center: Vec3::ZERO,
        radius: 1.0,
    }));
    g.push_child(g.root(), t);
    g.push_child(t, s);
    scene.graph = g;
    scene
}

/// Unit vectors tangent to the unit sphere at p, mapped by m: tangents of the world surface.
fn world_tangents(m: &Mat4, p: Vec3) -> [Vec3; 2] {
    let a = p.any_orthonormal_vector();
    let b = p.cross(a);
    [m.transform_vector3(a), m.transform_vector3(b)]
}

#[test]
fn sheared_sphere_normal_stays_perpendicular_to_surface() {
    let mut rng = Rng(0x1234_5678_9abc_def1);
    let mut incorrect_off = 0;
    let mut checked = 0;
    for _ in 0..200 {
        // Random affine map with shear and non-uniform scale, kept well conditioned.
        let lin = glam::Mat3::from_cols(
            rng.v() * 0.6 + Vec3::X,
            rng.v() * 0.6 + Vec3::Y,
            rng.v() * 0.6 + Vec3::Z,
        );
        if lin.determinant().abs() < 0.2 {
            continue;
        }
        let m = Mat4::from_translation(rng.v()) * Mat4::from_mat3(lin);
        let compiled = compile(&sphere_under(m));
        for _ in 0..10 {
            // Aim from outside at a random surface point.
            let p_obj = rng.v().normalize_or(Vec3::X);
            let target = m.transform_point3(p_obj);
            let origin = target + rng.v().normalize_or(Vec3::Z) * 10.0;
            let ray = Ray::new(origin, (target - origin).normalize());
            let Some(hit) = compiled.intersect(&ray, 0.0, f32::INFINITY) else {
                continue;
            };
            let p_hit = m.inverse().transform_point3(ray.at(hit.t));
            let n = compiled.world_normal(&ray, &hit, NormalTransform::Correct);
            for tangent in world_tangents(&m, p_hit.normalize()) {
                assert!(
                    n.dot(tangent.normalize()).abs() < 2e-3,
                    "correct normal not perpendicular: {}",
                    n.dot(tangent.normalize())
                );
            }
            let wrong = compiled.world_normal(&ray, &hit, NormalTransform::Incorrect);
            if world_tangents(&m, p_hit.normalize())
                .iter()
                .any(|t| wrong.dot(t.normalize()).abs() > 0.05)
            {
                incorrect_off += 1;
            }
            checked += 1;
        }
    }
    assert!(checked > 500, "too few hits checked: {checked}");
    assert!(
        incorrect_off > checked / 2,
        "M·n should usually be off the perpendicular: {incorrect_off}/{checked}"
    );
}

#[test]
fn incorrect_mode_equals_correct_for_similitudes() {
    let mut rng = Rng(0xdead_beef_cafe_f00d);
    for _ in 0..50 {
        let axis = rng.v().normalize_or(Vec3::Y);
        let m = Mat4::from_translation(rng.v() * 3.0)
            * Mat4::from_axis_angle(axis, rng.f() * 3.0)
            * Mat4::from_scale(Vec3::splat(0.5 + rng.f().abs() * 2.0));
        let compiled = compile(&sphere_under(m));
        let target = m.transform_point3(rng.v().normalize_or(Vec3::X));
        let origin = target + rng.v().normalize_or(Vec3::Z) * 20.0;
        let ray = Ray::new(origin, (target - origin).normalize());
        let Some(hit) = compiled.intersect(&ray, 0.0, f32::INFINITY) else {
            continue;
        };
        let a = compiled.world_normal(&ray, &hit, NormalTransform::Correct);
        let b = compiled.world_normal(&ray, &hit, NormalTransform::Incorrect);
        assert!((a - b).length() < 1e-4, "{a} vs {b}");
    }
}

#[test]
fn t_is_the_same_in_object_and_world_space() {
    // A sphere scaled by 2 along z: the world hit distance must be the world distance.
    let m = Mat4::from_scale(Vec3::new(1.0, 1.0, 2.0));
    let compiled = compile(&sphere_under(m));
    let ray = Ray::new(Vec3::new(0.0, 0.0, 10.0), Vec3::NEG_Z);
    let hit = compiled.intersect(&ray, 0.0, f32::INFINITY).expect("hit");
    assert!((hit.t - 8.0).abs() < 1e-5, "t = {}", hit.t);
}
