//! The Lecture menu: the figures of `scenes/lecture/`, each with its caption, the view it
//! needs (tab, normal rule, depth-t rule, compare, the rays of assignments 3–4 and
//! shade-back) and two lines on what to look at.

use std::path::PathBuf;

use tracelab_core::render::Secondary;
use tracelab_core::{NormalTransform, ObjectRays};

use crate::gui::panels::viewport::{Compare, SplitLine, Tab, ViewSettings};

pub struct Figure {
    /// File name in scenes/lecture/.
    pub file: &'static str,
    /// The menu entry: the figure's caption.
    pub caption: &'static str,
    /// What to look at, two lines.
    pub look: [&'static str; 2],
    pub tab: Tab,
    pub compare: Compare,
    /// Which way a split compare's line runs (through the figure's objects).
    pub split_line: SplitLine,
    pub normal_transform: NormalTransform,
    pub object_rays: ObjectRays,
    /// The depth view's range, where the figure uses it.
    pub depth: Option<(f32, f32)>,
    /// View › Rays as the figure opens: the course's defaults (none) but for the bounce
    /// figures, which open at their last bounce count.
    pub secondary: Secondary,
    /// The bounce figures see the inside of glass, so they shade back faces (`-shade_back`).
    pub shade_back: bool,
}

const fn fig(file: &'static str, caption: &'static str, look: [&'static str; 2]) -> Figure {
    Figure {
        file,
        caption,
        look,
        tab: Tab::Color,
        compare: Compare::Off,
        split_line: SplitLine::Vertical,
        normal_transform: NormalTransform::Correct,
        object_rays: ObjectRays::Unnormalized,
        depth: None,
        secondary: Secondary::NONE,
        shade_back: false,
    }
}

/// A bounce figure: opened with `-shadows -shade_back -bounces last -weight 0.01`, as its
/// scene's header says; the caption's second line tells how to step the bounces.
const fn bounces(
    file: &'static str,
    caption: &'static str,
    first: &'static str,
    last: u32,
    step: &'static str,
) -> Figure {
    Figure {
        secondary: Secondary {
            shadows: true,
            bounces: last,
            weight: 0.01,
            ..Secondary::NONE
        },
        shade_back: true,
        ..fig(file, caption, [first, step])
    }
}

pub static FIGURES: &[Figure] = &[
    fig(
        "simple_scene.txt",
        "A simple scene description",
        [
            "Camera, one light, background, three materials, four spheres.",
            "Open the tree: every part of the file is a node.",
        ],
    ),
    fig(
        "class_hierarchy.txt",
        "The class hierarchy",
        [
            "Materials set at three levels of Groups land where the slide says.",
            "Select a Group to see what its children inherit.",
        ],
    ),
    fig(
        "class_hierarchy_transforms.txt",
        "The class hierarchy with transforms",
        [
            "The blue cross turned by ZRotate 45, the brown group moved left.",
            "Drag the ops in the inspector: the whole subtree follows.",
        ],
    ),
    fig(
        "nested_transforms.txt",
        "Nested transforms",
        [
            "Each Transform applies to everything inside it: the first op listed is applied last.",
            "flat_transforms.txt lists the same ops in one Transform: the same image.",
        ],
    ),
    fig(
        "flat_transforms.txt",
        "Nested transforms, flattened",
        [
            "One Transform per object with the chain's ops in order.",
            "The same image as the nested version, pixel for pixel.",
        ],
    ),
    Figure {
        tab: Tab::Normals,
        ..fig(
            "normals.txt",
            "Normal visualisation",
            [
                "|n_x| |n_y| |n_z| as RGB: the floor is pure green (n = +y).",
                "A face's colour says which way it points.",
            ],
        )
    },
    // The sphere and the box sit side by side, so the line runs across both: each is seen
    // under both rules (a vertical line gave one object to each rule).
    Figure {
        compare: Compare::Split,
        split_line: SplitLine::Horizontal,
        ..fig(
            "normal_transform.txt",
            "Incorrect vs correct normal transformation",
            [
                "Above the yellow line (M^-1)^T·n, below it M·n: below, the shading slides off the sheared shapes.",
                "Click a pixel: the Ray panel draws both normals; the view bar gives their largest angle.",
            ],
        )
    },
    fig(
        "shading_light_only.txt",
        "Diffuse shading, light only",
        [
            "c = max(L·N, 0)·c_light·k_d with no ambient: the unlit sides are black.",
            "Click a pixel: the terms of the sum are listed.",
        ],
    ),
    fig(
        "shading_half_ambient.txt",
        "Diffuse shading with ambient",
        [
            "c_light = c_ambient = 0.5: the unlit sides show half the colour.",
            "Nothing is brighter than k_d itself.",
        ],
    ),
    fig(
        "perspective.txt",
        "A perspective camera",
        [
            "Equal spheres shrink with distance; the floor recedes to a horizon.",
            "Click near and far spheres: the world rays fan out from the eye.",
        ],
    ),
    fig(
        "cube_mesh.txt",
        "A triangle mesh",
        [
            "The cube from an OBJ file, 12 triangles, flat-shaded faces.",
            "No cracks along the triangles' shared edges.",
        ],
    ),
    fig(
        "csg_union.txt",
        "CSG: union",
        [
            "A or B: each part keeps its sphere's material.",
            "Click where they meet: the story names the operand hit.",
        ],
    ),
    fig(
        "csg_intersection.txt",
        "CSG: intersection",
        [
            "A and B: the lens both spheres share.",
            "Its faces come from both spheres.",
        ],
    ),
    Figure {
        tab: Tab::All,
        ..fig(
            "csg_subtraction.txt",
            "CSG: subtraction",
            [
                "A minus B: the bite is B's surface, its normals turned toward the viewer.",
                "Compare the colour and normal images of the bite.",
            ],
        )
    },
    fig(
        "csg_die.txt",
        "A CSG die",
        [
            "A rounded cube (cube and sphere) minus six spheres for the pips.",
            "Select an operand in the tree and drag it: the pits move.",
        ],
    ),
    Figure {
        object_rays: ObjectRays::NormalizedNoRescale,
        tab: Tab::All,
        depth: Some((2.0, 18.0)),
        ..fig(
            "depth_t.txt",
            "What to do about the depth t",
            [
                "Shown with the classic bug: M^-1 d normalised and t not rescaled, so the big blue sphere jumps in front.",
                "Switch 'depth t' to unnormalised or normalised (t rescaled): the small red sphere is in front again.",
            ],
        )
    },
    bounces(
        "bounces_mirrors.txt",
        "Bounces: mirrors",
        "A chrome ball between mirror walls: each bounce adds a level of reflections.",
        3,
        "View › Rays: step the bounces from 0 to 3 to see each level.",
    ),
    bounces(
        "bounces_glass_bars.txt",
        "Bounces: glass bars",
        "Three glass bars in a row: two bounces cross one bar (in, out), so each lets the eye through one more surface.",
        5,
        "View › Rays: step the bounces from 0 to 5 to see each level.",
    ),
    bounces(
        "bounces_gem.txt",
        "Bounces: a faceted gem",
        "A gem of index 2.4 under red, green and blue lights: light reflects inside it (total internal reflection) before it leaves.",
        5,
        "View › Rays: step the bounces from 0 to 5 to see each level.",
    ),
];

impl Figure {
    /// Where the scene file is: scenes/lecture/ under the working directory, else beside the
    /// sources tracelab was built from.
    pub fn path(&self) -> PathBuf {
        let here = PathBuf::from("scenes/lecture").join(self.file);
        if here.is_file() {
            return here;
        }
        PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/lecture")).join(self.file)
    }

    /// The view the figure needs (other settings kept).
    pub fn apply(&self, v: &mut ViewSettings) {
        v.tab = self.tab;
        v.compare = self.compare;
        if self.compare == Compare::Split {
            v.split_line = self.split_line;
            v.split = 0.5;
        }
        v.normal_transform = self.normal_transform;
        v.object_rays = self.object_rays;
        if let Some(d) = self.depth {
            v.depth = d;
        }
        v.secondary = self.secondary;
        v.shade_back = self.shade_back;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_lecture_scene_is_in_the_menu_once_and_every_entry_has_its_file() {
        let dir = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/lecture"));
        let mut files: Vec<String> = std::fs::read_dir(&dir)
            .expect("scenes/lecture")
            .filter_map(|e| e.ok()?.file_name().into_string().ok())
            .filter(|n| n.ends_with(".txt"))
            .collect();
        files.sort();
        let mut listed: Vec<String> = FIGURES.iter().map(|f| f.file.to_string()).collect();
        listed.sort();
        assert_eq!(files, listed);
        for f in FIGURES {
            assert!(f.path().is_file(), "{}", f.file);
        }
    }

    #[test]
    fn a_bounce_figure_opens_at_its_scene_s_command_line_and_says_how_far_to_step() {
        let bounce_figures: Vec<&Figure> =
            FIGURES.iter().filter(|f| f.secondary.bounces > 0).collect();
        assert_eq!(bounce_figures.len(), 3);
        for f in bounce_figures {
            let text = std::fs::read_to_string(f.path()).expect("scene");
            let line = format!(
                "-shadows -shade_back -bounces {} -weight {}",
                f.secondary.bounces, f.secondary.weight
            );
            assert!(text.contains(&line), "{}: {line}", f.file);
            assert!(f.shade_back && f.secondary.shadows, "{}", f.file);
            let step = format!(
                "View › Rays: step the bounces from 0 to {} to see each level",
                f.secondary.bounces
            );
            assert!(f.look[1].starts_with(&step), "{}: {:?}", f.file, f.look);
        }
    }
}
