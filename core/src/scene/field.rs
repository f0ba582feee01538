//! Which field a rule judges, by type: the rules in `validate/` name it, the parser turns
//! it into the place in the file, the editor's inspector shows the refusal beside the
//! widget that edits the same `Field` (never by comparing label text).

use std::borrow::Cow;

use super::NodeId;

#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Field {
    // A camera's, a light's and a node's (Sphere center, Plane normal, …).
    Center,
    Direction,
    Up,
    Angle,
    Size,
    Position,
    Color,
    Attenuation,
    AmbientLight,
    DiffuseColor,
    /// Another field of a material (Phong's, or one tracelab keeps without knowing), as
    /// the file names it.
    Material(String),
    /// A solid texture's own Transform (its ops together).
    TextureTransform,
    Octaves,
    Frequency,
    Amplitude,
    /// A texture's `materialIndex` line: 0 the first, 1 the second.
    TextureMaterial(usize),
    /// A Transform op, by its keyword (which one: the `op` beside the field).
    Op(&'static str),
    /// A Transform's ops together, or the chain of Transforms down to it.
    Ops,
    Radius,
    Normal,
    Offset,
    /// A Triangle's vertex 0, 1 or 2.
    Vertex(usize),
    ObjFile,
    Min,
    Max,
    /// The node's MaterialIndex.
    MaterialIndex,
    /// How many objects a Transform or CSG node holds.
    Children,
    /// One child at fault (for a CSG operand: the object its Transforms lead to).
    Child(NodeId),
}

impl Field {
    /// The field's name as the file writes it (`diffuseColor`, `vertex1`, `Scale`).
    pub fn name(&self) -> Cow<'static, str> {
        Cow::Borrowed(match self {
            Field::Center => "center",
            Field::Direction => "direction",
            Field::Up => "up",
            Field::Angle => "angle",
            Field::Size => "size",
            Field::Position => "position",
            Field::Color => "color",
            Field::Attenuation => "attenuation",
            Field::AmbientLight => "ambientLight",
            Field::DiffuseColor => "diffuseColor",
            Field::Material(name) => return Cow::Owned(name.clone()),
            Field::TextureTransform => "Transform",
            Field::Octaves => "octaves",
            Field::Frequency => "frequency",
            Field::Amplitude => "amplitude",
            Field::TextureMaterial(slot) => {
                return Cow::Owned(format!("materialIndex {}", slot + 1));
            }
            Field::Op(keyword) => keyword,
            Field::Ops => "ops",
            Field::Radius => "radius",
            Field::Normal => "normal",
            Field::Offset => "offset",
            Field::Vertex(i) => return Cow::Owned(format!("vertex{i}")),
            Field::ObjFile => "obj_file",
            Field::Min => "min",
            Field::Max => "max",
            Field::MaterialIndex => "MaterialIndex",
            Field::Children | Field::Child(_) => "children",
        })
    }
}

impl std::fmt::Display for Field {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.name())
    }
}
