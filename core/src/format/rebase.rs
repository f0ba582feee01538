//! Keeping relative `obj_file` paths right when a scene is written into another folder.

use std::path::{Component, Path, PathBuf};

use crate::scene::{NodeKind, Scene};

/// Rewrites every relative `obj_file` so that, written into `to_dir`, it names the file it
/// named from `from_dir` (the folders of the file read and the file about to be written).
/// Relative where a relative path exists, absolute otherwise (another drive); unchanged when
/// the folder does not change. Only `from_dir` is consulted, never the current folder: a
/// mesh that is not next to the original scene is left as written and reported, because
/// rebasing it would only point somewhere it is not. Returns one warning per such mesh.
pub fn rebase_mesh_paths(scene: &mut Scene, from_dir: &Path, to_dir: &Path) -> Vec<String> {
    let (from, to) = (absolute_dir(from_dir), absolute_dir(to_dir));
    let mut warnings = Vec::new();
    if from == to {
        return warnings;
    }
    for id in scene.graph.preorder() {
        let Some(node) = scene.graph.get_mut(id) else {
            continue;
        };
        let NodeKind::TriangleMesh { obj_file, .. } = &mut node.kind else {
            continue;
        };
        let name = Path::new(obj_file.as_str());
        if name.is_absolute() {
            continue;
        }
        let target = from.join(name);
        if !target.is_file() {
            warnings.push(format!(
                "obj_file \"{obj_file}\" is not in {}, the folder of the scene read; it is written unchanged",
                from.display()
            ));
            continue;
        }
        // Relative if one exists and reaches the file (a symlinked folder can defeat the
        // lexical `..`); else absolute. Either must be one word of the scene format.
        let relative = relative_path(&normalize(&target), &to).filter(|r| to.join(r).is_file());
        let relative = relative.and_then(|r| portable(&r));
        let absolute = target.to_str().map(str::to_string);
        let written = [relative, absolute]
            .into_iter()
            .flatten()
            .find(|s| is_word(s));
        match written {
            Some(w) => *obj_file = w,
            None => warnings.push(format!(
                "obj_file \"{obj_file}\" cannot be written relative to {} as one word of the scene format; it is written unchanged",
                to.display()
            )),
        }
    }
    warnings
}

/// A relative path with `/` between its parts, which every platform reads, so a scene saved
/// on Windows still opens elsewhere.
fn portable(rel: &Path) -> Option<String> {
    let parts: Option<Vec<&str>> = rel.components().map(|c| c.as_os_str().to_str()).collect();
    parts.map(|p| p.join("/"))
}

/// Whether the lexer reads `s` back as a single word.
fn is_word(s: &str) -> bool {
    !s.is_empty()
        && !s
            .chars()
            .any(|c| c.is_whitespace() || matches!(c, '{' | '}' | '#'))
}

/// The folder as an absolute path without symlinks where it exists (so `..` means what the
/// file system means), else made absolute and normalized lexically. An empty path is `.`.
fn absolute_dir(dir: &Path) -> PathBuf {
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    dir.canonicalize().unwrap_or_else(|_| {
        normalize(&std::path::absolute(dir).unwrap_or_else(|_| dir.to_path_buf()))
    })
}

/// Drops `.` and folds `name/..` (lexically).
fn normalize(p: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in p.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                if !out.pop() {
                    out.push("..");
                }
            }
            c => out.push(c),
        }
    }
    out
}

/// `target` as seen from folder `base`, both absolute and normalized; `None` when they share
/// no root (another drive).
fn relative_path(target: &Path, base: &Path) -> Option<PathBuf> {
    let (t, b): (Vec<_>, Vec<_>) = (target.components().collect(), base.components().collect());
    if t.first() != b.first() {
        return None;
    }
    let common = t.iter().zip(&b).take_while(|(x, y)| x == y).count();
    let mut out: PathBuf = std::iter::repeat_n(Component::ParentDir, b.len() - common).collect();
    out.extend(&t[common..]);
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{MeshSlot, Node};

    #[test]
    fn relative_paths_climb_out_of_the_base_and_down_to_the_target() {
        let rel = |t: &str, b: &str| {
            relative_path(Path::new(t), Path::new(b)).map(|p| p.display().to_string())
        };
        assert_eq!(
            rel("/a/scenes/bunny.obj", "/a/scenes").as_deref(),
            Some("bunny.obj")
        );
        assert_eq!(
            rel("/a/scenes/bunny.obj", "/a/out/sub").as_deref(),
            Some("../../scenes/bunny.obj")
        );
        assert_eq!(
            rel("/a/scenes/m/bunny.obj", "/a").as_deref(),
            Some("scenes/m/bunny.obj")
        );
        assert_eq!(
            rel("/bunny.obj", "/x/y").as_deref(),
            Some("../../bunny.obj")
        );
        assert_eq!(normalize(Path::new("/a/b/../c/./d")), Path::new("/a/c/d"));
        // No common root (on Windows: another drive): no relative path, so it is written absolute.
        assert_eq!(rel("/a/bunny.obj", "b"), None);
        assert_eq!(
            portable(Path::new("../x/y.obj")).as_deref(),
            Some("../x/y.obj")
        );
    }

    fn scene_with_meshes(names: &[&str]) -> Scene {
        let mut scene = Scene::default();
        let root = scene.graph.root();
        for n in names {
            let kind = NodeKind::TriangleMesh {
                obj_file: n.to_string(),
                mesh: MeshSlot::Failed(String::new()),
            };
            let id = scene.graph.add(Node::new(kind));
            scene.graph.push_child(root, id);
        }
        scene
    }

    fn obj_files(scene: &Scene) -> Vec<String> {
        scene
            .graph
            .iter()
            .filter_map(|(_, n)| match &n.kind {
                NodeKind::TriangleMesh { obj_file, .. } => Some(obj_file.clone()),
                _ => None,
            })
            .collect()
    }

    fn temp_tree(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("tracelab-rebase-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(d.join("scenes/meshes")).expect("dirs");
        std::fs::create_dir_all(d.join("out/sub")).expect("dirs");
        std::fs::write(d.join("scenes/meshes/a.obj"), "v 0 0 0\n").expect("obj");
        std::fs::write(d.join("b.obj"), "v 0 0 0\n").expect("obj");
        d.canonicalize().expect("canonical")
    }

    #[test]
    fn mesh_paths_follow_the_scene_into_another_folder() {
        let d = temp_tree("move");
        let mut s = scene_with_meshes(&["meshes/a.obj", "../b.obj", "./meshes/../meshes/a.obj"]);
        let w = rebase_mesh_paths(&mut s, &d.join("scenes"), &d.join("out/sub"));
        assert!(w.is_empty(), "{w:?}");
        assert_eq!(
            obj_files(&s),
            [
                "../../scenes/meshes/a.obj",
                "../../b.obj",
                "../../scenes/meshes/a.obj"
            ]
        );
        // And back again.
        let w = rebase_mesh_paths(&mut s, &d.join("out/sub"), &d.join("scenes/./"));
        assert!(w.is_empty(), "{w:?}");
        assert_eq!(obj_files(&s), ["meshes/a.obj", "../b.obj", "meshes/a.obj"]);
    }

    #[test]
    fn same_folder_absolute_and_missing_paths_stay_as_written() {
        let d = temp_tree("keep");
        let abs = d.join("b.obj").display().to_string();
        let names = ["meshes/a.obj", abs.as_str(), "missing.obj"];
        let mut s = scene_with_meshes(&names);
        assert!(
            rebase_mesh_paths(&mut s, &d.join("scenes"), &d.join("scenes/meshes/..")).is_empty()
        );
        assert_eq!(obj_files(&s), names);
        let w = rebase_mesh_paths(&mut s, &d.join("scenes"), &d.join("out"));
        assert_eq!(
            obj_files(&s),
            ["../scenes/meshes/a.obj", abs.as_str(), "missing.obj"]
        );
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(w[0].contains("\"missing.obj\""), "{w:?}");
    }
}
