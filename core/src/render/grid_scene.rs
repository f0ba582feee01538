//! The course's uniform grid in place of the objects' BVH (`-grid NX NY NZ`, assignments
//! 5–6): every bounded object by its world box and, as the handout asks, every triangle of a
//! mesh by its own world box; planes stay outside and are tested for every ray. A ray walks
//! the cells by 3D-DDA and tests what each holds, each test exactly as the BVH path makes it
//! (the same object-space ray, the same triangle arithmetic, the same tie rule), so the grid
//! finds the BVH's closest hit bit for bit. It also counts, for `-stats`.

use std::sync::Arc;

use glam::{UVec3, Vec3};

use super::compile::{CompiledScene, Hit, Shape, tie_bound};
use super::grid_data::{GridScene, RayCounts, WHOLE};
use crate::accel::{CellVisit, MAX_CELLS, MAX_ENTRIES, UniformGrid};
use crate::geometry::{Aabb, Ray, moller_trumbore};

/// The cells one ray walks through, nearest first, and the closest hit it found
/// ([`CompiledScene::grid_walk`]).
#[derive(Clone, Debug, PartialEq)]
pub struct GridWalk {
    pub cells: Vec<CellVisit>,
    pub hit: Option<Hit>,
}

/// Why a grid could not be built.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum GridError {
    #[error("-grid: each count must be 1 or more, found {0} {1} {2}")]
    Zero(u32, u32, u32),
    #[error("-grid: {0} {1} {2} is {3} cells; at most {MAX_CELLS} are allowed")]
    TooMany(u32, u32, u32, u64),
    #[error(
        "-grid: {0} {1} {2} would list this scene's objects in up to {3} cells in all; at most \
         {MAX_ENTRIES} are allowed (fewer cells, or smaller triangles)"
    )]
    TooManyEntries(u32, u32, u32, u64),
}

impl CompiledScene {
    /// Replaces the objects' BVH with a uniform grid of `cells` over the bounded objects'
    /// world box, for every ray from now on.
    pub fn use_grid(&mut self, cells: UVec3) -> Result<(), GridError> {
        let (x, y, z) = (cells.x, cells.y, cells.z);
        if x == 0 || y == 0 || z == 0 {
            return Err(GridError::Zero(x, y, z));
        }
        let n = u64::from(x) * u64::from(y) * u64::from(z);
        if n > MAX_CELLS {
            return Err(GridError::TooMany(x, y, z, n));
        }
        let mut boxes = Vec::new();
        let mut items = Vec::new();
        for &i in &self.bvh.indices {
            let Some(o) = self.objects.get(i as usize) else {
                continue;
            };
            match (&o.shape, &o.xf) {
                (Shape::Mesh(m), xf) => {
                    for k in 0..m.triangle_count() as u32 {
                        let local = Aabb::from_points(&m.triangle(k));
                        boxes.push(xf.as_ref().map_or(local, |xf| xf.world_bounds(local)));
                        items.push((i, k));
                    }
                }
                _ => {
                    boxes.push(self.object_world_bounds(i));
                    items.push((i, WHOLE));
                }
            }
        }
        let bounds = boxes
            .iter()
            .filter(|b| b.is_finite() && !b.is_empty())
            .fold(Aabb::EMPTY, |a, b| a.union(*b));
        // Before any allocation: big triangles in a fine grid multiply.
        let most = UniformGrid::entries_bound(bounds, cells, &boxes);
        if most > MAX_ENTRIES {
            return Err(GridError::TooManyEntries(x, y, z, most));
        }
        // A sphere with no transform of its own takes only the cells it reaches, as the
        // handout's pictures show it (a box's corners are empty); a cell the sphere touches
        // within rounding is kept, so no hit is lost.
        let spheres: Vec<Option<(Vec3, f32)>> = items
            .iter()
            .map(|&(i, k)| match self.objects.get(i as usize) {
                Some(o) if k == WHOLE && o.xf.is_none() => match o.shape {
                    Shape::Sphere { center, radius } => Some((center, radius)),
                    _ => None,
                },
                _ => None,
            })
            .collect();
        let grid = UniformGrid::build_with(bounds, cells, &boxes, |e, cell| match spheres[e] {
            Some((c, r)) => {
                let nearest = c.clamp(cell.min, cell.max);
                nearest.distance(c) <= r * (1.0 + 1e-4) + 1e-6
            }
            None => true,
        });
        self.grid = Some(Arc::new(GridScene {
            grid,
            items,
            stats: RayCounts::default(),
        }));
        Ok(())
    }

    /// The grid in use, if `-grid` asked for one.
    pub fn grid(&self) -> Option<&GridScene> {
        self.grid.as_deref()
    }

    /// `intersect` through the grid: planes first, then the cells along the ray, stopping
    /// once the nearest hit so far lies in the cell being left.
    pub(super) fn intersect_grid(
        &self,
        g: &GridScene,
        ray: &Ray,
        t_min: f32,
        t_max: f32,
    ) -> Option<Hit> {
        let (mut cells, mut tests) = (0u64, 0u64);
        let best = self.walk_grid(g, ray, t_min, t_max, |_, n| {
            cells += 1;
            tests += n as u64;
        });
        RayCounts::add(&g.stats.cells_traversed, cells);
        RayCounts::add(
            &g.stats.intersection_tests,
            tests + self.unbounded.len() as u64,
        );
        best
    }

    /// The one grid traversal behind [`Self::intersect_grid`] and [`Self::grid_walk`]: planes
    /// first, then the cells along the ray in DDA order, `on_cell(visit, entries tested)` for
    /// each, stopping once the nearest hit so far lies in the cell being left.
    fn walk_grid(
        &self,
        g: &GridScene,
        ray: &Ray,
        t_min: f32,
        t_max: f32,
        mut on_cell: impl FnMut(&CellVisit, usize),
    ) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        let mut t_best = t_max;
        for &i in &self.unbounded {
            self.offer_item(i, WHOLE, ray, t_min, &mut t_best, &mut best);
        }
        // Past a plane's hit no cell can hold a nearer one: the walk stops there.
        g.grid
            .walk(ray.origin, ray.direction, t_min, t_best, |v: &CellVisit| {
                let mut tested = 0;
                for &e in g.grid.entries(v.cell) {
                    if let Some(&(i, k)) = g.items.get(e as usize) {
                        tested += 1;
                        self.offer_item(i, k, ray, t_min, &mut t_best, &mut best);
                    }
                }
                on_cell(v, tested);
                // An object may reach past this cell: its hit counts only once no later
                // cell can hold a nearer one.
                !(best.is_some() && t_best <= v.t_exit)
            });
        best
    }

    /// The cells a ray walks through in the grid, in DDA order, up to and including the
    /// cell holding its closest hit (all the way through the grid when it hits nothing
    /// there), with that hit: what `intersect` does for this ray, listed (the editor's Ray
    /// panel draws it). `None` without a grid. The `-stats` counters are left alone.
    pub fn grid_walk(&self, ray: &Ray, t_min: f32, t_max: f32) -> Option<GridWalk> {
        let g = self.grid()?;
        let mut cells = Vec::new();
        let hit = self.walk_grid(g, ray, t_min, t_max, |v, _| cells.push(*v));
        Some(GridWalk { cells, hit })
    }

    /// Offers object `i` (or its triangle `k`) to a ray, as `offer` does for the BVH.
    fn offer_item(
        &self,
        i: u32,
        k: u32,
        ray: &Ray,
        t_min: f32,
        t_best: &mut f32,
        best: &mut Option<Hit>,
    ) {
        let bound = tie_bound(i, *t_best, best.as_ref());
        let hit = if k == WHOLE {
            self.intersect_object(i, ray, t_min, bound)
        } else {
            self.mesh_triangle_hit(i, k, ray, t_min, bound)
        };
        if let Some((t, prim)) = hit {
            *t_best = t;
            *best = Some(Hit { t, object: i, prim });
        }
    }

    /// Triangle `k` of mesh object `i`: the ray moved to object space as `mesh_hit` moves
    /// it, and the mesh BVH's own test (v0 and the edges from it, Möller–Trumbore).
    fn mesh_triangle_hit(
        &self,
        i: u32,
        k: u32,
        ray: &Ray,
        t_min: f32,
        t_max: f32,
    ) -> Option<(f32, u32)> {
        let o = self.objects.get(i as usize)?;
        let Shape::Mesh(m) = &o.shape else {
            return None;
        };
        let (org, dir) = match &o.xf {
            Some(xf) => (
                xf.object_from_world.transform_point3(ray.origin),
                xf.object_from_world.transform_vector3(ray.direction),
            ),
            None => (ray.origin, ray.direction),
        };
        if !(org.is_finite() && dir.is_finite()) {
            return None;
        }
        let [a, b, c] = m.triangle(k);
        let (t, _, _) = moller_trumbore(org, dir, a, b - a, c - a)?;
        (t > t_min && t < t_max).then_some((t, k))
    }

    /// The cell a primary ray enters first among those holding anything, with the face it
    /// entered by and how many entries the cell holds: `-visualize_grid`'s picture.
    pub fn first_occupied_cell(&self, ray: &Ray) -> Option<(CellVisit, usize)> {
        let g = self.grid()?;
        let mut found = None;
        g.grid.walk(
            ray.origin,
            ray.direction,
            self.camera.t_min(),
            f32::INFINITY,
            |v| {
                let n = g.grid.entries(v.cell).len();
                if n > 0 {
                    found = Some((*v, n));
                }
                found.is_none()
            },
        );
        found
    }
}

/// `-visualize_grid`'s colour for a cell holding `n` entries, entered by the face whose
/// outward normal is `normal`, seen along `d` (unit): pale yellow for one entry to deep red
/// for 16 or more (log scale), shaded by the face's angle to the eye so the cells read as
/// boxes.
pub fn grid_cell_color(n: usize, normal: Vec3, d: Vec3) -> Vec3 {
    let x = ((n.max(1) as f32).log2() / 4.0).clamp(0.0, 1.0);
    // Pale yellow (one entry) to deep red (16 or more): apart from the usual backgrounds.
    let ramp = Vec3::new(1.0, 0.95, 0.65).lerp(Vec3::new(0.85, 0.1, 0.1), x);
    let shade = 0.4 + 0.6 * normal.dot(-d).abs();
    ramp * shade
}

/// `-visualize_grid`: each pixel shows the first occupied cell its eye ray enters, coloured
/// by how many entries the cell holds and shaded by the face it entered by
/// ([`grid_cell_color`]); the background where the ray meets no occupied cell. The normal
/// view holds that face's normal, the depth view the t where the ray enters the cell.
pub fn visualize_grid(scene: &CompiledScene, width: u32, height: u32) -> super::Frame {
    use rayon::prelude::*;
    let mut frame = super::Frame::new(width, height);
    let background = super::frame::Sample {
        color: scene.background.to_array().map(super::quantize),
        ..super::frame::Sample::UNSET
    };
    frame
        .samples
        .par_chunks_mut(width.max(1) as usize)
        .enumerate()
        .for_each(|(row, line)| {
            for (x, s) in line.iter_mut().enumerate() {
                let ray = scene.camera.pixel_ray(x as u32, row as u32, width, height);
                *s = match scene.first_occupied_cell(&ray) {
                    None => background,
                    Some((v, n)) => {
                        let mut normal = Vec3::ZERO;
                        if let Some((axis, sign)) = v.entered_by {
                            normal[axis] = sign;
                        } else {
                            normal = -ray.direction.normalize_or_zero();
                        }
                        let c = grid_cell_color(n, normal, ray.direction.normalize_or_zero());
                        super::frame::Sample {
                            color: c.to_array().map(super::quantize),
                            normal: normal.abs().to_array().map(super::quantize),
                            t: v.t_enter,
                            node: 0,
                        }
                    }
                };
            }
        });
    frame
}
