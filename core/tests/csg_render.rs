//! CSG and Box rendering: exact intervals against analytic answers, and properties of the
//! operations (A∪A = A, A∩A = A, A−A = ∅, commutativity, exposed normals, camera inside).

use glam::Vec3;
use tracelab_core::geometry::Ray;
use tracelab_core::geometry::{box_face_normal, box_span};
use tracelab_core::render::csg::{Bound, CsgTree, FLIP_BIT};
use tracelab_core::render::{Frame, Shape};
use tracelab_core::{
    CompiledScene, MeshCache, NormalTransform, RenderSettings, Scene, compile, parse_scene,
    render_frame,
};

const HEAD: &str = "PerspectiveCamera { center 2 1.5 6 direction -2 -1.5 -6 up 0 1 0 angle 35 }\n\
Lights { numLights 1 DirectionalLight { direction -0.5 -0.6 -1 color 0.8 0.8 0.8 } }\n\
Background { color 0.1 0.1 0.1 ambientLight 0.2 0.2 0.2 }\n\
Materials { numMaterials 2 Material { diffuseColor 0.9 0.2 0.2 } Material { diffuseColor 0.2 0.3 0.9 } }\n";

/// Unit spheres A at x = −0.5 and B at x = +0.5, with their own materials.
const A: &str = "MaterialIndex 0 Sphere { center -0.5 0 0 radius 1 }";
const B: &str = "MaterialIndex 1 Sphere { center 0.5 0 0 radius 1 }";

fn scene(objects: &str) -> Scene {
    let text = format!("{HEAD}Group {{ numObjects 1 {objects} }}");
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes");
    parse_scene(text.as_bytes(), "t.txt", Some(&dir), &mut MeshCache::new())
        .into_result()
        .unwrap_or_else(|d| panic!("{d}\n{text}"))
        .0
}

fn csg(op: &str, a: &str, b: &str) -> String {
    format!("{op} {{ {a} {b} }}")
}

/// The compiled CSG tree of a scene whose only object is one CSG node.
fn tree(objects: &str) -> (CompiledScene, std::sync::Arc<CsgTree>) {
    let c = compile(&scene(objects));
    let t = match c.objects.first().map(|o| &o.shape) {
        Some(Shape::Csg(t)) => t.clone(),
        other => panic!("expected one CSG object, found {other:?}"),
    };
    (c, t)
}

fn ts(bounds: &[Bound]) -> Vec<f32> {
    bounds.iter().map(|b| b.t).collect()
}

fn assert_close(got: &[f32], want: &[f32]) {
    assert_eq!(got.len(), want.len(), "got {got:?}, want {want:?}");
    for (g, w) in got.iter().zip(want) {
        assert!((g - w).abs() < 1e-5, "got {got:?}, want {want:?}");
    }
}

fn render(s: &Scene, w: u32, h: u32) -> Frame {
    let settings = RenderSettings::new(w, h);
    render_frame(&compile(s), &settings)
}

/// Pixels whose colour, normal or t differ (node ids are not compared).
fn differing(a: &Frame, b: &Frame) -> usize {
    a.samples
        .iter()
        .zip(&b.samples)
        .filter(|(x, y)| {
            x.color != y.color || x.normal != y.normal || x.t.to_bits() != y.t.to_bits()
        })
        .count()
}

fn hits(f: &Frame) -> usize {
    f.samples.iter().filter(|s| s.is_hit()).count()
}

#[test]
fn ray_through_two_overlapping_unit_spheres_gives_exact_intervals_per_operation() {
    // Along the x axis from x = −5: A spans x ∈ [−1.5, 0.5], B spans x ∈ [−0.5, 1.5].
    let ray = Ray::new(Vec3::new(-5.0, 0.0, 0.0), Vec3::X);
    let (_, u) = tree(&csg("Union", A, B));
    assert_close(&ts(&u.intervals(&ray)), &[3.5, 6.5]);
    let (_, i) = tree(&csg("Intersection", A, B));
    assert_close(&ts(&i.intervals(&ray)), &[4.5, 5.5]);
    let (_, s) = tree(&csg("Subtraction", A, B));
    let sub = s.intervals(&ray);
    assert_close(&ts(&sub), &[3.5, 4.5]);
    // A − B ends where B begins, on B's surface, turned around.
    assert_eq!(sub[1].leaf(), Some(1));
    assert!(sub[1].is_flipped() && !sub[0].is_flipped());

    // Off the axis, at x = 0.2 going down −z from z = 5: A's half chord is √(1 − 0.7²), B's
    // is √(1 − 0.3²).
    let ray = Ray::new(Vec3::new(0.2, 0.0, 5.0), Vec3::NEG_Z);
    let (ha, hb) = ((1.0f32 - 0.49).sqrt(), (1.0f32 - 0.09).sqrt());
    assert_close(&ts(&u.intervals(&ray)), &[5.0 - hb, 5.0 + hb]);
    assert_close(&ts(&i.intervals(&ray)), &[5.0 - ha, 5.0 + ha]);
    assert!(s.intervals(&ray).is_empty(), "A is inside B along this ray");
    // B − A: two pieces, the inner ends on A's surface.
    let (_, ba) = tree(&csg("Subtraction", B, A));
    assert_close(
        &ts(&ba.intervals(&ray)),
        &[5.0 - hb, 5.0 - ha, 5.0 + ha, 5.0 + hb],
    );
}

#[test]
fn box_entry_and_exit_for_axis_and_oblique_rays() {
    let (lo, hi) = (Vec3::splat(-1.0), Vec3::splat(1.0));
    let axis = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::NEG_Z);
    let (t0, f0, t1, f1) = box_span(&axis, lo, hi).expect("axis ray hits");
    assert_eq!((t0, t1), (4.0, 6.0));
    assert_eq!(
        (box_face_normal(f0), box_face_normal(f1)),
        (Vec3::Z, Vec3::NEG_Z)
    );
    // Oblique: x enters at t = 2 (x = −1), y leaves at t = 3 (y = 1), z stays inside.
    let oblique = Ray::new(Vec3::new(-3.0, -0.5, 0.0), Vec3::new(1.0, 0.5, 0.25));
    let (t0, f0, t1, f1) = box_span(&oblique, lo, hi).expect("oblique ray hits");
    assert!(
        (t0 - 2.0).abs() < 1e-6 && (t1 - 3.0).abs() < 1e-6,
        "{t0} {t1}"
    );
    assert_eq!(
        (box_face_normal(f0), box_face_normal(f1)),
        (Vec3::NEG_X, Vec3::Y)
    );
    assert!(box_span(&Ray::new(Vec3::new(-3.0, 1.5, 0.0), Vec3::X), lo, hi).is_none());

    // The same through a compiled Box: the nearest face, or the far one from inside.
    let c = compile(&scene("MaterialIndex 0 Box { min -1 -1 -1 max 1 1 1 }"));
    let h = c.intersect(&oblique, 0.0, f32::INFINITY).expect("hit");
    assert!((h.t - 2.0).abs() < 1e-6);
    assert_eq!(
        c.world_normal(&oblique, &h, NormalTransform::Correct),
        Vec3::NEG_X
    );
    let h = c
        .intersect(&oblique, 2.5, f32::INFINITY)
        .expect("hit from inside");
    assert!((h.t - 3.0).abs() < 1e-6);
    assert_eq!(
        c.world_normal(&oblique, &h, NormalTransform::Correct),
        Vec3::Y
    );
}

#[test]
fn transformed_box_turns_its_faces() {
    // A unit box turned 90° about z: the face seen from +x was the +y face.
    let c = compile(&scene(
        "MaterialIndex 0 Transform { ZRotate 90 Scale 1 3 1 Box { min -1 -1 -1 max 1 1 1 } }",
    ));
    let ray = Ray::new(Vec3::new(10.0, 0.0, 0.0), Vec3::NEG_X);
    let h = c.intersect(&ray, 0.0, f32::INFINITY).expect("hit");
    // Scale 3 along the box's y, which ZRotate 90 turns onto x: the face is at x = 3.
    assert!((h.t - 7.0).abs() < 1e-5, "{}", h.t);
    assert!((c.world_normal(&ray, &h, NormalTransform::Correct) - Vec3::X).length() < 1e-5);
}

#[test]
fn transformed_csg_keeps_t_in_world_units() {
    // Scaled by 2 and moved: the spheres are radius 2 at x = −1 and x = 1, z = −3.
    let objects = format!(
        "Transform {{ Translate 0 0 -3 UniformScale 2 {} }}",
        csg("Union", A, B)
    );
    let (c, t) = tree(&objects);
    let ray = Ray::new(Vec3::new(-10.0, 0.0, -3.0), Vec3::X);
    assert_close(&ts(&t.intervals(&ray)), &[7.0, 13.0]);
    let h = c.intersect(&ray, 0.0, f32::INFINITY).expect("hit");
    assert!((h.t - 7.0).abs() < 1e-5);
    // The same as a plain sphere placed there by the same transform.
    let plain = compile(&scene(
        "MaterialIndex 0 Transform { Translate 0 0 -3 UniformScale 2 Sphere { center -0.5 0 0 radius 1 } }",
    ));
    assert_eq!(
        plain.intersect(&ray, 0.0, f32::INFINITY).map(|h| h.t),
        Some(h.t)
    );
}

#[test]
fn a_plane_operand_is_the_half_space_behind_its_normal() {
    // Sphere ∩ {y ≤ 0}: the lower hemisphere, its flat top on the plane.
    let (c, t) = tree(&csg(
        "Intersection",
        A,
        "MaterialIndex 1 Plane { normal 0 1 0 offset 0 }",
    ));
    let down = Ray::new(Vec3::new(-0.5, 5.0, 0.0), Vec3::NEG_Y);
    assert_close(&ts(&t.intervals(&down)), &[5.0, 6.0]);
    let h = c.intersect(&down, 0.0, f32::INFINITY).expect("hit");
    assert_eq!(c.world_normal(&down, &h, NormalTransform::Correct), Vec3::Y);
    // The flat top keeps the plane's material; the curved bottom keeps the sphere's.
    assert_eq!(c.hit_material(&h), 1);
    let up = Ray::new(Vec3::new(-0.5, -5.0, 0.0), Vec3::Y);
    let h = c.intersect(&up, 0.0, f32::INFINITY).expect("hit");
    assert!((h.t - 4.0).abs() < 1e-6);
    assert_eq!(c.hit_material(&h), 0);
    // Bounds are the sphere's, so the object can sit in the BVH.
    assert!(t.bounds().is_finite());
}

#[test]
fn csg_surfaces_keep_their_operands_material_and_node() {
    let s = scene(&csg("Subtraction", A, B));
    let c = compile(&s);
    let g = &s.graph;
    let sub = g.node(g.root()).children[0];
    let (a_node, b_node) = (g.node(sub).children[0], g.node(sub).children[1]);
    // From −x the ray meets A's own surface; from +x, B's exposed inner surface.
    let from_left = Ray::new(Vec3::new(-5.0, 0.0, 0.0), Vec3::X);
    let h = c.intersect(&from_left, 0.0, f32::INFINITY).expect("hit");
    assert_eq!((c.hit_material(&h), c.hit_node(&h)), (0, Some(a_node)));
    let from_right = Ray::new(Vec3::new(5.0, 0.0, 0.0), Vec3::NEG_X);
    let h = c.intersect(&from_right, 0.0, f32::INFINITY).expect("hit");
    assert!((h.t - 5.5).abs() < 1e-6, "{}", h.t);
    assert_eq!((c.hit_material(&h), c.hit_node(&h)), (1, Some(b_node)));
    assert_ne!(h.prim & FLIP_BIT, 0);
    assert_eq!(
        c.world_normal(&from_right, &h, NormalTransform::Correct),
        Vec3::X,
        "faces the viewer"
    );
}

#[test]
fn union_and_intersection_of_a_solid_with_itself_is_the_solid() {
    let a = "MaterialIndex 0 Transform { YRotate 30 Scale 1 0.6 1 Box { min -1 -1 -1 max 1 1 1 } }";
    let alone = render(&scene(a), 48, 40);
    assert!(hits(&alone) > 200);
    for op in ["Union", "Intersection"] {
        let f = render(&scene(&csg(op, a, a)), 48, 40);
        assert_eq!(differing(&alone, &f), 0, "{op}(A, A) differs from A");
    }
    let s = "MaterialIndex 1 Sphere { center 0 0 0 radius 1 }";
    let alone = render(&scene(s), 48, 40);
    assert_eq!(
        differing(&alone, &render(&scene(&csg("Union", s, s)), 48, 40)),
        0
    );
}

#[test]
fn a_solid_minus_itself_is_empty() {
    for a in [
        A,
        "MaterialIndex 0 Box { min -1 -1 -1 max 1 1 1 }",
        "MaterialIndex 0 TriangleMesh { obj_file ../assets/cube.obj }",
    ] {
        let f = render(&scene(&csg("Subtraction", a, a)), 48, 40);
        assert_eq!(hits(&f), 0, "{a} minus itself shows something");
    }
}

#[test]
fn union_and_intersection_commute_with_identical_images() {
    for op in ["Union", "Intersection"] {
        let ab = render(&scene(&csg(op, A, B)), 64, 48);
        let ba = render(&scene(&csg(op, B, A)), 64, 48);
        assert!(hits(&ab) > 300, "{op}: too little visible");
        assert_eq!(differing(&ab, &ba), 0, "{op} is not commutative");
    }
    // Subtraction is not: A − B and B − A differ.
    let ab = render(&scene(&csg("Subtraction", A, B)), 64, 48);
    let ba = render(&scene(&csg("Subtraction", B, A)), 64, 48);
    assert!(differing(&ab, &ba) > 100);
}

#[test]
fn subtractions_exposed_inner_surface_faces_the_viewer() {
    let s = scene(&csg("Subtraction", A, B));
    let c = compile(&s);
    let (w, h) = (64, 48);
    let b_node = s
        .graph
        .node(s.graph.node(s.graph.root()).children[0])
        .children[1];
    let mut exposed = 0;
    for row in 0..h {
        for x in 0..w {
            let ray = c.camera.pixel_ray(x, row, w, h);
            let Some(hit) = c.intersect(&ray, c.camera.t_min(), f32::INFINITY) else {
                continue;
            };
            if c.hit_node(&hit) == Some(b_node) {
                exposed += 1;
                let n = c.world_normal(&ray, &hit, NormalTransform::Correct);
                assert!(
                    n.dot(ray.direction) < 0.0,
                    "pixel {x},{row}: inner surface normal faces away"
                );
            }
        }
    }
    // The camera looks from the +x side, into the bite.
    assert!(
        exposed > 100,
        "only {exposed} pixels show the inner surface"
    );
}

#[test]
fn closed_mesh_operand_matches_the_same_box() {
    let sphere = "MaterialIndex 1 Sphere { center 0 0 0 radius 1.3 }";
    let mesh = render(
        &scene(&csg(
            "Intersection",
            "MaterialIndex 0 TriangleMesh { obj_file ../assets/cube.obj }",
            sphere,
        )),
        64,
        48,
    );
    let boxed = render(
        &scene(&csg(
            "Intersection",
            "MaterialIndex 0 Box { min -1 -1 -1 max 1 1 1 }",
            sphere,
        )),
        64,
        48,
    );
    assert!(hits(&boxed) > 300);
    let close = mesh
        .samples
        .iter()
        .zip(&boxed.samples)
        .filter(|(m, b)| {
            m.is_hit() == b.is_hit()
                && (!m.is_hit()
                    || ((m.t - b.t).abs() < 1e-4
                        && m.color.iter().zip(b.color).all(|(p, q)| p.abs_diff(q) <= 1)))
        })
        .count();
    assert!(
        close as f32 >= 0.99 * mesh.samples.len() as f32,
        "{close} of {} pixels agree",
        mesh.samples.len()
    );
}

#[test]
fn camera_inside_a_solid_sees_the_inside_of_the_result() {
    // From the centre of A ∪ B looking along +x, the ray leaves through B at x = 1.5.
    let (c, _) = tree(&csg("Union", A, B));
    let ray = Ray::new(Vec3::ZERO, Vec3::X);
    let h = c
        .intersect(&ray, 0.0, f32::INFINITY)
        .expect("hit from inside");
    assert!((h.t - 1.5).abs() < 1e-6);
    assert_eq!(
        c.world_normal(&ray, &h, NormalTransform::Correct),
        Vec3::X,
        "outward: a back face from inside"
    );
    // Inside a big sphere with a small one taken out ahead: the ray leaves the result where
    // it enters the small sphere, and that surface's normal points on, out of the result.
    let (c, _) = tree(&csg(
        "Subtraction",
        "MaterialIndex 0 Sphere { center 0 0 0 radius 3 }",
        "MaterialIndex 1 Sphere { center 2 0 0 radius 1 }",
    ));
    let h = c
        .intersect(&ray, 0.0, f32::INFINITY)
        .expect("hit from inside");
    assert!((h.t - 1.0).abs() < 1e-6);
    assert_eq!(c.world_normal(&ray, &h, NormalTransform::Correct), Vec3::X);
    // With shade-back the whole view from inside is lit, as with a plain sphere.
    let inside = format!(
        "PerspectiveCamera {{ center 0 0 0 direction 0 0 -1 up 0 1 0 angle 60 }}\n\
         Lights {{ numLights 1 DirectionalLight {{ direction 0 0 -1 color 1 1 1 }} }}\n\
         Materials {{ numMaterials 1 Material {{ diffuseColor 0.8 0.8 0.8 }} }}\n\
         Group {{ numObjects 1 MaterialIndex 0 {} }}",
        csg(
            "Union",
            "Sphere { center 0 0 -0.5 radius 2 }",
            "Box { min -1 -1 -1 max 1 1 1 }"
        )
    );
    let s = parse_scene(inside.as_bytes(), "t.txt", None, &mut MeshCache::new())
        .into_result()
        .expect("parses")
        .0;
    let settings = RenderSettings {
        shade_back: true,
        ..RenderSettings::new(16, 16)
    };
    let f = render_frame(&compile(&s), &settings);
    assert!(
        f.samples
            .iter()
            .all(|p| p.is_hit() && p.t > 0.0 && p.color[0] > 30),
        "every pixel sees the lit inside"
    );
}

#[test]
fn csg_bounds_follow_the_operation() {
    let (_, u) = tree(&csg("Union", A, B));
    assert_eq!(
        (u.bounds().min, u.bounds().max),
        (Vec3::new(-1.5, -1.0, -1.0), Vec3::new(1.5, 1.0, 1.0))
    );
    let (_, i) = tree(&csg("Intersection", A, B));
    assert_eq!(
        (i.bounds().min, i.bounds().max),
        (Vec3::new(-0.5, -1.0, -1.0), Vec3::new(0.5, 1.0, 1.0))
    );
    let (_, s) = tree(&csg("Subtraction", A, B));
    assert_eq!(
        (s.bounds().min, s.bounds().max),
        (Vec3::new(-1.5, -1.0, -1.0), Vec3::new(0.5, 1.0, 1.0))
    );
    // Disjoint operands intersect in nothing: the object is dropped, nothing is hit.
    let far = "MaterialIndex 1 Sphere { center 5 0 0 radius 1 }";
    let c = compile(&scene(&csg("Intersection", A, far)));
    assert!(
        c.intersect(
            &Ray::new(Vec3::new(-0.5, 0.0, 5.0), Vec3::NEG_Z),
            0.0,
            f32::INFINITY
        )
        .is_none()
    );
}

#[test]
fn normal_transform_mode_applies_to_csg_surfaces() {
    let sheared = format!(
        "Transform {{ Matrix {{ 1 0.7 0 0  0 1 0 0  0 0 1 0  0 0 0 1 }} Scale 1 0.5 1 {} }}",
        csg("Subtraction", A, B)
    );
    let s = scene(&sheared);
    let at = |mode| {
        render_frame(
            &compile(&s),
            &RenderSettings {
                normal_transform: mode,
                ..RenderSettings::new(64, 48)
            },
        )
    };
    let (correct, incorrect) = (at(NormalTransform::Correct), at(NormalTransform::Incorrect));
    assert!(hits(&correct) > 300);
    // Same geometry, different normals.
    assert!(
        correct
            .samples
            .iter()
            .zip(&incorrect.samples)
            .all(|(x, y)| x.t.to_bits() == y.t.to_bits())
    );
    let differing = correct
        .samples
        .iter()
        .zip(&incorrect.samples)
        .filter(|(x, y)| x.normal != y.normal)
        .count();
    assert!(differing > 100, "only {differing} normals differ");
    // A similitude (rotation, uniform scale) changes nothing.
    let similar = scene(&format!(
        "Transform {{ ZRotate 30 UniformScale 1.5 {} }}",
        csg("Subtraction", A, B)
    ));
    let at = |mode| {
        render_frame(
            &compile(&similar),
            &RenderSettings {
                normal_transform: mode,
                ..RenderSettings::new(64, 48)
            },
        )
    };
    let (a, b) = (at(NormalTransform::Correct), at(NormalTransform::Incorrect));
    let worst = a
        .samples
        .iter()
        .zip(&b.samples)
        .flat_map(|(x, y)| (0..3).map(move |c| x.normal[c].abs_diff(y.normal[c])))
        .max();
    assert!(
        worst.unwrap_or(0) <= 1,
        "similitudes must not change normals ({worst:?})"
    );
}

#[test]
fn coincident_faces_give_one_consistent_surface() {
    // A and B touch along the plane x = 0 and share their front face z = 1.
    let a = "MaterialIndex 0 Box { min -1 -1 -1 max 0 1 1 }";
    let b = "MaterialIndex 1 Box { min 0 -1 -1 max 1 1 1 }";
    let (_, u) = tree(&csg("Union", a, b));
    // No seam where the boxes meet: one interval through both.
    assert_close(
        &ts(&u.intervals(&Ray::new(Vec3::new(-5.0, 0.3, 0.2), Vec3::X))),
        &[4.0, 6.0],
    );
    // The same box twice: its front face is one boundary, A's.
    let (c, _) = tree(&csg("Union", a, a));
    let h = c
        .intersect(
            &Ray::new(Vec3::new(-0.5, 0.0, 5.0), Vec3::NEG_Z),
            0.0,
            f32::INFINITY,
        )
        .expect("hit");
    assert_eq!(c.hit_material(&h), 0);

    // A box minus a slab sharing its front face: that face is gone at every pixel, and what
    // shows is the slab's back face turned around, at z = 0.5, in the slab's material.
    let cut = csg(
        "Subtraction",
        "MaterialIndex 0 Box { min -1 -1 -1 max 1 1 1 }",
        "MaterialIndex 1 Box { min -1 -1 0.5 max 1 1 1 }",
    );
    let (c, _) = tree(&cut);
    let front = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::NEG_Z);
    let h = c.intersect(&front, 0.0, f32::INFINITY).expect("hit");
    assert!((h.t - 4.5).abs() < 1e-6, "{}", h.t);
    assert_eq!(
        (
            c.hit_material(&h),
            c.world_normal(&front, &h, NormalTransform::Correct)
        ),
        (1, Vec3::Z)
    );
    let mut seen = 0;
    for row in 0..40 {
        for x in 0..48 {
            let ray = c.camera.pixel_ray(x, row, 48, 40);
            if let Some(h) = c.intersect(&ray, c.camera.t_min(), f32::INFINITY) {
                seen += 1;
                let n = c.world_normal(&ray, &h, NormalTransform::Correct);
                assert!(
                    n.dot(ray.direction) < 0.0,
                    "pixel {x},{row} shows a back face"
                );
            }
        }
    }
    assert!(seen > 200);
}
