//! `-stats`: the course's `RayTracingStats` block, printed after the render.

use std::time::Duration;

use tracelab_core::render::RayCounts;
use tracelab_core::{CompiledScene, RenderSettings};

/// The counters as the course's programs print them. Rays and tests are counted while a
/// grid is in use (`-grid`); without one only the time, the pixels and the eye rays are
/// known, and the block says so rather than print zeros.
pub fn stats_text(scene: &CompiledScene, s: &RenderSettings, time: Duration) -> String {
    let pixels = u64::from(s.width) * u64::from(s.height);
    let secs = time.as_secs_f64();
    let mut out = vec![
        "********************************************".to_string(),
        "RAY TRACING STATISTICS".to_string(),
        format!("  total time                    {secs:.3} seconds"),
        format!(
            "  num pixels                    {pixels} ({}x{})",
            s.width, s.height
        ),
    ];
    let Some(g) = scene.grid() else {
        out.push(
            "  (rays, intersections and cells are counted with -grid NX NY NZ; without it \
             the objects' BVH is used)"
                .to_string(),
        );
        out.push("********************************************".to_string());
        return out.join("\n") + "\n";
    };
    let b = g.grid.bounds;
    let c = g.grid.cells;
    let get = |a| RayCounts::get(a);
    let non_shadow = pixels + get(&g.stats.secondary_rays);
    let shadow = get(&g.stats.shadow_rays);
    let tests = get(&g.stats.intersection_tests);
    let cells = get(&g.stats.cells_traversed);
    let rays = (non_shadow + shadow).max(1) as f64;
    out.extend([
        format!(
            "  scene bounds                  ({:.4}, {:.4}, {:.4}) - ({:.4}, {:.4}, {:.4})",
            b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z
        ),
        format!(
            "  num grid cells                {} ({}x{}x{}), {} occupied",
            g.grid.cell_count(),
            c.x,
            c.y,
            c.z,
            g.grid.occupied()
        ),
        format!("  num non-shadow rays           {non_shadow}"),
        format!("  num shadow rays               {shadow}"),
        format!("  total intersections           {tests}"),
        format!("  total cells traversed         {cells}"),
        format!(
            "  rays per second               {:.0}",
            rays / secs.max(1e-9)
        ),
        format!(
            "  rays per pixel                {:.3}",
            rays / pixels.max(1) as f64
        ),
        format!("  intersections per ray         {:.3}", tests as f64 / rays),
        format!("  cells traversed per ray       {:.3}", cells as f64 / rays),
        "********************************************".to_string(),
    ]);
    out.join("\n") + "\n"
}
