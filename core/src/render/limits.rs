//! The largest image tracelab renders, in one place: the command line, the benchmarks and
//! the GUI check a size here before they allocate a frame for it.

use thiserror::Error;

/// Longest side in pixels: 16384 is what common image viewers and GPU textures still open.
pub const MAX_IMAGE_SIDE: u32 = 16384;
/// Most pixels in one image (8192 × 8192): a frame costs 16 bytes a pixel plus 3 for the
/// encoded view, so this keeps one render around 1.2 GiB.
pub const MAX_IMAGE_PIXELS: u64 = 1 << 26;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
pub enum ImageSizeError {
    #[error("image size {width}x{height} is empty: width and height must be at least 1")]
    Empty { width: u32, height: u32 },
    #[error(
        "image size {width}x{height} is too large: each side can be at most {MAX_IMAGE_SIDE} pixels"
    )]
    SideTooLong { width: u32, height: u32 },
    #[error(
        "image size {width}x{height} is too large: at most {MAX_IMAGE_PIXELS} pixels (8192x8192) in all"
    )]
    TooManyPixels { width: u32, height: u32 },
}

/// Checks that a `width` × `height` image can be rendered: no side zero, none longer than
/// [`MAX_IMAGE_SIDE`], at most [`MAX_IMAGE_PIXELS`] in all.
pub fn check_image_size(width: u32, height: u32) -> Result<(), ImageSizeError> {
    if width == 0 || height == 0 {
        Err(ImageSizeError::Empty { width, height })
    } else if width > MAX_IMAGE_SIDE || height > MAX_IMAGE_SIDE {
        Err(ImageSizeError::SideTooLong { width, height })
    } else if u64::from(width) * u64::from(height) > MAX_IMAGE_PIXELS {
        Err(ImageSizeError::TooManyPixels { width, height })
    } else {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_up_to_the_limits_are_accepted() {
        assert_eq!(check_image_size(1, 1), Ok(()));
        assert_eq!(check_image_size(8192, 8192), Ok(()));
        assert_eq!(check_image_size(MAX_IMAGE_SIDE, 4096), Ok(()));
        assert_eq!(check_image_size(1, MAX_IMAGE_SIDE), Ok(()));
    }

    #[test]
    fn zero_sides_are_rejected() {
        assert!(matches!(
            check_image_size(0, 0),
            Err(ImageSizeError::Empty { .. })
        ));
        assert!(matches!(
            check_image_size(0, 10),
            Err(ImageSizeError::Empty { .. })
        ));
        assert!(matches!(
            check_image_size(10, 0),
            Err(ImageSizeError::Empty { .. })
        ));
    }

    #[test]
    fn long_sides_and_too_many_pixels_are_rejected_without_overflow() {
        assert!(matches!(
            check_image_size(MAX_IMAGE_SIDE + 1, 1),
            Err(ImageSizeError::SideTooLong { .. })
        ));
        assert!(matches!(
            check_image_size(1, 100_000),
            Err(ImageSizeError::SideTooLong { .. })
        ));
        assert!(matches!(
            check_image_size(u32::MAX, u32::MAX),
            Err(ImageSizeError::SideTooLong { .. })
        ));
        assert!(matches!(
            check_image_size(8193, 8192),
            Err(ImageSizeError::TooManyPixels { .. })
        ));
        assert!(matches!(
            check_image_size(MAX_IMAGE_SIDE, MAX_IMAGE_SIDE),
            Err(ImageSizeError::TooManyPixels { .. })
        ));
    }

    #[test]
    fn messages_name_the_size_and_the_limit() {
        let e = check_image_size(100_000, 100_000).expect_err("too large");
        assert_eq!(
            e.to_string(),
            "image size 100000x100000 is too large: each side can be at most 16384 pixels"
        );
    }
}
