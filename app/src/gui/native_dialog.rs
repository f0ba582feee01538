//! The desktop's own file dialog (through `rfd` and the XDG desktop portal), behind the
//! `native-dialogs` cargo feature. It runs on its own thread, as egui's file-dialog example
//! advises, so the window keeps painting while it is open. Without the feature, or where the
//! desktop has no portal, the built-in dialog (`file_dialog.rs`) is used instead: it is also
//! the one the tests drive.

use std::path::{Path, PathBuf};
use std::sync::mpsc::Receiver;
use std::time::{Duration, Instant};

use crate::gui::file_dialog::Purpose;

/// A native dialog that answers "nothing chosen" faster than a person can is taken for a
/// desktop without one (the portal backend returns at once and silently where there is none).
const TOO_FAST: Duration = Duration::from_millis(150);

pub struct NativeDialog {
    pub purpose: Purpose,
    started: Instant,
    rx: Receiver<Option<PathBuf>>,
}

/// What a native dialog said.
#[derive(Debug, PartialEq)]
pub enum Answer {
    Chosen(PathBuf),
    Cancelled,
    /// No native dialog here after all: use the built-in one.
    Unavailable,
}

impl NativeDialog {
    /// Whether this build has native dialogs and the session looks like it can show one.
    pub fn available() -> bool {
        cfg!(feature = "native-dialogs")
            && (cfg!(not(target_os = "linux"))
                || std::env::var_os("DBUS_SESSION_BUS_ADDRESS").is_some())
    }

    /// Opens one, or `None` when this build or desktop has none.
    pub fn start(
        purpose: Purpose,
        start: Option<&Path>,
        repaint: std::sync::Arc<dyn Fn() + Send + Sync>,
    ) -> Option<NativeDialog> {
        if !Self::available() {
            return None;
        }
        let (tx, rx) = std::sync::mpsc::channel();
        let start = start.map(Path::to_path_buf);
        std::thread::Builder::new()
            .name("tracelab-file-dialog".into())
            .spawn(move || {
                let _ = tx.send(run(purpose, start.as_deref()));
                repaint();
            })
            .ok()?;
        Some(NativeDialog {
            purpose,
            started: Instant::now(),
            rx,
        })
    }

    /// The answer, once there is one.
    pub fn poll(&self) -> Option<Answer> {
        match self.rx.try_recv() {
            Ok(Some(p)) => Some(Answer::Chosen(p)),
            Ok(None) if self.started.elapsed() < TOO_FAST => Some(Answer::Unavailable),
            Ok(None) => Some(Answer::Cancelled),
            Err(std::sync::mpsc::TryRecvError::Empty) => None,
            Err(std::sync::mpsc::TryRecvError::Disconnected) => Some(Answer::Unavailable),
        }
    }
}

#[cfg(feature = "native-dialogs")]
fn run(purpose: Purpose, start: Option<&Path>) -> Option<PathBuf> {
    let mut d = rfd::FileDialog::new().add_filter(purpose.filter_name(), purpose.extensions());
    if let Some(p) = start {
        let (dir, name) = if p.is_dir() {
            (Some(p), None)
        } else {
            (p.parent(), p.file_name())
        };
        if let Some(dir) = dir.filter(|d| !d.as_os_str().is_empty()) {
            d = d.set_directory(dir);
        }
        if let Some(name) = name.filter(|_| purpose != Purpose::Open) {
            let name = Path::new(name);
            let name = if purpose == Purpose::Export {
                name.with_extension("png")
            } else {
                name.to_path_buf()
            };
            d = d.set_file_name(name.to_string_lossy());
        }
    }
    match purpose {
        Purpose::Open => d.set_title("Open scene").pick_file(),
        Purpose::SaveAs => d.set_title("Save scene as").save_file(),
        Purpose::Export => d.set_title("Export view").save_file(),
    }
}

#[cfg(not(feature = "native-dialogs"))]
fn run(_purpose: Purpose, _start: Option<&Path>) -> Option<PathBuf> {
    None
}
