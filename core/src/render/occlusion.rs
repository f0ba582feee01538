//! Shadow rays: is anything hit between two points? pbrt's second query, which may stop at
//! the first blocker instead of searching for the closest. The answer is exactly
//! `intersect(..).is_some()`, bit for bit: each step is the closest-hit path's own
//! arithmetic, cut short.

use super::compile::{CompiledScene, Object, Shape};
use crate::geometry::Ray;
use crate::scene::Mesh;

impl CompiledScene {
    /// Whether anything is hit with t in (t_min, t_max): `intersect(ray, t_min, t_max)
    /// .is_some()`, returning at the first hit found.
    pub fn occluded(&self, ray: &Ray, t_min: f32, t_max: f32) -> bool {
        // Under `-grid` every query walks the grid (the course's programs do).
        if let Some(g) = &self.grid {
            return self.intersect_grid(g, ray, t_min, t_max).is_some();
        }
        // `intersect` sends a one-mesh scene straight to the mesh, past the top-level box
        // (whose unwidened slab test could differ at the edge): so must this.
        if let Some(i) = self.single_mesh
            && let Some(o) = self.objects.get(i as usize)
            && let Shape::Mesh(m) = &o.shape
        {
            return mesh_occludes(o, m, ray, t_min, t_max);
        }
        // Unbounded objects (planes) first, as `intersect` offers them first; each test
        // gets the full t_max, which is what the closest-hit loop offers until its first hit.
        if self
            .unbounded
            .iter()
            .any(|&i| self.object_occludes(i, ray, t_min, t_max))
        {
            return true;
        }
        self.bvh.any(ray.origin, ray.direction, t_min, t_max, |i| {
            self.object_occludes(i, ray, t_min, t_max)
        })
    }

    /// Whether object `i` is hit in (t_min, t_max): `intersect_object(..).is_some()`.
    #[inline]
    fn object_occludes(&self, i: u32, ray: &Ray, t_min: f32, t_max: f32) -> bool {
        let Some(o) = self.objects.get(i as usize) else {
            return false;
        };
        match &o.shape {
            Shape::Mesh(m) => mesh_occludes(o, m, ray, t_min, t_max),
            // A CSG solid's surface is known only from its operands' intervals along the
            // whole ray, so it has no cheaper any-hit test: the closest hit is the answer.
            // Spheres, planes, triangles and boxes are one closed-form test either way.
            Shape::Csg(_)
            | Shape::Sphere { .. }
            | Shape::Plane { .. }
            | Shape::Triangle { .. }
            | Shape::Box { .. } => self.intersect_object(i, ray, t_min, t_max).is_some(),
        }
    }
}

/// `CompiledScene::mesh_hit(..).is_some()` without the search for the closest: the ray moved
/// to object space by the very operations `mesh_hit` uses, so the mesh sees the same bits.
#[inline]
fn mesh_occludes(o: &Object, m: &Mesh, ray: &Ray, t_min: f32, t_max: f32) -> bool {
    m.accel.any_hit_of(ray, |r| o.object_ray(r), t_min, t_max)
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::format::obj::MeshCache;
    use crate::format::parse_scene;

    fn compiled(objects: &[&str]) -> CompiledScene {
        let text = format!(
            "OrthographicCamera {{ center 0 0 10 direction 0 0 -1 up 0 1 0 size 4 }}
Lights {{ numLights 1 DirectionalLight {{ direction 0 0 -1 color 1 1 1 }} }}
Background {{ color 0 0 0 ambientLight 0.1 0.1 0.1 }}
Materials {{ numMaterials 1 Material {{ diffuseColor 0.9 0.5 0.2 }} }}
Group {{ numObjects {} MaterialIndex 0 {} }}",
            objects.len(),
            objects.join(" ")
        );
        let scene = parse_scene(text.as_bytes(), "t.txt", None, &mut MeshCache::new())
            .into_result()
            .unwrap_or_else(|d| panic!("{d}\n{text}"))
            .0;
        CompiledScene::new(&scene)
    }

    /// Down the z axis from z = 10: the plane z = 1 is at t = 9, the sphere's front at 7.
    const RAY: Ray = Ray {
        origin: Vec3::new(0.0, 0.0, 10.0),
        direction: Vec3::NEG_Z,
    };

    fn agree(c: &CompiledScene, t_max: f32) -> bool {
        let got = c.occluded(&RAY, 1e-4, t_max);
        assert_eq!(
            got,
            c.intersect(&RAY, 1e-4, t_max).is_some(),
            "t_max {t_max}"
        );
        got
    }

    /// A plane is unbounded, so it is never in the BVH: an `occluded` that skipped
    /// `unbounded` would answer false here.
    #[test]
    fn a_plane_alone_occludes_from_its_t_on() {
        let c = compiled(&["Plane { normal 0 0 1 offset 1 }"]);
        assert!(c.bvh.nodes.is_empty() && c.unbounded.len() == 1);
        let t = c.intersect(&RAY, 1e-4, f32::INFINITY).map(|h| h.t);
        assert_eq!(t, Some(9.0));
        assert!(agree(&c, f32::INFINITY));
        assert!(agree(&c, 9f32.next_up()));
        assert!(!agree(&c, 9.0), "t_max is exclusive");
        assert!(!agree(&c, 5.0));
    }

    /// One of each kind on the z axis, nearest first from z = 10: a sphere (z 3..1), a
    /// triangle (z 0), a box (z -2..-3), a CSG solid (z -3.9..-4.5) and a plane (z -5). Rays
    /// start in front of, inside and between them: each kind is the first blocker of some,
    /// and the range cuts each answer exactly at the first hit's t.
    #[test]
    fn each_kind_blocks_from_its_own_t_on() {
        let c = compiled(&[
            "Sphere { center 0 0 2 radius 1 }",
            "Triangle { vertex0 -1 -1 0 vertex1 1 -1 0 vertex2 0 1 0 }",
            "Box { min -1 -1 -3 max 1 1 -2 }",
            "Subtraction { Sphere { center 0 0 -4 radius 0.5 } \
             Sphere { center 0 0 -3.5 radius 0.4 } }",
            "Plane { normal 0 0 1 offset -5 }",
        ]);
        let mut blockers = [0u32; 5];
        for k in 0..60 {
            let ray = Ray::new(Vec3::new(0.0, 0.0, 10.0 - 0.25 * k as f32), Vec3::NEG_Z);
            let Some(hit) = c.intersect(&ray, 1e-4, f32::INFINITY) else {
                panic!("ray {k} from z {} hits nothing", ray.origin.z);
            };
            blockers[hit.object as usize] += 1;
            assert!(c.occluded(&ray, 1e-4, f32::INFINITY), "ray {k}");
            assert!(c.occluded(&ray, 1e-4, hit.t.next_up()), "ray {k}");
            assert!(
                !c.occluded(&ray, 1e-4, hit.t),
                "ray {k}: t_max is exclusive"
            );
            assert!(!c.occluded(&ray, 1e-4, hit.t.next_down()), "ray {k}");
        }
        assert!(
            blockers.iter().all(|&n| n > 0),
            "first blockers {blockers:?}"
        );
        // Beside everything but the plane, which still blocks; pointing away, nothing does.
        let side = Ray::new(Vec3::new(3.0, 3.0, 10.0), Vec3::NEG_Z);
        assert!(c.occluded(&side, 1e-4, 15.0f32.next_up()));
        assert!(!c.occluded(&side, 1e-4, 15.0));
        assert!(!c.occluded(&Ray::new(RAY.origin, Vec3::Z), 1e-4, f32::INFINITY));
    }
}
