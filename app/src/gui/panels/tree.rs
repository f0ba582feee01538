//! The scene tree (left panel). The scene is first walked into plain rows (testable without
//! a UI), then drawn; clicks and toolbar buttons become commands (selections and [`Edit`]s).

use glam::Vec3;
use tracelab_core::scene::{LightKind, Walk};
use tracelab_core::{CsgOp, MeshSlot, NodeId, NodeKind, Scene, TransformOp};

use crate::document::edit::Edit;
use crate::document::{Document, Selection};
use crate::gui::command::AppCommand;
use crate::node_label::node_label;

#[derive(Clone, Debug, PartialEq)]
pub struct TreeRow {
    pub id: NodeId,
    pub depth: usize,
    /// e.g. `Transform: Translate(1, 0.5, 0) · Scale(2, 2, 2)`
    pub label: String,
    /// Material the node renders with (`None`: the default material).
    pub material: Option<u32>,
    /// Why the node renders nothing or cannot be saved yet (a mesh that did not load, one
    /// with no file chosen): drawn in red.
    pub error: Option<String>,
}

/// The object hierarchy as rows, parents first.
pub fn tree_rows(scene: &Scene) -> Vec<TreeRow> {
    let g = &scene.graph;
    // The same rules the editor and Save apply; an edited document breaks none but
    // "incomplete" ones.
    let mut problems: std::collections::HashMap<NodeId, String> = std::collections::HashMap::new();
    for p in tracelab_core::check_scene(scene) {
        if let Some(id) = p.node() {
            problems.entry(id).or_insert(p.reason);
        }
    }
    let mut rows = Vec::new();
    for v in Walk::new(g) {
        let (id, n) = (v.id, v.node);
        let error = match &n.kind {
            NodeKind::TriangleMesh {
                mesh: MeshSlot::Failed(e),
                ..
            } => Some(e.clone()),
            _ => None,
        };
        let error = problems.remove(&id).or(error);
        rows.push(TreeRow {
            id,
            depth: v.depth,
            label: node_label(&n.kind, n.children.len()),
            material: v.material,
            error,
        });
    }
    rows
}

/// Draws the tree; returns the edits asked for. `reveal` scrolls that node's row into view
/// (when it was selected elsewhere, e.g. by clicking the render).
pub fn ui(
    ui: &mut egui::Ui,
    doc: &Document,
    rows: &[TreeRow],
    reveal: Option<NodeId>,
) -> Vec<AppCommand> {
    let mut edits = Vec::new();
    toolbar(ui, doc, &mut edits);
    ui.separator();
    let sel = doc.selection;
    let mut clicked = None;
    {
        let mut item = |ui: &mut egui::Ui, s: Selection, text: String| {
            if ui.selectable_label(sel == Some(s), text).clicked() {
                clicked = Some(s);
            }
        };
        item(ui, Selection::Camera, camera_label(&doc.scene));
        item(
            ui,
            Selection::Lights,
            format!("Lights ({})", doc.scene.lights().len()),
        );
        for (i, l) in doc.scene.lights().iter().enumerate() {
            // Point lights named apart: the gizmo moves them, a direction has no place.
            let label = match l.kind {
                LightKind::Point { .. } => format!("Point light {i}"),
                LightKind::Directional { .. } => format!("Light {i}"),
            };
            ui.horizontal(|ui| {
                ui.add_space(14.0);
                item(ui, Selection::Light(i), label);
            });
        }
        item(ui, Selection::Background, "Background".into());
        item(
            ui,
            Selection::Materials,
            format!("Materials ({})", doc.scene.materials.len()),
        );
        for (i, m) in doc.scene.materials.iter().enumerate() {
            ui.horizontal(|ui| {
                ui.add_space(14.0);
                swatch(ui, m.diffuse);
                let kind = m.texture.as_ref().map_or("Material", |t| t.kind.name());
                item(ui, Selection::Material(i), format!("{kind} {i}"));
            });
        }
        ui.separator();
        let row_h = ui.spacing().interact_size.y;
        // Only visible rows are laid out: meshes and generated scenes can have many nodes.
        // Scrolls sideways too, so long summaries do not widen the panel.
        let mut area = egui::ScrollArea::both()
            .id_salt("objects")
            .auto_shrink([false, false]);
        if let Some(i) = reveal.and_then(|id| rows.iter().position(|r| r.id == id)) {
            let step = row_h + ui.spacing().item_spacing.y;
            area = area.vertical_scroll_offset(((i as f32 - 3.0) * step).max(0.0));
        }
        area.show_rows(ui, row_h, rows.len(), |ui, range| {
            for row in &rows[range] {
                ui.horizontal(|ui| {
                    ui.add_space(row.depth as f32 * 14.0);
                    if let Some(mat) = row
                        .material
                        .and_then(|m| doc.scene.materials.get(m as usize))
                    {
                        swatch(ui, mat.diffuse);
                    }
                    let mut text = short_numbers(&row.label);
                    if let Some(m) = row.material {
                        text.push_str(&format!("  [mat {m}]"));
                    }
                    let s = Selection::Node(row.id);
                    let mut label = egui::RichText::new(text);
                    if row.error.is_some() {
                        label = label.color(ui.visuals().error_fg_color);
                    }
                    let r = ui.selectable_label(sel == Some(s), label);
                    // The full text (a row is cut at the panel's edge, and its numbers are
                    // rounded as the inspector's are), and the error when there is one.
                    let r = match &row.error {
                        Some(e) => r.on_hover_text(format!("{}\n{e}", row.label)),
                        None => r.on_hover_text(&row.label),
                    };
                    if r.clicked() {
                        clicked = Some(s);
                    }
                });
            }
        });
    }
    let mut asked: Vec<AppCommand> = edits.into_iter().map(AppCommand::Edit).collect();
    if let Some(s) = clicked {
        asked.push(AppCommand::Select(Some(s)));
    }
    asked
}

fn camera_label(scene: &Scene) -> String {
    match scene.camera {
        tracelab_core::Camera::Orthographic { .. } => "Camera (orthographic)".into(),
        tracelab_core::Camera::Perspective { .. } => "Camera (perspective)".into(),
    }
}

fn swatch(ui: &mut egui::Ui, c: Vec3) {
    let (rect, _) = ui.allocate_exact_size(egui::vec2(10.0, 10.0), egui::Sense::hover());
    ui.painter()
        .rect_filled(rect, 2.0, crate::gui::widgets::color32(c));
}

/// The Group new objects go into: the selected Group, or the Group holding the selection.
fn target_group(doc: &Document) -> NodeId {
    let g = &doc.scene.graph;
    let Some(Selection::Node(id)) = doc.selection else {
        return g.root();
    };
    let path = g.path_to(id).unwrap_or_default();
    path.iter()
        .rev()
        .copied()
        .find(|&p| matches!(g.get(p).map(|n| &n.kind), Some(NodeKind::Group)))
        .unwrap_or(g.root())
}

fn toolbar(ui: &mut egui::Ui, doc: &Document, edits: &mut Vec<Edit>) {
    let parent = target_group(doc);
    let selected = match doc.selection {
        Some(Selection::Node(id)) if id != doc.scene.graph.root() => Some(id),
        _ => None,
    };
    ui.horizontal_wrapped(|ui| {
        ui.menu_button("Add", |ui| {
            let kinds: [(&str, NodeKind); 10] = [
                (
                    "Sphere",
                    NodeKind::Sphere {
                        center: Vec3::ZERO,
                        radius: 1.0,
                    },
                ),
                (
                    "Plane",
                    NodeKind::Plane {
                        normal: Vec3::Y,
                        offset: -1.0,
                    },
                ),
                (
                    "Triangle",
                    NodeKind::Triangle {
                        vertices: [
                            Vec3::new(-1.0, 0.0, 0.0),
                            Vec3::new(1.0, 0.0, 0.0),
                            Vec3::new(0.0, 1.5, 0.0),
                        ],
                    },
                ),
                (
                    "TriangleMesh",
                    NodeKind::TriangleMesh {
                        obj_file: String::new(),
                        mesh: MeshSlot::Failed("no OBJ file chosen yet".into()),
                    },
                ),
                (
                    "Box",
                    NodeKind::Box {
                        min: Vec3::splat(-1.0),
                        max: Vec3::splat(1.0),
                    },
                ),
                ("Union of a box and a sphere", NodeKind::Csg(CsgOp::Union)),
                (
                    "Intersection of a box and a sphere",
                    NodeKind::Csg(CsgOp::Intersection),
                ),
                (
                    "Box minus a sphere (Subtraction)",
                    NodeKind::Csg(CsgOp::Subtraction),
                ),
                ("Group", NodeKind::Group),
                (
                    "Transform",
                    NodeKind::Transform(vec![TransformOp::Translate(Vec3::ZERO)]),
                ),
            ];
            for (name, kind) in kinds {
                if ui.button(name).clicked() {
                    edits.push(Edit::AddNode { parent, kind });
                    ui.close();
                }
            }
        });
        ui.add_enabled_ui(selected.is_some(), |ui| {
            let Some(node) = selected.or(Some(doc.scene.graph.root())) else {
                return;
            };
            if ui.button("Delete").on_hover_text("Delete (Del)").clicked() {
                edits.push(Edit::DeleteNode { node });
            }
            if ui.button("Duplicate").clicked() {
                edits.push(Edit::DuplicateNode { node });
            }
            if ui.button("Wrap in Transform").clicked() {
                edits.push(Edit::WrapInTransform { node });
            }
            if ui.button("Wrap in Group").clicked() {
                edits.push(Edit::WrapInGroup { node });
            }
            let g = &doc.scene.graph;
            let parents = g.parents();
            // Up/down move the node's slot (itself or the Transform holding it) in its Group.
            // Always drawn (disabled where they cannot move), so the first selection does not
            // rewrap this row and shift the tree under the pointer.
            let mut slot = node;
            let mut place = None;
            while let Some(p) = parents.get(slot.index()).copied().flatten() {
                if matches!(g.node(p).kind, NodeKind::Group) {
                    let pos = g
                        .node(p)
                        .children
                        .iter()
                        .position(|&c| c == slot)
                        .unwrap_or(0);
                    place = Some((p, pos, g.node(p).children.len()));
                    break;
                }
                slot = p;
            }
            let up = place.filter(|&(_, pos, _)| pos > 0);
            if ui
                .add_enabled(up.is_some(), egui::Button::new("Up"))
                .clicked()
                && let Some((p, pos, _)) = up
            {
                edits.push(Edit::MoveNode {
                    node,
                    new_parent: p,
                    index: pos - 1,
                });
            }
            let down = place.filter(|&(_, pos, n)| pos + 1 < n);
            if ui
                .add_enabled(down.is_some(), egui::Button::new("Down"))
                .clicked()
                && let Some((p, pos, _)) = down
            {
                edits.push(Edit::MoveNode {
                    node,
                    new_parent: p,
                    index: pos + 2,
                });
            }
            ui.menu_button("Move to", |ui| {
                for (id, n) in g.iter() {
                    if matches!(n.kind, NodeKind::Group) {
                        let name = if id == g.root() {
                            "root Group".to_string()
                        } else {
                            format!("Group #{}", id.0)
                        };
                        if ui.button(name).clicked() {
                            edits.push(Edit::MoveNode {
                                node,
                                new_parent: id,
                                index: usize::MAX,
                            });
                            ui.close();
                        }
                    }
                }
            });
        });
    });
}

/// Decimals the tree shows, as the inspector's fields do.
const DECIMALS: usize = 4;

/// `label` with every number of more than [`DECIMALS`] decimals rounded to that many
/// ("Translate(2.7747805, 0, 0)" reads "Translate(2.7748, 0, 0)").
pub fn short_numbers(label: &str) -> String {
    let mut out = String::with_capacity(label.len());
    let chars: Vec<char> = label.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        let starts_number = chars[i].is_ascii_digit()
            && (i == 0 || !(chars[i - 1].is_alphanumeric() || chars[i - 1] == '.'));
        if !starts_number {
            out.push(chars[i]);
            i += 1;
            continue;
        }
        let start = i;
        while i < chars.len() && chars[i].is_ascii_digit() {
            i += 1;
        }
        let mut decimals = 0;
        if i + 1 < chars.len() && chars[i] == '.' && chars[i + 1].is_ascii_digit() {
            i += 1;
            while i < chars.len() && chars[i].is_ascii_digit() {
                i += 1;
                decimals += 1;
            }
        }
        let number: String = chars[start..i].iter().collect();
        let exponent = i < chars.len() && matches!(chars[i], 'e' | 'E');
        match number.parse::<f64>() {
            Ok(v) if decimals > DECIMALS && !exponent => {
                let t = format!("{v:.DECIMALS$}");
                out.push_str(t.trim_end_matches('0').trim_end_matches('.'));
            }
            _ => out.push_str(&number),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tree_labels_round_long_numbers_as_the_inspector_does() {
        assert_eq!(
            short_numbers("Transform: Translate(2.7747805, -0.5, 0) · Scale(1, 1e-7, 3.00001)"),
            "Transform: Translate(2.7748, -0.5, 0) · Scale(1, 1e-7, 3)"
        );
        assert_eq!(
            short_numbers("Sphere: (0, 0, 0) r 1  [mat 2]"),
            "Sphere: (0, 0, 0) r 1  [mat 2]"
        );
        assert_eq!(short_numbers("Box2: 0.123456789"), "Box2: 0.1235");
    }
}
