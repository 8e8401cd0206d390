//! How many averaging samples to take, and what to do when a projection ray misses.

use std::num::NonZeroU32;

use bssrdf_core::ParamError;

use crate::names::Named;

/// Number of independently shifted replicates used by [`SampleBudget::TargetRelError`] to
/// estimate the standard error (7 degrees of freedom).
pub const REPLICATES: u32 = 8;

/// The number of samples an averaging stage takes.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum SampleBudget {
    /// Exactly this many points of one randomly shifted low-discrepancy set.
    Fixed(NonZeroU32),
    /// Take samples until the estimated relative standard error of every averaged
    /// coefficient channel is at most `rel_se`, or `max` samples have been taken.
    ///
    /// The error is estimated from [`REPLICATES`] independently shifted replicates (sample
    /// standard deviation of the replicate means / √R); each round doubles every replicate
    /// (1, 2, 4, … points each), reusing the points already taken, so at least `REPLICATES`
    /// samples are used. If `max < REPLICATES` it behaves as `Fixed(max)`. A channel whose
    /// mean is 0 counts as converged only when its replicate means are all 0.
    TargetRelError {
        /// Target relative standard error (finite, > 0), e.g. 0.01.
        rel_se: f64,
        /// Maximum number of samples (points of the region; a multi-ellipse colour stage may
        /// project each point up to 3 times).
        max: NonZeroU32,
    },
}

impl SampleBudget {
    /// `Fixed(n)` in a `const` context; `n = 0` is taken as 1.
    pub const fn fixed(n: u32) -> Self {
        match NonZeroU32::new(n) {
            Some(n) => SampleBudget::Fixed(n),
            None => SampleBudget::Fixed(NonZeroU32::MIN),
        }
    }

    /// Checks the parameters (used by `Estimator::prepare`).
    pub fn validate(&self) -> Result<(), ParamError> {
        match *self {
            SampleBudget::Fixed(_) => Ok(()),
            SampleBudget::TargetRelError { rel_se, .. } => {
                if !rel_se.is_finite() {
                    Err(ParamError::NotFinite {
                        name: "rel_se",
                        value: rel_se,
                    })
                } else if rel_se <= 0.0 {
                    Err(ParamError::OutOfRange {
                        name: "rel_se",
                        range: "(0, inf)",
                        value: rel_se,
                    })
                } else {
                    Ok(())
                }
            }
        }
    }
}

/// What an averaging stage does with a sample whose two projection rays both miss the object
/// (the paper does not say; docs/physics.md#heuristics).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[non_exhaustive]
pub enum MissPolicy {
    /// Average over the hits only (Eq. (3) restricted to the part of the region that projects
    /// onto the object). Default. If every sample misses, the endpoint average
    /// ½(σ(x_i) + σ(x_o)) is used instead and `Diagnostics::fallback` is set.
    #[default]
    HitsOnly,
    /// A miss contributes the endpoint average ½(σ(x_i) + σ(x_o)) (two extra lookups, made
    /// once, on the first miss): the region keeps its full weight.
    Endpoints,
}

impl Named for MissPolicy {
    const WHAT: &'static str = "miss policy";
    const ALL: &'static [Self] = &[MissPolicy::HitsOnly, MissPolicy::Endpoints];
    fn name(self) -> &'static str {
        match self {
            MissPolicy::HitsOnly => "hits-only",
            MissPolicy::Endpoints => "endpoints",
        }
    }
}

named_display_fromstr!(MissPolicy);
