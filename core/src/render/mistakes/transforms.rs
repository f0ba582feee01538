//! The two transform mistakes that are the course parser's own rules: Rotate's axis used as
//! written, and Matrix composed on the other side. They change the scene, not the shading,
//! so a variant with one of them is rendered from its own compiled scene.

use glam::{Mat4, Vec3};

use crate::scene::{NodeKind, Scene, TransformOp};

/// The scene as a program that uses Rotate's axis as written (`rotate_as_written`) or puts
/// Matrix on the other side (`matrix_course_side`) would build it, or `None` when that
/// changes none of its transforms.
pub(super) fn course_parser_scene(
    scene: &Scene,
    rotate_as_written: bool,
    matrix_course_side: bool,
) -> Option<Scene> {
    let mut out = scene.clone();
    let mut changed = false;
    let ids: Vec<_> = out.graph.iter().map(|(id, _)| id).collect();
    for id in ids {
        let Some(node) = out.graph.get_mut(id) else {
            continue;
        };
        let NodeKind::Transform(ops) = &mut node.kind else {
            continue;
        };
        if rotate_as_written {
            for op in ops.iter_mut() {
                if let TransformOp::Rotate { axis, degrees } = *op
                    && (axis.length() - 1.0).abs() > 1e-6
                {
                    *op = TransformOp::Matrix(rotation_as_written(axis, degrees));
                    changed = true;
                }
            }
        }
        if matrix_course_side
            && ops.len() > 1
            && let Some(m) = course_side_composition(ops)
        {
            *ops = vec![TransformOp::Matrix(m)];
            changed = true;
        }
    }
    changed.then_some(out)
}

/// The course's axis rotation with the axis used as written: Rodrigues' matrix for a unit
/// axis, which for |axis| ≠ 1 is a rotation and a scale.
fn rotation_as_written(a: Vec3, degrees: f32) -> Mat4 {
    let (s, c) = degrees.to_radians().sin_cos();
    let k = 1.0 - c;
    let (x, y, z) = (a.x, a.y, a.z);
    // Columns of the row-major course matrix.
    Mat4::from_cols(
        glam::Vec4::new(k * x * x + c, k * x * y + z * s, k * x * z - y * s, 0.0),
        glam::Vec4::new(k * x * y - z * s, k * y * y + c, k * y * z + x * s, 0.0),
        glam::Vec4::new(k * x * z + y * s, k * y * z - x * s, k * z * z + c, 0.0),
        glam::Vec4::W,
    )
}

/// The ops composed as the course parser does: M = M·T for each op in order, but
/// M = T·M for `Matrix`; `None` where that is the same as tracelab's order.
fn course_side_composition(ops: &[TransformOp]) -> Option<Mat4> {
    let first_matrix = ops
        .iter()
        .position(|op| matches!(op, TransformOp::Matrix(_)))?;
    // A Matrix first in the list composes the same on either side.
    if first_matrix == 0
        && ops
            .iter()
            .skip(1)
            .all(|op| !matches!(op, TransformOp::Matrix(_)))
    {
        return None;
    }
    let mut m = Mat4::IDENTITY;
    for op in ops {
        m = match op {
            TransformOp::Matrix(t) => *t * m,
            other => m * other.matrix(),
        };
    }
    Some(m)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_unit_axis_rotates_as_glam_does_and_a_long_one_also_scales() {
        let a = rotation_as_written(Vec3::Z, 90.0);
        assert!(a.abs_diff_eq(Mat4::from_rotation_z(90f32.to_radians()), 1e-6));
        let b = rotation_as_written(Vec3::new(0.0, 0.0, 2.0), 0.0);
        // cos 0 = 1, k = 0: the identity whatever the axis; at 180° z² k + c = 4·2 − 1 = 7.
        assert!(b.abs_diff_eq(Mat4::IDENTITY, 1e-6));
        let c = rotation_as_written(Vec3::new(0.0, 0.0, 2.0), 180.0);
        assert!((c.z_axis.z - 7.0).abs() < 1e-5, "{c}");
    }

    #[test]
    fn the_course_puts_matrix_on_the_other_side() {
        let t = Mat4::from_translation(Vec3::Y);
        let ops = [TransformOp::UniformScale(2.0), TransformOp::Matrix(t)];
        let m = course_side_composition(&ops).expect("differs");
        // Course: M = T·S, so the origin goes to (0, 1, 0), not (0, 2, 0).
        assert!((m.transform_point3(Vec3::ZERO) - Vec3::Y).length() < 1e-6);
        assert_eq!(course_side_composition(&[TransformOp::Matrix(t)]), None);
    }
}
