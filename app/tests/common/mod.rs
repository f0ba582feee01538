//! Shared by the app's integration tests.

/// Libtest swallows `eprintln!` from passing tests, and a skip must be seen: write to the
/// process's stderr directly.
pub fn skip_note(msg: &str) {
    use std::io::Write as _;
    let _ = writeln!(std::io::stderr(), "{msg}");
}
