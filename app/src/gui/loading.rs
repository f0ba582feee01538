//! Opening scene files off the UI thread. Reading the 871k-triangle dragon and building its
//! BVH takes seconds; done on the UI thread it froze the window. The app starts a
//! [`Loading`], keeps the open scene usable, shows the progress, and takes the result when it
//! comes, or drops it when the user cancels (which also stops the read at its next step).

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, TryRecvError, channel};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::{Duration, Instant};

use tracelab_core::{MeshCache, MeshEvent};

use crate::io::{SceneRead, read_scene_file};

/// Why a file is being read: what to do with it when it arrives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LoadPurpose {
    /// Open it as the document, asking first when there are unsaved changes.
    Open,
    /// The open file again, asked for (File › Reload, "Reload (lose edits)"): replace
    /// without asking, keeping the selection.
    Reload,
    /// The open file again because it changed on disk while nothing was unsaved: replace
    /// quietly, unless edits were made while it was being read; then ask.
    Refresh,
}

/// Where the loader thread is.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Progress {
    /// Meshes read from disk so far (cached ones are not counted: they cost nothing).
    pub meshes_done: usize,
    /// The mesh being read now and its step.
    pub current: Option<(PathBuf, Step)>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    Reading { bytes: u64 },
    Parsing,
    Building { triangles: usize },
}

pub struct Loading {
    pub path: PathBuf,
    pub purpose: LoadPurpose,
    started: Instant,
    progress: Arc<Mutex<Progress>>,
    cancel: Arc<AtomicBool>,
    rx: Receiver<SceneRead>,
}

impl Loading {
    /// Starts reading `path` on a new thread with `cache` (a copy of the document's: the
    /// original stays in use meanwhile). `repaint` is called whenever there is news.
    pub fn start(
        path: &Path,
        purpose: LoadPurpose,
        mut cache: MeshCache,
        repaint: Arc<dyn Fn() + Send + Sync>,
    ) -> Loading {
        let progress = Arc::new(Mutex::new(Progress::default()));
        let cancel = Arc::new(AtomicBool::new(false));
        let (p, c, r) = (progress.clone(), cancel.clone(), repaint.clone());
        cache.set_observer(Some(Arc::new(move |e: MeshEvent<'_>| {
            let mut g = p.lock().unwrap_or_else(PoisonError::into_inner);
            match e {
                MeshEvent::Reading { path, bytes } => {
                    g.current = Some((path.to_path_buf(), Step::Reading { bytes }))
                }
                MeshEvent::Parsing { path } => {
                    g.current = Some((path.to_path_buf(), Step::Parsing))
                }
                MeshEvent::Building { path, triangles } => {
                    g.current = Some((path.to_path_buf(), Step::Building { triangles }));
                }
                MeshEvent::Done { .. } => {
                    g.current = None;
                    g.meshes_done += 1;
                }
            }
            drop(g);
            r();
            !c.load(Ordering::Relaxed)
        })));
        let (tx, rx) = channel();
        let file = path.to_path_buf();
        let spawned = std::thread::Builder::new()
            .name("tracelab-open".into())
            .spawn(move || {
                let mut read = read_scene_file(&file, cache);
                read.cache.set_observer(None);
                // After a cancel nobody listens: the result is dropped here.
                let _ = tx.send(read);
                repaint();
            });
        let rx = match spawned {
            Ok(_) => rx,
            Err(e) => {
                // No thread to be had: say so as the outcome of the load.
                let (tx, rx) = channel();
                let _ = tx.send(SceneRead {
                    path: path.to_path_buf(),
                    outcome: Err(vec![format!(
                        "{}: cannot start reading: {e}",
                        path.display()
                    )]),
                    cache: MeshCache::new(),
                });
                rx
            }
        };
        Loading {
            path: path.to_path_buf(),
            purpose,
            started: Instant::now(),
            progress,
            cancel,
            rx,
        }
    }

    /// The result, once the thread is done.
    pub fn poll(&self) -> Option<SceneRead> {
        match self.rx.try_recv() {
            Ok(r) => Some(r),
            Err(TryRecvError::Empty) => None,
            Err(TryRecvError::Disconnected) => Some(SceneRead {
                path: self.path.clone(),
                outcome: Err(vec![format!(
                    "{}: reading stopped unexpectedly",
                    self.path.display()
                )]),
                cache: MeshCache::new(),
            }),
        }
    }

    /// Stops the read at its next step; its result, if any still comes, is never used.
    pub fn cancel(self) {
        self.cancel.store(true, Ordering::Relaxed);
    }

    pub fn progress(&self) -> Progress {
        self.progress
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .clone()
    }

    pub fn elapsed(&self) -> Duration {
        self.started.elapsed()
    }

    /// A rough fraction for the progress bar: meshes done, plus the steps of the current
    /// one (reading, parsing and building take about a third of the time each on the dragon).
    pub fn fraction(&self) -> f32 {
        let p = self.progress();
        let step = match p.current.as_ref().map(|c| c.1) {
            None => 0.0,
            Some(Step::Reading { .. }) => 0.05,
            Some(Step::Parsing) => 0.3,
            Some(Step::Building { .. }) => 0.6,
        };
        let total = p.meshes_done + usize::from(p.current.is_some());
        if total == 0 {
            0.0
        } else {
            (p.meshes_done as f32 + step) / total as f32
        }
    }

    /// One line: what is being read, and for how long.
    pub fn describe(&self) -> String {
        let p = self.progress();
        let name = |p: &Path| {
            p.file_name().map_or_else(
                || p.display().to_string(),
                |n| n.to_string_lossy().to_string(),
            )
        };
        let what = match &p.current {
            Some((mesh, Step::Reading { bytes })) => {
                format!("reading {} ({:.1} MB)", name(mesh), *bytes as f64 / 1e6)
            }
            Some((mesh, Step::Parsing)) => format!("parsing {}", name(mesh)),
            Some((mesh, Step::Building { triangles })) => {
                format!(
                    "building the BVH of {} ({} triangles)",
                    name(mesh),
                    thousands(*triangles)
                )
            }
            None if p.meshes_done > 0 => format!("{} mesh(es) read, finishing", p.meshes_done),
            None => "reading the scene".to_string(),
        };
        let verb = match self.purpose {
            LoadPurpose::Open => "Opening",
            LoadPurpose::Reload | LoadPurpose::Refresh => "Reloading",
        };
        format!(
            "{verb} {}: {what} · {:.1} s",
            name(&self.path),
            self.elapsed().as_secs_f64()
        )
    }
}

fn thousands(n: usize) -> String {
    let s = n.to_string();
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if i > 0 && (s.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wait(l: &Loading) -> SceneRead {
        let start = Instant::now();
        loop {
            if let Some(r) = l.poll() {
                return r;
            }
            assert!(start.elapsed() < Duration::from_secs(30), "never finished");
            std::thread::sleep(Duration::from_millis(2));
        }
    }

    #[test]
    fn a_scene_with_a_mesh_loads_on_a_thread_and_reports_its_steps() {
        let dir = std::env::temp_dir().join(format!("tracelab-loading-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("dir");
        let cube = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/cube.obj");
        let scene = dir.join("s.txt");
        std::fs::write(
            &scene,
            format!(
                "OrthographicCamera {{ center 0 0 10 direction 0 0 -1 up 0 1 0 size 3 }}\n\
                 Group {{ numObjects 1 TriangleMesh {{ obj_file {} }} }}\n",
                cube.display()
            ),
        )
        .expect("write");
        let news = Arc::new(Mutex::new(0usize));
        let n = news.clone();
        let l = Loading::start(
            &scene,
            LoadPurpose::Open,
            MeshCache::new(),
            Arc::new(move || *n.lock().expect("lock") += 1),
        );
        let read = wait(&l);
        assert!(read.outcome.is_ok());
        assert_eq!(l.progress().meshes_done, 1);
        assert!((l.fraction() - 1.0).abs() < 1e-6);
        // Four mesh steps and the end: each asked for a repaint.
        assert!(*news.lock().expect("lock") >= 5);
        // The cache came back with the mesh in it: loading it again reads nothing.
        let mut cache = read.cache;
        let reads = Arc::new(Mutex::new(0usize));
        let r = reads.clone();
        cache.set_observer(Some(Arc::new(move |_| {
            *r.lock().expect("lock") += 1;
            true
        })));
        assert!(cache.load(&cube).is_ok());
        assert_eq!(*reads.lock().expect("lock"), 0);
    }

    #[test]
    fn a_file_that_is_not_there_fails_as_a_message() {
        let l = Loading::start(
            Path::new("/nonexistent/scene.txt"),
            LoadPurpose::Open,
            MeshCache::new(),
            Arc::new(|| {}),
        );
        let read = wait(&l);
        let e = read.outcome.err().expect("an error");
        assert!(
            e.iter().any(|m| m.contains("/nonexistent/scene.txt")),
            "{e:?}"
        );
        assert!(
            l.describe().starts_with("Opening scene.txt: "),
            "{}",
            l.describe()
        );
    }

    #[test]
    fn thousands_are_grouped() {
        assert_eq!(thousands(871_414), "871,414");
        assert_eq!(thousands(12), "12");
        assert_eq!(thousands(1_000), "1,000");
    }
}
