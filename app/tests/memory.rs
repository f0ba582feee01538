//! Bounded memory, shown under `ulimit -v`: `animate` streams its frames (memory does not grow
//! with `--frames`), and a job too big for the memory there is ends with a message and exit
//! 1, never an abort (SIGABRT) with nothing said.
//!
//! The limit is on address space, which every thread's stack and malloc arena takes too, so
//! the tests fix the number of render threads (`RAYON_NUM_THREADS`): what is measured is
//! tracelab's buffers, not the machine's cores.

mod common;

use std::os::unix::process::ExitStatusExt;
use std::path::Path;
use std::process::{Command, Output};

/// Runs tracelab in `dir` with its address space limited to `kib` KiB.
fn tracelab_within(kib: u64, args: &[&str], dir: &Path) -> Output {
    Command::new("bash")
        .arg("-c")
        .arg(format!("ulimit -v {kib} && exec \"$0\" \"$@\""))
        .arg(env!("CARGO_BIN_EXE_tracelab"))
        .args(args)
        .env("RAYON_NUM_THREADS", "4")
        .current_dir(dir)
        .output()
        .expect("run tracelab under ulimit")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A sphere moved along x by `Translate VALUE 0 0`; small in a full-HD frame, so the frames
/// are quick to trace and to encode.
const SCENE: &str = "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 20 }
Lights { numLights 1 DirectionalLight { direction -0.5 -0.5 -1 color 0.9 0.9 0.9 } }
Background { color 0.1 0.1 0.1 ambientLight 0.1 0.1 0.1 }
Materials { numMaterials 1 Material { diffuseColor 0.9 0.3 0.2 } }
Group { numObjects 1 MaterialIndex 0
  Transform { Translate 0 0 0 Sphere { center 0 0 0 radius 1 } } }
";

/// `animate` of `frames` frames of 1920×1080 under `kib` KiB: it succeeds, and the animated
/// PNG holds every frame.
fn animate_full_hd_within(frames: u32, kib: u64, name: &str) {
    let dir = common::temp_dir("memory", name);
    std::fs::write(dir.join("s.txt"), SCENE).expect("write scene");
    let n = frames.to_string();
    // Node 0 is the root Group, node 1 the Transform.
    let o = tracelab_within(
        kib,
        &[
            "animate", "s.txt", "--size", "1920", "1080", "--node", "1", "--from", "-8", "--to",
            "8", "--frames", &n, "--out", "out",
        ],
        &dir,
    );
    assert!(o.status.success(), "{:?}: {}", o.status, stderr(&o));
    assert!(
        dir.join(format!("out/frame_{:04}.png", frames - 1))
            .is_file()
    );
    let apng = std::fs::File::open(dir.join("out/frame.apng.png")).expect("apng");
    let decoder = png::Decoder::new(std::io::BufReader::new(apng))
        .read_info()
        .expect("png header");
    let info = decoder.info();
    assert_eq!((info.width, info.height), (1920, 1080));
    assert_eq!(info.animation_control().map(|a| a.num_frames), Some(frames));
    let _ = std::fs::remove_dir_all(&dir);
}

/// 60 frames of 1920×1080 are 373 MB of RGB: held until the end (as before), they cannot fit
/// in 300 MB (it aborted); streamed, each frame is written and dropped.
#[test]
fn sixty_full_hd_frames_are_animated_within_300_mb() {
    animate_full_hd_within(60, 300_000, "animate-60");
}

/// The figure: 300 frames of 1920×1080 (1.8 GB of RGB) within 1 GB.
#[test]
#[ignore = "slow: about 80 s in a debug build (300 frame files, each synced); the 60-frame test shows the same in 15 s"]
fn three_hundred_full_hd_frames_are_animated_within_a_gigabyte() {
    animate_full_hd_within(300, 1_000_000, "animate-300");
}

/// An 8192×8192 render (within the size limits) needs about 1.6 GB: under 1 GB it is refused
/// with what it needs, before the scene is read.
#[test]
fn a_render_too_big_for_the_memory_there_is_says_so_and_exits_1() {
    let dir = common::temp_dir("memory", "render");
    std::fs::write(dir.join("s.txt"), SCENE).expect("write scene");
    let o = tracelab_within(
        1_000_000,
        &[
            "render", "s.txt", "--size", "8192", "8192", "--output", "big.png",
        ],
        &dir,
    );
    assert_eq!(o.status.signal(), None, "{:?}: {}", o.status, stderr(&o));
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("not enough memory to render 8192x8192 (needs about "),
        "{}",
        stderr(&o)
    );
    assert!(!dir.join("big.png").exists());
}

/// A million spheres: under 600 MB the scene either fits or is refused with a message naming
/// what did not fit; never an abort.
#[test]
fn a_million_spheres_within_600_mb_render_or_say_what_did_not_fit() {
    let dir = common::temp_dir("memory", "spheres");
    let mut text = String::from(
        "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 1000 }
Lights { numLights 0 }
Background { color 0 0 0 }
Materials { numMaterials 1 Material { diffuseColor 1 1 1 } }
Group { numObjects 1000000 MaterialIndex 0
",
    );
    for i in 0..1_000_000 {
        text.push_str(&format!(
            "Sphere {{ center {} {} 0 radius 0.4 }}\n",
            i % 1000 - 500,
            i / 1000 - 500
        ));
    }
    text.push_str("}\n");
    std::fs::write(dir.join("spheres.txt"), text).expect("write scene");
    let render = [
        "render",
        "spheres.txt",
        "--size",
        "64",
        "64",
        "--output",
        "s.png",
    ];
    let inspect = [
        "inspect",
        "spheres.txt",
        "--size",
        "64",
        "64",
        "--pixel",
        "3",
        "3",
    ];
    // 600 MB as the issue measured; 300 MB (the parse's objects fail) and 500 MB (inspect's
    // compile fails) reach the other paths.
    for (kib, args) in [
        (600_000, &render[..]),
        (300_000, &render[..]),
        (500_000, &inspect[..]),
    ] {
        let o = tracelab_within(kib, args, &dir);
        assert_eq!(
            o.status.signal(),
            None,
            "{args:?}: {:?}: {}",
            o.status,
            stderr(&o)
        );
        assert!(
            o.status.success()
                || (o.status.code() == Some(1) && stderr(&o).contains("not enough memory")),
            "{args:?} under {kib} KiB: {:?}: {}",
            o.status,
            stderr(&o)
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
