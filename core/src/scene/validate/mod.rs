//! The validity rules of a scene, in one place: the parser applies them with file locations,
//! the editor checks every edit with them before applying it, and the checked writer before
//! it writes. A scene that passes them is one the writer can print and the parser read back.
//!
//! In parts: this file each item's own rules (camera, lights, background, materials,
//! textures, a node's parameters, a Transform op) and the whole scene's; `graph.rs` the
//! rules about the object graph as a whole; `tests.rs` their unit tests.

use glam::{DMat3, DMat4, Vec3};

mod graph;
#[cfg(test)]
mod tests;

pub use graph::{check_graph, check_material_index, is_solid};

use super::field::Field;
use super::transform::{compose_f64, op_matrix_f64, unit};
use super::words::{is_numberlike, is_word};
use super::{
    Background, Camera, Light, LightKind, MAX_OCTAVES, Material, NodeId, NodeKind, Scene,
    SolidTexture, TransformOp,
};

/// One broken rule of one item (a camera, a light, a node's own parameters, …).
#[derive(Clone, Debug, PartialEq)]
pub struct Invalid {
    /// The field at fault (its file name: `field.name()`).
    pub field: Field,
    /// For a Transform: the position of the op at fault.
    pub op: Option<usize>,
    pub message: String,
    /// A state an editor passes through on the way to a valid one (a new TriangleMesh with
    /// no file chosen yet): allowed in a document, never written.
    pub incomplete: bool,
}

impl Invalid {
    fn new(field: Field, message: impl Into<String>) -> Self {
        Invalid {
            field,
            op: None,
            message: message.into(),
            incomplete: false,
        }
    }
}

impl std::error::Error for Invalid {}
impl std::error::Error for Problem {}

impl std::fmt::Display for Invalid {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

/// What a scene-wide problem is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Place {
    Camera,
    Light(usize),
    Background,
    Material(usize),
    Node(NodeId),
}

/// One broken rule somewhere in a scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Problem {
    pub place: Place,
    pub field: Field,
    pub op: Option<usize>,
    /// Names the place: `Sphere (node #4): radius must be positive, found -1`.
    pub message: String,
    /// The rule alone, to show beside the field: `Sphere: radius must be positive, found -1`.
    pub reason: String,
    pub incomplete: bool,
}

impl Problem {
    pub fn node(&self) -> Option<NodeId> {
        match self.place {
            Place::Node(id) => Some(id),
            _ => None,
        }
    }
}

impl std::fmt::Display for Problem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

/// The largest ratio of stretch to squash a linear map may have. f32 keeps about 7 digits;
/// past a million the object-space ray keeps almost none of them, so the map is as good as
/// singular.
const MAX_CONDITION: f64 = 1e6;

fn finite(field: Field, values: &[f32]) -> Result<(), Invalid> {
    // No value in the message: a number field turns a typed "nan" into +inf, and showing
    // "inf" to someone who typed "nan" would only puzzle them.
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        let m = format!("{field} must be a finite number");
        Err(Invalid::new(field, m))
    }
}

fn finite3(field: Field, v: Vec3) -> Result<(), Invalid> {
    finite(field, &v.to_array())
}

pub fn check_camera(c: &Camera) -> Result<(), Invalid> {
    let (kw, center, direction, up) = match c {
        Camera::Orthographic {
            center,
            direction,
            up,
            ..
        } => ("OrthographicCamera", center, direction, up),
        Camera::Perspective {
            center,
            direction,
            up,
            ..
        } => ("PerspectiveCamera", center, direction, up),
    };
    finite3(Field::Center, *center)?;
    finite3(Field::Direction, *direction)?;
    finite3(Field::Up, *up)?;
    let Some(d) = unit(*direction) else {
        return Err(Invalid::new(
            Field::Direction,
            format!("{kw}: direction must not be zero"),
        ));
    };
    // Unit vectors: the parallel test cannot overflow, whatever the lengths given.
    match unit(*up) {
        Some(u) if u.cross(d).length_squared() > 1e-12 => {}
        _ => {
            return Err(Invalid::new(
                Field::Up,
                format!("{kw}: up must not be zero or parallel to direction"),
            ));
        }
    }
    match *c {
        Camera::Perspective { angle, .. } => {
            finite(Field::Angle, &[angle])?;
            if !(angle > 0.0 && angle < 180.0) {
                let m = format!(
                    "PerspectiveCamera: angle must be between 0 and 180 degrees, found {angle}"
                );
                return Err(Invalid::new(Field::Angle, m));
            }
        }
        Camera::Orthographic { size, .. } => {
            finite(Field::Size, &[size])?;
            if size <= 0.0 {
                return Err(Invalid::new(
                    Field::Size,
                    format!("OrthographicCamera: size must be positive, found {size}"),
                ));
            }
        }
    }
    Ok(())
}

pub fn check_light(l: &Light) -> Result<(), Invalid> {
    match l.kind {
        LightKind::Directional { direction } => {
            finite3(Field::Direction, direction)?;
            finite3(Field::Color, l.color)?;
            if unit(direction).is_none() {
                return Err(Invalid::new(
                    Field::Direction,
                    "DirectionalLight: direction must not be zero",
                ));
            }
        }
        LightKind::Point {
            position,
            attenuation,
        } => {
            finite3(Field::Position, position)?;
            finite3(Field::Color, l.color)?;
            if let Some(a) = attenuation {
                finite3(Field::Attenuation, a)?;
                // c + l·d + q·d² must stay positive for every distance d > 0.
                if a.min_element() < 0.0 || a == Vec3::ZERO {
                    return Err(Invalid::new(
                        Field::Attenuation,
                        format!(
                            "PointLight: attenuation (constant, linear, quadratic) must be \
                             non-negative and not all zero, found {} {} {}",
                            a.x, a.y, a.z
                        ),
                    ));
                }
            }
        }
    }
    Ok(())
}

pub fn check_background(b: &Background) -> Result<(), Invalid> {
    if let Some(c) = b.color {
        finite3(Field::Color, c)?;
    }
    if let Some(a) = b.ambient {
        finite3(Field::AmbientLight, a)?;
    }
    Ok(())
}

/// A word the lexer reads back as one token: not empty, no ASCII whitespace, braces, `#`
/// or NUL (the reader refuses files holding one).
pub fn check_material(m: &Material) -> Result<(), Invalid> {
    if let Some(t) = &m.texture {
        if m.diffuse != Vec3::ZERO || !m.extra.is_empty() {
            let field = m
                .extra
                .first()
                .map_or(Field::DiffuseColor, |(n, _)| Field::Material(n.clone()));
            let msg = format!(
                "a {} takes its colours from its two materials; it has no {field} of its own",
                t.kind.name()
            );
            return Err(Invalid::new(field, msg));
        }
        return check_texture(t);
    }
    finite3(Field::DiffuseColor, m.diffuse)?;
    for (i, (name, values)) in m.extra.iter().enumerate() {
        // The reader takes a number-like word as a value and `obj_file` as a mesh field.
        if !is_word(name) || is_numberlike(name) || name == "obj_file" {
            let m = format!(
                "material field name \"{}\" cannot be written",
                name.escape_debug()
            );
            return Err(Invalid::new(Field::Material(name.clone()), m));
        }
        if name == "diffuseColor" || m.extra[..i].iter().any(|(n, _)| n == name) {
            return Err(Invalid::new(
                Field::Material(name.clone()),
                format!("\"{name}\" is given twice in the material"),
            ));
        }
        finite(Field::Material(name.clone()), values)?;
        check_phong_field(name, values)?;
    }
    Ok(())
}

/// A texture's own numbers and Transform (its material indices need the whole list:
/// [`check_texture_refs`]).
pub fn check_texture(t: &SolidTexture) -> Result<(), Invalid> {
    let kind = t.kind.name();
    if let Some(ops) = &t.transform {
        for (i, op) in ops.iter().enumerate() {
            check_op(op).map_err(|e| Invalid { op: Some(i), ..e })?;
        }
        if let Some(why) = singular(DMat3::from_mat4(compose_f64(ops))) {
            return Err(Invalid::new(
                Field::TextureTransform,
                format!("singular transform: the combined operations {why}"),
            ));
        }
    }
    if !t.kind.has_octaves() && t.octaves != 0 {
        return Err(Invalid::new(
            Field::Octaves,
            format!("a {kind} has no octaves"),
        ));
    }
    if t.octaves > MAX_OCTAVES {
        let m = format!("octaves must be 0 to {MAX_OCTAVES}, found {}", t.octaves);
        return Err(Invalid::new(Field::Octaves, m));
    }
    for (field, v) in [
        (Field::Frequency, t.frequency),
        (Field::Amplitude, t.amplitude),
    ] {
        if !t.kind.has_waves() && v != 0.0 {
            let m = format!("a {kind} has no {field}");
            return Err(Invalid::new(field, m));
        }
        finite(field, &[v])?;
    }
    Ok(())
}

/// How deep textures may nest (a texture of textures of …): each level may evaluate both
/// of its materials, so the work per hit doubles with each one. The course nests 2 deep.
pub const MAX_TEXTURE_DEPTH: usize = 8;

/// One texture's `materialIndex` at fault: (material, which of its two lines, why).
pub type TextureRefProblem = (usize, usize, String);

/// Every texture's two material indices: in range, not itself, no loop of textures, and
/// nested at most [`MAX_TEXTURE_DEPTH`] deep. A loop is reported once, at the line that
/// closes it.
pub fn check_texture_refs(materials: &[Material]) -> Vec<TextureRefProblem> {
    let n = materials.len();
    let refs = |i: usize| {
        materials
            .get(i)
            .and_then(|m| m.texture.as_ref())
            .map(|t| t.materials)
    };
    let mut out = Vec::new();
    for i in 0..n {
        let Some(ab) = refs(i) else { continue };
        for (slot, &j) in ab.iter().enumerate() {
            if j as usize >= n {
                out.push((
                    i,
                    slot,
                    format!(
                        "materialIndex {j} is out of range: valid indices are 0 to {}",
                        n - 1
                    ),
                ));
            } else if j as usize == i {
                out.push((i, slot, format!("materialIndex {j} is this texture itself")));
            }
        }
    }
    if !out.is_empty() {
        return out;
    }
    // Depth-first over the texture references, iteratively (a hostile file may chain
    // thousands): 0 unseen, 1 on the path, 2 done with `depth` known.
    let mut state = vec![0u8; n];
    let mut depth = vec![0usize; n];
    for root in 0..n {
        if state[root] != 0 || refs(root).is_none() {
            continue;
        }
        // (material, next slot to follow)
        let mut stack = vec![(root, 0usize)];
        state[root] = 1;
        while let Some(top) = stack.last_mut() {
            let (i, k) = *top;
            top.1 += 1;
            let ab = refs(i).unwrap_or_default();
            if k == 2 {
                let d = ab.iter().map(|&j| depth[j as usize]).max().unwrap_or(0);
                depth[i] = d + 1;
                state[i] = 2;
                stack.pop();
                if depth[i] > MAX_TEXTURE_DEPTH {
                    let m = format!(
                        "textures nest more than {MAX_TEXTURE_DEPTH} deep here (a texture of \
                         a texture of …)"
                    );
                    out.push((i, 0, m));
                    return out;
                }
                continue;
            }
            let j = ab[k] as usize;
            if refs(j).is_none() {
                continue;
            }
            match state[j] {
                0 => {
                    state[j] = 1;
                    stack.push((j, 0));
                }
                1 => {
                    let from = stack.iter().position(|&(m, _)| m == j).unwrap_or(0);
                    let path: Vec<String> = stack[from..]
                        .iter()
                        .map(|&(m, _)| m.to_string())
                        .chain([j.to_string()])
                        .collect();
                    let m = format!(
                        "materialIndex {j} makes a loop of textures: {}",
                        path.join(" → ")
                    );
                    out.push((i, k, m));
                    return out;
                }
                _ => {}
            }
        }
    }
    out
}

/// A Phong field's count of numbers and range; other names pass (the reader warns of them).
fn check_phong_field(name: &str, values: &[f32]) -> Result<(), Invalid> {
    let Some(f) = super::phong::phong_field(name) else {
        return Ok(());
    };
    if values.len() != f.numbers {
        let m = format!(
            "\"{name}\" takes {} number(s), found {}",
            f.numbers,
            values.len()
        );
        return Err(Invalid::new(Field::Material(name.into()), m));
    }
    match (name, values) {
        ("exponent", &[e]) if e < 0.0 => Err(Invalid::new(
            Field::Material(name.into()),
            format!("exponent must not be negative, found {e}"),
        )),
        ("indexOfRefraction", &[n]) if n <= 0.0 => Err(Invalid::new(
            Field::Material(name.into()),
            format!("indexOfRefraction must be positive, found {n}"),
        )),
        _ => Ok(()),
    }
}

/// Why a linear map cannot move rays into object space, if it cannot: zero or overflowing
/// volume, or a condition number past [`MAX_CONDITION`]. Relative to the map's own scale,
/// so a uniform scale of 1e-4 or 1e13 is fine and `Scale 1 0 1` is not.
fn singular(a: DMat3) -> Option<&'static str> {
    let det = a.determinant();
    if !det.is_finite() {
        return Some("overflows");
    }
    if det == 0.0 {
        return Some("flattens space, so rays cannot be moved into object space");
    }
    let inv = a.inverse();
    let norm = |m: DMat3| {
        (m.x_axis.length_squared() + m.y_axis.length_squared() + m.z_axis.length_squared()).sqrt()
    };
    // Frobenius norms: the identity gives 3, a map squashing one axis by k about 3k.
    let cond = norm(a) * norm(inv) / 3.0;
    if !cond.is_finite() || cond > MAX_CONDITION {
        return Some(
            "squashes one direction so much more than another that rays lose all precision",
        );
    }
    // The tracer works in f32: both directions of the map must fit in it with room to spare.
    let fits = |m: DMat3| {
        m.to_cols_array()
            .iter()
            .all(|v| v.abs() < f64::from(f32::MAX) / 16.0)
    };
    if !fits(a) || !fits(inv) {
        return Some("overflows");
    }
    None
}

/// One op on its own: finite numbers, a last Matrix row of 0 0 0 1, a non-zero Rotate axis,
/// and not singular by itself.
pub fn check_op(op: &TransformOp) -> Result<(), Invalid> {
    let name = op.name();
    let field = Field::Op(name);
    match op {
        TransformOp::Scale(v) | TransformOp::Translate(v) => finite3(field.clone(), *v)?,
        TransformOp::UniformScale(s)
        | TransformOp::XRotate(s)
        | TransformOp::YRotate(s)
        | TransformOp::ZRotate(s) => finite(field.clone(), &[*s])?,
        TransformOp::Rotate { axis, degrees } => {
            finite(field.clone(), &axis.to_array())?;
            finite(field.clone(), &[*degrees])?;
            if unit(*axis).is_none() {
                return Err(Invalid::new(field, "Rotate: the axis must not be zero"));
            }
        }
        TransformOp::Matrix(m) => {
            finite(field.clone(), &m.to_cols_array())?;
            let r = m.row(3);
            if r != glam::Vec4::W {
                let m = format!(
                    "Matrix: the last row must be 0 0 0 1 (a projective matrix cannot move rays), found {} {} {} {}",
                    r.x, r.y, r.z, r.w
                );
                return Err(Invalid::new(field, m));
            }
        }
    }
    if let Some(why) = singular(DMat3::from_mat4(op_matrix_f64(op))) {
        return Err(Invalid::new(
            field,
            format!("singular transform: {} {why}", op.summary()),
        ));
    }
    Ok(())
}

/// A world-from-object matrix, composed through a chain of Transforms, that rays cannot be
/// moved through; `why` finishes "the combined transforms down to here …".
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("singular transform: the combined transforms down to here {why}")]
pub struct SingularTransform {
    pub why: &'static str,
}

/// Whether a world-from-object matrix (composed through the whole chain) can be used.
pub fn check_world_from_object(m: &DMat4) -> Result<(), SingularTransform> {
    match singular(DMat3::from_mat4(*m)) {
        Some(why) => Err(SingularTransform { why }),
        None => fits_f32(m),
    }
}

/// Every entry of a world-from-object matrix within f32's range.
fn fits_f32(m: &DMat4) -> Result<(), SingularTransform> {
    if m.to_cols_array()
        .iter()
        .all(|v| v.abs() < f64::from(f32::MAX))
    {
        Ok(())
    } else {
        Err(SingularTransform { why: "overflows" })
    }
}

/// The rules for one node's own parameters.
pub fn check_kind(kind: &NodeKind) -> Result<(), Invalid> {
    match kind {
        NodeKind::Group | NodeKind::Csg(_) => {}
        NodeKind::Transform(ops) => {
            for (i, op) in ops.iter().enumerate() {
                check_op(op).map_err(|e| Invalid { op: Some(i), ..e })?;
            }
            if let Some(why) = singular(DMat3::from_mat4(compose_f64(ops))) {
                return Err(Invalid::new(
                    Field::Ops,
                    format!("singular transform: the combined operations {why}"),
                ));
            }
        }
        NodeKind::Sphere { center, radius } => {
            finite3(Field::Center, *center)?;
            finite(Field::Radius, &[*radius])?;
            if *radius <= 0.0 {
                return Err(Invalid::new(
                    Field::Radius,
                    format!("Sphere: radius must be positive, found {radius}"),
                ));
            }
        }
        NodeKind::Plane { normal, offset } => {
            finite3(Field::Normal, *normal)?;
            finite(Field::Offset, &[*offset])?;
            if unit(*normal).is_none() {
                return Err(Invalid::new(
                    Field::Normal,
                    "Plane: normal must not be zero",
                ));
            }
        }
        NodeKind::Triangle { vertices } => {
            for (i, v) in vertices.iter().enumerate() {
                finite3(Field::Vertex(i), *v)?;
            }
        }
        NodeKind::TriangleMesh { obj_file, .. } => {
            if obj_file.is_empty() {
                return Err(Invalid {
                    incomplete: true,
                    ..Invalid::new(Field::ObjFile, "TriangleMesh: no OBJ file chosen yet")
                });
            }
            if !is_word(obj_file) {
                let m = format!(
                    "TriangleMesh: \"{}\" cannot be written as a file name (no spaces, braces or #)",
                    obj_file.escape_debug()
                );
                return Err(Invalid::new(Field::ObjFile, m));
            }
        }
        NodeKind::Box { min, max } => {
            finite3(Field::Min, *min)?;
            finite3(Field::Max, *max)?;
            if min.cmpgt(*max).any() {
                return Err(Invalid::new(
                    Field::Max,
                    "Box: min must not exceed max on any axis",
                ));
            }
            // A flat box has no inside: no ray enters it, so it would render as nothing,
            // and as a CSG operand it is empty. Refused, to say so.
            if let Some(axis) = (0..3).find(|&k| min[k] == max[k]) {
                return Err(Invalid::new(
                    Field::Max,
                    format!(
                        "Box: min and max are equal on {} ({}), so the box is flat and would not be seen; give it a thickness",
                        ["x", "y", "z"][axis],
                        min[axis]
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Every rule, over the whole scene.
pub fn check_scene(scene: &Scene) -> Vec<Problem> {
    let mut out = Vec::new();
    let mut push = |r: Result<(), Invalid>, place: Place, what: String| {
        if let Err(e) = r {
            let message = format!("{what}: {}", e.message);
            out.push(Problem {
                place,
                field: e.field,
                op: None,
                message,
                reason: e.message,
                incomplete: false,
            });
        }
    };
    push(check_camera(&scene.camera), Place::Camera, "camera".into());
    for (i, l) in scene.lights().iter().enumerate() {
        push(check_light(l), Place::Light(i), format!("light {i}"));
    }
    push(
        check_background(&scene.background),
        Place::Background,
        "background".into(),
    );
    for (i, m) in scene.materials.iter().enumerate() {
        push(
            check_material(m),
            Place::Material(i),
            format!("material {i}"),
        );
    }
    for (i, slot, reason) in check_texture_refs(&scene.materials) {
        out.push(Problem {
            place: Place::Material(i),
            field: Field::TextureMaterial(slot),
            op: None,
            message: format!("material {i}: {reason}"),
            reason,
            incomplete: false,
        });
    }
    out.extend(check_graph(&scene.graph, scene.materials.len()));
    out
}
