//! Writing files without losing them: every output of tracelab (rendered images, `fmt -o`,
//! the editor's Save, Save As and Export view) goes through [`write_atomic`], or, when it is
//! written piece by piece (an animation's APNG), through [`AtomicFile`] under the same rules.
//!
//! A regular file (or a new one) is replaced atomically: the bytes go to an exclusively
//! created temporary file with an unpredictable name in the target's own folder, which is
//! flushed, given the old file's mode (and owner, as root), synced, renamed over the target,
//! and the folder synced. On any failure the old file is untouched and the temporary file is
//! removed. A symlink is followed and its target written, so the link stays a link. A device
//! node or FIFO is not replaced but written into, and its errors (a full device) reported.
//!
//! On Linux the temporary file is unnamed (`O_TMPFILE`) while it is written and gets its
//! name only when complete, just before the rename, so a `kill -9` during the write leaves
//! nothing behind. Elsewhere, or on a file system without `O_TMPFILE`, it is a `tempfile`
//! named file, and a `kill -9` between creating and renaming leaves one `.tracelab-*.tmp`.

use std::fs::{File, Metadata};
use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// Symlinks followed before giving up, as the kernel's own limit (`ELOOP`).
const MAX_SYMLINKS: usize = 40;

/// Replaces `path` with `bytes`, or writes them into it if it is a device or FIFO; see the
/// module comment for the rules.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let mut file = AtomicFile::create(path)?;
    file.write_all(bytes)?;
    file.commit()
}

/// An output written piece by piece (an animated PNG, frame after frame, so that memory does
/// not grow with the frames) and put in place by [`AtomicFile::commit`] under the same rules
/// as [`write_atomic`]. Dropped without a commit, it leaves the old file as it was and no
/// temporary file (a device or FIFO keeps what was written into it).
pub struct AtomicFile {
    out: Out,
}

enum Out {
    /// A device node or FIFO: written into as a shell redirection would.
    InPlace(File),
    /// Linux: an unnamed file (`O_TMPFILE`) in the target's folder, named only at commit.
    #[cfg(target_os = "linux")]
    Unnamed {
        file: File,
        folder: File,
        dir: PathBuf,
        target: PathBuf,
        existing: Option<Metadata>,
    },
    /// A named temporary file (`.tracelab-*.tmp`) in the target's folder.
    Named {
        tmp: tempfile::NamedTempFile,
        dir: PathBuf,
        target: PathBuf,
        existing: Option<Metadata>,
    },
}

impl AtomicFile {
    /// Follows symlinks from `path` to the file they name and opens where its bytes will go.
    pub fn create(path: &Path) -> io::Result<AtomicFile> {
        let (target, existing) = resolve_symlinks(path)?;
        let out = match &existing {
            Some(meta) if meta.is_dir() => {
                return Err(io::Error::new(
                    io::ErrorKind::IsADirectory,
                    "is a directory",
                ));
            }
            Some(meta) if !meta.is_file() => {
                Out::InPlace(std::fs::OpenOptions::new().write(true).open(&target)?)
            }
            _ => temporary(target, existing)?,
        };
        Ok(AtomicFile { out })
    }

    /// As [`AtomicFile::create`] for a name tracelab invents (`io::output`): a symlink there
    /// is not followed but replaced at commit, its target untouched; a folder, device or
    /// FIFO is refused.
    pub fn create_no_follow(path: &Path) -> io::Result<AtomicFile> {
        let existing = match std::fs::symlink_metadata(path) {
            Ok(m) if m.is_file() => Some(m),
            Ok(m) if m.file_type().is_symlink() => None,
            Ok(_) => {
                return Err(io::Error::new(
                    io::ErrorKind::InvalidInput,
                    "not a regular file",
                ));
            }
            Err(e) if e.kind() == io::ErrorKind::NotFound => None,
            Err(e) => return Err(e),
        };
        Ok(AtomicFile {
            out: temporary(path.to_path_buf(), existing)?,
        })
    }

    /// Flushes, syncs and puts the file in place (or, for a device or FIFO, flushes it).
    pub fn commit(self) -> io::Result<()> {
        match self.out {
            Out::InPlace(mut file) => {
                file.flush()?;
                match file.sync_all() {
                    // Character devices and FIFOs have nothing to sync and say so with EINVAL.
                    Err(e)
                        if e.kind() == io::ErrorKind::InvalidInput
                            || e.kind() == io::ErrorKind::Unsupported =>
                    {
                        Ok(())
                    }
                    other => other,
                }
            }
            #[cfg(target_os = "linux")]
            Out::Unnamed {
                mut file,
                folder,
                dir,
                target,
                existing,
            } => {
                file.flush()?;
                if let Some(meta) = &existing {
                    keep_mode_and_owner(&file, meta)?;
                }
                file.sync_all()?;
                test_stall();
                match unnamed::link_in_place(&file, &folder, &target) {
                    Some(done) => done.and_then(|()| folder.sync_all()),
                    // Neither /proc nor the privilege to name it: copy it to a named file.
                    None => {
                        use std::io::Seek;
                        file.seek(io::SeekFrom::Start(0))?;
                        let mut named = named_temporary(&dir)?;
                        io::copy(&mut file, &mut named)?;
                        commit_named(named, &dir, &target, existing.as_ref())
                    }
                }
            }
            Out::Named {
                tmp,
                dir,
                target,
                existing,
            } => commit_named(tmp, &dir, &target, existing.as_ref()),
        }
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        match &mut self.out {
            Out::InPlace(f) => f.write(buf),
            #[cfg(target_os = "linux")]
            Out::Unnamed { file, .. } => file.write(buf),
            Out::Named { tmp, .. } => tmp.write(buf),
        }
    }
    fn flush(&mut self) -> io::Result<()> {
        match &mut self.out {
            Out::InPlace(f) => f.flush(),
            #[cfg(target_os = "linux")]
            Out::Unnamed { file, .. } => file.flush(),
            Out::Named { tmp, .. } => tmp.flush(),
        }
    }
}

/// Replaces `path` atomically without following a symlink there (the link itself is
/// replaced, its target untouched): for names tracelab invents (`io::output`). A folder,
/// device or FIFO is refused.
pub(super) fn write_atomic_no_follow(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let mut file = AtomicFile::create_no_follow(path)?;
    file.write_all(bytes)?;
    file.commit()
}

/// What `path` finally names once its symlinks are followed (itself when it is not a link
/// or they cannot be followed): where `write_atomic` would write.
pub(super) fn final_target(path: &Path) -> PathBuf {
    resolve_symlinks(path).map_or_else(|_| path.to_path_buf(), |(t, _)| t)
}

/// Follows symlinks from `path` to what they finally name, and what is there (`None` for
/// nothing yet: a new file, or a link to a file still to be made).
fn resolve_symlinks(path: &Path) -> io::Result<(PathBuf, Option<Metadata>)> {
    let mut current = path.to_path_buf();
    for _ in 0..MAX_SYMLINKS {
        let meta = match std::fs::symlink_metadata(&current) {
            Ok(m) => m,
            Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok((current, None)),
            Err(e) => return Err(e),
        };
        if !meta.file_type().is_symlink() {
            return Ok((current, Some(meta)));
        }
        let link = std::fs::read_link(&current)?;
        // A relative link is relative to the folder holding it.
        current = match current.parent() {
            Some(dir) if link.is_relative() => dir.join(link),
            _ => link,
        };
    }
    Err(io::Error::other(format!(
        "more than {MAX_SYMLINKS} levels of symbolic links"
    )))
}

/// The temporary file for a regular file or a new one, in the target's own folder.
fn temporary(target: PathBuf, existing: Option<Metadata>) -> io::Result<Out> {
    let dir = match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    #[cfg(target_os = "linux")]
    if let Some((file, folder)) = unnamed::create(&dir)? {
        return Ok(Out::Unnamed {
            file,
            folder,
            dir,
            target,
            existing,
        });
    }
    Ok(Out::Named {
        tmp: named_temporary(&dir)?,
        dir,
        target,
        existing,
    })
}

fn named_temporary(dir: &Path) -> io::Result<tempfile::NamedTempFile> {
    let mut builder = tempfile::Builder::new();
    builder.prefix(".tracelab-").suffix(".tmp");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        // A new file gets the usual 0666 less the umask, not tempfile's private 0600.
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    builder.tempfile_in(dir)
}

/// Flush, sync, rename over the target, sync the folder.
fn commit_named(
    mut tmp: tempfile::NamedTempFile,
    dir: &Path,
    target: &Path,
    existing: Option<&Metadata>,
) -> io::Result<()> {
    tmp.flush()?;
    if let Some(meta) = existing {
        keep_mode_and_owner(tmp.as_file(), meta)?;
    }
    tmp.as_file().sync_all()?;
    test_stall();
    // On failure the PersistError gives the temporary file back; dropping it removes it.
    tmp.persist(target).map_err(|e| e.error)?;
    sync_dir(dir)
}

/// Test hook: with `TRACELAB_TEST_STALL_BEFORE_RENAME` set, stop for a minute once the
/// bytes are written and synced but not yet in place, so a test can kill the process at
/// exactly the moment that matters (tests/cli.rs). Says so on stderr. Only in debug builds
/// (what `cargo test` builds): a release binary has no such hook, nor the variable's name.
#[cfg(debug_assertions)]
fn test_stall() {
    if std::env::var_os("TRACELAB_TEST_STALL_BEFORE_RENAME").is_some() {
        eprintln!("tracelab: test hook: stalled before rename");
        std::thread::sleep(std::time::Duration::from_secs(60));
    }
}

#[cfg(not(debug_assertions))]
fn test_stall() {}

/// The Linux path: `O_TMPFILE`, then `linkat` to a fresh name and `renameat` over the target.
#[cfg(target_os = "linux")]
mod unnamed {
    use std::fs::File;
    use std::io;
    use std::os::fd::AsRawFd;
    use std::path::Path;

    use rustix::fs::{AtFlags, CWD, Mode, OFlags};
    use rustix::io::Errno;

    /// An unnamed file in `dir` and the folder, or None where the folder's file system does
    /// not make them (the caller then uses a named temporary file). Read-write, so that it
    /// can be copied to a named one should it turn out that it cannot be linked.
    pub fn create(dir: &Path) -> io::Result<Option<(File, File)>> {
        let folder = File::open(dir)?;
        // 0666 less the umask, as for any new file.
        let flags = OFlags::RDWR | OFlags::TMPFILE | OFlags::CLOEXEC;
        match rustix::fs::openat(&folder, ".", flags, Mode::from_raw_mode(0o666)) {
            Ok(fd) => Ok(Some((File::from(fd), folder))),
            Err(Errno::OPNOTSUPP | Errno::ISDIR | Errno::INVAL | Errno::NOENT) => Ok(None),
            Err(e) => Err(e.into()),
        }
    }

    /// Links the complete file under a fresh name and renames that over `target`; None when
    /// it cannot be named (see [`link`]).
    pub fn link_in_place(file: &File, folder: &File, target: &Path) -> Option<io::Result<()>> {
        let name = match target.file_name() {
            Some(n) => n,
            None => return Some(Err(io::Error::other("no file name"))),
        };
        Some(link(file, folder)?.and_then(|temp| {
            rustix::fs::renameat(folder, &temp, folder, name)
                .map_err(io::Error::from)
                .inspect_err(|_| {
                    let _ = rustix::fs::unlinkat(folder, &temp, AtFlags::empty());
                })
        }))
    }

    /// Gives the unnamed file a fresh name in `folder` (linkat never replaces an existing
    /// entry, so a planted file or link at that name is refused, not followed). None when
    /// neither /proc nor AT_EMPTY_PATH (which needs privilege) can name it.
    fn link(file: &File, folder: &File) -> Option<io::Result<String>> {
        let proc_path = format!("/proc/self/fd/{}", file.as_raw_fd());
        let stamp = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos());
        for attempt in 0..100u32 {
            let temp = format!(".tracelab-{}-{stamp:x}-{attempt}.tmp", std::process::id());
            let linked = rustix::fs::linkat(
                CWD,
                proc_path.as_str(),
                folder,
                temp.as_str(),
                AtFlags::SYMLINK_FOLLOW,
            )
            .or_else(|e| match e {
                Errno::NOENT => {
                    rustix::fs::linkat(file, "", folder, temp.as_str(), AtFlags::EMPTY_PATH)
                }
                e => Err(e),
            });
            match linked {
                Ok(()) => return Some(Ok(temp)),
                Err(Errno::EXIST) => continue,
                Err(Errno::NOENT | Errno::PERM | Errno::ACCESS) => return None,
                Err(e) => return Some(Err(e.into())),
            }
        }
        Some(Err(io::Error::other("no free temporary name")))
    }
}

/// Gives the new file the mode of the one it replaces and, where allowed, its owner.
fn keep_mode_and_owner(file: &File, old: &Metadata) -> io::Result<()> {
    file.set_permissions(old.permissions())?;
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        let new = file.metadata()?;
        if (new.uid(), new.gid()) != (old.uid(), old.gid()) {
            match std::os::unix::fs::fchown(file, Some(old.uid()), Some(old.gid())) {
                Ok(()) => {}
                // Only root may give a file away; anyone else's new file stays theirs, as an
                // editor's would. Root must succeed.
                Err(e) if e.kind() == io::ErrorKind::PermissionDenied && new.uid() != 0 => {}
                Err(e) => return Err(e),
            }
            // chown clears set-user-ID and set-group-ID bits: put the mode back.
            file.set_permissions(old.permissions())?;
        }
    }
    Ok(())
}

/// Makes the rename itself durable.
fn sync_dir(dir: &Path) -> io::Result<()> {
    #[cfg(unix)]
    {
        File::open(dir)?.sync_all()
    }
    #[cfg(not(unix))]
    {
        let _ = dir;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::names_in;
    #[cfg(unix)]
    use std::os::unix::fs::{FileTypeExt, MetadataExt, PermissionsExt};

    fn temp_dir(name: &str) -> PathBuf {
        crate::test_support::temp_dir("io", name)
    }

    #[cfg(unix)]
    use crate::test_support::mknod;

    #[test]
    fn writes_a_new_file_and_replaces_an_old_one_leaving_no_temporary_file() {
        let d = temp_dir("new");
        let p = d.join("out.txt");
        write_atomic(&p, b"first").expect("write new");
        assert_eq!(std::fs::read(&p).expect("read"), b"first");
        write_atomic(&p, b"second, longer").expect("replace");
        assert_eq!(std::fs::read(&p).expect("read"), b"second, longer");
        assert_eq!(names_in(&d), ["out.txt"]);
    }

    #[cfg(unix)]
    #[test]
    fn replacing_keeps_the_mode_of_the_old_file() {
        let d = temp_dir("mode");
        let p = d.join("secret.txt");
        std::fs::write(&p, "old").expect("write");
        std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o600)).expect("chmod");
        write_atomic(&p, b"new").expect("replace");
        assert_eq!(std::fs::metadata(&p).expect("meta").mode() & 0o7777, 0o600);
        std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o444)).expect("chmod");
        write_atomic(&p, b"newer").expect("replace read-only");
        assert_eq!(std::fs::metadata(&p).expect("meta").mode() & 0o7777, 0o444);
        assert_eq!(std::fs::read(&p).expect("read"), b"newer");
    }

    #[cfg(unix)]
    #[test]
    #[ignore = "needs root: chowns a file to another user"]
    fn replacing_as_root_keeps_the_owner_of_the_old_file() {
        let d = temp_dir("owner");
        let p = d.join("theirs.txt");
        std::fs::write(&p, "old").expect("write");
        std::os::unix::fs::chown(&p, Some(65534), Some(65534))
            .expect("chown: this test needs root");
        write_atomic(&p, b"new").expect("replace");
        let m = std::fs::metadata(&p).expect("meta");
        assert_eq!((m.uid(), m.gid()), (65534, 65534));
    }

    #[cfg(unix)]
    #[test]
    fn a_symlink_is_written_through_and_stays_a_link() {
        let d = temp_dir("link");
        std::fs::create_dir(d.join("real")).expect("mkdir");
        std::fs::write(d.join("real/scene.txt"), "old").expect("write");
        std::os::unix::fs::symlink("real/scene.txt", d.join("link.txt")).expect("symlink");
        std::os::unix::fs::symlink("link.txt", d.join("link2.txt")).expect("symlink");
        write_atomic(&d.join("link2.txt"), b"new").expect("write through");
        assert!(
            std::fs::symlink_metadata(d.join("link.txt"))
                .expect("meta")
                .file_type()
                .is_symlink()
        );
        assert!(
            std::fs::symlink_metadata(d.join("link2.txt"))
                .expect("meta")
                .file_type()
                .is_symlink()
        );
        assert_eq!(
            std::fs::read(d.join("real/scene.txt")).expect("read"),
            b"new"
        );
        assert_eq!(names_in(&d.join("real")), ["scene.txt"]);
        // A dangling link makes its target.
        std::os::unix::fs::symlink("real/made.txt", d.join("dangling.txt")).expect("symlink");
        write_atomic(&d.join("dangling.txt"), b"made").expect("write dangling");
        assert_eq!(
            std::fs::read(d.join("real/made.txt")).expect("read"),
            b"made"
        );
        // A loop is an error, not a hang.
        std::os::unix::fs::symlink("loop_b", d.join("loop_a")).expect("symlink");
        std::os::unix::fs::symlink("loop_a", d.join("loop_b")).expect("symlink");
        assert!(write_atomic(&d.join("loop_a"), b"x").is_err());
    }

    #[cfg(unix)]
    #[test]
    fn a_planted_file_at_a_guessable_temporary_name_is_not_written() {
        let d = temp_dir("planted");
        std::fs::write(d.join("victim"), "keep").expect("write");
        // The old temporary names: `.NAME.tracelab-tmp-PID`.
        let guess = d.join(format!(".out.txt.tracelab-tmp-{}", std::process::id()));
        std::os::unix::fs::symlink(d.join("victim"), &guess).expect("plant");
        write_atomic(&d.join("out.txt"), b"data").expect("write");
        assert_eq!(std::fs::read(d.join("victim")).expect("read"), b"keep");
        assert_eq!(std::fs::read(d.join("out.txt")).expect("read"), b"data");
    }

    #[test]
    fn a_streamed_file_appears_only_when_committed() {
        let d = temp_dir("stream");
        let p = d.join("anim.png");
        std::fs::write(&p, "old").expect("write");
        let mut f = AtomicFile::create(&p).expect("create");
        f.write_all(b"frame 1, ").expect("write");
        f.write_all(b"frame 2").expect("write");
        assert_eq!(std::fs::read(&p).expect("read"), b"old", "not yet");
        drop(f);
        assert_eq!(
            std::fs::read(&p).expect("read"),
            b"old",
            "dropped: untouched"
        );
        assert_eq!(names_in(&d), ["anim.png"], "and no temporary file");
        let mut f = AtomicFile::create(&p).expect("create");
        f.write_all(b"frame 1, frame 2").expect("write");
        f.commit().expect("commit");
        assert_eq!(std::fs::read(&p).expect("read"), b"frame 1, frame 2");
        assert_eq!(names_in(&d), ["anim.png"]);
    }

    #[test]
    fn a_failed_write_leaves_the_old_file_and_no_temporary_file() {
        let d = temp_dir("fail");
        std::fs::write(d.join("old.txt"), "old").expect("write");
        assert!(write_atomic(&d.join("missing/out.txt"), b"x").is_err());
        assert!(
            write_atomic(&d, b"x").is_err(),
            "a directory is not replaced"
        );
        assert!(d.is_dir());
        assert_eq!(names_in(&d), ["old.txt"]);
        assert_eq!(std::fs::read(d.join("old.txt")).expect("read"), b"old");
    }

    #[cfg(unix)]
    #[test]
    #[ignore = "needs root: makes a private device node (mknod)"]
    fn a_full_device_is_written_into_reports_its_error_and_stays_a_device() {
        let d = temp_dir("full");
        let full = mknod(&d, "full", 7);
        let e = write_atomic(&full, b"bytes").expect_err("a full device fails");
        assert_eq!(e.kind(), io::ErrorKind::StorageFull, "{e}");
        assert!(
            std::fs::symlink_metadata(&full)
                .expect("meta")
                .file_type()
                .is_char_device()
        );
        let null = mknod(&d, "null", 3);
        write_atomic(&null, b"bytes").expect("a null device takes anything");
        assert!(
            std::fs::symlink_metadata(&null)
                .expect("meta")
                .file_type()
                .is_char_device()
        );
        assert_eq!(names_in(&d), ["full", "null"]);
    }

    #[cfg(unix)]
    #[test]
    fn a_fifo_is_written_into_and_stays_a_fifo() {
        let d = temp_dir("fifo");
        let fifo = d.join("pipe");
        let ok = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .is_ok_and(|s| s.success());
        assert!(ok, "mkfifo");
        let reader = {
            let fifo = fifo.clone();
            std::thread::spawn(move || std::fs::read(fifo).expect("read fifo"))
        };
        write_atomic(&fifo, b"through the pipe").expect("write fifo");
        assert_eq!(reader.join().expect("reader"), b"through the pipe");
        assert!(
            std::fs::symlink_metadata(&fifo)
                .expect("meta")
                .file_type()
                .is_fifo()
        );
    }
}
