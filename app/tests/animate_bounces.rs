//! `tracelab animate --bounces-from A --bounces-to B`: a frame per bounce count, each the
//! course line's render at that count, the animated PNG holding the same frames; hostile
//! values and a mix with the op sweep's flags are usage errors (exit 2) that name the flag
//! and write nothing.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use image::AnimationDecoder;

fn tracelab(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tracelab"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run tracelab")
}

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!(
        "tracelab-animate-bounces-{}-{name}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

fn read(p: &Path) -> image::RgbImage {
    image::open(p)
        .unwrap_or_else(|e| panic!("{}: {e}", p.display()))
        .to_rgb8()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn mirrors() -> String {
    concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../scenes/lecture/bounces_mirrors.txt"
    )
    .to_string()
}

#[test]
fn every_frame_is_the_course_render_at_its_bounce_count_and_the_apng_holds_them() {
    let dir = temp_dir("frames");
    let scene = mirrors();
    let o = tracelab(
        &[
            "animate",
            &scene,
            "--size",
            "40",
            "30",
            "--bounces-from",
            "0",
            "--bounces-to",
            "3",
            "--shadows",
            "--shade-back",
            "--weight",
            "0.01",
            "--out",
            "out",
        ],
        &dir,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let mut names: Vec<String> = std::fs::read_dir(dir.join("out"))
        .expect("out")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "frame.apng.png",
            "frame_0000.png",
            "frame_0001.png",
            "frame_0002.png",
            "frame_0003.png"
        ]
    );
    let mut seq = Vec::new();
    for k in 0..4 {
        let single = format!("single{k}.png");
        let bounces = k.to_string();
        let course = tracelab(
            &[
                "-input",
                &scene,
                "-size",
                "40",
                "30",
                "-output",
                &single,
                "-shadows",
                "-shade_back",
                "-bounces",
                &bounces,
                "-weight",
                "0.01",
            ],
            &dir,
        );
        assert!(course.status.success(), "{}", stderr(&course));
        let frame_file = dir.join(format!("out/frame_{k:04}.png"));
        let frame = read(&frame_file);
        assert_eq!(frame, read(&dir.join(&single)), "frame {k} (-bounces {k})");
        // Encoded alike too: the same file, byte for byte.
        assert!(
            std::fs::read(&frame_file).expect("frame")
                == std::fs::read(dir.join(&single)).expect("single"),
            "frame {k}: the PNG files differ"
        );
        seq.push(frame);
    }
    for k in 1..4 {
        assert_ne!(seq[k], seq[k - 1], "-bounces {k} changed nothing");
    }
    let file = std::fs::File::open(dir.join("out/frame.apng.png")).expect("apng");
    let decoder = image::codecs::png::PngDecoder::new(std::io::BufReader::new(file)).expect("png");
    assert!(decoder.is_apng().expect("apng header"));
    let frames = decoder
        .apng()
        .expect("apng")
        .into_frames()
        .collect_frames()
        .expect("frames");
    assert_eq!(frames.len(), 4);
    for (f, s) in frames.iter().zip(&seq) {
        assert_eq!(
            &image::DynamicImage::ImageRgba8(f.buffer().clone()).to_rgb8(),
            s
        );
    }
}

/// A sphere that both reflects and refracts: the rays double at every bounce.
const DOUBLING: &str = "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 5 }
Lights { numLights 1 DirectionalLight { direction -0.5 -0.5 -1 color 0.9 0.9 0.9 } }
Background { color 0.1 0.1 0.1 ambientLight 0.1 0.1 0.1 }
Materials { numMaterials 1 PhongMaterial { diffuseColor 0.1 0.1 0.1
  reflectiveColor 0.5 0.5 0.5 transparentColor 0.5 0.5 0.5 indexOfRefraction 1.5 } }
Group { numObjects 1 MaterialIndex 0 Sphere { center 0 0 0 radius 1 } }
";

#[test]
fn hostile_bounce_sweeps_are_usage_errors_naming_the_flag_and_write_nothing() {
    let dir = temp_dir("hostile");
    std::fs::write(dir.join("glass.txt"), DOUBLING).expect("write");
    let cases: &[(&[&str], &str)] = &[
        (
            &["--bounces-from", "3", "--bounces-to", "1"],
            "--bounces-from 3",
        ),
        (
            &["--bounces-from", "0", "--bounces-to", "101"],
            "--bounces-to 101",
        ),
        (
            &["--bounces-from", "101", "--bounces-to", "101"],
            "--bounces-from 101",
        ),
        (
            &["--bounces-from", "0", "--bounces-to", "4294967295"],
            "--bounces-to",
        ),
        (
            &["--bounces-from", "0", "--bounces-to", "4294967296"],
            "--bounces-to",
        ),
        (
            &["--bounces-from", "-1", "--bounces-to", "2"],
            "--bounces-from",
        ),
        (
            &["--bounces-from", "nan", "--bounces-to", "2"],
            "--bounces-from",
        ),
        (
            &["--bounces-from", "0", "--bounces-to", "1e39"],
            "--bounces-to",
        ),
        (
            &["--bounces-from", "", "--bounces-to", "2"],
            "--bounces-from",
        ),
        (&["--bounces-from", "0"], "--bounces-to"),
        (&["--bounces-to", "2"], "--bounces-from"),
        (
            &["--bounces-from", "0", "--bounces-to", "2", "--node", "1"],
            "--node",
        ),
        (
            &["--bounces-from", "0", "--bounces-to", "2", "--from", "0"],
            "--from",
        ),
        (
            &["--bounces-from", "0", "--bounces-to", "2", "--frames", "3"],
            "--frames",
        ),
        (
            &["--bounces-from", "0", "--bounces-to", "2", "--op", "0"],
            "--op",
        ),
        (
            &[
                "--bounces-from",
                "0",
                "--bounces-to",
                "2",
                "--weight",
                "nan",
            ],
            "--weight",
        ),
        (
            &[
                "--bounces-from",
                "0",
                "--bounces-to",
                "2",
                "--weight",
                "inf",
            ],
            "--weight",
        ),
        (&["--node", "1", "--from", "0"], "--bounces-from"),
        // Rays that double at every bounce: 2^21 - 2 of them a pixel at the last frame.
        (
            &["--bounces-from", "0", "--bounces-to", "20"],
            "--bounces-to 20",
        ),
    ];
    for (flags, named) in cases {
        let mut args = vec!["animate", "glass.txt", "--size", "8", "8", "--out", "out"];
        args.extend_from_slice(flags);
        let o = tracelab(&args, &dir);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{flags:?}: {err}");
        assert!(err.contains(named), "{flags:?} should name {named}: {err}");
        assert!(!err.contains("panicked"), "{flags:?}: {err}");
        assert!(
            !dir.join("out").exists(),
            "{flags:?}: something was written"
        );
    }
    // The positive control: the cap's own count is animated.
    let o = tracelab(
        &[
            "animate",
            "glass.txt",
            "--size",
            "8",
            "8",
            "--out",
            "out",
            "--bounces-from",
            "14",
            "--bounces-to",
            "15",
        ],
        &dir,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(dir.join("out/frame_0001.png").is_file());
    assert!(dir.join("out/frame.apng.png").is_file());
}
