//! A pixel's story as the text `tracelab inspect` prints and the pixel inspector shows.

use super::*;

/// The tree as indented text lines, one ray (and its shadow rays and cut-offs) a few lines,
/// for `tracelab inspect` and the pixel inspector.
pub fn ray_tree_lines(r: &RayTreeReport, depth: usize, out: &mut Vec<String>) {
    let ind = "  ".repeat(depth);
    let hit = match &r.hit {
        Some(h) => format!(
            "hit node {} at t = {:.5}",
            h.node.map_or("?".to_string(), |n| n.to_string()),
            h.t
        ),
        None => "missed: background".to_string(),
    };
    let factor = if r.kind == "eye" {
        String::new()
    } else {
        format!(" × {} (weight {:.4})", v3(r.factor), r.weight)
    };
    out.push(format!(
        "{ind}{} ray{factor}: {hit} -> {}",
        r.kind,
        v3(r.color)
    ));
    if r.hit.is_some() {
        out.push(format!("{ind}  ambient·k_d {}", v3(r.ambient)));
    }
    for l in &r.lights {
        let shadow = r.shadow_rays.iter().find(|s| s.light == l.light);
        let note = match shadow {
            Some(s) if s.blocked => format!(
                " (shadow ray blocked at t = {:.5}{})",
                s.blocker_t.unwrap_or(f32::NAN),
                s.blocker_node
                    .map_or(String::new(), |n| format!(" by node {n}"))
            ),
            Some(_) => " (shadow ray reaches it)".to_string(),
            None => String::new(),
        };
        out.push(format!("{ind}  light {} {}{note}", l.light, v3(l.color)));
    }
    for c in &r.not_traced {
        let why = match c.weight {
            Some(w) => format!("weight {w:.4} below -weight"),
            None if c.why == "bounces" => "-bounces used up".to_string(),
            None => c.why.to_string(),
        };
        out.push(format!("{ind}  {} ray not traced: {why}", c.kind));
    }
    for c in &r.children {
        ray_tree_lines(c, depth + 1, out);
    }
}

fn v3(v: [f32; 3]) -> String {
    format!("({:.5}, {:.5}, {:.5})", v[0], v[1], v[2])
}

fn d3(v: [f64; 3]) -> String {
    // + 0.0 turns −0 into 0: a sign on a zero only distracts.
    format!(
        "{:>10.5} {:>10.5} {:>10.5}",
        v[0] + 0.0,
        v[1] + 0.0,
        v[2] + 0.0
    )
}

fn matrix_lines(
    out: &mut Vec<String>,
    indent: &str,
    name: &str,
    linear: &[[f64; 3]; 3],
    translation: Option<[f64; 3]>,
) {
    for (i, r) in linear.iter().enumerate() {
        let head = if i == 0 {
            format!("{name:<9}")
        } else {
            " ".repeat(9)
        };
        let t = match translation {
            Some(t) => format!(" | {:>10.5}", t[i]),
            None => String::new(),
        };
        out.push(format!("{indent}{head}[{}]{t}", d3(*r)));
    }
}

/// M, M⁻¹ and (M⁻¹)ᵀ as text rows: 3×3 linear part, then the translation after a bar.
pub fn transform_lines(indent: &str, t: &TransformReport) -> Vec<String> {
    let mut out = Vec::new();
    matrix_lines(&mut out, indent, "M", &t.m.linear, Some(t.m.translation));
    matrix_lines(
        &mut out,
        indent,
        "M⁻¹",
        &t.m_inverse.linear,
        Some(t.m_inverse.translation),
    );
    matrix_lines(&mut out, indent, "(M⁻¹)ᵀ", &t.m_inverse_transpose, None);
    out.push(format!("{indent}{}", t.similitude.summary));
    out
}

/// The report as the text `tracelab inspect` prints.
pub fn report_text(r: &PixelReport) -> String {
    let mut out = Vec::new();
    out.push(format!(
        "pixel ({}, {}) of {}×{} (x from the left, row from the top); object rays {}; normal transform {}{}",
        r.pixel.x,
        r.pixel.row,
        r.size[0],
        r.size[1],
        r.settings.object_rays,
        r.settings.normal_transform,
        if r.settings.shade_back { "; shade back" } else { "" }
    ));
    out.push(format!(
        "world ray: origin {} direction {}",
        v3(r.world_ray.origin),
        v3(r.world_ray.direction)
    ));
    let Some(h) = &r.hit else {
        out.push(format!(
            "missed every object: background {}",
            v3(r.background)
        ));
        out.push(format!("colour {} -> bytes {:?}", v3(r.color), r.rgb8));
        out.push(images_line(&r.images));
        return out.join("\n") + "\n";
    };
    out.push(format!("hit: {} (node {})", h.node.label, h.node.id));
    out.push("path (the ray in each space; direction not renormalised, so t is the same):".into());
    for s in &h.path {
        out.push(format!("  {}", s.node.label));
        if let Some(t) = &s.transform {
            out.extend(transform_lines("      ", t));
        }
        out.push(format!(
            "      ray: origin {} direction {}",
            v3(s.ray.origin),
            v3(s.ray.direction)
        ));
    }
    out.push("world from object (composed):".into());
    out.extend(transform_lines("      ", &h.world_from_object));
    out.push(format!(
        "t: world {:.6}, object {:.6} (|M⁻¹d| = {:.6}); the renderer kept {:.6}, the {} t",
        h.t.world, h.t.object, h.t.object_direction_length, h.t.used, h.t.used_is
    ));
    out.push(format!(
        "traced ray (object space): origin {} direction {}",
        v3(h.traced_ray.origin),
        v3(h.traced_ray.direction)
    ));
    out.push(format!(
        "hit point: world {} object {}",
        v3(h.point_world),
        v3(h.point_object)
    ));
    out.push(format!("normal: object {}", v3(h.normal.object)));
    out.push(format!(
        "        world by (M⁻¹)ᵀ {}",
        v3(h.normal.world_correct)
    ));
    out.push(format!(
        "        world by M      {}",
        v3(h.normal.world_incorrect)
    ));
    out.push(format!(
        "        angle between them {:.4}°",
        h.normal.angle_degrees
    ));
    let sh = &h.shading;
    let black = sh.back_facing && !r.settings.shade_back;
    out.push(format!(
        "shading by the {} rule{}: k_d {}",
        sh.normal_rule,
        if black {
            " (back-facing: drawn black without --shade-back)"
        } else if sh.back_facing {
            " (back-facing: the normal flipped toward the eye)"
        } else {
            ""
        },
        v3(sh.diffuse)
    ));
    out.push(format!("  ambient·k_d            {}", v3(sh.ambient)));
    if black {
        out.push("  (no terms are added: the pixel is black)".into());
    }
    for (i, l) in sh.lights.iter().enumerate() {
        out.push(format!(
            "  light {i}: L·N = {:.5}  {}",
            l.l_dot_n,
            v3(l.contribution)
        ));
    }
    let label = if black { "colour" } else { "sum" };
    if let Some(tree) = &r.ray_tree {
        out.push(
            "ray tree (highlights, shadow rays, reflection, refraction; the sum is the pixel's colour):"
                .into(),
        );
        ray_tree_lines(tree, 1, &mut out);
    }
    out.push(format!(
        "  {label:<23}{} -> bytes {:?}",
        v3(r.color),
        r.rgb8
    ));
    out.push(images_line(&r.images));
    out.join("\n") + "\n"
}

/// "each image here: colour [..], normals [..], depth [..] (range 9 to 11)".
pub fn images_line(i: &ImageBytes) -> String {
    let depth = match &i.depth {
        Some(d) => format!(
            "depth {:?} (shade {:.5} in the range {} to {})",
            d.bytes, d.shade, d.min, d.max
        ),
        None => "depth: give --depth MIN MAX for its bytes".into(),
    };
    format!(
        "each image here: colour {:?}, normals {:?}, {depth}",
        i.color, i.normals
    )
}

/// One line for a pixel: what the ray hit, at which t, with which normal (for `tracelab diff`).
pub fn one_line(r: &PixelReport) -> String {
    let Some(h) = &r.hit else {
        return format!("the ray misses everything: background {}", v3(r.background));
    };
    let kept = if h.t.used_is == "object" {
        format!(" (kept the object-space t {:.4})", h.t.used)
    } else {
        String::new()
    };
    let n = if h.shading.normal_rule == "correct" {
        h.normal.world_correct
    } else {
        h.normal.world_incorrect
    };
    let rule = if h.shading.normal_rule == "correct" {
        "(M⁻¹)ᵀ"
    } else {
        "M"
    };
    let other = if h.normal.angle_degrees > 0.01 {
        format!(", {:.2}° from the other rule's", h.normal.angle_degrees)
    } else {
        String::new()
    };
    format!(
        "{} at t = {:.4}{kept}, normal by {rule} {}{other}",
        h.node.label,
        h.t.world,
        v3(n)
    )
}
