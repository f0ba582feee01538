//! The in-memory scene: camera, lights, background, materials and the object graph.
//! Plain data: the parser builds it, the writer prints it, the GUI edits it, the renderer
//! compiles a snapshot of it.

mod comments;
mod field;
mod graph;
mod mesh;
mod phong;
mod texture;
mod transform;
pub mod validate;
pub mod walk;
pub mod words;

pub use comments::{Anchor, Comments, SceneComments};
pub use field::Field;
pub use graph::{CsgOp, Graph, Node, NodeId, NodeKind};
pub use mesh::{Mesh, MeshSlot, NotClosed, check_closed};
pub use phong::{PHONG_FIELDS, Phong, PhongField, phong_field};
pub use texture::{MAX_OCTAVES, SolidTexture, TextureKind};
pub use transform::{TransformOp, compose, compose_f64, op_matrix_f64, unit};
pub use validate::{Invalid, Place, Problem, SingularTransform, check_scene};
pub use walk::{Visit, Walk};

use glam::Vec3;

#[derive(Clone, Debug, PartialEq)]
pub enum Camera {
    Orthographic {
        center: Vec3,
        direction: Vec3,
        up: Vec3,
        size: f32,
    },
    /// `angle` is the full field of view in degrees.
    Perspective {
        center: Vec3,
        direction: Vec3,
        up: Vec3,
        angle: f32,
    },
}

impl Default for Camera {
    fn default() -> Self {
        Camera::Perspective {
            center: Vec3::new(0.0, 0.0, 10.0),
            direction: Vec3::NEG_Z,
            up: Vec3::Y,
            angle: 30.0,
        }
    }
}

impl Camera {
    pub fn center(&self) -> Vec3 {
        match self {
            Camera::Orthographic { center, .. } | Camera::Perspective { center, .. } => *center,
        }
    }
    pub fn direction(&self) -> Vec3 {
        match self {
            Camera::Orthographic { direction, .. } | Camera::Perspective { direction, .. } => {
                *direction
            }
        }
    }
    pub fn up(&self) -> Vec3 {
        match self {
            Camera::Orthographic { up, .. } | Camera::Perspective { up, .. } => *up,
        }
    }
}

/// Where a light's light comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightKind {
    /// `DirectionalLight`: `direction` points from the light into the scene.
    Directional { direction: Vec3 },
    /// `PointLight` (assignment 4): the colour reaching a point at distance d is
    /// colour / (c + l·d + q·d²) with `attenuation` = (c, l, q); absent in the file means the
    /// course's (1, 0, 0), kept absent so a round trip writes the same text.
    Point {
        position: Vec3,
        attenuation: Option<Vec3>,
    },
}

/// The course's default point-light attenuation: constant 1, no fall-off.
pub const DEFAULT_ATTENUATION: Vec3 = Vec3::new(1.0, 0.0, 0.0);

#[derive(Clone, Debug, PartialEq)]
pub struct Light {
    pub kind: LightKind,
    pub color: Vec3,
    pub comments: Comments,
}

impl Light {
    /// A directional light.
    pub fn new(direction: Vec3, color: Vec3) -> Self {
        Light {
            kind: LightKind::Directional { direction },
            color,
            comments: Comments::default(),
        }
    }

    /// A point light with the attenuation the file gives (None: the course's default).
    pub fn point(position: Vec3, color: Vec3, attenuation: Option<Vec3>) -> Self {
        Light {
            kind: LightKind::Point {
                position,
                attenuation,
            },
            color,
            comments: Comments::default(),
        }
    }

    /// The direction of a directional light (None for a point light).
    pub fn direction(&self) -> Option<Vec3> {
        match self.kind {
            LightKind::Directional { direction } => Some(direction),
            LightKind::Point { .. } => None,
        }
    }

    /// The file's keyword for this light.
    pub fn keyword(&self) -> &'static str {
        match self.kind {
            LightKind::Directional { .. } => "DirectionalLight",
            LightKind::Point { .. } => "PointLight",
        }
    }
}

/// `Background { color ambientLight }`; either field may be absent in a file, and absent
/// fields are kept absent so a round trip writes the same text.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Background {
    pub color: Option<Vec3>,
    pub ambient: Option<Vec3>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MaterialKeyword {
    /// `Material { diffuseColor ... }` (assignment 2)
    Material,
    /// `PhongMaterial { diffuseColor ... }` (assignment 1 files)
    PhongMaterial,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub diffuse: Vec3,
    pub keyword: MaterialKeyword,
    /// Every field but diffuseColor, in the file's order, for the writer: the course's
    /// Phong fields (`phong.rs`: specularColor, exponent, reflectiveColor, transparentColor,
    /// indexOfRefraction), read through [`Material::phong`], and any other name, which the
    /// reader warns about by name and the renderer does not use.
    pub extra: Vec<(String, Vec<f32>)>,
    /// A solid texture (`Checkerboard`, `Noise`, `Marble`, `Wood`): its colours and Phong
    /// terms come from the two materials it names, so `diffuse` is zero and `extra` empty.
    pub texture: Option<SolidTexture>,
    pub comments: Comments,
}

impl Material {
    pub fn diffuse(diffuse: Vec3) -> Self {
        Material {
            diffuse,
            keyword: MaterialKeyword::Material,
            extra: Vec::new(),
            texture: None,
            comments: Comments::default(),
        }
    }

    /// A texture material (its own diffuse colour unused, zero).
    pub fn textured(texture: SolidTexture) -> Self {
        Material {
            texture: Some(texture),
            ..Material::diffuse(Vec3::ZERO)
        }
    }
}

/// What objects render with when no `MaterialIndex` applies to them.
pub const DEFAULT_MATERIAL_COLOR: Vec3 = Vec3::new(0.8, 0.8, 0.8);

#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    pub camera: Camera,
    /// `None` when the file has no `Lights` block: then the scene is shown flat in its
    /// diffuse colours (ambient 1), as the course's assignment 1 does.
    pub lights: Option<Vec<Light>>,
    pub background: Background,
    pub materials: Vec<Material>,
    pub graph: Graph,
    /// `#` comments of the top-level blocks and the end of the file (the others are on the
    /// nodes, lights and materials they were written next to).
    pub comments: SceneComments,
}

impl Default for Scene {
    fn default() -> Self {
        Scene {
            camera: Camera::default(),
            lights: Some(Vec::new()),
            background: Background::default(),
            materials: Vec::new(),
            graph: Graph::new(),
            comments: SceneComments::default(),
        }
    }
}

impl Scene {
    pub fn background_color(&self) -> Vec3 {
        self.background.color.unwrap_or(Vec3::ZERO)
    }

    /// The ambient light shading uses: (1,1,1) without a Lights block (assignment-1 flat look).
    pub fn effective_ambient(&self) -> Vec3 {
        match self.lights {
            None => Vec3::ONE,
            Some(_) => self.background.ambient.unwrap_or(Vec3::ZERO),
        }
    }

    pub fn lights(&self) -> &[Light] {
        self.lights.as_deref().unwrap_or(&[])
    }
}

/// The first part of a scene that would not read back the same after writing it: `part`
/// is "the camera", "the lights", "the background", "the materials", "the objects" or "the
/// comments".
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{part} would read back differently")]
pub struct ReadsBackDifferently {
    pub part: &'static str,
}

impl Scene {
    /// Whether `back` (this scene written and read again) is the same document: the graph
    /// compacted, every material a list continues spelt out, meshes compared by file name
    /// (whether one loads depends on the disk, not on the text), comments as the same lines
    /// (the writer may move one whose field is gone to the end of its block). `Err` names
    /// the first part that differs.
    pub fn reads_back_as(&self, back: &Scene) -> Result<(), ReadsBackDifferently> {
        let (a, a_lines) = self.normalised();
        let (b, b_lines) = back.normalised();
        let parts = [
            ("the camera", a.camera == b.camera),
            ("the lights", a.lights == b.lights),
            ("the background", a.background == b.background),
            ("the materials", a.materials == b.materials),
            ("the objects", a.graph == b.graph),
            ("the comments", a_lines == b_lines),
        ];
        match parts.iter().find(|(_, same)| !same) {
            Some((part, _)) => Err(ReadsBackDifferently { part }),
            None => Ok(()),
        }
    }

    fn normalised(&self) -> (Scene, Vec<String>) {
        let mut s = self.clone();
        let mut lines = Vec::new();
        let mut take = |c: &mut Comments| lines.extend(std::mem::take(c).lines().cloned());
        let sc = &mut s.comments;
        for c in [
            &mut sc.camera,
            &mut sc.lights,
            &mut sc.background,
            &mut sc.materials,
        ] {
            take(c);
        }
        take(&mut Comments {
            end: std::mem::take(&mut sc.end),
            ..Comments::default()
        });
        for l in s.lights.iter_mut().flatten() {
            take(&mut l.comments);
        }
        for m in &mut s.materials {
            take(&mut m.comments);
        }
        s.graph = s.graph.with_listed_materials().compacted();
        for id in s.graph.preorder() {
            let n = s.graph.node_mut(id);
            take(&mut n.comments);
            if let NodeKind::TriangleMesh { mesh, .. } = &mut n.kind {
                *mesh = MeshSlot::Unresolved;
            }
        }
        lines.sort();
        (s, lines)
    }
}
