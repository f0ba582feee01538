//! The render-ready scene: transforms flattened into one cached matrix set per object (a
//! Transform chain costs one matrix, never an inversion per ray), materials resolved, and a
//! top-level BVH over the bounded objects. Meshes are shared, not copied: each mesh is an
//! instance of its own BVH, entered once per ray in object space.

use std::sync::Arc;

use glam::{DMat4, Vec3, Vec3A};

use super::NormalTransform;
use super::camera::CameraRays;
use super::csg::CsgTree;
use super::texture::CompiledTexture;
use crate::accel::Bvh;
use crate::geometry::{
    Aabb, Ray, Transform, box_face_normal, box_span, intersect_plane, intersect_sphere,
    intersect_triangle, sphere_normal,
};
use crate::memory::{OutOfMemory, try_with_capacity};
use crate::scene::{
    DEFAULT_ATTENUATION, DEFAULT_MATERIAL_COLOR, LightKind, Mesh, NodeId, NodeKind, Phong, Scene,
    Walk, unit, validate::MAX_TEXTURE_DEPTH,
};

/// A point light ready to shade with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLight {
    pub position: Vec3,
    pub color: Vec3,
    /// (constant, linear, quadratic): the colour is divided by c + l·d + q·d².
    pub attenuation: Vec3,
}

/// An object's primitive: the description CSG's leaves share (`shape.rs`), its CSG subtree
/// compiled.
pub type Shape = super::shape::Shape<Arc<CsgTree>>;

#[derive(Clone, Debug)]
pub struct Object {
    pub shape: Shape,
    pub xf: Option<Transform>,
    /// Index into `CompiledScene::materials` (the last entry is the default material).
    pub material: u32,
    pub node: NodeId,
}

impl Object {
    /// A world ray in this object's space, as a mesh's traversal takes it
    /// (`Transform::object_ray`); `mesh_hit` and the shadow rays' `mesh_occludes` both use
    /// it, so a mesh sees the same bits from either.
    #[inline(always)]
    pub(super) fn object_ray(&self, ray: &Ray) -> (Vec3A, Vec3A) {
        match &self.xf {
            Some(xf) => xf.object_ray(ray.origin, ray.direction),
            None => (ray.origin.into(), ray.direction.into()),
        }
    }
}

/// The closest hit of a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// World ray parameter.
    pub t: f32,
    pub object: u32,
    /// Triangle index within a mesh, face of a box, boundary code of a CSG hit (0 otherwise).
    pub prim: u32,
}

#[derive(Clone, Debug)]
pub struct CompiledScene {
    pub camera: CameraRays,
    pub background: Vec3,
    pub ambient: Vec3,
    /// The directional lights: (direction toward the light, normalised; colour).
    pub lights: Vec<(Vec3, Vec3)>,
    /// The point lights (assignment 4), shaded by `whitted.rs` only.
    pub point_lights: Vec<PointLight>,
    /// The scene's index of each light of `lights`, then of each of `point_lights`.
    light_indices: Vec<usize>,
    /// Each material's diffuse colour (the last entry is the default material).
    pub materials: Vec<Vec3>,
    /// Each material's Phong terms, parallel to `materials`.
    pub phong: Vec<Phong>,
    /// Each material's solid texture, parallel to `materials` (whose entry for a texture is
    /// unused): a hit on one shades with its two materials (`shading_at`).
    pub textures: Vec<Option<CompiledTexture>>,
    /// Some material has a highlight, a mirror or glass, or is a texture: colour needs
    /// `whitted.rs`.
    pub(super) has_phong_terms: bool,
    pub objects: Vec<Object>,
    pub(super) bvh: Bvh,
    /// Objects with no finite bounds (planes), tested for every ray.
    pub(super) unbounded: Vec<u32>,
    /// The course's uniform grid, when `-grid` asks for it: then every ray goes through it
    /// instead of `bvh` (`grid_scene.rs`).
    pub(super) grid: Option<Arc<super::grid_data::GridScene>>,
    /// The one object of a scene that holds a single mesh and nothing else: rays go straight
    /// to it, since the mesh tests its own box first (in object space, needing no second
    /// reciprocal of the direction).
    pub(super) single_mesh: Option<u32>,
}

impl CompiledScene {
    /// The scene compiled for rendering; where it does not fit in memory, ends the process as
    /// a failed allocation does (see [`CompiledScene::try_new`] for an error instead).
    pub fn new(scene: &Scene) -> Self {
        match Self::try_new(scene) {
            Ok(compiled) => compiled,
            Err(e) => crate::memory::fail_as_infallible(e),
        }
    }

    /// [`CompiledScene::new`], with an error instead of an abort where its big arrays (one
    /// entry per object, and the BVH) do not fit in memory.
    pub fn try_new(scene: &Scene) -> Result<Self, OutOfMemory> {
        let mut materials: Vec<Vec3> = scene.materials.iter().map(|m| m.diffuse).collect();
        let default_material = materials.len() as u32;
        materials.push(DEFAULT_MATERIAL_COLOR);
        let n_mat = scene.materials.len() as u32;

        let g = &scene.graph;
        // Every object node at most once (a CSG's operands are one object with it): reserved
        // whole, since grown by doubling the array would at its last step need 1.5 times it.
        let most = g
            .iter()
            .filter(|(_, n)| !matches!(n.kind, NodeKind::Group | NodeKind::Transform(_)))
            .count();
        let mut objects: Vec<Object> = try_with_capacity(most, "the scene's objects")?;
        let mut walk = Walk::new(g);
        while let Some(v) = walk.next() {
            let (id, m, material) = (v.id, v.world_from_object, v.material);
            let shape = match &v.node.kind {
                NodeKind::Csg(_) => {
                    // One object for the whole subtree: its leaves keep their own transforms
                    // and materials, and its bounds go into the top-level BVH.
                    walk.skip_children();
                    let resolve =
                        |m: Option<u32>| m.filter(|&i| i < n_mat).unwrap_or(default_material);
                    let tree = CsgTree::build(g, id, m, material, &resolve);
                    objects.push(Object {
                        shape: Shape::Csg(Arc::new(tree)),
                        xf: None,
                        material: resolve(material),
                        node: id,
                    });
                    continue;
                }
                // Groups and Transforms are walked through; an unloaded mesh shows nothing.
                kind => match Shape::of_node(kind) {
                    Some(shape) => shape,
                    None => continue,
                },
            };
            let xf = (m != DMat4::IDENTITY).then(|| Transform::from_f64(m));
            let material = material.filter(|&i| i < n_mat).unwrap_or(default_material);
            objects.push(Object {
                shape,
                xf,
                material,
                node: id,
            });
        }

        let mut bounded_boxes = try_with_capacity(objects.len(), "the objects' bounds")?;
        let mut bounded_ids = try_with_capacity(objects.len(), "the objects' bounds")?;
        let mut unbounded = Vec::new();
        for (i, o) in objects.iter().enumerate() {
            let b = object_bounds(o);
            if b.is_finite() && !b.is_empty() {
                bounded_boxes.push(b);
                bounded_ids.push(i as u32);
            } else if !b.is_empty() {
                unbounded.push(i as u32);
            }
        }
        let mut bvh = Bvh::try_build(&bounded_boxes)?;
        // The BVH indexes `bounded_boxes`; point it at object ids instead.
        for p in &mut bvh.indices {
            *p = bounded_ids[*p as usize];
        }

        let single_mesh = match (bvh.indices.as_slice(), unbounded.is_empty()) {
            (&[i], true) => matches!(objects[i as usize].shape, Shape::Mesh(_)).then_some(i),
            _ => None,
        };

        let mut lights = Vec::new();
        let mut point_lights = Vec::new();
        let (mut directional_at, mut point_at) = (Vec::new(), Vec::new());
        for (i, l) in scene.lights().iter().enumerate() {
            match l.kind {
                LightKind::Directional { direction } => {
                    directional_at.push(i);
                    lights.push((-unit(direction).unwrap_or(Vec3::NEG_Z), l.color))
                }
                LightKind::Point {
                    position,
                    attenuation,
                } => {
                    point_at.push(i);
                    point_lights.push(PointLight {
                        position,
                        color: l.color,
                        attenuation: attenuation.unwrap_or(DEFAULT_ATTENUATION),
                    })
                }
            }
        }
        directional_at.extend(point_at);
        let light_indices = directional_at;
        let mut phong: Vec<Phong> = scene.materials.iter().map(|m| m.phong()).collect();
        phong.push(Phong::default());
        let mut textures: Vec<Option<CompiledTexture>> = scene
            .materials
            .iter()
            .map(|m| m.texture.as_ref().map(CompiledTexture::new))
            .collect();
        textures.push(None);
        let has_phong_terms =
            phong.iter().any(|p| !p.is_diffuse_only()) || textures.iter().any(Option::is_some);
        Ok(CompiledScene {
            camera: CameraRays::new(&scene.camera),
            background: scene.background_color(),
            ambient: scene.effective_ambient(),
            lights,
            point_lights,
            light_indices,
            materials,
            phong,
            textures,
            has_phong_terms,
            objects,
            bvh,
            unbounded,
            grid: None,
            single_mesh,
        })
    }

    /// The closest hit with t in (t_min, t_max).
    ///
    /// Inlined into the caller's pixel loop together with `mesh_hit`, so a one-mesh scene's
    /// ray goes from the registers it was made in to object space without a trip through
    /// memory, where each hop was a failed store forward (docs/perf.md). Always: with
    /// `#[inline]` LLVM kept it a call from `tracelab bench`'s loop, whose frame set-up and
    /// return each ray paid after its walk's last, mispredicted branch (single rays 1.5-11%
    /// slower on Zen 5, docs/perf.md).
    #[inline(always)]
    pub fn intersect(&self, ray: &Ray, t_min: f32, t_max: f32) -> Option<Hit> {
        if let Some(g) = &self.grid {
            return self.intersect_grid(g, ray, t_min, t_max);
        }
        if let Some(i) = self.single_mesh
            && let Some(o) = self.objects.get(i as usize)
            && let Shape::Mesh(m) = &o.shape
        {
            return Self::mesh_hit(o, m, ray, t_min, t_max).map(|(t, prim)| Hit {
                t,
                object: i,
                prim,
            });
        }
        self.intersect_scene(ray, t_min, t_max)
    }

    /// `intersect` for eight rays at once, for those whose bit is set in `active` (the others
    /// get None), each with the hit `intersect` gives it: a one-mesh scene traces them as one
    /// packet (`TriangleBvh::closest_hit8`, the same t bit for bit), any other scene walks the
    /// top-level BVH once for the eight (`Bvh::traverse8`), meshes among its objects taking
    /// the lanes that reach them as a packet and other shapes one ray at a time.
    #[inline]
    pub fn intersect8(
        &self,
        rays: &[Ray; 8],
        active: u8,
        t_min: f32,
        t_max: f32,
    ) -> [Option<Hit>; 8] {
        self.intersect8_with(rays, active, t_min, t_max, false)
    }

    /// `intersect8`; with `sparse` (a coarse pass's samples), a one-mesh scene's packet goes
    /// one ray at a time once it proves incoherent (`TriangleBvh::closest_hit8_with`). The
    /// same hits either way.
    #[inline(always)]
    pub fn intersect8_with(
        &self,
        rays: &[Ray; 8],
        active: u8,
        t_min: f32,
        t_max: f32,
        sparse: bool,
    ) -> [Option<Hit>; 8] {
        if self.grid.is_some() {
            // The grid walks one ray at a time.
            return std::array::from_fn(|k| {
                (active & (1 << k) != 0)
                    .then(|| self.intersect(&rays[k], t_min, t_max))
                    .flatten()
            });
        }
        if let Some(i) = self.single_mesh
            && let Some(o) = self.objects.get(i as usize)
            && let Shape::Mesh(m) = &o.shape
        {
            let (org, dir) = Self::object_rays8(o, rays);
            let mut t = [t_max; 8];
            let hits = m
                .accel
                .closest_hit8_with(&org, &dir, active, t_min, &mut t, sparse);
            return hits.map(|h| {
                h.map(|h| Hit {
                    t: h.t,
                    object: i,
                    prim: h.triangle,
                })
            });
        }
        self.intersect_scene8(rays, active, t_min, t_max)
    }

    /// Eight rays in a mesh instance's object space, the bits of `mesh_hit`'s (`Mat4` here,
    /// `Object::object_ray`'s `Affine3A` there: the same operations, a test in
    /// `geometry::transform` compares them).
    #[inline(always)]
    fn object_rays8(o: &Object, rays: &[Ray; 8]) -> ([Vec3A; 8], [Vec3A; 8]) {
        match &o.xf {
            // Direction deliberately not renormalised, as in `mesh_hit`.
            Some(xf) => {
                let m = &xf.object_from_world;
                // A perspective camera's rays share one origin: moved once, the same bits.
                let origin = rays[0].origin;
                let org = if rays.iter().all(|r| {
                    r.origin.to_array().map(f32::to_bits) == origin.to_array().map(f32::to_bits)
                }) {
                    [m.transform_point3(origin).into(); 8]
                } else {
                    std::array::from_fn(|k| m.transform_point3(rays[k].origin).into())
                };
                (
                    org,
                    std::array::from_fn(|k| m.transform_vector3(rays[k].direction).into()),
                )
            }
            None => (
                std::array::from_fn(|k| rays[k].origin.into()),
                std::array::from_fn(|k| rays[k].direction.into()),
            ),
        }
    }

    #[inline(never)]
    fn intersect_scene8(
        &self,
        rays: &[Ray; 8],
        active: u8,
        t_min: f32,
        t_max: f32,
    ) -> [Option<Hit>; 8] {
        let mut best: [Option<Hit>; 8] = [None; 8];
        let mut t = [t_max; 8];
        for &i in &self.unbounded {
            for k in lanes(active) {
                self.offer(i, &rays[k], t_min, &mut t[k], &mut best[k]);
            }
        }
        let org: [Vec3A; 8] = std::array::from_fn(|k| rays[k].origin.into());
        let dir: [Vec3A; 8] = std::array::from_fn(|k| rays[k].direction.into());
        self.bvh
            .traverse8(&org, &dir, active, t_min, &mut t, |i, reach, t| {
                let Some(o) = self.objects.get(i as usize) else {
                    return;
                };
                if let Shape::Mesh(m) = &o.shape
                    && reach.count_ones() > 1
                {
                    let (org, dir) = Self::object_rays8(o, rays);
                    let mut bound: [f32; 8] =
                        std::array::from_fn(|k| tie_bound(i, t[k], best[k].as_ref()));
                    let hits = m.accel.closest_hit8(&org, &dir, reach, t_min, &mut bound);
                    for k in lanes(reach) {
                        if let Some(h) = hits[k] {
                            t[k] = h.t;
                            best[k] = Some(Hit {
                                t: h.t,
                                object: i,
                                prim: h.triangle,
                            });
                        }
                    }
                } else {
                    for k in lanes(reach) {
                        self.offer(i, &rays[k], t_min, &mut t[k], &mut best[k]);
                    }
                }
            });
        best
    }

    /// Offers object `i` to a ray whose closest hit so far is `best` at `t_best`: it takes
    /// over if it is nearer, or as near with a lower index (`tie_bound`).
    #[inline]
    fn offer(&self, i: u32, ray: &Ray, t_min: f32, t_best: &mut f32, best: &mut Option<Hit>) {
        if let Some((t, prim)) =
            self.intersect_object(i, ray, t_min, tie_bound(i, *t_best, best.as_ref()))
        {
            *t_best = t;
            *best = Some(Hit { t, object: i, prim });
        }
    }

    /// A mesh instance's closest hit: the ray to object space, then the mesh BVH, the move
    /// compiled into the BVH's walk (`TriangleBvh::closest_hit_of`).
    #[inline(always)]
    fn mesh_hit(o: &Object, m: &Mesh, ray: &Ray, t_min: f32, t_max: f32) -> Option<(f32, u32)> {
        m.accel
            .closest_hit_of(ray, |r| o.object_ray(r), t_min, t_max)
            .map(|h| (h.t, h.triangle))
    }

    #[inline(never)]
    fn intersect_scene(&self, ray: &Ray, t_min: f32, t_max: f32) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        let mut t_best = t_max;
        for &i in &self.unbounded {
            self.offer(i, ray, t_min, &mut t_best, &mut best);
        }
        self.bvh
            .traverse(ray.origin, ray.direction, t_min, t_best, |i, t_max| {
                let (t, prim) =
                    self.intersect_object(i, ray, t_min, tie_bound(i, t_max, best.as_ref()))?;
                best = Some(Hit { t, object: i, prim });
                Some(t)
            });
        best
    }

    /// One object's closest hit: (t, triangle index).
    #[inline]
    pub fn intersect_object(
        &self,
        i: u32,
        ray: &Ray,
        t_min: f32,
        t_max: f32,
    ) -> Option<(f32, u32)> {
        let o = self.objects.get(i as usize)?;
        if let Shape::Mesh(m) = &o.shape {
            return Self::mesh_hit(o, m, ray, t_min, t_max);
        }
        let local;
        let r = match &o.xf {
            // Direction deliberately not renormalised: t is the same in both spaces.
            Some(xf) => {
                local = ray.transformed(&xf.object_from_world);
                &local
            }
            None => ray,
        };
        shape_hit(&o.shape, r, t_min, t_max)
    }

    /// The object-space normal at a hit (not normalised for spheres' scale; unit otherwise).
    pub fn object_normal(&self, ray: &Ray, hit: &Hit) -> Vec3 {
        let Some(o) = self.objects.get(hit.object as usize) else {
            return Vec3::Z;
        };
        match &o.shape {
            Shape::Sphere { center, .. } => {
                let r = match &o.xf {
                    Some(xf) => ray.transformed(&xf.object_from_world),
                    None => *ray,
                };
                sphere_normal(*center, r.at(hit.t))
            }
            Shape::Plane { normal, .. } => *normal,
            Shape::Triangle { normal, .. } => *normal,
            Shape::Mesh(m) => m.face_normal(hit.prim),
            Shape::Box { .. } => box_face_normal(hit.prim),
            // In the space of the operand hit: CSG leaves have their own transforms.
            Shape::Csg(tree) => tree.object_normal(ray, hit.t, hit.prim),
        }
    }

    /// The world normal at a hit, normalised, by the chosen rule.
    pub fn world_normal(&self, ray: &Ray, hit: &Hit, mode: NormalTransform) -> Vec3 {
        if let Some(Shape::Csg(tree)) = self.objects.get(hit.object as usize).map(|o| &o.shape) {
            return tree.world_normal(ray, hit.t, hit.prim, mode);
        }
        let n = self.object_normal(ray, hit);
        mode.apply(
            self.objects
                .get(hit.object as usize)
                .and_then(|o| o.xf.as_ref()),
            n,
        )
    }

    /// Object `i`'s box in world space (infinite for a plane, empty for none).
    pub fn object_world_bounds(&self, i: u32) -> Aabb {
        self.objects
            .get(i as usize)
            .map_or(Aabb::EMPTY, object_bounds)
    }

    pub fn object_count(&self) -> usize {
        self.objects.len()
    }

    /// The material index a hit shades with: a CSG surface keeps its operand's material.
    pub fn hit_material(&self, hit: &Hit) -> u32 {
        match self.objects.get(hit.object as usize) {
            Some(Object {
                shape: Shape::Csg(tree),
                ..
            }) => tree
                .leaf(hit.prim)
                .map_or(self.default_material(), |l| l.material),
            Some(o) => o.material,
            None => self.default_material(),
        }
    }

    /// The scene's index (in its Lights block) of light `k` of `lights` then `point_lights`.
    pub fn light_index(&self, k: usize) -> usize {
        self.light_indices.get(k).copied().unwrap_or(k)
    }

    /// The Phong terms of the material `hit_material` names.
    pub fn hit_phong(&self, hit: &Hit) -> Phong {
        self.phong
            .get(self.hit_material(hit) as usize)
            .copied()
            .unwrap_or_default()
    }

    /// The diffuse colour and Phong terms at world point `p` of a hit: its material's own,
    /// or for a solid texture the material (Checkerboard) or blend (Noise, Marble, Wood) of
    /// its two that the texture gives at `p`.
    pub fn hit_shading(&self, hit: &Hit, p: Vec3) -> (Vec3, Phong) {
        self.shading_at(self.hit_material(hit), p, 0)
    }

    fn shading_at(&self, material: u32, p: Vec3, depth: usize) -> (Vec3, Phong) {
        let i = material as usize;
        let own = || {
            let kd = self
                .materials
                .get(i)
                .copied()
                .unwrap_or(DEFAULT_MATERIAL_COLOR);
            (kd, self.phong.get(i).copied().unwrap_or_default())
        };
        let Some(t) = self.textures.get(i).and_then(Option::as_ref) else {
            return own();
        };
        // The rules bound the nesting; a scene compiled unchecked still ends here.
        if depth > MAX_TEXTURE_DEPTH {
            return (DEFAULT_MATERIAL_COLOR, Phong::default());
        }
        let [a, b] = t.materials;
        let w = t.weight(p);
        if w <= 0.0 {
            return self.shading_at(a, p, depth + 1);
        }
        if w >= 1.0 {
            return self.shading_at(b, p, depth + 1);
        }
        let (ka, pa) = self.shading_at(a, p, depth + 1);
        let (kb, pb) = self.shading_at(b, p, depth + 1);
        (ka.lerp(kb, w), pa.lerp(&pb, w))
    }

    /// The colour `hit_material` names.
    pub fn hit_color(&self, hit: &Hit) -> Vec3 {
        self.materials
            .get(self.hit_material(hit) as usize)
            .copied()
            .unwrap_or(DEFAULT_MATERIAL_COLOR)
    }

    /// The scene node a hit belongs to: for a CSG surface, the operand it came from, so the
    /// pixel inspector and click-to-select find the Sphere or Box, not the Union.
    pub fn hit_node(&self, hit: &Hit) -> Option<NodeId> {
        match self.objects.get(hit.object as usize) {
            Some(Object {
                shape: Shape::Csg(tree),
                node,
                ..
            }) => Some(tree.leaf(hit.prim).map_or(*node, |l| l.node)),
            Some(o) => Some(o.node),
            None => None,
        }
    }

    fn default_material(&self) -> u32 {
        self.materials.len().saturating_sub(1) as u32
    }

    pub fn material_color(&self, object: u32) -> Vec3 {
        self.objects
            .get(object as usize)
            .and_then(|o| self.materials.get(o.material as usize))
            .copied()
            .unwrap_or(DEFAULT_MATERIAL_COLOR)
    }
}

/// A shape's closest hit for a ray already in its own space: (t along that ray, prim).
#[inline(always)]
pub(super) fn shape_hit(shape: &Shape, r: &Ray, t_min: f32, t_max: f32) -> Option<(f32, u32)> {
    match shape {
        Shape::Sphere { center, radius } => {
            intersect_sphere(r, *center, *radius, t_min, t_max).map(|t| (t, 0))
        }
        Shape::Plane { normal, offset } => {
            intersect_plane(r, *normal, *offset, t_min, t_max).map(|t| (t, 0))
        }
        Shape::Triangle {
            vertices: [a, b, c],
            ..
        } => intersect_triangle(r, *a, *b, *c, t_min, t_max).map(|(t, _, _)| (t, 0)),
        Shape::Mesh(m) => m
            .accel
            .closest_hit(
                Vec3A::from(r.origin),
                Vec3A::from(r.direction),
                t_min,
                t_max,
            )
            .map(|h| (h.t, h.triangle)),
        Shape::Box { min, max } => {
            let (t0, f0, t1, f1) = box_span(r, *min, *max)?;
            if t0 > t_min && t0 < t_max {
                Some((t0, f0))
            } else {
                (t1 > t_min && t1 < t_max).then_some((t1, f1))
            }
        }
        Shape::Csg(tree) => tree.intersect(r, t_min, t_max),
    }
}

/// The t bound to test object `i` with when the nearest hit so far is `best` at `t_best`: one
/// ulp past `t_best` when `i` comes before `best`'s object, so that of two hits at the very
/// same t the lower object index wins, as in the course's Group loop. The rule depends on
/// neither traversal order nor packet grouping, which is what keeps single rays and packets
/// on the same hit.
#[inline(always)]
pub(super) fn tie_bound(i: u32, t_best: f32, best: Option<&Hit>) -> f32 {
    if best.is_some_and(|b| i < b.object) {
        t_best.next_up()
    } else {
        t_best
    }
}

/// The lanes whose bit is set in `mask`.
#[inline(always)]
fn lanes(mask: u8) -> impl Iterator<Item = usize> {
    (0..8).filter(move |k| mask & (1 << k) != 0)
}

fn object_bounds(o: &Object) -> Aabb {
    let local = match &o.shape {
        // Already in world space (the object has no transform of its own).
        Shape::Csg(tree) => return tree.bounds(),
        shape => shape.local_bounds().unwrap_or(Aabb::EMPTY),
    };
    o.xf.as_ref().map_or(local, |xf| xf.world_bounds(local))
}
