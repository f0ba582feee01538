//! Conformance with the course's assignments 3, 4, 6 and 7 (Phong highlights, point lights,
//! shadows, reflection, refraction; the uniform grid): every line of `commands.txt` that
//! writes an `output3_*`, `output4_*` or, with a reference, `output6_*` image is run unchanged (with `tracelab` for `raytracer`) in a
//! temporary copy of the scenes, and each image is judged by the references' own criterion
//! (`AGREEMENT.md`): it matches when fewer than 1% of its pixels differ from the reference by
//! more than 2/255 on some channel. The handout's `_fix` images (the optional specular fix,
//! "a choice of the implementation, not a flag") are the same lines with tracelab's
//! `-specular_fix`. The files are in `TRACELAB_SEMESTER_DIR` (default
//! ../shared/mit6837-semester); the test is `#[ignore]`d, and with `--ignored` it fails when
//! they are missing.

mod common;
use common::copy_dir;

use std::path::Path;
use std::process::Command;

/// (% of pixels off by more than 2/255, largest channel difference)
fn compare(out: &Path, reference: &Path) -> Result<(f64, u8), String> {
    let a = image::open(out)
        .map_err(|e| format!("{}: {e}", out.display()))?
        .to_rgb8();
    let b = image::open(reference)
        .map_err(|e| format!("{}: {e}", reference.display()))?
        .to_rgb8();
    if a.dimensions() != b.dimensions() {
        return Err(format!(
            "size {:?} vs reference {:?}",
            a.dimensions(),
            b.dimensions()
        ));
    }
    let mut off = 0usize;
    let mut worst = 0u8;
    for (p, q) in a.pixels().zip(b.pixels()) {
        let d = (0..3).map(|c| p[c].abs_diff(q[c])).max().unwrap_or(0);
        worst = worst.max(d);
        if d > 2 {
            off += 1;
        }
    }
    Ok((100.0 * off as f64 / (a.width() * a.height()) as f64, worst))
}

/// The image a course line writes (the value after `-output`).
fn output_of<'a>(args: &[&'a str]) -> Option<&'a str> {
    let i = args.iter().position(|a| *a == "-output")?;
    args.get(i + 1).copied()
}

/// Runs every line whose `-output` starts with one of `prefixes` and has a reference (with
/// its `_fix` twin where one exists), prints the table and returns (images judged,
/// failures).
fn run_lines(prefixes: &[&str], area: &str) -> (usize, Vec<String>) {
    let shared = common::semester_dir();
    let dir = common::temp_dir("semester", area);
    copy_dir(&shared.join("scenes"), &dir);
    let commands = std::fs::read_to_string(shared.join("commands.txt")).expect("commands.txt");
    let exe = env!("CARGO_BIN_EXE_tracelab");
    let mut jobs: Vec<(Vec<String>, String)> = Vec::new();
    for line in commands.lines().filter(|l| !l.trim().is_empty()) {
        let mut words = line.split_whitespace();
        assert_eq!(words.next(), Some("raytracer"), "unexpected line {line}");
        let args: Vec<&str> = words.collect();
        let Some(out) = output_of(&args) else {
            continue;
        };
        if !prefixes.iter().any(|p| out.starts_with(p))
            || !shared.join("reference").join(out).is_file()
        {
            continue;
        }
        jobs.push((args.iter().map(|s| s.to_string()).collect(), out.into()));
        // The handout's images with the optional specular fix, where a reference exists.
        let fixed = out.replace(".png", "_fix.png");
        if shared.join("reference").join(&fixed).is_file() {
            let mut a: Vec<String> = args
                .iter()
                .map(|s| {
                    if *s == out {
                        fixed.clone()
                    } else {
                        s.to_string()
                    }
                })
                .collect();
            a.push("-specular_fix".into());
            jobs.push((a, fixed));
        }
    }
    let mut rows = Vec::new();
    let mut failures = Vec::new();
    let start = std::time::Instant::now();
    for (args, img) in &jobs {
        let run = Command::new(exe)
            .args(args)
            .current_dir(&dir)
            .output()
            .expect("run tracelab");
        if !run.status.success() {
            failures.push(format!(
                "{}: exit {:?}: {}",
                args.join(" "),
                run.status.code(),
                String::from_utf8_lossy(&run.stderr)
            ));
            continue;
        }
        match compare(&dir.join(img), &shared.join("reference").join(img)) {
            Ok((pct, worst)) => {
                let pass = pct < 1.0;
                rows.push(format!(
                    "{img:<22} {pct:>8.2}% {worst:>6}  {}",
                    if pass { "pass" } else { "FAIL" }
                ));
                if !pass {
                    failures.push(format!("{img}: {pct:.2}% of pixels off by > 2/255"));
                }
            }
            Err(e) => failures.push(format!("{img}: {e}")),
        }
    }
    let elapsed = start.elapsed();
    println!("{:<22} {:>9} {:>6}  result", "image", "% off >2", "max");
    for r in &rows {
        println!("{r}");
    }
    println!(
        "conformance ({}): {} of {} images match; {} runs in {:.2} s",
        prefixes.join(", "),
        rows.iter().filter(|r| r.ends_with("pass")).count(),
        rows.len(),
        jobs.len(),
        elapsed.as_secs_f64()
    );
    let _ = std::fs::remove_dir_all(&dir);
    (rows.len(), failures)
}

#[test]
#[ignore = "needs the course's assignment 3-7 files: TRACELAB_SEMESTER_DIR, default ../shared/mit6837-semester"]
fn every_assignment_3_and_4_line_matches_its_reference() {
    let (judged, failures) = run_lines(&["output3_", "output4_"], "a34");
    assert!(
        failures.is_empty(),
        "conformance failures:\n{}",
        failures.join("\n")
    );
    assert_eq!(judged, 42, "expected 15 + 27 reference images");
}

/// Assignment 6's lines with a reference: the same scenes as before, with `-grid NX NY NZ`
/// (the uniform grid instead of the BVH) and `-stats` on many of them.
#[test]
#[ignore = "needs the course's assignment 3-7 files: TRACELAB_SEMESTER_DIR, default ../shared/mit6837-semester"]
fn every_assignment_6_line_with_a_reference_matches_it() {
    let (judged, failures) = run_lines(&["output6_"], "a6");
    assert!(
        failures.is_empty(),
        "conformance failures:\n{}",
        failures.join("\n")
    );
    assert_eq!(judged, 26, "expected 26 reference images");
}

/// The images a course line writes: the values after `-output`, `-render_samples` and
/// `-render_filter`.
fn images_of(args: &[String]) -> Vec<String> {
    args.iter()
        .enumerate()
        .filter(|(_, a)| ["-output", "-render_samples", "-render_filter"].contains(&a.as_str()))
        .filter_map(|(i, _)| args.get(i + 1).cloned())
        .collect()
}

/// Assignment 7's references tracelab does not match, and why. Each is still run and
/// printed; the test fails if one of them starts to match (so this list stays true) or if
/// any other reference does not.
/// Empty since the triangle test compares undivided barycentrics (output7_01d_low_res, whose
/// samples lie exactly on an edge, matches since then).
const A7_KNOWN: [(&str, &str); 0] = [];

/// Assignment 7: every line of `scene7_*` runs unchanged (exit 0, every image it names
/// written), including the random and jittered ones, which have no reference; each image with
/// a reference (29) is judged by the references' criterion.
#[test]
#[ignore = "needs the course's assignment 3-7 files: TRACELAB_SEMESTER_DIR, default ../shared/mit6837-semester"]
fn every_assignment_7_line_runs_and_each_reference_matches() {
    let shared = common::semester_dir();
    let dir = common::temp_dir("semester", "a7");
    copy_dir(&shared.join("scenes"), &dir);
    let commands = std::fs::read_to_string(shared.join("commands.txt")).expect("commands.txt");
    let exe = env!("CARGO_BIN_EXE_tracelab");
    let mut rows = Vec::new();
    let mut failures = Vec::new();
    let (mut lines, mut unreferenced) = (0, 0);
    let start = std::time::Instant::now();
    for line in commands.lines().filter(|l| l.contains("scene7_")) {
        let args: Vec<String> = line.split_whitespace().skip(1).map(String::from).collect();
        lines += 1;
        let run = Command::new(exe)
            .args(&args)
            .current_dir(&dir)
            .output()
            .expect("run tracelab");
        if !run.status.success() {
            failures.push(format!(
                "{line}: exit {:?}: {}",
                run.status.code(),
                String::from_utf8_lossy(&run.stderr)
            ));
            continue;
        }
        for img in images_of(&args) {
            if !dir.join(&img).is_file() {
                failures.push(format!("{line}: {img} was not written"));
                continue;
            }
            let reference = shared.join("reference").join(&img);
            if !reference.is_file() {
                unreferenced += 1;
                continue;
            }
            let known = A7_KNOWN.iter().find(|(k, _)| *k == img);
            match compare(&dir.join(&img), &reference) {
                Ok((pct, worst)) => {
                    let pass = pct < 1.0;
                    let verdict = match (pass, known) {
                        (true, None) => "pass",
                        (false, Some(_)) => "known",
                        (true, Some(_)) => {
                            failures.push(format!("{img} now matches: take it off A7_KNOWN"));
                            "pass?"
                        }
                        (false, None) => {
                            failures.push(format!("{img}: {pct:.2}% of pixels off by > 2/255"));
                            "FAIL"
                        }
                    };
                    rows.push(format!("{img:<26} {pct:>8.2}% {worst:>6}  {verdict}"));
                }
                Err(e) => failures.push(format!("{img}: {e}")),
            }
        }
    }
    println!("{:<26} {:>9} {:>6}  result", "image", "% off >2", "max");
    for r in &rows {
        println!("{r}");
    }
    for (img, why) in A7_KNOWN {
        println!("known: {img}: {why}");
    }
    println!(
        "conformance (assignment 7): {} of {} images match, {} known; {lines} lines run \
         (exit 0, images written; {unreferenced} images without a reference) in {:.2} s",
        rows.iter().filter(|r| r.ends_with("pass")).count(),
        rows.len(),
        rows.iter().filter(|r| r.ends_with("known")).count(),
        start.elapsed().as_secs_f64()
    );
    let _ = std::fs::remove_dir_all(&dir);
    assert!(
        failures.is_empty(),
        "assignment 7 failures:\n{}",
        failures.join("\n")
    );
    assert_eq!(rows.len(), 29, "expected 29 reference images");
    assert_eq!(lines, 62, "expected assignment 7's 62 lines");
}
