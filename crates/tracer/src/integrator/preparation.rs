//! What preparing a render reports while it runs, and how it is stopped early.
//!
//! Most of a BSSRDF render's preparation takes milliseconds (profile tables, estimators). A
//! material's shape correction is measured by random walks when the render is prepared, which
//! takes seconds to minutes (17 s on the bunny scene, 339 s on the marble block:
//! `docs/shapes.md`, "Cost"). [`crate::integrator::PathIntegrator::new_observed`] reports that
//! work to a [`PrepareObserver`], which draws it (the experiments crate's bar) and can stop it:
//! an interrupt during preparation ends it within one sample point's walks, with
//! [`crate::integrator::RenderError::Interrupted`] and nothing rendered.

/// What preparation reports while it runs, and how it is stopped early. Called from worker
/// threads, hence `Sync`.
pub trait PrepareObserver: Sync {
    /// A stage of `units` steps starts; `label` names it ("correction walks").
    fn stage(&self, label: &str, units: u64) {
        let _ = (label, units);
    }
    /// `units` more steps of the current stage are done.
    fn advance(&self, units: u64) {
        let _ = units;
    }
    /// True to stop: preparation is abandoned and no integrator is built. Polled once per
    /// step. The default follows [`crate::interrupt`].
    fn stop_requested(&self) -> bool {
        crate::interrupt::requested()
    }
}

/// No progress; stopped by [`crate::interrupt`].
impl PrepareObserver for crate::render::NoObserver {}
