//! The output policy: what every command (render, the course's flags, `fmt -o`, `diff`'s heat
//! maps, `animate`'s frames, the editor's exports) checks before it writes a file. One
//! [`OutputPlan`] per command run:
//!
//! 1. name what the command reads ([`OutputPlan::reads`]) and what its arguments name that it
//!    neither reads nor writes ([`OutputPlan::names`], e.g. `diff`'s `-output`);
//! 2. name what the user asked it to write ([`OutputPlan::writes`]) and call
//!    [`OutputPlan::check`] **before the work starts**: an output that is an input (the same
//!    file by device and inode, so `./a.png`, `a.png`, a symlink and a hard link all
//!    collide), two outputs that are one file, a name ending in `/` (a folder, never a file)
//!    or an existing folder, and a folder that is missing, not a folder or not writable, are
//!    all refused then, not after a long render;
//! 3. invent names (heat maps, frames) only through [`OutputPlan::implicit`] (another name
//!    when the wanted one is taken) or [`OutputPlan::implicit_exact`] (refuse instead), and
//!    write them with [`write_implicit`]: an invented name never follows or replaces a
//!    symlink, a folder, a device or FIFO, or any file named on the command line.
//!
//! Explicit outputs are then written with `write_atomic` as before (a symlink the user named
//! is written through; a device is written into).

use std::io;
use std::path::{Path, PathBuf};

/// Why an output was refused. [`OutputError::is_usage`] tells a mistake in the arguments
/// (exit 2) from a state of the file system (exit 1).
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    #[error("{}: names a folder, not a file", .0.display())]
    NamesAFolder(PathBuf),
    #[error("{}: names an input of this command ({}), which is never written", .output.display(), .input.display())]
    IsAnInput { output: PathBuf, input: PathBuf },
    #[error("{} and {} are the same file: give each output its own", .0.display(), .1.display())]
    SameOutputTwice(PathBuf, PathBuf),
    #[error("{}: cannot write: folder {} does not exist", .path.display(), .folder.display())]
    NoFolder { path: PathBuf, folder: PathBuf },
    #[error("{}: cannot write: {} is not a folder", .path.display(), .folder.display())]
    NotAFolder { path: PathBuf, folder: PathBuf },
    #[error("{}: cannot write into folder {}: {source}", .path.display(), .folder.display())]
    FolderNotWritable {
        path: PathBuf,
        folder: PathBuf,
        source: io::Error,
    },
    /// An invented name is taken (and, for [`OutputPlan::implicit`], so are its alternatives).
    #[error("{}: not written: {reason}", .path.display())]
    NameTaken { path: PathBuf, reason: String },
}

impl OutputError {
    /// True for mistakes in the arguments (an output that is an input, two outputs that are
    /// one file, a folder given as a file), false for the file system's state.
    pub fn is_usage(&self) -> bool {
        matches!(
            self,
            OutputError::NamesAFolder(_)
                | OutputError::IsAnInput { .. }
                | OutputError::SameOutputTwice(..)
        )
    }

    /// As the command line reports it: a usage error (exit 2) or a failure (exit 1).
    pub fn into_cli(self) -> anyhow::Error {
        if self.is_usage() {
            crate::exit::usage(self.to_string())
        } else {
            anyhow::Error::new(self)
        }
    }
}

/// Which file a path names, compared between paths: device and inode where the file exists
/// (so hard links and symlinks collide), else the absolute path with symlinks resolved.
#[derive(Clone, Debug, PartialEq, Eq)]
enum Identity {
    File { dev: u64, ino: u64 },
    Path(PathBuf),
}

fn identity(path: &Path) -> Identity {
    #[cfg(unix)]
    if let Ok(m) = std::fs::metadata(path) {
        use std::os::unix::fs::MetadataExt;
        return Identity::File {
            dev: m.dev(),
            ino: m.ino(),
        };
    }
    Identity::Path(absolute(&super::atomic::final_target(path)))
}

/// An absolute path for a file that may not exist: its folder canonicalised where it
/// exists, else `..` and `.` removed by their text.
fn absolute(path: &Path) -> PathBuf {
    if let (Some(dir), Some(name)) = (path.parent(), path.file_name()) {
        let dir = if dir.as_os_str().is_empty() {
            Path::new(".")
        } else {
            dir
        };
        if let Ok(d) = dir.canonicalize() {
            return d.join(name);
        }
    }
    if let Ok(p) = path.canonicalize() {
        return p;
    }
    let abs = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let mut out = PathBuf::new();
    for c in abs.components() {
        match c {
            std::path::Component::ParentDir => {
                out.pop();
            }
            std::path::Component::CurDir => {}
            c => out.push(c),
        }
    }
    out
}

/// A name whose last part is empty, `.` or `..` (`out.png/`, `out/.`) names a folder.
/// `Path` forgets a trailing slash, so this looks at the text.
pub fn names_a_folder(path: &Path) -> bool {
    let text = path.as_os_str().as_encoded_bytes();
    let last = text
        .rsplit(|&b| b == b'/' || (cfg!(windows) && b == b'\\'))
        .next()
        .unwrap_or_default();
    matches!(last, b"" | b"." | b"..")
}

struct Entry {
    path: PathBuf,
    id: Identity,
}

impl Entry {
    fn new(path: &Path) -> Entry {
        Entry {
            path: path.to_path_buf(),
            id: identity(path),
        }
    }
}

/// Everything one command run reads, names and writes; see the module comment.
#[derive(Default)]
pub struct OutputPlan {
    reads: Vec<Entry>,
    named: Vec<Entry>,
    writes: Vec<Entry>,
}

/// An invented output's name as chosen by [`OutputPlan::implicit`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Implicit {
    pub path: PathBuf,
    /// When the wanted name was passed over: that name and why (to tell the user).
    pub instead_of: Option<(PathBuf, String)>,
}

/// Alternatives tried after the wanted name: `mine.diff-2.png` … `mine.diff-99.png`.
const ALTERNATIVES: u32 = 99;

impl OutputPlan {
    pub fn new() -> Self {
        Self::default()
    }

    /// A file the command reads: nothing it writes may be this file. Call before anything is
    /// written (the identity is taken now).
    pub fn reads(&mut self, path: &Path) -> &mut Self {
        self.reads.push(Entry::new(path));
        self
    }

    /// A file the arguments name that the command neither reads nor writes (`diff`'s
    /// `-output`, promised never to be written): nothing it writes may be this file.
    pub fn names(&mut self, path: &Path) -> &mut Self {
        self.named.push(Entry::new(path));
        self
    }

    /// A file the user asked for by name; checked by [`OutputPlan::check`].
    pub fn writes(&mut self, path: &Path) -> &mut Self {
        self.writes.push(Entry::new(path));
        self
    }

    /// Checks every output named with [`OutputPlan::writes`] against the rules of the
    /// module comment; call it before the work starts (and again after adding inputs found
    /// later, such as a scene's meshes: it is cheap).
    pub fn check(&self) -> Result<(), OutputError> {
        for (k, w) in self.writes.iter().enumerate() {
            if names_a_folder(&w.path) {
                return Err(OutputError::NamesAFolder(w.path.clone()));
            }
            if let Some(r) = self.reads.iter().chain(&self.named).find(|r| r.id == w.id) {
                return Err(OutputError::IsAnInput {
                    output: w.path.clone(),
                    input: r.path.clone(),
                });
            }
            if let Some(earlier) = self.writes[..k].iter().find(|e| e.id == w.id) {
                return Err(OutputError::SameOutputTwice(
                    earlier.path.clone(),
                    w.path.clone(),
                ));
            }
            check_writable(&w.path)?;
        }
        Ok(())
    }

    /// Chooses the name of an output the command invents (a heat map): `wanted` if it is
    /// free, else `STEM-2.EXT`, `STEM-3.EXT`, … A name is free when nothing is there or a
    /// regular file that no argument names and no earlier output of this run took; a symlink,
    /// folder, device or FIFO is never free. The chosen name counts as written from now on,
    /// so two invented names never coincide. Write it with [`write_implicit`].
    pub fn implicit(&mut self, wanted: &Path) -> Result<Implicit, OutputError> {
        let first = match self.taken(wanted) {
            None => return Ok(self.claim(wanted, None)),
            Some(reason) => (wanted.to_path_buf(), reason),
        };
        let stem = wanted
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let ext = wanted
            .extension()
            .map(|e| format!(".{}", e.to_string_lossy()))
            .unwrap_or_default();
        for k in 2..=ALTERNATIVES {
            let p = wanted.with_file_name(format!("{stem}-{k}{ext}"));
            if self.taken(&p).is_none() {
                return Ok(self.claim(&p, Some(first)));
            }
        }
        Err(OutputError::NameTaken {
            path: first.0,
            reason: format!(
                "{}, and so are its {} alternatives",
                first.1,
                ALTERNATIVES - 1
            ),
        })
    }

    /// As [`OutputPlan::implicit`] for a name that must be exactly this (a numbered frame):
    /// refused, with the reason, when it is not free.
    pub fn implicit_exact(&mut self, path: &Path) -> Result<(), OutputError> {
        match self.taken(path) {
            None => {
                self.claim(path, None);
                Ok(())
            }
            Some(reason) => Err(OutputError::NameTaken {
                path: path.to_path_buf(),
                reason,
            }),
        }
    }

    fn claim(&mut self, path: &Path, instead_of: Option<(PathBuf, String)>) -> Implicit {
        self.writes.push(Entry::new(path));
        Implicit {
            path: path.to_path_buf(),
            instead_of,
        }
    }

    /// Why an invented name may not be used, or `None` when it may.
    fn taken(&self, path: &Path) -> Option<String> {
        if names_a_folder(path) {
            return Some("it names a folder".into());
        }
        match std::fs::symlink_metadata(path) {
            Ok(m) if m.file_type().is_symlink() => return Some("it is a symbolic link".into()),
            Ok(m) if m.is_dir() => return Some("it is a folder".into()),
            Ok(m) if !m.is_file() => return Some("it is not a regular file".into()),
            Ok(_) => {}
            Err(e) if e.kind() == io::ErrorKind::NotFound => {}
            Err(e) => return Some(format!("it cannot be checked: {e}")),
        }
        let id = identity(path);
        if let Some(e) = self.reads.iter().chain(&self.named).find(|e| e.id == id) {
            return Some(format!(
                "it is {} on the command line",
                same_or_other(path, &e.path)
            ));
        }
        if let Some(e) = self.writes.iter().find(|e| e.id == id) {
            return Some(format!(
                "it is {}, already an output",
                same_or_other(path, &e.path)
            ));
        }
        None
    }
}

fn same_or_other(path: &Path, other: &Path) -> String {
    if path == other {
        "named".into()
    } else {
        format!("the same file as {}", other.display())
    }
}

/// The folder an output goes into must exist, be a folder and be writable; an existing
/// output must not be a folder. A symlink is followed (its target's folder is where the
/// file is replaced); an existing device or FIFO is written into and needs no folder.
pub fn check_writable(path: &Path) -> Result<(), OutputError> {
    if names_a_folder(path) {
        return Err(OutputError::NamesAFolder(path.to_path_buf()));
    }
    let target = super::atomic::final_target(path);
    match std::fs::metadata(&target) {
        Ok(m) if m.is_dir() => return Err(OutputError::NamesAFolder(path.to_path_buf())),
        Ok(m) if !m.is_file() => return Ok(()),
        _ => {}
    }
    let folder = match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    check_folder(&folder).map_err(|e| match e {
        FolderProblem::Missing => OutputError::NoFolder {
            path: path.to_path_buf(),
            folder,
        },
        FolderProblem::NotAFolder => OutputError::NotAFolder {
            path: path.to_path_buf(),
            folder,
        },
        FolderProblem::NotWritable(source) => OutputError::FolderNotWritable {
            path: path.to_path_buf(),
            folder,
            source,
        },
    })
}

/// Checks a folder that outputs will be written into (`animate --out` once created).
pub fn check_output_folder(folder: &Path) -> Result<(), OutputError> {
    check_folder(folder).map_err(|e| match e {
        FolderProblem::Missing => OutputError::NoFolder {
            path: folder.to_path_buf(),
            folder: folder.to_path_buf(),
        },
        FolderProblem::NotAFolder => OutputError::NotAFolder {
            path: folder.to_path_buf(),
            folder: folder.to_path_buf(),
        },
        FolderProblem::NotWritable(source) => OutputError::FolderNotWritable {
            path: folder.to_path_buf(),
            folder: folder.to_path_buf(),
            source,
        },
    })
}

enum FolderProblem {
    Missing,
    NotAFolder,
    NotWritable(io::Error),
}

fn check_folder(folder: &Path) -> Result<(), FolderProblem> {
    match std::fs::metadata(folder) {
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Err(FolderProblem::Missing),
        Err(e) if e.raw_os_error() == Some(20) => return Err(FolderProblem::NotAFolder), // ENOTDIR
        Err(e) => return Err(FolderProblem::NotWritable(e)),
        Ok(m) if !m.is_dir() => return Err(FolderProblem::NotAFolder),
        Ok(_) => {}
    }
    #[cfg(unix)]
    {
        use rustix::fs::{Access, access};
        // access() also answers EROFS for a read-only file system.
        access(folder, Access::WRITE_OK | Access::EXEC_OK)
            .map_err(|e| FolderProblem::NotWritable(e.into()))?;
    }
    Ok(())
}

/// Writes an invented output chosen by [`OutputPlan::implicit`]: atomically, as
/// `write_atomic`, but never through a symlink (one planted since the name was chosen is
/// replaced by the rename, its target untouched) and never into a device or FIFO.
pub fn write_implicit(path: &Path, bytes: &[u8]) -> io::Result<()> {
    super::atomic::write_atomic_no_follow(path, bytes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::names_in;

    fn temp_dir(name: &str) -> PathBuf {
        crate::test_support::temp_dir("output", name)
    }

    #[test]
    fn a_trailing_slash_or_dot_names_a_folder() {
        for p in ["out.png/", "out/.", "a/..", ".", "..", "/"] {
            assert!(names_a_folder(Path::new(p)), "{p}");
        }
        for p in ["out.png", "a/out.png", "./out.png", ".hidden"] {
            assert!(!names_a_folder(Path::new(p)), "{p}");
        }
        let e = OutputPlan::new()
            .writes(Path::new("out.png/"))
            .check()
            .expect_err("a folder");
        assert!(
            matches!(e, OutputError::NamesAFolder(_)) && e.is_usage(),
            "{e}"
        );
    }

    #[cfg(unix)]
    #[test]
    fn an_output_that_is_an_input_by_any_name_is_refused() {
        let d = temp_dir("input");
        let scene = d.join("scene.png");
        std::fs::write(&scene, "scene").expect("write");
        std::fs::hard_link(&scene, d.join("hard.png")).expect("link");
        std::os::unix::fs::symlink("scene.png", d.join("soft.png")).expect("symlink");
        let dotted = d.join(".").join("scene.png");
        for out in [
            scene.clone(),
            dotted,
            d.join("hard.png"),
            d.join("soft.png"),
        ] {
            let e = OutputPlan::new()
                .reads(&scene)
                .writes(&out)
                .check()
                .expect_err("an input");
            assert!(matches!(e, OutputError::IsAnInput { .. }), "{e}");
            assert!(e.is_usage());
        }
        // Named but not read (diff's -output), and not yet there: still refused.
        let promised = d.join("x.png");
        let e = OutputPlan::new()
            .names(&promised)
            .writes(&d.join("sub/../x.png"))
            .check()
            .expect_err("named");
        assert!(matches!(e, OutputError::IsAnInput { .. }), "{e}");
        OutputPlan::new()
            .reads(&scene)
            .writes(&d.join("other.png"))
            .check()
            .expect("a different file");
        assert_eq!(names_in(&d), ["hard.png", "scene.png", "soft.png"]);
    }

    #[test]
    fn two_outputs_naming_one_file_are_refused() {
        let d = temp_dir("twice");
        let e = OutputPlan::new()
            .writes(&d.join("a.png"))
            .writes(&d.join(".").join("a.png"))
            .check()
            .expect_err("twice");
        assert!(
            matches!(e, OutputError::SameOutputTwice(..)) && e.is_usage(),
            "{e}"
        );
    }

    #[cfg(unix)]
    #[test]
    fn output_folders_are_checked_before_anything_is_written() {
        use std::os::unix::fs::PermissionsExt;
        let d = temp_dir("folders");
        std::fs::write(d.join("file"), "x").expect("write");
        std::fs::create_dir(d.join("dir")).expect("mkdir");
        let check = |p: &Path| OutputPlan::new().writes(p).check();
        assert!(matches!(
            check(&d.join("missing/o.png")),
            Err(OutputError::NoFolder { .. })
        ));
        assert!(matches!(
            check(&d.join("file/o.png")),
            Err(OutputError::NotAFolder { .. })
        ));
        let e = check(&d.join("dir")).expect_err("a folder");
        assert!(matches!(e, OutputError::NamesAFolder(_)), "{e}");
        assert!(!check(&d.join("missing/o.png")).expect_err("").is_usage());
        check(&d.join("dir/o.png")).expect("writable");
        std::fs::set_permissions(d.join("dir"), std::fs::Permissions::from_mode(0o555))
            .expect("chmod");
        // Root may write anyway; anyone else is refused: the check agrees with a real write.
        let writable = std::fs::write(d.join("dir/probe"), "x").is_ok();
        let _ = std::fs::remove_file(d.join("dir/probe"));
        assert_eq!(check(&d.join("dir/o.png")).is_ok(), writable);
        std::fs::set_permissions(d.join("dir"), std::fs::Permissions::from_mode(0o755))
            .expect("chmod");
        assert_eq!(names_in(&d), ["dir", "file"]);
    }

    #[cfg(unix)]
    #[test]
    fn invented_names_skip_symlinks_named_files_and_each_other() {
        let d = temp_dir("implicit");
        std::fs::write(d.join("grades.csv"), "keep").expect("write");
        std::os::unix::fs::symlink("grades.csv", d.join("mine.diff.png")).expect("plant");
        std::fs::write(d.join("mine.diff-2.png"), "normals").expect("write");
        std::fs::write(d.join("old.diff.png"), "an earlier heat map").expect("write");
        let mut plan = OutputPlan::new();
        plan.reads(&d.join("mine.png"))
            .reads(&d.join("mine.diff-2.png"));
        let first = plan.implicit(&d.join("mine.diff.png")).expect("a name");
        assert_eq!(first.path, d.join("mine.diff-3.png"));
        let (passed, why) = first.instead_of.expect("passed over");
        assert_eq!(passed, d.join("mine.diff.png"));
        assert!(why.contains("symbolic link"), "{why}");
        // The same wanted name again gets the next one: never two outputs in one file.
        let second = plan.implicit(&d.join("mine.diff.png")).expect("a name");
        assert_eq!(second.path, d.join("mine.diff-4.png"));
        // A regular file that nothing names (last run's heat map) is replaced as it was.
        let old = plan.implicit(&d.join("old.diff.png")).expect("a name");
        assert_eq!((old.path, old.instead_of), (d.join("old.diff.png"), None));
        // Exact names are refused, not renamed.
        let e = plan
            .implicit_exact(&d.join("mine.diff-2.png"))
            .expect_err("named");
        assert!(e.to_string().contains("named on the command line"), "{e}");
        write_implicit(&first.path, b"map").expect("write");
        assert_eq!(std::fs::read(d.join("grades.csv")).expect("read"), b"keep");
    }

    #[cfg(unix)]
    #[test]
    fn write_implicit_replaces_a_symlink_planted_late_without_following_it() {
        let d = temp_dir("late");
        std::fs::write(d.join("grades.csv"), "keep").expect("write");
        let mut plan = OutputPlan::new();
        let chosen = plan.implicit(&d.join("m.diff.png")).expect("free");
        std::os::unix::fs::symlink("grades.csv", &chosen.path).expect("plant after the check");
        write_implicit(&chosen.path, b"map").expect("write");
        assert_eq!(std::fs::read(d.join("grades.csv")).expect("read"), b"keep");
        assert_eq!(std::fs::read(&chosen.path).expect("read"), b"map");
        assert_eq!(names_in(&d), ["grades.csv", "m.diff.png"]);
    }

    #[test]
    fn a_name_with_every_alternative_taken_is_refused_with_the_reason() {
        let d = temp_dir("full");
        let mut plan = OutputPlan::new();
        plan.reads(&d.join("h.png"));
        for k in 2..=ALTERNATIVES {
            plan.reads(&d.join(format!("h-{k}.png")));
        }
        let e = plan.implicit(&d.join("h.png")).expect_err("all taken");
        assert!(matches!(e, OutputError::NameTaken { .. }), "{e}");
        assert!(e.to_string().contains("alternatives"), "{e}");
    }
}
