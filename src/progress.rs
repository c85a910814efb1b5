//! Progress of long steps, as the library reports it: a small trait that the binary implements
//! with terminal progress bars (`src/cli/progress.rs`) and tests leave silent. The
//! library never draws anything itself.

use std::sync::Arc;

/// One progress bar: a count towards a length, with a short message.
pub trait Progress: Send + Sync {
    /// The number of steps to expect (may change while running).
    fn set_length(&self, _len: u64) {}
    /// `n` more steps done.
    fn inc(&self, _n: u64) {}
    /// What is being done now ("frames", "3-D", ...).
    fn set_message(&self, _msg: &str) {}
}

/// Makes progress bars: one per session being processed or synthesized.
pub trait Reporter: Send + Sync {
    /// A new bar labelled `prefix`, counting `unit` (e.g. "sessions", "sensor frames").
    /// The bar is removed from the display when the returned value is dropped.
    fn bar(&self, prefix: &str, unit: &str) -> Box<dyn Progress>;
}

/// Reports nothing.
#[derive(Debug, Clone, Copy, Default)]
pub struct Silent;

impl Progress for Silent {}

impl Reporter for Silent {
    fn bar(&self, _prefix: &str, _unit: &str) -> Box<dyn Progress> {
        Box::new(Silent)
    }
}

/// A shared reporter, as options carry it (`None` = silent).
pub type SharedReporter = Option<Arc<dyn Reporter>>;

/// The reporter of `shared`, or [`Silent`].
pub fn reporter(shared: &SharedReporter) -> &dyn Reporter {
    match shared {
        Some(r) => r.as_ref(),
        None => &Silent,
    }
}
