//! The inspector (right panel): every parameter of the selection, as widgets that emit
//! [`Edit`]s (and, for a TriangleMesh's file, [`AppCommand::LoadMesh`]). Widgets edit copies;
//! nothing here changes the document or reads files.

//!
//! In parts by job: this file the selection's dispatch and an object node's own fields,
//! `scene_items.rs` the camera, lights and background, `material.rs` a material's colour,
//! Phong fields and solid texture, `transform.rs` a Transform's ops.

mod material;
mod scene_items;
mod transform;

use glam::Vec3;
use tracelab_core::{CsgOp, Field, Light, Material, MeshSlot, NodeId, NodeKind, Place};

use crate::document::edit::Edit;
use crate::document::{Document, Selection};
use crate::gui::command::AppCommand;
use crate::gui::drag_speed::{DragSpeeds, world_per_unit};

use super::fields::{refusal_note, scalar, show_refusal_for, vec3};
use material::material;
use scene_items::{background, camera, light};
use transform::transform_ops;

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
