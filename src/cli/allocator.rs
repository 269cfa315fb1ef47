//! How the command line has the C allocator give large blocks back when they are freed.
//!
//! glibc serves a block of up to 32 MB from its arenas once a block that size has been freed
//! (its mmap threshold rises to the largest freed mapping), and every rayon thread has an arena
//! of its own, so observation-sized buffers stay resident after they are freed: a fit's
//! residual vector (14 MB at 2e5 rows of 9 elements), the report's residuals. With the
//! threshold held at [`LARGE_BLOCK`], blocks that size and larger get mappings of their own,
//! returned to the system on free, while the smaller ones (a block's Jacobian columns, under
//! 3 MB) still reuse the arenas. The 2e5-row fit of docs/verification.md peaks at 138 MB
//! resident instead of 189 MB, its results unchanged.

/// Bytes from which a block is a mapping of its own.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
const LARGE_BLOCK: i32 = 4 << 20;

/// Holds glibc's mmap threshold at [`LARGE_BLOCK`]; a no-op with other allocators. Called once,
/// first thing in `main`, before any thread starts.
pub fn return_large_blocks_when_freed() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt only sets a parameter of the allocator, before any other thread exists.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, LARGE_BLOCK);
    }
}
