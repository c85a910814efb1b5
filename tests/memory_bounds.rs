//! The memory tests, as one test binary (`cargo test --test memory_bounds`): each installs
//! nothing itself; this root installs the counting global allocator once for all of them, and
//! each test holds [`support::counting_alloc::alone`] while it measures.

mod common;
mod hostile_memory;
mod memory;
mod mot_memory;

mod support {
    pub mod counting_alloc;
}

#[global_allocator]
static GLOBAL: support::counting_alloc::Counting = support::counting_alloc::Counting;
