//! `tracelab fmt`: a scene file rewritten in canonical form.

use std::ffi::OsString;
use std::path::{Path, PathBuf};

use tracelab_core::NodeKind;

use crate::io::{OutputError, OutputPlan, load_scene_text, write_stderr_text, write_stdout};

/// Warnings (comments that cannot be kept) go to stderr before anything is written. OBJ
/// files are not opened: the text is all `fmt` rewrites.
///
/// `-o` never names the scene itself (the comments `fmt` cannot keep would be lost with no
/// copy left) or one of its OBJ files: see `crate::io::output`.
pub(super) fn run_fmt(scene: &Path, output: Option<&Path>) -> anyhow::Result<()> {
    let mut plan = OutputPlan::new();
    if let Some(out) = output {
        plan.reads(scene).writes(out);
        plan.check().map_err(OutputError::into_cli)?;
    }
    let mut s = load_scene_text(scene)?;
    if let Some(out) = output {
        // The meshes are not read, but the scene names them: looked for beside it, then in
        // the current folder (as `resolve_obj_path` does).
        let beside = scene.parent().unwrap_or(Path::new(""));
        for (_, node) in s.graph.iter() {
            if let NodeKind::TriangleMesh { obj_file, .. } = &node.kind {
                plan.names(&beside.join(obj_file))
                    .names(Path::new(obj_file));
            }
        }
        plan.check().map_err(OutputError::into_cli)?;
        let dir = |p: &Path| {
            p.parent()
                .map_or_else(|| PathBuf::from("."), Path::to_path_buf)
        };
        for w in tracelab_core::rebase_mesh_paths(&mut s, &dir(scene), &dir(out)) {
            write_stderr_text(&format!("{}: warning: {w}\n", out.display()));
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

/// `-oFILE` run together is refused (exit 2) among `fmt`'s arguments (`args` from the
/// command's name on): clap reads a course flag given to `fmt` by mistake, `-object_rays`,
/// as `-o bject_rays`, and `fmt` wrote a file of that name and printed nothing (the CLI fuzz
/// run found it). `-o FILE`, `-o=FILE` and `--output FILE` are unambiguous and accepted.
pub(super) fn refuse_run_on_output(args: &[OsString]) -> anyhow::Result<()> {
    for a in args {
        let b = a.as_encoded_bytes();
        if b == b"--" {
            break;
        }
        if let Some(rest) = b.strip_prefix(b"-o")
            && !rest.is_empty()
            && rest[0] != b'='
        {
            let (arg, file) = (a.to_string_lossy(), String::from_utf8_lossy(rest));
            return Err(crate::exit::usage(format!(
                "\"{arg}\" would be read as `-o {file}` (write to a file named \"{file}\"); \
                 fmt has no option {arg}. To write to a file, put a space after -o: -o FILE"
            )));
        }
    }
    Ok(())
}
