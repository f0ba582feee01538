//! `tracelab animate`: every frame is the single render of the scene with that frame's value
//! written into the file, and the animated PNG holds the same frames.

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
    let d = std::env::temp_dir().join(format!("tracelab-animate-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

/// A squashed sphere moved along x by VALUE: `Translate VALUE 0 0` is op 0 of the Transform.
const SCENE: &str = "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 5 }
Lights { numLights 1 DirectionalLight { direction -0.5 -0.5 -1 color 0.9 0.9 0.9 } }
Background { color 0.1 0.1 0.1 ambientLight 0.1 0.1 0.1 }
Materials { numMaterials 1 Material { diffuseColor 0.9 0.3 0.2 } }
Group { numObjects 1 MaterialIndex 0
  Transform { Translate VALUE 0 0 Scale 1.5 0.6 1 Sphere { center 0 0 0 radius 1 } } }
";

fn read(p: &Path) -> image::RgbImage {
    image::open(p)
        .unwrap_or_else(|e| panic!("{}: {e}", p.display()))
        .to_rgb8()
}

/// The Transform's node id, as `tracelab inspect --json` reports it on the path.
fn transform_id(dir: &Path) -> String {
    std::fs::write(dir.join("probe.txt"), SCENE.replace("VALUE", "0")).expect("write");
    let o = tracelab(
        &[
            "inspect",
            "probe.txt",
            "--size",
            "32",
            "24",
            "--pixel",
            "16",
            "12",
            "--json",
        ],
        dir,
    );
    assert!(o.status.success());
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
    let step = &j["hit"]["path"][1];
    assert_eq!(step["node"]["kind"], "Transform");
    step["node"]["id"].to_string()
}

#[test]
fn every_frame_is_the_single_render_of_its_value_and_the_apng_holds_them() {
    let dir = temp_dir("frames");
    let id = transform_id(&dir);
    std::fs::write(dir.join("anim.txt"), SCENE.replace("VALUE", "0")).expect("write");
    let o = tracelab(
        &[
            "animate",
            "anim.txt",
            "--size",
            "32",
            "24",
            "--node",
            &id,
            "--op",
            "0",
            "--component",
            "0",
            "--from",
            "-1",
            "--to",
            "1",
            "--frames",
            "5",
            "--out",
            "out",
        ],
        &dir,
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut seq = Vec::new();
    for (k, value) in ["-1", "-0.5", "0", "0.5", "1"].iter().enumerate() {
        let scene = format!("v{k}.txt");
        std::fs::write(dir.join(&scene), SCENE.replace("VALUE", value)).expect("write");
        let single = format!("single{k}.png");
        assert!(
            tracelab(
                &["render", &scene, "--size", "32", "24", "--output", &single],
                &dir
            )
            .status
            .success()
        );
        let frame = read(&dir.join(format!("out/frame_{k:04}.png")));
        assert_eq!(
            frame,
            read(&dir.join(&single)),
            "frame {k} (Translate {value})"
        );
        seq.push(frame);
    }
    assert_ne!(seq[0], seq[4], "the sphere moved");
    let file = std::fs::File::open(dir.join("out/frame.apng.png")).expect("apng");
    let decoder = image::codecs::png::PngDecoder::new(std::io::BufReader::new(file)).expect("png");
    assert!(decoder.is_apng().expect("apng header"));
    let frames = decoder
        .apng()
        .expect("apng")
        .into_frames()
        .collect_frames()
        .expect("frames");
    assert_eq!(frames.len(), 5);
    for (f, s) in frames.iter().zip(&seq) {
        assert_eq!(
            &image::DynamicImage::ImageRgba8(f.buffer().clone()).to_rgb8(),
            s
        );
    }
}

#[test]
fn a_compare_animation_puts_both_normal_rules_side_by_side() {
    let dir = temp_dir("compare");
    let id = transform_id(&dir);
    std::fs::write(dir.join("anim.txt"), SCENE.replace("VALUE", "0")).expect("write");
    // Op 1, component 1: Scale y, swept from 0.6 (the file's value) to 1.5.
    let o = tracelab(
        &[
            "animate",
            "anim.txt",
            "--size",
            "32",
            "24",
            "--node",
            &id,
            "--op",
            "1",
            "--component",
            "1",
            "--from",
            "0.6",
            "--to",
            "1.5",
            "--frames",
            "2",
            "--compare",
            "--out",
            "out",
        ],
        &dir,
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let frame = read(&dir.join("out/frame_0000.png"));
    assert_eq!(frame.dimensions(), (64, 24));
    std::fs::write(dir.join("s.txt"), SCENE.replace("VALUE", "0")).expect("write");
    assert!(
        tracelab(
            &["render", "s.txt", "--size", "32", "24", "--output", "c.png"],
            &dir
        )
        .status
        .success()
    );
    assert!(
        tracelab(
            &[
                "render",
                "s.txt",
                "--size",
                "32",
                "24",
                "--output",
                "i.png",
                "--normal-transform",
                "incorrect"
            ],
            &dir
        )
        .status
        .success()
    );
    let left = image::imageops::crop_imm(&frame, 0, 0, 32, 24).to_image();
    let right = image::imageops::crop_imm(&frame, 32, 0, 32, 24).to_image();
    assert_eq!(left, read(&dir.join("c.png")));
    assert_eq!(right, read(&dir.join("i.png")));
    assert_ne!(left, right, "the rules differ on a squashed sphere");
}

#[test]
fn a_sweep_through_a_refused_value_writes_nothing_and_says_which_frame() {
    let dir = temp_dir("refused");
    let id = transform_id(&dir);
    std::fs::write(dir.join("anim.txt"), SCENE.replace("VALUE", "0")).expect("write");
    // Scale x from 1 to −1 passes through 0 at the middle frame: a flat, singular transform.
    let o = tracelab(
        &[
            "animate",
            "anim.txt",
            "--node",
            &id,
            "--op",
            "1",
            "--component",
            "0",
            "--from",
            "1",
            "--to",
            "-1",
            "--frames",
            "3",
            "--out",
            "out",
        ],
        &dir,
    );
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("frame 1 (value 0)"), "{err}");
    assert!(!dir.join("out").exists(), "nothing written");
    let o = tracelab(
        &[
            "animate", "anim.txt", "--node", "999", "--from", "0", "--to", "1", "--out", "out",
        ],
        &dir,
    );
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("node #999 does not exist"));
}

/// `animate ARGS… --node ID --from FROM --to TO --out out` in `dir` on `anim.txt`.
fn animate(dir: &Path, id: &str, from: &str, to: &str, more: &[&str]) -> Output {
    std::fs::write(dir.join("anim.txt"), SCENE.replace("VALUE", "0")).expect("write");
    let mut args = vec![
        "animate", "anim.txt", "--size", "8", "6", "--node", id, "--from", from, "--to", to,
        "--frames", "3", "--out", "out",
    ];
    args.extend(more);
    tracelab(&args, dir)
}

#[test]
fn a_stem_with_a_folder_part_is_a_usage_error_and_nothing_is_written() {
    let dir = temp_dir("stem");
    let id = transform_id(&dir);
    let abs = dir.join("abs").display().to_string();
    for stem in ["../x", "a/b", "..", ".", "", abs.as_str(), "x\u{7}"] {
        let o = animate(&dir, &id, "0", "1", &["--stem", stem]);
        assert_eq!(o.status.code(), Some(2), "--stem {stem:?}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains("--stem"), "{err}");
    }
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .expect("list")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["anim.txt", "probe.txt"], "nothing written anywhere");
}

#[test]
fn a_sweep_across_most_of_f32s_range_has_finite_values() {
    let dir = temp_dir("wide-sweep");
    let id = transform_id(&dir);
    // -3e38 to 3e38: the span (6e38) overflows f32; the middle frame's value is 0.
    let o = animate(&dir, &id, "-3e38", "3e38", &[]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!err.contains("NaN"), "{err}");
    assert!(o.status.success(), "{err}");
    // The middle frame is the file's own scene (Translate 0).
    assert!(
        tracelab(
            &[
                "render", "anim.txt", "--size", "8", "6", "--output", "mid.png"
            ],
            &dir
        )
        .status
        .success()
    );
    assert_eq!(
        read(&dir.join("out/frame_0001.png")),
        read(&dir.join("mid.png"))
    );
}

#[test]
fn a_compare_animation_wider_than_the_side_limit_is_refused_before_anything() {
    let dir = temp_dir("compare-wide");
    let id = transform_id(&dir);
    std::fs::write(dir.join("anim.txt"), SCENE.replace("VALUE", "0")).expect("write");
    // 10000 a side is allowed; the compare view would be 20000 wide.
    let o = tracelab(
        &[
            "animate",
            "anim.txt",
            "--size",
            "10000",
            "1",
            "--node",
            &id,
            "--from",
            "0",
            "--to",
            "1",
            "--compare",
            "--out",
            "out",
        ],
        &dir,
    );
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("20000x1 is too large"), "{err}");
    assert!(err.contains("compare view"), "{err}");
    assert!(!dir.join("out").exists());
}

#[cfg(unix)]
#[test]
fn a_frame_name_that_is_a_symlink_or_the_scene_is_refused_before_rendering() {
    let dir = temp_dir("frame-link");
    let id = transform_id(&dir);
    std::fs::create_dir(dir.join("out")).expect("mkdir");
    std::fs::write(dir.join("grades.csv"), "keep").expect("write");
    std::os::unix::fs::symlink("../grades.csv", dir.join("out/frame_0001.png")).expect("link");
    let o = animate(&dir, &id, "0", "1", &[]);
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("frame_0001.png: not written: it is a symbolic link"),
        "{err}"
    );
    assert_eq!(
        std::fs::read(dir.join("grades.csv")).expect("read"),
        b"keep"
    );
    assert!(
        !dir.join("out/frame_0000.png").exists(),
        "refused before any frame"
    );
    // The scene itself at an invented name (`--out . --stem anim` would not name it, but a
    // scene called frame.apng.png is named by the animated PNG).
    let scene = dir.join("out2/frame.apng.png");
    std::fs::create_dir(dir.join("out2")).expect("mkdir");
    std::fs::write(&scene, SCENE.replace("VALUE", "0")).expect("write");
    let o = tracelab(
        &[
            "animate",
            "out2/frame.apng.png",
            "--size",
            "8",
            "6",
            "--node",
            &id,
            "--from",
            "0",
            "--to",
            "1",
            "--out",
            "out2",
        ],
        &dir,
    );
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("on the command line"), "{err}");
    assert_eq!(
        std::fs::read_to_string(&scene).expect("read"),
        SCENE.replace("VALUE", "0")
    );
}
