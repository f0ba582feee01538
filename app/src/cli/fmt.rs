//! `tracelab fmt`: a scene file rewritten in canonical form.

use std::path::{Path, PathBuf};

use crate::io::{load_scene_text, write_stderr_text, write_stdout};

/// Warnings (comments that cannot be kept) go to stderr before anything is written. OBJ
/// files are not opened: the text is all `fmt` rewrites.
pub(super) fn run_fmt(scene: &Path, output: Option<&Path>) -> anyhow::Result<()> {
    let mut s = load_scene_text(scene)?;
    if let Some(out) = output {
        let dir = |p: &Path| {
            p.parent()
                .map_or_else(|| PathBuf::from("."), Path::to_path_buf)
        };
        for w in tracelab_core::rebase_mesh_paths(&mut s, &dir(scene), &dir(out)) {
            write_stderr_text(&format!("{}: warning: {w}\n", out.display()));
        }
    }
    let text = tracelab_core::write_scene(&s);
    match output {
        None => write_stdout(text.as_bytes()),
        Some(out) => crate::io::write_atomic(out, text.as_bytes())
            .map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", out.display())),
    }
}
