//! Parsing a method name (`pt` or an estimator name) and adjusting a method's estimator
//! samples and profile model.

use std::str::FromStr;

use bssrdf_core::ProfileModel;
use het_estimate::Estimator;

use super::Method;

impl FromStr for Method {
    type Err = String;
    /// `pt`, `auto` ([`Method::auto`]), or an estimator name (those of [`Estimator::ALL`])
    /// with the estimator's default parameters and each material's own profile.
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
    /// The BSSRDF method's estimator changed by `f`; the path tracer unchanged.
    fn map_estimator(self, f: impl FnOnce(Estimator) -> Estimator) -> Self {
        match self {
            Method::Bssrdf {
                estimator,
                profile,
                policy,
            } => Method::Bssrdf {
                estimator: f(estimator),
                profile,
                policy,
            },
            m => m,
        }
    }

    /// The estimator of a BSSRDF method (`None` for the path tracer).
    fn estimator(&self) -> Option<Estimator> {
        match self {
            Method::Bssrdf { estimator, .. } => Some(*estimator),
            _ => None,
        }
    }

    /// The method with `n` averaging samples per region ([`Estimator::with_samples`]); methods
    /// whose estimator takes none are unchanged.
    pub fn with_estimator_samples(self, n: Option<u32>) -> Self {
        let Some(n) = n else { return self };
        let budget = het_estimate::SampleBudget::fixed(n.max(1));
        self.map_estimator(|e| e.with_samples(budget))
    }

    /// The method with its estimator's averaging set to `averaging` (prefiltered or Monte
    /// Carlo, [`Estimator::with_averaging`]); other methods and `None` leave it unchanged.
    pub fn with_averaging(self, averaging: Option<het_estimate::Averaging>) -> Self {
        match averaging {
            Some(a) => self.map_estimator(|e| e.with_averaging(a)),
            None => self,
        }
    }

    /// The same method with the semi-minor axis reading of Eq. (2) replaced by `semi_minor`
    /// ([`Estimator::with_semi_minor`]); other methods and `None` leave it unchanged.
    pub fn with_semi_minor(self, semi_minor: Option<het_estimate::SemiMinorAxis>) -> Self {
        match semi_minor {
            Some(b) => self.map_estimator(|e| e.with_semi_minor(b)),
            None => self,
        }
    }

    /// The estimator's semi-minor axis reading (`None` for methods without one).
    pub fn semi_minor(&self) -> Option<het_estimate::SemiMinorAxis> {
        self.estimator().and_then(|e| e.semi_minor())
    }

    /// The estimator's averaging (`None` for methods without one).
    pub fn averaging(&self) -> Option<het_estimate::Averaging> {
        self.estimator().and_then(|e| e.averaging())
    }

    /// The options the method's estimator takes (none for the path tracer).
    pub fn estimator_options(&self) -> het_estimate::EstimatorOptions {
        self.estimator().map(|e| e.options()).unwrap_or_default()
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
