//! The references' criterion, and how one image compares with another under it: a pixel is
//! off when a channel differs by more than the tolerance (2/255), and an image matches when
//! fewer than 1% of its pixels are off (`../shared/mit6837/AGREEMENT.md`: the consensus
//! images were built with it).

use image::RgbImage;

/// When a pixel is off and when an image still matches.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Criterion {
    /// The largest channel difference (of 255) that is not off.
    pub tolerance: u8,
    /// The percentage of pixels that must not be off: the off ones must be fewer than
    /// (100 − min_match)% of the image (none at all for 100).
    pub min_match: f64,
}

impl Criterion {
    pub const REFERENCES: Criterion = Criterion {
        tolerance: 2,
        min_match: 99.0,
    };

    /// Whether `off` of `total` pixels is few enough. Strictly fewer, as the references'
    /// "fewer than 1%": 400 of 40,000 does not match.
    pub fn matches(&self, off: usize, total: usize) -> bool {
        off == 0 || (off as f64) * 100.0 < (100.0 - self.min_match) * total as f64
    }

    /// "< 1%" (the limit as a percentage of the image).
    pub fn limit(&self) -> String {
        let p = 100.0 - self.min_match;
        if p <= 0.0 {
            "no pixel".to_string()
        } else {
            format!("< {}%", trim(p))
        }
    }
}

/// A percentage without needless zeros: 1, 0.5, 0.25.
fn trim(p: f64) -> String {
    let s = format!("{p:.4}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// 40000 → "40,000".
pub fn count(n: usize) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// The largest channel difference of two pixels.
#[inline]
pub fn difference(p: &[u8], q: &[u8]) -> u8 {
    p.iter()
        .zip(q)
        .map(|(a, b)| a.abs_diff(*b))
        .max()
        .unwrap_or(0)
}

/// How one image compares with its reference.
#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    pub off: usize,
    pub total: usize,
    pub max_difference: u8,
}

impl Comparison {
    pub fn percent_off(&self) -> f64 {
        if self.total == 0 {
            0.0
        } else {
            100.0 * self.off as f64 / self.total as f64
        }
    }
}

/// Per-pixel comparison of two images of the same size.
pub fn compare(mine: &RgbImage, reference: &RgbImage, tolerance: u8) -> Comparison {
    let mut off = 0;
    let mut max_difference = 0;
    for (p, q) in mine
        .as_raw()
        .chunks_exact(3)
        .zip(reference.as_raw().chunks_exact(3))
    {
        let d = difference(p, q);
        max_difference = max_difference.max(d);
        off += usize::from(d > tolerance);
    }
    Comparison {
        off,
        total: (mine.width() * mine.height()) as usize,
        max_difference,
    }
}

/// Pixels off in `mine` against `a` that are not off against `b`: what `b` explains.
pub fn explained(mine: &[u8], a: &[u8], b: &[u8], tolerance: u8) -> usize {
    mine.chunks_exact(3)
        .zip(a.chunks_exact(3))
        .zip(b.chunks_exact(3))
        .filter(|((p, q), r)| difference(p, q) > tolerance && difference(p, r) <= tolerance)
        .count()
}

/// Pixels off between two byte images.
pub fn off(a: &[u8], b: &[u8], tolerance: u8) -> usize {
    a.chunks_exact(3)
        .zip(b.chunks_exact(3))
        .filter(|(p, q)| difference(p, q) > tolerance)
        .count()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_references_criterion_wants_strictly_fewer_than_one_percent() {
        let c = Criterion::REFERENCES;
        assert!(c.matches(399, 40_000));
        assert!(!c.matches(400, 40_000));
        assert!(c.matches(0, 0));
        let strict = Criterion {
            tolerance: 2,
            min_match: 100.0,
        };
        assert!(strict.matches(0, 10) && !strict.matches(1, 10));
        assert_eq!(c.limit(), "< 1%");
        assert_eq!(strict.limit(), "no pixel");
        assert_eq!(
            Criterion {
                tolerance: 2,
                min_match: 99.75
            }
            .limit(),
            "< 0.25%"
        );
    }

    #[test]
    fn counts_have_thousands_separators() {
        assert_eq!(count(0), "0");
        assert_eq!(count(412), "412");
        assert_eq!(count(40_000), "40,000");
        assert_eq!(count(1_234_567), "1,234,567");
    }

    #[test]
    fn a_pixel_is_off_past_the_tolerance_only() {
        let reference = RgbImage::from_pixel(4, 3, image::Rgb([100, 100, 100]));
        let mut mine = reference.clone();
        mine.put_pixel(1, 2, image::Rgb([100, 103, 100])); // 3: off
        mine.put_pixel(3, 0, image::Rgb([60, 100, 100])); // 40: off
        mine.put_pixel(0, 0, image::Rgb([102, 98, 100])); // 2: not off
        let c = compare(&mine, &reference, 2);
        assert_eq!((c.off, c.total, c.max_difference), (2, 12, 40));
        let mut other = reference.clone();
        other.put_pixel(3, 0, image::Rgb([61, 100, 100]));
        assert_eq!(
            explained(mine.as_raw(), reference.as_raw(), other.as_raw(), 2),
            1
        );
        assert_eq!(off(mine.as_raw(), other.as_raw(), 2), 1);
    }
}
