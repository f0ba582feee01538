//! The catalogue itself: each mistake's name, what it draws, the course rule it breaks, the
//! images it can change and a cheap test of whether it can change a given picture.

use glam::Vec3;

use super::transforms::course_parser_scene;
use crate::render::compile::CompiledScene;
use crate::render::{NormalTransform, ObjectRays, RenderSettings};
use crate::scene::Scene;

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
    // Assignments 3 and 4.
    ReflectionVector,
    SpecularBehind,
    ShadowAcne,
    AmbientDroppedInShadow,
    TransparentCastsNoShadow,
    IndexNotInverted,
    TotalInternalReflectionTransmitted,
    WeightIgnored,
}

/// Which images a mistake can change.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Views {
    pub color: bool,
    pub normals: bool,
    pub depth: bool,
}

impl Mistake {
    pub const ALL: [Mistake; 25] = [
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
        Mistake::ReflectionVector,
        Mistake::SpecularBehind,
        Mistake::ShadowAcne,
        Mistake::AmbientDroppedInShadow,
        Mistake::TransparentCastsNoShadow,
        Mistake::IndexNotInverted,
        Mistake::TotalInternalReflectionTransmitted,
        Mistake::WeightIgnored,
    ];

    /// The mistakes of assignments 3 and 4 (Phong, shadows, reflection, refraction): they
    /// change only pictures with highlights, shadow rays or secondary rays.
    pub const ASSIGNMENTS_3_4: [Mistake; 8] = [
        Mistake::ReflectionVector,
        Mistake::SpecularBehind,
        Mistake::ShadowAcne,
        Mistake::AmbientDroppedInShadow,
        Mistake::TransparentCastsNoShadow,
        Mistake::IndexNotInverted,
        Mistake::TotalInternalReflectionTransmitted,
        Mistake::WeightIgnored,
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
            Mistake::ReflectionVector => "reflection-vector",
            Mistake::SpecularBehind => "specular-behind",
            Mistake::ShadowAcne => "shadow-acne",
            Mistake::AmbientDroppedInShadow => "ambient-dropped-in-shadow",
            Mistake::TransparentCastsNoShadow => "transparent-casts-no-shadow",
            Mistake::IndexNotInverted => "index-not-inverted",
            Mistake::TotalInternalReflectionTransmitted => "tir-transmitted",
            Mistake::WeightIgnored => "weight-ignored",
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
            Mistake::ReflectionVector => {
                "the highlight as Phong's (R·V)^e, R the light's mirror direction, instead of Blinn's (N·H)^e"
            }
            Mistake::SpecularBehind => {
                "the specular term kept where N·L ≤ 0 (highlights on the side facing away from the light)"
            }
            Mistake::ShadowAcne => {
                "shadow rays start at t_min 0: a surface shadows itself in speckles (shadow acne)"
            }
            Mistake::AmbientDroppedInShadow => {
                "the ambient term dropped where a shadow ray is blocked (shadows drawn black)"
            }
            Mistake::TransparentCastsNoShadow => {
                "shadow rays pass through transparent objects (they cast no shadow)"
            }
            Mistake::IndexNotInverted => {
                "refraction always from index 1 into n: the index not inverted when the ray leaves"
            }
            Mistake::TotalInternalReflectionTransmitted => {
                "on total internal reflection the transmitted ray is traced along the mirror direction (times the transparent colour) instead of none"
            }
            Mistake::WeightIgnored => {
                "-weight ignored: rays whose weight is below the cut-off are traced"
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
            Mistake::ReflectionVector => {
                "the handout's Blinn-Torrance highlight: k_s·(N·H)^e with H = normalize(L − d)"
            }
            Mistake::SpecularBehind => {
                "the specular term is 0 where N·L ≤ 0 (or, with the optional fix, times max(N·L, 0))"
            }
            Mistake::ShadowAcne => "a shadow ray starts at the hit point with t_min = epsilon",
            Mistake::AmbientDroppedInShadow => {
                "in shadow only the light's diffuse and specular terms go: ambient·k_d stays"
            }
            Mistake::TransparentCastsNoShadow => {
                "transparent objects cast opaque shadows (semi-transparent shadows are extra credit)"
            }
            Mistake::IndexNotInverted => {
                "N·d > 0 means the ray leaves: index n into 1, with the normal flipped"
            }
            Mistake::TotalInternalReflectionTransmitted => {
                "on total internal reflection nothing is transmitted, and no reflected ray is added beyond reflectiveColor's"
            }
            Mistake::WeightIgnored => {
                "a ray whose weight (parent's × |colour|) is below -weight is not traced"
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
            Mistake::ReflectionVector
            | Mistake::SpecularBehind
            | Mistake::ShadowAcne
            | Mistake::AmbientDroppedInShadow
            | Mistake::TransparentCastsNoShadow
            | Mistake::IndexNotInverted
            | Mistake::TotalInternalReflectionTransmitted
            | Mistake::WeightIgnored => only(true, false, false),
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
        let sec = &settings.secondary;
        let lit = !compiled.lights.is_empty() || !compiled.point_lights.is_empty();
        let specular = lit && compiled.phong.iter().any(|p| p.specular != Vec3::ZERO);
        let transparent = compiled.phong.iter().any(|p| p.transparent != Vec3::ZERO);
        // Refraction bends only across a change of index; leaving takes a second level.
        let refracting =
            |p: &crate::scene::Phong| p.transparent != Vec3::ZERO && p.index_of_refraction != 1.0;
        let leaves = sec.bounces >= 2 && compiled.phong.iter().any(refracting);
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
            Mistake::ReflectionVector => specular,
            Mistake::SpecularBehind => specular && !sec.specular_fix,
            Mistake::ShadowAcne => sec.shadows && lit,
            Mistake::AmbientDroppedInShadow => sec.shadows && lit && compiled.ambient != Vec3::ZERO,
            Mistake::TransparentCastsNoShadow => sec.shadows && lit && transparent,
            Mistake::IndexNotInverted => leaves,
            // Past the critical angle leaving (n > 1), or entering an index below 1.
            Mistake::TotalInternalReflectionTransmitted => {
                leaves
                    || (sec.bounces >= 1
                        && compiled
                            .phong
                            .iter()
                            .any(|p| refracting(p) && p.index_of_refraction < 1.0))
            }
            Mistake::WeightIgnored => {
                sec.weight > 0.0
                    && sec.bounces >= 1
                    && compiled
                        .phong
                        .iter()
                        .any(|p| p.reflective != Vec3::ZERO || p.transparent != Vec3::ZERO)
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
pub struct Variant(pub(super) u32);

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
    course_parser_scene(
        scene,
        variant.has(Mistake::RotateAxisAsWritten),
        variant.has(Mistake::MatrixCourseSide),
    )
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
}
