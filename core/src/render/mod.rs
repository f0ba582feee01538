//! Rendering: camera rays, the compiled (render-ready) scene, shading, the colour, normal
//! and depth views, and the progressive, cancellable driver.

mod camera;
mod coarse;
mod compile;
pub mod csg;
mod cull;
pub mod film;
pub mod filter;
mod frame;
mod grid_data;
mod grid_scene;
mod inspect;
mod limits;
pub mod mistakes;
mod object_rays;
mod occlusion;
mod plan;
mod progressive;
mod rule_gap;
mod rules;
pub mod sampling;
mod shade;
mod shade_lanes;
mod shape;
mod shared_frame;
mod similitude;
pub mod texture;
mod whitted;

pub use camera::CameraRays;
pub use coarse::CoarseFrame;
pub use compile::{CompiledScene, Hit, Object, PointLight, Shape};
pub use film::{Film, FilmError, Picture, Supersampling, check_film, filter_picture};
pub use filter::{Filter, FilterError};
pub use frame::{Frame, Sample, View, depth_shade, quantize};
pub use grid_data::{GridScene, RayCounts};
pub use grid_scene::{GridError, GridWalk, grid_cell_color, visualize_grid};
pub use inspect::{HitStory, PathStep, RayStory, inspect_pixel};
pub use limits::{ImageSizeError, MAX_IMAGE_PIXELS, MAX_IMAGE_SIDE, check_image_size};
pub use mistakes::{Mistake, Variant};
pub use object_rays::{ObjectRays, ObjectT};
pub use plan::{Cancel, Cancelled, Passes, RenderPlan, Tracing, Uncancellable};
pub use progressive::{PassInfo, render, render_frame, try_render_frame};
pub use rule_gap::{NormalGap, normal_rule_gap};
pub use rules::{Ambient, Rules};
pub use sampling::{DEFAULT_SEED, Sampler, SamplerError, SamplerKind};
pub use shade::{LightTerm, ShadeInfo, shade_hit};
pub use shared_frame::{FrameGuard, SharedFrame, ShownPixels};
pub use similitude::{Breaks, SimilitudeTest, similitude, similitude_within};
pub use whitted::{
    Blocker, Cut, LightShare, MAX_BOUNCES, MAX_SECONDARY_RAYS, RayKind, RayNode, SECONDARY_T_MIN,
    Secondary, ShadowQuery, ShadowRay, needs_whitted, ray_tree, transmitted,
};

/// How world normals are obtained from object-space ones under a Transform.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum NormalTransform {
    /// (M⁻¹)ᵀ · n, normalised: stays perpendicular to the surface under any affine M.
    #[default]
    Correct,
    /// M · n, normalised: the lecture's "incorrect normal transformation"; wrong under
    /// non-uniform scale and shear, right for rotations and uniform scale.
    Incorrect,
}

impl NormalTransform {
    /// An object-space normal in world space by this rule, normalised; `None` (no transform)
    /// leaves it as it is. The one place the lecture's two rules are written.
    #[inline]
    pub fn apply(self, xf: Option<&crate::geometry::Transform>, n: glam::Vec3) -> glam::Vec3 {
        match (xf, self) {
            (None, _) => n,
            (Some(xf), NormalTransform::Correct) => xf.normal_by_inverse_transpose(n),
            (Some(xf), NormalTransform::Incorrect) => xf.normal_by_m(n),
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    /// Flip back-facing normals toward the eye before shading (`-shade_back`); without it a
    /// back-facing hit is black.
    pub shade_back: bool,
    pub normal_transform: NormalTransform,
    /// How rays are moved into object space, and which t is kept (the lecture's "what to do
    /// about the depth t").
    pub object_rays: ObjectRays,
    /// A known student mistake (or two) to render instead of the course's image, for
    /// `tracelab diff`'s diagnosis; `None` is the course's render.
    pub variant: Option<Variant>,
    /// Shadows, reflection and refraction (assignment 4) and the specular fix (assignment 3).
    pub secondary: Secondary,
    /// Assignment 7: after its full-resolution pass, a progressive render traces these
    /// samples and filters them into the colours (`None`: one ray a pixel).
    pub supersample: Option<Supersampling>,
}

impl RenderSettings {
    pub fn new(width: u32, height: u32) -> Self {
        RenderSettings {
            width,
            height,
            shade_back: false,
            normal_transform: NormalTransform::Correct,
            object_rays: ObjectRays::Unnormalized,
            variant: None,
            secondary: Secondary::default(),
            supersample: None,
        }
    }
}

/// Compiles a scene for rendering (flattens transforms, resolves materials, builds the
/// top-level BVH).
pub fn compile(scene: &crate::Scene) -> CompiledScene {
    CompiledScene::new(scene)
}
