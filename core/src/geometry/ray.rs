use glam::{Mat4, Vec3};

/// A ray `origin + t · direction`. The direction is not necessarily unit length: in object
/// space it is M⁻¹ applied to the world direction, so t means the same in both spaces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: Vec3,
    pub direction: Vec3,
}

impl Ray {
    pub fn new(origin: Vec3, direction: Vec3) -> Self {
        Ray { origin, direction }
    }

    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.direction * t
    }

    /// The same ray expressed in another space: origin as a point, direction as a vector,
    /// direction deliberately not renormalised.
    pub fn transformed(&self, m: &Mat4) -> Ray {
        Ray {
            origin: m.transform_point3(self.origin),
            direction: m.transform_vector3(self.direction),
        }
    }
}
