//! Where tests find the data that is not in the checkout. Each folder is a setting, an
//! environment variable, with a default beside the checkout (`../shared`):
//!
//! | variable | default | holds |
//! |---|---|---|
//! | `TRACELAB_COURSE_DIR` | `../shared/mit6837` | the course's scenes, `commands.txt`, reference images |
//! | `TRACELAB_SEMESTER_DIR` | `../shared/mit6837-semester` | assignments 3–7: `scenes/` (with their meshes), `commands.txt`, references |
//! | `TRACELAB_MESHES_DIR` | `../shared/meshes` | scanned meshes (cube, bunnies, dragon) |
//! | `TRACELAB_PERF_DIR` | `../shared/perf` | the benchmark scenes (`bench_*.txt`) |
//!
//! A relative value is taken from the workspace root, whatever folder cargo runs the test in.
//! Tests that read one are `#[ignore = "needs …"]`: a plain `cargo test` lists them as
//! ignored; `cargo test -- --ignored` runs them and they fail here, naming the variable,
//! when the folder is missing — never a skip.
//!
//! This one file is the only reader of these settings: core's unit tests include it from
//! `lib.rs`, core's and app's integration tests from their `common` module (`#[path]`).

use std::path::{Path, PathBuf};

/// The course's files: `scenes/`, `commands.txt`, `reference/`.
pub fn course_dir() -> PathBuf {
    required(
        "TRACELAB_COURSE_DIR",
        "../shared/mit6837",
        "the course's files (scenes, commands.txt, reference images)",
    )
}

/// The course's later assignments (3 to 7): `scenes/` with their meshes, `commands.txt`,
/// `reference/`. Scenes of assignments 5–7 use features tracelab does not read (yet).
pub fn semester_dir() -> PathBuf {
    required(
        "TRACELAB_SEMESTER_DIR",
        "../shared/mit6837-semester",
        "the course's assignment 3-7 files (scenes, commands.txt, reference images)",
    )
}

/// The scanned meshes: `cube.obj`, `bunny_1k.obj`, `stanford-bunny.obj`, `dragon_vrip.obj`.
pub fn meshes_dir() -> PathBuf {
    required(
        "TRACELAB_MESHES_DIR",
        "../shared/meshes",
        "the scanned meshes (cube, bunnies, dragon)",
    )
}

/// The benchmark scenes `bench_*.txt` (their meshes are in the meshes folder beside it).
pub fn perf_dir() -> PathBuf {
    required(
        "TRACELAB_PERF_DIR",
        "../shared/perf",
        "the benchmark scenes (bench_*.txt)",
    )
}

/// The folder `var` names (else `default`), relative to the workspace root; a missing one
/// fails the test, saying what it needed and how to point to it.
fn required(var: &str, default: &str, what: &str) -> PathBuf {
    // Both crates sit one folder below the workspace root.
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let set = std::env::var_os(var).filter(|v| !v.is_empty());
    // `join` keeps an absolute value as it is.
    let dir = root.join(set.as_deref().unwrap_or(default.as_ref()));
    assert!(
        dir.is_dir(),
        "{} is missing: this test needs {what}; set {var} to their folder \
         (default {default}, from the workspace root)",
        dir.display()
    );
    dir
}
