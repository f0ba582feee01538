//! The course's Phong fields (assignments 3 and 4) beyond `diffuseColor`, with the course
//! parser's defaults. They live in `Material::extra` in the file's order, so the writer gives
//! back the text it read; this is their typed view.

use glam::Vec3;

use super::Material;

/// A Phong field of a material: its name in the file and how many numbers it takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PhongField {
    pub name: &'static str,
    pub numbers: usize,
}

/// The fields `PhongMaterial` (and `Material`, read the same way as the course's parser
/// does) may hold besides `diffuseColor`.
pub const PHONG_FIELDS: [PhongField; 5] = [
    PhongField {
        name: "specularColor",
        numbers: 3,
    },
    PhongField {
        name: "exponent",
        numbers: 1,
    },
    PhongField {
        name: "reflectiveColor",
        numbers: 3,
    },
    PhongField {
        name: "transparentColor",
        numbers: 3,
    },
    PhongField {
        name: "indexOfRefraction",
        numbers: 1,
    },
];

/// The Phong field called `name`, if it is one.
pub fn phong_field(name: &str) -> Option<PhongField> {
    PHONG_FIELDS.iter().copied().find(|f| f.name == name)
}

/// What a material shades with beyond its diffuse colour.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Phong {
    pub specular: Vec3,
    pub exponent: f32,
    pub reflective: Vec3,
    pub transparent: Vec3,
    pub index_of_refraction: f32,
}

impl Default for Phong {
    /// The course parser's defaults: no highlight, exponent 1, neither mirror nor glass,
    /// index 1.
    fn default() -> Self {
        Phong {
            specular: Vec3::ZERO,
            exponent: 1.0,
            reflective: Vec3::ZERO,
            transparent: Vec3::ZERO,
            index_of_refraction: 1.0,
        }
    }
}

impl Phong {
    /// Whether this shades exactly as a diffuse-only material (assignments 1 and 2).
    /// Every term blended linearly, `w` of the way from `self` to `other` (a Noise, Marble
    /// or Wood texture between two materials).
    pub fn lerp(&self, other: &Phong, w: f32) -> Phong {
        let f = |a: f32, b: f32| a + (b - a) * w;
        Phong {
            specular: self.specular.lerp(other.specular, w),
            exponent: f(self.exponent, other.exponent),
            reflective: self.reflective.lerp(other.reflective, w),
            transparent: self.transparent.lerp(other.transparent, w),
            index_of_refraction: f(self.index_of_refraction, other.index_of_refraction),
        }
    }

    pub fn is_diffuse_only(&self) -> bool {
        self.specular == Vec3::ZERO
            && self.reflective == Vec3::ZERO
            && self.transparent == Vec3::ZERO
    }
}

impl Material {
    /// The Phong terms, each field the file does not give at the course's default. A field
    /// with the wrong count of numbers (refused by the rules) also reads as the default.
    pub fn phong(&self) -> Phong {
        let mut p = Phong::default();
        for (name, v) in &self.extra {
            match (name.as_str(), v.as_slice()) {
                ("specularColor", &[x, y, z]) => p.specular = Vec3::new(x, y, z),
                ("exponent", &[e]) => p.exponent = e,
                ("reflectiveColor", &[x, y, z]) => p.reflective = Vec3::new(x, y, z),
                ("transparentColor", &[x, y, z]) => p.transparent = Vec3::new(x, y, z),
                ("indexOfRefraction", &[n]) => p.index_of_refraction = n,
                _ => {}
            }
        }
        p
    }

    /// The numbers of field `name` (not `diffuseColor`), if the material has it.
    pub fn field(&self, name: &str) -> Option<&[f32]> {
        self.extra
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_slice())
    }

    /// Sets field `name` (added at the end when absent, kept in place when present).
    pub fn set_field(&mut self, name: &str, values: Vec<f32>) {
        match self.extra.iter_mut().find(|(n, _)| n == name) {
            Some((_, v)) => *v = values,
            None => self.extra.push((name.to_string(), values)),
        }
    }

    /// Removes field `name`, so it reads as the course's default again.
    pub fn remove_field(&mut self, name: &str) {
        self.extra.retain(|(n, _)| n != name);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn absent_fields_read_as_the_course_defaults_and_given_ones_as_written() {
        let mut m = Material::diffuse(Vec3::ONE);
        assert_eq!(m.phong(), Phong::default());
        assert!(m.phong().is_diffuse_only());
        m.set_field("exponent", vec![32.0]);
        m.set_field("specularColor", vec![0.1, 0.2, 0.3]);
        m.set_field("exponent", vec![64.0]);
        let p = m.phong();
        assert_eq!(p.exponent, 64.0);
        assert_eq!(p.specular, Vec3::new(0.1, 0.2, 0.3));
        assert!(!p.is_diffuse_only());
        // Kept in place: the writer gives the file's order back.
        assert_eq!(m.extra[0].0, "exponent");
        m.remove_field("specularColor");
        assert!(m.phong().is_diffuse_only());
        // A wrong count reads as the default (the rules refuse it before any render).
        m.set_field("indexOfRefraction", vec![1.5, 2.0]);
        assert_eq!(m.phong().index_of_refraction, 1.0);
    }
}
