//! The variant renderer: one ray per pixel through the same intersection, normal, material
//! and shading code as the renderer (`whitted.rs`, with the variant's rule switches), so a
//! variant differs from the reference exactly where its mistake shows.

use glam::Vec3;
use rayon::prelude::*;

use super::catalogue::{Mistake, Variant};
use crate::geometry::Ray;
use crate::render::compile::{CompiledScene, Hit, Shape};
use crate::render::frame::{Frame, Sample, View, depth_shade, quantize};
use crate::render::rules::{Ambient, Rules};
use crate::render::whitted::shade_with_rules;
use crate::render::{NormalTransform, ObjectRays, RenderSettings};

/// Renders the variant `settings.variant` (which must be set) into a frame: one ray per
/// pixel, rows in parallel. Transform mistakes need `scene` compiled from [`scene_with`].
pub fn render_variant(scene: &CompiledScene, settings: &RenderSettings) -> Frame {
    let v = settings.variant.unwrap_or(Variant(0));
    let (w, h) = (settings.width, settings.height);
    let mut frame = Frame::new(w, h);
    if w == 0 || h == 0 {
        return frame;
    }
    frame
        .samples
        .par_chunks_mut(w as usize)
        .enumerate()
        .for_each(|(row, samples)| {
            for (x, dst) in samples.iter_mut().enumerate() {
                *dst = trace(scene, settings, v, x as u32, row as u32);
            }
        });
    if v.has(Mistake::RowsFlipped) {
        let rows: Vec<Sample> = frame
            .samples
            .chunks(w as usize)
            .rev()
            .flatten()
            .copied()
            .collect();
        frame.samples = rows;
    }
    frame
}

/// The screen point pixel (i, row) samples: its centre, or its lower-left corner.
fn screen_point(i: u32, row: u32, w: u32, h: u32, corners: bool) -> (f32, f32) {
    let s = w.max(h) as f32;
    let j = h - 1 - row.min(h - 1);
    let at = if corners { 0.0 } else { 0.5 };
    let x = (i as f32 + at + (s - w as f32) * 0.5) / s;
    let y = (j as f32 + at + (s - h as f32) * 0.5) / s;
    (x, y)
}

fn camera_ray(scene: &CompiledScene, v: Variant, x: f32, y: f32) -> Ray {
    let c = &scene.camera;
    if c.perspective && v.has(Mistake::AngleInterpolated) {
        let angle = 2.0 * (c.extent * 0.5).atan();
        let d = c.direction
            + ((x - 0.5) * angle).tan() * c.horizontal
            + ((y - 0.5) * angle).tan() * c.up;
        return Ray::new(c.center, d.normalize());
    }
    c.ray_at(x, y)
}

fn trace(scene: &CompiledScene, s: &RenderSettings, v: Variant, x: u32, row: u32) -> Sample {
    let (sx, sy) = screen_point(x, row, s.width, s.height, v.has(Mistake::PixelCorners));
    let ray = camera_ray(scene, v, sx, sy);
    let t_min = if !scene.camera.perspective && v.has(Mistake::OrthographicTminZero) {
        0.0
    } else {
        scene.camera.t_min()
    };
    let rule = if v.has(Mistake::DepthNotRescaled) {
        ObjectRays::NormalizedNoRescale
    } else {
        s.object_rays
    };
    let rounding = v.has(Mistake::Rounding);
    let Some(hit) = scene.intersect_with(&ray, t_min, f32::INFINITY, rule) else {
        return Sample {
            color: bytes(scene.background, rounding),
            normal: [0; 3],
            t: f32::INFINITY,
            node: u32::MAX,
        };
    };
    let at_hit = scene.ray_for_hit_point(&ray, &hit, rule);
    let normal = world_normal(scene, s, v, &at_hit, &hit);
    // Secondary rays' normals follow the variant's rule too.
    let shading = RenderSettings {
        normal_transform: normal_rule(s, v),
        ..*s
    };
    let color = shade_with_rules(scene, &at_hit, &hit, normal, &shading, &rules(v));
    Sample {
        color: bytes(color, rounding),
        normal: bytes(normal.abs(), rounding),
        t: hit.t,
        node: scene.hit_node(&hit).map_or(u32::MAX, |n| n.0),
    }
}

fn world_normal(
    scene: &CompiledScene,
    s: &RenderSettings,
    v: Variant,
    at_hit: &Ray,
    hit: &Hit,
) -> Vec3 {
    let rule = normal_rule(s, v);
    let o = scene.objects.get(hit.object as usize);
    if v.has(Mistake::NormalNotNormalized)
        && let Some(o) = o
        && let Some(xf) = &o.xf
        && !matches!(o.shape, Shape::Csg(_))
    {
        let n = scene.object_normal(at_hit, hit).normalize_or(Vec3::Z);
        return match rule {
            NormalTransform::Correct => xf.normal_from_object * n,
            NormalTransform::Incorrect => xf.world_from_object.transform_vector3(n),
        };
    }
    scene.world_normal(at_hit, hit, rule)
}

fn normal_rule(s: &RenderSettings, v: Variant) -> NormalTransform {
    if v.has(Mistake::NormalByM) {
        NormalTransform::Incorrect
    } else {
        s.normal_transform
    }
}

/// The shading rules the variant breaks, as `whitted.rs`'s switches.
fn rules(v: Variant) -> Rules {
    Rules {
        ambient: if v.has(Mistake::AmbientNotTimesDiffuse) {
            Ambient::Plain
        } else if v.has(Mistake::AmbientTimesDiffuseTwice) {
            Ambient::TimesDiffuseTwice
        } else {
            Ambient::TimesDiffuse
        },
        back_faces_lit: v.has(Mistake::BackFacesLit),
        back_faces_flipped: v.has(Mistake::BackFacesFlippedWithoutShadeBack),
        shade_back_absolute: v.has(Mistake::ShadeBackAbsolute),
        reflection_vector: v.has(Mistake::ReflectionVector),
        specular_behind: v.has(Mistake::SpecularBehind),
        shadow_t_min_zero: v.has(Mistake::ShadowAcne),
        ambient_dropped_in_shadow: v.has(Mistake::AmbientDroppedInShadow),
        transparent_casts_no_shadow: v.has(Mistake::TransparentCastsNoShadow),
        index_not_inverted: v.has(Mistake::IndexNotInverted),
        tir_transmits_reflected: v.has(Mistake::TotalInternalReflectionTransmitted),
        weight_ignored: v.has(Mistake::WeightIgnored),
    }
}

fn byte(c: f32, rounding: bool) -> u8 {
    if rounding {
        // NaN as u8 is 0, as in `quantize`.
        (c * 255.0).round().clamp(0.0, 255.0) as u8
    } else {
        quantize(c)
    }
}

fn bytes(c: Vec3, rounding: bool) -> [u8; 3] {
    [
        byte(c.x, rounding),
        byte(c.y, rounding),
        byte(c.z, rounding),
    ]
}

/// RGB8 bytes of one view of a variant's frame (rows top to bottom), with the variant's
/// depth and background mistakes; for no variant, `Frame::rgb8`'s bytes.
pub fn variant_rgb8(
    scene: &CompiledScene,
    frame: &Frame,
    variant: Option<Variant>,
    view: View,
    depth: (f32, f32),
) -> Vec<u8> {
    let Some(v) = variant else {
        return frame.rgb8(view, depth);
    };
    let background = bytes(scene.background, v.has(Mistake::Rounding));
    let mut out = Vec::with_capacity(frame.samples.len() * 3);
    for s in &frame.samples {
        let px = match view {
            View::Color => s.color,
            View::Normals if !s.is_hit() && v.has(Mistake::BackgroundNotBlack) => background,
            View::Normals => s.normal,
            View::Depth if !s.is_hit() => {
                if v.has(Mistake::BackgroundNotBlack) {
                    background
                } else {
                    [0; 3]
                }
            }
            View::Depth => {
                let g = if v.has(Mistake::DepthNotClamped) && s.t < depth.0 {
                    0
                } else {
                    byte(depth_shade(s.t, depth.0, depth.1), v.has(Mistake::Rounding))
                };
                [g; 3]
            }
        };
        out.extend_from_slice(&px);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rounding_differs_from_truncating_only_past_the_half() {
        assert_eq!(byte(0.5 / 255.0, false), 0);
        assert_eq!(byte(0.5 / 255.0, true), 1);
        assert_eq!(byte(f32::NAN, true), 0);
        assert_eq!(byte(2.0, true), 255);
    }
}
