//! The command line as a user meets it: help, exit codes, error messages with locations,
//! the course's flags, output formats and `fmt`.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn tracelab(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tracelab")).args(args).current_dir(dir).output().expect("run tracelab")
}

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("tracelab-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
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
}

#[test]
fn missing_scene_file_exits_1_with_its_name() {
    let d = temp_dir("missing");
    let o = tracelab(&["-input", "nope.txt", "-size", "10", "10", "-output", "o.png"], &d);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("nope.txt: cannot read scene file"), "{}", stderr(&o));
}

#[test]
fn broken_scene_exits_1_with_file_line_col() {
    let d = temp_dir("broken");
    std::fs::write(d.join("bad.txt"), "OrthographicCamera {\n  center 0 0 10\n  direction 0 0 -1\n  up 0 1 0\n  size }\n").expect("write");
    let o = tracelab(&["render", "bad.txt", "--output", "o.png"], &d);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("bad.txt:5:8: expected a number after \"size\", found \"}\""), "{}", stderr(&o));
    assert!(!d.join("o.png").exists(), "no image for a broken scene");
}

#[test]
fn usage_errors_exit_2() {
    let d = temp_dir("usage");
    assert_eq!(tracelab(&["render", "--size", "a", "b"], &d).status.code(), Some(2));
    assert_eq!(tracelab(&["-input", "x.txt", "-size", "10"], &d).status.code(), Some(2));
    assert_eq!(tracelab(&["-input", "x.txt", "-size", "10", "10", "-bogus"], &d).status.code(), Some(2));
    let o = tracelab(&["render", "--output", "o.gif"], &d);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("unknown image format"), "{}", stderr(&o));
}

#[test]
fn course_flags_write_every_image_in_the_format_of_its_extension() {
    let d = temp_dir("course");
    let scene = repo().join("scenes/inside_sphere.txt");
    let scene = scene.to_str().expect("utf-8 path");
    let o = tracelab(
        &["-input", scene, "-size", "40", "30", "-output", "c.tga", "-normals", "n.bmp", "-depth", "4", "6", "d.ppm", "-shade_back"],
        &d,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    for (f, fmt) in [("c.tga", image::ImageFormat::Tga), ("n.bmp", image::ImageFormat::Bmp), ("d.ppm", image::ImageFormat::Pnm)] {
        let img = image::ImageReader::open(d.join(f)).expect("open").with_guessed_format().expect("guess");
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
    assert!(tracelab(&["render", scene, "--size", "50", "50", "--output", "a.png", "--normal-transform", "incorrect"], &d).status.success());
    assert!(tracelab(&["-input", scene, "-size", "50", "50", "-output", "b.png", "-normal_transform", "incorrect"], &d).status.success());
    let a = image::open(d.join("a.png")).expect("a").to_rgb8();
    let b = image::open(d.join("b.png")).expect("b").to_rgb8();
    assert_eq!(a, b);
    assert!(tracelab(&["-input", scene, "-size", "50", "50", "-output", "c.png"], &d).status.success());
    assert_ne!(image::open(d.join("c.png")).expect("c").to_rgb8(), a, "correct and incorrect differ on a sheared sphere");
}

#[test]
fn builtin_scene_renders_without_a_file() {
    let d = temp_dir("builtin");
    let o = tracelab(&["render", "--size", "32", "24", "--output", "default.png"], &d);
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
    assert!(text.starts_with("OrthographicCamera {\n    center 0 0 10\n"), "{text}");
    // Idempotent.
    let o = tracelab(&["fmt", "out.txt"], &d);
    assert_eq!(String::from_utf8_lossy(&o.stdout), text);
    // No temporary files left behind.
    let leftovers: Vec<_> = std::fs::read_dir(&d).expect("dir").filter_map(|e| e.ok()).filter(|e| e.file_name().to_string_lossy().contains("tmp")).collect();
    assert!(leftovers.is_empty());
}

#[test]
fn fmt_keeps_comments() {
    let d = temp_dir("fmt-comments");
    let src = "# a header\nOrthographicCamera{center 0 0 10 direction 0 0 -1 up 0 1 0 size 5}\nMaterials{numMaterials 1 Material{diffuseColor 1 0 0}}\nGroup{numObjects 1\n# the ball\nMaterialIndex 0 Sphere{center 0 0 0\n# its radius\nradius 1}}\n# the end\n";
    std::fs::write(d.join("s.txt"), src).expect("write");
    let o = tracelab(&["fmt", "s.txt"], &d);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    for c in ["# a header\nOrthographicCamera {", "    # the ball\n    MaterialIndex 0\n", "        # its radius\n        radius 1\n", "}\n# the end\n"] {
        assert!(text.contains(c), "{c:?} missing:\n{text}");
    }
}

#[test]
fn fmt_warns_about_a_comment_it_cannot_keep_before_writing() {
    let d = temp_dir("fmt-lost");
    std::fs::write(d.join("s.txt"), "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size # five\n 5 }\nGroup { }\n").expect("write");
    let o = tracelab(&["fmt", "s.txt", "-o", "out.txt"], &d);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("s.txt:1:67: warning: this comment stands inside a value"), "{}", stderr(&o));
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
        let o = tracelab(&["render", written, "--size", "8", "8", "--output", "o.png"], &d.join(cwd));
        assert!(o.status.success(), "from {cwd}: {}", stderr(&o));
        assert!(!stderr(&o).contains("current folder"), "from {cwd}: {}", stderr(&o));
    }
    // Formatting in place keeps the name as written.
    let o = tracelab(&["fmt", "scenes/s.txt", "-o", "scenes/again.txt"], &d);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(std::fs::read_to_string(d.join("scenes/again.txt")).expect("again").contains("obj_file mesh.obj\n"));
}

#[test]
fn a_mesh_found_only_in_the_current_folder_is_reported() {
    let d = temp_dir("cwd-fallback");
    std::fs::create_dir_all(d.join("scenes")).expect("dirs");
    std::fs::copy(repo().join("assets/cube.obj"), d.join("mesh.obj")).expect("obj");
    let src = "PerspectiveCamera { center 3 3 5 direction -3 -3 -5 up 0 1 0 angle 40 }\nMaterials { numMaterials 1 Material { diffuseColor 1 1 1 } }\nGroup { numObjects 1 MaterialIndex 0 TriangleMesh { obj_file mesh.obj } }\n";
    std::fs::write(d.join("scenes/s.txt"), src).expect("scene");
    // The course's way (mesh in the working folder, scene elsewhere) still renders...
    let o = tracelab(&["-input", "scenes/s.txt", "-size", "8", "8", "-output", "o.png"], &d);
    assert!(o.status.success(), "{}", stderr(&o));
    // ...but says where the mesh came from.
    assert!(stderr(&o).contains("not in the scene's folder"), "{}", stderr(&o));
}
