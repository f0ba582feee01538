//! The course's own `raytracer` command line, flag for flag.

use std::ffi::OsString;
use std::path::PathBuf;

use tracelab_core::render::Secondary;
use tracelab_core::{NormalTransform, ObjectRays};

use super::render::RenderJob;
use super::values::{MAX_BOUNCES, parse_count, parse_f32, parse_u32};
use crate::exit::usage;
use crate::io::write_stderr_text;

/// Flags of the course's later weeks that tracelab does not implement yet: refused by name,
/// never ignored (an image made without them would be silently wrong).
const NOT_YET: [(&str, &str); 11] = [
    ("-grid", "assignment 5's uniform grid"),
    ("-visualize_grid", "assignment 5's grid view"),
    ("-stats", "assignment 6's counters"),
    ("-random_samples", "assignment 7's sampling"),
    ("-uniform_samples", "assignment 7's sampling"),
    ("-jittered_samples", "assignment 7's sampling"),
    ("-box_filter", "assignment 7's filters"),
    ("-tent_filter", "assignment 7's filters"),
    ("-gaussian_filter", "assignment 7's filters"),
    ("-render_samples", "assignment 7's sample view"),
    ("-render_filter", "assignment 7's filter view"),
];

/// The course's flags, verbatim: `-input F -size W H -output F -normals F -depth MIN MAX F
/// -shade_back` (assignments 1–2), `-shadows -bounces N -weight W` (assignment 4), the
/// OpenGL preview's `-gui -tessellation A B -gouraud` (accepted, with a note: the editor is
/// tracelab's preview), plus tracelab's `-specular_fix` (assignment 3's optional fix),
/// `-normal_transform correct|incorrect` and
/// `-object_rays unnormalized|normalized|normalized-no-rescale`.
pub fn parse_course_args(args: &[OsString]) -> anyhow::Result<RenderJob> {
    let mut job = RenderJob {
        scene: None,
        width: 0,
        height: 0,
        output: None,
        normals: None,
        depth: None,
        shade_back: false,
        normal_transform: NormalTransform::Correct,
        object_rays: ObjectRays::Unnormalized,
        secondary: Secondary::default(),
    };
    let mut preview = Vec::new();
    let mut it = args.iter();
    let take = |it: &mut std::slice::Iter<OsString>, flag: &str| -> anyhow::Result<OsString> {
        it.next()
            .cloned()
            .ok_or_else(|| usage(format!("{flag} needs a value")))
    };
    while let Some(arg) = it.next() {
        // Flags are ASCII; a value after one may be any bytes (a file name).
        let a = arg.to_str().unwrap_or_default();
        match a {
            "-input" => job.scene = Some(PathBuf::from(take(&mut it, a)?)),
            "-size" => {
                job.width = parse_u32(&take(&mut it, a)?, "-size width")?;
                job.height = parse_u32(&take(&mut it, a)?, "-size height")?;
            }
            "-output" => job.output = Some(PathBuf::from(take(&mut it, a)?)),
            "-normals" => job.normals = Some(PathBuf::from(take(&mut it, a)?)),
            "-depth" => {
                let min = parse_f32(&take(&mut it, a)?, "-depth min")?;
                let max = parse_f32(&take(&mut it, a)?, "-depth max")?;
                job.depth = Some((min, max, PathBuf::from(take(&mut it, a)?)));
            }
            "-shade_back" => job.shade_back = true,
            "-shadows" => job.secondary.shadows = true,
            "-specular_fix" => job.secondary.specular_fix = true,
            "-bounces" => {
                let n = parse_count(&take(&mut it, a)?, "-bounces")?;
                if n > MAX_BOUNCES {
                    return Err(usage(format!(
                        "-bounces: at most {MAX_BOUNCES} levels, found {n}"
                    )));
                }
                job.secondary.bounces = n;
            }
            "-weight" => {
                let w = parse_f32(&take(&mut it, a)?, "-weight")?;
                if !(w.is_finite() && w >= 0.0) {
                    return Err(usage(format!(
                        "-weight: expected a number of 0 or more, found {w}"
                    )));
                }
                job.secondary.weight = w;
            }
            "-gui" | "-gouraud" => preview.push(a.to_string()),
            "-tessellation" => {
                let th = parse_u32(&take(&mut it, a)?, "-tessellation theta steps")?;
                let ph = parse_u32(&take(&mut it, a)?, "-tessellation phi steps")?;
                preview.push(format!("-tessellation {th} {ph}"));
            }
            _ if NOT_YET.iter().any(|(f, _)| *f == a) => {
                let what = NOT_YET.iter().find(|(f, _)| *f == a).map_or("", |(_, w)| w);
                return Err(usage(format!(
                    "{a} ({what}) is not implemented by tracelab yet; \
                     an image rendered without it would not be the course's"
                )));
            }
            "-normal_transform" => {
                let v = take(&mut it, a)?;
                job.normal_transform = match v.to_str() {
                    Some("correct") => NormalTransform::Correct,
                    Some("incorrect") => NormalTransform::Incorrect,
                    _ => {
                        return Err(usage(format!(
                            "-normal_transform: expected correct or incorrect, found \"{}\"",
                            v.display()
                        )));
                    }
                }
            }
            "-object_rays" => {
                let v = take(&mut it, a)?;
                job.object_rays = v.to_str().and_then(ObjectRays::from_name).ok_or_else(|| {
                    usage(format!(
                        "-object_rays: expected unnormalized, normalized or normalized-no-rescale, found \"{}\"",
                        v.display()
                    ))
                })?;
            }
            _ => {
                return Err(usage(format!(
                    "unknown option \"{}\" (course flags: -input -size -output -normals -depth -shade_back -shadows -bounces -weight)",
                    arg.display()
                )));
            }
        }
    }
    if job.scene.is_none() {
        return Err(usage("-input needs a scene file"));
    }
    if job.width == 0 {
        return Err(usage("-size W H is required"));
    }
    if !preview.is_empty() {
        write_stderr_text(&format!(
            "tracelab: note: {} only set the course's OpenGL preview, which tracelab does not \
             open; the editor is tracelab's preview: `tracelab SCENE`\n",
            preview.join(", ")
        ));
    }
    Ok(job)
}
