//! A counting global allocator for the memory tests (exact and deterministic, unlike RSS): the
//! `memory_bounds` test binary installs it with `#[global_allocator]` and its tests read
//! [`CURRENT`] and [`PEAK`] (bytes), each holding [`alone`] so that no other test of the binary
//! allocates while it measures.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};
use std::sync::{Mutex, MutexGuard};

pub struct Counting;
pub static CURRENT: AtomicUsize = AtomicUsize::new(0);
pub static PEAK: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            let now = CURRENT.fetch_add(layout.size(), Relaxed) + layout.size();
            PEAK.fetch_max(now, Relaxed);
        }
        p
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) };
        CURRENT.fetch_sub(layout.size(), Relaxed);
    }
}

static SERIAL: Mutex<()> = Mutex::new(());

/// Held for the whole of a measuring test: the counters are process-wide, so the tests of this
/// binary run one at a time (a test that panicked leaves the lock poisoned, not unusable).
pub fn alone() -> MutexGuard<'static, ()> {
    SERIAL
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}
