//! Transform ops as the scene format lists them, and their composition (in f64, so long
//! chains keep their precision).

use glam::{DMat4, DVec3, Mat4, Vec3};

#[derive(Clone, Debug, PartialEq)]
pub enum TransformOp {
    Scale(Vec3),
    UniformScale(f32),
    Translate(Vec3),
    XRotate(f32),
    YRotate(f32),
    ZRotate(f32),
    /// Rotation about `axis` (normalised when composed) by `degrees`.
    Rotate {
        axis: Vec3,
        degrees: f32,
    },
    /// A 4×4 matrix, as written row by row in the file.
    Matrix(Mat4),
}

impl TransformOp {
    pub fn matrix(&self) -> Mat4 {
        match *self {
            TransformOp::Scale(s) => Mat4::from_scale(s),
            TransformOp::UniformScale(s) => Mat4::from_scale(Vec3::splat(s)),
            TransformOp::Translate(t) => Mat4::from_translation(t),
            TransformOp::XRotate(d) => Mat4::from_rotation_x(d.to_radians()),
            TransformOp::YRotate(d) => Mat4::from_rotation_y(d.to_radians()),
            TransformOp::ZRotate(d) => Mat4::from_rotation_z(d.to_radians()),
            TransformOp::Rotate { axis, degrees } => {
                // A deliberate difference from the course parser: the axis is normalised, so
                // `Rotate { 0 0 2 90 }` is a rotation, not a rotation and a scale.
                let axis = unit(axis).unwrap_or(Vec3::Z);
                Mat4::from_axis_angle(axis, degrees.to_radians())
            }
            TransformOp::Matrix(m) => m,
        }
    }

    pub fn name(&self) -> &'static str {
        match self {
            TransformOp::Scale(_) => "Scale",
            TransformOp::UniformScale(_) => "UniformScale",
            TransformOp::Translate(_) => "Translate",
            TransformOp::XRotate(_) => "XRotate",
            TransformOp::YRotate(_) => "YRotate",
            TransformOp::ZRotate(_) => "ZRotate",
            TransformOp::Rotate { .. } => "Rotate",
            TransformOp::Matrix(_) => "Matrix",
        }
    }

    /// A short human summary, e.g. `Translate(1, 0.5, 0)`.
    pub fn summary(&self) -> String {
        // Very large and very small values in exponent form: 3.4028235e38, not 39 digits.
        let n = |x: f32| {
            let a = x.abs();
            if a.is_finite() && (a >= 1e7 || (a != 0.0 && a < 1e-4)) {
                format!("{x:e}")
            } else {
                format!("{x}")
            }
        };
        let v = |v: Vec3| format!("{}, {}, {}", n(v.x), n(v.y), n(v.z));
        match self {
            TransformOp::Scale(s) => format!("Scale({})", v(*s)),
            TransformOp::UniformScale(s) => format!("UniformScale({})", n(*s)),
            TransformOp::Translate(t) => format!("Translate({})", v(*t)),
            TransformOp::XRotate(d) => format!("XRotate({}°)", n(*d)),
            TransformOp::YRotate(d) => format!("YRotate({}°)", n(*d)),
            TransformOp::ZRotate(d) => format!("ZRotate({}°)", n(*d)),
            TransformOp::Rotate { axis, degrees } => {
                format!("Rotate({}; {}°)", v(*axis), n(*degrees))
            }
            TransformOp::Matrix(_) => "Matrix(4×4)".to_string(),
        }
    }
}

/// M = op1 · op2 · … · opn: the first op listed is applied last, as nested Transforms would.
/// (Another deliberate difference from the course code: `Matrix` composes in its listed
/// position like every other op.) Composed in f64 and rounded once, so long chains keep
/// their precision.
pub fn compose(ops: &[TransformOp]) -> Mat4 {
    compose_f64(ops).as_mat4()
}

/// M = op1 · op2 · … · opn in f64.
pub fn compose_f64(ops: &[TransformOp]) -> DMat4 {
    ops.iter()
        .fold(DMat4::IDENTITY, |m, op| m * op_matrix_f64(op))
}

/// An op's matrix in f64, so long chains compose without losing precision.
pub fn op_matrix_f64(op: &TransformOp) -> DMat4 {
    let d = |v: Vec3| v.as_dvec3();
    match *op {
        TransformOp::Scale(s) => DMat4::from_scale(d(s)),
        TransformOp::UniformScale(s) => DMat4::from_scale(DVec3::splat(f64::from(s))),
        TransformOp::Translate(t) => DMat4::from_translation(d(t)),
        TransformOp::XRotate(a) => DMat4::from_rotation_x(f64::from(a).to_radians()),
        TransformOp::YRotate(a) => DMat4::from_rotation_y(f64::from(a).to_radians()),
        TransformOp::ZRotate(a) => DMat4::from_rotation_z(f64::from(a).to_radians()),
        TransformOp::Rotate { axis, degrees } => {
            // Normalised in f64 after the overflow-safe f32 step, so `0 0 1e20` is z.
            let axis = unit(axis).unwrap_or(Vec3::Z).as_dvec3().normalize();
            DMat4::from_axis_angle(axis, f64::from(degrees).to_radians())
        }
        TransformOp::Matrix(m) => m.as_dmat4(),
    }
}

/// `v` at unit length, or `None` for a zero or non-finite vector. Divides by the largest
/// component first, so vectors whose squared length overflows f32 (`0 0 1e20`) still
/// normalise to what their direction says.
pub fn unit(v: Vec3) -> Option<Vec3> {
    let m = v.abs().max_element();
    if !(m.is_finite() && m > 0.0) {
        return None;
    }
    (v / m).try_normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_listed_op_is_applied_last() {
        let m = compose(&[
            TransformOp::Translate(Vec3::X),
            TransformOp::UniformScale(2.0),
        ]);
        // scale first (1,0,0) -> (2,0,0), then translate -> (3,0,0)
        assert!((m.transform_point3(Vec3::X) - Vec3::new(3.0, 0.0, 0.0)).length() < 1e-6);
    }

    #[test]
    fn rotate_axis_is_normalised() {
        let a = TransformOp::Rotate {
            axis: Vec3::new(0.0, 0.0, 5.0),
            degrees: 90.0,
        }
        .matrix();
        let b = TransformOp::ZRotate(90.0).matrix();
        assert!(a.abs_diff_eq(b, 1e-6));
    }

    #[test]
    fn matrix_op_composes_in_listed_position() {
        let t = Mat4::from_translation(Vec3::new(0.0, 1.0, 0.0));
        let m = compose(&[TransformOp::UniformScale(2.0), TransformOp::Matrix(t)]);
        // translate first, then scale: (0,0,0) -> (0,1,0) -> (0,2,0)
        assert!((m.transform_point3(Vec3::ZERO) - Vec3::new(0.0, 2.0, 0.0)).length() < 1e-6);
    }
}
