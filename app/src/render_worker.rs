//! Background rendering. The UI submits an immutable snapshot of the scene with its
//! generation; the worker compiles it, cancels the render in flight, and renders the new one
//! progressively into fresh frames. The UI thread never renders and never waits: it reads the
//! latest published result, and results of older generations are simply replaced.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, Sender, channel};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::{Duration, Instant};

use tracelab_core::render::{NormalGap, RenderPlan, normal_rule_gap, render};
use tracelab_core::{CompiledScene, NormalTransform, RenderSettings, Scene, SharedFrame};

/// The course's uniform grid for the view (View › Uniform grid): `-grid NX NY NZ`, and
/// `-visualize_grid`'s picture of its occupied cells in place of the render.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GridRequest {
    pub cells: [u32; 3],
    pub visualize: bool,
}

/// What to render: one frame per normal rule in `modes` (two in compare mode).
#[derive(Clone, Debug)]
pub struct Job {
    pub generation: u64,
    /// Counts requests: a view change (size, normal rule) renders the same generation
    /// again, and only this tells the two renders apart.
    pub request: u64,
    pub scene: Arc<Scene>,
    pub settings: RenderSettings,
    pub modes: Vec<NormalTransform>,
    /// When the edit that caused this job happened (for edit→image timings).
    pub submitted: Instant,
    /// Only the coarse passes (the view is being dragged).
    pub coarse: bool,
    /// Render through the course's uniform grid (or show it) instead of the BVH.
    pub grid: Option<GridRequest>,
}

/// The render the UI should show.
pub struct Published {
    pub job: Job,
    pub compiled: Arc<CompiledScene>,
    /// One per `job.modes`, filled progressively.
    pub frames: Vec<Arc<SharedFrame>>,
    /// Passes completed by every frame (the least of them; `passes` once all are done).
    pub passes_done: usize,
    /// Passes planned, the most of any frame (fewer once a quick coarse pass skips some).
    pub passes: usize,
    pub first_image: Option<Duration>,
    pub full: Option<Duration>,
    /// The largest angle between the two normal rules over this render's pixels, computed
    /// after the full image (so it never delays it).
    pub normal_gap: Option<NormalGap>,
    /// Why the grid the job asked for was not built (too many cells or entries): the render
    /// went through the BVH instead, and the editor says so.
    pub grid_error: Option<String>,
}

#[derive(Default)]
struct Shared {
    published: Mutex<Option<Published>>,
    repaint: Mutex<Option<Box<dyn Fn() + Send>>>,
}

pub struct RenderWorker {
    tx: Option<Sender<(Job, Arc<AtomicBool>)>>,
    cancel: Arc<AtomicBool>,
    shared: Arc<Shared>,
    thread: Option<std::thread::JoinHandle<()>>,
    /// Why there is no render thread (the system refused one): the view says so instead of
    /// "Rendering…" forever.
    spawn_error: Option<String>,
    last_generation: u64,
    requests: u64,
    /// Every setting of the last request (all of `RenderSettings`, so a new one such as the
    /// rays of View › Rays can never be left out of it), its normal rules and coarseness.
    last_key: Option<(
        RenderSettings,
        Vec<NormalTransform>,
        bool,
        Option<GridRequest>,
    )>,
    /// Render only the coarse passes from now on (the view is being dragged); a request with
    /// this off renders the same generation again in full.
    pub coarse_only: bool,
    /// The uniform grid of the requests from now on (View › Uniform grid); `None`: the BVH.
    pub grid: Option<GridRequest>,
}

impl Default for RenderWorker {
    fn default() -> Self {
        Self::new()
    }
}

impl RenderWorker {
    pub fn new() -> Self {
        let (tx, rx) = channel::<(Job, Arc<AtomicBool>)>();
        let shared = Arc::new(Shared::default());
        let s = shared.clone();
        let spawned = std::thread::Builder::new()
            .name("tracelab-render".into())
            .spawn(move || worker_loop(&rx, &s));
        let (thread, spawn_error) = match spawned {
            Ok(t) => (Some(t), None),
            Err(e) => (None, Some(e.to_string())),
        };
        RenderWorker {
            tx: Some(tx),
            cancel: Arc::new(AtomicBool::new(false)),
            shared,
            thread,
            spawn_error,
            last_generation: 0,
            requests: 0,
            last_key: None,
            coarse_only: false,
            grid: None,
        }
    }

    /// A worker whose thread could not be started, as when the system refuses one (tests of
    /// what the window shows then).
    pub fn failed_to_start(why: &str) -> Self {
        let mut w = Self::new();
        w.tx = None;
        if let Some(t) = w.thread.take() {
            let _ = t.join();
        }
        w.spawn_error = Some(why.to_string());
        w
    }

    /// Why there is no render thread, if there is none: nothing will ever be rendered.
    pub fn spawn_error(&self) -> Option<&str> {
        self.spawn_error.as_deref()
    }

    /// Called (from the worker thread) whenever there are new pixels to show.
    pub fn set_repaint(&self, f: impl Fn() + Send + 'static) {
        *self
            .shared
            .repaint
            .lock()
            .unwrap_or_else(PoisonError::into_inner) = Some(Box::new(f));
    }

    /// Starts a render unless the same generation at the same settings is already going.
    /// Returns whether a new render started.
    pub fn request(
        &mut self,
        generation: u64,
        scene: impl FnOnce() -> Arc<Scene>,
        settings: RenderSettings,
        modes: Vec<NormalTransform>,
    ) -> bool {
        let key = (settings, modes.clone(), self.coarse_only, self.grid);
        if generation == self.last_generation && self.last_key.as_ref() == Some(&key) {
            return false;
        }
        self.last_generation = generation;
        self.last_key = Some(key);
        // Stop the render in flight within a tile; the next job gets a fresh flag.
        self.cancel.store(true, Ordering::Relaxed);
        self.cancel = Arc::new(AtomicBool::new(false));
        self.requests += 1;
        let job = Job {
            generation,
            request: self.requests,
            scene: scene(),
            settings,
            modes,
            submitted: Instant::now(),
            coarse: self.coarse_only,
            grid: self.grid,
        };
        if let Some(tx) = &self.tx {
            let _ = tx.send((job, self.cancel.clone()));
        }
        true
    }

    /// Reads the latest published render.
    pub fn with_published<R>(&self, f: impl FnOnce(Option<&Published>) -> R) -> R {
        let p = self
            .shared
            .published
            .lock()
            .unwrap_or_else(PoisonError::into_inner);
        f(p.as_ref())
    }

    /// Whether the newest request has been fully rendered.
    pub fn is_idle(&self) -> bool {
        self.with_published(|p| {
            // The normal-rule gap is part of what is shown (the toolbar), so idle waits for it.
            p.is_some_and(|p| {
                p.job.request == self.requests && p.full.is_some() && p.normal_gap.is_some()
            })
        })
    }

    /// Waits up to `budget` for the newest request's last pass (polling every millisecond);
    /// true when it is done.
    pub fn wait_for_full(&self, budget: Duration) -> bool {
        let start = Instant::now();
        loop {
            let done = self.with_published(|p| {
                p.is_some_and(|p| p.job.request == self.requests && p.full.is_some())
            });
            if done || start.elapsed() >= budget {
                return done;
            }
            std::thread::sleep(Duration::from_millis(1));
        }
    }

    pub fn last_generation(&self) -> u64 {
        self.last_generation
    }
}

impl Drop for RenderWorker {
    fn drop(&mut self) {
        self.cancel.store(true, Ordering::Relaxed);
        self.tx = None;
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// From each frame's (passes done, passes planned): the passes every frame has done (all of
/// them once every frame is finished), the most any plans, and whether all are finished.
fn passes_of(frames: &[(usize, usize)]) -> (usize, usize, bool) {
    let planned = frames.iter().map(|f| f.1).max().unwrap_or(0);
    let finished = frames.iter().all(|&(done, plan)| plan > 0 && done == plan);
    let least = frames.iter().map(|f| f.0).min().unwrap_or(0);
    (if finished { planned } else { least }, planned, finished)
}

fn worker_loop(rx: &Receiver<(Job, Arc<AtomicBool>)>, shared: &Shared) {
    let log = log::log_enabled!(target: crate::logging::TIMES, log::Level::Info);
    while let Ok(mut next) = rx.recv() {
        // Only the newest request matters.
        while let Ok(newer) = rx.try_recv() {
            next = newer;
        }
        let (job, cancel) = next;
        if cancel.load(Ordering::Relaxed) {
            continue;
        }
        let mut compiled = CompiledScene::new(&job.scene);
        let grid_error = job.grid.and_then(|g| {
            let [x, y, z] = g.cells;
            compiled
                .use_grid(glam::UVec3::new(x, y, z))
                .err()
                .map(|e| e.to_string())
        });
        let compiled = Arc::new(compiled);
        let frames: Vec<Arc<SharedFrame>> = job
            .modes
            .iter()
            .map(|_| Arc::new(SharedFrame::new()))
            .collect();
        // Per frame: passes done and passes planned (a quick coarse pass skips the passes
        // before the full one, and the flip view's two frames may not skip the same).
        let counts: Vec<[std::sync::atomic::AtomicUsize; 2]> =
            job.modes.iter().map(|_| Default::default()).collect();
        {
            // The UI keeps showing its previous image until this one has its first pass.
            let mut p = shared
                .published
                .lock()
                .unwrap_or_else(PoisonError::into_inner);
            let new = Published {
                job: job.clone(),
                compiled: compiled.clone(),
                frames: frames.clone(),
                passes_done: 0,
                passes: 0,
                first_image: None,
                full: None,
                normal_gap: None,
                grid_error,
            };
            *p = Some(new);
        }
        let on_pass = |i: usize, info: tracelab_core::render::PassInfo| {
            // Under the lock, so the last frame to finish sees the other's counts.
            let mut p = shared
                .published
                .lock()
                .unwrap_or_else(PoisonError::into_inner);
            counts[i][0].store(info.pass + 1, Ordering::Relaxed);
            counts[i][1].store(info.passes, Ordering::Relaxed);
            let now: Vec<(usize, usize)> = counts
                .iter()
                .map(|c| (c[0].load(Ordering::Relaxed), c[1].load(Ordering::Relaxed)))
                .collect();
            let (done, planned, finished) = passes_of(&now);
            if let Some(p) = p.as_mut().filter(|p| p.job.request == job.request) {
                p.passes = planned;
                if done > p.passes_done {
                    let t = job.submitted.elapsed();
                    if p.passes_done == 0 {
                        p.first_image = Some(t);
                    }
                    p.passes_done = done;
                    if finished {
                        p.full = Some(t);
                    }
                }
            }
            drop(p);
            if let Some(f) = shared
                .repaint
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
                .as_ref()
            {
                f();
            }
        };
        let render_one = |i: usize| {
            let settings = RenderSettings {
                normal_transform: job.modes[i],
                ..job.settings
            };
            let pass = |info: tracelab_core::render::PassInfo| on_pass(i, info);
            if job.grid.is_some_and(|g| g.visualize) && compiled.grid().is_some() {
                // `-visualize_grid`'s picture, made in one go as the command line makes it.
                let start = Instant::now();
                frames[i].set(tracelab_core::render::visualize_grid(
                    &compiled,
                    settings.width,
                    settings.height,
                ));
                pass(tracelab_core::render::PassInfo {
                    pass: 0,
                    passes: 1,
                    scale: 1,
                    elapsed: start.elapsed(),
                });
                return !cancel.load(Ordering::Relaxed);
            }
            let plan = if job.coarse {
                RenderPlan::COARSE
            } else {
                RenderPlan::PROGRESSIVE
            };
            render(&compiled, &settings, plan, &frames[i], &*cancel, pass).is_ok()
        };
        let ok = if frames.len() == 2 {
            let (a, b) = rayon::join(|| render_one(0), || render_one(1));
            a && b
        } else {
            (0..frames.len()).all(render_one)
        };
        let repaint = || {
            if let Some(f) = shared
                .repaint
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
                .as_ref()
            {
                f();
            }
        };
        if ok && let Ok(gap) = normal_rule_gap(&compiled, &job.settings, &cancel) {
            if let Some(p) = shared
                .published
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
                .as_mut()
                && p.job.request == job.request
            {
                p.normal_gap = Some(gap);
            }
            repaint();
        }
        if ok && log {
            shared.published.lock().unwrap_or_else(PoisonError::into_inner).as_ref().inspect(|p| {
                log::info!(
                    target: crate::logging::TIMES,
                    "generation {} {}x{}{}{}: edit to first image {:.1} ms, to full refinement {:.1} ms",
                    p.job.generation,
                    p.job.settings.width,
                    p.job.settings.height,
                    if p.frames.len() > 1 { " (compare)" } else { "" },
                    if p.job.coarse { " (coarse, dragging)" } else { "" },
                    p.first_image.unwrap_or_default().as_secs_f64() * 1e3,
                    p.full.unwrap_or_default().as_secs_f64() * 1e3,
                );
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The flip view's two frames may plan different passes (one skipping some): the
    /// render is full once both are done, and not before.
    #[test]
    fn a_render_is_full_when_every_frame_has_done_its_own_passes() {
        assert_eq!(passes_of(&[(0, 0), (0, 0)]), (0, 0, false));
        assert_eq!(
            passes_of(&[(1, 4), (0, 0)]),
            (0, 4, false),
            "one frame yet to report"
        );
        assert_eq!(passes_of(&[(2, 3), (1, 4)]), (1, 4, false));
        assert_eq!(
            passes_of(&[(3, 3), (3, 4)]),
            (3, 4, false),
            "the skipper done, the other not"
        );
        assert_eq!(passes_of(&[(3, 3), (4, 4)]), (4, 4, true));
        assert_eq!(passes_of(&[(3, 3)]), (3, 3, true));
        assert_eq!(
            passes_of(&[(2, 2), (2, 2)]),
            (2, 2, true),
            "coarse passes only"
        );
    }

    fn scene() -> Arc<Scene> {
        let out = tracelab_core::parse_scene(
            crate::DEFAULT_SCENE.as_bytes(),
            "default",
            None,
            &mut tracelab_core::MeshCache::new(),
        );
        Arc::new(out.scene.expect("built-in scene parses"))
    }

    fn wait_idle(w: &RenderWorker) {
        let start = Instant::now();
        while !w.is_idle() {
            assert!(
                start.elapsed() < Duration::from_secs(30),
                "worker never finished"
            );
            std::thread::sleep(Duration::from_millis(2));
        }
    }

    #[test]
    fn a_newer_generation_replaces_the_render_in_flight() {
        let mut w = RenderWorker::new();
        let s = scene();
        // A large first job, replaced at once: only the newest may be published at the end.
        assert!(w.request(
            1,
            || s.clone(),
            RenderSettings::new(1600, 1600),
            vec![NormalTransform::Correct]
        ));
        assert!(w.request(
            2,
            || s.clone(),
            RenderSettings::new(32, 24),
            vec![NormalTransform::Correct]
        ));
        wait_idle(&w);
        w.with_published(|p| {
            let p = p.expect("published");
            assert_eq!(p.job.generation, 2);
            assert_eq!(p.passes_done, p.passes);
            let f = p.frames[0].lock();
            assert_eq!((f.width, f.height), (32, 24));
        });
    }

    #[test]
    fn the_same_request_twice_does_not_restart() {
        let mut w = RenderWorker::new();
        let s = scene();
        let settings = RenderSettings::new(16, 16);
        assert!(w.request(5, || s.clone(), settings, vec![NormalTransform::Correct]));
        assert!(!w.request(5, || s.clone(), settings, vec![NormalTransform::Correct]));
        // A new size or rule is a new render even at the same generation.
        assert!(w.request(
            5,
            || s.clone(),
            settings,
            vec![NormalTransform::Correct, NormalTransform::Incorrect]
        ));
        wait_idle(&w);
        w.with_published(|p| assert_eq!(p.expect("published").frames.len(), 2));
    }

    #[test]
    fn a_new_rule_at_the_same_generation_is_not_idle_until_it_is_rendered() {
        // A view change keeps the document's generation; the finished render of the old
        // rule must not count as the new one being done (the GUI test of the normal switch
        // once read the old image this way).
        let mut w = RenderWorker::new();
        let s = scene();
        let settings = RenderSettings::new(400, 400);
        assert!(w.request(7, || s.clone(), settings, vec![NormalTransform::Correct]));
        wait_idle(&w);
        assert!(w.request(7, || s.clone(), settings, vec![NormalTransform::Incorrect]));
        assert!(!w.is_idle(), "idle before the Incorrect render ran");
        wait_idle(&w);
        w.with_published(|p| {
            assert_eq!(
                p.expect("published").job.modes,
                [NormalTransform::Incorrect]
            );
        });
    }
}
