//! The validity rules of a scene, in one place: the parser applies them with file locations,
//! the editor checks every edit with them before applying it, and the checked writer before
//! it writes. A scene that passes them is one the writer can print and the parser read back.

use glam::{DMat3, DMat4, Vec3};

use super::field::Field;
use super::transform::{compose_f64, op_matrix_f64, unit};
use super::walk::Walk;
use super::words::{is_numberlike, is_word};
use super::{
    Background, Camera, Graph, Light, LightKind, MAX_OCTAVES, Material, NodeId, NodeKind, Scene,
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

/// Whether `id` bounds a solid (a CSG operand): Transforms are followed to what they move.
pub fn is_solid(graph: &Graph, id: NodeId) -> bool {
    not_a_solid(graph, id).is_none() && !ends_in_empty_transform(graph, id)
}

/// The object at the end of `id`'s Transforms, when it is not a solid: a Triangle or a
/// Group. A Transform holding nothing is judged by its own rule, not here.
fn not_a_solid(graph: &Graph, id: NodeId) -> Option<NodeId> {
    let mut cur = id;
    loop {
        let node = graph.get(cur)?;
        match &node.kind {
            NodeKind::Transform(_) => cur = *node.children.first()?,
            NodeKind::Triangle { .. } | NodeKind::Group => return Some(cur),
            _ => return None,
        }
    }
}

fn ends_in_empty_transform(graph: &Graph, id: NodeId) -> bool {
    let mut cur = id;
    while let Some(n) = graph.get(cur) {
        match (&n.kind, n.children.first()) {
            (NodeKind::Transform(_), Some(&c)) => cur = c,
            (NodeKind::Transform(_), None) => return true,
            _ => return false,
        }
    }
    true
}

/// A MaterialIndex (as written: a file may give one past `u32`) against the scene's
/// materials.
pub fn check_material_index(index: u64, n_materials: usize) -> Result<(), Invalid> {
    if index < n_materials as u64 {
        return Ok(());
    }
    let range = if n_materials == 0 {
        "the scene has no materials".to_string()
    } else {
        format!("valid indices are 0 to {}", n_materials - 1)
    };
    Err(Invalid::new(
        Field::MaterialIndex,
        format!("MaterialIndex {index} is out of range: {range}"),
    ))
}

/// Rules about the object graph: each node's parameters, Transform and CSG child counts,
/// CSG operands that are solids, materials in range and placed where the file can say
/// them, and every Transform's world-from-object matrix composed through its whole chain
/// (not below a node whose own parameters are already at fault).
pub fn check_graph(graph: &Graph, n_materials: usize) -> Vec<Problem> {
    let mut out = Vec::new();
    // Nodes whose own parameters break a rule: their chain says the same thing again.
    let mut own = std::collections::HashSet::new();
    // Every Transform's world-from-object matrix, composed in f64 through its whole chain
    // of ancestors, in the same walk; only the outermost failing Transform of a chain is
    // reported (`below`: its depth, while the walk is inside it).
    let mut chain = Vec::new();
    let mut below: Option<usize> = None;
    for v in Walk::new(graph) {
        let (id, node, parent) = (v.id, v.node, v.parent);
        let own_verdict = check_kind(&node.kind);
        // A Transform right under the world whose own ops pass: its chain is those ops,
        // already judged singular or not, so only f32's range is left (the load of a
        // scene of many placed objects does not pay for the same test twice).
        let chain_is_own = own_verdict.is_ok() && v.world_from_parent == DMat4::IDENTITY;
        if below.is_some_and(|d| v.depth > d) {
            // Inside a chain already reported.
        } else if let NodeKind::Transform(_) = &node.kind
            && let Err(e) = if chain_is_own {
                fits_f32(&v.world_from_object)
            } else {
                check_world_from_object(&v.world_from_object)
            }
        {
            let message = e.to_string();
            chain.push(Problem {
                place: Place::Node(id),
                field: Field::Ops,
                op: None,
                reason: message.clone(),
                message,
                incomplete: false,
            });
            below = Some(v.depth);
        } else {
            below = None;
        }
        let name = node.kind.name();
        let mut push = |field: Field, op: Option<usize>, reason: String, incomplete: bool| {
            // "Sphere (node #4): radius …", not "Sphere (node #4): Sphere: radius …".
            let rest = reason
                .strip_prefix(name)
                .and_then(|r| r.strip_prefix(": "))
                .unwrap_or(&reason);
            out.push(Problem {
                place: Place::Node(id),
                field,
                op,
                message: format!("{name} (node #{}): {rest}", id.0),
                reason: reason.clone(),
                incomplete,
            })
        };
        if let Err(e) = own_verdict {
            own.insert(Place::Node(id));
            push(e.field, e.op, e.message, e.incomplete);
        }
        if let Some(m) = node.material {
            let parent_kind = parent.and_then(|p| graph.get(p)).map(|p| &p.kind);
            if !matches!(parent_kind, Some(NodeKind::Group | NodeKind::Csg(_))) {
                let m = format!(
                    "MaterialIndex {m} can only be set on an object listed in a Group or CSG node"
                );
                push(Field::MaterialIndex, None, m, false);
            }
            if let Err(e) = check_material_index(u64::from(m), n_materials) {
                push(e.field, None, e.message, false);
            }
        }
        match &node.kind {
            NodeKind::Transform(_) if node.children.is_empty() => {
                let m = "Transform needs one object after its operations".to_string();
                push(Field::Children, None, m, false);
            }
            NodeKind::Transform(_) => {
                for &c in &node.children[1..] {
                    let m = "a Transform holds exactly one object; this is a second (wrap them \
                             in a Group)";
                    push(Field::Child(c), None, m.into(), false);
                }
            }
            NodeKind::Csg(op) => {
                let op = op.name();
                let n = node.children.len();
                if n != 2 {
                    let m = format!(
                        "{op} needs exactly two operand objects (nest them for more), found {n}"
                    );
                    push(Field::Children, None, m, false);
                }
                for &c in &node.children {
                    let Some(at) = not_a_solid(graph, c) else {
                        continue;
                    };
                    let m = match graph.get(at).map(|n| &n.kind) {
                        Some(NodeKind::Group) => format!(
                            "a Group cannot be an operand of {op}: operands are solids (Sphere, \
                             Box, Plane, closed TriangleMesh, a Transform of one, or Union, \
                             Intersection, Subtraction); combine several with Union"
                        ),
                        _ => format!(
                            "a lone Triangle is not a solid, so it cannot be an operand of {op} \
                             (use a closed TriangleMesh)"
                        ),
                    };
                    push(Field::Child(at), None, m, false);
                }
            }
            _ => {}
        }
    }
    out.extend(
        chain
            .into_iter()
            .filter(|p| !own.contains(&p.place))
            .map(|p| Problem {
                message: format!(
                    "Transform (node #{}): {}",
                    p.node().map_or(0, |n| n.0),
                    p.message
                ),
                ..p
            }),
    );
    out
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

#[cfg(test)]
mod tests {
    use super::super::{MeshSlot, Node};
    use super::*;
    use glam::Mat4;

    fn ts(ops: Vec<TransformOp>) -> Result<(), Invalid> {
        check_kind(&NodeKind::Transform(ops))
    }

    #[test]
    fn unit_survives_components_whose_square_overflows() {
        assert_eq!(unit(Vec3::new(0.0, 0.0, 1e20)), Some(Vec3::Z));
        assert_eq!(unit(Vec3::new(0.0, 0.0, -3e38)), Some(Vec3::NEG_Z));
        let l = Vec3::new(-0.5, -1.0, -0.5);
        assert!((unit(l * 1e20).expect("unit") - l.normalize()).length() < 1e-6);
        assert_eq!(unit(Vec3::ZERO), None);
        assert_eq!(unit(Vec3::new(f32::NAN, 0.0, 1.0)), None);
    }

    #[test]
    fn singularity_is_relative_to_the_matrix_s_own_scale() {
        assert!(ts(vec![TransformOp::UniformScale(0.0001)]).is_ok());
        assert!(ts(vec![TransformOp::UniformScale(1e13)]).is_ok());
        assert!(ts(vec![TransformOp::Scale(Vec3::new(1.0, 0.0, 1.0))]).is_err());
        assert!(ts(vec![TransformOp::Scale(Vec3::new(1.0, 1e-8, 1.0))]).is_err());
        assert!(ts(vec![TransformOp::UniformScale(0.0)]).is_err());
        let e = ts(vec![
            TransformOp::Translate(Vec3::X),
            TransformOp::Scale(Vec3::new(1.0, 0.0, 1.0)),
        ])
        .expect_err("flat");
        assert_eq!((e.field, e.op), (Field::Op("Scale"), Some(1)));
    }

    #[test]
    fn a_projective_matrix_and_a_zero_rotate_axis_are_errors() {
        let mut m = Mat4::IDENTITY.to_cols_array_2d();
        m[0][3] = 0.5; // row 3, column 0
        let e =
            check_op(&TransformOp::Matrix(Mat4::from_cols_array_2d(&m))).expect_err("projective");
        assert!(e.message.contains("last row must be 0 0 0 1"), "{e}");
        let e = check_op(&TransformOp::Rotate {
            axis: Vec3::ZERO,
            degrees: 45.0,
        })
        .expect_err("zero axis");
        assert!(e.message.contains("axis must not be zero"), "{e}");
    }

    #[test]
    fn camera_rules_use_unit_vectors_and_name_their_field() {
        let cam = |direction: Vec3, up: Vec3, size: f32| Camera::Orthographic {
            center: Vec3::ZERO,
            direction,
            up,
            size,
        };
        assert!(check_camera(&cam(Vec3::new(0.0, 0.0, -3e38), Vec3::Y, 1.0)).is_ok());
        assert_eq!(
            check_camera(&cam(Vec3::Y * 2.0, Vec3::Y, 1.0))
                .expect_err("parallel")
                .field,
            Field::Up
        );
        assert_eq!(
            check_camera(&cam(Vec3::NEG_Z, Vec3::Y, 0.0))
                .expect_err("size 0")
                .field,
            Field::Size
        );
        assert_eq!(
            check_camera(&cam(Vec3::NEG_Z, Vec3::Y, f32::NAN))
                .expect_err("nan")
                .field,
            Field::Size
        );
    }

    #[test]
    fn negative_radius_and_empty_mesh_file_differ_in_kind() {
        let e = check_kind(&NodeKind::Sphere {
            center: Vec3::ZERO,
            radius: -1.0,
        })
        .expect_err("negative");
        assert!(
            !e.incomplete,
            "a negative radius is invalid, not incomplete"
        );
        let mesh = |f: &str| NodeKind::TriangleMesh {
            obj_file: f.into(),
            mesh: MeshSlot::Failed(String::new()),
        };
        assert!(check_kind(&mesh("")).expect_err("no file").incomplete);
        assert!(!check_kind(&mesh("a b.obj")).expect_err("space").incomplete);
        assert!(
            check_kind(&mesh("1.obj")).is_ok(),
            "the reader takes any word after obj_file"
        );
    }

    #[test]
    fn material_field_names_must_read_back_as_fields() {
        let with = |name: &str| Material {
            extra: vec![(name.into(), vec![1.0])],
            ..Material::diffuse(Vec3::ONE)
        };
        assert!(check_material(&with("exponent")).is_ok());
        for bad in [
            "",
            "2x",
            "-e",
            "nan",
            "obj_file",
            "diffuseColor",
            "a b",
            "x}",
        ] {
            assert!(check_material(&with(bad)).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn graph_verdicts_name_the_child_at_fault_by_field() {
        let sphere = || {
            Node::new(NodeKind::Sphere {
                center: Vec3::ZERO,
                radius: 1.0,
            })
        };
        // A Transform of two objects: the second is named, where the parser places it.
        let mut g = Graph::new();
        let t = g.add(Node::new(NodeKind::Transform(Vec::new())));
        let (a, b) = (g.add(sphere()), g.add(sphere()));
        g.push_child(g.root(), t);
        g.push_child(t, a);
        g.push_child(t, b);
        let p = check_graph(&g, 0);
        assert_eq!(p.len(), 1, "{p:?}");
        assert_eq!(
            (p[0].place, &p[0].field),
            (Place::Node(t), &Field::Child(b))
        );
        // A CSG operand through a Transform: the Triangle it leads to is named.
        let mut g = Graph::new();
        let u = g.add(Node::new(NodeKind::Csg(super::super::CsgOp::Union)));
        let t = g.add(Node::new(NodeKind::Transform(Vec::new())));
        let tri = g.add(Node::new(NodeKind::Triangle {
            vertices: [Vec3::ZERO, Vec3::X, Vec3::Y],
        }));
        let s = g.add(sphere());
        g.push_child(g.root(), u);
        g.push_child(u, t);
        g.push_child(t, tri);
        g.push_child(u, s);
        let p = check_graph(&g, 0);
        assert_eq!(p.len(), 1, "{p:?}");
        assert_eq!(
            (p[0].place, &p[0].field),
            (Place::Node(u), &Field::Child(tri))
        );
        assert!(
            p[0].reason.starts_with("a lone Triangle is not a solid"),
            "{p:?}"
        );
        assert!(!is_solid(&g, t) && is_solid(&g, s));
    }

    #[test]
    fn nested_tiny_scales_are_fine_and_a_flattening_one_is_found_in_the_chain() {
        let mut g = Graph::new();
        let mut parent = g.root();
        for _ in 0..10 {
            let t = g.add(Node::new(NodeKind::Transform(vec![
                TransformOp::UniformScale(0.1),
            ])));
            g.push_child(parent, t);
            parent = t;
        }
        let s = g.add(Node::new(NodeKind::Sphere {
            center: Vec3::ZERO,
            radius: 1e10,
        }));
        g.push_child(parent, s);
        assert_eq!(check_graph(&g, 0), []);
        // Two ops, each fine alone, that squash y by 1e-8 together.
        let mut g = Graph::new();
        let ops = vec![TransformOp::Scale(Vec3::new(1.0, 1e-4, 1.0))];
        let a = g.add(Node::new(NodeKind::Transform(ops.clone())));
        let b = g.add(Node::new(NodeKind::Transform(ops)));
        let s = g.add(Node::new(NodeKind::Sphere {
            center: Vec3::ZERO,
            radius: 1.0,
        }));
        g.push_child(g.root(), a);
        g.push_child(a, b);
        g.push_child(b, s);
        let p = check_graph(&g, 0);
        assert_eq!(p.len(), 1, "{p:?}");
        assert_eq!(p[0].place, Place::Node(b));
    }
}
