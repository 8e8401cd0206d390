//! Parsing a method name (`pt` or an estimator name) and adjusting a method's estimator
//! samples and profile model.

use std::str::FromStr;

use bssrdf_core::ProfileModel;
use het_estimate::Estimator;

use super::Method;

impl FromStr for Method {
    type Err = String;
    /// `pt`, `auto` ([`Method::auto`]), or an estimator name (`jensen-in`, `jensen-out`,
    /// `endpoints`, `segment`, `sone`, `kernel`) with the estimator's default parameters and
    /// each material's own profile.
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "pt" => return Ok(Method::PathTraced),
            "auto" => {
                return Ok(Method::auto(Estimator::Sone(
                    het_estimate::SoneParams::new(),
                )));
            }
            _ => {}
        }
        Estimator::from_str(s)
            .map(|estimator| Method::bssrdf(estimator, None))
            .map_err(|e| {
                format!(
                    "{e}; or `pt` for the path-traced reference, `auto` for the per-object choice"
                )
            })
    }
}

impl Method {
    /// The method with `n` averaging samples per region (segment: on the chord; Sone: in the
    /// disk and in the ellipse; kernel: points drawn around the chord, at most
    /// `KernelParams::MAX_SAMPLES`, which `prepare` enforces); other methods are unchanged.
    pub fn with_estimator_samples(self, n: Option<u32>) -> Self {
        let Some(n) = n else { return self };
        let budget = het_estimate::SampleBudget::fixed(n.max(1));
        match self {
            Method::Bssrdf {
                estimator: Estimator::Segment(p),
                profile,
                policy,
            } => Method::Bssrdf {
                estimator: Estimator::Segment(p.with_samples(budget)),
                profile,
                policy,
            },
            Method::Bssrdf {
                estimator: Estimator::Sone(p),
                profile,
                policy,
            } => Method::Bssrdf {
                estimator: Estimator::Sone(p.with_samples(budget)),
                profile,
                policy,
            },
            Method::Bssrdf {
                estimator: Estimator::Kernel(p),
                profile,
                policy,
            } => Method::Bssrdf {
                estimator: Estimator::Kernel(p.with_samples(budget)),
                profile,
                policy,
            },
            m => m,
        }
    }

    /// The method with Sone's or the kernel's averaging set to `averaging` (prefiltered or
    /// Monte Carlo); other methods are unchanged.
    pub fn with_averaging(self, averaging: Option<het_estimate::Averaging>) -> Self {
        match (self, averaging) {
            (
                Method::Bssrdf {
                    estimator,
                    profile,
                    policy,
                },
                Some(a),
            ) => Method::Bssrdf {
                estimator: match estimator {
                    Estimator::Sone(p) => Estimator::Sone(p.with_averaging(a)),
                    Estimator::Kernel(p) => Estimator::Kernel(p.with_averaging(a)),
                    e => e,
                },
                profile,
                policy,
            },
            (m, _) => m,
        }
    }

    /// The same method with Sone's semi-minor axis reading of Eq. (2) replaced by
    /// `semi_minor` (b = w, the default, or b = w/2, the literal reading); other methods and
    /// `None` leave it unchanged.
    pub fn with_semi_minor(self, semi_minor: Option<het_estimate::SemiMinorAxis>) -> Self {
        match (self, semi_minor) {
            (
                Method::Bssrdf {
                    estimator: Estimator::Sone(mut p),
                    profile,
                    policy,
                },
                Some(b),
            ) => {
                p.semi_minor = b;
                Method::Bssrdf {
                    estimator: Estimator::Sone(p),
                    profile,
                    policy,
                }
            }
            (m, _) => m,
        }
    }

    /// Sone's semi-minor axis reading (`None` for other methods).
    pub fn semi_minor(&self) -> Option<het_estimate::SemiMinorAxis> {
        match self {
            Method::Bssrdf {
                estimator: Estimator::Sone(p),
                ..
            } => Some(p.semi_minor),
            _ => None,
        }
    }

    /// Sone's or the kernel's averaging (`None` for other methods).
    pub fn averaging(&self) -> Option<het_estimate::Averaging> {
        match self {
            Method::Bssrdf {
                estimator: Estimator::Sone(p),
                ..
            } => Some(p.averaging),
            Method::Bssrdf {
                estimator: Estimator::Kernel(p),
                ..
            } => Some(p.averaging),
            _ => None,
        }
    }

    /// The method with its profile model overridden (BSSRDF methods only).
    pub fn with_profile(self, profile: Option<ProfileModel>) -> Self {
        match self {
            Method::Bssrdf {
                estimator, policy, ..
            } => Method::Bssrdf {
                estimator,
                profile,
                policy,
            },
            m => m,
        }
    }
}
