//! Assignment 7 on the command line: the samplers, filters, seed and the two pictures, in the
//! course's spelling and `render`'s; every hostile value a usage error naming its flag that
//! writes nothing; the pictures under the output policy.

mod common;

use std::path::Path;
use std::process::Output;

use common::repo;
use common::tracelab;

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).to_string()
}

fn scene() -> String {
    repo().join("scenes/default.txt").display().to_string()
}

/// Runs a course line on the default scene at `size` × `size` writing `out`, plus `extra`.
fn course(d: &Path, size: &str, out: &str, extra: &[&str]) -> Output {
    let s = scene();
    let mut args = vec!["-input", s.as_str(), "-size", size, size, "-output", out];
    args.extend(extra);
    tracelab(&args, d)
}

fn bytes(d: &Path, f: &str) -> Vec<u8> {
    std::fs::read(d.join(f)).unwrap_or_else(|e| panic!("{f}: {e}"))
}

#[test]
fn one_centred_sample_and_the_default_box_are_the_plain_render() {
    let d = common::temp_dir("samples", "plain");
    for (out, extra) in [
        ("plain.png", &[][..]),
        ("u1.png", &["-uniform_samples", "1"][..]),
        ("box.png", &["-box_filter", "0.5"][..]),
        (
            "both.png",
            &["-uniform_samples", "1", "-box_filter", "0.5"][..],
        ),
    ] {
        let o = course(&d, "24", out, extra);
        assert!(o.status.success(), "{extra:?}: {}", stderr(&o));
    }
    let plain = bytes(&d, "plain.png");
    for f in ["u1.png", "box.png", "both.png"] {
        assert_eq!(bytes(&d, f), plain, "{f}");
    }
    // More samples change the image (the default scene has edges).
    let o = course(&d, "24", "u9.png", &["-uniform_samples", "9"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_ne!(bytes(&d, "u9.png"), plain);
}

#[test]
fn random_sampling_repeats_for_a_seed_and_changes_with_it() {
    let d = common::temp_dir("samples", "seed");
    let runs: [(&str, &[&str]); 5] = [
        ("a.png", &["-random_samples", "4"]),
        ("b.png", &["-random_samples", "4"]),
        ("c.png", &["-random_samples", "4", "-seed", "6837"]),
        ("d.png", &["-random_samples", "4", "-seed", "1"]),
        ("e.png", &["-jittered_samples", "4", "-seed", "1"]),
    ];
    for (out, extra) in runs {
        let o = course(&d, "24", out, extra);
        assert!(o.status.success(), "{extra:?}: {}", stderr(&o));
    }
    assert_eq!(
        bytes(&d, "a.png"),
        bytes(&d, "b.png"),
        "same line, same image"
    );
    assert_eq!(
        bytes(&d, "a.png"),
        bytes(&d, "c.png"),
        "the default seed is 6837"
    );
    assert_ne!(
        bytes(&d, "a.png"),
        bytes(&d, "d.png"),
        "another seed, another image"
    );
    assert_ne!(
        bytes(&d, "d.png"),
        bytes(&d, "e.png"),
        "jittered is not random"
    );
}

#[test]
fn render_spells_the_flags_long_and_gives_the_same_bytes() {
    let d = common::temp_dir("samples", "long");
    let s = scene();
    let o = course(
        &d,
        "20",
        "a.png",
        &[
            "-jittered_samples",
            "9",
            "-tent_filter",
            "1.5",
            "-seed",
            "3",
            "-render_samples",
            "as.png",
            "4",
            "-render_filter",
            "af.png",
            "5",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let o = tracelab(
        &[
            "render",
            &s,
            "--size",
            "20",
            "20",
            "-o",
            "b.png",
            "--samples",
            "9",
            "--sampler",
            "jittered",
            "--tent-filter",
            "1.5",
            "--seed",
            "3",
            "--render-samples",
            "bs.png",
            "4",
            "--render-filter",
            "bf.png",
            "5",
        ],
        &d,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    for (a, b) in [
        ("a.png", "b.png"),
        ("as.png", "bs.png"),
        ("af.png", "bf.png"),
    ] {
        assert_eq!(bytes(&d, a), bytes(&d, b), "{a} vs {b}");
    }
    let pic = image::open(d.join("as.png")).expect("as.png").to_rgb8();
    assert_eq!(pic.dimensions(), (80, 80));
    let pic = image::open(d.join("af.png")).expect("af.png").to_rgb8();
    assert_eq!(pic.dimensions(), (101, 101));
    // The pictures alone, with no colour image.
    let o = tracelab(
        &[
            "render",
            &s,
            "--size",
            "9",
            "9",
            "--render-filter",
            "f.png",
            "20",
        ],
        &d,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(d.join("f.png").is_file());
}

#[test]
fn hostile_values_are_usage_errors_naming_the_flag_and_write_nothing() {
    let d = common::temp_dir("samples", "hostile");
    let cases: Vec<(&str, Vec<&str>, &str)> = vec![
        ("16", vec!["-uniform_samples", "0"], "-uniform_samples"),
        ("16", vec!["-uniform_samples", "-1"], "-uniform_samples"),
        ("16", vec!["-uniform_samples", "8"], "not a square"),
        ("16", vec!["-jittered_samples", "2"], "-jittered_samples 2"),
        ("16", vec!["-uniform_samples", "4.0"], "-uniform_samples"),
        (
            "16",
            vec!["-random_samples", "65537"],
            "-random_samples 65537",
        ),
        (
            "16",
            vec!["-random_samples", "4294967296"],
            "-random_samples",
        ),
        ("16", vec!["-random_samples", "nan"], "-random_samples"),
        ("16", vec!["-random_samples", ""], "-random_samples"),
        (
            "16",
            vec!["-random_samples"],
            "-random_samples needs a value",
        ),
        ("16", vec!["-box_filter", "0"], "-box_filter"),
        ("16", vec!["-box_filter", "-0"], "-box_filter"),
        ("16", vec!["-box_filter", "-1"], "-box_filter"),
        ("16", vec!["-tent_filter", "nan"], "-tent_filter"),
        ("16", vec!["-tent_filter", "inf"], "-tent_filter"),
        ("16", vec!["-tent_filter", "1e39"], "-tent_filter"),
        ("16", vec!["-box_filter", "64.5"], "-box_filter"),
        ("16", vec!["-gaussian_filter", "33"], "-gaussian_filter"),
        ("16", vec!["-gaussian_filter", ""], "-gaussian_filter"),
        ("16", vec!["-random_samples", "4", "-seed", "-1"], "-seed"),
        (
            "16",
            vec!["-random_samples", "4", "-seed", "18446744073709551616"],
            "-seed",
        ),
        (
            "16",
            vec!["-seed", "3"],
            "-seed only changes random and jittered",
        ),
        (
            "16",
            vec!["-uniform_samples", "4", "-seed", "3"],
            "-seed only",
        ),
        (
            "16",
            vec!["-random_samples", "4", "-uniform_samples", "4"],
            "-random_samples already chose",
        ),
        (
            "16",
            vec!["-box_filter", "1", "-tent_filter", "1"],
            "-box_filter already chose",
        ),
        (
            "16",
            vec!["-render_samples", "s.png", "0"],
            "-render_samples zoom",
        ),
        (
            "16",
            vec!["-render_samples", "s.png", "-1"],
            "-render_samples zoom",
        ),
        (
            "16",
            vec!["-render_samples", "s.png", "4294967296"],
            "-render_samples zoom",
        ),
        (
            "16",
            vec!["-render_samples", "s.png", "100000"],
            "-render_samples zoom 100000",
        ),
        (
            "16",
            vec!["-render_filter", "f.png", "1024"],
            "-render_filter zoom 1024",
        ),
        (
            "16",
            vec!["-render_filter", "f.png"],
            "-render_filter FILE needs a value",
        ),
        // Samples in all, and filter work, are capped before any allocation.
        ("8192", vec!["-random_samples", "4"], "67108864 are allowed"),
        (
            "1024",
            vec!["-random_samples", "1024", "-box_filter", "1"],
            "at most 67108864",
        ),
        (
            "256",
            vec!["-random_samples", "256", "-gaussian_filter", "30"],
            "filter weights",
        ),
        // Combinations tracelab does not make.
        (
            "16",
            vec!["-random_samples", "4", "-normals", "n.png"],
            "-normals with -random_samples",
        ),
        (
            "16",
            vec!["-box_filter", "1", "-depth", "0", "1", "n.png"],
            "-depth with -box_filter",
        ),
        (
            "16",
            vec!["-uniform_samples", "4", "-stats"],
            "-stats with -uniform_samples",
        ),
        (
            "16",
            vec![
                "-grid",
                "2",
                "2",
                "2",
                "-visualize_grid",
                "-box_filter",
                "1",
            ],
            "-visualize_grid with -box_filter",
        ),
    ];
    for (size, extra, want) in cases {
        let o = course(&d, size, "out.png", &extra);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {e}");
        assert!(e.contains(want), "{extra:?}: expected {want:?} in: {e}");
        assert!(!e.contains("panicked"), "{extra:?}: {e}");
        for f in ["out.png", "s.png", "f.png", "n.png"] {
            assert!(!d.join(f).exists(), "{extra:?} wrote {f}");
        }
    }
    // `render`'s spellings.
    let s = scene();
    for (extra, want) in [
        (
            vec!["--samples", "8", "--sampler", "jittered"],
            "not a square",
        ),
        (vec!["--samples", "0"], "--samples"),
        (vec!["--sampler", "random"], "--samples"),
        (vec!["--gaussian-filter", "nan"], "--gaussian-filter"),
        (
            vec!["--box-filter", "1", "--tent-filter", "1"],
            "--tent-filter",
        ),
        (vec!["--seed", "1"], "--seed only"),
        (
            vec!["--render-samples", "s.png", "0"],
            "--render-samples zoom",
        ),
        (
            vec!["--samples", "4", "--normals", "n.png"],
            "--normals with --samples",
        ),
    ] {
        let mut args = vec!["render", s.as_str(), "--size", "16", "16", "-o", "out.png"];
        args.extend(&extra);
        let o = tracelab(&args, &d);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {e}");
        assert!(e.contains(want), "{extra:?}: expected {want:?} in: {e}");
        assert!(!d.join("out.png").exists(), "{extra:?} wrote out.png");
    }
}

#[test]
fn the_pictures_follow_the_output_policy() {
    let d = common::temp_dir("samples", "policy");
    let s = scene();
    let before = std::fs::read(&s).expect("scene");
    // Never the scene, never the same file as the colour image, a trailing slash is a folder.
    for (extra, want) in [
        (vec!["-render_samples", s.as_str(), "4"], ""),
        (vec!["-render_filter", "out.png", "4"], ""),
        (vec!["-render_samples", "pics/", "4"], ""),
        (vec!["-render_filter", "f.jpg", "4"], "unknown image format"),
    ] {
        let o = course(&d, "8", "out.png", &extra);
        let e = stderr(&o);
        assert_ne!(o.status.code(), Some(0), "{extra:?}: {e}");
        assert!(e.contains(want), "{extra:?}: {e}");
        assert!(!d.join("out.png").exists(), "{extra:?} wrote out.png");
    }
    assert_eq!(
        std::fs::read(&s).expect("scene"),
        before,
        "the scene changed"
    );
    // `diff` judges the colour image only: a line with a picture is refused, not half-judged.
    let o = course(&d, "8", "mine.png", &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = tracelab(
        &[
            "diff",
            "mine.png",
            "--",
            "-input",
            &s,
            "-size",
            "8",
            "8",
            "-output",
            "mine.png",
            "-render_samples",
            "s.png",
            "4",
        ],
        &d,
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("-render_samples"), "{}", stderr(&o));
    assert!(!d.join("s.png").exists());
}
