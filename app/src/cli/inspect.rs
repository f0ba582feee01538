//! `tracelab inspect`: the pixel inspector's story for one pixel, on the command line — a
//! student's oracle to check their own ray tracer against, value by value.

use std::ffi::OsString;
use std::path::PathBuf;

use tracelab_core::render::inspect_pixel;
use tracelab_core::{CompiledScene, RenderSettings};

use super::render::{NormalMode, ObjectRaysMode};
use super::values::parse_f32;
use crate::exit::{check_size, usage};
use crate::io::{escape_json, load_scene, write_stdout, write_stdout_text};
use crate::story::{pixel_report, report_text};

/// `tracelab inspect --help`.
pub const LONG_ABOUT: &str = "Print one pixel's story, as the editor's pixel inspector shows it: the world ray; each \
    node on the path with its matrix M, M⁻¹ and (M⁻¹)ᵀ and the ray in its space; t in world and \
    object space and which one the renderer kept; the hit point in both spaces; the object \
    normal, the world normals by (M⁻¹)ᵀ and by M and the angle between them; whether each \
    Transform is a similitude; the shading terms that sum to the pixel's colour (a back face \
    without --shade-back is drawn black; its ambient·k_d is still shown); and the bytes each of \
    the course's images holds at the pixel: colour, normals and, with --depth MIN MAX (the \
    course line's -depth range), depth.\n\n\
    Pixels are counted as images store them: X from the left, Y (the row) from the TOP, both from \
    0. (The course's own j counts from the bottom: row = H − 1 − j.)\n\n\
    --json prints the same as one JSON object, schema tracelab-inspect/1 (docs/inspect-json.md).";

#[derive(clap::Args, Debug)]
pub struct InspectArgs {
    /// Scene file (default: the built-in scene).
    pub scene: Option<PathBuf>,
    /// Image size in pixels.
    #[arg(long, num_args = 2, value_names = ["W", "H"], required = true)]
    pub size: Vec<u32>,
    /// The pixel: X from the left, Y (row) from the top, from 0.
    #[arg(long, num_args = 2, value_names = ["X", "Y"], required = true)]
    pub pixel: Vec<u32>,
    /// Print JSON (schema tracelab-inspect/1, docs/inspect-json.md) instead of text.
    #[arg(long)]
    pub json: bool,
    #[arg(long, value_enum, default_value_t = ObjectRaysMode::Unnormalized)]
    pub object_rays: ObjectRaysMode,
    #[arg(long, value_enum, default_value_t = NormalMode::Correct)]
    pub normal_transform: NormalMode,
    /// Shade back-facing surfaces with the flipped normal instead of black.
    #[arg(long)]
    pub shade_back: bool,
    /// The depth image's range, as the course line's `-depth MIN MAX`: the depth byte is printed
    /// for it.
    #[arg(long, num_args = 2, value_names = ["MIN", "MAX"], allow_hyphen_values = true)]
    pub depth: Option<Vec<OsString>>,
    #[command(flatten)]
    pub secondary: super::render::SecondaryArgs,
}

pub fn run_inspect(a: &InspectArgs) -> anyhow::Result<()> {
    let (&[w, h], &[x, row]) = (a.size.as_slice(), a.pixel.as_slice()) else {
        return Err(usage("--size needs W H and --pixel X Y"));
    };
    check_size(w, h)?;
    if x >= w || row >= h {
        return Err(usage(format!(
            "--pixel {x} {row} is outside the {w}×{h} image (X is 0 to {}, Y is 0 to {}, rows from the top)",
            w - 1,
            h - 1
        )));
    }
    // Checked before the scene is read: a usage error names the flag.
    let depth = match a.depth.as_deref() {
        Some([min, max]) => Some((
            parse_f32(min, "--depth MIN")?,
            parse_f32(max, "--depth MAX")?,
        )),
        Some(_) => return Err(usage("--depth needs MIN MAX")),
        None => None,
    };
    let secondary = a.secondary.secondary()?;
    let scene = load_scene(a.scene.as_deref())?;
    let compiled = CompiledScene::new(&scene);
    secondary.check_bounded(&compiled).map_err(usage)?;
    let settings = RenderSettings {
        shade_back: a.shade_back,
        normal_transform: a.normal_transform.into(),
        object_rays: a.object_rays.into(),
        secondary,
        ..RenderSettings::new(w, h)
    };
    let story = inspect_pixel(&scene, &compiled, &settings, x, row);
    let mut report = pixel_report(&scene, &story, &settings);
    if let Some((min, max)) = depth {
        report = report.with_depth_range(min, max);
    }
    // Node labels carry the scene's text (an `obj_file` name): escaped, in JSON as \uXXXX.
    if a.json {
        let json = serde_json::to_string_pretty(&report)
            .map_err(|e| anyhow::anyhow!("cannot write JSON: {e}"))?;
        write_stdout(escape_json(json + "\n").as_bytes())
    } else {
        write_stdout_text(&report_text(&report))
    }
}
