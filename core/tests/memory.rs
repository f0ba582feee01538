//! What reading a hostile scene file costs in memory, measured by a counting allocator: the
//! peak above what was allocated before parsing must stay a small multiple of the input
//! (the issue: a file of `{` cost 24 bytes of tokens per byte; a field of millions of
//! numbers held 16-32 bytes per number).

#![allow(unsafe_code)] // a GlobalAlloc wrapper is unsafe by definition

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use tracelab_core::{MeshCache, parse_scene};

struct Counting;
static NOW: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

// SAFETY: forwards to the system allocator unchanged; only counts.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        let now = NOW.fetch_add(l.size(), Ordering::Relaxed) + l.size();
        PEAK.fetch_max(now, Ordering::Relaxed);
        // SAFETY: as the caller promised for `l`.
        unsafe { System.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        NOW.fetch_sub(l.size(), Ordering::Relaxed);
        // SAFETY: `p` came from `alloc` with `l`.
        unsafe { System.dealloc(p, l) }
    }
}

#[global_allocator]
static A: Counting = Counting;

/// One test at a time: the counters are process-wide.
static SERIAL: Mutex<()> = Mutex::new(());

/// The text `make` builds, and the peak bytes allocated while parsing it above what was
/// allocated before (made under the lock, so no other test's allocations count).
fn parse_peak(make: impl FnOnce() -> Vec<u8>) -> (usize, usize, Vec<String>) {
    let _one = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let text = make();
    let base = NOW.load(Ordering::Relaxed);
    PEAK.store(base, Ordering::Relaxed);
    let out = parse_scene(&text, "hostile.txt", None, &mut MeshCache::new());
    let peak = PEAK.load(Ordering::Relaxed) - base;
    let msgs = out.diagnostics.0.iter().map(|d| d.to_string()).collect();
    (text.len(), peak, msgs)
}

const MB: usize = 1 << 20;

#[test]
fn a_file_of_braces_costs_little_more_than_its_size() {
    let (len, peak, msgs) = parse_peak(|| vec![b'{'; 16 * MB]);
    assert!(
        peak < len,
        "peak {} MB for {} MB of braces",
        peak / MB,
        len / MB
    );
    assert!(msgs.len() <= 21, "{msgs:?}");
}

#[test]
fn a_field_of_millions_of_numbers_is_refused_not_held() {
    let (len, peak, msgs) = parse_peak(|| {
        let mut text = b"OrthographicCamera { center ".to_vec();
        text.extend(b"1 ".repeat(8 * MB));
        text.extend(b"}\n");
        text
    });
    assert!(
        peak < len,
        "peak {} MB for {} MB of numbers",
        peak / MB,
        len / MB
    );
    assert!(
        msgs[0].contains("\"center\" takes at most 1024 numbers"),
        "{msgs:?}"
    );
}

#[test]
fn a_file_of_newlines_with_an_error_costs_at_most_four_bytes_a_line() {
    let (len, peak, msgs) = parse_peak(|| {
        let mut text = vec![b'\n'; 16 * MB];
        text.extend(b"}\n");
        text
    });
    assert!(
        peak < 5 * len,
        "peak {} MB for {} MB of newlines",
        peak / MB,
        len / MB
    );
    assert!(
        msgs[0].starts_with(&format!("hostile.txt:{}:1:", 16 * MB + 1)),
        "{msgs:?}"
    );
}
