//! The inspector (right panel): every parameter of the selection, as widgets that emit
//! [`Edit`]s (and, for a TriangleMesh's file, [`AppCommand::LoadMesh`]). Widgets edit copies;
//! nothing here changes the document or reads files.

use glam::{Mat4, Vec3};
use tracelab_core::scene::{DEFAULT_ATTENUATION, LightKind};
use tracelab_core::{
    Background, Camera, CsgOp, Field, Light, Material, MeshSlot, NodeId, NodeKind, Place,
    TransformOp,
};

use crate::document::edit::Edit;
use crate::document::{Document, Selection};
use crate::gui::command::AppCommand;
use crate::gui::drag_speed::{DragSpeeds, world_per_unit};
use crate::gui::widgets::number;

use super::fields::{color, op_id, refusal_note, scalar, show_refusal_for, vec3};

pub fn ui(ui: &mut egui::Ui, doc: &Document) -> Vec<AppCommand> {
    let mut edits = Vec::new();
    let mut asked = Vec::new();
    let place = match doc.selection {
        Some(Selection::Camera) => Some(Place::Camera),
        Some(Selection::Background) => Some(Place::Background),
        Some(Selection::Light(i)) => Some(Place::Light(i)),
        Some(Selection::Material(i)) => Some(Place::Material(i)),
        Some(Selection::Node(id)) => Some(Place::Node(id)),
        _ => None,
    };
    show_refusal_for(ui, doc, place);
    egui::ScrollArea::vertical()
        .auto_shrink([false, false])
        .show(ui, |ui| match doc.selection {
            None => {
                ui.label(
                    "Select something in the scene tree, or click an object in the render view.",
                );
            }
            Some(Selection::Camera) => camera(ui, &doc.scene.camera, &mut edits),
            Some(Selection::Lights) => {
                ui.heading("Lights");
                if doc.scene.lights.is_none() {
                    ui.label("No Lights block: the scene is shown flat in its diffuse colours.");
                }
                for i in 0..doc.scene.lights().len() {
                    ui.separator();
                    light(ui, doc, i, &mut edits);
                }
                ui.horizontal(|ui| {
                    if ui.button("Add light").clicked() {
                        edits.push(Edit::AddLight(Light::new(
                            Vec3::new(-0.5, -1.0, -0.5),
                            Vec3::splat(0.5),
                        )));
                    }
                    if ui.button("Add point light").clicked() {
                        edits.push(Edit::AddLight(Light::point(
                            Vec3::new(0.0, 5.0, 5.0),
                            Vec3::splat(0.5),
                            None,
                        )));
                    }
                });
            }
            Some(Selection::Light(i)) => light(ui, doc, i, &mut edits),
            Some(Selection::Background) => background(ui, &doc.scene.background, &mut edits),
            Some(Selection::Materials) => {
                ui.heading("Materials");
                for i in 0..doc.scene.materials.len() {
                    ui.separator();
                    ui.strong(format!("Material {i}"));
                    material(ui, doc, i, &mut edits);
                }
                if ui.button("Add material").clicked() {
                    edits.push(Edit::AddMaterial(Material::diffuse(Vec3::splat(0.7))));
                }
            }
            Some(Selection::Material(i)) => {
                ui.heading(format!("Material {i}"));
                material(ui, doc, i, &mut edits);
            }
            Some(Selection::Node(id)) => node(ui, doc, id, &mut edits, &mut asked),
        });
    edits
        .into_iter()
        .map(AppCommand::Edit)
        .chain(asked)
        .collect()
}

fn camera(ui: &mut egui::Ui, cam: &Camera, edits: &mut Vec<Edit>) {
    let speeds = DragSpeeds::for_scene_camera(cam);
    ui.heading("Camera");
    let mut c = cam.clone();
    let mut changed = false;
    ui.horizontal(|ui| {
        let ortho = matches!(c, Camera::Orthographic { .. });
        if ui.selectable_label(ortho, "Orthographic").clicked() && !ortho {
            c = Camera::Orthographic {
                center: c.center(),
                direction: c.direction(),
                up: c.up(),
                size: 5.0,
            };
            changed = true;
        }
        if ui.selectable_label(!ortho, "Perspective").clicked() && ortho {
            c = Camera::Perspective {
                center: c.center(),
                direction: c.direction(),
                up: c.up(),
                angle: 30.0,
            };
            changed = true;
        }
    });
    match &mut c {
        Camera::Orthographic {
            center,
            direction,
            up,
            size,
        } => {
            changed |= vec3(ui, "center", Field::Center, center, speeds.length(1.0));
            changed |= vec3(ui, "direction", Field::Direction, direction, 0.01);
            changed |= vec3(ui, "up", Field::Up, up, 0.01);
            changed |= scalar(ui, "size", Field::Size, size, DragSpeeds::factor(*size));
        }
        Camera::Perspective {
            center,
            direction,
            up,
            angle,
        } => {
            changed |= vec3(ui, "center", Field::Center, center, speeds.length(1.0));
            changed |= vec3(ui, "direction", Field::Direction, direction, 0.01);
            changed |= vec3(ui, "up", Field::Up, up, 0.01);
            // No clamp of its own: an angle out of (0, 180) is refused by the rules, beside
            // the field.
            changed |= scalar(ui, "angle (degrees)", Field::Angle, angle, 0.1);
        }
    }
    if changed {
        edits.push(Edit::SetCamera(c));
    }
}

fn light(ui: &mut egui::Ui, doc: &Document, i: usize, edits: &mut Vec<Edit>) {
    let Some(l) = doc.scene.lights().get(i) else {
        return;
    };
    let mut l = l.clone();
    show_refusal_for(ui, doc, Some(Place::Light(i)));
    let mut changed = match &mut l.kind {
        LightKind::Directional { direction } => {
            ui.strong(format!("Light {i} (directional)"));
            vec3(ui, "direction", Field::Direction, direction, 0.01)
        }
        LightKind::Point {
            position,
            attenuation,
        } => {
            ui.strong(format!("Light {i} (point)"));
            let mut changed = vec3(ui, "position", Field::Position, position, 0.01);
            // Absent means the course's 1 0 0, and stays absent until given.
            let mut on = attenuation.is_some();
            if ui
                .checkbox(&mut on, "attenuation (constant, linear, quadratic)")
                .changed()
            {
                *attenuation = on.then_some(DEFAULT_ATTENUATION);
                changed = true;
            }
            if let Some(a) = attenuation {
                changed |= vec3(ui, "attenuation", Field::Attenuation, a, 0.01);
            }
            changed
        }
    };
    changed |= color(ui, "colour", Field::Color, &mut l.color);
    if changed {
        edits.push(Edit::SetLight { index: i, light: l });
    }
    if ui.button(format!("Remove light {i}")).clicked() {
        edits.push(Edit::RemoveLight { index: i });
    }
}

fn background(ui: &mut egui::Ui, bg: &Background, edits: &mut Vec<Edit>) {
    ui.heading("Background");
    let mut b = bg.clone();
    let mut changed = false;
    for (name, field, value) in [
        ("colour", Field::Color, &mut b.color),
        ("ambient light", Field::AmbientLight, &mut b.ambient),
    ] {
        let mut on = value.is_some();
        ui.horizontal(|ui| {
            if ui.checkbox(&mut on, "").changed() {
                *value = on.then_some(Vec3::ZERO);
                changed = true;
            }
            if let Some(c) = value {
                changed |= color(ui, name, field.clone(), c);
            } else {
                ui.label(format!("{name} (not set: black)"));
            }
        });
    }
    if changed {
        edits.push(Edit::SetBackground(b));
    }
}

fn material(ui: &mut egui::Ui, doc: &Document, i: usize, edits: &mut Vec<Edit>) {
    let Some(m) = doc.scene.materials.get(i) else {
        return;
    };
    let mut m = m.clone();
    show_refusal_for(ui, doc, Some(Place::Material(i)));
    ui.push_id(("material", i), |ui| {
        if let Some(t) = &m.texture {
            // Shown, not yet editable: the file's text is the way to change one.
            texture_lines(ui, i, t);
        } else {
            color_and_phong(ui, i, &mut m, edits);
        }
        if ui
            .button("Remove")
            .on_hover_text(format!("Remove material {i}"))
            .clicked()
        {
            edits.push(Edit::RemoveMaterial { index: i });
        }
    });
}

/// A solid texture, read-only: its kind, materials, numbers and Transform ops.
fn texture_lines(ui: &mut egui::Ui, i: usize, t: &tracelab_core::SolidTexture) {
    let [a, b] = t.materials;
    ui.label(format!("{i}: {} of materials {a} and {b}", t.kind.name()));
    if t.kind.has_octaves() {
        ui.label(format!("octaves {}", t.octaves));
    }
    if t.kind.has_waves() {
        ui.label(format!(
            "frequency {}  amplitude {}",
            t.frequency, t.amplitude
        ));
    }
    for op in t.transform.iter().flatten() {
        ui.small(format!("Transform: {}", op.summary()));
    }
    ui.small("(a solid texture: edit it in the scene file)");
}

fn color_and_phong(ui: &mut egui::Ui, i: usize, m: &mut Material, edits: &mut Vec<Edit>) {
    {
        // Remove under the colour, not beside it: beside, the row was wider than the panel
        // and egui widened the inspector by 60 points, pushing the picture aside.
        let mut c = m.diffuse;
        if color(ui, &format!("{i}: diffuse"), Field::DiffuseColor, &mut c) {
            m.diffuse = c;
            edits.push(Edit::SetMaterial {
                index: i,
                material: m.clone(),
            });
        }
        if let Some(material) = super::phong::fields(ui, m) {
            edits.push(Edit::SetMaterial { index: i, material });
        }
    }
}

fn node(
    ui: &mut egui::Ui,
    doc: &Document,
    id: NodeId,
    edits: &mut Vec<Edit>,
    asked: &mut Vec<AppCommand>,
) {
    let g = &doc.scene.graph;
    let Some(n) = g.get(id) else { return };
    ui.heading(n.kind.name());
    if let Some(path) = g.path_to(id) {
        let names: Vec<&str> = path
            .iter()
            .filter_map(|&p| g.get(p))
            .map(|n| n.kind.name())
            .collect();
        ui.small(breadcrumb(&names));
    }
    similitude_lines(ui, doc, id);
    // MaterialIndex
    if id != g.root() {
        let mats = doc.scene.materials.len() as u32;
        let current = n.material;
        let eff = g.effective_materials().get(id.index()).copied().flatten();
        let text = |m: Option<u32>| m.map_or("inherit".to_string(), |m| format!("Material {m}"));
        let mut chosen = current;
        egui::ComboBox::from_label("material")
            .selected_text(match current {
                Some(_) => text(current),
                // Name what it renders with, not only that it inherits.
                None => eff.map_or("inherits no material: default grey".into(), |m| {
                    format!("inherits Material {m}")
                }),
            })
            .show_ui(ui, |ui| {
                ui.selectable_value(&mut chosen, None, "inherit from the Group");
                for m in 0..mats {
                    ui.selectable_value(&mut chosen, Some(m), text(Some(m)));
                }
            });
        refusal_note(ui, &Field::MaterialIndex);
        if chosen != current {
            edits.push(Edit::SetNodeMaterial {
                node: id,
                material: chosen,
            });
        }
    }
    ui.separator();
    // Lengths drag by a share of the view, in the units of the space the node lives in.
    let speeds = DragSpeeds::for_scene(&doc.scene);
    let len = speeds.length(world_per_unit(&doc.scene, id, None));
    let mut kind = n.kind.clone();
    match &mut kind {
        NodeKind::Transform(ops) => {
            let lens: Vec<f64> = (0..ops.len())
                .map(|i| speeds.length(world_per_unit(&doc.scene, id, Some(i))))
                .collect();
            transform_ops(ui, id, ops, &lens, edits);
        }
        NodeKind::Group => {
            ui.label(format!("{} objects", n.children.len()));
        }
        NodeKind::Sphere { center, radius } => {
            let mut c = vec3(ui, "center", Field::Center, center, len);
            c |= scalar(ui, "radius", Field::Radius, radius, len);
            if c {
                edits.push(Edit::SetNodeKind {
                    node: id,
                    kind: kind.clone(),
                });
            }
        }
        NodeKind::Plane { normal, offset } => {
            let mut c = vec3(ui, "normal", Field::Normal, normal, 0.01);
            c |= scalar(ui, "offset", Field::Offset, offset, len);
            if c {
                edits.push(Edit::SetNodeKind {
                    node: id,
                    kind: kind.clone(),
                });
            }
        }
        NodeKind::Triangle { vertices } => {
            let mut c = false;
            for (i, v) in vertices.iter_mut().enumerate() {
                c |= vec3(ui, &format!("vertex{i}"), Field::Vertex(i), v, len);
            }
            if c {
                edits.push(Edit::SetNodeKind {
                    node: id,
                    kind: kind.clone(),
                });
            }
        }
        NodeKind::TriangleMesh { obj_file, mesh } => {
            // The path being typed lives in egui's memory until it is loaded: an edit per
            // keystroke would fill the undo history with half-typed names. The app salts the
            // inspector's ids with its widget epoch, so after an open, undo or reload the
            // field starts again from the document's value.
            let buf_id = ui.scope_id().with(("obj_file", id.0));
            let mut path = ui
                .data_mut(|d| d.get_temp::<String>(buf_id))
                .unwrap_or_else(|| obj_file.clone());
            ui.horizontal(|ui| {
                ui.label("obj_file");
                ui.text_edit_singleline(&mut path);
                refusal_note(ui, &Field::ObjFile);
            });
            if path == *obj_file {
                ui.data_mut(|d| d.remove::<String>(buf_id));
            } else {
                ui.data_mut(|d| d.insert_temp(buf_id, path.clone()));
                ui.colored_label(
                    ui.visuals().warn_fg_color,
                    format!(
                        "not loaded yet (the scene uses {obj_file:?}): press Enter or Load / reload"
                    ),
                );
            }
            match mesh {
                MeshSlot::Loaded(m) => {
                    ui.label(format!(
                        "{} vertices, {} triangles",
                        m.positions.len(),
                        m.triangle_count()
                    ));
                }
                MeshSlot::Failed(e) => {
                    ui.colored_label(ui.visuals().error_fg_color, e.as_str());
                }
                MeshSlot::Unresolved => {
                    ui.colored_label(ui.visuals().warn_fg_color, "not loaded yet");
                }
            }
            if ui.button("Load / reload").clicked()
                || (path != *obj_file && ui.input(|i| i.key_pressed(egui::Key::Enter)))
            {
                ui.data_mut(|d| d.remove::<String>(buf_id));
                asked.push(AppCommand::LoadMesh {
                    node: id,
                    obj_file: path,
                });
            }
        }
        NodeKind::Box { min, max } => {
            let mut c = vec3(ui, "min", Field::Min, min, len);
            c |= vec3(ui, "max", Field::Max, max, len);
            if c {
                edits.push(Edit::SetNodeKind {
                    node: id,
                    kind: kind.clone(),
                });
            }
        }
        NodeKind::Csg(op) => {
            let mut chosen = *op;
            ui.horizontal(|ui| {
                ui.label("operation");
                for o in CsgOp::ALL {
                    ui.selectable_value(&mut chosen, o, o.name());
                }
            });
            if chosen != *op {
                edits.push(Edit::SetNodeKind {
                    node: id,
                    kind: NodeKind::Csg(chosen),
                });
            }
            let g = &doc.scene.graph;
            for (name, c) in ["A", "B"].iter().zip(&n.children) {
                let label = g.get(*c).map_or("?", |k| k.kind.name());
                ui.label(format!("{name}: {label}"));
            }
            if ui
                .button("Swap A and B")
                .on_hover_text("A minus B becomes B minus A")
                .clicked()
            {
                edits.push(Edit::SwapOperands { node: id });
            }
        }
    }
}

fn op_names() -> [(&'static str, TransformOp); 8] {
    [
        ("Translate", TransformOp::Translate(Vec3::ZERO)),
        ("Scale", TransformOp::Scale(Vec3::ONE)),
        ("UniformScale", TransformOp::UniformScale(1.0)),
        ("XRotate", TransformOp::XRotate(0.0)),
        ("YRotate", TransformOp::YRotate(0.0)),
        ("ZRotate", TransformOp::ZRotate(0.0)),
        (
            "Rotate",
            TransformOp::Rotate {
                axis: Vec3::Y,
                degrees: 0.0,
            },
        ),
        ("Matrix", TransformOp::Matrix(Mat4::IDENTITY)),
    ]
}

/// `lengths[i]`: the drag speed of a length in the space op `i` acts in.
fn transform_ops(
    ui: &mut egui::Ui,
    node: NodeId,
    ops: &mut [TransformOp],
    lengths: &[f64],
    edits: &mut Vec<Edit>,
) {
    ui.label("Ops, first listed applied last (M = op1 · op2 · …):");
    // The ops together (or the chain above them) flatten space.
    refusal_note(ui, &Field::Ops);
    let n = ops.len();
    for (index, op) in ops.iter_mut().enumerate() {
        ui.push_id(index, |ui| {
            ui.data_mut(|d| d.insert_temp(op_id(), Some(index)));
            ui.group(|ui| {
                let len = lengths.get(index).copied().unwrap_or(0.02);
                let changed = match op {
                    TransformOp::Translate(v) => {
                        vec3(ui, "Translate", Field::Op("Translate"), v, len)
                    }
                    TransformOp::Scale(v) => vec3(
                        ui,
                        "Scale",
                        Field::Op("Scale"),
                        v,
                        DragSpeeds::factor(v.abs().max_element()),
                    ),
                    TransformOp::UniformScale(s) => scalar(
                        ui,
                        "UniformScale",
                        Field::Op("UniformScale"),
                        s,
                        DragSpeeds::factor(*s),
                    ),
                    TransformOp::XRotate(d) => {
                        scalar(ui, "XRotate (degrees)", Field::Op("XRotate"), d, 0.5)
                    }
                    TransformOp::YRotate(d) => {
                        scalar(ui, "YRotate (degrees)", Field::Op("YRotate"), d, 0.5)
                    }
                    TransformOp::ZRotate(d) => {
                        scalar(ui, "ZRotate (degrees)", Field::Op("ZRotate"), d, 0.5)
                    }
                    TransformOp::Rotate { axis, degrees } => {
                        let a = vec3(ui, "Rotate axis", Field::Op("Rotate"), axis, 0.01);
                        scalar(ui, "Rotate degrees", Field::Op("Rotate"), degrees, 0.5) || a
                    }
                    TransformOp::Matrix(m) => matrix(ui, m),
                };
                if changed {
                    edits.push(Edit::SetTransformOp {
                        node,
                        index,
                        op: op.clone(),
                    });
                }
                ui.horizontal(|ui| {
                    if ui.add_enabled(index > 0, egui::Button::new("Up")).clicked() {
                        edits.push(Edit::MoveOp {
                            node,
                            from: index,
                            to: index - 1,
                        });
                    }
                    if ui
                        .add_enabled(index + 1 < n, egui::Button::new("Down"))
                        .clicked()
                    {
                        edits.push(Edit::MoveOp {
                            node,
                            from: index,
                            to: index + 1,
                        });
                    }
                    if ui.button("Remove").clicked() {
                        edits.push(Edit::RemoveOp { node, index });
                    }
                });
            });
        });
    }
    ui.data_mut(|d| d.insert_temp(op_id(), None::<usize>));
    ui.menu_button("Add op", |ui| {
        for (name, op) in op_names() {
            if ui.button(name).clicked() {
                edits.push(Edit::AddOp { node, op });
                ui.close();
            }
        }
    });
}

/// A 4×4 matrix edited row by row, as the file writes it.
fn matrix(ui: &mut egui::Ui, m: &mut Mat4) -> bool {
    let mut changed = false;
    ui.horizontal(|ui| {
        ui.label("Matrix (rows)");
        refusal_note(ui, &Field::Op("Matrix"));
    });
    let mut rows = [
        m.row(0).to_array(),
        m.row(1).to_array(),
        m.row(2).to_array(),
        m.row(3).to_array(),
    ];
    egui::Grid::new("matrix").show(ui, |ui| {
        for row in &mut rows {
            for c in row.iter_mut() {
                changed |= number(ui, c, |d| d.speed(0.01).max_decimals(4)).changed();
            }
            ui.end_row();
        }
    });
    if changed {
        *m = Mat4::from_cols_array_2d(&rows).transpose();
    }
    changed
}

/// "When does M·n happen to work?": the selected Transform's and the chain's similitude test.
fn similitude_lines(ui: &mut egui::Ui, doc: &Document, id: NodeId) {
    let (own, chain) = crate::story::node_similitudes(&doc.scene, id);
    let ascii = crate::gui::widgets::ascii_math;
    if let Some(t) = own {
        ui.label(format!("This Transform: {}", ascii(&t.summary())));
    }
    if id != doc.scene.graph.root() {
        ui.label(format!("World from here: {}", ascii(&chain.summary())));
    }
}

/// The path from the root to the selection, "Group › Transform › Sphere"; a deep one keeps
/// its two first and four last steps (20,000 nested Groups once filled the inspector).
fn breadcrumb(names: &[&str]) -> String {
    const HEAD: usize = 2;
    const TAIL: usize = 4;
    if names.len() <= HEAD + TAIL + 1 {
        return names.join(" › ");
    }
    let hidden = names.len() - HEAD - TAIL;
    format!(
        "{} › … {hidden} more … › {}",
        names[..HEAD].join(" › "),
        names[names.len() - TAIL..].join(" › ")
    )
}

#[cfg(test)]
mod tests {
    use super::breadcrumb;

    #[test]
    fn a_deep_breadcrumb_keeps_its_ends_and_counts_the_middle() {
        assert_eq!(
            breadcrumb(&["Group", "Transform", "Sphere"]),
            "Group › Transform › Sphere"
        );
        let deep: Vec<&str> = std::iter::repeat_n("Group", 20_000)
            .chain(["Sphere"])
            .collect();
        let b = breadcrumb(&deep);
        assert_eq!(
            b,
            "Group › Group › … 19995 more … › Group › Group › Group › Sphere"
        );
    }
}
