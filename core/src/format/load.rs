//! Reading a scene as the renderer and the editor need it: parse, then load the meshes.

use std::path::Path;

use super::obj::MeshCache;
use super::parser::{ParseOutcome, load_scene_unresolved, parse_scene_unresolved};
use super::resolve::resolve_meshes;

/// Reads and parses a scene file and loads its meshes; OBJ paths resolve against the file's
/// folder first.
pub fn load_scene(path: &Path, cache: &mut MeshCache) -> ParseOutcome {
    let mut out = load_scene_unresolved(path);
    resolve_meshes(&mut out, path.parent(), cache);
    out
}

/// Parses scene text and loads its meshes. `name` is used in messages; `base_dir` is where
/// OBJ files are looked for first (then the current folder).
pub fn parse_scene(
    bytes: &[u8],
    name: &str,
    base_dir: Option<&Path>,
    cache: &mut MeshCache,
) -> ParseOutcome {
    let mut out = parse_scene_unresolved(bytes, name);
    resolve_meshes(&mut out, base_dir, cache);
    out
}
