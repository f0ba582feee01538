//! What the command line prints, as a hostile file or argument meets it: control bytes in
//! an `obj_file` name, an image path or an argument never reach the terminal raw (in text,
//! JSON, reports and errors); a closed or full standard output is an error for every
//! command that writes one; a mistyped command is a usage error, not the editor.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

mod common;
use common::tracelab;

fn temp_dir(name: &str) -> PathBuf {
    common::temp_dir("cli-text", name)
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).to_string()
}

/// Control characters a terminal acts on (line breaks aside) and the bidirectional overrides.
fn raw_controls(text: &str) -> Vec<char> {
    text.chars()
        .filter(|&c| {
            (c.is_control() && c != '\n')
                || matches!(c, '\u{200e}' | '\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}')
        })
        .collect()
}

/// An `obj_file` name that sets the window title, clears the screen, and reverses what follows
/// (ESC, BEL, DEL, the one-byte CSI U+009B, RLO); the scene's tokens end at ASCII spaces only.
const HOSTILE_OBJ: &str = "m\u{1b}]0;pwned\u{7}\u{1b}[2J\u{7f}\u{9b}31m\u{202e}jbo.obj";

/// A folder with `s.txt`: an orthographic camera looking down −z at one triangle, from a
/// mesh file with the hostile name, that covers the whole view.
fn hostile_scene(name: &str) -> PathBuf {
    let d = temp_dir(name);
    std::fs::write(
        d.join(HOSTILE_OBJ),
        "v -10 -10 0\nv 10 -10 0\nv 0 10 0\nf 1 2 3\n",
    )
    .expect("write obj");
    std::fs::write(
        d.join("s.txt"),
        format!(
            "OrthographicCamera {{ center 0 0 10 direction 0 0 -1 up 0 1 0 size 2 }}\n\
             Lights {{ numLights 1 DirectionalLight {{ direction 0 0 -1 color 1 1 1 }} }}\n\
             Background {{ color 0 0 0 ambientLight 0 0 0 }}\n\
             Materials {{ numMaterials 1 Material {{ diffuseColor 0.5 0.5 0.5 }} }}\n\
             Group {{ numObjects 1 MaterialIndex 0 TriangleMesh {{ obj_file {HOSTILE_OBJ} }} }}\n"
        ),
    )
    .expect("write scene");
    d
}

#[test]
fn inspect_escapes_an_obj_file_name_in_text_and_keeps_it_exact_in_valid_json() {
    let d = hostile_scene("inspect");
    let args = ["inspect", "s.txt", "--size", "8", "8", "--pixel", "4", "4"];
    let o = tracelab(&args, &d);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains(
            "hit: TriangleMesh: m\\x1b]0;pwned\\x07\\x1b[2J\\x7f\\u{9b}31m\\u{202e}jbo.obj"
        ),
        "{text}"
    );
    assert_eq!(raw_controls(&text), Vec::<char>::new(), "{text:?}");

    let o = tracelab(&[&args[..], &["--json"]].concat(), &d);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let json = String::from_utf8(o.stdout).expect("UTF-8");
    assert_eq!(raw_controls(&json), Vec::<char>::new(), "{json:?}");
    let v: serde_json::Value = serde_json::from_str(&json).expect("valid JSON");
    assert_eq!(
        v["hit"]["node"]["label"],
        format!("TriangleMesh: {HOSTILE_OBJ} (1 tris)"),
        "JSON keeps the name exact"
    );
}

#[test]
fn diff_escapes_the_obj_file_name_in_its_explanations_and_the_image_path() {
    let d = hostile_scene("diff");
    // The student's image: magenta everywhere, so every pixel is explained.
    let mine = "mine\r\u{1b}[1A.png";
    image::RgbImage::from_pixel(8, 8, image::Rgb([255, 0, 255]))
        .save_with_format(d.join(mine), image::ImageFormat::Png)
        .expect("write png");
    let o = tracelab(
        &[
            "diff", mine, "--", "-input", "s.txt", "-size", "8", "8", "-output", "x.png",
        ],
        &d,
    );
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("colour mine\\x0d\\x1b[1A.png: "), "{text}");
    assert!(text.contains("TriangleMesh: m\\x1b]0;pwned"), "{text}");
    assert_eq!(raw_controls(&text), Vec::<char>::new(), "{text:?}");
}

#[test]
fn errors_escape_the_arguments_they_quote() {
    let d = temp_dir("errors");
    // Usage errors of tracelab's own (the course's flags, a mistyped command) and one of
    // clap's, in colour as on a terminal (clap strips escapes from a pipe, not a terminal).
    for args in [
        &["-input", "s.txt", "-bogus\u{1b}[2J\u{7}"][..],
        &["render", "--size", "x\u{1b}[2J\u{7}", "8"][..],
        &["rend\u{1b}[2J\u{7}"][..],
    ] {
        let o = Command::new(env!("CARGO_BIN_EXE_tracelab"))
            .args(args)
            .current_dir(&d)
            .env("CLICOLOR_FORCE", "1")
            .env_remove("DISPLAY")
            .env_remove("WAYLAND_DISPLAY")
            .output()
            .expect("run tracelab");
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(
            stderr(&o).contains("\\x1b[2J\\x07"),
            "{args:?}: {}",
            stderr(&o)
        );
        assert_eq!(
            raw_controls(&stderr(&o)),
            Vec::<char>::new(),
            "{args:?}: {:?}",
            stderr(&o)
        );
    }
}

// ---- Standard output closed or full: an error for every command that writes it ----

fn scene() -> PathBuf {
    common::repo().join("scenes/default.txt")
}

/// `tracelab ARGS >&-`: the shell closes standard output before the program starts.
fn with_stdout_closed(args: &[&str], dir: &Path) -> Output {
    Command::new("bash")
        .arg("-c")
        .arg(r#"exec >&-; exec "$@""#)
        .arg("bash")
        .arg(env!("CARGO_BIN_EXE_tracelab"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run bash")
}

fn every_stdout_command(dir: &Path) -> Vec<Vec<String>> {
    let s = scene().to_str().expect("UTF-8 path").to_string();
    let mine = dir.join("mine.png");
    image::RgbImage::from_pixel(4, 4, image::Rgb([255, 0, 255]))
        .save(&mine)
        .expect("write png");
    let mine = mine.to_str().expect("UTF-8 path").to_string();
    [
        vec!["fmt", &s],
        vec!["inspect", &s, "--size", "4", "4", "--pixel", "1", "1"],
        vec![
            "inspect", &s, "--size", "4", "4", "--pixel", "1", "1", "--json",
        ],
        vec![
            "diff", &mine, "--", "-input", &s, "-size", "4", "4", "-output", "x.png",
        ],
        vec!["bench", &s, "--size", "4", "4", "--repeat", "1"],
        vec!["--help"],
        vec!["render", "--help"],
        vec!["--version"],
    ]
    .iter()
    .map(|a| a.iter().map(|s| s.to_string()).collect())
    .collect()
}

#[cfg(target_os = "linux")]
#[test]
fn every_command_with_standard_output_closed_warns_that_its_output_is_lost() {
    // A warning and the command's own exit code, not an error: a closed standard output
    // reads as /dev/null opened read-write, which is also what Python's subprocess.DEVNULL
    // gives a grading script that only checks `tracelab diff`'s exit code.
    let d = temp_dir("closed");
    for args in every_stdout_command(&d) {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = with_stdout_closed(&args, &d);
        let piped = Command::new(env!("CARGO_BIN_EXE_tracelab"))
            .args(&args)
            .current_dir(&d)
            .output()
            .expect("run tracelab");
        assert!(
            !stderr(&piped).contains("warning: standard output"),
            "{args:?}: a pipe is no closed output: {}",
            stderr(&piped)
        );
        assert_eq!(
            o.status.code(),
            piped.status.code(),
            "{args:?}: {}",
            stderr(&o)
        );
        assert_eq!(
            stderr(&o)
                .matches("warning: standard output is closed")
                .count(),
            1,
            "{args:?}: {}",
            stderr(&o)
        );
    }
}

/// A private device node (never the machine's own /dev files).
#[cfg(unix)]
fn mknod(dir: &Path, name: &str, minor: u32) -> PathBuf {
    let p = dir.join(name);
    let ok = Command::new("mknod")
        .arg(&p)
        .args(["c", "1", &minor.to_string()])
        .status()
        .is_ok_and(|s| s.success());
    assert!(ok, "mknod {} failed: this test needs root", p.display());
    p
}

#[cfg(unix)]
fn with_stdout_to(device: &Path, args: &[String], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tracelab"))
        .args(args)
        .current_dir(dir)
        .stdout(
            std::fs::OpenOptions::new()
                .write(true)
                .open(device)
                .expect("open private device"),
        )
        .output()
        .expect("run tracelab")
}

#[cfg(unix)]
#[test]
#[ignore = "needs root (private device nodes): run with -- --ignored, as .ci/run does"]
fn every_command_to_a_full_standard_output_says_so_and_exits_1() {
    let d = temp_dir("full");
    let full = mknod(&d, "full", 7);
    for args in every_stdout_command(&d) {
        let o = with_stdout_to(&full, &args, &d);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {}", stderr(&o));
        assert!(
            stderr(&o).contains("standard output: cannot write"),
            "{args:?}: {}",
            stderr(&o)
        );
    }
}

/// `> /dev/null` (here a private null device, opened write-only as a shell does) is where a
/// user sends output on purpose: not taken for a closed standard output.
#[cfg(unix)]
#[test]
#[ignore = "needs root (private device nodes): run with -- --ignored, as .ci/run does"]
fn every_command_to_a_null_device_succeeds() {
    let d = temp_dir("null");
    let null = mknod(&d, "null", 3);
    for args in every_stdout_command(&d) {
        let o = with_stdout_to(&null, &args, &d);
        // diff: the magenta image does not match (3), and says so on standard output.
        let expected = if args[0] == "diff" { 3 } else { 0 };
        assert_eq!(o.status.code(), Some(expected), "{args:?}: {}", stderr(&o));
    }
}

// ---- A mistyped command ----

#[test]
fn a_mistyped_command_is_a_usage_error_naming_the_nearest_not_the_editor() {
    let d = temp_dir("mistyped");
    for (typo, hint) in [
        ("rendr", "did you mean `render`?"),
        ("inspcet", "did you mean `inspect`?"),
        ("zzzqqq", "neither a file nor a command (commands: render,"),
    ] {
        // No display: should the editor start anyway, it fails rather than opening a window.
        let o = Command::new(env!("CARGO_BIN_EXE_tracelab"))
            .arg(typo)
            .current_dir(&d)
            .env_remove("DISPLAY")
            .env_remove("WAYLAND_DISPLAY")
            .output()
            .expect("run tracelab");
        assert_eq!(o.status.code(), Some(2), "{typo}: {}", stderr(&o));
        assert!(stderr(&o).contains(hint), "{typo}: {}", stderr(&o));
    }
}

// ---- The test-only stall hook ----

/// The hook that lets tests/cli.rs kill a write at the worst moment is compiled only into
/// debug builds: a release binary with the variable set writes at once and says nothing.
/// (Runs under `cargo test --release`; debug builds have the hook, which that test uses.)
#[cfg(not(debug_assertions))]
#[test]
fn a_release_binary_ignores_the_stall_hook() {
    let d = temp_dir("no-stall");
    let start = std::time::Instant::now();
    let o = Command::new(env!("CARGO_BIN_EXE_tracelab"))
        .args([
            "fmt",
            scene().to_str().expect("UTF-8 path"),
            "-o",
            "out.txt",
        ])
        .current_dir(&d)
        .env("TRACELAB_TEST_STALL_BEFORE_RENAME", "1")
        .output()
        .expect("run tracelab");
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(!stderr(&o).contains("stalled"), "{}", stderr(&o));
    assert!(start.elapsed() < std::time::Duration::from_secs(30));
    assert!(d.join("out.txt").is_file());
}
