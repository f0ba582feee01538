//! The output policy (`app/src/io/output.rs`) as a user meets it: no command writes a file it
//! reads or that its arguments name, invented names (diff's heat maps) never follow a
//! symlink, a trailing slash means a folder, output folders are checked before the work,
//! and `diff` reads its images from their headers first, from pipes too.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

mod common;
use common::repo;
use common::tracelab;

fn temp_dir(name: &str) -> PathBuf {
    common::temp_dir("output", name)
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).to_string()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).to_string()
}

fn read(p: &Path) -> Vec<u8> {
    std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// The sheared sphere copied into `dir` as `s.txt`, rendered 50×40 to `good.png` (colour)
/// and `good_n.png` (normals).
fn student_dir(name: &str) -> PathBuf {
    let d = temp_dir(name);
    std::fs::copy(repo().join("scenes/sheared_sphere.txt"), d.join("s.txt")).expect("copy");
    let o = tracelab(
        &[
            "-input",
            "s.txt",
            "-size",
            "50",
            "40",
            "-output",
            "good.png",
            "-normals",
            "good_n.png",
        ],
        &d,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    d
}

fn diff(dir: &Path, image: &str, line: &str) -> Output {
    let mut args = vec!["diff", image, "--"];
    args.extend(line.split(' '));
    tracelab(&args, dir)
}

#[test]
fn diff_never_writes_over_an_image_the_course_line_names() {
    let d = student_dir("diff-named");
    std::fs::copy(d.join("good.png"), d.join("a.png")).expect("copy");
    // The student's normals are called a.diff.png: the colour heat map's natural name.
    std::fs::copy(d.join("good_n.png"), d.join("a.diff.png")).expect("copy");
    let normals = read(&d.join("a.diff.png"));
    let o = diff(
        &d,
        "a.png",
        "-input s.txt -size 50 40 -output x.png -normals a.diff.png",
    );
    let out = stdout(&o);
    assert_eq!(o.status.code(), Some(0), "{out}{}", stderr(&o));
    assert_eq!(read(&d.join("a.diff.png")), normals, "normals overwritten");
    assert!(
        out.contains("normals a.diff.png: 0 of 2,000 pixels off"),
        "the normals were read before any heat map:\n{out}"
    );
    assert!(
        out.contains("heat map a.diff-2.png (not a.diff.png: it is named on the command line)"),
        "{out}"
    );
    assert!(d.join("a.diff-2.png").is_file());
    // -output is promised never to be written, whatever its name.
    std::fs::write(d.join("b.diff.png"), "promised").expect("write");
    std::fs::copy(d.join("good.png"), d.join("b.png")).expect("copy");
    let o = diff(&d, "b.png", "-input s.txt -size 50 40 -output b.diff.png");
    assert_eq!(o.status.code(), Some(0), "{}{}", stdout(&o), stderr(&o));
    assert_eq!(read(&d.join("b.diff.png")), b"promised");
    assert!(
        stdout(&o).contains("heat map b.diff-2.png"),
        "{}",
        stdout(&o)
    );
}

#[cfg(unix)]
#[test]
fn diff_heat_map_never_follows_a_planted_symlink() {
    let top = temp_dir("diff-symlink");
    std::fs::write(top.join("grades.csv"), "alice,A\n").expect("write");
    let d = top.join("student");
    std::fs::create_dir(&d).expect("mkdir");
    std::fs::copy(repo().join("scenes/sheared_sphere.txt"), d.join("s.txt")).expect("copy");
    let o = tracelab(
        &[
            "-input", "s.txt", "-size", "50", "40", "-output", "mine.png",
        ],
        &d,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    std::os::unix::fs::symlink("../grades.csv", d.join("mine.diff.png")).expect("plant");
    let o = diff(&d, "mine.png", "-input s.txt -size 50 40 -output x.png");
    let out = stdout(&o);
    assert_eq!(o.status.code(), Some(0), "{out}{}", stderr(&o));
    assert_eq!(read(&top.join("grades.csv")), b"alice,A\n");
    assert!(
        std::fs::symlink_metadata(d.join("mine.diff.png"))
            .expect("meta")
            .file_type()
            .is_symlink()
    );
    assert!(
        out.contains("heat map mine.diff-2.png (not mine.diff.png: it is a symbolic link)"),
        "{out}"
    );
    image::open(d.join("mine.diff-2.png")).expect("the heat map");
}

#[test]
fn diff_prints_its_verdict_when_the_heat_map_cannot_be_written() {
    let d = student_dir("diff-no-map");
    std::fs::copy(d.join("good.png"), d.join("m.png")).expect("copy");
    // Every name the heat map could take is a folder.
    std::fs::create_dir(d.join("m.diff.png")).expect("mkdir");
    for k in 2..=99 {
        std::fs::create_dir(d.join(format!("m.diff-{k}.png"))).expect("mkdir");
    }
    let o = diff(&d, "m.png", "-input s.txt -size 50 40 -output x.png");
    assert_eq!(o.status.code(), Some(4), "{}{}", stdout(&o), stderr(&o));
    assert!(
        stdout(&o).contains("colour m.png: 0 of 2,000 pixels off")
            && stdout(&o).contains("matches; heat map not written"),
        "{}",
        stdout(&o)
    );
    assert!(
        stderr(&o).contains("m.diff.png") && stderr(&o).contains("it is a folder"),
        "{}",
        stderr(&o)
    );
    // A wrong image that cannot have its heat map: 5, and its verdict.
    let o = tracelab(
        &[
            "-input",
            "s.txt",
            "-size",
            "50",
            "40",
            "-output",
            "m.png",
            "-normal_transform",
            "incorrect",
        ],
        &d,
    );
    assert!(o.status.success());
    let o = diff(&d, "m.png", "-input s.txt -size 50 40 -output x.png");
    assert_eq!(o.status.code(), Some(5), "{}{}", stdout(&o), stderr(&o));
    assert!(
        stdout(&o).contains("does not match; heat map not written"),
        "{}",
        stdout(&o)
    );
}

/// A valid 13000×13000 all-black PNG: 507 MB of pixels, a few hundred KB of file.
fn png_bomb(path: &Path) {
    let (w, h) = (13_000u32, 13_000u32);
    let file = std::io::BufWriter::new(std::fs::File::create(path).expect("create"));
    let mut enc = png::Encoder::new(file, w, h);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    enc.set_compression(png::Compression::Balanced);
    let mut writer = enc.write_header().expect("header");
    let mut stream = writer.stream_writer().expect("stream");
    let row = vec![0u8; w as usize * 3];
    for _ in 0..h {
        std::io::Write::write_all(&mut stream, &row).expect("row");
    }
    stream.finish().expect("finish");
}

#[cfg(unix)]
#[test]
fn diff_judges_a_png_bomb_by_its_header_under_300_mb() {
    use std::os::unix::process::ExitStatusExt;
    let d = student_dir("diff-bomb");
    png_bomb(&d.join("bomb.png"));
    assert!(std::fs::metadata(d.join("bomb.png")).expect("meta").len() < 2_000_000);
    let run = |line: &str| {
        Command::new("bash")
            .arg("-c")
            .arg(format!(
                "ulimit -v 300000; exec \"$0\" diff bomb.png -- {line}"
            ))
            .arg(env!("CARGO_BIN_EXE_tracelab"))
            .current_dir(&d)
            .env("RAYON_NUM_THREADS", "2")
            .env("MALLOC_ARENA_MAX", "2")
            .output()
            .expect("run bash")
    };
    let o = run("-input s.txt -size 50 40 -output x.png");
    assert_eq!(
        o.status.signal(),
        None,
        "killed by a signal: {}",
        stderr(&o)
    );
    assert_eq!(o.status.code(), Some(3), "{}{}", stdout(&o), stderr(&o));
    assert!(
        stdout(&o).contains("size 13000×13000, but the command line asks for 50×40"),
        "{}",
        stdout(&o)
    );
    assert!(!d.join("bomb.diff.png").exists());
}

#[cfg(unix)]
#[test]
fn diff_reads_an_image_from_a_fifo() {
    let d = student_dir("diff-fifo");
    let ok = Command::new("mkfifo")
        .arg(d.join("pipe.png"))
        .status()
        .is_ok_and(|s| s.success());
    assert!(ok, "mkfifo");
    let mut writer = Command::new("sh")
        .args(["-c", "cat good.png > pipe.png"])
        .current_dir(&d)
        .spawn()
        .expect("writer");
    let o = diff(&d, "pipe.png", "-input s.txt -size 50 40 -output x.png");
    let _ = writer.kill();
    let _ = writer.wait();
    assert!(!stderr(&o).contains("Illegal seek"), "{}", stderr(&o));
    assert_eq!(o.status.code(), Some(0), "{}{}", stdout(&o), stderr(&o));
    assert!(
        stdout(&o).contains("colour pipe.png: 0 of 2,000 pixels off"),
        "{}",
        stdout(&o)
    );
}

#[cfg(unix)]
#[test]
fn diff_reads_no_more_than_an_image_of_the_asked_size_could_need() {
    let d = student_dir("diff-cap");
    // Larger than any 50×40 file (12 bytes a pixel and a MiB), but its header says
    // 700×700: that is the verdict.
    image::RgbImage::new(700, 700)
        .save(d.join("big.bmp"))
        .expect("save");
    assert!(std::fs::metadata(d.join("big.bmp")).expect("meta").len() > 50 * 40 * 12 + (1 << 20));
    let o = diff(&d, "big.bmp", "-input s.txt -size 50 40 -output x.png");
    assert_eq!(o.status.code(), Some(3), "{}{}", stdout(&o), stderr(&o));
    assert!(
        stdout(&o).contains("size 700×700, but the command line asks for 50×40"),
        "{}",
        stdout(&o)
    );
    // A pipe that never ends is read up to that cap, then refused.
    let ok = Command::new("mkfifo")
        .arg(d.join("endless.png"))
        .status()
        .is_ok_and(|s| s.success());
    assert!(ok, "mkfifo");
    let mut writer = Command::new("sh")
        .args(["-c", "yes > endless.png"])
        .current_dir(&d)
        .spawn()
        .expect("writer");
    let o = diff(&d, "endless.png", "-input s.txt -size 50 40 -output x.png");
    let _ = writer.kill();
    let _ = writer.wait();
    assert_eq!(o.status.code(), Some(1), "{}{}", stdout(&o), stderr(&o));
    assert!(
        stderr(&o).contains("endless.png: cannot read image: more than 1072576 bytes"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn diff_with_the_course_line_not_after_dashes_says_where_it_goes() {
    let d = student_dir("diff-dashes");
    let o = tracelab(
        &["diff", "good.png", "-input", "s.txt", "-size", "50", "40"],
        &d,
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("the course's command line goes after `--`"),
        "{}",
        stderr(&o)
    );
    assert!(!stderr(&o).contains("unknown option"), "{}", stderr(&o));
}

#[test]
fn an_output_with_a_trailing_slash_is_a_folder_never_a_file() {
    let d = temp_dir("slash");
    for args in [
        &["render", "--size", "4", "4", "--output", "out.png/"][..],
        &["render", "--size", "4", "4", "--normals", "out.png/."][..],
        &["-input", "s.txt", "-size", "4", "4", "-output", "out.png/"][..],
    ] {
        let o = tracelab(args, &d);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains("names a folder"), "{}", stderr(&o));
        assert!(!d.join("out.png").exists(), "{args:?} made out.png");
    }
    // An existing folder is not replaced either.
    std::fs::create_dir(d.join("dir.png")).expect("mkdir");
    let o = tracelab(&["render", "--size", "4", "4", "-o", "dir.png"], &d);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(d.join("dir.png").is_dir());
}

#[test]
fn output_folders_are_checked_before_the_scene_is_read_or_rendered() {
    let d = temp_dir("folders-first");
    std::fs::write(d.join("file"), "x").expect("write");
    // The scene is missing too: the output's folder is what is reported, so it was
    // checked first.
    for (out, says) in [
        ("missing/o.png", "folder missing does not exist"),
        ("file/o.png", "file is not a folder"),
    ] {
        let o = tracelab(&["render", "absent.txt", "--size", "4", "4", "-o", out], &d);
        assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
        assert!(stderr(&o).contains(says), "{out}: {}", stderr(&o));
    }
}

#[cfg(unix)]
#[test]
fn render_never_writes_its_scene_or_a_mesh_by_any_name() {
    let d = temp_dir("render-input");
    // A scene and a mesh whose names have image extensions.
    let scene = std::fs::read_to_string(repo().join("scenes/default.txt")).expect("read");
    std::fs::write(d.join("scene.ppm"), &scene).expect("write");
    std::fs::hard_link(d.join("scene.ppm"), d.join("hard.ppm")).expect("link");
    std::fs::copy(repo().join("assets/cube.obj"), d.join("mesh.bmp")).expect("copy");
    std::fs::write(
        d.join("m.txt"),
        "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 4 }\n\
         Background { color 0 0 0 }\n\
         Group { numObjects 1 TriangleMesh { obj_file mesh.bmp } }\n",
    )
    .expect("write");
    let mesh = read(&d.join("mesh.bmp"));
    for args in [
        &[
            "render",
            "scene.ppm",
            "--size",
            "4",
            "4",
            "-o",
            "./scene.ppm",
        ][..],
        &["render", "scene.ppm", "--size", "4", "4", "-o", "hard.ppm"][..],
        &[
            "-input",
            "scene.ppm",
            "-size",
            "4",
            "4",
            "-normals",
            "scene.ppm",
        ][..],
        &["render", "m.txt", "--size", "4", "4", "-o", "mesh.bmp"][..],
    ] {
        let o = tracelab(args, &d);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(
            stderr(&o).contains("names an input of this command"),
            "{}",
            stderr(&o)
        );
    }
    assert_eq!(
        std::fs::read_to_string(d.join("scene.ppm")).expect("read"),
        scene
    );
    assert_eq!(read(&d.join("mesh.bmp")), mesh);
    let o = tracelab(&["render", "m.txt", "--size", "4", "4", "-o", "ok.bmp"], &d);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn two_outputs_of_one_render_naming_one_file_are_a_usage_error() {
    let d = temp_dir("twice");
    for args in [
        &[
            "render",
            "--size",
            "4",
            "4",
            "-o",
            "a.png",
            "--normals",
            "./a.png",
        ][..],
        &[
            "render",
            "--size",
            "4",
            "4",
            "--normals",
            "a.png",
            "--depth",
            "0",
            "1",
            "a.png",
        ][..],
    ] {
        let o = tracelab(args, &d);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains("are the same file"), "{}", stderr(&o));
        assert!(!d.join("a.png").exists());
    }
}

#[test]
fn fmt_never_writes_over_the_scene_it_reads_or_its_mesh() {
    let d = temp_dir("fmt-input");
    let text = "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 4 }\n\
                Background { color 0 0 0 }\n\
                Group { numObjects 1 TriangleMesh { obj_file cube.obj } }\n";
    std::fs::write(d.join("s.txt"), text).expect("write");
    std::fs::copy(repo().join("assets/cube.obj"), d.join("cube.obj")).expect("copy");
    let mesh = read(&d.join("cube.obj"));
    for out in ["s.txt", "./s.txt", "cube.obj"] {
        let o = tracelab(&["fmt", "s.txt", "-o", out], &d);
        assert_eq!(o.status.code(), Some(2), "{out}: {}", stderr(&o));
    }
    assert_eq!(read(&d.join("s.txt")), text.as_bytes());
    assert_eq!(read(&d.join("cube.obj")), mesh);
    assert!(
        tracelab(&["fmt", "s.txt", "-o", "t.txt"], &d)
            .status
            .success()
    );
}
