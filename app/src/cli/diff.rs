//! `tracelab diff IMAGE -- COURSE-COMMAND-LINE`: a student's image against tracelab's
//! reference for the same course command line — the size first, then every pixel by the
//! references' own criterion (`judge`), a heat map, the known mistake the images match
//! (`diagnose`), and the off pixels as regions (`regions`), each with the story of what the
//! reference ray hit there. Normal and depth images named on the line are compared the same
//! way. Nothing the command line names is written: those are the student's files.

use std::ffi::OsString;
use std::io::Cursor;
use std::path::{Path, PathBuf};

use image::RgbImage;
use tracelab_core::render::{depth_shade, inspect_pixel, quantize};
use tracelab_core::{CompiledScene, Frame, RenderSettings, Scene, View};

use super::course::parse_course_args;
use super::diagnose::{Judged, diagnose, diagnosis_text};
use super::judge::{Criterion, compare, count, difference};
use super::regions::regions;
use super::render::{RenderJob, compile_for, frame_for};
use crate::exit::{Exit, check_size, usage};
use crate::io::{Implicit, OutputPlan, load_scene_and_meshes, write_implicit, write_summary_text};
use crate::story::{one_line, pixel_report};

/// `tracelab diff --help`.
pub const LONG_ABOUT: &str = "Compare your ray tracer's image with tracelab's reference for the same course \
    command line, e.g.\n  tracelab diff mine.png -- -input scene2_11_squashed_sphere.txt -size 200 200 -output x.png\n\n\
    The reference is rendered for that line (nothing it names is written). The sizes must agree; \
    then images are judged as the course's reference images were made: a pixel is off when a \
    channel differs by more than 2/255 (--tolerance), and an image matches when fewer than 1% of \
    its pixels are off (--min-match 99: fewer than 100 − 99 percent; 100: none). The verdict gives \
    the count: \"412 of 40,000 pixels off by more than 2/255 (1.03%; the limit is < 1%)\".\n\n\
    When an image does not match, diff renders the known mistakes that change this picture \
    (pixel corners instead of centres, normals by M, t not rescaled, back faces lit, ambient \
    not times the diffuse colour, rows flipped, ... 17 in all) and says first which one your \
    images match by the same criterion, or which pair, with the course's rule it breaks and how \
    many of the off pixels it explains; or that none does. Then the off pixels of each image as \
    connected regions, largest first (--regions N of them), with their size and bounding box, \
    one-pixel fringes along silhouettes marked as such, and the story of each region's typical \
    pixel: what the reference ray hit, at which t, with which normal, the bytes each image \
    should hold there, and what your byte implies (the t your depth byte encodes).\n\n\
    A heat map is written beside IMAGE (IMAGE.diff.png): pixels not off as dim grey, the others \
    from red (just over) to yellow (far off). The heat map never replaces a file named on the \
    command line, a symbolic link or anything but a regular file: then it is written as \
    IMAGE.diff-2.png (or -3, ...), and the verdict says so. When the line names -normals or \
    -depth files, those files (your program's outputs) are compared with the reference's too.\n\n\
    Pixel coordinates are x from the left, row from the top (as in tracelab inspect).\n\
    Exit status: 0 when every image matches, 3 when one does not, 4 when every image matches but a \
    heat map could not be written, 5 when one does not match and a heat map could not be written \
    (the verdicts are printed either way), 1 for a file that cannot be read, 2 for a usage error.\n\n\
    A whole class folder: tracelab diff --batch commands.txt --images DIR [--scenes DIR] [--report FILE] \
    judges every `raytracer` line of the handout's commands file (as it is: blank lines and # comments \
    skipped, any other line skipped with a warning naming it; at most 1000 lines, 1 MiB) against the \
    images in DIR that its -output, -normals and -depth name (names inside DIR only). The scenes are \
    read from --scenes, else scenes/ beside the commands file, else its folder. It prints one line per \
    image (\"commands.txt:12: colour DIR/output2_05.png: … matches\"; a missing image, a link to \
    nothing, a FIFO or a folder does not match), then the total, and writes one self-contained HTML \
    report (images inlined: yours, the reference and the heat map side by side, the verdicts, the \
    diagnosis and the regions of each line) to --report FILE (never an input) or tracelab-report.html \
    (another name where that is a link or an input); no heat map files. Exit status: 0 when every \
    image matches, 3 when one does not, 1 when a line could not be judged (its flags or its scene; \
    the others are still judged and the report written) or the report could not be written, 2 for \
    a usage error.";

#[derive(clap::Args, Debug)]
pub struct DiffArgs {
    /// Your colour image (.png .tga .ppm .bmp).
    #[arg(required_unless_present = "batch")]
    pub image: Option<PathBuf>,
    /// The largest channel difference (of 255) that is not off: the references' own is 2.
    #[arg(long, default_value_t = Criterion::REFERENCES.tolerance)]
    pub tolerance: u8,
    /// The percentage of pixels that must not be off: fewer than (100 − this)% may be (the
    /// references' own: 99, so fewer than 1%).
    #[arg(long, default_value_t = Criterion::REFERENCES.min_match)]
    pub min_match: f64,
    /// How many regions of off pixels to explain, largest first.
    #[arg(long, visible_alias = "worst", default_value_t = 5)]
    pub regions: usize,
    /// The course's command line, after `--`: -input F -size W H -output F [-normals F] [-depth MIN MAX F] ...
    #[arg(
        last = true,
        required_unless_present = "batch",
        allow_hyphen_values = true,
        value_name = "COURSE-COMMAND-LINE"
    )]
    pub course: Vec<OsString>,
    /// Judge a folder of outputs against every `raytracer` line of the handout's commands
    /// file (with --images DIR), writing one HTML report.
    #[arg(long, value_name = "COMMANDS.txt", conflicts_with_all = ["image", "course"], requires = "images")]
    pub batch: Option<PathBuf>,
    /// With --batch: the folder holding the images the lines name (-output, -normals, -depth).
    #[arg(long, value_name = "DIR", requires = "batch")]
    pub images: Option<PathBuf>,
    /// With --batch: the folder of the scenes the lines' -input name (default: `scenes/` beside
    /// the commands file when there is one, else the commands file's folder).
    #[arg(long, value_name = "DIR", requires = "batch")]
    pub scenes: Option<PathBuf>,
    /// With --batch: the HTML report to write (default: tracelab-report.html in the current
    /// folder, under another name when that one is taken by a link or an input).
    #[arg(long, value_name = "FILE", requires = "batch")]
    pub report: Option<PathBuf>,
}

/// The heat map: pixels not off as the reference dimmed to a quarter in grey, the others
/// from red (just over the tolerance) to yellow (255 apart).
pub fn heat_map(mine: &RgbImage, reference: &RgbImage, tolerance: u8) -> RgbImage {
    RgbImage::from_fn(reference.width(), reference.height(), |x, row| {
        let q = reference.get_pixel(x, row);
        let p = mine.get_pixel(x, row);
        let d = difference(&p.0, &q.0);
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
pub(super) struct Student<'a> {
    pub what: &'static str,
    pub path: &'a Path,
    pub view: View,
    pub depth: (f32, f32),
    bytes: Vec<u8>,
    pub size: (u32, u32),
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
pub(super) fn read_student<'a>(
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

pub(super) struct Reference<'a> {
    scene: &'a Scene,
    compiled: &'a CompiledScene,
    settings: RenderSettings,
    frame: &'a Frame,
}

/// One of the student's images of the right size, decoded, with the reference's bytes and
/// the heat map.
pub(super) struct Decoded<'s> {
    pub student: &'s Student<'s>,
    pub mine: RgbImage,
    pub reference: Vec<u8>,
    pub heat: RgbImage,
}

/// One image of a line judged: the verdict's text (without the heat map's name) and, for an
/// image of the right size, the pictures.
pub(super) struct Verdict<'s> {
    pub student: &'s Student<'s>,
    pub text: String,
    pub ok: bool,
    pub decoded: Option<Decoded<'s>>,
}

/// Compares one of the student's images with one view of the reference. A wrong size does
/// not match and is not decoded.
fn check<'s>(c: &Criterion, r: &Reference, s: &'s Student<'s>) -> anyhow::Result<Verdict<'s>> {
    let (w, h) = (r.frame.width, r.frame.height);
    if s.size != (w, h) {
        return Ok(Verdict {
            student: s,
            text: format!(
                "{} {}: size {}×{}, but the command line asks for {w}×{h}: does not match",
                s.what,
                s.path.display(),
                s.size.0,
                s.size.1
            ),
            ok: false,
            decoded: None,
        });
    }
    let mine = decode(s, (w, h))?;
    let reference = RgbImage::from_raw(w, h, r.frame.rgb8(s.view, s.depth))
        .ok_or_else(|| anyhow::anyhow!("reference image has the wrong size"))?;
    let cmp = compare(&mine, &reference, c.tolerance);
    let ok = c.matches(cmp.off, cmp.total);
    let text = format!(
        "{} {}: {} of {} pixels off by more than {}/255 ({:.2}%; the limit is {}), largest difference {}: {}",
        s.what,
        s.path.display(),
        count(cmp.off),
        count(cmp.total),
        c.tolerance,
        cmp.percent_off(),
        c.limit(),
        cmp.max_difference,
        if ok { "matches" } else { "does not match" },
    );
    let heat = heat_map(&mine, &reference, c.tolerance);
    Ok(Verdict {
        student: s,
        text,
        ok,
        decoded: Some(Decoded {
            student: s,
            mine,
            reference: reference.into_raw(),
            heat,
        }),
    })
}

/// A line judged: the diagnosis (empty when every image matches), each image's verdict, the
/// regions of off pixels with their stories, and, when the line asks for `-stats`, the
/// counters of the reference render (tracelab's, not the student program's).
pub(super) struct Judgement<'s> {
    pub diagnosis: String,
    pub verdicts: Vec<Verdict<'s>>,
    pub regions: String,
    pub stats: Option<String>,
}

impl Judgement<'_> {
    pub fn all_match(&self) -> bool {
        self.verdicts.iter().all(|v| v.ok)
    }
}

/// The reference for `job` rendered and each of `students` judged against it, with the
/// diagnosis and `keep` regions an image. Mesh files the scene reads are added to `plan`.
pub(super) fn judge_line<'s>(
    job: &RenderJob,
    students: &'s [Student<'s>],
    c: &Criterion,
    keep: usize,
    plan: &mut OutputPlan,
) -> anyhow::Result<Judgement<'s>> {
    let (scene, meshes) = load_scene_and_meshes(job.scene.as_deref())?;
    for m in &meshes {
        plan.reads(m);
    }
    let compiled = compile_for(job, &scene)?;
    let settings = RenderSettings {
        shade_back: job.shade_back,
        normal_transform: job.normal_transform,
        object_rays: job.object_rays,
        secondary: job.secondary,
        ..RenderSettings::new(job.width, job.height)
    };
    let start = std::time::Instant::now();
    let frame = frame_for(job, &compiled, &settings)?;
    let stats = job.stats.then(|| {
        format!(
            "-stats: the counters of tracelab's reference render for this line (not of your \
             program's run):\n{}",
            super::stats::stats_text(&compiled, &settings, start.elapsed())
        )
    });
    let r = Reference {
        scene: &scene,
        compiled: &compiled,
        settings,
        frame: &frame,
    };
    let verdicts = students
        .iter()
        .map(|s| check(c, &r, s))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let decoded: Vec<&Decoded> = verdicts.iter().filter_map(|v| v.decoded.as_ref()).collect();
    let mut diagnosis = String::new();
    // The catalogue's mistakes are of the one-ray-a-pixel render, not of a picture of the
    // grid's cells nor of a supersampled image (its variants would not be supersampled).
    if !verdicts.iter().all(|v| v.ok)
        && !decoded.is_empty()
        && !job.visualize_grid
        && !job.supersample.filters_the_output()
    {
        // The mistake first: it says more than any pixel.
        let judged: Vec<Judged> = decoded
            .iter()
            .map(|d| Judged {
                what: d.student.what,
                view: d.student.view,
                depth: d.student.depth,
                mine: d.mine.as_raw(),
                reference: &d.reference,
            })
            .collect();
        let found = diagnose(&scene, &compiled, &settings, &judged, c);
        diagnosis = diagnosis_text(&found, &judged);
    }
    let regions: String = decoded
        .iter()
        .map(|d| region_text(d, &r, students, c, keep))
        .collect();
    Ok(Judgement {
        diagnosis,
        verdicts,
        regions,
        stats,
    })
}

/// The images a course line names, as (what, path, view, depth range): the colour image at
/// `colour`, and the line's -normals and -depth files.
pub(super) fn wanted_images<'j>(
    job: &'j RenderJob,
    colour: &'j Path,
) -> Vec<(&'static str, &'j Path, View, (f32, f32))> {
    let mut wanted = vec![("colour", colour, View::Color, (0.0, 1.0))];
    if let Some(n) = &job.normals {
        wanted.push(("normals", n.as_path(), View::Normals, (0.0, 1.0)));
    }
    if let Some((min, max, d)) = &job.depth {
        wanted.push(("depth", d.as_path(), View::Depth, (*min, *max)));
    }
    wanted
}

/// The t a depth byte `g` encodes: shade in [g/255, (g+1)/255), so t in (t_lo, t_hi].
fn t_of_depth_byte(g: u8, (min, max): (f32, f32)) -> (f64, f64) {
    let (min, max) = (f64::from(min), f64::from(max));
    let t = |shade: f64| max - shade * (max - min);
    (t((f64::from(g) + 1.0) / 255.0), t(f64::from(g) / 255.0))
}

/// What the student's byte at a pixel implies, where it says something in the course's terms.
fn implied(d: &Decoded, p: [u8; 3], r: &Reference) -> String {
    match d.student.view {
        View::Depth if p[0] == 0 => "; your byte 0 is the background or t ≥ max".to_string(),
        View::Depth if p[0] == 255 => "; your byte 255 means t ≤ min".to_string(),
        View::Depth => {
            let (lo, hi) = t_of_depth_byte(p[0], d.student.depth);
            format!("; your byte {} means t in ({lo:.4}, {hi:.4}]", p[0])
        }
        View::Normals => format!(
            "; yours means |n| ≈ ({:.3}, {:.3}, {:.3})",
            f32::from(p[0]) / 255.0,
            f32::from(p[1]) / 255.0,
            f32::from(p[2]) / 255.0
        ),
        View::Color if p == quantize3(r.compiled.background) => {
            "; yours is the background colour: your ray seems to miss".to_string()
        }
        View::Color => String::new(),
    }
}

fn quantize3(c: glam::Vec3) -> [u8; 3] {
    [quantize(c.x), quantize(c.y), quantize(c.z)]
}

/// The bytes each image of the line should hold at pixel `i`.
fn expected_bytes(r: &Reference, students: &[Student], x: u32, row: u32) -> String {
    let Some(s) = r.frame.get(x, row) else {
        return String::new();
    };
    let mut parts = vec![format!("colour {:?}", s.color)];
    for st in students {
        match st.view {
            View::Normals => parts.push(format!("normals {:?}", s.normal)),
            View::Depth => {
                let g = if s.is_hit() {
                    quantize(depth_shade(s.t, st.depth.0, st.depth.1))
                } else {
                    0
                };
                parts.push(format!("depth {:?}", [g; 3]));
            }
            View::Color => {}
        }
    }
    parts.join(", ")
}

/// Each image's regions of off pixels, largest first, with the story at the typical pixel.
fn region_text(
    d: &Decoded,
    r: &Reference,
    students: &[Student],
    c: &Criterion,
    keep: usize,
) -> String {
    let (w, h) = (r.frame.width, r.frame.height);
    let nodes: Vec<u32> = r.frame.samples.iter().map(|s| s.node).collect();
    let all = regions(d.mine.as_raw(), &d.reference, &nodes, (w, h), c.tolerance);
    if all.is_empty() {
        return String::new();
    }
    let fringes = all.iter().filter(|g| g.fringe).count();
    let mut out = format!(
        "{} {}: {} region{} of off pixels ({} of them one-pixel fringes along silhouettes), largest first:\n",
        d.student.what,
        d.student.path.display(),
        count(all.len()),
        if all.len() == 1 { "" } else { "s" },
        count(fringes)
    );
    for (k, g) in all.iter().take(keep).enumerate() {
        let (x, row) = g.typical;
        let i = (row * w + x) as usize * 3;
        let p = [
            d.mine.as_raw()[i],
            d.mine.as_raw()[i + 1],
            d.mine.as_raw()[i + 2],
        ];
        let q = [d.reference[i], d.reference[i + 1], d.reference[i + 2]];
        let story = inspect_pixel(r.scene, r.compiled, &r.settings, x, row);
        let report = pixel_report(r.scene, &story, &r.settings);
        let (x0, y0, x1, y1) = g.bounds;
        out.push_str(&format!(
            "  {}. {} pixel{} in ({x0}, {y0})–({x1}, {y1}){}; at ({x}, {row}): yours {p:?}, reference {q:?}{}\n     the reference ray: {}\n     each image there: {}\n",
            k + 1,
            count(g.pixels),
            if g.pixels == 1 { "" } else { "s" },
            if g.fringe {
                ", a one-pixel fringe along a silhouette (where the edge is sampled)"
            } else {
                ""
            },
            implied(d, p, r),
            one_line(&report),
            expected_bytes(r, students, x, row),
        ));
    }
    if all.len() > keep {
        out.push_str(&format!(
            "  … and {} smaller region{} (--regions N lists more)\n",
            count(all.len() - keep),
            if all.len() - keep == 1 { "" } else { "s" }
        ));
    }
    out
}

/// The criterion of `--tolerance` and `--min-match`, checked.
pub(super) fn criterion(a: &DiffArgs) -> anyhow::Result<Criterion> {
    if !(0.0..=100.0).contains(&a.min_match) {
        return Err(usage(format!(
            "--min-match {}: expected a percentage from 0 to 100",
            a.min_match
        )));
    }
    Ok(Criterion {
        tolerance: a.tolerance,
        min_match: a.min_match,
    })
}

pub fn run_diff(a: &DiffArgs) -> anyhow::Result<()> {
    let criterion = criterion(a)?;
    let Some(image) = a.image.as_deref() else {
        return Err(usage(
            "diff needs IMAGE -- COURSE-COMMAND-LINE, or --batch COMMANDS.txt --images DIR",
        ));
    };
    if a.course.is_empty() {
        return Err(usage(
            "diff: the course's command line goes after `--`: tracelab diff IMAGE -- -input SCENE -size W H ...",
        ));
    }
    let job: RenderJob = parse_course_args(&a.course)?;
    job.supersample.refuse_pictures("diff")?;
    check_size(job.width, job.height)?;
    let size = (job.width, job.height);
    // Heat maps are invented names: never a file this command reads or the line names.
    let mut plan = OutputPlan::new();
    plan.reads(image);
    if let Some(s) = &job.scene {
        plan.reads(s);
    }
    if let Some(o) = &job.output {
        plan.names(o);
    }
    // Every image is read and its header checked before the (possibly long) render.
    let mut students = Vec::new();
    for (what, path, view, depth) in wanted_images(&job, image) {
        plan.reads(path);
        students.push(read_student(what, path, view, depth, size)?);
    }
    let j = judge_line(&job, &students, &criterion, a.regions, &mut plan)?;
    let mut failed = Vec::new();
    let mut out = j.stats.clone().unwrap_or_default();
    out.push_str(&j.diagnosis);
    for v in &j.verdicts {
        out.push_str(&v.text);
        if let Some(d) = &v.decoded {
            let map = match write_heat_map(&d.heat, v.student.path, &mut plan) {
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
            out.push_str(&format!("; {map}"));
        }
        out.push('\n');
    }
    out.push_str(&j.regions);
    let all = j.all_match();
    // Paths and node labels (an `obj_file` name) are the user's text: escaped.
    write_summary_text(&out)?;
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
    fn the_heat_map_marks_pixels_past_the_tolerance() {
        let reference = RgbImage::from_pixel(4, 3, image::Rgb([100, 100, 100]));
        let mut mine = reference.clone();
        mine.put_pixel(3, 0, image::Rgb([60, 100, 100])); // 40 over
        mine.put_pixel(0, 0, image::Rgb([102, 98, 100])); // 2: not off
        let map = heat_map(&mine, &reference, 2);
        assert_eq!(map.get_pixel(3, 0).0, [255, 40, 0]);
        assert_eq!(map.get_pixel(0, 0).0, [25, 25, 25]);
    }

    #[test]
    fn a_depth_byte_encodes_a_range_of_t() {
        // Range 8..11: byte 255 is t ≤ 8 + 3/255; byte 0 is t > 11 − 3/255.
        let (lo, hi) = t_of_depth_byte(85, (8.0, 11.0));
        assert!((hi - 10.0).abs() < 1e-9 && (lo - (10.0 - 3.0 / 255.0)).abs() < 1e-9);
    }
}
