//! What a scene's uniform grid holds (`grid_scene.rs` builds and walks it; the compiled
//! scene keeps it): the grid, what each entry stands for, and the `-stats` counters.

use std::sync::atomic::{AtomicU64, Ordering};

use crate::accel::UniformGrid;

/// A grid entry that stands for a whole object.
pub(super) const WHOLE: u32 = u32::MAX;

/// The grid and what each of its entries is: (object, triangle of a mesh or `WHOLE`).
#[derive(Debug)]
pub struct GridScene {
    pub grid: UniformGrid,
    pub(super) items: Vec<(u32, u32)>,
    pub stats: RayCounts,
}

impl GridScene {
    /// What grid entry `e` stands for: (object index, `Some(triangle)` of a mesh or `None`
    /// for the whole object).
    pub fn entry(&self, e: u32) -> Option<(u32, Option<u32>)> {
        let &(i, k) = self.items.get(e as usize)?;
        Some((i, (k != WHOLE).then_some(k)))
    }

    /// How many entries the grid was built from (objects and mesh triangles).
    pub fn entry_count(&self) -> usize {
        self.items.len()
    }
}

/// The course's `-stats` counters (`RayTracingStats`), counted while a grid is in use.
#[derive(Debug, Default)]
pub struct RayCounts {
    pub cells_traversed: AtomicU64,
    pub intersection_tests: AtomicU64,
    pub shadow_rays: AtomicU64,
    pub secondary_rays: AtomicU64,
}

impl RayCounts {
    pub(super) fn add(c: &AtomicU64, n: u64) {
        c.fetch_add(n, Ordering::Relaxed);
    }
    pub fn get(c: &AtomicU64) -> u64 {
        c.load(Ordering::Relaxed)
    }
}
