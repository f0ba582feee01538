//! Why the document could not be opened or saved. Each error's `Display` is the message the
//! editor shows (in its messages list) and the tests read.

use std::path::PathBuf;

/// The file could not be opened as a scene; the current document stays. One line per
/// diagnostic, `file:line:col: message`.
#[derive(Debug, thiserror::Error)]
#[error("{}", .0.join("\n"))]
pub struct OpenError(pub Vec<String>);

/// Nothing was written, and why.
#[derive(Debug, thiserror::Error)]
pub enum SaveError {
    #[error("the built-in scene has no file yet: use Save As")]
    NoFile,
    /// A node is incomplete or a rule is broken: what to fix, one line each.
    #[error("{}: not saved; first fix:\n{}", .path.display(), .fix.iter().map(|f| format!("  {f}")).collect::<Vec<_>>().join("\n"))]
    BreaksRules { path: PathBuf, fix: Vec<String> },
    /// The text would be longer than a scene file tracelab reads (deep nesting): written,
    /// it could not be opened again.
    #[error("{}: not saved: {source}", .path.display())]
    TooLarge {
        path: PathBuf,
        source: tracelab_core::format::TooLargeToReadBack,
    },
    /// The checked text would not read back as this document: a writer or parser bug.
    #[error("{}: not saved, because {why} (a tracelab bug; please report it)", .path.display())]
    WouldNotReadBack { path: PathBuf, why: String },
    #[error("{}: cannot write: {source}", .path.display())]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
}

/// An edit that does not fit the scene's structure (a stale id, an index out of range, a
/// move into its own subtree): nothing changed.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct Misfit(pub String);

impl From<String> for Misfit {
    fn from(s: String) -> Self {
        Misfit(s)
    }
}

impl From<&str> for Misfit {
    fn from(s: &str) -> Self {
        Misfit(s.to_string())
    }
}
