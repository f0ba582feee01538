//! The `tracelab` binary: the command line, and (with no subcommand) the GUI.

fn main() -> std::process::ExitCode {
    tracelab_core::memory::set_out_of_memory_handler(orderly_oom::report);
    tracelab::cli::main()
}

/// Running out of memory ends the program with a message and exit 1, never an abort: the big
/// buffers are allocated fallibly and say what did not fit; any other allocation that fails
/// (a small one that happened to cross a memory limit) lands here. Stable Rust has no other
/// way to replace the abort of `handle_alloc_error`, hence the allocator (measured: a
/// million-sphere scene under `ulimit -v` aborted in a dozen different small allocations).
#[allow(unsafe_code)]
mod orderly_oom {
    use std::alloc::{GlobalAlloc, Layout, System};
    use std::io::Write;

    pub struct Orderly;

    /// A buffer that did not fit, reported by core (`memory::fail_as_infallible`).
    pub fn report(e: tracelab_core::OutOfMemory) {
        let _ = writeln!(std::io::stderr().lock(), "tracelab: {e}");
        std::process::exit(1);
    }

    /// A failed allocation that nobody handles: say so and exit 1. Allocates nothing.
    #[cold]
    fn out_of_memory(size: usize) {
        if tracelab_core::memory::allocation_is_fallible() {
            return; // `try_reserve`: the caller reports it
        }
        let mut digits = [0u8; 20];
        let mut i = digits.len();
        let mut n = size;
        loop {
            i -= 1;
            digits[i] = b'0' + (n % 10) as u8;
            n /= 10;
            if n == 0 {
                break;
            }
        }
        let mut err = std::io::stderr().lock();
        let _ = err.write_all(b"tracelab: not enough memory (an allocation of ");
        let _ = err.write_all(&digits[i..]);
        let _ = err.write_all(b" bytes failed)\n");
        drop(err);
        std::process::exit(1);
    }

    // SAFETY: every call forwards to the system allocator with the caller's arguments
    // unchanged and returns its result; only a null result is looked at, before returning it.
    unsafe impl GlobalAlloc for Orderly {
        unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
            // SAFETY: as the caller promised for `layout`.
            let p = unsafe { System.alloc(layout) };
            if p.is_null() {
                out_of_memory(layout.size());
            }
            p
        }
        unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
            // SAFETY: as the caller promised for `layout`.
            let p = unsafe { System.alloc_zeroed(layout) };
            if p.is_null() {
                out_of_memory(layout.size());
            }
            p
        }
        unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
            // SAFETY: `ptr` came from this allocator with `layout`, as the caller promised.
            let p = unsafe { System.realloc(ptr, layout, new_size) };
            if p.is_null() {
                out_of_memory(new_size);
            }
            p
        }
        unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
            // SAFETY: `ptr` came from this allocator with `layout`.
            unsafe { System.dealloc(ptr, layout) }
        }
    }
}

#[global_allocator]
static ALLOCATOR: orderly_oom::Orderly = orderly_oom::Orderly;
