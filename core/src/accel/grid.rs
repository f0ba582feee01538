//! The course's uniform grid (assignments 5–6): the scene's box cut into nx × ny × nz equal
//! cells, each listing the entries whose box overlaps it, walked along a ray cell by cell
//! by the 3D-DDA of Amanatides and Woo ("A Fast Voxel Traversal Algorithm", 1987).
//!
//! The grid holds entries by index only (what an entry is — an object, a mesh's triangle —
//! is the caller's business), in one compressed array: cell c's entries are
//! `entries[offsets[c]..offsets[c + 1]]`.

use glam::{UVec3, Vec3};

use super::super::geometry::Aabb;

/// At most this many cells in all: 256³, far past any handout grid (40 × 40 × 33), and small
/// enough that the offsets array (4 bytes a cell) stays at 64 MiB.
pub const MAX_CELLS: u64 = 1 << 24;

/// At most this many (cell, entry) pairs: 256 MiB of entries. The handout's grids on the
/// course's 40k bunny hold about 200,000; a scene of big triangles in a fine grid could ask
/// for billions, which would take minutes and all the memory there is.
pub const MAX_ENTRIES: u64 = 1 << 26;

#[derive(Clone, Debug, PartialEq)]
pub struct UniformGrid {
    pub bounds: Aabb,
    pub cells: UVec3,
    cell_size: Vec3,
    offsets: Vec<u32>,
    entries: Vec<u32>,
}

/// One cell a ray passes through: its coordinates, where the ray enters and leaves it, and
/// the face it entered by (axis 0–2 and the sign of the outward normal; None for the cell
/// the ray starts in).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CellVisit {
    pub cell: UVec3,
    pub t_enter: f32,
    pub t_exit: f32,
    pub entered_by: Option<(usize, f32)>,
}

impl UniformGrid {
    /// A grid of `cells` over `bounds` holding entry i in every cell its box `boxes[i]`
    /// overlaps (closed boxes: one touching a cell's face counts, so rounding never loses a
    /// hit at a boundary). Empty or non-finite boxes are left out.
    pub fn build(bounds: Aabb, cells: UVec3, boxes: &[Aabb]) -> UniformGrid {
        Self::build_with(bounds, cells, boxes, |_, _| true)
    }

    /// [`UniformGrid::build`], keeping entry i out of a cell its box overlaps where
    /// `overlaps(i, cell_box)` says the entry itself does not reach it (a sphere's corners).
    /// The predicate must be conservative: a cell the entry's surface touches must pass.
    pub fn build_with(
        bounds: Aabb,
        cells: UVec3,
        boxes: &[Aabb],
        overlaps: impl Fn(usize, &Aabb) -> bool,
    ) -> UniformGrid {
        let cells = cells.max(UVec3::ONE);
        let extent = bounds.extent().max(Vec3::splat(f32::MIN_POSITIVE));
        let cell_size = extent / cells.as_vec3();
        let n = (cells.x * cells.y * cells.z) as usize;
        let mut grid = UniformGrid {
            bounds,
            cells,
            cell_size,
            offsets: vec![0; n + 1],
            entries: Vec::new(),
        };
        // Two passes (count, then fill): the entries array is allocated once.
        let ranges: Vec<Option<(UVec3, UVec3)>> =
            boxes.iter().map(|b| grid.cell_range(b)).collect();
        let inside = |i: usize, c: UVec3, g: &UniformGrid| overlaps(i, &g.cell_box(c));
        for (i, r) in ranges.iter().enumerate() {
            let Some((lo, hi)) = r else { continue };
            for c in cells_in(*lo, *hi) {
                if inside(i, c, &grid) {
                    let k = grid.index(c);
                    grid.offsets[k + 1] += 1;
                }
            }
        }
        for i in 0..n {
            grid.offsets[i + 1] += grid.offsets[i];
        }
        let mut next = grid.offsets.clone();
        grid.entries = vec![0; grid.offsets[n] as usize];
        for (i, r) in ranges.iter().enumerate() {
            let Some((lo, hi)) = r else { continue };
            for c in cells_in(*lo, *hi) {
                if inside(i, c, &grid) {
                    let k = grid.index(c);
                    grid.entries[next[k] as usize] = i as u32;
                    next[k] += 1;
                }
            }
        }
        grid
    }

    /// How many (cell, entry) pairs `build` could make at most (every cell of each box's
    /// range), counted without building: checked against [`MAX_ENTRIES`] first.
    pub fn entries_bound(bounds: Aabb, cells: UVec3, boxes: &[Aabb]) -> u64 {
        let cells = cells.max(UVec3::ONE);
        let probe = UniformGrid {
            bounds,
            cells,
            cell_size: bounds.extent().max(Vec3::splat(f32::MIN_POSITIVE)) / cells.as_vec3(),
            offsets: Vec::new(),
            entries: Vec::new(),
        };
        boxes
            .iter()
            .filter_map(|b| probe.cell_range(b))
            .map(|(lo, hi)| {
                let n = (hi - lo + UVec3::ONE).as_u64vec3();
                n.x * n.y * n.z
            })
            .fold(0u64, u64::saturating_add)
    }

    /// The cells' count along each axis times each other.
    pub fn cell_count(&self) -> usize {
        self.offsets.len() - 1
    }

    /// Cells holding at least one entry.
    pub fn occupied(&self) -> usize {
        self.offsets.windows(2).filter(|w| w[1] > w[0]).count()
    }

    /// Every cell holding at least one entry, with how many, in index order (x fastest).
    pub fn occupied_cells(&self) -> impl Iterator<Item = (UVec3, usize)> + '_ {
        let (nx, ny) = (self.cells.x as usize, self.cells.y as usize);
        self.offsets
            .windows(2)
            .enumerate()
            .filter_map(move |(k, w)| {
                let n = (w[1] - w[0]) as usize;
                let c = UVec3::new(
                    (k % nx) as u32,
                    (k / nx % ny) as u32,
                    (k / (nx * ny)) as u32,
                );
                (n > 0).then_some((c, n))
            })
    }

    /// The entries of cell `c`.
    pub fn entries(&self, c: UVec3) -> &[u32] {
        let k = self.index(c);
        let (a, b) = (self.offsets[k] as usize, self.offsets[k + 1] as usize);
        &self.entries[a..b]
    }

    /// The box of cell `c`.
    pub fn cell_box(&self, c: UVec3) -> Aabb {
        let lo = self.bounds.min + c.as_vec3() * self.cell_size;
        Aabb::new(lo, lo + self.cell_size)
    }

    fn index(&self, c: UVec3) -> usize {
        ((c.z * self.cells.y + c.y) * self.cells.x + c.x) as usize
    }

    /// The cells a closed box overlaps, clamped to the grid; None if it misses the grid.
    fn cell_range(&self, b: &Aabb) -> Option<(UVec3, UVec3)> {
        if b.is_empty() || !b.is_finite() {
            return None;
        }
        let g = &self.bounds;
        if (b.min.cmpgt(g.max) | b.max.cmplt(g.min)).any() {
            return None;
        }
        let top = (self.cells - UVec3::ONE).as_vec3();
        let to_cell = |p: Vec3| {
            ((p - g.min) / self.cell_size)
                .floor()
                .clamp(Vec3::ZERO, top)
                .as_uvec3()
        };
        Some((to_cell(b.min), to_cell(b.max)))
    }

    /// Walks the cells the ray `o + t d` passes through with t in (t_min, t_max), nearest
    /// first, calling `visit` for each; `visit` returns false to stop (the caller has found
    /// the hit it wanted). A non-finite ray walks nothing.
    pub fn walk(
        &self,
        o: Vec3,
        d: Vec3,
        t_min: f32,
        t_max: f32,
        mut visit: impl FnMut(&CellVisit) -> bool,
    ) {
        if !(o.is_finite() && d.is_finite()) {
            return;
        }
        let inv = d.recip();
        let (lo, hi) = (self.bounds.min, self.bounds.max);
        let (t0, t1) = ((lo - o) * inv, (hi - o) * inv);
        // NaN (0·∞, a ray along a face) drops out of the max/min as in the slab test.
        let near = t0.min(t1).max(Vec3::splat(t_min)).max_element();
        let far = t0.max(t1).min(Vec3::splat(t_max)).min_element();
        if near > far {
            return;
        }
        // The axis the ray enters the grid by (its outward normal faces the ray).
        let entry_axis = (0..3).find(|&a| t0[a].min(t1[a]) == near && near > t_min);
        let p = o + d * near;
        let top = (self.cells - UVec3::ONE).as_vec3();
        let mut cell = ((p - lo) / self.cell_size)
            .floor()
            .clamp(Vec3::ZERO, top)
            .as_uvec3();
        // Per axis: the step, the t of the next cell boundary, the t across one cell.
        let mut step = [0i32; 3];
        let mut t_next = [f32::INFINITY; 3];
        let mut t_delta = [f32::INFINITY; 3];
        for a in 0..3 {
            if d[a] > 0.0 {
                step[a] = 1;
                let edge = lo[a] + (cell[a] + 1) as f32 * self.cell_size[a];
                t_next[a] = (edge - o[a]) * inv[a];
                t_delta[a] = self.cell_size[a] * inv[a];
            } else if d[a] < 0.0 {
                step[a] = -1;
                let edge = lo[a] + cell[a] as f32 * self.cell_size[a];
                t_next[a] = (edge - o[a]) * inv[a];
                t_delta[a] = -self.cell_size[a] * inv[a];
            }
        }
        let mut t_enter = near;
        let mut entered_by = entry_axis.map(|a| (a, -d[a].signum()));
        loop {
            let a = if t_next[0] <= t_next[1] && t_next[0] <= t_next[2] {
                0
            } else if t_next[1] <= t_next[2] {
                1
            } else {
                2
            };
            let t_exit = t_next[a].min(far);
            let v = CellVisit {
                cell,
                t_enter,
                t_exit,
                entered_by,
            };
            if !visit(&v) || t_next[a] > far {
                return;
            }
            let c = cell[a] as i64 + step[a] as i64;
            if c < 0 || c >= self.cells[a] as i64 {
                return;
            }
            cell[a] = c as u32;
            t_enter = t_next[a];
            t_next[a] += t_delta[a];
            entered_by = Some((a, -(step[a] as f32)));
        }
    }
}

/// Every cell from `lo` to `hi` inclusive.
fn cells_in(lo: UVec3, hi: UVec3) -> impl Iterator<Item = UVec3> {
    (lo.z..=hi.z).flat_map(move |z| {
        (lo.y..=hi.y).flat_map(move |y| (lo.x..=hi.x).map(move |x| UVec3::new(x, y, z)))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_grid(n: u32) -> UniformGrid {
        UniformGrid::build(
            Aabb::new(Vec3::ZERO, Vec3::splat(n as f32)),
            UVec3::splat(n),
            &[
                Aabb::new(Vec3::splat(0.5), Vec3::splat(1.5)),
                Aabb::new(Vec3::new(3.0, 0.2, 0.2), Vec3::new(3.5, 0.4, 0.4)),
            ],
        )
    }

    #[test]
    fn boxes_land_in_every_cell_they_overlap_and_nowhere_else() {
        let g = unit_grid(4);
        // Box 0 spans cells 0..=1 on each axis: 8 cells; box 1 one cell.
        assert_eq!(g.occupied(), 9);
        assert_eq!(g.entries(UVec3::new(1, 1, 0)), &[0]);
        assert_eq!(g.entries(UVec3::new(3, 0, 0)), &[1]);
        assert!(g.entries(UVec3::new(2, 2, 2)).is_empty());
    }

    #[test]
    fn the_walk_visits_the_cells_along_the_ray_in_order_with_contiguous_spans() {
        let g = unit_grid(4);
        let mut seen = Vec::new();
        let d = Vec3::new(1.0, 0.37, 0.11).normalize();
        g.walk(Vec3::new(-1.0, 0.3, 0.2), d, 0.0, f32::INFINITY, |v| {
            seen.push(*v);
            true
        });
        assert_eq!(seen[0].cell, UVec3::new(0, 0, 0));
        assert_eq!(seen[0].entered_by, Some((0, -1.0)));
        for w in seen.windows(2) {
            assert_eq!(w[0].t_exit, w[1].t_enter, "no gap or overlap");
            let moved = (w[1].cell.as_ivec3() - w[0].cell.as_ivec3())
                .abs()
                .element_sum();
            assert_eq!(moved, 1, "one face at a time");
        }
        // Every visited cell really meets the ray (its box, slightly widened).
        for v in &seen {
            let b = g.cell_box(v.cell);
            let mid = Vec3::new(-1.0, 0.3, 0.2) + d * (0.5 * (v.t_enter + v.t_exit));
            assert!(
                (mid.cmpge(b.min - 1e-4) & mid.cmple(b.max + 1e-4)).all(),
                "{v:?}"
            );
        }
        assert_eq!(seen.last().map(|v| v.cell.x), Some(3));
        // A ray that misses the grid, or a NaN one, visits nothing; stopping early works.
        let mut n = 0;
        g.walk(
            Vec3::new(-1.0, 9.0, 0.0),
            Vec3::X,
            0.0,
            f32::INFINITY,
            |_| {
                n += 1;
                true
            },
        );
        g.walk(Vec3::NAN, Vec3::X, 0.0, f32::INFINITY, |_| {
            n += 1;
            true
        });
        assert_eq!(n, 0);
        g.walk(
            Vec3::new(-1.0, 0.5, 0.5),
            Vec3::X,
            0.0,
            f32::INFINITY,
            |_| {
                n += 1;
                false
            },
        );
        assert_eq!(n, 1);
    }

    #[test]
    fn a_ray_starting_inside_walks_from_its_own_cell() {
        let g = unit_grid(4);
        let mut first = None;
        g.walk(
            Vec3::new(2.5, 2.5, 2.5),
            Vec3::NEG_Y,
            0.0,
            f32::INFINITY,
            |v| {
                first.get_or_insert(*v);
                true
            },
        );
        let f = first.expect("a cell");
        assert_eq!(f.cell, UVec3::new(2, 2, 2));
        assert_eq!(f.entered_by, None);
    }
}
