//! Progress of long command-line work (a render, an animation's frames) on standard error,
//! drawn by indicatif (terminal width, redraws, rate limits). Drawn only when standard error
//! is a terminal, and only once the work has taken a second, so a quick job prints nothing;
//! with standard error redirected (scripts, tests, a grading server) nothing is printed.

use std::io::IsTerminal;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// A job shorter than this shows no bar.
const SHOW_AFTER: Duration = Duration::from_secs(1);

pub(super) struct Progress {
    bar: ProgressBar,
    /// Where the bar goes once `SHOW_AFTER` has passed; `None` once shown, or never to show.
    pending: Option<ProgressDrawTarget>,
    shown: bool,
    start: Instant,
    show_after: Duration,
}

impl Progress {
    /// A bar of `len` steps drawn with indicatif's `template`, on standard error if that is
    /// a terminal.
    pub fn on_stderr(template: &str, len: u64) -> Progress {
        let target = std::io::stderr()
            .is_terminal()
            .then(ProgressDrawTarget::stderr);
        Progress::new(template, len, target, SHOW_AFTER)
    }

    fn new(
        template: &str,
        len: u64,
        target: Option<ProgressDrawTarget>,
        show_after: Duration,
    ) -> Progress {
        let bar = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::hidden());
        // The templates are ours and fixed; a bad one would still draw the default bar.
        bar.set_style(
            ProgressStyle::with_template(template).unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        Progress {
            bar,
            pending: target,
            shown: false,
            start: Instant::now(),
            show_after,
        }
    }

    /// Whether anything can be drawn (standard error is a terminal).
    pub fn on_terminal(&self) -> bool {
        self.pending.is_some() || self.shown
    }

    /// `done` steps of `len` are done.
    pub fn set(&mut self, done: u64) {
        if self.start.elapsed() >= self.show_after
            && let Some(target) = self.pending.take()
        {
            self.bar.set_draw_target(target);
            self.shown = true;
        }
        self.bar.set_position(done);
    }

    /// The work is done: a bar that was shown is left at 100%.
    pub fn finish(self) {
        if self.shown {
            self.bar.finish();
        }
    }
}

/// A bar redrawn from another thread every 100 ms while work that cannot report its own
/// progress runs (a render, a film), reading `done` (steps of `len`). Nothing is spawned when
/// standard error is no terminal.
pub(super) struct Watcher {
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

impl Watcher {
    pub fn on_stderr(template: &str, len: u64, done: impl Fn() -> u64 + Send + 'static) -> Self {
        Watcher::drawing(Progress::on_stderr(template, len), len, done)
    }

    fn drawing(mut bar: Progress, len: u64, done: impl Fn() -> u64 + Send + 'static) -> Self {
        let stop = Arc::new(AtomicBool::new(false));
        let thread = bar.on_terminal().then(|| {
            let stop = stop.clone();
            std::thread::spawn(move || {
                while !stop.load(Ordering::Relaxed) {
                    std::thread::sleep(Duration::from_millis(100));
                    bar.set(done().min(len));
                }
                bar.finish();
            })
        });
        Watcher { stop, thread }
    }

    /// The work is done: the bar (if shown) is finished before this returns.
    pub fn finish(self) {
        drop(self);
    }
}

/// Also when the work ends early (an error returned with `?`, a panic unwinding): the
/// thread is stopped and the bar finished, rather than left redrawing until the process
/// exits.
impl Drop for Watcher {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use std::sync::{Arc, Mutex};

    use indicatif::TermLike;

    use super::*;

    /// A terminal that keeps what is written to it.
    #[derive(Debug, Clone, Default)]
    struct Screen(Arc<Mutex<String>>);

    impl Screen {
        fn text(&self) -> String {
            self.0.lock().expect("screen").clone()
        }
        fn put(&self, s: &str) -> std::io::Result<()> {
            self.0.lock().expect("screen").push_str(s);
            Ok(())
        }
    }

    impl TermLike for Screen {
        fn width(&self) -> u16 {
            80
        }
        fn move_cursor_up(&self, _: usize) -> std::io::Result<()> {
            Ok(())
        }
        fn move_cursor_down(&self, _: usize) -> std::io::Result<()> {
            Ok(())
        }
        fn move_cursor_right(&self, _: usize) -> std::io::Result<()> {
            Ok(())
        }
        fn move_cursor_left(&self, _: usize) -> std::io::Result<()> {
            Ok(())
        }
        fn write_line(&self, s: &str) -> std::io::Result<()> {
            self.put(&format!("{s}\n"))
        }
        fn write_str(&self, s: &str) -> std::io::Result<()> {
            self.put(s)
        }
        fn clear_line(&self) -> std::io::Result<()> {
            Ok(())
        }
        fn flush(&self) -> std::io::Result<()> {
            Ok(())
        }
    }

    const TEMPLATE: &str = "rendering [{bar:10}] {percent:>3}%";

    fn on_screen(show_after: Duration) -> (Progress, Screen) {
        let screen = Screen::default();
        let target = ProgressDrawTarget::term_like(Box::new(screen.clone()));
        (
            Progress::new(TEMPLATE, 100, Some(target), show_after),
            screen,
        )
    }

    #[test]
    fn a_long_job_on_a_terminal_draws_the_bar_and_ends_at_100_percent() {
        let (mut p, screen) = on_screen(Duration::ZERO);
        assert!(p.on_terminal());
        p.set(50);
        p.finish();
        let text = screen.text();
        assert!(text.contains("rendering ["), "{text:?}");
        assert!(text.contains("100%"), "{text:?}");
    }

    #[test]
    fn a_watcher_dropped_without_finish_stops_its_thread_and_finishes_the_bar() {
        use std::sync::atomic::AtomicU64;
        let (bar, screen) = on_screen(Duration::ZERO);
        let calls = Arc::new(AtomicU64::new(0));
        let counted = calls.clone();
        let watcher = Watcher::drawing(bar, 100, move || {
            counted.fetch_add(1, Ordering::Relaxed);
            50
        });
        // Control: the thread runs while the watcher lives.
        let start = Instant::now();
        while calls.load(Ordering::Relaxed) == 0 && start.elapsed() < Duration::from_secs(10) {
            std::thread::sleep(Duration::from_millis(20));
        }
        assert!(
            calls.load(Ordering::Relaxed) > 0,
            "the bar's thread never ran"
        );
        // Work that ends with an error instead of calling `finish`.
        fn fails_early(_w: Watcher) -> Result<(), &'static str> {
            Err("the render failed")
        }
        assert!(fails_early(watcher).is_err());
        // Dropped means joined: no call can follow (one every 100 ms while it ran).
        let after = calls.load(Ordering::Relaxed);
        std::thread::sleep(Duration::from_millis(500));
        assert_eq!(
            calls.load(Ordering::Relaxed),
            after,
            "the thread still runs"
        );
        assert!(screen.text().contains("100%"), "{:?}", screen.text());
    }

    #[test]
    fn a_job_quicker_than_the_delay_draws_nothing() {
        let (mut p, screen) = on_screen(Duration::from_secs(3600));
        p.set(50);
        p.finish();
        assert_eq!(screen.text(), "");
    }

    #[test]
    fn without_a_terminal_the_bar_stays_hidden() {
        let mut p = Progress::new(TEMPLATE, 100, None, Duration::ZERO);
        assert!(!p.on_terminal());
        p.set(50);
        assert!(p.bar.is_hidden());
        p.finish();
    }
}
