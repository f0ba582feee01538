//! The course's own `raytracer` command line, flag for flag.

use std::ffi::OsString;
use std::path::PathBuf;

use tracelab_core::{NormalTransform, ObjectRays};

use super::render::RenderJob;
use super::values::{parse_f32, parse_u32};
use crate::exit::usage;

/// The course's flags, verbatim: `-input F -size W H -output F -normals F -depth MIN MAX F
/// -shade_back`, plus tracelab's `-normal_transform correct|incorrect` and
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
    };
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
                    "unknown option \"{}\" (course flags: -input -size -output -normals -depth -shade_back)",
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
    Ok(job)
}
