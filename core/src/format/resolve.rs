//! The step after parsing: load each TriangleMesh's OBJ file and check what needs the
//! geometry (a CSG operand must be closed). Kept apart from the parser, as pbrt keeps its
//! tokenizer apart from scene building, so that `tracelab fmt` and the checked writer read a
//! scene without opening a single mesh.

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use super::diagnostic::{Diagnostic, Severity, escape_controls};
use super::obj::{MeshCache, resolve_obj_path};
use super::parser::{Located, MAX_SHOWN, ParseOutcome, UnshownSummary};
use crate::scene::{MeshSlot, NodeKind, NotClosed, check_closed};

/// Loads every mesh `out` still lists, through `cache`, relative to `base_dir` first (then
/// the current folder), and reports what fails at the file name's location. A mesh that
/// cannot be loaded leaves the scene usable: its node becomes [`MeshSlot::Failed`] and
/// renders nothing. Running it twice does nothing the second time.
pub fn resolve_meshes(out: &mut ParseOutcome, base_dir: Option<&Path>, cache: &mut MeshCache) {
    // Go on counting within the parser's cap: its "… and N more" lines are rewritten at the end.
    let u = std::mem::take(&mut out.unshown);
    let kept = out.diagnostics.0.len() - u.summaries.min(out.diagnostics.0.len());
    out.diagnostics.0.truncate(kept);
    let shown = |s: Severity| out.diagnostics.0.iter().filter(|d| d.severity == s).count();
    let mut report = Capped {
        shown: [shown(Severity::Error), shown(Severity::Warning)],
        unshown: [u.errors.0, u.warnings.0],
        first_unshown: [u.errors.1, u.warnings.1],
        ..Capped::default()
    };
    // Closedness per loaded mesh (by address), so a mesh used many times is checked once.
    let mut closed: HashMap<usize, Result<(), NotClosed>> = HashMap::new();
    for r in std::mem::take(&mut out.meshes) {
        let name = &r.obj_file;
        let slot = match resolve_obj_path(name, base_dir).and_then(|path| cache.load(&path)) {
            Ok(mesh) => {
                if let Some(dir) = base_dir.filter(|d| !d.join(name).is_file()) {
                    let dir = if dir.as_os_str().is_empty() {
                        ".".to_string()
                    } else {
                        dir.display().to_string()
                    };
                    report.push(Severity::Warning, &r.at, format!("OBJ file \"{name}\" is not in the scene's folder ({dir}); using the one in the current folder"));
                }
                if mesh.triangle_count() == 0 {
                    report.push(
                        Severity::Warning,
                        &r.at,
                        format!("OBJ file \"{name}\" has no triangles"),
                    );
                }
                for (op, at) in &r.operand_of {
                    let key = Arc::as_ptr(&mesh) as usize;
                    if let Err(why) = closed.entry(key).or_insert_with(|| check_closed(&mesh)) {
                        let op = op.name();
                        report.push(
                            Severity::Error,
                            at,
                            format!("TriangleMesh \"{name}\" is not a closed solid, so it cannot be an operand of {op}: {why}"),
                        );
                    }
                }
                MeshSlot::Loaded(mesh)
            }
            Err(msg) => {
                report.push(
                    Severity::Error,
                    &r.at,
                    format!("cannot load OBJ file \"{name}\": {msg}"),
                );
                MeshSlot::Failed(msg.to_string())
            }
        };
        if let Some(NodeKind::TriangleMesh { mesh, .. }) = out
            .scene
            .as_mut()
            .and_then(|s| s.graph.get_mut(r.node))
            .map(|n| &mut n.kind)
        {
            *mesh = slot;
        }
    }
    let (diags, unshown) = report.finish();
    out.diagnostics.0.extend(diags);
    out.unshown = unshown;
}

/// At most `MAX_SHOWN` errors and as many warnings, then "… and N more", as the parser
/// reports: a scene of a million meshes that are all missing prints a screenful.
#[derive(Default)]
struct Capped {
    new: Vec<Diagnostic>,
    /// Per severity (errors, warnings): shown so far, counted but not shown, and where the
    /// first of those stands.
    shown: [usize; 2],
    unshown: [usize; 2],
    first_unshown: [Option<Located>; 2],
}

impl Capped {
    fn push(&mut self, severity: Severity, at: &Located, message: String) {
        let k = usize::from(severity == Severity::Warning);
        if self.shown[k] < MAX_SHOWN {
            self.shown[k] += 1;
            self.new.push(diagnostic(severity, at, &message));
        } else {
            self.unshown[k] += 1;
            self.first_unshown[k].get_or_insert_with(|| at.clone());
        }
    }

    fn finish(mut self) -> (Vec<Diagnostic>, UnshownSummary) {
        let mut summary = UnshownSummary::default();
        for (k, (severity, what)) in [(Severity::Error, "error"), (Severity::Warning, "warning")]
            .into_iter()
            .enumerate()
        {
            let n = self.unshown[k];
            if let Some(at) = self.first_unshown[k].clone().filter(|_| n > 0) {
                let s = if n == 1 { "" } else { "s" };
                self.new.push(diagnostic(
                    severity,
                    &at,
                    &format!("… and {n} more {what}{s}"),
                ));
                summary.summaries += 1;
                match severity {
                    Severity::Error => summary.errors = (n, Some(at)),
                    Severity::Warning => summary.warnings = (n, Some(at)),
                }
            }
        }
        (self.new, summary)
    }
}

fn diagnostic(severity: Severity, at: &Located, message: &str) -> Diagnostic {
    let message = escape_controls(message).into_owned();
    Diagnostic {
        severity,
        file: at.file.clone(),
        line: at.line,
        col: at.col,
        message,
    }
}
