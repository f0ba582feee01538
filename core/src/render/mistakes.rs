//! The catalogue of known student mistakes, each a render variant: what a ray tracer that
//! breaks one of the course's rules draws, so `tracelab diff` can name the rule a student's
//! image breaks. A variant is one or two mistakes at once; with none (`RenderSettings::variant`
//! = `None`) nothing here runs and the render is today's, bit for bit.
//!
//! The variant renderer traces one ray per pixel through the same intersection, normal and
//! material code as the renderer, changing only what each mistake changes, so a variant
//! differs from the reference exactly where the mistake shows.

use glam::{Mat4, Vec3};
use rayon::prelude::*;

use super::compile::{CompiledScene, Hit, Shape};
use super::frame::{Frame, Sample, View, depth_shade, quantize};
use super::{NormalTransform, ObjectRays, RenderSettings};
use crate::geometry::Ray;
use crate::scene::{NodeKind, Scene, TransformOp};

/// One known mistake. The order is the catalogue's (and the order diagnoses list ties in).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Mistake {
    PixelCorners,
    AngleInterpolated,
    RowsFlipped,
    OrthographicTminZero,
    NormalByM,
    NormalNotNormalized,
    DepthNotRescaled,
    BackFacesLit,
    BackFacesFlippedWithoutShadeBack,
    ShadeBackAbsolute,
    AmbientNotTimesDiffuse,
    AmbientTimesDiffuseTwice,
    Rounding,
    DepthNotClamped,
    BackgroundNotBlack,
    MatrixCourseSide,
    RotateAxisAsWritten,
}

/// Which images a mistake can change.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Views {
    pub color: bool,
    pub normals: bool,
    pub depth: bool,
}

impl Mistake {
    pub const ALL: [Mistake; 17] = [
        Mistake::PixelCorners,
        Mistake::AngleInterpolated,
        Mistake::RowsFlipped,
        Mistake::OrthographicTminZero,
        Mistake::NormalByM,
        Mistake::NormalNotNormalized,
        Mistake::DepthNotRescaled,
        Mistake::BackFacesLit,
        Mistake::BackFacesFlippedWithoutShadeBack,
        Mistake::ShadeBackAbsolute,
        Mistake::AmbientNotTimesDiffuse,
        Mistake::AmbientTimesDiffuseTwice,
        Mistake::Rounding,
        Mistake::DepthNotClamped,
        Mistake::BackgroundNotBlack,
        Mistake::MatrixCourseSide,
        Mistake::RotateAxisAsWritten,
    ];

    fn bit(self) -> u32 {
        1 << self as u32
    }

    /// A short stable name (for tests, JSON and the batch report).
    pub fn name(self) -> &'static str {
        match self {
            Mistake::PixelCorners => "pixel-corners",
            Mistake::AngleInterpolated => "angle-interpolated",
            Mistake::RowsFlipped => "rows-flipped",
            Mistake::OrthographicTminZero => "orthographic-tmin-zero",
            Mistake::NormalByM => "normal-by-m",
            Mistake::NormalNotNormalized => "normal-not-normalized",
            Mistake::DepthNotRescaled => "depth-not-rescaled",
            Mistake::BackFacesLit => "back-faces-lit",
            Mistake::BackFacesFlippedWithoutShadeBack => "back-faces-flipped",
            Mistake::ShadeBackAbsolute => "shade-back-absolute",
            Mistake::AmbientNotTimesDiffuse => "ambient-not-times-diffuse",
            Mistake::AmbientTimesDiffuseTwice => "ambient-times-diffuse-twice",
            Mistake::Rounding => "rounding",
            Mistake::DepthNotClamped => "depth-not-clamped",
            Mistake::BackgroundNotBlack => "background-not-black",
            Mistake::MatrixCourseSide => "matrix-course-side",
            Mistake::RotateAxisAsWritten => "rotate-axis-as-written",
        }
    }

    pub fn from_name(s: &str) -> Option<Mistake> {
        Self::ALL.into_iter().find(|m| m.name() == s)
    }

    /// What the image shows was done, in one line.
    pub fn explanation(self) -> &'static str {
        match self {
            Mistake::PixelCorners => "rays through pixel corners (x = i/W, y = j/H), not centres",
            Mistake::AngleInterpolated => {
                "the perspective angle interpolated across the screen (tan((x-0.5)·angle)) instead of a planar image plane"
            }
            Mistake::RowsFlipped => "the image upside down: row 0 written at the top",
            Mistake::OrthographicTminZero => {
                "the orthographic camera's t_min at 0: hits behind the camera centre are lost"
            }
            Mistake::NormalByM => "normals transformed by M instead of (M⁻¹)ᵀ",
            Mistake::NormalNotNormalized => "the transformed normal not normalised",
            Mistake::DepthNotRescaled => {
                "the object-space ray direction normalised, but t not rescaled to world space"
            }
            Mistake::BackFacesLit => {
                "back faces shaded with their outward normal without -shade_back"
            }
            Mistake::BackFacesFlippedWithoutShadeBack => {
                "back faces shaded with the flipped normal without -shade_back"
            }
            Mistake::ShadeBackAbsolute => "-shade_back as |L·N| instead of a flipped normal",
            Mistake::AmbientNotTimesDiffuse => {
                "the ambient light not multiplied by the diffuse colour"
            }
            Mistake::AmbientTimesDiffuseTwice => {
                "the ambient light multiplied by the diffuse colour twice"
            }
            Mistake::Rounding => "colours rounded to bytes instead of truncated",
            Mistake::DepthNotClamped => "depth closer than min drawn black (not clamped to white)",
            Mistake::BackgroundNotBlack => {
                "the scene's background colour in the depth or normal image"
            }
            Mistake::MatrixCourseSide => {
                "Matrix { } composed on the other side (M = T·M, as the course parser does)"
            }
            Mistake::RotateAxisAsWritten => {
                "Rotate { } with its axis as written, not normalised (as the course parser does)"
            }
        }
    }

    /// The course's rule that the mistake breaks (handout, lecture or `AGREEMENT.md`).
    pub fn rule(self) -> &'static str {
        match self {
            Mistake::PixelCorners => "pixel (i, j) samples the screen at ((i+0.5)/W, (j+0.5)/H)",
            Mistake::AngleInterpolated => {
                "d + (x-0.5)·2·tan(angle/2)·h + (y-0.5)·2·tan(angle/2)·u, normalised (a planar image plane)"
            }
            Mistake::RowsFlipped => {
                "j = 0 is the bottom row: the image's top row is the camera's +up side"
            }
            Mistake::OrthographicTminZero => {
                "the orthographic camera's t_min is −∞ (scene1_07 puts objects behind the centre)"
            }
            Mistake::NormalByM => {
                "world normals are (M⁻¹)ᵀ·n: M skews them under non-uniform scale and shear"
            }
            Mistake::NormalNotNormalized => {
                "the world normal is normalised after (M⁻¹)ᵀ: only unit normals shade L·N"
            }
            Mistake::DepthNotRescaled => {
                "t is the world ray parameter: normalising M⁻¹d needs t_WS = t_OS / |M⁻¹d|"
            }
            Mistake::BackFacesLit | Mistake::BackFacesFlippedWithoutShadeBack => {
                "without -shade_back a back-facing hit is black"
            }
            Mistake::ShadeBackAbsolute => {
                "with -shade_back the normal is flipped toward the eye before shading"
            }
            Mistake::AmbientNotTimesDiffuse | Mistake::AmbientTimesDiffuseTwice => {
                "c = ambient·kd + Σ max(L·N, 0)·light·kd: ambient times kd exactly once"
            }
            Mistake::Rounding => "byte = clamp(int(c·255), 0, 255), truncated",
            Mistake::DepthNotClamped => {
                "depth shade = (max − t)/(max − min) clamped to [0, 1]: t < min is white"
            }
            Mistake::BackgroundNotBlack => "depth and normal images have a black background",
            Mistake::MatrixCourseSide => {
                "tracelab composes Matrix { } in its listed place like every op; the course parser puts it on the other side"
            }
            Mistake::RotateAxisAsWritten => {
                "tracelab normalises Rotate's axis; the course parser does not (a rotation and a scale)"
            }
        }
    }

    /// The images this mistake can change.
    pub fn views(self) -> Views {
        let all = Views {
            color: true,
            normals: true,
            depth: true,
        };
        let only = |color, normals, depth| Views {
            color,
            normals,
            depth,
        };
        match self {
            Mistake::PixelCorners
            | Mistake::AngleInterpolated
            | Mistake::RowsFlipped
            | Mistake::OrthographicTminZero
            | Mistake::DepthNotRescaled
            | Mistake::Rounding
            | Mistake::MatrixCourseSide
            | Mistake::RotateAxisAsWritten => all,
            Mistake::NormalByM | Mistake::NormalNotNormalized => only(true, true, false),
            Mistake::BackFacesLit
            | Mistake::BackFacesFlippedWithoutShadeBack
            | Mistake::ShadeBackAbsolute
            | Mistake::AmbientNotTimesDiffuse
            | Mistake::AmbientTimesDiffuseTwice => only(true, false, false),
            Mistake::DepthNotClamped => only(false, false, true),
            Mistake::BackgroundNotBlack => only(false, true, true),
        }
    }

    /// A cheap test, before any render: can this mistake change one of `views` of this scene
    /// rendered with `settings`? (False only where it certainly cannot; the caller still
    /// drops variants whose images come out identical.)
    pub fn may_change(
        self,
        scene: &Scene,
        compiled: &CompiledScene,
        settings: &RenderSettings,
        views: Views,
    ) -> bool {
        let v = self.views();
        if !((v.color && views.color) || (v.normals && views.normals) || (v.depth && views.depth)) {
            return false;
        }
        let transformed = compiled.objects.iter().any(|o| o.xf.is_some());
        match self {
            Mistake::AngleInterpolated => compiled.camera.perspective,
            Mistake::OrthographicTminZero => !compiled.camera.perspective,
            Mistake::NormalByM => {
                transformed && settings.normal_transform == NormalTransform::Correct
            }
            Mistake::NormalNotNormalized => transformed,
            Mistake::DepthNotRescaled => {
                transformed && settings.object_rays != ObjectRays::NormalizedNoRescale
            }
            Mistake::BackFacesLit | Mistake::BackFacesFlippedWithoutShadeBack => {
                !settings.shade_back
            }
            Mistake::ShadeBackAbsolute => settings.shade_back,
            Mistake::AmbientNotTimesDiffuse | Mistake::AmbientTimesDiffuseTwice => {
                compiled.ambient != Vec3::ZERO
            }
            Mistake::BackgroundNotBlack => compiled.background != Vec3::ZERO,
            Mistake::MatrixCourseSide | Mistake::RotateAxisAsWritten => {
                scene_with(scene, Variant::one(self)).is_some()
            }
            Mistake::PixelCorners
            | Mistake::RowsFlipped
            | Mistake::Rounding
            | Mistake::DepthNotClamped => true,
        }
    }

    /// Whether the mistake changes the scene itself (its transforms), so a variant needs its
    /// own compiled scene from [`scene_with`].
    pub fn changes_scene(self) -> bool {
        matches!(
            self,
            Mistake::MatrixCourseSide | Mistake::RotateAxisAsWritten
        )
    }
}

/// One or more mistakes made at once (a diagnosis tries one, then pairs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Variant(u32);

impl Variant {
    pub fn one(m: Mistake) -> Variant {
        Variant(m.bit())
    }

    pub fn pair(a: Mistake, b: Mistake) -> Variant {
        Variant(a.bit() | b.bit())
    }

    pub fn has(self, m: Mistake) -> bool {
        self.0 & m.bit() != 0
    }

    /// The mistakes in catalogue order.
    pub fn mistakes(self) -> impl Iterator<Item = Mistake> {
        Mistake::ALL.into_iter().filter(move |m| self.has(*m))
    }

    pub fn changes_scene(self) -> bool {
        self.mistakes().any(Mistake::changes_scene)
    }
}

/// The scene as a program with the variant's transform mistakes would build it, or `None`
/// when those mistakes change none of its transforms.
pub fn scene_with(scene: &Scene, variant: Variant) -> Option<Scene> {
    let mut out = scene.clone();
    let mut changed = false;
    let ids: Vec<_> = out.graph.iter().map(|(id, _)| id).collect();
    for id in ids {
        let Some(node) = out.graph.get_mut(id) else {
            continue;
        };
        let NodeKind::Transform(ops) = &mut node.kind else {
            continue;
        };
        if variant.has(Mistake::RotateAxisAsWritten) {
            for op in ops.iter_mut() {
                if let TransformOp::Rotate { axis, degrees } = *op
                    && (axis.length() - 1.0).abs() > 1e-6
                {
                    *op = TransformOp::Matrix(rotation_as_written(axis, degrees));
                    changed = true;
                }
            }
        }
        if variant.has(Mistake::MatrixCourseSide)
            && ops.len() > 1
            && let Some(m) = course_side_composition(ops)
        {
            *ops = vec![TransformOp::Matrix(m)];
            changed = true;
        }
    }
    changed.then_some(out)
}

/// The course's axis rotation with the axis used as written: Rodrigues' matrix for a unit
/// axis, which for |axis| ≠ 1 is a rotation and a scale.
fn rotation_as_written(a: Vec3, degrees: f32) -> Mat4 {
    let (s, c) = degrees.to_radians().sin_cos();
    let k = 1.0 - c;
    let (x, y, z) = (a.x, a.y, a.z);
    // Columns of the row-major course matrix.
    Mat4::from_cols(
        glam::Vec4::new(k * x * x + c, k * x * y + z * s, k * x * z - y * s, 0.0),
        glam::Vec4::new(k * x * y - z * s, k * y * y + c, k * y * z + x * s, 0.0),
        glam::Vec4::new(k * x * z + y * s, k * y * z - x * s, k * z * z + c, 0.0),
        glam::Vec4::W,
    )
}

/// The ops composed as the course parser does: M = M·T for each op in order, but
/// M = T·M for `Matrix`; `None` where that is the same as tracelab's order.
fn course_side_composition(ops: &[TransformOp]) -> Option<Mat4> {
    let first_matrix = ops
        .iter()
        .position(|op| matches!(op, TransformOp::Matrix(_)))?;
    // A Matrix first in the list composes the same on either side.
    if first_matrix == 0
        && ops
            .iter()
            .skip(1)
            .all(|op| !matches!(op, TransformOp::Matrix(_)))
    {
        return None;
    }
    let mut m = Mat4::IDENTITY;
    for op in ops {
        m = match op {
            TransformOp::Matrix(t) => *t * m,
            other => m * other.matrix(),
        };
    }
    Some(m)
}

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
    let color = shade(scene, s, v, &ray, &hit, normal);
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
    let rule = if v.has(Mistake::NormalByM) {
        NormalTransform::Incorrect
    } else {
        s.normal_transform
    };
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

/// The lecture's diffuse shading with the variant's shading mistakes.
fn shade(
    scene: &CompiledScene,
    s: &RenderSettings,
    v: Variant,
    ray: &Ray,
    hit: &Hit,
    normal: Vec3,
) -> Vec3 {
    let kd = scene.hit_color(hit);
    let mut n = normal;
    let back = ray.direction.dot(normal) > 0.0;
    let absolute = back && s.shade_back && v.has(Mistake::ShadeBackAbsolute);
    if back && !absolute {
        if s.shade_back || v.has(Mistake::BackFacesFlippedWithoutShadeBack) {
            n = -normal;
        } else if !v.has(Mistake::BackFacesLit) {
            return Vec3::ZERO;
        }
    }
    let mut c = if v.has(Mistake::AmbientNotTimesDiffuse) {
        scene.ambient
    } else if v.has(Mistake::AmbientTimesDiffuseTwice) {
        scene.ambient * kd * kd
    } else {
        scene.ambient * kd
    };
    for &(l, color) in &scene.lights {
        let d = l.dot(n);
        let d = if absolute { d.abs() } else { d.max(0.0) };
        c += d * color * kd;
    }
    c
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
    fn names_round_trip_and_are_distinct() {
        for m in Mistake::ALL {
            assert_eq!(Mistake::from_name(m.name()), Some(m));
            assert!(!m.explanation().is_empty() && !m.rule().is_empty());
        }
        let mut names: Vec<_> = Mistake::ALL.iter().map(|m| m.name()).collect();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), Mistake::ALL.len());
    }

    #[test]
    fn a_pair_holds_both_mistakes_in_catalogue_order() {
        let v = Variant::pair(Mistake::Rounding, Mistake::PixelCorners);
        assert_eq!(
            v.mistakes().collect::<Vec<_>>(),
            [Mistake::PixelCorners, Mistake::Rounding]
        );
        assert!(!v.has(Mistake::NormalByM));
    }

    #[test]
    fn a_unit_axis_rotates_as_glam_does_and_a_long_one_also_scales() {
        let a = rotation_as_written(Vec3::Z, 90.0);
        assert!(a.abs_diff_eq(Mat4::from_rotation_z(90f32.to_radians()), 1e-6));
        let b = rotation_as_written(Vec3::new(0.0, 0.0, 2.0), 0.0);
        // cos 0 = 1, k = 0: the identity whatever the axis; at 180° z² k + c = 4·2 − 1 = 7.
        assert!(b.abs_diff_eq(Mat4::IDENTITY, 1e-6));
        let c = rotation_as_written(Vec3::new(0.0, 0.0, 2.0), 180.0);
        assert!((c.z_axis.z - 7.0).abs() < 1e-5, "{c}");
    }

    #[test]
    fn the_course_puts_matrix_on_the_other_side() {
        let t = Mat4::from_translation(Vec3::Y);
        let ops = [TransformOp::UniformScale(2.0), TransformOp::Matrix(t)];
        let m = course_side_composition(&ops).expect("differs");
        // Course: M = T·S, so the origin goes to (0, 1, 0), not (0, 2, 0).
        assert!((m.transform_point3(Vec3::ZERO) - Vec3::Y).length() < 1e-6);
        assert_eq!(course_side_composition(&[TransformOp::Matrix(t)]), None);
    }

    #[test]
    fn rounding_differs_from_truncating_only_past_the_half() {
        assert_eq!(byte(0.5 / 255.0, false), 0);
        assert_eq!(byte(0.5 / 255.0, true), 1);
        assert_eq!(byte(f32::NAN, true), 0);
        assert_eq!(byte(2.0, true), 255);
    }
}
