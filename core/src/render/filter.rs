//! Assignment 7's reconstruction filters. A pixel's colour is the weighted average of the
//! samples of the pixels around it, each weighted by the filter at the sample's offset from
//! the pixel's centre, counted in pixels. Only pixels within the filter's support radius
//! (in whole pixels, a square) are visited: for a radius r, ⌈r − ½⌉ pixels each way, which
//! holds every sample within r of the centre; for the Gaussian, r = 2σ, and its weight is not
//! cut to 0 beyond 2σ inside that square (the course's references show it uncut).

use thiserror::Error;

/// Largest radius (box, tent) or 2σ (Gaussian) in pixels: a filter reaching 64 pixels
/// averages over 129 × 129 pixels; the course's largest reaches 4.6.
pub const MAX_FILTER_RADIUS: f32 = 64.0;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Filter {
    /// Weight 1 where |x| ≤ r and |y| ≤ r, else 0.
    Box { radius: f32 },
    /// Weight max(0, 1 − d/r), d the distance from the pixel's centre.
    Tent { radius: f32 },
    /// Weight e^(−d²/2σ²).
    Gaussian { sigma: f32 },
}

#[derive(Clone, Copy, Debug, PartialEq, Error)]
pub enum FilterError {
    #[error("expected a number above 0 and at most {max}, found {value}")]
    OutOfRange { value: f32, max: f32 },
}

impl Default for Filter {
    /// The handout's default: each pixel the plain average of its own samples.
    fn default() -> Self {
        Filter::Box { radius: 0.5 }
    }
}

impl Filter {
    /// A box of half-width `radius` (pixels), checked.
    pub fn box_filter(radius: f32) -> Result<Self, FilterError> {
        check(radius, MAX_FILTER_RADIUS).map(|radius| Filter::Box { radius })
    }
    /// A tent of radius `radius` (pixels), checked.
    pub fn tent(radius: f32) -> Result<Self, FilterError> {
        check(radius, MAX_FILTER_RADIUS).map(|radius| Filter::Tent { radius })
    }
    /// A Gaussian of standard deviation `sigma` (pixels), checked.
    pub fn gaussian(sigma: f32) -> Result<Self, FilterError> {
        check(sigma, MAX_FILTER_RADIUS / 2.0).map(|sigma| Filter::Gaussian { sigma })
    }

    /// The course flag that makes this filter, and its value, for messages.
    pub fn course_flag(&self) -> (&'static str, f32) {
        match *self {
            Filter::Box { radius } => ("-box_filter", radius),
            Filter::Tent { radius } => ("-tent_filter", radius),
            Filter::Gaussian { sigma } => ("-gaussian_filter", sigma),
        }
    }

    /// The weight of a sample at offset (x, y) pixels from the pixel's centre.
    pub fn weight(&self, x: f32, y: f32) -> f32 {
        match *self {
            Filter::Box { radius } => {
                if x.abs() <= radius && y.abs() <= radius {
                    1.0
                } else {
                    0.0
                }
            }
            Filter::Tent { radius } => (1.0 - (x * x + y * y).sqrt() / radius).max(0.0),
            Filter::Gaussian { sigma } => (-(x * x + y * y) / (2.0 * sigma * sigma)).exp(),
        }
    }

    /// Whole pixels around a pixel whose samples it takes: ⌈r − ½⌉, r the radius or 2σ.
    pub fn support_radius(&self) -> u32 {
        let r = match *self {
            Filter::Box { radius } | Filter::Tent { radius } => radius,
            Filter::Gaussian { sigma } => 2.0 * sigma,
        };
        // r is checked to (0, 64]: the cast neither wraps nor saturates.
        (r - 0.5).ceil().max(0.0) as u32
    }
}

fn check(v: f32, max: f32) -> Result<f32, FilterError> {
    if v.is_finite() && v > 0.0 && v <= max {
        Ok(v)
    } else {
        Err(FilterError::OutOfRange { value: v, max })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn supports_hold_every_sample_within_the_radius() {
        let support =
            |f: Result<Filter, FilterError>| f.expect("a valid test value").support_radius();
        assert_eq!(support(Filter::box_filter(0.5)), 0);
        assert_eq!(support(Filter::box_filter(0.51)), 1);
        assert_eq!(support(Filter::tent(1.5)), 1);
        assert_eq!(support(Filter::tent(1.7)), 2);
        assert_eq!(support(Filter::box_filter(2.3)), 2);
        assert_eq!(support(Filter::gaussian(0.5)), 1);
        assert_eq!(support(Filter::gaussian(1.0)), 2);
        assert_eq!(support(Filter::gaussian(2.3)), 5);
        assert_eq!(support(Filter::box_filter(0.1)), 0);
    }

    #[test]
    fn weights_follow_the_handout() {
        let b = Filter::box_filter(0.5).expect("a valid test value");
        assert_eq!(b.weight(0.5, -0.5), 1.0);
        assert_eq!(b.weight(0.51, 0.0), 0.0);
        let t = Filter::tent(2.0).expect("a valid test value");
        assert_eq!(t.weight(0.0, 0.0), 1.0);
        assert_eq!(t.weight(1.0, 0.0), 0.5);
        assert_eq!(t.weight(0.0, -3.0), 0.0);
        let g = Filter::gaussian(0.5).expect("a valid test value");
        assert_eq!(g.weight(0.0, 0.0), 1.0);
        assert!((g.weight(1.0, 0.0) - (-2.0f32).exp()).abs() < 1e-7);
        // Beyond 2σ the weight is small but not cut.
        assert!(g.weight(1.2, 0.0) > 0.05);
    }

    #[test]
    fn bad_radii_are_refused() {
        for v in [0.0, -0.0, -1.0, f32::NAN, f32::INFINITY, 64.5, 1e38] {
            assert!(Filter::box_filter(v).is_err(), "{v}");
            assert!(Filter::tent(v).is_err(), "{v}");
            assert!(Filter::gaussian(v).is_err(), "{v}");
        }
        assert!(Filter::box_filter(64.0).is_ok());
        assert!(Filter::gaussian(32.0).is_ok());
        assert!(Filter::gaussian(32.5).is_err());
    }
}
