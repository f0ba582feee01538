//! The inspector's Transform ops: each op's numbers, moving and removing ops, adding one,
//! and a Matrix edited row by row.

use glam::{Mat4, Vec3};
use tracelab_core::{Field, NodeId, TransformOp};

use crate::document::edit::Edit;
use crate::gui::drag_speed::DragSpeeds;
use crate::gui::widgets::number;

use super::super::fields::{op_id, refusal_note, scalar, vec3};

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
pub(super) fn transform_ops(
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
