//! The shading rules `whitted.rs` follows, as switches: all off is the course's rules (the
//! render's only setting); the mistake catalogue (`mistakes/`) turns one or two on to draw
//! what a program that breaks them draws. One implementation of the shading, the mistakes as
//! switches, so a variant differs from the reference exactly where its mistake shows.

/// Which rule for the ambient term.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Ambient {
    /// c_a·k_d (the course).
    #[default]
    TimesDiffuse,
    /// c_a alone.
    Plain,
    /// c_a·k_d·k_d.
    TimesDiffuseTwice,
}

/// Each field off (the default) is the course's rule; on, the named mistake.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Rules {
    pub ambient: Ambient,
    /// Without -shade_back, back faces shaded with their outward normal (not black).
    pub back_faces_lit: bool,
    /// Without -shade_back, back faces shaded with the flipped normal (not black).
    pub back_faces_flipped: bool,
    /// With -shade_back, |L·N| instead of a flipped normal.
    pub shade_back_absolute: bool,
    /// Phong's (R·V)^e instead of Blinn's (N·H)^e.
    pub reflection_vector: bool,
    /// The specular term kept where N·L ≤ 0.
    pub specular_behind: bool,
    /// Shadow rays start at t_min 0 (shadow acne).
    pub shadow_t_min_zero: bool,
    /// A point whose shadow ray to some light is blocked loses its ambient term.
    pub ambient_dropped_in_shadow: bool,
    /// Shadow rays pass through transparent objects.
    pub transparent_casts_no_shadow: bool,
    /// Refraction always from index 1 into n, leaving as well as entering.
    pub index_not_inverted: bool,
    /// On total internal reflection the transmitted ray goes along the mirror direction.
    pub tir_transmits_reflected: bool,
    /// `-weight` ignored: every ray within `-bounces` is traced.
    pub weight_ignored: bool,
}

impl Rules {
    /// The course's rules: what every render but a diagnosis's variant uses.
    pub const COURSE: Rules = Rules {
        ambient: Ambient::TimesDiffuse,
        back_faces_lit: false,
        back_faces_flipped: false,
        shade_back_absolute: false,
        reflection_vector: false,
        specular_behind: false,
        shadow_t_min_zero: false,
        ambient_dropped_in_shadow: false,
        transparent_casts_no_shadow: false,
        index_not_inverted: false,
        tir_transmits_reflected: false,
        weight_ignored: false,
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_is_the_course() {
        assert_eq!(Rules::default(), Rules::COURSE);
    }
}
