//! Assignments 3–4 on the command line: `-shadows -bounces -weight -specular_fix`, the
//! preview flags noted, hostile values, rays that would never finish refused before any
//! work, and the ray tree in `inspect`. (Assignment 7's flags: `cli_samples.rs`.)

mod common;

use std::process::Output;

use common::repo;
use common::tracelab;

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).to_string()
}

fn scene() -> String {
    repo().join("scenes/mirror_glass.txt").display().to_string()
}

#[test]
fn the_handout_flags_render_and_change_the_image() {
    let d = common::temp_dir("rays", "flags");
    let s = scene();
    let plain = tracelab(&["-input", &s, "-size", "40", "40", "-output", "a.png"], &d);
    assert!(plain.status.success(), "{}", stderr(&plain));
    let full = tracelab(
        &[
            "-input",
            &s,
            "-size",
            "40",
            "40",
            "-output",
            "b.png",
            "-shadows",
            "-bounces",
            "4",
            "-weight",
            "0.01",
            "-shade_back",
        ],
        &d,
    );
    assert!(full.status.success(), "{}", stderr(&full));
    let a = std::fs::read(d.join("a.png")).expect("a.png");
    let b = std::fs::read(d.join("b.png")).expect("b.png");
    assert_ne!(a, b, "shadows and bounces must show in the image");
    // `render` spells them as long options and gives the same bytes.
    let long = tracelab(
        &[
            "render",
            &s,
            "--size",
            "40",
            "40",
            "--output",
            "c.png",
            "--shadows",
            "--bounces",
            "4",
            "--weight",
            "0.01",
            "--shade-back",
        ],
        &d,
    );
    assert!(long.status.success(), "{}", stderr(&long));
    assert_eq!(std::fs::read(d.join("c.png")).expect("c.png"), b);
}

#[test]
fn preview_flags_are_accepted_with_a_note() {
    let d = common::temp_dir("rays", "preview");
    let s = scene();
    let o = tracelab(
        &[
            "-input",
            &s,
            "-size",
            "20",
            "20",
            "-output",
            "a.png",
            "-gui",
            "-tessellation",
            "10",
            "5",
            "-gouraud",
        ],
        &d,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("-gui, -tessellation 10 5, -gouraud") && e.contains("tracelab SCENE"),
        "{e}"
    );
}

#[test]
fn hostile_bounce_and_weight_values_are_usage_errors_naming_the_flag() {
    let d = common::temp_dir("rays", "hostile");
    let s = scene();
    for (flag, value) in [
        ("-bounces", "101"),
        ("-bounces", "-1"),
        ("-bounces", "4294967296"),
        ("-bounces", "two"),
        ("-bounces", ""),
        ("-weight", "nan"),
        ("-weight", "inf"),
        ("-weight", "-0.5"),
        ("-weight", "1e39"),
        ("-weight", "x"),
    ] {
        let o = tracelab(
            &[
                "-input", &s, "-size", "8", "8", "-output", "h.png", flag, value,
            ],
            &d,
        );
        assert_eq!(o.status.code(), Some(2), "{flag} {value:?}: {}", stderr(&o));
        assert!(
            stderr(&o).contains(flag),
            "{flag} {value:?}: {}",
            stderr(&o)
        );
    }
    // The edges that are fine (in a scene whose rays do not branch, for -bounces 100).
    let plain = repo().join("scenes/default.txt").display().to_string();
    for (flag, value) in [("-bounces", "0"), ("-bounces", "100"), ("-weight", "0")] {
        let o = tracelab(
            &[
                "-input", &plain, "-size", "8", "8", "-output", "ok.png", flag, value,
            ],
            &d,
        );
        assert!(o.status.success(), "{flag} {value}: {}", stderr(&o));
    }
    let o = tracelab(&["-input", &s, "-size", "8", "8", "-bounces"], &d);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("-bounces needs a value"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn rays_that_would_double_past_the_cap_are_refused_before_any_work() {
    // mirror_glass.txt's glass both reflects and refracts: 2 + 4 + … + 2^15 = 65,534
    // secondary rays a pixel at -bounces 15, twice that at 16.
    let d = common::temp_dir("rays", "cap");
    let s = scene();
    let run = |b: &str| {
        tracelab(
            &[
                "-input", &s, "-size", "1", "1", "-output", "o.png", "-bounces", b,
            ],
            &d,
        )
    };
    let o = run("16");
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("-bounces 15 or fewer here"),
        "{}",
        stderr(&o)
    );
    assert!(!d.join("o.png").exists());
    // At the cap it renders (one pixel: quick whatever it meets).
    let o = run("15");
    assert!(o.status.success(), "{}", stderr(&o));
    // A scene whose rays do not branch takes any count up to 100.
    let o = tracelab(
        &[
            "-input",
            &repo().join("scenes/default.txt").display().to_string(),
            "-size",
            "4",
            "4",
            "-output",
            "p.png",
            "-bounces",
            "100",
        ],
        &d,
    );
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn inspect_prints_the_ray_tree_whose_root_is_the_pixel_s_colour() {
    let d = common::temp_dir("rays", "inspect");
    let s = scene();
    let args = [
        "inspect",
        &s,
        "--size",
        "60",
        "60",
        "--pixel",
        "40",
        "30",
        "--shadows",
        "--bounces",
        "3",
        "--weight",
        "0.01",
        "--shade-back",
    ];
    let o = tracelab(&args, &d);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("ray tree"), "{text}");
    assert!(text.contains("refracted ray"), "{text}");
    let mut json = args.to_vec();
    json.push("--json");
    let o = tracelab(&json, &d);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
    let tree = &v["ray_tree"];
    assert_eq!(tree["kind"], "eye");
    assert_eq!(tree["color"], v["color"], "the root brings back the pixel");
    assert_eq!(v["settings"]["bounces"], 3);
    // The pixel's bytes are what the render writes for the same line.
    let r = tracelab(
        &[
            "render",
            &s,
            "--size",
            "60",
            "60",
            "--output",
            "r.png",
            "--shadows",
            "--bounces",
            "3",
            "--weight",
            "0.01",
            "--shade-back",
        ],
        &d,
    );
    assert!(r.status.success(), "{}", stderr(&r));
    let img = image::open(d.join("r.png")).expect("r.png").to_rgb8();
    let px = img.get_pixel(40, 30).0;
    let rgb8: Vec<u64> = v["rgb8"]
        .as_array()
        .expect("rgb8")
        .iter()
        .map(|x| x.as_u64().unwrap_or(999))
        .collect();
    assert_eq!(rgb8, px.iter().map(|&b| u64::from(b)).collect::<Vec<_>>());
    // Without anything beyond diffuse shading there is no tree.
    let o = tracelab(
        &[
            "inspect",
            &repo().join("scenes/default.txt").display().to_string(),
            "--size",
            "20",
            "20",
            "--pixel",
            "10",
            "10",
            "--json",
        ],
        &d,
    );
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
    assert!(v["ray_tree"].is_null());
}

#[test]
fn grid_flags_render_the_same_image_print_stats_and_refuse_hostile_counts() {
    let d = common::temp_dir("rays", "grid");
    let s = repo()
        .join("scenes/perspective_mesh.txt")
        .display()
        .to_string();
    let base = ["-input", &s, "-size", "48", "48", "-shadows"];
    let run = |extra: &[&str]| {
        let mut a: Vec<&str> = base.to_vec();
        a.extend(extra);
        tracelab(&a, &d)
    };
    let bvh = run(&["-output", "bvh.png"]);
    assert!(bvh.status.success(), "{}", stderr(&bvh));
    let grid = run(&["-output", "grid.png", "-grid", "9", "7", "5", "-stats"]);
    assert!(grid.status.success(), "{}", stderr(&grid));
    assert_eq!(
        std::fs::read(d.join("grid.png")).expect("grid.png"),
        std::fs::read(d.join("bvh.png")).expect("bvh.png"),
        "the grid changes how rays find hits, not what they find"
    );
    let out = String::from_utf8_lossy(&grid.stdout);
    for line in [
        "RAY TRACING STATISTICS",
        "num grid cells                315 (9x7x5)",
        "num non-shadow rays           2304",
        "num shadow rays",
        "cells traversed per ray",
    ] {
        assert!(out.contains(line), "{line}:\n{out}");
    }
    let vis = run(&[
        "-output",
        "vis.png",
        "-grid",
        "9",
        "7",
        "5",
        "-visualize_grid",
    ]);
    assert!(vis.status.success(), "{}", stderr(&vis));
    assert_ne!(
        std::fs::read(d.join("vis.png")).expect("vis.png"),
        std::fs::read(d.join("bvh.png")).expect("bvh.png")
    );
    for (extra, says) in [
        (&["-grid", "0", "1", "1"][..], "-grid x cells"),
        (&["-grid", "-1", "1", "1"][..], "-grid x cells"),
        (&["-grid", "10", "10"][..], "-grid z cells"),
        (&["-grid", "1024", "1024", "1024"][..], "at most 16777216"),
        (&["-grid", "nan", "1", "1"][..], "-grid x cells"),
        (&["-visualize_grid"][..], "give -grid too"),
    ] {
        let mut a = extra.to_vec();
        a.extend(["-output", "bad.png"]);
        let o = run(&a);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(says), "{extra:?}: {}", stderr(&o));
        assert!(!d.join("bad.png").exists());
    }
}

/// `-stats` on a line given to `diff` is never silently dropped: the reference render's
/// counters are printed and named as such (before: nothing). Positive control: without
/// `-stats` the block is absent.
#[test]
fn diff_prints_the_reference_renders_stats_when_its_line_asks_for_them() {
    let d = common::temp_dir("rays", "diff-stats");
    let s = repo()
        .join("scenes/perspective_mesh.txt")
        .display()
        .to_string();
    let line = ["-input", &s, "-size", "24", "24", "-output", "mine.png"];
    let made = tracelab(&[&line[..], &["-grid", "5", "5", "5"]].concat(), &d);
    assert!(made.status.success(), "{}", stderr(&made));
    let diff = |extra: &[&str]| {
        let mut a = vec!["diff", "mine.png", "--"];
        a.extend(line);
        a.extend(["-grid", "5", "5", "5"]);
        a.extend(extra);
        tracelab(&a, &d)
    };
    let with = diff(&["-stats"]);
    assert!(with.status.success(), "{}", stderr(&with));
    let out = String::from_utf8_lossy(&with.stdout);
    assert!(
        out.contains("tracelab's reference render")
            && out.contains("num grid cells                125 (5x5x5)"),
        "{out}"
    );
    let without = diff(&[]);
    assert!(without.status.success(), "{}", stderr(&without));
    assert!(!String::from_utf8_lossy(&without.stdout).contains("RAY TRACING STATISTICS"));
}
