//! Big buffers (frames, images, scene arrays, BVHs) allocated fallibly, so that running out
//! of memory is a message naming what did not fit, never an abort with nothing said.

use std::cell::Cell;

use thiserror::Error;

thread_local! {
    /// How many fallible allocations this thread is inside (see [`fallibly`]).
    static FALLIBLE: Cell<u32> = const { Cell::new(0) };
}

/// Runs `f`, which allocates fallibly (`try_reserve`) and handles the failure itself, so
/// that an allocator that ends the process on a failed allocation (the binary's) lets this
/// one come back as an error.
pub fn fallibly<T>(f: impl FnOnce() -> T) -> T {
    FALLIBLE.with(|c| c.set(c.get() + 1));
    let out = f();
    FALLIBLE.with(|c| c.set(c.get().saturating_sub(1)));
    out
}

/// Whether the allocation under way on this thread is one whose failure is handled (inside
/// [`fallibly`]). Allocates nothing: callable from a global allocator.
pub fn allocation_is_fallible() -> bool {
    FALLIBLE.try_with(|c| c.get() > 0).unwrap_or(false)
}

/// A buffer that could not be allocated: what it was for and about how big it was.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
#[error("not enough memory for {what} (needs about {} MB)", megabytes(*.bytes))]
pub struct OutOfMemory {
    pub what: &'static str,
    pub bytes: u64,
}

/// Bytes in whole megabytes (10⁶), rounded up, as the messages give them.
pub fn megabytes(bytes: u64) -> u64 {
    bytes.div_ceil(1_000_000)
}

/// An empty vector with room for `len` items, or the error naming `what`.
pub fn try_with_capacity<T>(len: usize, what: &'static str) -> Result<Vec<T>, OutOfMemory> {
    let mut v = Vec::new();
    fallibly(|| v.try_reserve_exact(len)).map_err(|_| OutOfMemory {
        what,
        bytes: (len as u64).saturating_mul(std::mem::size_of::<T>() as u64),
    })?;
    Ok(v)
}

/// `vec![value; len]`, or the error naming `what`.
pub fn try_vec<T: Clone>(len: usize, value: T, what: &'static str) -> Result<Vec<T>, OutOfMemory> {
    let mut v = try_with_capacity(len, what)?;
    v.resize(len, value);
    Ok(v)
}

/// Makes sure that `bytes` more can be had now by taking and giving them back: a check
/// before a long job whose buffers, together, would not fit (under a memory limit, where an
/// allocation past it fails at once rather than being promised and killed later).
pub fn check_available(bytes: u64, what: &'static str) -> Result<(), OutOfMemory> {
    let err = OutOfMemory { what, bytes };
    let len = usize::try_from(bytes).map_err(|_| err)?;
    let mut probe: Vec<u8> = Vec::new();
    fallibly(|| probe.try_reserve_exact(len)).map_err(|_| err)?;
    Ok(())
}

/// What the program does when an infallible wrapper (`CompiledScene::new`) runs out of
/// memory; set once by the binary (a message and exit 1).
static ON_OUT_OF_MEMORY: std::sync::OnceLock<fn(OutOfMemory)> = std::sync::OnceLock::new();

/// Sets what [`fail_as_infallible`] does before it aborts: the binary prints the message and
/// exits. The first call wins.
pub fn set_out_of_memory_handler(handler: fn(OutOfMemory)) {
    let _ = ON_OUT_OF_MEMORY.set(handler);
}

/// Ends the process for an infallible wrapper of a fallible builder (`CompiledScene::new`)
/// that ran out of memory: the handler the binary set (a message, exit 1), else
/// `handle_alloc_error`, as a failed allocation would.
pub fn fail_as_infallible(e: OutOfMemory) -> ! {
    if let Some(handler) = ON_OUT_OF_MEMORY.get() {
        handler(e);
    }
    let size = usize::try_from(e.bytes)
        .unwrap_or(isize::MAX as usize)
        .min(isize::MAX as usize);
    std::alloc::handle_alloc_error(
        std::alloc::Layout::from_size_align(size, 1).unwrap_or(std::alloc::Layout::new::<u8>()),
    )
}

/// Address space a thread's malloc arena reserves (glibc on 64-bit systems: 64 MiB),
/// counted against a memory limit (`ulimit -v`) whether used or not.
pub const ARENA_BYTES: u64 = 64 << 20;

/// [`check_available`] for a job of many small allocations made on the render threads
/// (a BVH build): its bytes and room for the arenas those threads may yet open (two, as
/// measured on a million-sphere scene: with none, it could abort past this check; with one
/// per thread, it refused scenes that fit).
pub fn check_available_threaded(bytes: u64, what: &'static str) -> Result<(), OutOfMemory> {
    // A small job is not checked: the margin alone would be most of what it asks for.
    if bytes < ARENA_BYTES {
        return Ok(());
    }
    check_available(bytes.saturating_add(2 * ARENA_BYTES), what)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_impossible_buffer_is_an_error_naming_it_not_an_abort() {
        let e = try_vec(usize::MAX / 16, 0u64, "a test buffer").expect_err("too big");
        assert_eq!(e.what, "a test buffer");
        assert!(
            e.to_string()
                .starts_with("not enough memory for a test buffer (needs about "),
            "{e}"
        );
        assert!(check_available(u64::MAX, "everything").is_err());
        assert_eq!(try_vec(3, 7u8, "small").expect("fits"), [7, 7, 7]);
        check_available(1 << 20, "a megabyte").expect("fits");
    }

    #[test]
    fn megabytes_round_up() {
        assert_eq!(megabytes(0), 0);
        assert_eq!(megabytes(1), 1);
        assert_eq!(megabytes(1_000_000), 1);
        assert_eq!(megabytes(1_000_001), 2);
    }
}
