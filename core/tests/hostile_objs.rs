//! OBJ paths and files built to hurt: material libraries that are FIFOs, meshes that are
//! folders, FIFOs or symlink loops, files past the size cap. None may block or fill memory,
//! and each is reported as what it is.

mod common;
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::Duration;

use tracelab_core::format::obj::{MAX_OBJ_BYTES, load_obj};
use tracelab_core::{MeshCache, parse_scene};

fn mkfifo(path: &Path) {
    let ok = std::process::Command::new("mkfifo")
        .arg(path)
        .status()
        .is_ok_and(|s| s.success());
    assert!(ok, "mkfifo {}", path.display());
}

/// Runs `f` on another thread; fails the test instead of hanging when it blocks.
fn within<T: Send + 'static>(secs: u64, f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(f());
    });
    rx.recv_timeout(Duration::from_secs(secs))
        .expect("blocked: it did not return in time")
}

/// The scene-level message for a TriangleMesh whose `obj_file` is `name` in `dir`.
fn mesh_error(dir: &Path, name: &str) -> String {
    let text = format!(
        "OrthographicCamera {{ center 0 0 10 direction 0 0 -1 up 0 1 0 size 5 }}\n\
         Materials {{ numMaterials 1 Material {{ diffuseColor 1 0 0 }} }}\n\
         Group {{ numObjects 1 MaterialIndex 0 TriangleMesh {{ obj_file {name} }} }}\n"
    );
    let dir = dir.to_path_buf();
    within(20, move || {
        let out = parse_scene(
            text.as_bytes(),
            "scene.txt",
            Some(&dir),
            &mut MeshCache::new(),
        );
        out.diagnostics
            .errors()
            .map(|d| d.message.clone())
            .collect::<Vec<_>>()
            .join("\n")
    })
}

#[test]
fn an_mtllib_that_is_a_fifo_is_never_opened() {
    let dir = temp_dir("mtl");
    mkfifo(&dir.join("pipe.mtl"));
    // Negative indices send the file to tobj, which used to open every mtllib.
    let obj = dir.join("m.obj");
    std::fs::write(
        &obj,
        "mtllib pipe.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf -3 -2 -1\n",
    )
    .expect("write");
    let mesh = within(20, move || load_obj(&obj)).expect("loads without its materials");
    assert_eq!(mesh.triangle_count(), 1);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_folder_a_fifo_and_a_symlink_loop_are_named_for_what_they_are() {
    let dir = temp_dir("kinds");
    std::fs::create_dir_all(dir.join("folder.obj")).expect("folder");
    mkfifo(&dir.join("pipe.obj"));
    std::os::unix::fs::symlink("loop.obj", dir.join("loop.obj")).expect("symlink");
    let at = |name: &str| dir.join(name).display().to_string();
    assert_eq!(
        mesh_error(&dir, "folder.obj"),
        format!(
            "cannot load OBJ file \"folder.obj\": {} is a folder, not an OBJ file",
            at("folder.obj")
        )
    );
    assert_eq!(
        mesh_error(&dir, "pipe.obj"),
        format!(
            "cannot load OBJ file \"pipe.obj\": {} is a FIFO (named pipe), not an OBJ file; meshes are read from regular files only",
            at("pipe.obj")
        )
    );
    assert_eq!(
        mesh_error(&dir, "loop.obj"),
        format!(
            "cannot load OBJ file \"loop.obj\": {} is a symbolic link loop (or a chain of links too long to follow)",
            at("loop.obj")
        )
    );
    // Loaded directly, a FIFO is refused as well, without blocking.
    let fifo = dir.join("pipe.obj");
    let e = within(20, move || load_obj(&fifo)).expect_err("a FIFO");
    assert!(e.to_string().contains("is a FIFO"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_obj_over_the_size_cap_is_refused_before_parsing() {
    let dir = temp_dir("cap");
    let big = dir.join("big.obj");
    // Sparse: no disk is spent on the zeros.
    std::fs::File::create(&big)
        .and_then(|f| f.set_len(MAX_OBJ_BYTES as u64 + 1))
        .expect("sparse file");
    let e = load_obj(&big).expect_err("too big");
    assert_eq!(
        e.to_string(),
        "the file is larger than 512 MiB, the most tracelab reads as an OBJ mesh"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

fn temp_dir(name: &str) -> PathBuf {
    common::temp_dir("hostile-obj", name)
}
