//! View › Uniform grid (assignments 5–6): render through the course's uniform grid of
//! NX × NY × NZ cells (`-grid`) or show its occupied cells (`-visualize_grid`), and, for the
//! picked pixel, the grid's occupied cells and the cells its eye ray walks through in DDA
//! order up to its hit, in the Ray panel's world diagram — the handout's debugging pictures.
//! The walk is the core's own (`CompiledScene::grid_walk`, the traversal `intersect` makes).

use glam::{UVec3, Vec3};
use tracelab_core::accel::CellVisit;
use tracelab_core::geometry::Aabb;

use crate::gui::panels::pixel_inspector::Inspected;
use crate::gui::ray_diagram::{Diagram, Item, Role, Shape};
use crate::render_worker::{GridRequest, Published};

/// The most cells a side may have in the editor: 256³ is the core's cell cap
/// (`MAX_CELLS`), so no choice here exceeds it; the (cell, entry) cap depends on the scene
/// and is checked when the grid is built, the view saying so if it refuses.
pub const MAX_SIDE: u32 = 256;

/// The most occupied cells drawn as boxes; past it every k-th is drawn, and the panel says
/// how many of how many.
pub const MAX_DRAWN: usize = 3000;

/// What View › Uniform grid holds. Off by default: the BVH renders.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GridSettings {
    pub on: bool,
    pub cells: [u32; 3],
    pub visualize: bool,
}

impl Default for GridSettings {
    /// 10³: the handout's size for the scenes of assignment 6 that have no other.
    fn default() -> Self {
        GridSettings {
            on: false,
            cells: [10, 10, 10],
            visualize: false,
        }
    }
}

impl GridSettings {
    /// The render worker's request: `None` while off. Counts are kept within 1..=MAX_SIDE.
    pub fn request(&self) -> Option<GridRequest> {
        self.on.then(|| GridRequest {
            cells: self.cells.map(|n| n.clamp(1, MAX_SIDE)),
            visualize: self.visualize,
        })
    }
}

/// The submenu's widgets; changes `s` in place.
pub fn menu(ui: &mut egui::Ui, s: &mut GridSettings) {
    ui.checkbox(&mut s.on, "Render through a uniform grid (-grid)")
        .on_hover_text("Every ray walks the grid's cells by 3D-DDA instead of the BVH");
    ui.add_enabled_ui(s.on, |ui| {
        ui.horizontal(|ui| {
            ui.label("cells");
            for (n, axis) in s.cells.iter_mut().zip(["NX", "NY", "NZ"]) {
                ui.add(
                    egui::DragValue::new(n)
                        .range(1..=MAX_SIDE)
                        .prefix(format!("{axis} ")),
                );
            }
        });
        ui.checkbox(
            &mut s.visualize,
            "Show the occupied cells (-visualize_grid)",
        )
        .on_hover_text(
            "The image -visualize_grid writes: each pixel the first occupied cell its ray enters",
        );
    });
    ui.label(
        egui::RichText::new(format!(
            "At most {MAX_SIDE} cells a side. Pick a pixel: the Ray panel draws the cells its ray walks."
        ))
        .small(),
    );
}

/// The grid and the picked pixel's walk through it, ready to draw.
#[derive(Clone, Debug, PartialEq)]
pub struct GridPick {
    pub cells: UVec3,
    /// Occupied cells in the grid, and how many of them `items` draws.
    pub occupied: usize,
    pub drawn: usize,
    /// The cells the eye ray walks, nearest first, up to the one holding its hit.
    pub walk: Vec<CellVisit>,
    pub hit: bool,
    /// The eye ray's origin, and where the walk leaves off (the hit, or where the ray
    /// leaves the grid): the world diagram's ray when the ray hits nothing.
    pub origin: Vec3,
    pub end: Vec3,
    /// The world diagram's additions: occupied cells, then the walked ones.
    pub items: Vec<Item>,
}

impl GridPick {
    /// One line for the panel: the grid, and the walk as cell coordinates in order.
    pub fn summary(&self) -> String {
        let [x, y, z] = self.cells.to_array();
        let cells: Vec<String> = self
            .walk
            .iter()
            .map(|v| format!("({},{},{})", v.cell.x, v.cell.y, v.cell.z))
            .collect();
        let drawn = if self.drawn < self.occupied {
            format!(
                ", {} of them drawn (every {}th)",
                self.drawn,
                self.occupied.div_ceil(MAX_DRAWN)
            )
        } else {
            String::new()
        };
        let n = self.walk.len();
        format!(
            "Grid {x}×{y}×{z}: {} occupied cells (grey){drawn}. The ray walks {n} cell{} \
             (orange, numbered) {}: {}",
            self.occupied,
            if n == 1 { "" } else { "s" },
            if self.hit {
                "to its hit"
            } else {
                "and hits nothing in the grid"
            },
            cells.join(" ")
        )
    }
}

impl GridPick {
    /// The world diagram for a ray that hits nothing: the grid, the walk and the ray alone.
    pub fn miss_diagram(&self) -> Diagram {
        let mut items = vec![
            Item {
                role: Role::Eye,
                shape: Shape::Point(self.origin),
                label: Some("eye".into()),
            },
            Item {
                role: Role::Ray,
                shape: Shape::Line(vec![self.origin, self.end]),
                label: Some("misses".into()),
            },
        ];
        items.extend(self.items.iter().cloned());
        Diagram { items }
    }
}

/// The grid walk of the inspected pixel's eye ray in the published render, when that render
/// went through a grid.
pub fn pick(p: &Published, at: &Inspected) -> Option<GridPick> {
    let c = &p.compiled;
    let g = &c.grid()?.grid;
    let ray = c.camera.pixel_ray(at.x, at.row, at.size.0, at.size.1);
    let walk = c.grid_walk(&ray, c.camera.t_min(), f32::INFINITY)?;
    let occupied: Vec<UVec3> = g.occupied_cells().map(|(cell, _)| cell).collect();
    let every = occupied.len().div_ceil(MAX_DRAWN).max(1);
    let mut items: Vec<Item> = occupied
        .iter()
        .step_by(every)
        .map(|&cell| Item {
            role: Role::GridCell,
            shape: Shape::Line(box_path(&g.cell_box(cell))),
            label: None,
        })
        .collect();
    let drawn = items.len();
    let n = walk.cells.len();
    for (k, v) in walk.cells.iter().enumerate() {
        // Every cell numbered on a short walk; the first and last on a long one.
        let label = (n <= 24 || k == 0 || k + 1 == n).then(|| (k + 1).to_string());
        items.push(Item {
            role: Role::GridWalk,
            shape: Shape::Line(box_path(&g.cell_box(v.cell))),
            label,
        });
    }
    let end = match (walk.hit, walk.cells.last()) {
        (Some(h), _) => ray.at(h.t),
        (None, Some(v)) => ray.at(v.t_exit),
        (None, None) => ray.at(c.camera.t_min()),
    };
    Some(GridPick {
        origin: ray.origin,
        end,
        cells: g.cells,
        occupied: occupied.len(),
        drawn,
        hit: walk.hit.is_some(),
        walk: walk.cells,
        items,
    })
}

/// A box's 12 edges as one path (three edges drawn twice), its last point the far corner
/// (where a label goes).
pub fn box_path(b: &Aabb) -> Vec<Vec3> {
    let p = |i: u32| {
        Vec3::new(
            if i & 1 == 0 { b.min.x } else { b.max.x },
            if i & 2 == 0 { b.min.y } else { b.max.y },
            if i & 4 == 0 { b.min.z } else { b.max.z },
        )
    };
    [0, 1, 3, 2, 0, 4, 5, 1, 5, 7, 3, 7, 6, 2, 6, 4, 6, 7]
        .into_iter()
        .map(p)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_box_path_runs_along_all_twelve_edges_and_nothing_else() {
        let b = Aabb::new(Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0));
        let path = box_path(&b);
        let mut edges = std::collections::BTreeSet::new();
        for w in path.windows(2) {
            let d = w[1] - w[0];
            // Along one axis only, the box's full side.
            assert_eq!(d.cmpne(Vec3::ZERO).bitmask().count_ones(), 1, "{w:?}");
            let key = |p: Vec3| (p.x as u32, p.y as u32, p.z as u32);
            let (a, c) = (key(w[0]), key(w[1]));
            edges.insert(if a < c { (a, c) } else { (c, a) });
        }
        assert_eq!(edges.len(), 12);
        assert_eq!(path.last(), Some(&b.max));
    }

    #[test]
    fn the_request_is_none_while_off_and_clamps_the_counts() {
        assert_eq!(GridSettings::default().request(), None);
        let s = GridSettings {
            on: true,
            cells: [0, 300, 7],
            visualize: true,
        };
        assert_eq!(
            s.request(),
            Some(GridRequest {
                cells: [1, MAX_SIDE, 7],
                visualize: true
            })
        );
    }
}
