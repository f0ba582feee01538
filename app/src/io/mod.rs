//! Files in and out, for the command line and the editor alike: scene files read with
//! their meshes, outputs written atomically ([`write_atomic`]), images encoded
//! ([`write_image`]), standard output written with its errors checked and user text escaped
//! ([`write_stdout`], [`write_stdout_text`]), and the output policy every command's files go
//! through first ([`OutputPlan`]).

mod atomic;
mod image;
pub mod output;
mod stdout;

use std::path::{Path, PathBuf};

use tracelab_core::{MeshCache, Scene, Severity};

pub use atomic::{AtomicFile, write_atomic};
pub use image::{ImageWriteError, encode_image, image_format, write_image};
pub use output::{Implicit, OutputError, OutputPlan, write_implicit};
pub use stdout::{
    escape_json, escape_text, write_stderr_text, write_stdout, write_stdout_text,
    write_summary_text,
};

/// A scene file as read, before it replaces the document: on any thread, so that a large
/// mesh cannot freeze the window, and before asking about unsaved changes, so that nothing
/// is asked when the file cannot be opened.
pub struct SceneRead {
    pub path: PathBuf,
    /// The scene, or the errors that kept it from opening.
    pub outcome: Result<Opened, Vec<String>>,
    /// The mesh cache the read used (a copy of the document's plus what it loaded).
    pub cache: MeshCache,
}

pub struct Opened {
    pub scene: Scene,
    /// Warnings and per-node errors, `file:line:col: message`, each with its severity.
    pub messages: Vec<(Severity, String)>,
    /// Comments that saving would drop (see `Document::save_warnings`).
    pub lost_comments: Vec<String>,
}

/// Reads and parses a scene file with its meshes.
pub fn read_scene_file(path: &Path, mut cache: MeshCache) -> SceneRead {
    let out = tracelab_core::load_scene(path, &mut cache);
    let messages = out
        .diagnostics
        .0
        .iter()
        .map(|d| (d.severity, d.to_string()));
    let lost_comments = out.lost_comments.iter().map(|d| d.to_string()).collect();
    let outcome = match out.scene {
        Some(scene) => Ok(Opened {
            scene,
            messages: messages.collect(),
            lost_comments,
        }),
        None => Err(messages.map(|(_, m)| m).collect()),
    };
    SceneRead {
        path: path.to_path_buf(),
        outcome,
        cache,
    }
}

/// Reads a scene (`None`: the built-in one) for the command line, printing its warnings to
/// standard error; errors come back as one message.
pub fn load_scene(path: Option<&Path>) -> anyhow::Result<Scene> {
    load_scene_and_meshes(path).map(|(scene, _)| scene)
}

/// As [`load_scene`], also giving the OBJ files it read (canonical paths), so that no output
/// of the command replaces one of them ([`OutputPlan::reads`]).
pub fn load_scene_and_meshes(path: Option<&Path>) -> anyhow::Result<(Scene, Vec<PathBuf>)> {
    let read = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
    let mut cache = MeshCache::new();
    let seen = read.clone();
    cache.set_observer(Some(std::sync::Arc::new(
        move |e: tracelab_core::MeshEvent<'_>| {
            if let tracelab_core::MeshEvent::Reading { path, .. } = e
                && let Ok(mut v) = seen.lock()
            {
                v.push(path.to_path_buf());
            }
            true
        },
    )));
    let outcome = match path {
        Some(p) => tracelab_core::load_scene(p, &mut cache),
        None => tracelab_core::parse_scene(
            crate::DEFAULT_SCENE.as_bytes(),
            crate::DEFAULT_SCENE_NAME,
            None,
            &mut cache,
        ),
    };
    let scene = warn_or_fail(outcome)?;
    let meshes = read.lock().map(|v| v.clone()).unwrap_or_default();
    Ok((scene, meshes))
}

/// Reads a scene without loading its meshes (for `fmt`, which rewrites the text and needs
/// no OBJ file), printing its warnings to standard error.
pub fn load_scene_text(path: &Path) -> anyhow::Result<Scene> {
    warn_or_fail(tracelab_core::load_scene_unresolved(path))
}

fn warn_or_fail(outcome: tracelab_core::ParseOutcome) -> anyhow::Result<Scene> {
    match outcome.into_result() {
        Ok((scene, warnings)) => {
            for w in warnings.warnings() {
                write_stderr_text(&format!("{w}\n"));
            }
            Ok(scene)
        }
        Err(diags) => Err(anyhow::Error::msg(diags.to_string())),
    }
}
