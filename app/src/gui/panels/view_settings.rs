//! What the render view shows: the tab, the compare mode and its split line, the normal and
//! depth-t rules, shade back, the depth range and the render size. Plain data; the view bar
//! (`view_bar.rs`) edits it and the view (`viewport.rs`) draws what it asks for.

use tracelab_core::render::Secondary;
use tracelab_core::{NormalTransform, ObjectRays, View};

use crate::gui::gizmo::Axes;

#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Tab {
    Color,
    Normals,
    Depth,
    All,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Compare {
    Off,
    SideBySide,
    Split,
}

/// Which way the split compare's line runs. A vertical line puts the correct rule on the
/// left; a horizontal one puts it above, so objects placed side by side are each cut in two
/// and seen under both rules.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SplitLine {
    Vertical,
    Horizontal,
}

/// The render view's settings. Three are kept between runs (`gui/settings.rs`): the tab,
/// shade back and the depth range; the others start at their defaults every run.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewSettings {
    pub tab: Tab,
    pub compare: Compare,
    pub normal_transform: NormalTransform,
    /// How rays enter object space and which t is kept (the lecture's depth question).
    pub object_rays: ObjectRays,
    pub shade_back: bool,
    pub depth: (f32, f32),
    /// `None`: follow the view's size in pixels.
    pub fixed_size: Option<(u32, u32)>,
    /// Split position in compare-split mode, 0..1 from the left (or from the top).
    pub split: f32,
    pub split_line: SplitLine,
    /// The gizmo's arrows along the world's axes or the Translate's own.
    pub gizmo_axes: Axes,
    /// Draw the gizmo and the overlays (outline, axes, lights).
    pub overlays: bool,
    /// Shadows, bounces, weight and the specular fix (View › Rays); the course's defaults.
    pub secondary: Secondary,
    /// Assignment 7's sampler and filter (View › Supersampling); `None`: one ray a pixel.
    pub supersample: Option<tracelab_core::render::Supersampling>,
}

impl Default for ViewSettings {
    fn default() -> Self {
        ViewSettings {
            tab: Tab::Color,
            compare: Compare::Off,
            normal_transform: NormalTransform::Correct,
            object_rays: ObjectRays::Unnormalized,
            shade_back: false,
            depth: (8.0, 18.0),
            fixed_size: None,
            split: 0.5,
            split_line: SplitLine::Vertical,
            gizmo_axes: Axes::World,
            overlays: true,
            secondary: Secondary::default(),
            supersample: None,
        }
    }
}

/// The depth-t rules as the view bar names them.
pub fn object_rays_label(r: ObjectRays) -> &'static str {
    match r {
        ObjectRays::Unnormalized => "unnormalised: t_OS = t_WS",
        ObjectRays::Normalized => "normalised, t rescaled",
        ObjectRays::NormalizedNoRescale => "normalised, t not rescaled (bug)",
    }
}

impl ViewSettings {
    /// The renders needed: one, or both rules when comparing.
    pub fn modes(&self) -> Vec<NormalTransform> {
        match self.compare {
            Compare::Off => vec![self.normal_transform],
            _ => vec![NormalTransform::Correct, NormalTransform::Incorrect],
        }
    }

    /// (frame index, view, caption) for each image cell.
    pub fn cells(&self) -> Vec<(usize, View, &'static str)> {
        let single = match self.tab {
            Tab::Color => View::Color,
            Tab::Normals | Tab::All => View::Normals,
            Tab::Depth => View::Depth,
        };
        match (self.compare, self.tab) {
            (Compare::Off, Tab::All) => {
                vec![
                    (0, View::Color, "Colour"),
                    (0, View::Normals, "Normals"),
                    (0, View::Depth, "Depth"),
                ]
            }
            (Compare::Off, _) => vec![(0, single, "")],
            (Compare::SideBySide, _) => vec![
                (0, single, "Correct: (M^-1)^T n"),
                (1, single, "Incorrect: M n"),
            ],
            // Split draws both frames into one cell.
            (Compare::Split, _) => vec![(
                0,
                single,
                match self.split_line {
                    SplitLine::Vertical => "Correct (left) | Incorrect (right)",
                    SplitLine::Horizontal => "Correct (above the line) | Incorrect (below)",
                },
            )],
        }
    }
}
