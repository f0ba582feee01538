//! What is at a mesh path, said before anything is opened: opening a FIFO blocks until
//! someone writes to it, and a folder or a symlink loop is not "file not found".

use std::fs::File;
use std::io::ErrorKind;
use std::path::Path;

use super::error::ObjError;

#[derive(Debug, PartialEq, Eq)]
pub enum FileKind {
    Regular,
    Missing,
    Folder,
    Fifo,
    Device,
    Socket,
    DanglingLink,
    LinkLoop,
    /// Could not be examined (permissions, …): the system's reason.
    Unreadable(String),
}

impl FileKind {
    /// The rest of "PATH …" for everything but a regular file.
    pub fn describe(&self) -> String {
        match self {
            FileKind::Regular => "is a file".to_string(),
            FileKind::Missing => "does not exist".to_string(),
            FileKind::Folder => "is a folder, not an OBJ file".to_string(),
            FileKind::Fifo => {
                "is a FIFO (named pipe), not an OBJ file; meshes are read from regular files only"
                    .to_string()
            }
            FileKind::Device => "is a device, not an OBJ file".to_string(),
            FileKind::Socket => "is a socket, not an OBJ file".to_string(),
            FileKind::DanglingLink => {
                "is a symbolic link to a file that does not exist".to_string()
            }
            FileKind::LinkLoop => {
                "is a symbolic link loop (or a chain of links too long to follow)".to_string()
            }
            FileKind::Unreadable(why) => format!("cannot be examined: {why}"),
        }
    }
}

/// Follows symbolic links, as opening would.
pub fn file_kind(path: &Path) -> FileKind {
    match std::fs::metadata(path) {
        Ok(m) => kind_of(&m.file_type()),
        Err(e) if e.kind() == ErrorKind::NotFound => {
            if std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink()) {
                FileKind::DanglingLink
            } else {
                FileKind::Missing
            }
        }
        // ELOOP has no stable ErrorKind yet.
        Err(e) if e.raw_os_error() == Some(ELOOP) => FileKind::LinkLoop,
        Err(e) => FileKind::Unreadable(e.to_string()),
    }
}

#[cfg(target_os = "linux")]
const ELOOP: i32 = 40;
#[cfg(not(target_os = "linux"))]
const ELOOP: i32 = 62;

fn kind_of(t: &std::fs::FileType) -> FileKind {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt as _;
        if t.is_fifo() {
            return FileKind::Fifo;
        }
        if t.is_char_device() || t.is_block_device() {
            return FileKind::Device;
        }
        if t.is_socket() {
            return FileKind::Socket;
        }
    }
    if t.is_dir() {
        FileKind::Folder
    } else if t.is_file() {
        FileKind::Regular
    } else {
        FileKind::Unreadable("not a regular file".to_string())
    }
}

/// Opens `path` only if it is a regular file, and checks the opened handle again, so a file
/// swapped for a FIFO between the check and the open cannot block the reader.
pub fn open_regular(path: &Path) -> Result<File, ObjError> {
    let not_a_file = |k: FileKind| ObjError::NotAFile {
        path: path.to_path_buf(),
        what: k.describe(),
    };
    match file_kind(path) {
        FileKind::Regular => {}
        other => return Err(not_a_file(other)),
    }
    let file = open_nonblocking(path)?;
    let meta = file.metadata()?;
    match kind_of(&meta.file_type()) {
        FileKind::Regular => Ok(file),
        other => Err(not_a_file(other)),
    }
}

/// O_NONBLOCK makes opening a FIFO return at once; it changes nothing for regular files.
#[cfg(target_os = "linux")]
fn open_nonblocking(path: &Path) -> std::io::Result<File> {
    use std::os::unix::fs::OpenOptionsExt as _;
    const O_NONBLOCK: i32 = 0o4000;
    std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(O_NONBLOCK)
        .open(path)
}

#[cfg(not(target_os = "linux"))]
fn open_nonblocking(path: &Path) -> std::io::Result<File> {
    File::open(path)
}

#[cfg(all(test, unix))]
mod tests {
    use super::*;

    #[test]
    fn kinds_are_told_apart_without_opening_anything() {
        let dir = std::env::temp_dir().join(format!("tracelab-file-kind-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("temp dir");
        std::fs::write(dir.join("f.obj"), "v 0 0 0\n").expect("write");
        std::os::unix::fs::symlink("loop", dir.join("loop")).expect("symlink");
        std::os::unix::fs::symlink("nothing", dir.join("dangling")).expect("symlink");
        let fifo = std::process::Command::new("mkfifo")
            .arg(dir.join("pipe"))
            .status();
        assert!(fifo.is_ok_and(|s| s.success()), "mkfifo");
        assert_eq!(file_kind(&dir.join("f.obj")), FileKind::Regular);
        assert_eq!(file_kind(&dir), FileKind::Folder);
        assert_eq!(file_kind(&dir.join("loop")), FileKind::LinkLoop);
        assert_eq!(file_kind(&dir.join("dangling")), FileKind::DanglingLink);
        assert_eq!(file_kind(&dir.join("pipe")), FileKind::Fifo);
        assert_eq!(file_kind(&dir.join("absent")), FileKind::Missing);
        assert_eq!(file_kind(Path::new("/dev/null")), FileKind::Device);
        // Refused without blocking (a blocking open of a FIFO would hang this test).
        let e = open_regular(&dir.join("pipe")).expect_err("a FIFO");
        assert!(
            e.to_string().ends_with(
                "is a FIFO (named pipe), not an OBJ file; meshes are read from regular files only"
            ),
            "{e}"
        );
        assert!(open_regular(&dir.join("f.obj")).is_ok());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
