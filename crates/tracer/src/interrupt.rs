//! A process-wide request to stop long work early (set by the command line's SIGINT/SIGTERM
//! handler). The render loop ([`crate::render::render`]) and the beam experiment's light tracer
//! poll it, abandon the pass in progress and return what the completed passes gave, marked as
//! interrupted.

use std::sync::atomic::{AtomicBool, Ordering};

static REQUESTED: AtomicBool = AtomicBool::new(false);

/// Asks every running render to stop after abandoning its current pass.
pub fn request() {
    REQUESTED.store(true, Ordering::SeqCst);
}

/// True once [`request`] was called.
#[inline]
pub fn requested() -> bool {
    REQUESTED.load(Ordering::Relaxed)
}
