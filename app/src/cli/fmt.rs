//! `tracelab fmt`: a scene file rewritten in canonical form.

use std::path::{Path, PathBuf};

use crate::io::{load_scene_text, write_stdout};

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
            eprintln!("{}: warning: {w}", out.display());
        }
    }
    let text = tracelab_core::write_scene(&s);
    // Deep nesting makes the canonical text longer than its source: refuse what could not
    // be opened again, rather than write it.
    tracelab_core::format::check_reads_back(&text)
        .map_err(|e| anyhow::anyhow!("{}: not rewritten: {e}", scene.display()))?;
    match output {
        None => write_stdout(text.as_bytes()),
        Some(out) => crate::io::write_atomic(out, text.as_bytes())
            .map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", out.display())),
    }
}
