//! "When does M·n happen to work?" For a similitude — rotations, reflections, uniform
//! scales (and any translation, which normals never see) — (M⁻¹)ᵀ = λM, so M·n points the
//! right way after normalising. This names, for a 3×3 linear part, whether it is one, its λ,
//! and otherwise what breaks it, measured on the object's own axes: axes stretched by
//! different amounts (non-uniform scale) or no longer at right angles (shear).

use glam::{DMat3, DVec3};

/// Relative tolerance on the Gram matrix: matrices are composed in f64, so a product of
/// rotations and uniform scales lands far inside it, and a visible shear far outside.
const TOLERANCE: f64 = 1e-9;

#[derive(Clone, Debug, PartialEq)]
pub struct SimilitudeTest {
    /// How long each object axis becomes: |A·x̂|, |A·ŷ|, |A·ẑ|.
    pub axis_scales: [f64; 3],
    /// Angles in degrees between the images of the axis pairs (x,y), (y,z), (z,x).
    pub axis_angles: [f64; 3],
    /// det A < 0: a reflection (still a similitude, if nothing else breaks it).
    pub reflects: bool,
    /// λ with (A⁻¹)ᵀ = λ·A, when A is a similitude: 1/c² for A = c·Q, Q orthogonal.
    pub lambda: Option<f64>,
    /// What breaks it, empty for a similitude.
    pub breaks: Vec<Breaks>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Breaks {
    /// The axes are stretched by different amounts (the smallest and largest of them).
    NonUniformScale { min: f64, max: f64 },
    /// Two axes' images are not at right angles: the angle furthest from 90°, in degrees.
    Shear { angle_degrees: f64 },
}

impl SimilitudeTest {
    pub fn is_similitude(&self) -> bool {
        self.breaks.is_empty()
    }

    /// One line for the inspector and the command line.
    pub fn summary(&self) -> String {
        if let Some(l) = self.lambda {
            let kind = if self.reflects {
                "similitude (with a reflection)"
            } else {
                "similitude"
            };
            return format!("{kind}: (M⁻¹)ᵀ = λ·M with λ = {}", short(l));
        }
        let parts: Vec<String> = self
            .breaks
            .iter()
            .map(|b| match b {
                Breaks::NonUniformScale { min, max } => {
                    format!(
                        "non-uniform scale (axes stretched {} to {})",
                        short(*min),
                        short(*max)
                    )
                }
                Breaks::Shear { angle_degrees } => format!("shear (axes at {angle_degrees:.2}°)"),
            })
            .collect();
        format!("not a similitude: {}", parts.join(", "))
    }
}

/// The test for the linear part `a` of a transform (its upper-left 3×3), composed in f64.
pub fn similitude(a: DMat3) -> SimilitudeTest {
    similitude_within(a, TOLERANCE)
}

/// `similitude` with a chosen relative tolerance (f32 matrices need about 1e-6).
pub fn similitude_within(a: DMat3, tolerance: f64) -> SimilitudeTest {
    let cols = [a.x_axis, a.y_axis, a.z_axis];
    let len2 = cols.map(|c| c.length_squared());
    let axis_scales = len2.map(f64::sqrt);
    let pairs = [(0, 1), (1, 2), (2, 0)];
    let axis_angles = pairs.map(|(i, j)| angle_degrees(cols[i], cols[j]));
    let reflects = a.determinant() < 0.0;

    // AᵀA = c²·I exactly when A = c·Q: equal diagonal, zero off-diagonal, relative to c².
    let c2 = (len2[0] + len2[1] + len2[2]) / 3.0;
    let mut breaks = Vec::new();
    let (min, max) = axis_scales
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), &s| {
            (lo.min(s), hi.max(s))
        });
    if len2.iter().any(|&l| (l - c2).abs() > tolerance * c2) {
        breaks.push(Breaks::NonUniformScale { min, max });
    }
    if pairs
        .iter()
        .any(|&(i, j)| cols[i].dot(cols[j]).abs() > tolerance * c2)
    {
        let worst = axis_angles.iter().copied().fold(90.0, |w: f64, a| {
            if (a - 90.0).abs() > (w - 90.0).abs() {
                a
            } else {
                w
            }
        });
        breaks.push(Breaks::Shear {
            angle_degrees: worst,
        });
    }
    let lambda = (breaks.is_empty() && c2 > 0.0).then(|| 1.0 / c2);
    SimilitudeTest {
        axis_scales,
        axis_angles,
        reflects,
        lambda,
        breaks,
    }
}

fn angle_degrees(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b)).to_degrees()
}

/// Four significant digits, in exponent form for huge and tiny values.
fn short(v: f64) -> String {
    if v != 0.0 && !(1e-3..1e5).contains(&v.abs()) {
        format!("{v:.3e}")
    } else {
        format!("{}", (v * 1e4).round() / 1e4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DQuat;

    #[test]
    fn a_rotation_times_a_uniform_scale_is_a_similitude_with_lambda_one_over_c_squared() {
        let a = DMat3::from_quat(DQuat::from_axis_angle(
            DVec3::new(1.0, 2.0, 3.0).normalize(),
            0.7,
        )) * 2.0;
        let t = similitude(a);
        assert!(t.is_similitude(), "{t:?}");
        let l = t.lambda.expect("lambda");
        assert!((l - 0.25).abs() < 1e-12, "{l}");
        // The defining identity, checked on the matrix itself.
        let diff = a.inverse().transpose() - a * l;
        assert!(diff.to_cols_array().iter().all(|d| d.abs() < 1e-12));
    }

    #[test]
    fn a_reflection_is_a_similitude() {
        let t = similitude(DMat3::from_diagonal(DVec3::new(-3.0, 3.0, 3.0)));
        assert!(t.is_similitude() && t.reflects);
        assert!((t.lambda.expect("lambda") - 1.0 / 9.0).abs() < 1e-15);
    }

    #[test]
    fn a_non_uniform_scale_is_named_with_its_stretches() {
        let t = similitude(DMat3::from_diagonal(DVec3::new(1.5, 0.5, 1.0)));
        assert_eq!(t.lambda, None);
        assert_eq!(t.breaks, [Breaks::NonUniformScale { min: 0.5, max: 1.5 }]);
        assert!(t.summary().contains("non-uniform scale"), "{}", t.summary());
    }

    #[test]
    fn a_shear_is_named_with_the_angle_between_the_axes() {
        // x' = x + y: ŷ goes to (1, 1, 0), 45° from x̂, and √2 long.
        let a = DMat3::from_cols(DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Z);
        let t = similitude(a);
        assert!(t.breaks.iter().any(|b| matches!(b, Breaks::Shear { angle_degrees } if (angle_degrees - 45.0).abs() < 1e-9)), "{t:?}");
        assert!(
            t.breaks
                .iter()
                .any(|b| matches!(b, Breaks::NonUniformScale { .. }))
        );
    }

    #[test]
    fn m_n_points_along_the_correct_normal_exactly_for_similitudes() {
        let n = DVec3::new(1.0, 1.0, 0.3).normalize();
        let rot = DMat3::from_quat(DQuat::from_rotation_y(0.4));
        for (a, similar) in [
            (rot * 3.0, true),
            (DMat3::from_diagonal(DVec3::new(1.0, -1.0, 1.0)) * rot, true),
            (DMat3::from_diagonal(DVec3::new(2.0, 1.0, 1.0)) * rot, false),
            (
                rot * DMat3::from_cols(DVec3::X, DVec3::new(0.5, 1.0, 0.0), DVec3::Z),
                false,
            ),
        ] {
            let gap = angle_degrees(a.inverse().transpose() * n, a * n);
            assert_eq!(similitude(a).is_similitude(), similar, "{a:?}");
            assert_eq!(gap < 1e-9, similar, "{gap}° for {a:?}");
        }
    }

    #[test]
    fn an_equal_area_shear_with_equal_axis_lengths_is_still_caught() {
        // Columns of equal length at 60°: only the angle betrays it.
        let c = 60f64.to_radians();
        let a = DMat3::from_cols(DVec3::X, DVec3::new(c.cos(), c.sin(), 0.0), DVec3::Z);
        let t = similitude(a);
        assert_eq!(t.breaks.len(), 1, "{t:?}");
        assert!(
            matches!(t.breaks[0], Breaks::Shear { angle_degrees } if (angle_degrees - 60.0).abs() < 1e-9)
        );
    }
}
