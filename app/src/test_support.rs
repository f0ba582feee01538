//! Helpers shared by the unit tests of app/ (the integration tests have `tests/common`).

use std::path::{Path, PathBuf};

/// An empty folder of the system's temporary folder, private to this test process:
/// `tracelab-{area}-{pid}-{name}`, emptied first.
pub fn temp_dir(area: &str, name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("tracelab-{area}-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

/// The names in a folder, sorted (to see that nothing else was left there).
pub fn names_in(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .expect("read dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().to_string())
        .collect();
    v.sort();
    v
}

/// A private device node (character device 1, `minor`: 3 null, 7 full) in `dir`, never the
/// machine's own /dev files; the test needs root (it fails, saying so, where mknod is
/// refused). Also the integration tests' (`tests/common` includes this file).
#[cfg(unix)]
pub fn mknod(dir: &Path, name: &str, minor: u32) -> PathBuf {
    let p = dir.join(name);
    let ok = std::process::Command::new("mknod")
        .arg(&p)
        .args(["c", "1", &minor.to_string()])
        .status()
        .is_ok_and(|s| s.success());
    assert!(ok, "mknod {} failed: this test needs root", p.display());
    p
}
