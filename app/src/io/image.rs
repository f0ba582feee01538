//! Images as files: the formats tracelab writes, encoded in memory, written atomically.

use std::path::Path;

use tracelab_core::{Frame, View};

use super::atomic::write_atomic;

/// Why an image was not written (an existing file is left as it was).
#[derive(Debug, thiserror::Error)]
pub enum ImageWriteError {
    #[error("{}: unknown image format (use .png, .tga, .ppm or .bmp)", .0.display())]
    UnknownFormat(std::path::PathBuf),
    #[error("{}: cannot encode image: {source}", .path.display())]
    Encode {
        path: std::path::PathBuf,
        source: image::ImageError,
    },
    #[error("{}: cannot write image: {source}", .path.display())]
    Write {
        path: std::path::PathBuf,
        source: std::io::Error,
    },
}

/// Encodes one view of a frame in the format its extension names (see [`image_format`]),
/// all in memory first so that a failed encode never touches an existing file, then writes
/// it with [`write_atomic`].
pub fn write_image(
    frame: &Frame,
    view: View,
    depth: (f32, f32),
    path: &Path,
) -> Result<(), ImageWriteError> {
    let p = || path.to_path_buf();
    let format = image_format(path).ok_or_else(|| ImageWriteError::UnknownFormat(p()))?;
    let bytes = encode_image(frame, view, depth, format)
        .map_err(|source| ImageWriteError::Encode { path: p(), source })?;
    write_atomic(path, &bytes).map_err(|source| ImageWriteError::Write { path: p(), source })
}

/// The image formats tracelab writes, from a file name's extension (any case).
pub fn image_format(path: &Path) -> Option<image::ImageFormat> {
    let ext = path.extension()?.to_str()?.to_ascii_lowercase();
    match ext.as_str() {
        "png" => Some(image::ImageFormat::Png),
        "tga" => Some(image::ImageFormat::Tga),
        "ppm" | "pnm" => Some(image::ImageFormat::Pnm),
        "bmp" => Some(image::ImageFormat::Bmp),
        _ => None,
    }
}

/// The file's bytes for one view. `.ppm` is binary PPM (`P6`), which the course's tools
/// read; the `image` crate's default for PNM would be PAM (`P7`).
pub fn encode_image(
    frame: &Frame,
    view: View,
    depth: (f32, f32),
    format: image::ImageFormat,
) -> image::ImageResult<Vec<u8>> {
    use image::ImageEncoder;
    use image::codecs::pnm::{PnmEncoder, PnmSubtype, SampleEncoding};

    let (w, h) = (frame.width, frame.height);
    if w == 0 || h == 0 {
        // PNG and BMP encoders would write a header for an image that no reader opens.
        return Err(image::ImageError::Parameter(
            image::error::ParameterError::from_kind(
                image::error::ParameterErrorKind::DimensionMismatch,
            ),
        ));
    }
    // Fallibly, as every big buffer: a frame too big for memory is an error, not an abort.
    let no_memory = |_| {
        image::ImageError::Limits(image::error::LimitError::from_kind(
            image::error::LimitErrorKind::InsufficientMemory,
        ))
    };
    let rgb = frame.try_rgb8(view, depth).map_err(no_memory)?;
    // Room for an incompressible image and the format's overhead, so that it seldom grows.
    let room = rgb.len() + rgb.len() / 64 + h as usize * 4 + 4096;
    let mut out =
        tracelab_core::memory::try_with_capacity(room, "the encoded image").map_err(no_memory)?;
    let color = image::ExtendedColorType::Rgb8;
    match format {
        image::ImageFormat::Pnm => PnmEncoder::new(&mut out)
            .with_subtype(PnmSubtype::Pixmap(SampleEncoding::Binary))
            .write_image(&rgb, w, h, color)?,
        image::ImageFormat::Png => {
            image::codecs::png::PngEncoder::new(&mut out).write_image(&rgb, w, h, color)?
        }
        image::ImageFormat::Tga => {
            image::codecs::tga::TgaEncoder::new(&mut out).write_image(&rgb, w, h, color)?
        }
        image::ImageFormat::Bmp => {
            image::codecs::bmp::BmpEncoder::new(&mut out).write_image(&rgb, w, h, color)?
        }
        other => {
            return Err(image::ImageError::Unsupported(
                image::error::UnsupportedError::from_format_and_kind(
                    other.into(),
                    image::error::UnsupportedErrorKind::Format(other.into()),
                ),
            ));
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::names_in;
    use std::path::PathBuf;

    fn temp_dir(name: &str) -> PathBuf {
        crate::test_support::temp_dir("image", name)
    }

    #[test]
    fn ppm_is_binary_p6() {
        let frame = Frame::new(3, 2);
        let bytes =
            encode_image(&frame, View::Color, (0.0, 1.0), image::ImageFormat::Pnm).expect("encode");
        assert!(
            bytes.starts_with(b"P6\n3 2 255\n"),
            "{:?}",
            String::from_utf8_lossy(&bytes[..12])
        );
        assert_eq!(bytes.len(), b"P6\n3 2 255\n".len() + 3 * 2 * 3);
    }

    #[test]
    fn a_failed_encode_never_touches_the_existing_file() {
        let d = temp_dir("encode");
        let p = d.join("wide.tga");
        std::fs::write(&p, "old image").expect("write");
        // TGA stores sides in 16 bits.
        let wide = Frame::new(70_000, 1);
        let e = write_image(&wide, View::Color, (0.0, 1.0), &p).expect_err("too wide for TGA");
        assert!(e.to_string().contains("cannot encode image"), "{e}");
        let empty = Frame::new(0, 0);
        for name in ["wide.tga", "e.png", "e.bmp", "e.ppm"] {
            assert!(
                write_image(&empty, View::Color, (0.0, 1.0), &d.join(name)).is_err(),
                "{name}"
            );
        }
        assert_eq!(std::fs::read(&p).expect("read"), b"old image");
        assert_eq!(names_in(&d), ["wide.tga"]);
    }
}
