//! A case's folder and what a case may change in it. The folder holds work/ (the current
//! folder: inputs, planted links, FIFOs and device nodes), outside/ (what no case may change
//! unless a line names it as an output), home/ (HOME, XDG_RUNTIME_DIR) and log/ (standard
//! output and error; not checked). A snapshot before and after, and what the arguments name,
//! decide which changes were allowed.

use std::collections::{BTreeMap, BTreeSet};
use std::ffi::{OsStr, OsString};
use std::os::unix::ffi::OsStrExt;
use std::os::unix::fs::{FileTypeExt, MetadataExt};
use std::path::{Path, PathBuf};

use super::generate::{Case, Family, Role};
/// Files shared by every case, made once.
pub struct Fixture {
    files: Vec<(&'static str, Vec<u8>)>,
}

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn png(width: u32, height: u32, seed: u8) -> Vec<u8> {
    let img = image::RgbImage::from_fn(width, height, |x, y| {
        image::Rgb([(x * 31) as u8 ^ seed, (y * 17) as u8, seed.wrapping_mul(7)])
    });
    let mut bytes = Vec::new();
    img.write_to(
        &mut std::io::Cursor::new(&mut bytes),
        image::ImageFormat::Png,
    )
    .expect("encode png");
    bytes
}

fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = (crc >> 1) ^ (0xedb8_8320 & (crc & 1).wrapping_neg());
        }
    }
    !crc
}

fn png_chunk(out: &mut Vec<u8>, kind: &[u8; 4], data: &[u8]) {
    out.extend_from_slice(&(data.len() as u32).to_be_bytes());
    let start = out.len();
    out.extend_from_slice(kind);
    out.extend_from_slice(data);
    let crc = crc32(&out[start..]);
    out.extend_from_slice(&crc.to_be_bytes());
}

/// A small PNG whose header claims 13000×13000 RGB (507 MB decoded): a decoder that trusts the
/// header allocates it all before finding the data cut short.
fn png_bomb() -> Vec<u8> {
    let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut ihdr = Vec::new();
    ihdr.extend_from_slice(&13000u32.to_be_bytes());
    ihdr.extend_from_slice(&13000u32.to_be_bytes());
    ihdr.extend_from_slice(&[8, 2, 0, 0, 0]);
    png_chunk(&mut out, b"IHDR", &ihdr);
    // zlib header, then a stored block of 1000 zero bytes that ends the data early.
    let mut idat = vec![0x78, 0x01, 0x00, 0xe8, 0x03, 0x17, 0xfc];
    idat.extend(std::iter::repeat_n(0u8, 1000));
    png_chunk(&mut out, b"IDAT", &idat);
    out
}

const SMALL_SCENE_HEAD: &str = "PerspectiveCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 angle 30 }
Lights { numLights 1 DirectionalLight { direction -0.5 -0.5 -1 color 0.9 0.9 0.9 } }
Background { color 0.1 0.1 0.2 ambientLight 0.1 0.1 0.1 }
Materials { numMaterials 2 Material { diffuseColor 0.9 0.3 0.2 } Material { diffuseColor 0.2 0.6 0.9 } }
";

fn small_scene(body: &str) -> Vec<u8> {
    format!("{SMALL_SCENE_HEAD}{body}\n").into_bytes()
}

fn mesh_scene(obj: &str) -> Vec<u8> {
    small_scene(&format!(
        "Group {{ numObjects 2 MaterialIndex 0 Transform {{ YRotate 30 TriangleMesh {{ obj_file {obj} }} }}
         MaterialIndex 1 Transform {{ Translate 2 0 0 Scale 0.5 0.5 0.5 TriangleMesh {{ obj_file icosphere.obj }} }} }}"
    ))
}

impl Fixture {
    pub fn new() -> Fixture {
        let read = |p: &str| std::fs::read(repo().join(p)).unwrap_or_else(|e| panic!("{p}: {e}"));
        // The project's own scenes, with their meshes moved beside them.
        let unassets = |b: Vec<u8>| {
            String::from_utf8(b)
                .expect("utf-8 scene")
                .replace("../assets/", "")
                .into_bytes()
        };
        let scene = unassets(read("scenes/default.txt"));
        let mut bom = b"\xef\xbb\xbf".to_vec();
        bom.extend_from_slice(&scene);
        let mut bom_obj = b"\xef\xbb\xbf".to_vec();
        bom_obj.extend_from_slice(&read("assets/cube.obj"));
        let mut deep = String::new();
        for _ in 0..200 {
            deep.push_str("Transform { Translate 0.001 0 0 ");
        }
        deep.push_str("Sphere { center 0 0 0 radius 1 }");
        for _ in 0..200 {
            deep.push_str(" }");
        }
        let files = vec![
            ("work/scene.txt", scene.clone()),
            ("work/sub/scene.txt", scene.clone()),
            // A scene with an image's name: `render scene.png -o scene.png` passes the
            // extension check and must still not write its input.
            ("work/scene.png", scene.clone()),
            ("outside/scene.txt", scene.clone()),
            ("work/hier.txt", unassets(read("scenes/hierarchy.txt"))),
            ("work/csg.txt", read("scenes/lecture/csg_union.txt")),
            ("work/cube.obj", read("assets/cube.obj")),
            ("work/icosphere.obj", read("assets/icosphere.obj")),
            ("work/bom.obj", bom_obj),
            ("work/mesh.txt", mesh_scene("cube.obj")),
            ("work/bommesh.txt", mesh_scene("bom.obj")),
            ("work/fifomesh.txt", mesh_scene("pipe.obj")),
            ("work/devmesh.txt", mesh_scene("zero_dev")),
            ("work/missingmesh.txt", mesh_scene("missing.obj")),
            (
                "work/ctl.txt",
                mesh_scene("cube\u{1b}[31m\u{7}.obj"),
            ),
            ("work/bom.txt", bom),
            ("work/bad.txt", b"Group { numObjects 2 Sphere { radius }".to_vec()),
            ("work/empty.txt", Vec::new()),
            (
                "work/flat.txt",
                small_scene("Group { numObjects 1 MaterialIndex 0 Box { min -1 -1 0 max 1 1 0 } }"),
            ),
            (
                "work/huge_tri.txt",
                small_scene(
                    "Group { numObjects 2 MaterialIndex 0 Triangle { vertex0 -3e9 -3e9 -1 vertex1 3e9 -3e9 -1 vertex2 0 3e9 -1 }
                     MaterialIndex 1 Triangle { vertex0 -1e19 -1e19 -2 vertex1 1e19 -1e19 -2 vertex2 0 3e38 -2 } }",
                ),
            ),
            ("work/deep.txt", small_scene(&format!("Group {{ numObjects 1 MaterialIndex 0 {deep} }}"))),
            ("work/mine.png", png(8, 8, 1)),
            ("work/mine_n.png", png(8, 8, 2)),
            ("work/old.png", png(4, 4, 3)),
            ("work/bomb.png", png_bomb()),
            ("work/mine.ppm", b"P6\n8 8\n255\n".iter().copied().chain(std::iter::repeat_n(7u8, 192)).collect()),
            ("work/-o.txt", scene.clone()),
            ("work/outdir/keep.txt", b"keep".to_vec()),
            ("outside/target.png", b"precious: not a png".to_vec()),
            ("outside/grades.csv", b"student,grade\nada,A\n".to_vec()),
            ("outside/dir/keep.txt", b"keep".to_vec()),
        ];
        Fixture { files }
    }
}

#[derive(Clone, Copy)]
pub struct Machine {
    /// Private device nodes can be made (root with CAP_MKNOD).
    pub nodes: bool,
}

pub fn mknod(path: &Path, kind: rustix::fs::FileType, dev: (u32, u32)) -> std::io::Result<()> {
    rustix::fs::mknodat(
        rustix::fs::CWD,
        path,
        kind,
        rustix::fs::Mode::from_raw_mode(0o666),
        rustix::fs::makedev(dev.0, dev.1),
    )
    .map_err(std::io::Error::from)
}

fn symlink(target: impl AsRef<Path>, link: &Path) {
    std::os::unix::fs::symlink(target, link).expect("symlink");
}

/// Lays out the case's folders. Optional plants (a bit each of `plants`): links where the
/// implicit outputs go, pointing out of the folder, and stale regular files there.
pub fn build(dir: &Path, fixture: &Fixture, plants: u64, machine: Machine) {
    for (rel, bytes) in &fixture.files {
        let p = dir.join(rel);
        std::fs::create_dir_all(p.parent().expect("parent")).expect("mkdir");
        std::fs::write(&p, bytes).expect("write fixture");
    }
    let w = dir.join("work");
    for d in ["home/run", "log", "work/sub/deeper"] {
        std::fs::create_dir_all(dir.join(d)).expect("mkdir");
    }
    std::fs::write(
        w.join(OsStr::from_bytes(b"sc\xe9ne.txt")),
        fixture_bytes(fixture, "work/scene.txt"),
    )
    .expect("write");
    std::fs::write(
        w.join("ctl\u{1b}[2J\u{7}.txt"),
        fixture_bytes(fixture, "work/scene.txt"),
    )
    .expect("write");
    // ctl.txt's mesh: control bytes in a name the commands print.
    std::fs::write(
        w.join("cube\u{1b}[31m\u{7}.obj"),
        fixture_bytes(fixture, "work/cube.obj"),
    )
    .expect("write");
    symlink("scene.txt", &w.join("link_scene.txt"));
    symlink("mine.png", &w.join("link_mine.png"));
    symlink("old.png", &w.join("link_old.png"));
    symlink("missing/x.png", &w.join("dangling.png"));
    symlink("missing.txt", &w.join("dangling.txt"));
    symlink("../outside/new_by_link.png", &w.join("dangling_out.png"));
    symlink("loop_b", &w.join("loop_a"));
    symlink("loop_a", &w.join("loop_b"));
    symlink("../outside/target.png", &w.join("to_outside.png"));
    symlink(dir.join("outside/target.png"), &w.join("abs_outside.png"));
    symlink("../outside", &w.join("to_outside_dir"));
    // Where the implicit names fall: links out of the folder, or stale files.
    let plant = |bit: u32, name: &str, target: &str| {
        if plants >> bit & 1 == 1 {
            symlink(target, &w.join(name));
        } else if plants >> (bit + 16) & 1 == 1 {
            std::fs::write(w.join(name), b"stale").expect("write");
        }
    };
    plant(0, "mine.diff.png", "../outside/grades.csv");
    plant(1, "mine_n.diff.png", "../outside/target.png");
    plant(2, "frame_0000.png", "../outside/grades.csv");
    plant(3, "frame.apng.png", "../outside/target.png");
    plant(4, "frame_0001.png", "../outside/dir/keep.txt");
    plant(5, "outdir/frame_0000.png", "../../outside/grades.csv");
    plant(6, "old.diff.png", "../outside/grades.csv");
    plant(7, "f.apng.png", "../outside/grades.csv");
    let fifo = rustix::fs::FileType::Fifo;
    for f in ["pipe.txt", "pipe.png", "pipe.obj"] {
        mknod(&w.join(f), fifo, (0, 0)).expect("mkfifo");
    }
    if machine.nodes {
        let chr = rustix::fs::FileType::CharacterDevice;
        // Private nodes of the kernel's null, zero and full devices, never the machine's /dev.
        for (name, dev) in [
            ("work/null_dev", (1, 3)),
            ("work/null.png", (1, 3)),
            ("work/zero_dev", (1, 5)),
            ("work/full_dev", (1, 7)),
            ("work/full.png", (1, 7)),
            ("log/stdout_full", (1, 7)),
        ] {
            mknod(&dir.join(name), chr, dev).expect("mknod");
        }
    }
}

pub fn fixture_bytes<'a>(f: &'a Fixture, rel: &str) -> &'a [u8] {
    f.files
        .iter()
        .find(|(r, _)| *r == rel)
        .map(|(_, b)| b.as_slice())
        .expect("fixture file")
}

// Snapshots: everything under the case's folder (except log/), never opening a FIFO or a
// device.

#[derive(Clone, PartialEq, Eq, Debug)]
pub enum Entry {
    Dir,
    File(Vec<u8>),
    /// A file too big to keep: its size and modification time.
    Big(u64, i64, i64),
    Link(PathBuf),
    Fifo,
    Device(u64),
    Other,
}

pub type Snapshot = BTreeMap<PathBuf, Entry>;

pub fn snapshot(case_dir: &Path) -> Snapshot {
    let mut out = BTreeMap::new();
    walk(case_dir, Path::new(""), &mut out);
    out
}

fn walk(base: &Path, rel: &Path, out: &mut Snapshot) {
    let Ok(rd) = std::fs::read_dir(base.join(rel)) else {
        return;
    };
    for e in rd.flatten() {
        let r = rel.join(e.file_name());
        if r == Path::new("log") {
            continue;
        }
        let p = base.join(&r);
        let Ok(m) = std::fs::symlink_metadata(&p) else {
            continue;
        };
        let t = m.file_type();
        let entry = if t.is_symlink() {
            Entry::Link(std::fs::read_link(&p).unwrap_or_default())
        } else if t.is_dir() {
            walk(base, &r, out);
            Entry::Dir
        } else if t.is_file() {
            if m.len() > 1 << 20 {
                Entry::Big(m.len(), m.mtime(), m.mtime_nsec())
            } else {
                Entry::File(std::fs::read(&p).unwrap_or_default())
            }
        } else if t.is_fifo() {
            Entry::Fifo
        } else if t.is_char_device() || t.is_block_device() {
            Entry::Device(m.rdev())
        } else {
            Entry::Other
        };
        out.insert(r, entry);
    }
}

/// Where writing `arg` (relative to `work`) ends, following symlinks as `write_atomic` does,
/// relative to the case's folder; None when its folder does not exist or it is outside.
pub fn written_path(case_dir: &Path, work: &Path, arg: &OsStr) -> Option<PathBuf> {
    let mut cur = work.join(arg);
    for _ in 0..40 {
        match std::fs::symlink_metadata(&cur) {
            Ok(m) if m.file_type().is_symlink() => {
                let link = std::fs::read_link(&cur).ok()?;
                cur = cur.parent()?.join(link);
            }
            _ => break,
        }
    }
    let name = cur.file_name()?.to_owned();
    let dir = std::fs::canonicalize(cur.parent()?).ok()?;
    dir.join(name)
        .strip_prefix(case_dir)
        .ok()
        .map(Path::to_path_buf)
}

/// The name itself (the last component not followed), relative to the case's folder.
fn lexical_path(case_dir: &Path, work: &Path, arg: &OsStr) -> Option<PathBuf> {
    let p = work.join(arg);
    let name = p.file_name()?.to_owned();
    let dir = std::fs::canonicalize(p.parent()?).ok()?;
    dir.join(name)
        .strip_prefix(case_dir)
        .ok()
        .map(Path::to_path_buf)
}

/// A folder argument, followed all the way.
fn folder_path(case_dir: &Path, work: &Path, arg: &OsStr) -> Option<PathBuf> {
    let dir = std::fs::canonicalize(work.join(arg)).ok()?;
    dir.strip_prefix(case_dir).ok().map(Path::to_path_buf)
}

/// Which changes a case may make.
#[derive(Default)]
pub struct Allowed {
    /// Files that must not change: named inputs (followed through links).
    pub inputs: BTreeSet<PathBuf>,
    /// Explicit outputs, where their links lead and the names themselves.
    outputs: BTreeSet<PathBuf>,
    /// Every name on the line, followed and not: an implicit output may not replace one.
    named: BTreeSet<PathBuf>,
    /// (folder, name prefix) of implicit outputs.
    implicit: Vec<(PathBuf, Vec<Vec<u8>>)>,
    /// Outputs given with a trailing slash (a folder), as the file name without it.
    slashed: Vec<PathBuf>,
    /// An explicit output is a full device: the write fails, so success would be a lie.
    pub full_output: bool,
}

pub fn allowed(case: &Case, case_dir: &Path) -> Allowed {
    let work = case_dir.join("work");
    let mut a = Allowed::default();
    let mut out_dir: Option<OsString> = None;
    let mut stem: Option<OsString> = None;
    for arg in &case.args {
        let p = arg.path();
        a.named.extend(written_path(case_dir, &work, p));
        a.named.extend(lexical_path(case_dir, &work, p));
        let slash = p.as_bytes().ends_with(b"/");
        match arg.role {
            Role::Input => a.inputs.extend(written_path(case_dir, &work, p)),
            Role::DiffImage => {
                a.inputs.extend(written_path(case_dir, &work, p));
                let path = Path::new(p);
                if let (Some(stem), false) = (path.file_stem(), slash) {
                    let dir = path.parent().unwrap_or(Path::new(""));
                    if let Some(d) = folder_path(case_dir, &work, dir.as_os_str()) {
                        let mut exact = stem.as_bytes().to_vec();
                        exact.extend_from_slice(b".diff");
                        let mut lossy = stem.to_string_lossy().into_owned().into_bytes();
                        lossy.extend_from_slice(b".diff");
                        a.implicit.push((d, vec![exact, lossy]));
                    }
                }
            }
            Role::Output if slash => {
                let trimmed = OsStr::from_bytes(p.as_bytes().trim_ascii_end());
                let trimmed =
                    OsStr::from_bytes(trimmed.as_bytes().strip_suffix(b"/").unwrap_or(b""));
                a.slashed.extend(lexical_path(case_dir, &work, trimmed));
            }
            Role::Output => {
                // Written through its links (as `write_atomic` does), or the link itself
                // replaced: either is the file the line asked for.
                let target = written_path(case_dir, &work, p);
                a.full_output |= target.as_ref().is_some_and(|t| {
                    std::fs::metadata(case_dir.join(t)).is_ok_and(|m| {
                        m.file_type().is_char_device() && m.rdev() == rustix::fs::makedev(1, 7)
                    })
                });
                a.outputs.extend(target);
                a.outputs.extend(lexical_path(case_dir, &work, p));
            }
            Role::AnimateOut => out_dir = Some(p.to_owned()),
            Role::Stem => stem = Some(p.to_owned()),
            Role::Plain => {}
        }
    }
    if case.family == Family::Animate {
        let stem = stem.unwrap_or_else(|| "frame".into());
        let dir = out_dir.unwrap_or_else(|| ".".into());
        // A stem with a folder in it is not a name in --out: nothing it writes is allowed
        // outside the working folder.
        // A folder that does not exist yet is made (one level), as asked: the folder itself
        // is an output (the 1,000,000-case run's `--out ../escaped.png`, outside `work`).
        let d = folder_path(case_dir, &work, &dir).or_else(|| {
            let d = lexical_path(case_dir, &work, &dir)?;
            a.outputs.insert(d.clone());
            Some(d)
        });
        if !stem.as_bytes().contains(&b'/')
            && stem != "."
            && stem != ".."
            && let Some(d) = d
        {
            let lossy = stem.to_string_lossy().into_owned().into_bytes();
            a.implicit.push((d, vec![stem.as_bytes().to_vec(), lossy]));
        }
    }
    if case.loads_meshes {
        for obj in ["cube.obj", "icosphere.obj", "bom.obj"] {
            a.inputs.insert(Path::new("work").join(obj));
        }
    }
    a
}

/// The changes a case made that it may not have; empty when it kept to its outputs.
pub fn judge(before: &Snapshot, after: &Snapshot, a: &Allowed, clean_exit: bool) -> Vec<String> {
    let mut wrong = Vec::new();
    let keys: BTreeSet<&PathBuf> = before.keys().chain(after.keys()).collect();
    for key in keys {
        let (b, f) = (before.get(key), after.get(key));
        if b == f {
            continue;
        }
        let what = match (b, f) {
            (Some(_), None) => "removed",
            (None, Some(_)) => "created",
            (Some(Entry::Link(_)), Some(_)) => "replaced (was a symlink)",
            _ => "changed",
        };
        let k = key.display();
        let in_work = key.starts_with("work");
        let name = key.file_name().map(OsStr::as_bytes).unwrap_or_default();
        if clean_exit && name.starts_with(b".tracelab-") && name.ends_with(b".tmp") {
            wrong.push(format!("temporary file left: {k}"));
        } else if a.inputs.contains(key) {
            wrong.push(format!("input changed: {k} {what}"));
        } else if a.slashed.contains(key) && !matches!(f, Some(Entry::Dir) | None) {
            wrong.push(format!("trailing slash: {k}/ (a folder) made the file {k}"));
        } else if b.is_some() && f.is_none() {
            wrong.push(format!(
                "{} {k} removed",
                if in_work { "file" } else { "outside:" }
            ));
        } else if a.outputs.contains(key) && !matches!(b, Some(Entry::Dir)) {
            // An output the line names: written, through its links, as asked.
        } else if implicit_ok(a, key, b) {
        } else if b.is_none() && in_work {
            // A new file in the working folder: an output, however named.
        } else if in_work {
            wrong.push(format!("file not named as an output {what}: {k}"));
        } else {
            wrong.push(format!("outside the working folder: {k} {what}"));
        }
    }
    wrong
}

fn implicit_ok(a: &Allowed, key: &Path, before: Option<&Entry>) -> bool {
    let (Some(dir), Some(name)) = (key.parent(), key.file_name()) else {
        return false;
    };
    let fresh_or_stale = match before {
        None => true,
        Some(Entry::File(_) | Entry::Big(..)) => !a.named.contains(key),
        _ => false,
    };
    fresh_or_stale
        && a.implicit.iter().any(|(d, prefixes)| {
            d == dir && prefixes.iter().any(|p| name.as_bytes().starts_with(p))
        })
}
