//! Writing files without losing them: every output of tracelab (rendered images, `fmt -o`,
//! the editor's Save, Save As and Export view) goes through [`write_atomic`].
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
    let (target, existing) = resolve_symlinks(path)?;
    match &existing {
        Some(meta) if meta.is_dir() => Err(io::Error::new(
            io::ErrorKind::IsADirectory,
            "is a directory",
        )),
        Some(meta) if !meta.is_file() => write_in_place(&target, bytes),
        _ => replace(&target, existing.as_ref(), bytes),
    }
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

/// A device node or FIFO: write into it as a shell redirection would.
fn write_in_place(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let mut file = std::fs::OpenOptions::new().write(true).open(path)?;
    file.write_all(bytes)?;
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

/// A regular file or a new one: temporary file, sync, rename, sync the folder.
fn replace(target: &Path, existing: Option<&Metadata>, bytes: &[u8]) -> io::Result<()> {
    let dir = match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    #[cfg(target_os = "linux")]
    if let Some(name) = target.file_name()
        && let Some(done) = unnamed::replace(dir, name, existing, bytes)
    {
        return done;
    }
    let mut builder = tempfile::Builder::new();
    builder.prefix(".tracelab-").suffix(".tmp");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        // A new file gets the usual 0666 less the umask, not tempfile's private 0600.
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let mut tmp = builder.tempfile_in(dir)?;
    tmp.write_all(bytes)?;
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
/// exactly the moment that matters (tests/cli.rs). Says so on stderr.
fn test_stall() {
    if std::env::var_os("TRACELAB_TEST_STALL_BEFORE_RENAME").is_some() {
        eprintln!("tracelab: test hook: stalled before rename");
        std::thread::sleep(std::time::Duration::from_secs(60));
    }
}

/// The Linux path: `O_TMPFILE`, then `linkat` to a fresh name and `renameat` over the target.
#[cfg(target_os = "linux")]
mod unnamed {
    use std::ffi::OsStr;
    use std::fs::{File, Metadata};
    use std::io::{self, Write};
    use std::os::fd::AsRawFd;
    use std::path::Path;

    use rustix::fs::{AtFlags, CWD, Mode, OFlags};
    use rustix::io::Errno;

    /// None where the folder's file system (or a missing /proc) does not allow an unnamed
    /// file to be linked: the caller then uses a named temporary file.
    pub fn replace(
        dir: &Path,
        name: &OsStr,
        existing: Option<&Metadata>,
        bytes: &[u8],
    ) -> Option<io::Result<()>> {
        let folder = match File::open(dir) {
            Ok(f) => f,
            Err(e) => return Some(Err(e)),
        };
        // 0666 less the umask, as for any new file.
        let flags = OFlags::WRONLY | OFlags::TMPFILE | OFlags::CLOEXEC;
        let fd = match rustix::fs::openat(&folder, ".", flags, Mode::from_raw_mode(0o666)) {
            Ok(fd) => fd,
            Err(Errno::OPNOTSUPP | Errno::ISDIR | Errno::INVAL | Errno::NOENT) => return None,
            Err(e) => return Some(Err(e.into())),
        };
        let mut file = File::from(fd);
        let written = (|| {
            file.write_all(bytes)?;
            file.flush()?;
            if let Some(meta) = existing {
                super::keep_mode_and_owner(&file, meta)?;
            }
            file.sync_all()
        })();
        if let Err(e) = written {
            return Some(Err(e)); // the unnamed file goes with its descriptor
        }
        super::test_stall();
        let temp = link(&file, &folder)?;
        let moved = match temp {
            Ok(temp) => rustix::fs::renameat(&folder, &temp, &folder, name)
                .map_err(io::Error::from)
                .inspect_err(|_| {
                    let _ = rustix::fs::unlinkat(&folder, &temp, AtFlags::empty());
                }),
            Err(e) => Err(e),
        };
        Some(moved.and_then(|()| folder.sync_all()))
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

    /// A private device node in `dir` (never the machine's own /dev files); `None`, with a
    /// message, where mknod is not allowed.
    #[cfg(unix)]
    fn mknod(dir: &Path, name: &str, minor: u32) -> PathBuf {
        let p = dir.join(name);
        let ok = std::process::Command::new("mknod")
            .arg(&p)
            .args(["c", "1", &minor.to_string()])
            .status()
            .is_ok_and(|s| s.success());
        assert!(ok, "mknod {} failed: this test needs root", p.display());
        p
    }

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
