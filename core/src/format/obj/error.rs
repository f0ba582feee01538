//! Why an OBJ file could not be loaded.

use std::path::PathBuf;

/// The message of a mesh load stopped by its observer.
pub const MESH_LOAD_CANCELLED: &str = "loading cancelled";

/// Why an OBJ file could not be loaded. Each says what a user can act on; `Display` is
/// the message shown on the TriangleMesh node.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ObjError {
    /// No file of that name in any folder tried (named in the message).
    #[error("file not found (looked in {})", tried.join(" and "))]
    NotFound { tried: Vec<String> },
    /// Something other than a regular file stands there: a folder, a FIFO, a device, a link
    /// loop (`what` says which, as "is a folder, not an OBJ file").
    #[error("{} {what}", path.display())]
    NotAFile { path: PathBuf, what: String },
    /// The operating system refused (permissions, I/O error).
    #[error("{0}")]
    Io(String),
    #[error("the file is larger than {limit_mib} MiB, the most tracelab reads as an OBJ mesh")]
    TooLarge { limit_mib: usize },
    /// More triangles (after splitting polygons) than a mesh's BVH can hold.
    #[error("the mesh has {count} triangles, more than the {limit} tracelab can trace")]
    TooManyTriangles { count: usize, limit: usize },
    /// The text is not a mesh tracelab can use; the message names the line where it can.
    #[error("{0}")]
    Syntax(String),
    /// Stopped by the [`super::MeshObserver`].
    #[error("{MESH_LOAD_CANCELLED}")]
    Cancelled,
}

impl From<std::io::Error> for ObjError {
    fn from(e: std::io::Error) -> Self {
        ObjError::Io(e.to_string())
    }
}
