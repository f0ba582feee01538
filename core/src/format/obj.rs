//! Loading OBJ meshes (polygons triangulated; v, v/vt, v//vn, v/vt/vn faces), shared by path
//! so a mesh used twice is read and its BVH built once. Plain files go through a fast parallel
//! reader; anything it does not understand goes to `tobj`, the reference.

mod error;
mod fast;
mod file_kind;
mod locate;

pub use error::{MESH_LOAD_CANCELLED, ObjError};

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::SystemTime;

use glam::Vec3;

use crate::accel::MAX_TRIANGLES;
use crate::scene::Mesh;
use file_kind::{FileKind, file_kind, open_regular};

/// The largest OBJ file read: 15 times the 871k-triangle dragon. Bigger files would need
/// several times their size in memory for parsing and the BVH.
pub const MAX_OBJ_BYTES: usize = 512 << 20;

/// Resolves `obj_file` against the scene's folder first, then the current folder. The first
/// candidate that exists decides: a folder, FIFO, device or symlink loop there is reported
/// as what it is, not skipped as "not found".
///
/// The current-folder fallback stays for the course's command lines, which open OBJ files
/// relative to the working directory (`raytracer -input ../scenes/x.txt` run from the folder
/// holding the mesh). It cannot mask a saved path: the scene's own folder is tried first,
/// Save As and `fmt -o` rewrite relative paths against that folder alone
/// ([`crate::format::rebase_mesh_paths`]), and the parser warns whenever the fallback is used.
pub fn resolve_obj_path(name: &str, base_dir: Option<&Path>) -> Result<PathBuf, ObjError> {
    let mut tried = Vec::new();
    let mut candidates = Vec::new();
    if let Some(dir) = base_dir {
        candidates.push(dir.join(name));
        tried.push(if dir.as_os_str().is_empty() {
            ".".to_string()
        } else {
            dir.display().to_string()
        });
    }
    candidates.push(PathBuf::from(name));
    tried.push("the current folder".to_string());
    for p in candidates {
        match file_kind(&p) {
            FileKind::Missing => continue,
            FileKind::Regular => return Ok(p),
            other => {
                return Err(ObjError::NotAFile {
                    path: p,
                    what: other.describe(),
                });
            }
        }
    }
    Err(ObjError::NotFound { tried })
}

/// Meshes already loaded, by canonical path; reused while the file is unchanged on disk.
/// Cloning is cheap (the meshes are shared), so a load on another thread can start from a
/// copy while the original stays in use.
#[derive(Clone, Default)]
pub struct MeshCache {
    meshes: HashMap<PathBuf, (Option<SystemTime>, u64, Arc<Mesh>)>,
    observer: Option<MeshObserver>,
}

/// Told before each step of reading an OBJ file from disk (meshes served from the cache are
/// not reported), for a progress display. Returning `false` stops that load: it fails with
/// [`ObjError::Cancelled`], and so does every later one, at once.
pub type MeshObserver = Arc<dyn Fn(MeshEvent<'_>) -> bool + Send + Sync>;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshEvent<'a> {
    /// About to read `path`, `bytes` long.
    Reading { path: &'a Path, bytes: u64 },
    /// Read; about to parse its text.
    Parsing { path: &'a Path },
    /// Parsed; about to build the BVH over `triangles` triangles (the longest step).
    Building { path: &'a Path, triangles: usize },
    /// Done with `path`, loaded or failed.
    Done { path: &'a Path },
}

impl std::fmt::Debug for MeshCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MeshCache")
            .field("meshes", &self.meshes.len())
            .field("observed", &self.observer.is_some())
            .finish()
    }
}

impl MeshCache {
    pub fn new() -> Self {
        Self::default()
    }

    /// Reports each step of each mesh read from disk to `observer` (see [`MeshObserver`]).
    pub fn set_observer(&mut self, observer: Option<MeshObserver>) {
        self.observer = observer;
    }

    pub fn load(&mut self, path: &Path) -> Result<Arc<Mesh>, ObjError> {
        let canon = path.canonicalize().unwrap_or_else(|_| path.to_path_buf());
        let meta = std::fs::metadata(&canon)?;
        let stamp = (meta.modified().ok(), meta.len());
        if let Some((t, len, m)) = self.meshes.get(&canon)
            && (*t, *len) == stamp
        {
            return Ok(m.clone());
        }
        let observer = self.observer.clone();
        let go_on = |e: MeshEvent<'_>| observer.as_ref().is_none_or(|o| o(e));
        let loaded = (|| {
            if !go_on(MeshEvent::Reading {
                path: &canon,
                bytes: meta.len(),
            }) {
                return Err(ObjError::Cancelled);
            }
            let bytes = read_obj_bytes(&canon)?;
            if !go_on(MeshEvent::Parsing { path: &canon }) {
                return Err(ObjError::Cancelled);
            }
            let (positions, triangles) = parse_obj_triangles(&bytes, &file_name(&canon))?;
            drop(bytes);
            if !go_on(MeshEvent::Building {
                path: &canon,
                triangles: triangles.len(),
            }) {
                return Err(ObjError::Cancelled);
            }
            Ok(Mesh::new(positions, triangles))
        })();
        go_on(MeshEvent::Done { path: &canon });
        let mesh = Arc::new(loaded?);
        self.meshes.insert(canon, (stamp.0, stamp.1, mesh.clone()));
        Ok(mesh)
    }

    /// Forgets a path so the next load reads it again.
    pub fn forget(&mut self, path: &Path) {
        let canon = path.canonicalize().unwrap_or_else(|_| path.to_path_buf());
        self.meshes.remove(&canon);
    }
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_default()
}

/// Reads one OBJ file into a single mesh (all its objects and groups together). Only regular
/// files are read (a FIFO is never opened), at most `MAX_OBJ_BYTES` of them.
pub fn load_obj(path: &Path) -> Result<Mesh, ObjError> {
    let bytes = read_obj_bytes(path)?;
    parse_obj(&bytes, &file_name(path))
}

/// The bytes of an OBJ file: a regular file only, at most `MAX_OBJ_BYTES`.
fn read_obj_bytes(path: &Path) -> Result<Vec<u8>, ObjError> {
    use std::io::Read as _;
    let file = open_regular(path)?;
    let mut bytes = Vec::new();
    file.take(MAX_OBJ_BYTES as u64 + 1)
        .read_to_end(&mut bytes)?;
    if bytes.len() > MAX_OBJ_BYTES {
        return Err(ObjError::TooLarge {
            limit_mib: MAX_OBJ_BYTES >> 20,
        });
    }
    Ok(bytes)
}

/// Parses OBJ text (`name` is used in messages): the fast reader when it understands the
/// file, else tobj.
pub fn parse_obj(bytes: &[u8], name: &str) -> Result<Mesh, ObjError> {
    let (positions, triangles) = parse_obj_triangles(bytes, name)?;
    Ok(Mesh::new(positions, triangles))
}

/// Positions and triangles of OBJ text, checked, before the BVH is built.
fn parse_obj_triangles(bytes: &[u8], name: &str) -> Result<(Vec<Vec3>, Vec<[u32; 3]>), ObjError> {
    parse_obj_triangles_up_to(bytes, name, MAX_TRIANGLES)
}

/// `parse_obj_triangles` with at most `limit` triangles: a polygon of n corners is n - 2
/// triangles, so even a file under `MAX_OBJ_BYTES` can hold more than the BVH takes.
fn parse_obj_triangles_up_to(
    bytes: &[u8],
    name: &str,
    limit: usize,
) -> Result<(Vec<Vec3>, Vec<[u32; 3]>), ObjError> {
    let bytes = without_bom(bytes);
    let (positions, triangles) = match fast::parse(bytes) {
        Some(r) => r,
        None => load_with_tobj(bytes, name)?,
    };
    if positions.iter().any(|p| !p.is_finite()) {
        return Err(ObjError::Syntax(locate::non_finite_vertex(bytes, name)));
    }
    if triangles.len() > limit {
        return Err(ObjError::TooManyTriangles {
            count: triangles.len(),
            limit,
        });
    }
    Ok((positions, triangles))
}

/// The text after a UTF-8 byte-order mark, which some editors on Windows put first. Read
/// as text it would make the first line's keyword "\u{feff}v", which both readers skip as
/// unknown: the first vertex lost and every face shifted by one.
fn without_bom(bytes: &[u8]) -> &[u8] {
    bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes)
}

/// Positions and triangles as the fast reader gives them, or None when it defers to tobj.
pub fn parse_obj_fast(bytes: &[u8]) -> Option<(Vec<Vec3>, Vec<[u32; 3]>)> {
    fast::parse(without_bom(bytes))
}

/// The reference reader: every OBJ feature tobj knows, all objects and groups merged.
/// `mtllib` files are never opened: tracelab shades with the scene's materials, and a
/// material library could be a FIFO or a device. Its errors are told as
/// `name:LINE: what is wrong`, found by reading the text again with tobj's rules.
pub fn load_with_tobj(bytes: &[u8], name: &str) -> Result<(Vec<Vec3>, Vec<[u32; 3]>), ObjError> {
    let bytes = without_bom(bytes);
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let no_materials = |_: &Path| -> tobj::MTLLoadResult { Err(tobj::LoadError::OpenFileFailed) };
    let refused = |e: &tobj::LoadError| {
        ObjError::Syntax(
            locate::tobj_refusal(bytes, name).unwrap_or_else(|| locate::unlocated(e, name)),
        )
    };
    let (models, _materials) =
        tobj::load_obj_buf(&mut &bytes[..], &opts, no_materials).map_err(|e| refused(&e))?;
    let mut positions: Vec<Vec3> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    for m in &models {
        let base = positions.len() as u32;
        positions.extend(
            m.mesh
                .positions
                .chunks_exact(3)
                .map(|p| Vec3::new(p[0], p[1], p[2])),
        );
        let nv = positions.len() as u32;
        for t in m.mesh.indices.chunks_exact(3) {
            let tri = [t[0] + base, t[1] + base, t[2] + base];
            if tri.iter().any(|&i| i >= nv) {
                return Err(refused(&tobj::LoadError::FaceVertexOutOfBounds));
            }
            triangles.push(tri);
        }
    }
    Ok((positions, triangles))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(name: &str, text: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("tracelab-obj-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let p = dir.join(name);
        std::fs::write(&p, text).expect("write");
        p
    }

    #[test]
    fn a_mesh_of_more_triangles_than_the_bvh_holds_is_an_error() {
        // A pentagon and a triangle: 4 triangles, on both readers.
        let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 2 0\nf 1 2 3 4 5\nf 1 2 3\n";
        let fast = parse_obj_fast(text.as_bytes()).expect("the fast reader's file");
        assert_eq!(fast.1.len(), 4);
        let tobj = load_with_tobj(text.as_bytes(), "fan.obj").expect("tobj reads it");
        assert_eq!(tobj.1.len(), 4);
        assert!(parse_obj_triangles_up_to(text.as_bytes(), "fan.obj", 4).is_ok());
        let e = parse_obj_triangles_up_to(text.as_bytes(), "fan.obj", 3)
            .expect_err("4 triangles are over a limit of 3");
        assert_eq!(e, ObjError::TooManyTriangles { count: 4, limit: 3 });
        assert_eq!(
            e.to_string(),
            "the mesh has 4 triangles, more than the 3 tracelab can trace"
        );
    }

    #[test]
    fn quads_are_triangulated_and_slash_forms_accepted() {
        let p = write(
            "quad.obj",
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1 4//1\n",
        );
        let m = load_obj(&p).expect("load");
        assert_eq!(m.triangle_count(), 2);
    }

    #[test]
    fn the_cache_reports_each_step_and_an_observer_can_stop_a_load() {
        use std::sync::Mutex;
        let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
        let p = write("steps.obj", text);
        let seen = Arc::new(Mutex::new(Vec::new()));
        let stop_at_build = Arc::new(std::sync::atomic::AtomicBool::new(true));
        let (s, stop) = (seen.clone(), stop_at_build.clone());
        let mut cache = MeshCache::new();
        cache.set_observer(Some(Arc::new(move |e: MeshEvent<'_>| {
            let step = match e {
                MeshEvent::Reading { bytes, .. } => format!("reading {bytes}"),
                MeshEvent::Parsing { .. } => "parsing".into(),
                MeshEvent::Building { triangles, .. } => format!("building {triangles}"),
                MeshEvent::Done { .. } => "done".into(),
            };
            s.lock().expect("lock").push(step);
            !(stop.load(std::sync::atomic::Ordering::Relaxed)
                && matches!(e, MeshEvent::Building { .. }))
        })));
        assert_eq!(cache.load(&p).expect_err("stopped"), ObjError::Cancelled);
        let reading = format!("reading {}", text.len());
        assert_eq!(
            *seen.lock().expect("lock"),
            [reading.as_str(), "parsing", "building 2", "done"]
        );
        // A stopped load caches nothing: the next one reads the file again.
        stop_at_build.store(false, std::sync::atomic::Ordering::Relaxed);
        seen.lock().expect("lock").clear();
        assert_eq!(cache.load(&p).expect("loads").triangle_count(), 2);
        assert_eq!(seen.lock().expect("lock").len(), 4);
        // From the cache: nothing to report.
        seen.lock().expect("lock").clear();
        let copy = cache.clone();
        assert!(copy.clone().load(&p).is_ok());
        assert!(seen.lock().expect("lock").is_empty());
    }

    #[test]
    fn bad_face_reports_obj_line() {
        let p = write("bad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 7\n");
        let e = load_obj(&p).expect_err("must fail");
        assert!(e.to_string().contains("bad.obj:4"), "{e}");
    }

    /// The same triangles, as vertex positions, from the fast reader and from tobj.
    fn same_geometry(path: &Path) {
        let bytes = std::fs::read(path).expect("read");
        let (fp, ft) = fast::parse(&bytes).expect("fast reader accepts the file");
        let (tp, tt) = load_with_tobj(&bytes, "t.obj").expect("tobj");
        assert_eq!(ft.len(), tt.len(), "{}", path.display());
        for (k, (a, b)) in ft.iter().zip(&tt).enumerate() {
            let pa = a.map(|i| fp[i as usize]);
            let pb = b.map(|i| tp[i as usize]);
            assert_eq!(pa, pb, "{} triangle {k}", path.display());
        }
    }

    #[test]
    fn fast_reader_matches_tobj_on_polygons_and_slash_forms() {
        let p = write(
            "poly.obj",
            "# c\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 2 1e-3\nvn 0 0 1\nvt 0 0\ng a\n\
             f 1//1 2//1 3//1 4//1\ns off\nf 1/1/1 3/1/1 5/1/1\r\nf 5 4 3 2 1\n",
        );
        same_geometry(&p);
    }

    #[test]
    fn fast_reader_defers_to_tobj_on_what_it_does_not_know() {
        for (name, text) in [
            ("neg.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n"),
            ("later.obj", "v 0 0 0\nv 1 0 0\nf 1 2 3\nv 0 1 0\n"),
            ("w.obj", "v 0 0 0 1\nv 1 0 0 1\nv 0 1 0 1\nf 1 2 3\n"),
            ("line.obj", "v 0 0 0\nv 1 0 0\nl 1 2\n"),
        ] {
            assert!(fast::parse(text.as_bytes()).is_none(), "{name}");
        }
        // tobj still reads what the fast reader declines.
        let p = write("neg.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n");
        assert_eq!(load_obj(&p).expect("load").triangle_count(), 1);
    }

    #[test]
    #[ignore = "needs the scanned meshes: TRACELAB_MESHES_DIR, default ../shared/meshes"]
    fn fast_reader_matches_tobj_on_the_shared_meshes() {
        let dir = crate::test_data::meshes_dir();
        // The dragon takes tobj seconds in a debug build; the smaller meshes cover the format.
        for name in ["cube.obj", "bunny_1k.obj", "stanford-bunny.obj"] {
            same_geometry(&dir.join(name));
        }
    }

    /// A UTF-8 byte-order mark before the first `v` used to hide that vertex (the line's
    /// keyword read as "\u{feff}v"), shifting every face by one, exit 0. Both readers skip it.
    #[test]
    fn a_byte_order_mark_is_skipped_by_both_readers() {
        let plain = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 2 3 4\n";
        let with_bom = format!("\u{feff}{plain}");
        let want = parse_obj_triangles(plain.as_bytes(), "m.obj").expect("plain");
        assert_eq!(
            parse_obj_triangles(with_bom.as_bytes(), "m.obj").expect("with a BOM"),
            want
        );
        assert_eq!(parse_obj_fast(with_bom.as_bytes()), Some(want.clone()));
        // tobj's result as positions per triangle (it renumbers the vertices it uses).
        let corners = |(p, t): (Vec<Vec3>, Vec<[u32; 3]>)| -> Vec<[Vec3; 3]> {
            t.iter().map(|tri| tri.map(|i| p[i as usize])).collect()
        };
        assert_eq!(
            corners(load_with_tobj(with_bom.as_bytes(), "m.obj").expect("tobj")),
            corners(want)
        );
        // A file only tobj reads (relative indices), with a BOM.
        let relative = "\u{feff}v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n";
        let (p, t) = parse_obj_triangles(relative.as_bytes(), "m.obj").expect("tobj, BOM");
        assert_eq!(t.len(), 1);
        assert_eq!(t[0].map(|i| p[i as usize]), [Vec3::ZERO, Vec3::X, Vec3::Y]);
    }

    /// Every refusal is `m.obj:LINE: what is wrong` in tracelab's words, never tobj's
    /// ("color parse error" for a comment after a vertex, "face vertex out of bounds").
    #[test]
    fn every_refusal_names_its_line_in_our_words() {
        let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
        for (text, want) in [
            (
                format!("v 0 0 0 # origin\n{tri}f 1 2 3\n"),
                "m.obj:1: vertex \"v 0 0 0 # origin\" has 5 values: expected x y z, x y z w or x y z r g b (a # comment must be on a line of its own)",
            ),
            (
                format!("{tri}v 0 0\nf 1 2 3\n"),
                "m.obj:4: bad vertex \"v 0 0\": expected three numbers",
            ),
            (
                format!("{tri}v 0 0 0 0\nf 1 2 3\n"),
                "m.obj:4: vertex \"v 0 0 0 0\" has w = 0",
            ),
            (
                format!("{tri}vt 0\nf 1 2 3\n"),
                "m.obj:4: bad texture coordinate \"vt 0\": expected two numbers",
            ),
            (
                format!("{tri}vn 0 0 x\nf 1 2 3\n"),
                "m.obj:4: bad normal \"vn 0 0 x\": expected three numbers",
            ),
            (format!("{tri}f 1 2 x\n"), "m.obj:4: bad face index \"x\""),
            (
                format!("{tri}f 1 2 3/1/1/1\n"),
                "m.obj:4: bad face index \"3/1/1/1\": at most vertex/texture/normal",
            ),
            (format!("{tri}f\n"), "m.obj:4: face without vertices"),
            (
                format!("{tri}usemtl\nf 1 2 3\n"),
                "m.obj:4: usemtl without a material name",
            ),
            (
                format!("{tri}f 1 2 3\nf 1 2 4\ng next\nv 0 0 1\n"),
                "m.obj:5: face refers to vertex 4, but the file has only 3 vertices",
            ),
            (
                format!("{tri}f -1 -2 -4\n"),
                "m.obj:4: face refers to vertex -4, counting back past the first of the 3 vertices before it",
            ),
            (
                format!("{tri}f 0 1 2\n"),
                "m.obj:4: face refers to vertex \"0\": vertex indices start at 1",
            ),
            (
                format!("{tri}vt 0 0\nf 1/1 2/2 3/1\n"),
                "m.obj:5: face \"2/2\" refers to a texture coordinate that does not exist (the file has 1)",
            ),
            (
                format!("{tri}vn 0 0 1\nf 1//1 2//1 3//3\n"),
                "m.obj:5: face \"3//3\" refers to a normal that does not exist (the file has 1)",
            ),
            (
                "v 0 0 0 1 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".to_string(),
                "m.obj:4: face uses vertex 2, which has no colour while others have: give every vertex r g b, or none",
            ),
            (
                format!("{tri}f 1 2 3\n\u{ff}\n"),
                "m.obj:5: not a text OBJ file: bytes that are not UTF-8",
            ),
            (
                "v 1e39 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".to_string(),
                "m.obj:1: vertex \"v 1e39 0 0\" is not a finite number (f32 holds up to about 3.4e38)",
            ),
            (
                format!("{tri}v 1 1 1 1e-39\nf 1 2 4\n"),
                "m.obj:4: vertex \"v 1 1 1 1e-39\" is not a finite number (f32 holds up to about 3.4e38)",
            ),
        ] {
            // The \u{ff} case is bytes, not text.
            let bytes = text.replace('\u{ff}', "\u{1}").into_bytes();
            let bytes: Vec<u8> = bytes
                .iter()
                .map(|&b| if b == 1 { 0xff } else { b })
                .collect();
            let e = parse_obj(&bytes, "m.obj").expect_err(&text);
            assert_eq!(e.to_string(), want, "{text:?}");
        }
    }

    #[test]
    fn cache_shares_one_mesh() {
        let p = write("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
        let mut c = MeshCache::new();
        let a = c.load(&p).expect("a");
        let b = c.load(&p).expect("b");
        assert!(Arc::ptr_eq(&a, &b));
    }
}
