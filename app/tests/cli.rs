//! The command line as a user meets it: help, exit codes, error messages with locations,
//! the course's flags, output formats and `fmt`.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

mod common;
use common::repo;
use common::tracelab;

fn temp_dir(name: &str) -> PathBuf {
    common::temp_dir("cli", name)
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).to_string()
}

#[test]
fn help_lists_subcommands_and_succeeds() {
    let o = tracelab(&["--help"], &repo());
    assert!(o.status.success());
    let out = String::from_utf8_lossy(&o.stdout);
    for word in ["render", "fmt", "bench", "-input"] {
        assert!(out.contains(word), "--help should mention {word}:\n{out}");
    }
    assert!(tracelab(&["render", "--help"], &repo()).status.success());
    // One line per subcommand, saying what that one does (a merge once gave `animate`
    // inspect's summary and printed inspect's whole long help in the list).
    let line = |cmd: &str| {
        out.lines()
            .find(|l| l.trim_start().starts_with(&format!("{cmd} ")))
            .unwrap_or_default()
            .to_string()
    };
    assert!(
        line("animate").contains("Sweep") && !line("animate").contains("pixel"),
        "{out}"
    );
    assert!(line("inspect").contains("pixel's story"), "{out}");
    assert!(
        !out.contains("Pixels are counted as images store them"),
        "the list shows short help only:\n{out}"
    );
}

/// The command-line build (`--no-default-features`, no `gui` feature) has no editor: with
/// no arguments, or a SCENE, it says so and how to get one, and exits 2.
#[cfg(not(feature = "gui"))]
#[test]
fn without_the_gui_feature_the_editor_is_said_not_to_be_built_in() {
    for args in [&[][..], &["scenes/default.txt"][..]] {
        let o = tracelab(args, &repo());
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
        assert!(
            e.contains("the editor is not built in") && e.contains("cargo install --path app"),
            "{args:?}: {e}"
        );
    }
}

#[test]
fn missing_scene_file_exits_1_with_its_name() {
    let d = temp_dir("missing");
    let o = tracelab(
        &[
            "-input", "nope.txt", "-size", "10", "10", "-output", "o.png",
        ],
        &d,
    );
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("nope.txt: cannot read scene file"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn broken_scene_exits_1_with_file_line_col() {
    let d = temp_dir("broken");
    std::fs::write(
        d.join("bad.txt"),
        "OrthographicCamera {\n  center 0 0 10\n  direction 0 0 -1\n  up 0 1 0\n  size }\n",
    )
    .expect("write");
    let o = tracelab(&["render", "bad.txt", "--output", "o.png"], &d);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("bad.txt:5:8: expected a number after \"size\", found \"}\""),
        "{}",
        stderr(&o)
    );
    assert!(!d.join("o.png").exists(), "no image for a broken scene");
}

#[test]
fn usage_errors_exit_2() {
    let d = temp_dir("usage");
    assert_eq!(
        tracelab(&["render", "--size", "a", "b"], &d).status.code(),
        Some(2)
    );
    assert_eq!(
        tracelab(&["-input", "x.txt", "-size", "10"], &d)
            .status
            .code(),
        Some(2)
    );
    assert_eq!(
        tracelab(&["-input", "x.txt", "-size", "10", "10", "-bogus"], &d)
            .status
            .code(),
        Some(2)
    );
    let o = tracelab(&["render", "--output", "o.gif"], &d);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("unknown image format"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn course_flags_write_every_image_in_the_format_of_its_extension() {
    let d = temp_dir("course");
    let scene = repo().join("scenes/inside_sphere.txt");
    let scene = scene.to_str().expect("utf-8 path");
    let o = tracelab(
        &[
            "-input",
            scene,
            "-size",
            "40",
            "30",
            "-output",
            "c.tga",
            "-normals",
            "n.bmp",
            "-depth",
            "4",
            "6",
            "d.ppm",
            "-shade_back",
        ],
        &d,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    for (f, fmt) in [
        ("c.tga", image::ImageFormat::Tga),
        ("n.bmp", image::ImageFormat::Bmp),
        ("d.ppm", image::ImageFormat::Pnm),
    ] {
        let img = image::ImageReader::open(d.join(f))
            .expect("open")
            .with_guessed_format()
            .expect("guess");
        assert_eq!(img.format(), Some(fmt), "{f}");
        let img = img.decode().expect("decode");
        assert_eq!((img.width(), img.height()), (40, 30), "{f}");
    }
}

#[test]
fn render_subcommand_matches_course_flags() {
    let d = temp_dir("same");
    let scene = repo().join("scenes/sheared_sphere.txt");
    let scene = scene.to_str().expect("utf-8 path");
    assert!(
        tracelab(
            &[
                "render",
                scene,
                "--size",
                "50",
                "50",
                "--output",
                "a.png",
                "--normal-transform",
                "incorrect"
            ],
            &d
        )
        .status
        .success()
    );
    assert!(
        tracelab(
            &[
                "-input",
                scene,
                "-size",
                "50",
                "50",
                "-output",
                "b.png",
                "-normal_transform",
                "incorrect"
            ],
            &d
        )
        .status
        .success()
    );
    let a = image::open(d.join("a.png")).expect("a").to_rgb8();
    let b = image::open(d.join("b.png")).expect("b").to_rgb8();
    assert_eq!(a, b);
    assert!(
        tracelab(
            &["-input", scene, "-size", "50", "50", "-output", "c.png"],
            &d
        )
        .status
        .success()
    );
    assert_ne!(
        image::open(d.join("c.png")).expect("c").to_rgb8(),
        a,
        "correct and incorrect differ on a sheared sphere"
    );
}

#[test]
fn builtin_scene_renders_without_a_file() {
    let d = temp_dir("builtin");
    let o = tracelab(
        &["render", "--size", "32", "24", "--output", "default.png"],
        &d,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(image::open(d.join("default.png")).expect("png").width(), 32);
}

#[test]
fn fmt_writes_canonical_text_that_reads_back() {
    let d = temp_dir("fmt");
    let src = "OrthographicCamera{center 0 0 10 direction 0 0 -1 up 0 1 0 size 5}\nMaterials{numMaterials 1 Material{diffuseColor 1 0 0}}\nGroup{numObjects 1 MaterialIndex 0 Sphere{center 0 0 0 radius 1}}";
    std::fs::write(d.join("s.txt"), src).expect("write");
    let o = tracelab(&["fmt", "s.txt", "-o", "out.txt"], &d);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(d.join("out.txt")).expect("read");
    assert!(
        text.starts_with("OrthographicCamera {\n    center 0 0 10\n"),
        "{text}"
    );
    // Idempotent.
    let o = tracelab(&["fmt", "out.txt"], &d);
    assert_eq!(String::from_utf8_lossy(&o.stdout), text);
    // No temporary files left behind.
    let leftovers: Vec<_> = std::fs::read_dir(&d)
        .expect("dir")
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains("tmp"))
        .collect();
    assert!(leftovers.is_empty());
}

/// A course flag given to `fmt` by mistake, `-object_rays`, is `-o bject_rays` to clap: fmt
/// wrote a file named `bject_rays` and exited 0. Now a usage error, nothing written; the
/// spaced, `=` and long forms still write (the control).
#[test]
fn fmt_refuses_an_o_value_run_on_that_a_mistyped_flag_would_make() {
    let d = temp_dir("fmt_run_on");
    let src = "OrthographicCamera{center 0 0 10 direction 0 0 -1 up 0 1 0 size 5}\nMaterials{numMaterials 1 Material{diffuseColor 1 0 0}}\nGroup{numObjects 1 MaterialIndex 0 Sphere{center 0 0 0 radius 1}}";
    std::fs::write(d.join("s.txt"), src).expect("write");
    for (args, file) in [
        (vec!["fmt", "s.txt", "-object_rays"], "bject_rays"),
        (vec!["fmt", "-output", "s.txt"], "utput"),
        (vec!["fmt", "s.txt", "-oout.txt"], "out.txt"),
    ] {
        let o = tracelab(&args, &d);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(
            stderr(&o).contains(&format!("`-o {file}`")) && stderr(&o).contains("-o FILE"),
            "{args:?}: {}",
            stderr(&o)
        );
        assert!(o.stdout.is_empty(), "{args:?}");
        assert!(!d.join(file).exists(), "{args:?} wrote {file}");
    }
    for (args, file) in [
        (vec!["fmt", "s.txt", "-o", "a.txt"], "a.txt"),
        (vec!["fmt", "s.txt", "-o=b.txt"], "b.txt"),
        (vec!["fmt", "s.txt", "--output", "c.txt"], "c.txt"),
        (vec!["fmt", "s.txt", "--output=d.txt"], "d.txt"),
    ] {
        let o = tracelab(&args, &d);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
        assert!(d.join(file).is_file(), "{args:?} did not write {file}");
    }
}

/// `fmt` rewrites text: it must not need the meshes the scene names (it used to exit 1).
#[test]
fn fmt_rewrites_a_scene_whose_obj_file_is_missing() {
    let d = temp_dir("fmt-no-obj");
    let src = "OrthographicCamera{center 0 0 10 direction 0 0 -1 up 0 1 0 size 5}\nMaterials{numMaterials 1 Material{diffuseColor 1 0 0}}\nGroup{numObjects 1 MaterialIndex 0 TriangleMesh{obj_file not_here.obj}}";
    std::fs::write(d.join("s.txt"), src).expect("write");
    let o = tracelab(&["fmt", "s.txt"], &d);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("TriangleMesh {\n        obj_file not_here.obj\n"),
        "{text}"
    );
    assert!(!stderr(&o).contains("cannot load"), "{}", stderr(&o));
    // Rendering it still says what is missing.
    let o = tracelab(
        &["render", "s.txt", "--size", "8", "8", "--output", "o.png"],
        &d,
    );
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("cannot load OBJ file \"not_here.obj\""),
        "{}",
        stderr(&o)
    );
}

#[test]
fn fmt_keeps_comments() {
    let d = temp_dir("fmt-comments");
    let src = "# a header\nOrthographicCamera{center 0 0 10 direction 0 0 -1 up 0 1 0 size 5}\nMaterials{numMaterials 1 Material{diffuseColor 1 0 0}}\nGroup{numObjects 1\n# the ball\nMaterialIndex 0 Sphere{center 0 0 0\n# its radius\nradius 1}}\n# the end\n";
    std::fs::write(d.join("s.txt"), src).expect("write");
    let o = tracelab(&["fmt", "s.txt"], &d);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    for c in [
        "# a header\nOrthographicCamera {",
        "    # the ball\n    MaterialIndex 0\n",
        "        # its radius\n        radius 1\n",
        "}\n# the end\n",
    ] {
        assert!(text.contains(c), "{c:?} missing:\n{text}");
    }
}

/// `fmt` read a 3.6 MB scene of Groups nested 180,000 deep and wrote its canonical form,
/// over 64 MiB (every level a line, indented), which tracelab then refused to open. It
/// refuses instead, saying why, and writes nothing; a shallower one still goes through.
#[test]
fn fmt_refuses_to_write_what_it_could_not_read_back() {
    let d = temp_dir("fmt-too-deep");
    let nested = |depth: usize| {
        let mut s = String::from(
            "OrthographicCamera{center 0 0 10 direction 0 0 -1 up 0 1 0 size 5}\n\
             Materials{numMaterials 1 Material{diffuseColor 1 0 0}}\n",
        );
        s.push_str(&"Group{numObjects 1\n".repeat(depth));
        s.push_str("Sphere{center 0 0 0 radius 1}");
        s.push_str(&"}".repeat(depth));
        s
    };
    std::fs::write(d.join("deep.txt"), nested(180_000)).expect("write");
    let o = tracelab(&["fmt", "deep.txt", "-o", "out.txt"], &d);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("deep.txt: not rewritten: its text would be ")
            && stderr(&o).contains("MiB, more than the 64 MiB tracelab reads as a scene"),
        "{}",
        stderr(&o)
    );
    assert!(!d.join("out.txt").exists());
    let o = tracelab(&["fmt", "deep.txt"], &d);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(o.stdout.is_empty());
    std::fs::write(d.join("less.txt"), nested(1000)).expect("write");
    let o = tracelab(&["fmt", "less.txt", "-o", "out.txt"], &d);
    assert!(o.status.success(), "{}", stderr(&o));
    let _ = std::fs::remove_dir_all(&d);
}

// ---- Robustness (issue 11): sizes, non-UTF-8 arguments, pipes, full devices, writes ----

#[cfg(unix)]
fn is_char_device(p: &Path) -> bool {
    use std::os::unix::fs::FileTypeExt;
    std::fs::symlink_metadata(p).is_ok_and(|m| m.file_type().is_char_device())
}

#[test]
fn image_sizes_over_the_limit_or_zero_are_usage_errors_before_any_allocation() {
    let d = temp_dir("sizes");
    std::fs::write(d.join("o.png"), "old").expect("write");
    for size in [
        ["100000", "100000"],
        ["4294967295", "4294967295"],
        ["0", "0"],
        ["16384", "16384"],
    ] {
        let o = tracelab(
            &["render", "--size", size[0], size[1], "--output", "o.png"],
            &d,
        );
        assert_eq!(o.status.code(), Some(2), "--size {size:?}: {}", stderr(&o));
        assert!(stderr(&o).contains("image size"), "{}", stderr(&o));
    }
    let o = tracelab(
        &[
            "-input", "x.txt", "-size", "100000", "100000", "-output", "o.png",
        ],
        &d,
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert_eq!(
        std::fs::read(d.join("o.png")).expect("read"),
        b"old",
        "the old image is untouched"
    );
    let scene = repo().join("scenes/inside_sphere.txt");
    let scene = scene.to_str().expect("utf-8 path");
    for cmd in ["bench", "bench-progressive"] {
        let o = tracelab(&[cmd, scene, "--size", "0", "0"], &d);
        assert_eq!(o.status.code(), Some(2), "{cmd}: {}", stderr(&o));
        assert!(stderr(&o).contains("image size 0x0"), "{}", stderr(&o));
    }
    let help = String::from_utf8_lossy(&tracelab(&["--help"], &d).stdout).to_string();
    assert!(help.contains("16384 pixels a side"), "{help}");
    assert_eq!(
        (
            tracelab_core::render::MAX_IMAGE_SIDE,
            tracelab_core::render::MAX_IMAGE_PIXELS
        ),
        (16384, 8192 * 8192),
        "--help states these numbers"
    );
}

#[cfg(unix)]
#[test]
fn non_utf8_file_names_are_paths_not_panics() {
    use std::ffi::OsStr;
    use std::os::unix::ffi::OsStrExt;
    let d = temp_dir("nonutf8");
    let scene = repo().join("scenes/inside_sphere.txt");
    let odd = OsStr::from_bytes(b"\xffodd.png");
    let run = |args: &[&OsStr]| {
        Command::new(env!("CARGO_BIN_EXE_tracelab"))
            .args(args)
            .current_dir(&d)
            .output()
            .expect("run")
    };
    let o = run(&[
        OsStr::new("render"),
        scene.as_os_str(),
        OsStr::new("--size"),
        OsStr::new("8"),
        OsStr::new("8"),
        OsStr::new("--output"),
        odd,
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(d.join(odd).is_file());
    let o = run(&[
        OsStr::new("-input"),
        scene.as_os_str(),
        OsStr::new("-size"),
        OsStr::new("8"),
        OsStr::new("8"),
        OsStr::new("-depth"),
        OsStr::new("1"),
        OsStr::new("9"),
        OsStr::from_bytes(b"\xfed.png"),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let o = run(&[OsStr::new("fmt"), OsStr::from_bytes(b"\xffmissing.txt")]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let o = run(&[
        OsStr::new("-input"),
        OsStr::new("x.txt"),
        OsStr::new("-size"),
        OsStr::from_bytes(b"\xff"),
        OsStr::new("8"),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

/// A scene whose canonical text is far larger than a pipe's buffer.
fn big_scene(d: &Path) -> PathBuf {
    let mut s = String::from(
        "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 5 }\nMaterials { numMaterials 1 Material { diffuseColor 1 0 0 } }\nGroup { numObjects 4000 MaterialIndex 0\n",
    );
    for i in 0..4000 {
        s.push_str(&format!("Sphere {{ center {i} 0 0 radius 1 }}\n"));
    }
    s.push_str("}\n");
    let p = d.join("big.txt");
    std::fs::write(&p, s).expect("write");
    p
}

#[test]
fn fmt_into_a_closed_pipe_ends_quietly() {
    use std::io::Read;
    let d = temp_dir("pipe");
    let scene = big_scene(&d);
    let mut child = Command::new(env!("CARGO_BIN_EXE_tracelab"))
        .arg("fmt")
        .arg(&scene)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("spawn");
    let mut head = [0u8; 10];
    child
        .stdout
        .take()
        .expect("stdout")
        .read_exact(&mut head)
        .expect("read 10 bytes"); // like `head -c 10`, then close
    let o = child.wait_with_output().expect("wait");
    assert_eq!(&head, b"Orthograph");
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(o.stderr.is_empty(), "quiet: {}", stderr(&o));
}

/// `tracelab bench … | head`: a reader that has gone before the first figure ends the run
/// quietly (it panicked with "failed printing to stdout: Broken pipe"). The pipe's read
/// end is closed before the run starts, so every write meets the closed pipe.
#[test]
fn bench_into_a_closed_pipe_ends_quietly() {
    let (reader, writer) = std::io::pipe().expect("pipe");
    drop(reader);
    let o = Command::new(env!("CARGO_BIN_EXE_tracelab"))
        .args([
            "bench",
            "scenes/default.txt",
            "--size",
            "8",
            "8",
            "--repeat",
            "1",
        ])
        .current_dir(repo())
        .stdout(writer)
        .output()
        .expect("run");
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(o.stderr.is_empty(), "quiet: {}", stderr(&o));
}

#[cfg(unix)]
#[test]
#[ignore = "needs root: makes a private device node (mknod)"]
fn bench_to_a_full_standard_output_is_an_error() {
    let d = temp_dir("bench-full");
    let full = common::mknod(&d, "full", 7);
    let o = Command::new(env!("CARGO_BIN_EXE_tracelab"))
        .args([
            "bench",
            "scenes/default.txt",
            "--size",
            "8",
            "8",
            "--repeat",
            "1",
        ])
        .current_dir(repo())
        .stdout(
            std::fs::OpenOptions::new()
                .write(true)
                .open(&full)
                .expect("open private full device"),
        )
        .output()
        .expect("run");
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("standard output: cannot write"),
        "{}",
        stderr(&o)
    );
    assert!(is_char_device(&full));
}

#[cfg(unix)]
#[test]
#[ignore = "needs root: makes a private device node (mknod)"]
fn fmt_to_a_full_standard_output_is_an_error() {
    let d = temp_dir("stdout-full");
    let full = common::mknod(&d, "full", 7);
    let scene = big_scene(&d);
    let o = Command::new(env!("CARGO_BIN_EXE_tracelab"))
        .arg("fmt")
        .arg(&scene)
        .stdout(
            std::fs::OpenOptions::new()
                .write(true)
                .open(&full)
                .expect("open private full device"),
        )
        .output()
        .expect("run");
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("standard output: cannot write"),
        "{}",
        stderr(&o)
    );
    assert!(is_char_device(&full));
}

#[cfg(unix)]
#[test]
#[ignore = "needs root: makes a private device node (mknod)"]
fn writing_to_a_full_device_fails_for_every_output_and_leaves_the_node() {
    let d = temp_dir("full");
    let scene = repo().join("scenes/inside_sphere.txt");
    let scene = scene.to_str().expect("utf-8 path");
    for ext in ["png", "tga", "ppm", "bmp"] {
        let full = common::mknod(&d, &format!("full.{ext}"), 7);
        let o = tracelab(
            &[
                "render",
                scene,
                "--size",
                "8",
                "8",
                "--output",
                &format!("full.{ext}"),
            ],
            &d,
        );
        assert_eq!(o.status.code(), Some(1), "{ext}: {}", stderr(&o));
        assert!(is_char_device(&full), "{ext}: still a device node");
    }
    let full = common::mknod(&d, "full.txt", 7);
    let o = tracelab(&["fmt", scene, "-o", "full.txt"], &d);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(is_char_device(&full), "fmt -o keeps the device node");
    let null = common::mknod(&d, "null.txt", 3);
    let o = tracelab(&["fmt", scene, "-o", "null.txt"], &d);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(is_char_device(&null), "fmt -o writes into a null device");
}

#[cfg(unix)]
#[test]
fn fmt_output_keeps_mode_and_symlinks_and_leaves_no_temporary_file() {
    use std::os::unix::fs::PermissionsExt;
    let d = temp_dir("fmt-keep");
    let scene = repo().join("scenes/inside_sphere.txt");
    let scene = scene.to_str().expect("utf-8 path");
    std::fs::write(d.join("private.txt"), "old").expect("write");
    std::fs::set_permissions(
        d.join("private.txt"),
        std::fs::Permissions::from_mode(0o600),
    )
    .expect("chmod");
    assert!(
        tracelab(&["fmt", scene, "-o", "private.txt"], &d)
            .status
            .success()
    );
    assert_eq!(
        std::fs::metadata(d.join("private.txt"))
            .expect("meta")
            .permissions()
            .mode()
            & 0o777,
        0o600
    );
    std::fs::write(d.join("target.txt"), "old").expect("write");
    std::os::unix::fs::symlink("target.txt", d.join("link.txt")).expect("symlink");
    assert!(
        tracelab(&["fmt", scene, "-o", "link.txt"], &d)
            .status
            .success()
    );
    assert!(
        std::fs::symlink_metadata(d.join("link.txt"))
            .expect("meta")
            .file_type()
            .is_symlink()
    );
    assert!(
        std::fs::read_to_string(d.join("target.txt"))
            .expect("read")
            .contains("Camera")
    );
    let mut names: Vec<_> = std::fs::read_dir(&d)
        .expect("dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().to_string())
        .collect();
    names.sort();
    assert_eq!(names, ["link.txt", "private.txt", "target.txt"]);
}

#[test]
fn a_rejected_render_keeps_the_existing_image() {
    let d = temp_dir("keep-image");
    std::fs::write(d.join("o.png"), "old").expect("write");
    let o = tracelab(&["render", "--size", "0", "0", "--output", "o.png"], &d);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert_eq!(std::fs::read(d.join("o.png")).expect("read"), b"old");
}

#[test]
fn ppm_output_is_binary_ppm_p6() {
    let d = temp_dir("p6");
    for name in ["o.ppm", "o.pnm"] {
        let o = tracelab(&["render", "--size", "5", "4", "--output", name], &d);
        assert!(o.status.success(), "{}", stderr(&o));
        let bytes = std::fs::read(d.join(name)).expect("read");
        assert!(
            bytes.starts_with(b"P6\n5 4 255\n"),
            "{name}: {:?}",
            String::from_utf8_lossy(&bytes[..bytes.len().min(16)])
        );
    }
}

#[test]
fn fmt_warns_about_a_comment_it_cannot_keep_before_writing() {
    let d = temp_dir("fmt-lost");
    std::fs::write(d.join("s.txt"), "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size # five\n 5 }\nGroup { }\n").expect("write");
    let o = tracelab(&["fmt", "s.txt", "-o", "out.txt"], &d);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("s.txt:1:67: warning: this comment stands inside a value"),
        "{}",
        stderr(&o)
    );
}

/// A scene in `scenes/` using `mesh.obj` beside it, formatted into `out/sub/`: the written
/// file must find the mesh from its own folder, whatever the working directory.
#[test]
fn fmt_into_another_folder_rewrites_relative_mesh_paths() {
    let d = temp_dir("fmt-rebase");
    for sub in ["scenes", "out/sub", "elsewhere"] {
        std::fs::create_dir_all(d.join(sub)).expect("dirs");
    }
    std::fs::copy(repo().join("assets/cube.obj"), d.join("scenes/mesh.obj")).expect("obj");
    let src = "PerspectiveCamera { center 3 3 5 direction -3 -3 -5 up 0 1 0 angle 40 }\nMaterials { numMaterials 1 Material { diffuseColor 1 1 1 } }\nGroup { numObjects 1 MaterialIndex 0 TriangleMesh { obj_file mesh.obj } }\n";
    std::fs::write(d.join("scenes/s.txt"), src).expect("scene");
    let o = tracelab(&["fmt", "scenes/s.txt", "-o", "out/sub/o.txt"], &d);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(d.join("out/sub/o.txt")).expect("written");
    assert!(text.contains("obj_file ../../scenes/mesh.obj\n"), "{text}");
    let written = d.join("out/sub/o.txt");
    let written = written.to_str().expect("utf-8 path");
    // From a folder without the mesh, and from the mesh's own folder (where the loader's
    // current-folder fallback would have hidden a wrong path): found next to the file.
    for cwd in ["elsewhere", "scenes"] {
        let o = tracelab(
            &["render", written, "--size", "8", "8", "--output", "o.png"],
            &d.join(cwd),
        );
        assert!(o.status.success(), "from {cwd}: {}", stderr(&o));
        assert!(
            !stderr(&o).contains("current folder"),
            "from {cwd}: {}",
            stderr(&o)
        );
    }
    // Formatting in place keeps the name as written.
    let o = tracelab(&["fmt", "scenes/s.txt", "-o", "scenes/again.txt"], &d);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        std::fs::read_to_string(d.join("scenes/again.txt"))
            .expect("again")
            .contains("obj_file mesh.obj\n")
    );
}

#[test]
fn a_mesh_found_only_in_the_current_folder_is_reported() {
    let d = temp_dir("cwd-fallback");
    std::fs::create_dir_all(d.join("scenes")).expect("dirs");
    std::fs::copy(repo().join("assets/cube.obj"), d.join("mesh.obj")).expect("obj");
    let src = "PerspectiveCamera { center 3 3 5 direction -3 -3 -5 up 0 1 0 angle 40 }\nMaterials { numMaterials 1 Material { diffuseColor 1 1 1 } }\nGroup { numObjects 1 MaterialIndex 0 TriangleMesh { obj_file mesh.obj } }\n";
    std::fs::write(d.join("scenes/s.txt"), src).expect("scene");
    // The course's way (mesh in the working folder, scene elsewhere) still renders...
    let o = tracelab(
        &[
            "-input",
            "scenes/s.txt",
            "-size",
            "8",
            "8",
            "-output",
            "o.png",
        ],
        &d,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    // ...but says where the mesh came from.
    assert!(
        stderr(&o).contains("not in the scene's folder"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn negative_depth_ranges_are_accepted_in_both_spellings() {
    let d = temp_dir("negative");
    let scene = repo().join("scenes/inside_sphere.txt");
    let scene = scene.to_str().expect("utf-8 path");
    let o = tracelab(
        &[
            "render", scene, "--size", "8", "8", "--depth", "-1", "1", "d.png",
        ],
        &d,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(d.join("d.png").is_file());
    let o = tracelab(
        &[
            "-input", scene, "-size", "8", "8", "-depth", "-1", "1", "e.png",
        ],
        &d,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    // A negative size is now "invalid value", still a usage error.
    assert_eq!(
        tracelab(&["render", "--size", "-1", "5", "--output", "x.png"], &d)
            .status
            .code(),
        Some(2)
    );
}

/// `kill -9` while `fmt -o` is writing: the old file stays whole and no temporary file is
/// left in its folder (on Linux the temporary file has no name until it is complete). The
/// test hook stops the write once its bytes are out but before the rename, the moment a
/// named temporary file would be left behind.
#[cfg(target_os = "linux")]
#[test]
#[cfg_attr(
    not(debug_assertions),
    ignore = "the stall hook exists only in debug builds (tests/cli_text.rs checks release ignores it)"
)]
fn kill_9_during_fmt_o_leaves_the_old_file_and_no_temporary_file() {
    use std::io::{BufRead, BufReader};
    let d = temp_dir("kill9");
    std::fs::copy(repo().join("scenes/default.txt"), d.join("in.txt")).expect("copy scene");
    std::fs::write(d.join("out.txt"), "old contents").expect("write");
    for image in [false, true] {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_tracelab"));
        if image {
            std::fs::write(d.join("out.png"), "old image").expect("write");
            cmd.args([
                "render", "in.txt", "--size", "8", "8", "--output", "out.png",
            ]);
        } else {
            cmd.args(["fmt", "in.txt", "-o", "out.txt"]);
        }
        let mut child = cmd
            .current_dir(&d)
            .env("TRACELAB_TEST_STALL_BEFORE_RENAME", "1")
            .stderr(std::process::Stdio::piped())
            .spawn()
            .expect("run tracelab");
        let mut line = String::new();
        BufReader::new(child.stderr.take().expect("stderr"))
            .read_line(&mut line)
            .expect("read stderr");
        assert!(line.contains("stalled before rename"), "{line}");
        child.kill().expect("kill -9");
        let _ = child.wait();
    }
    let mut names: Vec<String> = std::fs::read_dir(&d)
        .expect("read dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into())
        .collect();
    names.sort();
    assert_eq!(
        names,
        ["in.txt", "out.png", "out.txt"],
        "a temporary file was left behind"
    );
    assert_eq!(
        std::fs::read_to_string(d.join("out.txt")).expect("read"),
        "old contents"
    );
    assert_eq!(
        std::fs::read_to_string(d.join("out.png")).expect("read"),
        "old image"
    );
}

#[test]
fn object_rays_flag_in_both_spellings_keeps_or_breaks_the_depth_order() {
    let d = temp_dir("object-rays");
    let scene = repo().join("scenes/lecture/depth_t.txt");
    let scene = scene.to_str().expect("utf-8 path");
    let mut images = Vec::new();
    for mode in ["unnormalized", "normalized", "normalized-no-rescale"] {
        let (c, z) = (format!("{mode}.png"), format!("{mode}-depth.png"));
        let o = tracelab(
            &[
                "render",
                scene,
                "--size",
                "60",
                "60",
                "--output",
                &c,
                "--depth",
                "8",
                "16",
                &z,
                "--object-rays",
                mode,
            ],
            &d,
        );
        assert!(o.status.success(), "{mode}: {}", stderr(&o));
        let (cc, zc) = (
            format!("course-{mode}.png"),
            format!("course-{mode}-depth.png"),
        );
        let o = tracelab(
            &[
                "-input",
                scene,
                "-size",
                "60",
                "60",
                "-output",
                &cc,
                "-depth",
                "8",
                "16",
                &zc,
                "-object_rays",
                mode,
            ],
            &d,
        );
        assert!(o.status.success(), "{mode}: {}", stderr(&o));
        let read = |f: &str| image::open(d.join(f)).expect("image").to_rgb8();
        assert_eq!(read(&c), read(&cc), "{mode}: both spellings");
        images.push((read(&c), read(&z)));
    }
    let max_diff = |a: &image::RgbImage, b: &image::RgbImage| {
        a.as_raw()
            .iter()
            .zip(b.as_raw())
            .map(|(x, y)| x.abs_diff(*y))
            .max()
            .unwrap_or(0)
    };
    let [(c0, z0), (c1, z1), (c2, z2)] = images.try_into().expect("three modes");
    // The two correct rules: the same images to rounding.
    assert!(max_diff(&c0, &c1) <= 1 && max_diff(&z0, &z1) <= 1);
    // Pixel (36, 29) looks at the small red sphere's centre, in front of the big blue one
    // (world t 9 against 12); without rescaling red's t doubles and blue's is quartered.
    let (good, bug) = (c0.get_pixel(36, 29), c2.get_pixel(36, 29));
    assert!(
        good[0] > good[2] && bug[2] > bug[0],
        "red {good:?} then blue {bug:?}"
    );
    // Depth in [8, 16]: red at t = 9 is grey 223 (⌊(16 − 9)/8·255⌋), blue's t ≈ 3 is white.
    let (zg, zb) = (z0.get_pixel(36, 29)[0], z2.get_pixel(36, 29)[0]);
    assert!(zg.abs_diff(223) <= 2 && zb == 255, "depth {zg} then {zb}");
    let o = tracelab(
        &[
            "render",
            scene,
            "--output",
            "x.png",
            "--object-rays",
            "sideways",
        ],
        &d,
    );
    assert_eq!(o.status.code(), Some(2));
    let o = tracelab(
        &[
            "-input",
            scene,
            "-size",
            "9",
            "9",
            "-output",
            "x.png",
            "-object_rays",
            "sideways",
        ],
        &d,
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o)
            .contains("-object_rays: expected unnormalized, normalized or normalized-no-rescale"),
        "{}",
        stderr(&o)
    );
}
