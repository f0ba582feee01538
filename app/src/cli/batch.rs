//! `tracelab diff --batch COMMANDS.txt --images DIR`: a student's folder of outputs judged
//! against every `raytracer` line of the handout's commands file, as `diff` judges one
//! line; one summary line per image on standard output and one self-contained HTML report
//! (`report_html`). The student's files are only read.

use std::ffi::OsString;
use std::io::Read;
use std::path::{Component, Path, PathBuf};

use super::course::parse_course_args;
use super::diff::{DiffArgs, Judgement, Student, judge_line, read_student, wanted_images};
use super::judge::{Criterion, count};
use super::render::RenderJob;
use super::report_html::{ImageRow, LineRow, Pictures, report_html};
use crate::exit::{Exit, check_size, usage};
use crate::io::{OutputPlan, write_atomic, write_implicit, write_stderr_text, write_summary_text};

/// The largest commands file read (the handout's is 2 KiB).
pub const COMMANDS_CAP: u64 = 1 << 20;
/// The most `raytracer` lines judged in one run.
pub const LINES_CAP: usize = 1000;
const DEFAULT_REPORT: &str = "tracelab-report.html";
/// The largest image whose pictures are inlined in the report, and the most base64 the
/// report holds in all: the page stays one a browser opens, and memory stays bounded.
pub const INLINE_PIXELS: u64 = 1024 * 1024;
pub const INLINE_BYTES: usize = 256 << 20;

/// One `raytracer` line of the commands file.
struct CourseLine {
    number: usize,
    text: String,
    args: Vec<OsString>,
}

/// The commands file's `raytracer` lines. Blank lines and `#` comments are skipped; any
/// other line is skipped with a warning naming it.
fn read_commands(path: &Path) -> anyhow::Result<(Vec<CourseLine>, Vec<String>)> {
    let fail = |e: &dyn std::fmt::Display| anyhow::anyhow!("{}: cannot read: {e}", path.display());
    let meta = std::fs::metadata(path).map_err(|e| fail(&e))?;
    if !meta.is_file() {
        return Err(fail(&"not a regular file"));
    }
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .map_err(|e| fail(&e))?
        .take(COMMANDS_CAP + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| fail(&e))?;
    if bytes.len() as u64 > COMMANDS_CAP {
        return Err(fail(&format_args!(
            "larger than {COMMANDS_CAP} bytes: no handout commands file is"
        )));
    }
    let (mut lines, mut warnings) = (Vec::new(), Vec::new());
    for (i, raw) in bytes.split(|&b| b == b'\n').enumerate() {
        let number = i + 1;
        let text = String::from_utf8_lossy(raw).trim().to_string();
        let words: Vec<&[u8]> = raw
            .split(|b| b.is_ascii_whitespace())
            .filter(|w| !w.is_empty())
            .collect();
        match words.first() {
            None => continue,
            Some(w) if w.starts_with(b"#") => continue,
            Some(&b"raytracer") => {}
            Some(_) => {
                warnings.push(format!(
                    "{}:{number}: not a `raytracer` line, skipped: {text}",
                    path.display()
                ));
                continue;
            }
        }
        if lines.len() == LINES_CAP {
            return Err(usage(format!(
                "{}:{number}: more than {LINES_CAP} raytracer lines",
                path.display()
            )));
        }
        lines.push(CourseLine {
            number,
            text,
            args: words[1..].iter().map(|w| os_string(w)).collect(),
        });
    }
    Ok((lines, warnings))
}

#[cfg(unix)]
fn os_string(bytes: &[u8]) -> OsString {
    use std::os::unix::ffi::OsStringExt;
    OsString::from_vec(bytes.to_vec())
}

#[cfg(not(unix))]
fn os_string(bytes: &[u8]) -> OsString {
    OsString::from(String::from_utf8_lossy(bytes).into_owned())
}

/// `name` inside `dir`: a line's file names are names in the folder, never a way out of it.
fn inside(dir: &Path, name: &Path, flag: &str) -> Result<PathBuf, String> {
    if name
        .components()
        .all(|c| matches!(c, Component::Normal(_) | Component::CurDir))
    {
        Ok(dir.join(name))
    } else {
        Err(format!(
            "{flag} {}: a name inside the folder is expected (no `..`, not absolute)",
            name.display()
        ))
    }
}

/// Why a student's image cannot be judged before it is opened: missing, or not a regular
/// file once links are followed (a FIFO would block, a device never end).
fn unreadable(path: &Path) -> Option<String> {
    match std::fs::metadata(path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            let dangling = std::fs::symlink_metadata(path).is_ok();
            Some(if dangling {
                "missing: a symbolic link to nothing".into()
            } else {
                "missing".into()
            })
        }
        Err(e) => Some(format!("cannot read: {e}")),
        Ok(m) if m.is_dir() => Some("cannot read: it is a folder".into()),
        Ok(m) if !m.is_file() => Some("cannot read: not a regular file".into()),
        Ok(_) => None,
    }
}

/// The scenes folder: `--scenes`, else `scenes/` beside the commands file, else its folder.
fn scenes_dir(a: &DiffArgs, commands: &Path) -> PathBuf {
    if let Some(d) = &a.scenes {
        return d.clone();
    }
    let parent = match commands.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let beside = parent.join("scenes");
    if beside.is_dir() { beside } else { parent }
}

/// One line parsed, its paths resolved: the job and the images it names.
struct Planned {
    line: CourseLine,
    job: Result<RenderJob, String>,
}

fn plan_line(line: CourseLine, images: &Path, scenes: &Path) -> Planned {
    let job = (|| {
        let mut job = parse_course_args(&line.args).map_err(|e| e.to_string())?;
        job.supersample
            .refuse_pictures("diff --batch")
            .map_err(|e| e.to_string())?;
        check_size(job.width, job.height).map_err(|e| e.to_string())?;
        let scene = job.scene.take().unwrap_or_default();
        job.scene = Some(inside(scenes, &scene, "-input")?);
        let Some(output) = job.output.take() else {
            return Err("no -output: nothing to compare".to_string());
        };
        job.output = Some(inside(images, &output, "-output")?);
        if let Some(n) = job.normals.take() {
            job.normals = Some(inside(images, &n, "-normals")?);
        }
        if let Some((min, max, d)) = job.depth.take() {
            job.depth = Some((min, max, inside(images, &d, "-depth")?));
        }
        Ok(job)
    })();
    Planned { line, job }
}

pub fn run_batch(a: &DiffArgs, commands: &Path, c: &Criterion) -> anyhow::Result<()> {
    let Some(images) = a.images.as_deref() else {
        return Err(usage("--batch needs --images DIR"));
    };
    if !images.is_dir() {
        return Err(usage(format!(
            "--images {}: not a folder",
            images.display()
        )));
    }
    let (lines, warnings) = read_commands(commands)?;
    for w in &warnings {
        write_stderr_text(&format!("warning: {w}\n"));
    }
    let scenes = scenes_dir(a, commands);
    let planned: Vec<Planned> = lines
        .into_iter()
        .map(|l| plan_line(l, images, &scenes))
        .collect();
    // The report is never an input: the commands file, a scene or an image.
    let mut plan = OutputPlan::new();
    plan.reads(commands);
    for p in &planned {
        if let Ok(job) = &p.job {
            for f in job.scene.iter().chain(&job.output).chain(&job.normals) {
                plan.reads(f);
            }
            if let Some((_, _, d)) = &job.depth {
                plan.reads(d);
            }
        }
    }
    let report = match &a.report {
        Some(r) => {
            plan.writes(r);
            plan.check().map_err(|e| e.into_cli())?;
            (r.clone(), true)
        }
        None => {
            let chosen = plan
                .implicit(Path::new(DEFAULT_REPORT))
                .map_err(|e| e.into_cli())?;
            (chosen.path, false)
        }
    };
    let mut rows = Vec::new();
    let mut summary = String::new();
    let (mut failed_lines, mut images_total, mut images_ok) = (0, 0, 0);
    let mut inlined = 0;
    for p in planned {
        if p.job.as_ref().is_ok_and(|j| j.stats) {
            // Never silently ignored: the report has no place for the counters.
            write_stderr_text(&format!(
                "warning: {}:{}: -stats is not printed by --batch (it judges images); \
                 `tracelab diff IMAGE -- LINE` prints the reference render's counters\n",
                commands.display(),
                p.line.number
            ));
        }
        let row = judge_planned(p, a, c, &mut plan, &mut inlined);
        for img in &row.images {
            images_total += 1;
            images_ok += usize::from(img.ok);
            summary.push_str(&format!(
                "{}:{}: {}\n",
                commands.display(),
                row.number,
                img.verdict
            ));
        }
        if let Some(e) = &row.error {
            failed_lines += 1;
            summary.push_str(&format!("{}:{}: {e}\n", commands.display(), row.number));
        }
        rows.push(row);
    }
    let html = report_html(commands, images, &scenes, c, &warnings, &rows);
    // Checked again: the meshes the scenes read are inputs too.
    let written = plan.check().map_err(|e| e.to_string()).and_then(|()| {
        if report.1 {
            write_atomic(&report.0, html.as_bytes())
        } else {
            write_implicit(&report.0, html.as_bytes())
        }
        .map_err(|e| format!("{}: cannot write the report: {e}", report.0.display()))
    });
    summary.push_str(&format!(
        "{} of {} images match ({} line{}{}); report {}\n",
        count(images_ok),
        count(images_total),
        count(rows.len()),
        if rows.len() == 1 { "" } else { "s" },
        if failed_lines > 0 {
            format!(", {failed_lines} could not be judged")
        } else {
            String::new()
        },
        match &written {
            Ok(()) => report.0.display().to_string(),
            Err(_) => "not written".into(),
        }
    ));
    write_summary_text(&summary)?;
    if let Err(e) = written {
        return Err(anyhow::anyhow!(e));
    }
    if failed_lines > 0 {
        return Err(anyhow::anyhow!(
            "{failed_lines} line{} of {} could not be judged (see above)",
            if failed_lines == 1 { "" } else { "s" },
            commands.display()
        ));
    }
    if images_ok == images_total {
        Ok(())
    } else {
        Err(Exit::Differs.into())
    }
}

/// One line judged into the report's row; any failure is the row's error, never the run's.
fn judge_planned(
    p: Planned,
    a: &DiffArgs,
    c: &Criterion,
    plan: &mut OutputPlan,
    inlined: &mut usize,
) -> LineRow {
    let mut row = LineRow {
        number: p.line.number,
        text: p.line.text,
        diagnosis: String::new(),
        regions: String::new(),
        images: Vec::new(),
        error: None,
    };
    let job = match p.job {
        Ok(j) => j,
        Err(e) => {
            row.error = Some(e);
            return row;
        }
    };
    let colour = job.output.clone().unwrap_or_default();
    let mut students: Vec<Student> = Vec::new();
    // The images that cannot be read, by their place on the line (colour, normals, depth).
    let mut unread = Vec::new();
    for (k, (what, path, view, depth)) in wanted_images(&job, &colour).into_iter().enumerate() {
        let why = unreadable(path).map(Err).unwrap_or_else(|| {
            read_student(what, path, view, depth, (job.width, job.height))
                .map_err(|e| strip_path(&e.to_string(), path))
        });
        match why {
            Ok(s) => students.push(s),
            Err(why) => unread.push((
                k,
                ImageRow {
                    verdict: format!("{what} {}: {why}: does not match", path.display()),
                    ok: false,
                    pictures: None,
                    note: None,
                },
            )),
        }
    }
    if !students.is_empty() {
        match judge_line(&job, &students, c, a.regions, plan) {
            Ok(j) => fill(&mut row, &j, inlined),
            Err(e) => row.error = Some(e.to_string()),
        }
    }
    // Back in the line's order.
    for (k, r) in unread {
        let at = k.min(row.images.len());
        row.images.insert(at, r);
    }
    row
}

/// "DIR/x.png: cannot read image: …" → "cannot read image: …" (the verdict names the path).
fn strip_path(message: &str, path: &Path) -> String {
    let prefix = format!("{}: ", path.display());
    message.strip_prefix(&prefix).unwrap_or(message).to_string()
}

/// The line's verdicts and pictures into its row; pictures only within the inline caps.
fn fill(row: &mut LineRow, j: &Judgement, inlined: &mut usize) {
    row.diagnosis = j.diagnosis.clone();
    row.regions = j.regions.clone();
    for v in &j.verdicts {
        let (mut pictures, mut note) = (None, None);
        if let Some(d) = &v.decoded {
            let (w, h) = d.mine.dimensions();
            if u64::from(w) * u64::from(h) > INLINE_PIXELS {
                note = Some(format!(
                    "pictures not inlined: {w}×{h} is over {INLINE_PIXELS} pixels (tracelab diff on this line writes its heat map)"
                ));
            } else if *inlined > INLINE_BYTES {
                note = Some(format!(
                    "pictures not inlined: the report already holds {} MiB of them",
                    INLINE_BYTES >> 20
                ));
            } else {
                let p = Pictures::new(d);
                *inlined += p.mine.len() + p.reference.len() + p.heat.len();
                pictures = Some(p);
            }
        }
        row.images.push(ImageRow {
            verdict: v.text.clone(),
            ok: v.ok,
            pictures,
            note,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_outside_the_folder_are_refused() {
        let d = Path::new("imgs");
        assert_eq!(
            inside(d, Path::new("a.png"), "-output"),
            Ok(PathBuf::from("imgs/a.png"))
        );
        for bad in ["../a.png", "/etc/passwd", "x/../../a.png"] {
            let e = inside(d, Path::new(bad), "-output").expect_err(bad);
            assert!(e.contains("-output") && e.contains("inside"), "{e}");
        }
    }
}
