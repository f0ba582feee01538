//! Knowing when the open scene file changes on disk, from the operating system's file events
//! (`notify`: inotify, FSEvents, ReadDirectoryChangesW) instead of polling its modification
//! time with a repaint every second while idle. The folder is watched, not the file: text
//! editors save by writing a new file and renaming it over the old one, which ends a watch
//! on the file itself. Where events are not available (no inotify watches left, a network
//! file system that sends none), it falls back to polling.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use notify::{RecursiveMode, Watcher as _};

/// How often the fallback looks at the file's modification time.
pub const POLL_EVERY: Duration = Duration::from_millis(700);

pub struct FileWatch {
    /// The file followed, if any.
    file: Option<PathBuf>,
    /// `None` while polling (no file, or events unavailable for its folder).
    watcher: Option<notify::RecommendedWatcher>,
    /// Set by the watcher's thread when an event names the file.
    changed: Arc<AtomicBool>,
    last_poll: Instant,
}

impl Default for FileWatch {
    fn default() -> Self {
        FileWatch {
            file: None,
            watcher: None,
            changed: Arc::new(AtomicBool::new(false)),
            last_poll: Instant::now(),
        }
    }
}

impl FileWatch {
    /// Follows `file` (or nothing), waking the UI through `repaint` when it changes. Does
    /// nothing when it already follows that file.
    pub fn follow(&mut self, file: Option<&Path>, repaint: Arc<dyn Fn() + Send + Sync>) {
        if self.file.as_deref() == file {
            return;
        }
        self.file = file.map(Path::to_path_buf);
        self.watcher = None;
        self.changed.store(false, Ordering::Relaxed);
        let Some(file) = file else { return };
        self.watcher = watch_folder_of(file, self.changed.clone(), repaint)
            .map_err(|e| log::info!(target: "tracelab::watch", "{}: no file events ({e}); polling", file.display()))
            .ok();
    }

    /// Whether the file may have changed since the last call: an event named it, or (when
    /// polling) it is time to look again. The caller compares modification times to decide.
    pub fn take_changed(&mut self) -> bool {
        if self.file.is_none() {
            return false;
        }
        if self.watcher.is_some() {
            return self.changed.swap(false, Ordering::Relaxed);
        }
        if self.last_poll.elapsed() >= POLL_EVERY {
            self.last_poll = Instant::now();
            return true;
        }
        false
    }

    /// True when changes arrive as events, so an idle window needs no timed repaint.
    pub fn has_events(&self) -> bool {
        self.file.is_none() || self.watcher.is_some()
    }
}

fn watch_folder_of(
    file: &Path,
    changed: Arc<AtomicBool>,
    repaint: Arc<dyn Fn() + Send + Sync>,
) -> notify::Result<notify::RecommendedWatcher> {
    let folder = match file.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let name = file.file_name().map(|n| n.to_os_string());
    let mut w = notify::recommended_watcher(move |ev: notify::Result<notify::Event>| {
        let ours = match &ev {
            Ok(ev) => ev
                .paths
                .iter()
                .any(|p| p.file_name().map(|n| n.to_os_string()) == name),
            // Events were lost (queue overflow): look at the file to be sure.
            Err(_) => true,
        };
        if ours && !matches!(&ev, Ok(e) if e.kind.is_access()) {
            changed.store(true, Ordering::Relaxed);
            repaint();
        }
    })?;
    w.watch(&folder, RecursiveMode::NonRecursive)?;
    Ok(w)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wait_for(w: &mut FileWatch, want: bool) -> bool {
        let start = Instant::now();
        while start.elapsed() < Duration::from_secs(5) {
            if w.take_changed() == want {
                return true;
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        false
    }

    #[test]
    fn an_edit_and_a_save_by_rename_are_seen_and_a_neighbour_is_not() {
        let dir = std::env::temp_dir().join(format!("tracelab-watch-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("dir");
        let file = dir.join("scene.txt");
        std::fs::write(&file, "a").expect("write");
        let woken = Arc::new(AtomicBool::new(false));
        let w2 = woken.clone();
        let mut w = FileWatch::default();
        w.follow(
            Some(&file),
            Arc::new(move || w2.store(true, Ordering::Relaxed)),
        );
        assert!(w.has_events(), "inotify is available on Linux");
        assert!(!w.take_changed());
        // Another file in the folder: no change reported.
        std::fs::write(dir.join("other.txt"), "x").expect("write");
        std::thread::sleep(Duration::from_millis(200));
        assert!(!w.take_changed(), "a neighbour's change is not ours");
        std::fs::write(&file, "b").expect("write");
        assert!(wait_for(&mut w, true), "an edit in place is seen");
        assert!(woken.load(Ordering::Relaxed), "and wakes the window");
        // As editors save: a new file renamed over the old one.
        std::thread::sleep(Duration::from_millis(100));
        while w.take_changed() {}
        std::fs::write(dir.join(".scene.txt.tmp"), "c").expect("write");
        std::fs::rename(dir.join(".scene.txt.tmp"), &file).expect("rename");
        assert!(wait_for(&mut w, true), "a save by rename is seen");
        std::thread::sleep(Duration::from_millis(100));
        while w.take_changed() {}
        std::fs::write(&file, "d").expect("write");
        assert!(wait_for(&mut w, true), "and the watch survives it");
    }
}
