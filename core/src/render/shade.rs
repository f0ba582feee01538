//! Diffuse shading as the lecture defines it:
//! c = c_ambient·k_d + Σ max(L·N, 0)·c_light·k_d. No shadows (assignment 2).

use glam::Vec3;

use super::RenderSettings;
use super::compile::{CompiledScene, Hit};
use crate::geometry::Ray;

/// One light's share of a pixel, for the pixel inspector.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightTerm {
    /// Direction toward the light (normalised).
    pub l: Vec3,
    pub l_dot_n: f32,
    pub contribution: Vec3,
}

/// Everything that went into a hit's colour.
#[derive(Clone, Debug, PartialEq)]
pub struct ShadeInfo {
    /// World normal by the chosen rule, before any shade-back flip (what the normal view shows).
    pub normal: Vec3,
    /// The normal used for shading (flipped toward the eye under shade-back).
    pub shading_normal: Vec3,
    pub back_facing: bool,
    pub diffuse: Vec3,
    pub ambient_term: Vec3,
    pub lights: Vec<LightTerm>,
    pub color: Vec3,
}

pub fn shade_hit(
    scene: &CompiledScene,
    ray: &Ray,
    hit: &Hit,
    settings: &RenderSettings,
) -> ShadeInfo {
    let at_hit = scene.ray_for_hit_point(ray, hit, settings.object_rays);
    let normal = scene.world_normal(&at_hit, hit, settings.normal_transform);
    let kd = scene.hit_shading(hit, at_hit.at(hit.t)).0;
    let back_facing = ray.direction.dot(normal) > 0.0;
    let mut info = ShadeInfo {
        normal,
        shading_normal: normal,
        back_facing,
        diffuse: kd,
        ambient_term: Vec3::ZERO,
        lights: Vec::new(),
        color: Vec3::ZERO,
    };
    if back_facing {
        if !settings.shade_back {
            // The course's sample images draw back faces black without -shade_back.
            return info;
        }
        info.shading_normal = -normal;
    }
    let n = info.shading_normal;
    info.ambient_term = scene.ambient * kd;
    let mut c = info.ambient_term;
    for &(l, color) in &scene.lights {
        let d = l.dot(n);
        let contribution = d.max(0.0) * color * kd;
        c += contribution;
        info.lights.push(LightTerm {
            l,
            l_dot_n: d,
            contribution,
        });
    }
    info.color = c;
    if super::whitted::needs_whitted(scene, settings) {
        // Highlights, point lights, shadows and bounces: the colour the render gives.
        info.color = super::whitted::shade_primary(scene, ray, hit, settings).0;
    }
    info
}

/// Colour only, without collecting terms (the hot path).
#[inline]
pub(super) fn shade_fast(
    scene: &CompiledScene,
    ray: &Ray,
    hit: &Hit,
    settings: &RenderSettings,
) -> (Vec3, Vec3) {
    // The normal at the point really hit, whatever t the depth rule kept.
    let at_hit = scene.ray_for_hit_point(ray, hit, settings.object_rays);
    let normal = scene.world_normal(&at_hit, hit, settings.normal_transform);
    (lit(scene, ray, hit, normal, settings.shade_back), normal)
}

/// The lecture's diffuse colour at a hit with world normal `normal`: black for a back face
/// unless `shade_back` turns the normal toward the eye.
#[inline(always)]
fn lit(scene: &CompiledScene, ray: &Ray, hit: &Hit, normal: Vec3, shade_back: bool) -> Vec3 {
    let kd = scene.hit_color(hit);
    let mut n = normal;
    if ray.direction.dot(normal) > 0.0 {
        if !shade_back {
            return Vec3::ZERO;
        }
        n = -normal;
    }
    let mut c = scene.ambient * kd;
    for &(l, color) in &scene.lights {
        c += l.dot(n).max(0.0) * color * kd;
    }
    c
}
