//! `tracelab diff IMAGE -- COURSE-COMMAND-LINE`: a student's image against tracelab's
//! reference for the same course command line — the size first, then every pixel within a
//! tolerance as the course's graders allow, a heat map, and for the worst pixels the one-line
//! story of what the reference ray hit. Normal and depth images named on the line are
//! compared the same way. Nothing the command line names is written: those are the
//! student's files.

use std::ffi::OsString;
use std::io::Cursor;
use std::path::{Path, PathBuf};

use image::RgbImage;
use tracelab_core::render::inspect_pixel;
use tracelab_core::{CompiledScene, Frame, RenderSettings, Scene, View};

use super::course::parse_course_args;
use super::render::{RenderJob, render_with_progress};
use crate::exit::{Exit, check_size, usage};
use crate::io::{Implicit, OutputPlan, load_scene_and_meshes, write_implicit, write_stdout_text};
use crate::story::{one_line, pixel_report};

/// `tracelab diff --help`.
pub const LONG_ABOUT: &str = "Compare your ray tracer's image with tracelab's reference for the same course \
    command line, e.g.\n  tracelab diff mine.png -- -input scene2_11_squashed_sphere.txt -size 200 200 -output x.png\n\n\
    The reference is rendered for that line (nothing it names is written). The sizes must agree; \
    then a pixel matches when no channel differs by more than --tolerance (of 255), and the image \
    matches when at least --min-match percent of its pixels do (the course's graders allow a few \
    pixels on silhouettes). A heat map is written beside IMAGE (IMAGE.diff.png): matching pixels as \
    dim grey, the others from red (just over) to yellow (far off). The heat map never replaces a file \
    named on the command line, a symbolic link or anything but a regular file: then it is written as \
    IMAGE.diff-2.png (or -3, ...), and the verdict says so. For the worst pixels the one-line \
    story of the reference ray is printed: what it hit, at which t, with which normal. When the line \
    names -normals or -depth files, those files (your program's outputs) are compared with the \
    reference's too.\n\n\
    Pixel coordinates are x from the left, row from the top (as in tracelab inspect).\n\
    Exit status: 0 when every image matches, 3 when one does not, 4 when every image matches but a \
    heat map could not be written, 5 when one does not match and a heat map could not be written \
    (the verdicts are printed either way), 1 for a file that cannot be read, 2 for a usage error.";

#[derive(clap::Args, Debug)]
pub struct DiffArgs {
    /// Your colour image (.png .tga .ppm .bmp).
    pub image: PathBuf,
    /// The largest channel difference (of 255) that still counts as matching.
    #[arg(long, default_value_t = 8)]
    pub tolerance: u8,
    /// The percentage of matching pixels an image needs.
    #[arg(long, default_value_t = 99.0)]
    pub min_match: f64,
    /// How many of the worst pixels to explain.
    #[arg(long, default_value_t = 5)]
    pub worst: usize,
    /// The course's command line, after `--`: -input F -size W H -output F [-normals F] [-depth MIN MAX F] ...
    #[arg(
        last = true,
        required = true,
        allow_hyphen_values = true,
        value_name = "COURSE-COMMAND-LINE"
    )]
    pub course: Vec<OsString>,
}

/// How one image compares with its reference.
#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    pub within: usize,
    pub total: usize,
    pub max_difference: u8,
    /// (largest channel difference, x, row), largest first, ties by position.
    pub worst: Vec<(u8, u32, u32)>,
}

impl Comparison {
    pub fn percent(&self) -> f64 {
        if self.total == 0 {
            100.0
        } else {
            100.0 * self.within as f64 / self.total as f64
        }
    }
}

/// Per-pixel comparison of two images of the same size.
pub fn compare(
    mine: &RgbImage,
    reference: &RgbImage,
    tolerance: u8,
    keep_worst: usize,
) -> Comparison {
    let mut within = 0;
    let mut max_difference = 0;
    let mut off = Vec::new();
    for (x, row, p) in mine.enumerate_pixels() {
        let q = reference.get_pixel(x, row);
        let d = (0..3).map(|c| p[c].abs_diff(q[c])).max().unwrap_or(0);
        max_difference = max_difference.max(d);
        if d <= tolerance {
            within += 1;
        } else {
            off.push((d, x, row));
        }
    }
    off.sort_by(|a, b| b.0.cmp(&a.0).then((a.2, a.1).cmp(&(b.2, b.1))));
    off.truncate(keep_worst);
    Comparison {
        within,
        total: (mine.width() * mine.height()) as usize,
        max_difference,
        worst: off,
    }
}

/// The heat map: matching pixels as the reference dimmed to a quarter in grey, the others
/// from red (just over the tolerance) to yellow (255 apart).
pub fn heat_map(mine: &RgbImage, reference: &RgbImage, tolerance: u8) -> RgbImage {
    RgbImage::from_fn(reference.width(), reference.height(), |x, row| {
        let q = reference.get_pixel(x, row);
        let p = mine.get_pixel(x, row);
        let d = (0..3).map(|c| p[c].abs_diff(q[c])).max().unwrap_or(0);
        if d <= tolerance {
            let lum = (u32::from(q[0]) * 3 + u32::from(q[1]) * 6 + u32::from(q[2])) / 10;
            let g = (lum / 4) as u8;
            image::Rgb([g, g, g])
        } else {
            image::Rgb([255, d, 0])
        }
    })
}

/// A student's image as read, before the render: its bytes and the size its header claims.
struct Student<'a> {
    what: &'static str,
    path: &'a Path,
    view: View,
    depth: (f32, f32),
    bytes: Vec<u8>,
    size: (u32, u32),
}

/// The most bytes read as an image of `w`×`h`: 12 a pixel (an ASCII PPM writes up to
/// "255 255 255 ") and a MiB of headers. A larger file is no such image, and a pipe or
/// device could go on for ever.
fn byte_cap(w: u32, h: u32) -> u64 {
    u64::from(w) * u64::from(h) * 12 + (1 << 20)
}

/// Reads the file whole (so a pipe or FIFO works: nothing seeks on it) up to
/// [`byte_cap`], then the size from the image's header alone: nothing is decoded yet. A
/// longer file is refused unless its header gives another size (then only that is judged).
fn read_student<'a>(
    what: &'static str,
    path: &'a Path,
    view: View,
    depth: (f32, f32),
    (w, h): (u32, u32),
) -> anyhow::Result<Student<'a>> {
    use std::io::Read;
    let fail =
        |e: &dyn std::fmt::Display| anyhow::anyhow!("{}: cannot read image: {e}", path.display());
    let file = std::fs::File::open(path).map_err(|e| fail(&e))?;
    let meta = file.metadata().map_err(|e| fail(&e))?;
    if meta.is_dir() {
        return Err(fail(&"it is a folder"));
    }
    let cap = byte_cap(w, h);
    let mut bytes = Vec::new();
    if meta.is_file() {
        bytes
            .try_reserve_exact(meta.len().min(cap + 1) as usize)
            .map_err(|e| fail(&e))?;
    }
    file.take(cap + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| fail(&e))?;
    let size = reader(&bytes, path).into_dimensions();
    if bytes.len() as u64 > cap {
        // Too long for the size asked: a header of another size still gets its verdict.
        match size {
            Ok(other) if other != (w, h) => bytes = Vec::new(),
            _ => {
                return Err(fail(&format_args!(
                    "more than {cap} bytes, larger than any {w}×{h} image"
                )));
            }
        }
    }
    let size = size.map_err(|e| fail(&e))?;
    Ok(Student {
        what,
        path,
        view,
        depth,
        bytes,
        size,
    })
}

/// A reader for the bytes: the format from the content where it says (PNG, BMP, PPM), else
/// from the file name's extension (TGA has no signature).
fn reader<'b>(bytes: &'b [u8], path: &Path) -> image::ImageReader<Cursor<&'b [u8]>> {
    let mut r = image::ImageReader::new(Cursor::new(bytes));
    if let Some(f) = image::guess_format(bytes)
        .ok()
        .or_else(|| image::ImageFormat::from_path(path).ok())
    {
        r.set_format(f);
    }
    r
}

/// Decodes an image whose header said `w`×`h`, with the decoder held to that size and to
/// the memory such an image needs (16-bit RGBA at most), whatever the data says.
fn decode(s: &Student, (w, h): (u32, u32)) -> anyhow::Result<RgbImage> {
    let mut r = reader(&s.bytes, s.path);
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(w);
    limits.max_image_height = Some(h);
    limits.max_alloc = Some(u64::from(w) * u64::from(h) * 8 + (1 << 20));
    r.limits(limits);
    let img = r
        .decode()
        .map_err(|e| anyhow::anyhow!("{}: cannot read image: {e}", s.path.display()))?;
    Ok(img.into_rgb8())
}

/// `mine.png` → `mine.diff.png`, beside it (the output policy may choose `mine.diff-2.png`).
fn heat_map_path(image: &Path) -> PathBuf {
    let stem = image
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "image".into());
    image.with_file_name(format!("{stem}.diff.png"))
}

/// Chooses the heat map's name and writes it; an error says why it was not written.
fn write_heat_map(img: &RgbImage, image: &Path, plan: &mut OutputPlan) -> Result<Implicit, String> {
    let chosen = plan
        .implicit(&heat_map_path(image))
        .map_err(|e| format!("heat map {e}"))?;
    let path = &chosen.path;
    let mut bytes = Vec::new();
    img.write_to(&mut Cursor::new(&mut bytes), image::ImageFormat::Png)
        .map_err(|e| format!("{}: cannot encode heat map: {e}", path.display()))?;
    write_implicit(path, &bytes)
        .map_err(|e| format!("{}: cannot write heat map: {e}", path.display()))?;
    Ok(chosen)
}

struct Reference<'a> {
    scene: &'a Scene,
    compiled: &'a CompiledScene,
    settings: RenderSettings,
    frame: &'a Frame,
}

/// Compares one of the student's images with one view of the reference, printing the
/// verdict and the worst pixels. Returns whether it matches; a heat map that could not be
/// written is said in the verdict and its reason pushed on `failed`.
fn check(
    a: &DiffArgs,
    r: &Reference,
    s: &Student,
    plan: &mut OutputPlan,
    out: &mut String,
    failed: &mut Vec<String>,
) -> anyhow::Result<bool> {
    let (w, h) = (r.frame.width, r.frame.height);
    if s.size != (w, h) {
        out.push_str(&format!(
            "{} {}: size {}×{}, but the command line asks for {w}×{h}: does not match\n",
            s.what,
            s.path.display(),
            s.size.0,
            s.size.1
        ));
        return Ok(false);
    }
    let mine = decode(s, (w, h))?;
    let reference = RgbImage::from_raw(w, h, r.frame.rgb8(s.view, s.depth))
        .ok_or_else(|| anyhow::anyhow!("reference image has the wrong size"))?;
    let c = compare(&mine, &reference, a.tolerance, a.worst);
    let ok = c.percent() >= a.min_match;
    let map = match write_heat_map(&heat_map(&mine, &reference, a.tolerance), s.path, plan) {
        Ok(Implicit {
            path,
            instead_of: None,
        }) => format!("heat map {}", path.display()),
        Ok(Implicit {
            path,
            instead_of: Some((wanted, why)),
        }) => format!(
            "heat map {} (not {}: {why})",
            path.display(),
            wanted.display()
        ),
        Err(e) => {
            failed.push(e);
            "heat map not written".to_string()
        }
    };
    out.push_str(&format!(
        "{} {}: {:.2}% of {} pixels within {}/255 (largest difference {}): {}; {map}\n",
        s.what,
        s.path.display(),
        c.percent(),
        c.total,
        a.tolerance,
        c.max_difference,
        if ok { "matches" } else { "does not match" },
    ));
    for &(d, x, row) in &c.worst {
        let story = inspect_pixel(r.scene, r.compiled, &r.settings, x, row);
        let report = pixel_report(r.scene, &story, &r.settings);
        out.push_str(&format!(
            "  ({x}, {row}): yours {:?}, reference {:?} (off by {d}): {}\n",
            mine.get_pixel(x, row).0,
            reference.get_pixel(x, row).0,
            one_line(&report)
        ));
    }
    Ok(ok)
}

pub fn run_diff(a: &DiffArgs) -> anyhow::Result<()> {
    if !(0.0..=100.0).contains(&a.min_match) {
        return Err(usage(format!(
            "--min-match {}: expected a percentage from 0 to 100",
            a.min_match
        )));
    }
    let job: RenderJob = parse_course_args(&a.course)?;
    check_size(job.width, job.height)?;
    let size = (job.width, job.height);
    // Heat maps are invented names: never a file this command reads or the line names.
    let mut plan = OutputPlan::new();
    plan.reads(&a.image);
    if let Some(s) = &job.scene {
        plan.reads(s);
    }
    if let Some(o) = &job.output {
        plan.names(o);
    }
    let mut wanted = vec![("colour", a.image.as_path(), View::Color, (0.0, 1.0))];
    if let Some(n) = &job.normals {
        wanted.push(("normals", n, View::Normals, (0.0, 1.0)));
    }
    if let Some((min, max, d)) = &job.depth {
        wanted.push(("depth", d, View::Depth, (*min, *max)));
    }
    // Every image is read and its header checked before the (possibly long) render.
    let mut students = Vec::new();
    for (what, path, view, depth) in wanted {
        plan.reads(path);
        students.push(read_student(what, path, view, depth, size)?);
    }
    let (scene, meshes) = load_scene_and_meshes(job.scene.as_deref())?;
    for m in &meshes {
        plan.reads(m);
    }
    let compiled = CompiledScene::new(&scene);
    let settings = RenderSettings {
        shade_back: job.shade_back,
        normal_transform: job.normal_transform,
        object_rays: job.object_rays,
        ..RenderSettings::new(job.width, job.height)
    };
    let frame = render_with_progress(&compiled, &settings)?;
    let r = Reference {
        scene: &scene,
        compiled: &compiled,
        settings,
        frame: &frame,
    };
    let mut out = String::new();
    let mut failed = Vec::new();
    let mut all = true;
    for s in &students {
        all &= check(a, &r, s, &mut plan, &mut out, &mut failed)?;
    }
    // Paths and node labels (an `obj_file` name) are the user's text: escaped.
    write_stdout_text(&out)?;
    if !failed.is_empty() {
        return Err(Exit::HeatMapNotWritten {
            matched: all,
            message: failed.join("\n"),
        }
        .into());
    }
    if all {
        Ok(())
    } else {
        Err(Exit::Differs.into())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn compare_counts_pixels_over_the_tolerance_and_sorts_the_worst() {
        let reference = RgbImage::from_pixel(4, 3, image::Rgb([100, 100, 100]));
        let mut mine = reference.clone();
        mine.put_pixel(1, 2, image::Rgb([100, 109, 100])); // 9 over
        mine.put_pixel(3, 0, image::Rgb([60, 100, 100])); // 40 over
        mine.put_pixel(0, 0, image::Rgb([108, 92, 100])); // 8: within
        let c = compare(&mine, &reference, 8, 5);
        assert_eq!((c.within, c.total, c.max_difference), (10, 12, 40));
        assert_eq!(c.worst, [(40, 3, 0), (9, 1, 2)]);
        let map = heat_map(&mine, &reference, 8);
        assert_eq!(map.get_pixel(3, 0).0, [255, 40, 0]);
        assert_eq!(map.get_pixel(0, 0).0, [25, 25, 25]);
    }
}
