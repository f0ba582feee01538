//! The course's own `raytracer` command line, flag for flag.

use std::ffi::OsString;
use std::path::PathBuf;

use tracelab_core::render::{Filter, SamplerKind, Secondary};
use tracelab_core::{NormalTransform, ObjectRays};

use super::render::RenderJob;
use super::supersample::Supersample;
use super::values::{parse_count, parse_f32, parse_u32};
use crate::exit::usage;
use crate::io::write_stderr_text;

/// The course's flags, verbatim: `-input F -size W H -output F -normals F -depth MIN MAX F
/// -shade_back` (assignments 1–2), `-shadows -bounces N -weight W` (assignment 4), the
/// OpenGL preview's `-gui -tessellation A B -gouraud` (accepted, with a note: the editor is
/// tracelab's preview), plus tracelab's `-specular_fix` (assignment 3's optional fix),
/// `-normal_transform correct|incorrect`,
/// `-object_rays unnormalized|normalized|normalized-no-rescale`, and assignment 7's sampling
/// (`-uniform_samples`, `-random_samples`, `-jittered_samples`, `-box_filter`, `-tent_filter`,
/// `-gaussian_filter`, `-render_samples FILE ZOOM`, `-render_filter FILE ZOOM`) with
/// tracelab's `-seed N` for the random ones.
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
        grid: None,
        visualize_grid: false,
        stats: false,
        supersample: Supersample::default(),
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
                job.secondary.bounces = parse_count(&take(&mut it, a)?, "-bounces")?;
            }
            "-weight" => {
                job.secondary.weight = parse_f32(&take(&mut it, a)?, "-weight")?;
            }
            "-grid" => {
                let mut n = [0u32; 3];
                for (k, axis) in ["x", "y", "z"].iter().enumerate() {
                    n[k] = parse_u32(&take(&mut it, a)?, &format!("-grid {axis} cells"))?;
                }
                job.grid = Some(n);
            }
            "-visualize_grid" => job.visualize_grid = true,
            "-stats" => job.stats = true,
            "-gui" | "-gouraud" => preview.push(a.to_string()),
            "-tessellation" => {
                let th = parse_u32(&take(&mut it, a)?, "-tessellation theta steps")?;
                let ph = parse_u32(&take(&mut it, a)?, "-tessellation phi steps")?;
                preview.push(format!("-tessellation {th} {ph}"));
            }
            "-uniform_samples" => {
                let v = take(&mut it, a)?;
                job.supersample.set_sampler(SamplerKind::Uniform, &v, a)?;
            }
            "-random_samples" => {
                let v = take(&mut it, a)?;
                job.supersample.set_sampler(SamplerKind::Random, &v, a)?;
            }
            "-jittered_samples" => {
                let v = take(&mut it, a)?;
                job.supersample.set_sampler(SamplerKind::Jittered, &v, a)?;
            }
            "-box_filter" => {
                let v = take(&mut it, a)?;
                job.supersample.set_filter(Filter::box_filter, &v, a)?;
            }
            "-tent_filter" => {
                let v = take(&mut it, a)?;
                job.supersample.set_filter(Filter::tent, &v, a)?;
            }
            "-gaussian_filter" => {
                let v = take(&mut it, a)?;
                job.supersample.set_filter(Filter::gaussian, &v, a)?;
            }
            "-seed" => {
                let v = take(&mut it, a)?;
                job.supersample.set_seed(&v, a)?;
            }
            "-render_samples" | "-render_filter" => {
                let file = take(&mut it, a)?;
                let zoom = take(&mut it, &format!("{a} FILE"))?;
                let picture = Supersample::picture(&file, &zoom, a)?;
                if a == "-render_samples" {
                    job.supersample.render_samples = Some(picture);
                } else {
                    job.supersample.render_filter = Some(picture);
                }
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
                    "unknown option \"{}\" (course flags: -input -size -output -normals -depth -shade_back -shadows -bounces -weight -grid -visualize_grid -stats -uniform_samples -random_samples -jittered_samples -box_filter -tent_filter -gaussian_filter -render_samples -render_filter -seed)",
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
    job.secondary
        .check_flags("-bounces", "-weight")
        .map_err(usage)?;
    if job.visualize_grid && job.grid.is_none() {
        return Err(usage(
            "-visualize_grid shows the grid -grid NX NY NZ builds: give -grid too",
        ));
    }
    let mut others: Vec<&str> = Vec::new();
    if job.normals.is_some() {
        others.push("-normals");
    }
    if job.depth.is_some() {
        others.push("-depth");
    }
    if job.visualize_grid {
        others.push("-visualize_grid");
    }
    job.supersample.resolve(
        job.width,
        job.height,
        &others,
        job.stats.then_some("-stats"),
    )?;
    if !preview.is_empty() {
        write_stderr_text(&format!(
            "tracelab: note: {} only set the course's OpenGL preview, which tracelab does not \
             open; the editor is tracelab's preview: `tracelab SCENE`\n",
            preview.join(", ")
        ));
    }
    Ok(job)
}
